//! The TMS320C6727B side as far as the navigation needs it (c6727.md): SPI1 as a slave receiving
//! the node's packets word by word, dMAX moving each word to memory and raising the packet
//! interrupt, the RTI as its time base and packet watchdog, and the handler's cycle cost.
//!
//! - **SPI1 (slave)**: SCLK comes from the node's SPI #8; the thesis's 10 MHz ceiling is checked
//!   when the profile is read. Each 16-bit word ends 16 SCLK periods after the previous one; dMAX
//!   moves it in `dmax_word_cycles` [estimate] and, after the last word of a packet, raises the
//!   interrupt (thesis l. 1363).
//! - **RTI**: a free-running counter on SYSCLK2 (= SYSCLK1 / 2, 112.5 MHz) [unconfirmed, c6727.md:
//!   RTI structure from the TMS470/570 lineage]; each packet is stamped with it, and a compare at
//!   the packet rate finds a packet that did not come (`packet_missing`).
//! - **Navigation** ([`super::nav`]): on every packet, in the C67x+'s single precision
//!   ([`C67xF32`]): the strapdown at 200 Hz, the compass sub-filter at 10 Hz, the GPS sub-filter
//!   and the fusion at 1 Hz. Denormals the filter meets are flushed and counted
//!   ([`DspOutput::flushes`]).
//! - **Cycle costs**: each stage's cycles are its operations, counted by running the stage's own
//!   code in the counting type ([`Counted`]), times the `[dsp]` per-operation costs, plus the ISR
//!   entry and the CRC loop for the decode. A stage's count depends only on its branch pattern
//!   (decode: which words are new; strapdown: which axes the rate recovery bridged; the filters and
//!   the fusion: one pattern each, their data-dependent zero tests priced from their first run), so
//!   it is counted once per pattern and reused. The start (one packet) and the output's f64
//!   conversions are not priced.
//! - **Arithmetic of the decode's tilt**: IEEE double. The C67x+ flushes denormal operands and
//!   results to zero and writes NaN as 0x7FFF_FFFF ([unconfirmed] recollection of SPRU733); Rust's
//!   f64 does neither. On what this handler computes they cannot differ: every input is a count
//!   n, |n| < 2¹⁵, times a power of two (3.9 mg = 2⁻⁸ g) or a decimal scale, so each nonzero
//!   operand and result is ≥ 2⁻¹⁶ in magnitude (products ≥ 2⁻³², sums of squares likewise), far
//!   above the smallest normal double (2⁻¹⁰²²); no operation takes 0/0, ∞ or a negative square
//!   root (the sum of squares is ≥ 0, atan2(0, 0) is 0 in TI's RTS as in C99), so no NaN is made.
//!   `tilt` is generic over [`Scalar`] so a C67x backend can be put in when the navigation's
//!   filter (issue 23) reaches values where they would differ. The libraries' last bit
//!   (TI RTS atan2/sqrt against Rust's) is not modelled.
//!
//! Besides the navigation the handler outputs the packet's values in physical units and a tilt
//! (pitch, roll) from the specific force at the array's origin (the centre accelerometer's A₇, A₈,
//! A₉ in the thesis's layout) by the reference design's level
//! formula, θ = atan2(−f_x, √(f_y² + f_z²)), φ = atan2(f_y, f_z) — the attitude only when the
//! vehicle does not accelerate (priced with the decode).

use super::frame::{self, Packet};
use super::nav::{self, Nav, NavConfig, NavOutput};
use super::node::TickTiming;
use super::{profile, Stages};
use crate::deadline;
use crate::device::adxl345;
use crate::events::{Event, EventLog, Severity};
use crate::firmware::gfnav::{self, Bridge};
use crate::numerics::counter::{count, Counted, OpCounts};
use crate::numerics::{c67x, C67xF32, QClass, Scalar};
use crate::time::{Clock, Ps};
use std::collections::HashMap;

