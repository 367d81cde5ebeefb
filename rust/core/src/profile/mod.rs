//! Board and firmware profiles. A profile is TOML data (`firmware_model/*.toml`) describing the
//! board as registers and parameters, and the firmware as choices (schedule, decode, algorithm,
//! numeric backend). Every key is documented in `firmware_model/SCHEMA.md`; `key=value` overrides
//! change one field for one run. Unknown keys are errors with a "did you mean".

mod board;
mod faults;
mod geomag;
mod sections;
mod serial;

pub use board::{
    link_kind, link_kinds, link_names, Board, BoardDevice, BoxedLink, Devices, I2cBus, LinkKind, Placed, SciPort,
    Section, SENSOR_CHIP_SELECT,
};
pub use faults::*;
pub use geomag::{AxisCal, Geomag};
pub use sections::*;
pub use serial::{Serial, SerialRx};

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// A whole profile: the board (clocks, SPI-A, timer, device, sensor errors), the firmware, and the
/// faults injected into a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct Profile {
    /// Name and description.
    pub meta: Meta,
    /// F28335 clock tree.
    pub clocks: Clocks,
    /// F28335 SPI-A register values and bus level.
    pub spi: Spi,
    /// Which part sits on which link (`[[board.devices]]`).
    pub board: Board,
    /// CPU timer 0.
    pub timer: Timer,
    /// The ADIS16407.
    pub device: Device,
    /// Sensor error model applied inside the device.
    pub errors: Errors,
    /// Firmware choices.
    pub firmware: Firmware,
    /// Navigation initial state and earth model.
    pub navigation: Navigation,
    /// IQmath Q formats per quantity class.
    pub iq: IqFormats,
    /// Compute-time model settings.
    pub timing: Timing,
    /// Device-side faults injected into the run (none by default).
    pub faults: Faults,
    /// The geomagnetic–gyro board's front end and firmware constants (`firmware.application =
    /// "ads8344-geomag"`; absent on the other boards).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub geomag: Option<Geomag>,
    /// What arrives on the SCI ports from outside (`[serial.sci_b]`: a GPS's NMEA file); none by
    /// default.
    #[serde(skip_serializing_if = "Serial::is_default")]
    pub serial: Serial,
}

