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

use crate::output::CycleRow;

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
                format!("velocity {axis} = {v:e} m/s, expected within ±{VELOCITY_LIMIT_M_S:e}"),
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
            format!("height = {h:e} m, expected {h_min:e} … {h_max:e} m (the vertical channel has run away)"),
        ));
    }
    let what = bad.iter().map(|b| b.2.as_str()).collect::<Vec<_>>().join("; ");
    let (value, limit) = bad.first().map_or((f64::NAN, 0.0), |b| (b.0, b.1));
    (value, limit, what)
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