/// What the DSP has after one packet.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DspOutput {
    /// The packet interrupt, ps.
    pub t_irq: Ps,
    /// The handler's end, ps.
    pub t_done: Ps,
    /// RTI count at the interrupt.
    pub rti: u64,
    /// The packet.
    pub packet: Packet,
    /// A₁…A₉, g.
    pub accel_g: [f64; 9],
    /// Compass heading, pitch, roll, °.
    pub compass_deg: [f64; 3],
    /// GPS latitude, longitude (°), altitude (m), speed (m/s), course (°), UTC (s of the day).
    pub gps: [f64; 6],
    /// Pitch and roll from the specific force at the array's origin (the centre accelerometer in
    /// the thesis's layout), rad.
    pub tilt: [f64; 2],
    /// The navigation after this packet (NaN until it starts).
    pub nav: NavOutput,
    /// Handler cycles (SYSCLK1).
    pub cycles: u64,
    /// The handler's time by stage, ps.
    pub stages: Stages,
    /// Denormals flushed by the navigation since power-up.
    pub flushes: u64,
}

/// The priced stages (the cache's keys).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Stage {
    Decode,
    Strapdown,
    Compass,
    Gps,
    Fusion,
}

/// The cycles of `stage` in branch pattern `key`: counted by `run` the first time, then reused.
fn cost(
    costs: &mut HashMap<(Stage, u32), u64>,
    d: &profile::Dsp,
    stage: Stage,
    key: u32,
    run: impl FnOnce() -> OpCounts,
) -> u64 {
    *costs.entry((stage, key)).or_insert_with(|| price(&run(), d))
}

/// `ops` priced with the `[dsp]` per-operation costs, CPU cycles.
pub fn price(c: &OpCounts, d: &profile::Dsp) -> u64 {
    (c.adds + c.subs) * d.add_cycles
        + (c.muls + c.int_muls) * d.mul_cycles
        + c.divs * d.div_cycles
        + c.sqrts * d.sqrt_cycles
        + (c.sins + c.coss) * d.sin_cos_cycles
        + c.atans * d.atan_cycles
        + c.atan2s * d.atan2_cycles
        + c.asins * d.asin_cycles
        + (c.abs + c.negs) * d.neg_abs_cycles
        + c.comparisons * d.compare_cycles
        + c.int_to_float * d.int_to_float_cycles
        + c.constants * d.constant_cycles
}

/// The tilt of a specific force (any units): pitch θ = atan2(−f_x, √(f_y² + f_z²)), roll
/// φ = atan2(f_y, f_z).
pub fn tilt<T: Scalar>(f: [T; 3]) -> [T; 2] {
    let [fx, fy, fz] = f;
    [(-fx).atan2((fy * fy + fz * fz).sqrt()).to_class(QClass::Angle), fy.atan2(fz).to_class(QClass::Angle)]
}

/// The C6727B.
#[derive(Debug)]
pub struct Dsp {
    cfg: profile::Dsp,
    cpu: Clock,
    rti: Clock,
    lsb_g: f64,
    period: Ps,
    last_irq: Option<Ps>,
    last_sequence: Option<u16>,
    events: EventLog,
    nav: Nav<C67xF32>,
    /// Cycles per (stage, branch pattern), counted once.
    costs: HashMap<(Stage, u32), u64>,
    flushes: u64,
    /// A packet's navigation has been out of range ([`check_state`]): reported once.
    state_tripped: bool,
}

impl Dsp {
    /// The compass errors' correlation time its navigation models, s (`compass.correlation_time_s`).
    pub fn compass_tau_s(&self) -> f64 {
        self.nav.compass_tau_s()
    }

    /// The DSP of `profile` (`lsb_g`: the accelerometer counts' scale; `period`: the packet period).
    pub fn new(profile: &profile::GfsinsProfile, period: Ps) -> Dsp {
        let cpu = Clock::from_hz(profile.dsp.cpu_hz);
        let lsb_g = adxl345::resolution(profile.array.data_format).1;
        let cfg = NavConfig {
            dt: period as f64 * 1e-12,
            array: profile.array.inverse(),
            lsb_g,
            min_denominator: profile.dsp.min_denominator,
            gps_age_s: profile.dsp.gps_age_ms * 1e-3,
            compass_tau_s: profile.compass.correlation_time_s,
        };
        Dsp {
            nav: Nav::new(cfg),
            costs: HashMap::new(),
            flushes: 0,
            state_tripped: false,
            cfg: profile.dsp.clone(),
            cpu,
            rti: cpu.divided(2),
            lsb_g,
            period,
            last_irq: None,
            last_sequence: None,
            events: EventLog::default(),
        }
    }

