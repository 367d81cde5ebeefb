//! `[faults]`: device-side faults injected into a run (a stuck output, a spike, a CS glitch, a reset,
//! DIAG_STAT flags, a supply out of range). One flat entry shape for every kind, so that a fault fits
//! on one `--set 'faults.list=[{kind="spike", channel="gyro_z", start_s=2.0, magnitude=50.0}]'`;
//! which keys a kind takes is checked here, with errors naming `faults.list[i].key`.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// The faults of a run (none by default: a healthy board).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct Faults {
    /// Fault entries, in any order.
    pub list: Vec<Fault>,
}

/// What goes wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FaultKind {
    /// An output register stops updating (keeps the value it held before `start_s`).
    StuckAxis,
    /// `samples` internal samples of a channel carry `magnitude` more than the filtered value.
    Spike,
    /// The CS line goes high inside a burst (after frame `after_frame`), for `glitch_us` or until
    /// the firmware raises CS itself.
    DroppedBurst,
    /// A software reset (the semantics of GLOB_CMD bit 7) at `start_s`.
    SensorReset,
    /// DIAG_STAT `flags` set by every sample in the window.
    DiagFlags,
    /// The supply is `volts` in the window (SUPPLY_OUT and the DIAG_STAT supply flags follow).
    SupplyOutOfRange,
}

impl FaultKind {
    /// The kind as written in a profile.
    pub fn as_str(self) -> &'static str {
        match self {
            FaultKind::StuckAxis => "stuck_axis",
            FaultKind::Spike => "spike",
            FaultKind::DroppedBurst => "dropped_burst",
            FaultKind::SensorReset => "sensor_reset",
            FaultKind::DiagFlags => "diag_flags",
            FaultKind::SupplyOutOfRange => "supply_out_of_range",
        }
    }
}

/// An output register of the ADIS16407, by the quantity it holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[allow(missing_docs)]
pub enum OutputChannel {
    Supply,
    GyroX,
    GyroY,
    GyroZ,
    AccelX,
    AccelY,
    AccelZ,
    MagX,
    MagY,
    MagZ,
    Baro,
    BaroLow,
    Temp,
    Aux,
}

impl OutputChannel {
    /// Position in the burst's 14 output registers (SUPPLY_OUT = 0 … AUX_ADC = 13).
    pub fn burst_index(self) -> usize {
        self as usize
    }

    /// The channel as written in a profile.
    pub fn as_str(self) -> &'static str {
        [
            "supply", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z", "mag_x", "mag_y", "mag_z", "baro",
            "baro_low", "temp", "aux",
        ][self.burst_index()]
    }
}

/// One fault. `kind` and `start_s` always; the other keys as the kind needs them (SCHEMA.md).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fault {
    /// What goes wrong.
    pub kind: FaultKind,
    /// Virtual time the fault starts, s since power-on.
    pub start_s: f64,
    /// Length of the fault window, s (omitted: to the end of the run; `dropped_burst`: 0, one burst).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration_s: Option<f64>,
    /// Output register affected (`stuck_axis`, `spike`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub channel: Option<OutputChannel>,
    /// Spike size in the channel's units (°/s, g, gauss, mbar, °C, V), added to the filtered value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub magnitude: Option<f64>,
    /// Internal samples a spike lasts (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<u32>,
    /// Burst frame after which CS rises, 0…13 (0: after the command frame; default 3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub after_frame: Option<u32>,
    /// How long CS stays high, µs (omitted: until the firmware raises CS at the end of the burst).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub glitch_us: Option<f64>,
    /// DIAG_STAT bits to set (16-bit mask, not 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flags: Option<u32>,
    /// Supply voltage during the window, V.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub volts: Option<f64>,
}

/// Default burst frame after which a dropped burst's CS rises: frame 3 (YGYRO_OUT), so ZGYRO_OUT and
/// everything after it (the accelerometers included) are lost: a glitch the attitude feels.
pub const DEFAULT_AFTER_FRAME: u32 = 3;

