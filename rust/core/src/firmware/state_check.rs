//! The firmware state's validity, checked at every attitude step on the values its output row
//! carries (already converted to f64 for the row: the check is a dozen comparisons). The first step
//! whose state is out of range raises one `state_out_of_range` event (error): from there the
//! output is not a navigation solution, however finite it may still look.
//!
//! In range (firmware_model/SCHEMA.md, "Firmware state checked at every step"):
//! - the quaternion: finite, |‖Q‖² − 1| ≤ 1e-3 (every update ends with a normalisation, which leaves
//!   ‖Q‖² within a few units of the last place of 1: 1e-7 in f32, 4e-9 in IQ30);
//! - the Euler angles: finite;
//! - the velocity: each component within ±1e4 m/s, the range the profile accepts for the initial
//!   velocity (`navigation.velocity_enu`);
//! - the latitude within (−90°, 90°) (cos φ vanishes at the pole: λ̇ and ω_en are infinite there), the
//!   longitude finite;
//! - the height within −1e4 … 1e5 m, the range the profile accepts (`navigation.height_m`): the earth
//!   model (first-order free-air gravity, radii R + h) is built for heights near the surface. The
//!   free-inertial vertical channel leaves it first: gravity falls off as γ(1 − 2h/R), so a height
//!   error grows as e^(t/τ) with τ = √(R/2γ) ≈ 571 s, until it runs away.

use crate::events::{Event, Severity};
use crate::output::{CycleRow, ReadRow};
use crate::time::{ps_to_s, Ps, PS_PER_S};

/// |‖Q‖² − 1| above this is a quaternion out of range.
pub const QUAT_NORM2_TOLERANCE: f64 = 1e-3;
/// |V| per component above this (m/s) is out of range: `navigation.velocity_enu`'s limit.
pub const VELOCITY_LIMIT_M_S: f64 = 1e4;
/// |latitude| at or above this (degrees) is out of range.
pub const LATITUDE_LIMIT_DEG: f64 = 90.0;
/// The height range (m): `navigation.height_m`'s.
pub const HEIGHT_RANGE_M: (f64, f64) = (-1e4, 1e5);

/// Whether every state variable of the row is in range. Every comparison is false for NaN, so a
/// non-finite value is out of range too.
#[inline]
pub fn in_range(row: &CycleRow) -> bool {
    let [q0, q1, q2, q3] = row.quat;
    let norm2 = q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3;
    let [e0, e1, e2] = row.euler_deg;
    let [v0, v1, v2] = row.vel_enu;
    let [lat, lon, h] = row.pos;
    (norm2 - 1.0).abs() <= QUAT_NORM2_TOLERANCE
        && (e0 + e1 + e2).is_finite()
        && v0.abs() <= VELOCITY_LIMIT_M_S
        && v1.abs() <= VELOCITY_LIMIT_M_S
        && v2.abs() <= VELOCITY_LIMIT_M_S
        && lat.abs() < LATITUDE_LIMIT_DEG
        && lon.is_finite()
        && h >= HEIGHT_RANGE_M.0
        && h <= HEIGHT_RANGE_M.1
}

/// What is out of range in a row [`in_range`] refused: (the first variable out of range, its value,
/// the limit it crossed, a sentence naming every variable out of range with its value).
#[cold]
pub fn describe(row: &CycleRow) -> (f64, f64, String) {
    let [q0, q1, q2, q3] = row.quat;
    let norm2 = q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3;
    let (h_min, h_max) = HEIGHT_RANGE_M;
    let mut bad: Vec<(f64, f64, String)> = Vec::new();
    if (norm2 - 1.0).abs() > QUAT_NORM2_TOLERANCE || norm2.is_nan() {
        bad.push((
            norm2,
            1.0,
            format!("quaternion {:?}: |Q|² = {norm2:e}, expected 1 ± {QUAT_NORM2_TOLERANCE:e}", row.quat),
        ));
    }
    if !row.euler_deg.iter().all(|x| x.is_finite()) {
        bad.push((f64::NAN, 0.0, format!("Euler angles {:?}° not finite", row.euler_deg)));
    }
    for (axis, v) in ["east", "north", "up"].iter().zip(row.vel_enu) {
        let in_range = v.abs() <= VELOCITY_LIMIT_M_S;
        if !in_range {
            bad.push((
                v,
                VELOCITY_LIMIT_M_S,
                if *axis == "up" {
                    format!(
                        "velocity up = {v:e} m/s, expected within ±{VELOCITY_LIMIT_M_S:e} (the free-inertial \
                         vertical channel has run away; for an attitude-only trace set firmware.navigation=false)"
                    )
                } else {
                    format!("velocity {axis} = {v:e} m/s, expected within ±{VELOCITY_LIMIT_M_S:e}")
                },
            ));
        }
    }
    let [lat, lon, h] = row.pos;
    let lat_in_range = lat.abs() < LATITUDE_LIMIT_DEG;
    if !lat_in_range {
        bad.push((lat, LATITUDE_LIMIT_DEG, format!("latitude = {lat:e}°, expected within ±{LATITUDE_LIMIT_DEG}°")));
    }
    if !lon.is_finite() {
        bad.push((lon, 0.0, format!("longitude = {lon}°, expected finite")));
    }
    let h_in_range = h >= h_min && h <= h_max;
    if !h_in_range {
        let limit = if h < h_min { h_min } else { h_max };
        bad.push((
            h,
            limit,
            format!(
                "height = {h:e} m, expected {h_min:e} … {h_max:e} m (the free-inertial vertical channel has run \
                 away; for an attitude-only trace set firmware.navigation=false)"
            ),
        ));
    }
    let what = bad.iter().map(|b| b.2.as_str()).collect::<Vec<_>>().join("; ");
    let (value, limit) = bad.first().map_or((f64::NAN, 0.0), |b| (b.0, b.1));
    (value, limit, what)
}