    /// The navigation's stages on `packet` (cycles per stage into `stages`), and its output.
    fn navigate(&mut self, packet: &Packet, t_irq: Ps, stages: &mut [(&'static str, u64); 5]) -> NavOutput {
        let lsb = self.lsb_g;
        let d = nav::decode::<C67xF32>(packet, lsb);
        let key = u32::from(packet.flags & (frame::NEW_COMPASS | frame::NEW_GPS | frame::GPS_VALID));
        let fixed = self.cfg.isr_entry_cycles + self.cfg.crc_cycles_per_word * frame::WORDS as u64;
        let array = self.nav.array();
        stages[0].1 = fixed
            + cost(&mut self.costs, &self.cfg, Stage::Decode, key, || {
                count(|| {
                    let d = nav::decode::<Counted>(packet, lsb);
                    tilt(array.accel(&d.accel))
                })
                .1
            });
        if !self.nav.start(packet, &d) {
            return self.nav.solution(&gfnav::RateOutput {
                rate: [C67xF32::default(); 3],
                bridged: [Bridge::No; 3],
                denominators: [C67xF32::default(); 3],
            });
        }
        let before = self.nav.ins().clone();
        let out = self.nav.strapdown(&d.accel);
        let pattern = out.bridged.iter().fold(0u32, |k, b| k * 3 + *b as u32);
        stages[1].1 = cost(&mut self.costs, &self.cfg, Stage::Strapdown, pattern, || {
            // The copy is made outside the count: its conversions are the model's, not the DSP's.
            let (mut copy, accel) = (before.cast::<Counted>(), d.accel.map(|x| Counted(x.to_f64())));
            count(|| copy.step(&accel)).1
        });
        if self.nav.spell(&out) {
            if let Some(mut e) = gfnav::singular_event(t_irq, &out, self.cfg.min_denominator) {
                e.message.push_str(" (a spell begins: reported once until a step is solved on every axis)");
                self.events.push(e);
            }
        }
        let (mut compass_update, mut gps_update, mut fused) = (false, false, None);
        // Each filter's cost is counted on a copy in the counting type before the filter runs, the
        // first time only (the copy is made only then).
        let seq = packet.sequence;
        if let Some(hpr) = d.compass {
            stages[2].1 = cost(&mut self.costs, &self.cfg, Stage::Compass, 0, || {
                let (mut copy, h) = (self.nav.cast::<Counted>(), hpr.map(|x| Counted(x.to_f64())));
                count(|| copy.compass_filter(seq, &h)).1
            });
            self.nav.compass_filter(seq, &hpr);
            compass_update = true;
        }
        if let Some(sc) = d.gps_vel {
            stages[3].1 = cost(&mut self.costs, &self.cfg, Stage::Gps, 0, || {
                let (mut copy, g) = (self.nav.cast::<Counted>(), sc.map(|x| Counted(x.to_f64())));
                count(|| copy.gps_filter(seq, packet, &g)).1
            });
            stages[4].1 = cost(&mut self.costs, &self.cfg, Stage::Fusion, 0, || {
                let mut copy = self.nav.cast::<Counted>();
                count(|| copy.fusion()).1
            });
            self.nav.gps_filter(seq, packet, &sc);
            let done = self.nav.fusion();
            if !done {
                let what = "C6727: fusion refused: sub-filter 2's factor D has an element ≤ 0 (the fused estimate keeps its last value)";
                self.events.push(Event::new(t_irq, "fusion_refused", Severity::Warning, what.to_string()));
            }
            gps_update = true;
            fused = Some(done);
        }
        // The solution after the filters (the fusion may have moved it).
        NavOutput { compass_update, gps_update, fused, ..self.nav.solution(&out) }
    }

    /// The packet `words` clocked in by SPI1 as `timing` says (SCLK period `sck`): the output, or
    /// `None` when the packet is refused (an event says why).
    pub fn receive(&mut self, words: &[u16], timing: &TickTiming) -> Option<DspOutput> {
        let t_irq = timing.packet_end + self.cpu.cycles_to_ps(self.cfg.dmax_word_cycles);
        if let Some(last) = self.last_irq {
            // The RTI compare at the packet rate: more than one period and a half without a packet.
            if t_irq > last + self.period + self.period / 2 {
                let what = format!("C6727: no packet between {last} ps and {t_irq} ps");
                self.events.push(Event::new(t_irq, "packet_missing", Severity::Error, what));
            }
        }
        self.last_irq = Some(t_irq);
        let packet = match Packet::decode(words) {
            Ok(p) => p,
            Err(why) => {
                self.events.push(Event::new(t_irq, "packet_refused", Severity::Error, format!("C6727: {why}")));
                return None;
            }
        };
        if let Some(s) = self.last_sequence.filter(|&s| packet.sequence != s.wrapping_add(1)) {
            let what = format!("C6727: packet {} after {s}", packet.sequence);
            self.events.push(Event::new(t_irq, "packet_missing", Severity::Error, what));
        }
        self.last_sequence = Some(packet.sequence);
        let accel_g = packet.accel.map(|n| f64::from(n) * self.lsb_g);
        let [h, p, r] = packet.compass.map(|n| f64::from(n) / 10.0);
        let g = &packet.gps;
        let gps = [
            f64::from(g.lat_e7) * 1e-7,
            f64::from(g.lon_e7) * 1e-7,
            f64::from(g.alt_cm) / 100.0,
            f64::from(g.speed_cm_s) / 100.0,
            f64::from(g.course_cdeg) / 100.0,
            f64::from(g.utc_ms) / 1000.0,
        ];
        let tilt = tilt(self.nav.array().accel(&accel_g));
        let flushes_before = c67x::flushes();
        let mut cycles = [("decode", 0), ("strapdown", 0), ("compass filter", 0), ("GPS filter", 0), ("fusion", 0)];
        let nav = self.navigate(&packet, t_irq, &mut cycles);
        self.flushes += c67x::flushes().wrapping_sub(flushes_before);
        if !self.state_tripped && self.nav.started() {
            if let Some(e) = check_state(t_irq, packet.sequence, &nav) {
                self.state_tripped = true;
                self.events.push(e);
            }
        }
        let mut stages = Stages::default();
        for (name, c) in cycles.iter().filter(|(_, c)| *c > 0) {
            stages.push(name, self.cpu.cycles_to_ps(*c));
        }
        let total = cycles.iter().map(|(_, c)| c).sum();
        let t_done = t_irq + stages.total();
        // The deadline: the next packet's interrupt, one period after this one's.
        let sequence = packet.sequence;
        if let Some(e) = deadline::check(|| format!("C6727, packet {sequence}"), t_irq, t_done, t_irq + self.period) {
            self.events.push(e);
        }
        Some(DspOutput {
            t_irq,
            t_done,
            rti: self.rti.ps_to_cycles(t_irq),
            packet,
            accel_g,
            compass_deg: [h, p, r],
            gps,
            tilt,
            nav,
            cycles: total,
            stages,
            flushes: self.flushes,
        })
    }

    /// The CPU's cycles in one packet period.
    pub fn cycles_per_period(&self) -> u64 {
        self.cpu.ps_to_cycles(self.period)
    }

    /// Take the DSP's events out.
    pub fn drain_events(&mut self) -> Vec<Event> {
        self.events.drain()
    }
}

/// The navigation's state checked after every packet once it has started, with the ranges of the
/// other boards' step rows (`firmware::state_check`, firmware_model/SCHEMA.md "Firmware state
/// checked at every step"): attitude finite, each velocity component within ±1e4 m/s, latitude
/// within (−90°, 90°), longitude finite, height within −1e4 … 1e5 m. Every comparison is false for
/// NaN, so a non-finite value is out of range too. The first packet out of range is one
/// `state_out_of_range` error naming every variable out of range and its value.
pub fn check_state(t_irq: Ps, sequence: u16, nav: &NavOutput) -> Option<Event> {
    use crate::firmware::state_check::{HEIGHT_RANGE_M, LATITUDE_LIMIT_DEG, VELOCITY_LIMIT_M_S};
    let [lat_rad, lon_rad, h] = nav.pos;
    let lat = lat_rad.to_degrees();
    let (h_min, h_max) = HEIGHT_RANGE_M;
    let mut bad: Vec<(f64, f64, String)> = Vec::new();
    if !nav.attitude.iter().all(|a| a.is_finite()) {
        let deg = nav.attitude.map(f64::to_degrees);
        bad.push((f64::NAN, 0.0, format!("roll, pitch, heading {deg:?}° not finite")));
    }
    for (axis, v) in ["east", "north", "up"].iter().zip(nav.vel) {
        let in_range = v.abs() <= VELOCITY_LIMIT_M_S;
        if !in_range {
            bad.push((
                v,
                VELOCITY_LIMIT_M_S,
                format!("velocity {axis} = {v:e} m/s, expected within ±{VELOCITY_LIMIT_M_S:e}"),
            ));
        }
    }
    let lat_in_range = lat.abs() < LATITUDE_LIMIT_DEG;
    if !lat_in_range {
        bad.push((lat, LATITUDE_LIMIT_DEG, format!("latitude = {lat:e}°, expected within ±{LATITUDE_LIMIT_DEG}°")));
    }
    if !lon_rad.is_finite() {
        bad.push((lon_rad, 0.0, format!("longitude = {}°, expected finite", lon_rad.to_degrees())));
    }
    let h_in_range = h >= h_min && h <= h_max;
    if !h_in_range {
        let limit = if h < h_min { h_min } else { h_max };
        bad.push((h, limit, format!("height = {h:e} m, expected {h_min:e} … {h_max:e} m")));
    }
    let (value, limit, _) = bad.first()?;
    let what = bad.iter().map(|b| b.2.as_str()).collect::<Vec<_>>().join("; ");
    Some(Event::rule(
        t_irq,
        "state_out_of_range",
        Severity::Error,
        format!(
            "C6727, packet {sequence} at {:.3} s: the navigation state is out of range: {what}; the output is \
             no navigation solution from here",
            crate::time::ps_to_s(t_irq)
        ),
        *value,
        *limit,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The level formula: exact at the axes, and the claim that f64 meets no subnormal or NaN on
    /// the counts a packet can carry (every combination of the extreme and smallest counts).
    #[test]
    fn tilt_stays_in_normal_doubles() {
        let lsb = adxl345::LSB_G;
        assert_eq!(tilt([0.0, 0.0, 1.0]), [0.0, 0.0]);
        assert_eq!(tilt([-1.0, 0.0, 0.0])[0], std::f64::consts::FRAC_PI_2);
        let counts = [i16::MIN, -1, 0, 1, i16::MAX];
        for a in counts {
            for b in counts {
                for c in counts {
                    let f = [a, b, c].map(|n| f64::from(n) * lsb);
                    let s = f[1] * f[1] + f[2] * f[2];
                    for v in [f[0], f[1], f[2], f[1] * f[1], f[2] * f[2], s, s.sqrt()].into_iter().chain(tilt(f)) {
                        assert!(v == 0.0 || v.is_normal(), "{v} from counts {a}, {b}, {c}");
                    }
                }
            }
        }
    }

    fn nav_at(attitude: [f64; 3], vel: [f64; 3], pos: [f64; 3]) -> NavOutput {
        NavOutput {
            rate: [0.0; 3],
            bridged: [false; 3],
            attitude,
            vel,
            pos,
            compass_update: false,
            gps_update: false,
            fused: None,
        }
    }

    /// The range check: a solution in range passes; each variable out of range (and NaN, ±inf)
    /// is an error naming it.
    #[test]
    fn the_navigation_state_is_checked_for_range() {
        let (lat, lon) = (28.2f64.to_radians(), 112.9f64.to_radians());
        let good = nav_at([0.01, -0.02, 1.0], [19.2, 11.1, 0.1], [lat, lon, 5.0]);
        assert!(check_state(5, 1, &good).is_none());
        let cases = [
            (nav_at([f64::NAN, 0.0, 0.0], good.vel, good.pos), "roll, pitch, heading"),
            (nav_at(good.attitude, [2e4, 0.0, 0.0], good.pos), "velocity east"),
            (nav_at(good.attitude, [0.0, 0.0, f64::NEG_INFINITY], good.pos), "velocity up"),
            (nav_at(good.attitude, good.vel, [1.6, lon, 5.0]), "latitude"),
            (nav_at(good.attitude, good.vel, [lat, f64::INFINITY, 5.0]), "longitude"),
            (nav_at(good.attitude, good.vel, [lat, lon, 2e5]), "height"),
            (nav_at(good.attitude, good.vel, [lat, lon, f64::NAN]), "height"),
        ];
        for (nav, what) in cases {
            let e = check_state(7_000_000_000, 42, &nav).unwrap_or_else(|| panic!("{what} not refused"));
            assert_eq!((e.kind, e.severity, e.t_ps), ("state_out_of_range", Severity::Error, 7_000_000_000));
            assert!(e.message.contains(what) && e.message.contains("packet 42"), "{}", e.message);
        }
    }
}