impl Fault {
    /// Every key present in this entry, to reject the ones its kind does not take.
    fn present(&self) -> [(&'static str, bool); 8] {
        [
            ("duration_s", self.duration_s.is_some()),
            ("channel", self.channel.is_some()),
            ("magnitude", self.magnitude.is_some()),
            ("samples", self.samples.is_some()),
            ("after_frame", self.after_frame.is_some()),
            ("glitch_us", self.glitch_us.is_some()),
            ("flags", self.flags.is_some()),
            ("volts", self.volts.is_some()),
        ]
    }

    /// The keys a kind takes (besides `kind` and `start_s`) and which of them are required.
    fn keys(kind: FaultKind) -> (&'static [&'static str], &'static [&'static str]) {
        match kind {
            FaultKind::StuckAxis => (&["duration_s", "channel"], &["channel"]),
            FaultKind::Spike => (&["channel", "magnitude", "samples"], &["channel", "magnitude"]),
            FaultKind::DroppedBurst => (&["duration_s", "after_frame", "glitch_us"], &[]),
            FaultKind::SensorReset => (&[], &[]),
            FaultKind::DiagFlags => (&["duration_s", "flags"], &["flags"]),
            FaultKind::SupplyOutOfRange => (&["duration_s", "volts"], &["volts"]),
        }
    }

    fn validate(&self, i: usize) -> Result<()> {
        let key = |k: &str| format!("faults.list[{i}].{k}");
        let bad = |k: &str, v: &dyn std::fmt::Display, expected: &str| {
            Error::Profile(format!("key `{}` = {v}: expected {expected}", key(k)))
        };
        let kind = self.kind.as_str();
        let (allowed, required) = Fault::keys(self.kind);
        for (k, present) in self.present() {
            if present && !allowed.contains(&k) {
                let takes = if allowed.is_empty() { "none".to_string() } else { allowed.join(", ") };
                return Err(Error::Profile(format!(
                    "key `{}`: a `{kind}` fault does not take `{k}` (its keys besides kind and start_s: {takes})",
                    key(k)
                )));
            }
        }
        for k in required {
            if !self.present().iter().any(|(name, present)| name == k && *present) {
                return Err(Error::Profile(format!("key `{}` is missing: a `{kind}` fault needs it", key(k))));
            }
        }
        if !(self.start_s.is_finite() && self.start_s >= 0.0) {
            return Err(bad("start_s", &self.start_s, "a finite time ≥ 0 s"));
        }
        if let Some(d) = self.duration_s {
            let ok = d.is_finite() && if self.kind == FaultKind::DroppedBurst { d >= 0.0 } else { d > 0.0 };
            if !ok {
                let want =
                    if self.kind == FaultKind::DroppedBurst { "a finite time ≥ 0 s" } else { "a finite time > 0 s" };
                return Err(bad("duration_s", &d, want));
            }
        }
        if let Some(m) = self.magnitude {
            if !m.is_finite() {
                return Err(bad("magnitude", &m, "a finite value in the channel's units"));
            }
        }
        if let Some(n) = self.samples {
            if n == 0 {
                return Err(bad("samples", &n, "at least 1 internal sample"));
            }
        }
        if let Some(f) = self.after_frame {
            if f > 13 {
                return Err(bad("after_frame", &f, "a burst frame 0…13 (CS rises after it; 14 is the last)"));
            }
        }
        if let Some(g) = self.glitch_us {
            if !(g.is_finite() && g >= 0.0) {
                return Err(bad("glitch_us", &g, "a finite time ≥ 0 µs"));
            }
        }
        if let Some(f) = self.flags {
            if f == 0 || f > 0xFFFF {
                return Err(bad("flags", &format!("0x{f:X}"), "a non-zero 16-bit DIAG_STAT mask (0x0001…0xFFFF)"));
            }
        }
        if let Some(v) = self.volts {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad("volts", &v, "a finite voltage ≥ 0 V"));
            }
        }
        Ok(())
    }

    /// The end of the fault window, s (infinite when the fault lasts to the end of the run).
    pub fn end_s(&self) -> f64 {
        self.start_s + self.duration_s.unwrap_or(f64::INFINITY)
    }
}

impl Faults {
    pub(crate) fn validate(&self) -> Result<()> {
        self.list.iter().enumerate().try_for_each(|(i, f)| f.validate(i))
    }

    /// Whether any fault acts on the device model (every kind but `dropped_burst`, a bus fault).
    pub fn any_in_device(&self) -> bool {
        self.list.iter().any(|f| f.kind != FaultKind::DroppedBurst)
    }
}

#[cfg(test)]
mod tests {
    use crate::profile::Profile;

    fn with(set: &str) -> crate::Result<Profile> {
        Profile::from_toml("", "t", &[format!("faults.list={set}")])
    }

    #[test]
    fn a_set_override_gives_a_fault_list() {
        let p = with(r#"[{kind="stuck_axis", channel="gyro_x", start_s=2.0, duration_s=1.0}]"#).unwrap();
        let f = &p.faults.list[0];
        assert_eq!(
            (f.kind, f.channel, f.start_s, f.duration_s),
            (super::FaultKind::StuckAxis, Some(super::OutputChannel::GyroX), 2.0, Some(1.0))
        );
        // And back through TOML (what the Python side reads).
        let back = Profile::from_toml(&p.to_toml(), "round", &[]).unwrap();
        assert_eq!(back, p);
    }

    #[test]
    fn errors_name_the_entry_and_the_key() {
        let m = |s: &str| with(s).unwrap_err().to_string();
        let e = m(r#"[{kind="spike", channel="gyro_x", start_s=1.0}]"#);
        assert!(e.contains("faults.list[0].magnitude") && e.contains("missing"), "{e}");
        let e = m(r#"[{kind="sensor_reset", start_s=1.0}, {kind="diag_flags", start_s=1.0, flags=0}]"#);
        assert!(e.contains("faults.list[1].flags") && e.contains("non-zero"), "{e}");
        let e = m(r#"[{kind="sensor_reset", start_s=1.0, volts=4.0}]"#);
        assert!(e.contains("faults.list[0].volts") && e.contains("does not take"), "{e}");
        let e = m(r#"[{kind="stuck", start_s=1.0}]"#);
        assert!(e.contains("faults.list[0]") && e.contains("stuck_axis"), "{e}");
        let e = m(r#"[{kind="stuck_axis", channel="gyro_w", start_s=1.0}]"#);
        assert!(e.contains("faults.list[0]") && e.contains("gyro_x"), "{e}");
        let e = m(r#"[{kind="sensor_reset", start_s=-1.0}]"#);
        assert!(e.contains("faults.list[0].start_s"), "{e}");
        let e = m(r#"[{kind="dropped_burst", start_s=1.0, after_frame=14}]"#);
        assert!(e.contains("faults.list[0].after_frame") && e.contains("0…13"), "{e}");
        let e = m(r#"[{kind="sensor_reset", start_s=1.0, tick=3}]"#);
        assert!(e.contains("faults.list[0]") && e.contains("tick"), "{e}");
    }

    #[test]
    fn no_faults_by_default() {
        assert!(Profile::default().faults.list.is_empty());
    }
}
