//! `[geomag]`: the geomagnetic–gyro board's analogue front end and its firmware's constants
//! (`firmware.application = "ads8344-geomag"`; algorithms.md §1). The ADS8344's channels
//! (single-ended against COM): CH0–CH2 the gyro's x, y, z; CH3–CH5 the magnetometer's x, y, z;
//! CH6 the board temperature sensor (0.5 V + 10 mV/°C); CH7 spare, wired to VREF/2 as a
//! ratiometric check (`device::analog::FrontEnd`).

use super::sections::bad;
use crate::error::Result;
use serde::{Deserialize, Serialize};

/// The board's front end and the firmware's constants.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Geomag {
    /// The spin-axis (x) gyro's preset (`device::analog::GyroPreset`): `spin1200` or `adxrs300`.
    pub gyro_x: String,
    /// The cross-axis (y, z) gyros' preset.
    pub gyro_yz: String,
    /// The magnetometer's preset: `amr`.
    pub magnetometer: String,
    /// Sensors without their unit errors and noise (the presets' sensitivities, ranges and
    /// bandwidths kept); the unit's errors are drawn from `errors.seed` otherwise.
    pub ideal_sensors: bool,
    /// The ADC's reference, V.
    pub vref_v: f64,
    /// The earth's field the firmware expects, navigation frame east-north-up, gauss (the aid
    /// compares the measured field with it).
    pub field_enu_gauss: [f64; 3],
    /// Roll aid proportional gain K_p, 1/s.
    pub aid_kp: f64,
    /// Roll aid integral gain K_i, 1/s².
    pub aid_ki: f64,
    /// The aid runs while the expected field across the spin axis exceeds this, gauss.
    pub aid_gate_gauss: f64,
    /// The magnetometer chain's bandwidth the firmware compensates the lag of, Hz (0: none).
    pub mag_cutoff_hz: f64,
    /// The cross-axis (y, z) gyro chain's first-order bandwidth the firmware compensates on a
    /// spinning body, Hz (0: none; `Spin::with_cross_lag`: the nav-fixed cross rates come through
    /// turned by atan(ω/ω_c) about the spin axis).
    pub cross_gyro_cutoff_hz: f64,
    /// The spin gyro chain's group delay τ_g the firmware compensates, s (`Spin::with_gyro_delay`;
    /// 2ζ/ω_n of a second-order preset, `LowPass::group_delay_s`); none: not compensated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gyro_delay_s: Option<f64>,
    /// The gyro calibration table, x, y, z (the firmware inverts the sensor law with it).
    pub calibration: [AxisCal; 3],
    /// The launch's elevation, degrees (−90 … 90): when set, the firmware starts with the spin axis
    /// at this pitch and `launch_azimuth_deg` (roll 0), the launcher's setting handed to the fuze
    /// before firing; unset, it starts level at `firmware.initial_yaw_deg`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub launch_elevation_deg: Option<f64>,
    /// The launch's azimuth, degrees clockwise from north (with `launch_elevation_deg`; 0 when unset).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub launch_azimuth_deg: Option<f64>,
    /// The aid's axis check, degrees: the angle between the spin axis and the field that the
    /// magnetometer measures (its component along the axis against the whole) is compared with the
    /// angle the propagated attitude expects; while they differ by more than this the roll aid holds
    /// its integral (event `mag_aid_axis` on each change; back on below half of it). A wrong axis
    /// turns the field's expected direction across the axis, so the aid would steer the roll by
    /// that error (× cot of the axis–field angle). Unset: no check.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub aid_axis_gate_deg: Option<f64>,
}

/// One gyro axis's calibration row.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisCal {
    /// Bias at the reference temperature, °/s.
    pub bias_dps: f64,
    /// Bias temperature coefficient, °/s per °C.
    pub bias_temp_dps_per_c: f64,
    /// Reference temperature, °C.
    pub ref_temp_c: f64,
    /// Scale-factor error δk (measured = (1 + δk)·true).
    pub scale_error: f64,
    /// Nonlinearity k₂ (bow at full scale, fraction of FS).
    pub nonlinearity: f64,
    /// Full scale, °/s.
    pub full_scale_dps: f64,
}

impl AxisCal {
    /// A nominal row: no bias, no scale error, no bow, full scale `fs`.
    pub fn nominal(full_scale_dps: f64) -> AxisCal {
        AxisCal {
            bias_dps: 0.0,
            bias_temp_dps_per_c: 0.0,
            ref_temp_c: 25.0,
            scale_error: 0.0,
            nonlinearity: 0.0,
            full_scale_dps,
        }
    }
}