/// The state check every application's step rows go through (the emulator runs it on each row a
/// tick wrote): the first step out of range raises one `state_out_of_range` error naming what; later
/// steps are not checked (the state does not come back from there on its own).
#[derive(Debug, Clone, Default)]
pub struct StateWatch {
    /// A step has been out of range.
    tripped: bool,
}

impl StateWatch {
    /// The event of `row`, if it is the first step out of range.
    #[inline]
    pub fn check(&mut self, row: &CycleRow) -> Option<Event> {
        if self.tripped || in_range(row) {
            return None;
        }
        self.tripped = true;
        Some(out_of_range_event(row))
    }

    /// Whether a step has been out of range.
    pub fn tripped(&self) -> bool {
        self.tripped
    }
}

#[cold]
#[inline(never)]
fn out_of_range_event(row: &CycleRow) -> Event {
    let (value, limit, what) = describe(row);
    Event::rule(
        row.t_ps,
        "state_out_of_range",
        Severity::Error,
        format!(
            "step {} at {:.3} s: the firmware state is out of range: {what}; the output is no navigation \
             solution from here",
            row.step,
            ps_to_s(row.t_ps)
        ),
        value,
        limit,
    )
}

/// How long the reads may find no new sample from the part before it is reported as producing no
/// data: one second, hundreds of sample periods of any part the boards read (the slowest, the
/// ADIS16407's decimated rates, still samples at tens of hertz), so that a part that only starts
/// late (`device.first_sample_us`, a start-up) or skips samples is not reported, and one that never
/// samples, or stops, is.
pub const NO_DATA_PS: Ps = PS_PER_S;

/// The data check of every application whose reads carry the device's sample (the emulator runs it
/// on each read row): one `no_data` error when the reads have found no new sample for
/// [`NO_DATA_PS`] (none since the first read, or none since the last new one); it re-arms when a new
/// sample comes. At the end of the input, reads that never found a sample are reported whatever
/// their span ([`DataWatch::finish`]).
#[derive(Debug, Clone, Default)]
pub struct DataWatch {
    /// The time of the first read, and the last sample index seen with its read's time.
    first_read: Option<Ps>,
    last: Option<(i64, Ps)>,
    reads: u64,
    reported: bool,
}

impl DataWatch {
    /// The event of read `r`, if the part has produced no new sample for [`NO_DATA_PS`] by then.
    #[inline]
    pub fn read(&mut self, r: &ReadRow) -> Option<Event> {
        self.reads += 1;
        let first = *self.first_read.get_or_insert(r.t_cs_ps);
        if r.sample_index >= 0 && self.last.is_none_or(|(i, _)| i != r.sample_index) {
            self.last = Some((r.sample_index, r.t_cs_ps));
            self.reported = false;
            return None;
        }
        let since = self.last.map_or(first, |(_, t)| t);
        if self.reported || r.t_cs_ps.saturating_sub(since) < NO_DATA_PS {
            return None;
        }
        self.reported = true;
        Some(self.event(r.t_cs_ps, since))
    }

    /// At the end of the input: the event of reads that never found a sample, if no event said so.
    pub fn finish(&mut self) -> Option<Event> {
        match (self.first_read, self.last, self.reported) {
            (Some(first), None, false) => {
                self.reported = true;
                Some(self.event(first, first))
            }
            _ => None,
        }
    }