impl Profile {
    /// Parse a profile from TOML text, apply `key=value` overrides, and validate.
    /// `source` names the file in error messages.
    pub fn from_toml(text: &str, source: &str, overrides: &[String]) -> Result<Profile> {
        let mut table: toml::Table =
            text.parse().map_err(|e: toml::de::Error| Error::Profile(format!("{source}: {}", e.to_string().trim())))?;
        for ov in overrides {
            apply_override(&mut table, ov)?;
        }
        apply_gyro_range(&mut table).map_err(|e| match e {
            Error::Profile(m) => Error::Profile(format!("{source}: {m}")),
            other => other,
        })?;
        // A board with a schema of its own (`meta.board`, e.g. the gyro-free board's gfsins.toml) is
        // not an F28335 profile: say so rather than list its keys as unknown.
        if let Some(board) = table.get("meta").and_then(|m| m.get("board")).and_then(|b| b.as_str()) {
            return Err(Error::Profile(format!(
                "{source}: key `meta.board` = \"{board}\": a board with a schema of its own; `board`, \
                 `budget`, `run` and `replay` take it, this command takes an F28335 profile (without \
                 `meta.board`)"
            )));
        }
        fill_part_defaults(&mut table);
        check_keys(&table, source)?;
        let de = toml::Value::Table(table);
        let profile: Profile = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.inner().to_string();
            // serde's message ends by naming the key again; it is already named up front.
            let inner = inner.trim().trim_end_matches(&format!("in `{path}`")).trim_end().to_string();
            Error::Profile(format!("{source}: key `{path}`: {inner}"))
        })?;
        profile.validate().map_err(|e| match e {
            Error::Profile(m) => Error::Profile(format!("{source}: {m}")),
            other => other,
        })?;
        Ok(profile)
    }

    /// The reference profile's defaults (what `Profile::default()` holds) as TOML text.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }

    /// Every key a profile may hold, dotted (`spi.spibrr`), in schema order.
    pub fn known_keys() -> Vec<String> {
        let value = toml::Value::try_from(Profile::default()).unwrap_or(toml::Value::Table(Default::default()));
        let mut keys = Vec::new();
        flatten_keys(&value, "", &mut keys);
        // The link kinds' sections, absent from the defaults' text (the reference profile stays as it is).
        keys.extend(Board::section_keys());
        keys.push("firmware.application".into());
        keys.extend(Serial::keys());
        keys.push("firmware.gpio_at_start".into());
        keys.push("firmware.wing.gyro_bias_tempco_dps_per_c".into());
        keys.push("spi.ste_pulse_between_words".into());
        // Its optional keys too (absent from the defaults' text).
        if let Ok(v) = toml::Value::try_from(Geomag {
            gyro_delay_s: Some(0.0),
            launch_elevation_deg: Some(0.0),
            launch_azimuth_deg: Some(0.0),
            aid_axis_gate_deg: Some(0.0),
            ..Geomag::default()
        }) {
            flatten_keys(&v, "geomag", &mut keys);
        }
        keys
    }

    /// Check every value against what the hardware and the firmware allow.
    pub fn validate(&self) -> Result<()> {
        self.clocks.validate()?;
        self.spi.validate()?;
        self.board.validate(self)?;
        self.board.validate_spi(&self.spi)?;
        self.timer.validate()?;
        self.device.validate()?;
        self.device.validate_power_on_sens_avg()?;
        self.errors.validate()?;
        self.firmware.validate()?;
        self.navigation.validate()?;
        self.iq.validate()?;
        self.timing.validate()?;
        self.faults.validate()?;
        if let Some(g) = &self.geomag {
            g.validate()?;
        }
        self.serial.validate()?;
        Ok(())
    }
}

fn flatten_keys(v: &toml::Value, prefix: &str, out: &mut Vec<String>) {
    if let toml::Value::Table(t) = v {
        for (k, sub) in t {
            let key = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
            match sub {
                toml::Value::Table(_) => flatten_keys(sub, &key, out),
                _ => out.push(key),
            }
        }
    }
}

/// Reject unknown keys with the closest known key as a hint.
fn check_keys(table: &toml::Table, source: &str) -> Result<()> {
    let known = Profile::known_keys();
    let mut present = Vec::new();
    flatten_keys(&toml::Value::Table(table.clone()), "", &mut present);
    for key in present {
        if known.contains(&key) {
            continue;
        }
        // A known section holding a table-valued key (e.g. an inline table) is also fine.
        if known.iter().any(|k| k.starts_with(&format!("{key}."))) {
            continue;
        }
        let hint = known
            .iter()
            .map(|k| (strsim::levenshtein(k, &key), k))
            .min()
            .filter(|(d, _)| *d <= 4)
            .map(|(_, k)| format!("; did you mean `{k}`?"))
            .unwrap_or_default();
        return Err(Error::Profile(format!("{source}: unknown key `{key}`{hint}")));
    }
    Ok(())
}

/// Apply one `a.b.c=value` override. The value is parsed as a TOML value (`49`, `0x31`, `true`,
/// `"rk4"`, `[0, 0, 0]`); anything that does not parse is taken as a string (`numeric=iq`).
pub fn apply_override(table: &mut toml::Table, ov: &str) -> Result<()> {
    let (key, raw) =
        ov.split_once('=').ok_or_else(|| Error::Profile(format!("override `{ov}`: expected key=value")))?;
    let key = key.trim();
    let raw = raw.trim();
    if key.is_empty() {
        return Err(Error::Profile(format!("override `{ov}`: empty key")));
    }
    let value = parse_value(raw).ok_or_else(|| {
        Error::Profile(format!(
            "override `{}`: the value runs over a line break into more text; expected one value \
             (give each override its own key=value)",
            ov.escape_debug()
        ))
    })?;
    let parts: Vec<&str> = key.split('.').collect();
    let mut cur = table;
    for p in &parts[..parts.len() - 1] {
        let entry = cur.entry(p.to_string()).or_insert_with(|| toml::Value::Table(Default::default()));
        cur = match entry {
            toml::Value::Table(t) => t,
            _ => return Err(Error::Profile(format!("override `{ov}`: `{p}` is not a section"))),
        };
    }
    cur.insert(parts[parts.len() - 1].to_string(), value);
    Ok(())
}