impl Default for Geomag {
    /// The board of `firmware_model/geomag.toml` without its field: the aid's gains of the issue-21
    /// tests (K_p 2/s, K_i 1/s², gate 0.05 gauss), nominal calibration.
    fn default() -> Self {
        Geomag {
            gyro_x: "spin1200".into(),
            gyro_yz: "adxrs300".into(),
            magnetometer: "amr".into(),
            ideal_sensors: false,
            vref_v: 5.0,
            field_enu_gauss: [0.0, 0.0, 0.0],
            aid_kp: 2.0,
            aid_ki: 1.0,
            aid_gate_gauss: 0.05,
            mag_cutoff_hz: 0.0,
            cross_gyro_cutoff_hz: 0.0,
            gyro_delay_s: None,
            calibration: [AxisCal::nominal(1200.0), AxisCal::nominal(300.0), AxisCal::nominal(300.0)],
            launch_elevation_deg: None,
            launch_azimuth_deg: None,
            aid_axis_gate_deg: None,
        }
    }
}

impl Geomag {
    pub(crate) fn validate(&self) -> Result<()> {
        if !(self.vref_v.is_finite() && (0.1..=5.0).contains(&self.vref_v)) {
            return Err(bad("geomag.vref_v", self.vref_v, "0.1 … 5 V (ads8344.md)"));
        }
        for (k, v) in [("aid_kp", self.aid_kp), ("aid_ki", self.aid_ki), ("aid_gate_gauss", self.aid_gate_gauss)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(&format!("geomag.{k}"), v, "a finite number ≥ 0"));
            }
        }
        if !(self.mag_cutoff_hz.is_finite() && self.mag_cutoff_hz >= 0.0) {
            return Err(bad("geomag.mag_cutoff_hz", self.mag_cutoff_hz, "a bandwidth ≥ 0 Hz (0: no compensation)"));
        }
        if !(self.cross_gyro_cutoff_hz.is_finite() && self.cross_gyro_cutoff_hz >= 0.0) {
            return Err(bad(
                "geomag.cross_gyro_cutoff_hz",
                self.cross_gyro_cutoff_hz,
                "a bandwidth ≥ 0 Hz (0: no compensation; adxrs300: 40)",
            ));
        }
        if let Some(tau) = self.gyro_delay_s.filter(|t| !(t.is_finite() && (0.0..=0.1).contains(t))) {
            return Err(bad(
                "geomag.gyro_delay_s",
                tau,
                "a group delay of 0 … 0.1 s (τ_g = 2ζ/ω_n of the gyro preset: 2.228e-3 s for spin1200)",
            ));
        }
        if let Some(e) = self.launch_elevation_deg.filter(|e| !(e.is_finite() && (-90.0..=90.0).contains(e))) {
            return Err(bad("geomag.launch_elevation_deg", e, "an elevation of −90 … 90 degrees"));
        }
        if let Some(a) = self.launch_azimuth_deg {
            if !(a.is_finite() && (-360.0..=360.0).contains(&a)) {
                return Err(bad(
                    "geomag.launch_azimuth_deg",
                    a,
                    "an azimuth of −360 … 360 degrees clockwise from north",
                ));
            }
            if self.launch_elevation_deg.is_none() {
                return Err(bad(
                    "geomag.launch_azimuth_deg",
                    a,
                    "set together with geomag.launch_elevation_deg (the launch's direction)",
                ));
            }
        }
        if let Some(g) = self.aid_axis_gate_deg.filter(|g| !(g.is_finite() && *g > 0.0 && *g <= 90.0)) {
            return Err(bad("geomag.aid_axis_gate_deg", g, "an angle of more than 0 and at most 90 degrees"));
        }
        if !self.field_enu_gauss.iter().all(|x| x.is_finite() && x.abs() <= 1.0) {
            return Err(bad("geomag.field_enu_gauss", format!("{:?}", self.field_enu_gauss), "|B| ≤ 1 gauss per axis"));
        }
        for (i, c) in self.calibration.iter().enumerate() {
            let ok = [c.bias_dps, c.bias_temp_dps_per_c, c.ref_temp_c, c.nonlinearity].iter().all(|x| x.is_finite())
                && c.scale_error > -0.5
                && c.scale_error < 0.5
                && c.full_scale_dps > 0.0;
            if !ok {
                return Err(bad(
                    &format!("geomag.calibration[{i}]"),
                    format!("{c:?}"),
                    "finite values, |scale_error| < 0.5, full_scale_dps > 0",
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::profile::Profile;

    /// `geomag.gyro_delay_s` is optional (none by default), set by the file or an override, and a
    /// value outside 0…0.1 s is refused naming the key.
    #[test]
    fn gyro_delay_is_an_optional_key() {
        let text =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../firmware_model/geomag.toml")).unwrap();
        let p = Profile::from_toml(&text, "geomag.toml", &[]).unwrap();
        assert_eq!(p.geomag.unwrap().gyro_delay_s, None);
        let p = Profile::from_toml(&text, "geomag.toml", &["geomag.gyro_delay_s=2.228e-3".into()]).unwrap();
        assert_eq!(p.geomag.unwrap().gyro_delay_s, Some(2.228e-3));
        let e = Profile::from_toml(&text, "geomag.toml", &["geomag.gyro_delay_s=-1.0".into()]).unwrap_err();
        assert!(e.to_string().contains("key `geomag.gyro_delay_s` = -1"), "{e}");
    }
}
