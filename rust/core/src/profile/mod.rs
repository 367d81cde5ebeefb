//! Board and firmware profiles. A profile is TOML data (`firmware_model/*.toml`) describing the
//! board as registers and parameters, and the firmware as choices (schedule, decode, algorithm,
//! numeric backend). Every key is documented in `firmware_model/SCHEMA.md`; `key=value` overrides
//! change one field for one run. Unknown keys are errors with a "did you mean".

mod faults;
mod sections;

pub use faults::*;
pub use sections::*;

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
        check_keys(&table, source)?;
        let de = toml::Value::Table(table);
        let profile: Profile = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            Error::Profile(format!("{source}: key `{path}`: {}", e.inner().to_string().trim()))
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
        keys
    }

    /// Check every value against what the hardware and the firmware allow.
    pub fn validate(&self) -> Result<()> {
        self.clocks.validate()?;
        self.spi.validate()?;
        self.timer.validate()?;
        self.device.validate()?;
        self.errors.validate()?;
        self.firmware.validate()?;
        self.navigation.validate()?;
        self.iq.validate()?;
        self.timing.validate()?;
        self.faults.validate()?;
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
    let value = parse_value(raw);
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

fn parse_value(raw: &str) -> toml::Value {
    let doc = format!("v = {raw}");
    match doc.parse::<toml::Table>() {
        Ok(mut t) => t.remove("v").unwrap_or(toml::Value::String(raw.to_string())),
        Err(_) => toml::Value::String(raw.to_string()),
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
        let e = Profile::from_toml("", "x", &["firmware.algorithm=rk5".into()]).unwrap_err();
        let m = e.to_string();
        assert!(m.contains("firmware.algorithm") && m.contains("rk4"), "{m}");
    }

    #[test]
    fn out_of_range_register_is_rejected() {
        let e = Profile::from_toml("", "x", &["spi.spibrr=200".into()]).unwrap_err();
        assert!(e.to_string().contains("spi.spibrr") && e.to_string().contains("127"), "{e}");
        let e = Profile::from_toml("", "x", &["timer.period_us=0".into()]).unwrap_err();
        assert!(e.to_string().contains("timer.period_us"), "{e}");
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