/// The TOML value of an override (a bare word is a string); None when the text is more than one
/// value: a line break followed by more (`9\nkey = 1`), which TOML would read as further keys.
fn parse_value(raw: &str) -> Option<toml::Value> {
    let doc = format!("v = {raw}");
    match doc.parse::<toml::Table>() {
        Ok(mut t) => {
            let v = t.remove("v");
            if t.is_empty() {
                v
            } else {
                None
            }
        }
        Err(_) if raw.contains(['\n', '\r']) => None,
        Err(_) => Some(toml::Value::String(raw.to_string())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_round_trips_through_toml() {
        let p = Profile::default();
        let text = p.to_toml();
        let back = Profile::from_toml(&text, "default", &[]).unwrap();
        assert_eq!(p, back);
    }

    #[test]
    fn override_changes_one_field() {
        let p = Profile::from_toml("", "empty", &["spi.spibrr=9".into(), "firmware.numeric=iq".into()]).unwrap();
        assert_eq!(p.spi.spibrr, 9);
        assert_eq!(p.firmware.numeric, Numeric::Iq);
        for n in Numeric::ALL {
            let p = Profile::from_toml("", "empty", &[format!("firmware.numeric=\"{}\"", n.name())]).unwrap();
            assert_eq!(p.firmware.numeric, n, "{}", n.name());
        }
    }

    #[test]
    fn unknown_key_has_a_hint() {
        let e = Profile::from_toml("[spi]\nspibr = 3\n", "x.toml", &[]).unwrap_err();
        let m = e.to_string();
        assert!(m.contains("x.toml") && m.contains("spi.spibr") && m.contains("did you mean `spi.spibrr`"), "{m}");
    }

    #[test]
    fn wrong_type_names_key() {
        let e = Profile::from_toml("[spi]\nspibrr = \"fast\"\n", "x.toml", &[]).unwrap_err();
        assert!(e.to_string().contains("spi.spibrr"), "{e}");
    }

    #[test]
    fn unknown_variant_lists_allowed() {
        // (`firmware.algorithm` is a name the firmware's registry looks up: `firmware::algorithms`.)
        let e = Profile::from_toml("", "x", &["firmware.numeric=f16".into()]).unwrap_err();
        let m = e.to_string();
        assert!(m.contains("firmware.numeric") && m.contains("c28x-f32"), "{m}");
    }

    #[test]
    fn out_of_range_register_is_rejected() {
        let e = Profile::from_toml("", "x", &["spi.spibrr=200".into()]).unwrap_err();
        assert!(e.to_string().contains("spi.spibrr") && e.to_string().contains("127"), "{e}");
        let e = Profile::from_toml("", "x", &["timer.period_us=0".into()]).unwrap_err();
        assert!(e.to_string().contains("timer.period_us"), "{e}");
    }

    fn rejected(overrides: &[&str]) -> String {
        let ov: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        Profile::from_toml("", "x.toml", &ov).unwrap_err().to_string()
    }

    #[test]
    fn an_override_running_over_a_line_break_is_refused_not_cut() {
        for ov in ["spi.spibrr=9\nspi.spibrr=300", "firmware.numeric=iq\nrest", "timer.period_us=8000\r\nx=1"] {
            let m = rejected(&[ov]);
            assert!(m.contains("line break") && m.contains("override `"), "{m}");
        }
        // One value written over several lines is still one value.
        let p = Profile::from_toml("", "x", &["navigation.velocity_enu=[0.0,\n 0.0,\n 0.0]".into()]).unwrap();
        assert_eq!(p.navigation.velocity_enu, [0.0; 3]);
    }

    #[test]
    fn contradictions_name_both_keys() {
        let m = rejected(&["firmware.initial_attitude=level", "firmware.alignment_s=0"]);
        assert!(m.contains("firmware.alignment_s") && m.contains("firmware.initial_attitude"), "{m}");
        // With the published Q = [1, 0, 0, 0] start the still period is not used.
        assert!(Profile::from_toml("", "x", &["firmware.alignment_s=0".into()]).is_ok());
        let m = rejected(&["device.sclk_burst_max_hz=3e6"]);
        assert!(m.contains("device.sclk_burst_max_hz") && m.contains("device.sclk_max_hz"), "{m}");
        let m = rejected(&["clocks.crystal_hz=35000000"]);
        assert!(m.contains("clocks.crystal_hz") && m.contains("clocks.divsel") && m.contains("175 MHz"), "{m}");
        assert!(Profile::from_toml("", "x", &["clocks.pllcr=0".into(), "clocks.divsel=1".into()]).is_ok());
    }

    #[test]
    fn gyro_range_dps_writes_sens_avg_range_bits() {
        let sens = |ov: &[&str]| {
            let ov: Vec<String> = ov.iter().map(|s| s.to_string()).collect();
            Profile::from_toml("", "x", &ov).map(|p| p.device.sens_avg)
        };
        // M raised to the range's minimum (4 with ±75), as the part does on a write.
        assert_eq!(sens(&["device.gyro_range_dps=75"]).unwrap(), 0x0104);
        assert_eq!(sens(&["device.gyro_range_dps=150"]).unwrap(), 0x0202);
        assert_eq!(sens(&["device.gyro_range_dps=300.0"]).unwrap(), 0x0402);
        // A larger M is kept; the range bits are the alias's.
        assert_eq!(sens(&["device.sens_avg=0x0406", "device.gyro_range_dps=75"]).unwrap(), 0x0106);
        let m = rejected(&["device.gyro_range_dps=100"]);
        assert!(m.contains("device.gyro_range_dps") && m.contains("75, 150 or 300"), "{m}");
        let m = rejected(&["firmware.gyro_range_dps=120"]);
        assert!(m.contains("firmware.gyro_range_dps") && m.contains("75, 150 or 300"), "{m}");
    }

    #[test]
    fn sens_avg_the_part_cannot_hold_is_rejected() {
        // ±75 °/s needs M ≥ 4, ±150 °/s M ≥ 2 (the device model's minimums): the message says what to write.
        let m = rejected(&["device.sens_avg=0x0102"]);
        assert!(m.contains("device.sens_avg") && m.contains("M = 2") && m.contains("0x0104"), "{m}");
        let m = rejected(&["device.sens_avg=0x0201"]);
        assert!(m.contains("±150") && m.contains("0x0202"), "{m}");
        for ok in ["0x0104", "0x0202", "0x0400"] {
            assert!(Profile::from_toml("", "x", &[format!("device.sens_avg={ok}")]).is_ok(), "{ok}");
        }
        let m = rejected(&["device.smpl_prd=0x0101"]);
        assert!(m.contains("device.smpl_prd") && m.contains("0x00FF"), "{m}");
    }

    #[test]
    fn extreme_integers_are_errors_not_overflows() {
        let m = rejected(&["device.clock_ppb=-9223372036854775808"]);
        assert!(m.contains("device.clock_ppb"), "{m}");
        let m = rejected(&["spi.spibrr=-1"]);
        assert!(m.contains("spi.spibrr"), "{m}");
        let m = rejected(&["clocks.crystal_hz=18446744073709551615"]);
        assert!(m.contains("clocks.crystal_hz"), "{m}");
    }
}

#[cfg(test)]
mod reference_file {
    use super::*;

    /// The reference profile file and the code's defaults describe the same board.
    #[test]
    fn reference_toml_equals_defaults() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../firmware_model/reference.toml");
        let text = std::fs::read_to_string(path).unwrap();
        let p = Profile::from_toml(&text, "reference.toml", &[]).unwrap();
        assert_eq!(p, Profile::default());
    }
}

#[cfg(test)]
mod prop_tests;