    #[cold]
    fn event(&self, t_ps: Ps, since: Ps) -> Event {
        let what = match self.last {
            None => format!(
                "the part has produced no sample in {} read(s) since the first at {:.6} s: the firmware reads no \
                 data (a part that never samples: see device.first_sample_us and the start-up settings)",
                self.reads,
                ps_to_s(since)
            ),
            Some((i, _)) => format!(
                "the part has produced no new sample since sample {i} at {:.6} s: the firmware reads stale data",
                ps_to_s(since)
            ),
        };
        Event::rule(t_ps, "no_data", Severity::Error, what, ps_to_s(t_ps.saturating_sub(since)), ps_to_s(NO_DATA_PS))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row() -> CycleRow {
        CycleRow {
            step: 7,
            t_ps: 0,
            quat: [1.0, 0.0, 0.0, 0.0],
            euler_deg: [0.0; 3],
            vel_enu: [0.0; 3],
            pos: [40.84, 111.75, 1050.0],
        }
    }

    /// Each state variable forced out of range (or to NaN / ±inf) is refused and named; a state at
    /// the edges of the ranges is accepted.
    #[test]
    fn every_state_variable_out_of_range_is_named() {
        assert!(in_range(&row()));
        let edge = CycleRow {
            quat: [1.0 + 0.49e-3, 0.0, 0.0, 0.0],
            vel_enu: [-1e4, 1e4, 0.0],
            pos: [89.999, -1e6, -1e4],
            ..row()
        };
        assert!(in_range(&edge));
        type Force = fn(&mut CycleRow);
        let cases: [(Force, &str); 10] = [
            (|r| r.quat = [f64::NAN, 0.0, 0.0, 0.0], "quaternion"),
            (|r| r.quat = [0.0; 4], "quaternion"),
            (|r| r.quat[2] = f64::INFINITY, "quaternion"),
            (|r| r.euler_deg[1] = f64::NAN, "Euler"),
            (|r| r.vel_enu[2] = -2e4, "velocity up"),
            (|r| r.vel_enu[0] = f64::NEG_INFINITY, "velocity east"),
            (|r| r.pos[0] = 90.0, "latitude"),
            (|r| r.pos[1] = f64::NAN, "longitude"),
            (|r| r.pos[2] = -1.5e4, "height = -1.5e4 m"),
            (|r| r.pos[2] = f64::INFINITY, "height = inf m"),
        ];
        for (force, name) in cases {
            let mut r = row();
            force(&mut r);
            assert!(!in_range(&r), "{name}");
            let (_, _, what) = describe(&r);
            assert!(what.contains(name), "{name}: {what}");
        }
    }
}

#[cfg(test)]
mod watch_tests {
    use super::*;

    fn read(t_ps: Ps, sample_index: i64) -> ReadRow {
        ReadRow {
            tick: 0,
            t_cs_ps: t_ps,
            t_start_ps: t_ps,
            t_end_ps: t_ps,
            words: [0; crate::output::READ_WORDS],
            rate: [0.0; 3],
            accel: [0.0; 3],
            sample_index,
            sample_ps: t_ps,
            assumed_s: 0.0,
            age_ps: 0,
        }
    }

    /// Reads that never find a sample: one `no_data` error a second after the first read; reads
    /// that find a new sample every period: none; a part that stops: one, a second after its last
    /// sample, and again after it resumes and stops again.
    #[test]
    fn a_part_without_data_is_one_event_per_spell() {
        let ms = 1_000_000_000;
        let mut w = DataWatch::default();
        let events: Vec<Event> = (0..3000).filter_map(|k| w.read(&read(k * ms, -1))).collect();
        assert_eq!(events.len(), 1, "{events:?}");
        assert_eq!((events[0].kind, events[0].t_ps), ("no_data", 1000 * ms));
        assert!(w.finish().is_none(), "reported once");

        let mut w = DataWatch::default();
        assert!((0..3000).all(|k| w.read(&read(k * ms, k as i64)).is_none()));
        assert!(w.finish().is_none());

        let mut w = DataWatch::default();
        let index = |k: i64| {
            if (500..2000).contains(&k) {
                499
            } else if k >= 3000 {
                2999
            } else {
                k
            }
        };
        let events: Vec<Event> = (0..5000).filter_map(|k| w.read(&read(k as Ps * ms, index(k)))).collect();
        let at: Vec<Ps> = events.iter().map(|e| e.t_ps / ms).collect();
        assert_eq!(at, [1499, 3999]);

        let mut w = DataWatch::default();
        assert!((0..10).all(|k| w.read(&read(k * ms, -1)).is_none()), "a short run");
        assert_eq!(w.finish().map(|e| e.kind), Some("no_data"), "…that never found a sample");
    }

    #[test]
    fn the_state_watch_reports_the_first_step_out_of_range_once() {
        let good = CycleRow {
            step: 0,
            t_ps: 0,
            quat: [1.0, 0.0, 0.0, 0.0],
            euler_deg: [0.0; 3],
            vel_enu: [0.0; 3],
            pos: [0.0; 3],
        };
        let bad = CycleRow { step: 1, t_ps: 5, quat: [f64::NAN; 4], ..good };
        let mut w = StateWatch::default();
        assert!(w.check(&good).is_none());
        let e = w.check(&bad).unwrap();
        assert_eq!((e.kind, e.t_ps), ("state_out_of_range", 5));
        assert!(e.message.contains("step 1") && e.message.contains("quaternion"), "{}", e.message);
        assert!(w.check(&bad).is_none() && w.tripped());
    }
}
