//! The one place the attitude algorithms are registered (the trait they implement is in
//! `attitude.rs`): one row of [`algorithms`] each, with the name the profile's `firmware.algorithm`
//! gives it, the line `firmware_model/SCHEMA.md` lists it with (a test holds the schema to the
//! table) and how it is made from the profile's `[firmware]` section.
//!
//! Adding one: a file with a type implementing [`AttitudeUpdate`] (and its `mod` line in
//! `firmware/mod.rs`), then one row here.

use super::attitude::AttitudeUpdate;
use super::dcm::Dcm;
use super::quat::Rk4;
use super::rotvec::RotationVector;
use super::wing::WingUnit;
use crate::error::{Error, Result};
use crate::numerics::Scalar;
use crate::profile;

/// An attitude update made for a profile (an error when the profile's values do not make one).
pub type MadeUpdate<T> = Result<Box<dyn AttitudeUpdate<T>>>;

/// One attitude algorithm of the registry.
pub struct Algorithm<T> {
    /// Its value of `firmware.algorithm`.
    pub name: &'static str,
    /// What `firmware_model/SCHEMA.md` says of it.
    pub doc: &'static str,
    /// The update for the profile's `[firmware]` section and an update period of `step_s` seconds.
    pub make: fn(fw: &profile::Firmware, step_s: f64) -> MadeUpdate<T>,
}

/// The registry: every attitude algorithm, one row each.
pub fn algorithms<T: Scalar>() -> Vec<Algorithm<T>> {
    vec![
        Algorithm {
            name: "rk4",
            doc: "RK4 on the quaternion equation (the reference design; `firmware.quat_derivative`)",
            make: |fw, step_s| Ok(Box::new(Rk4::<T>::new(step_s, fw.quat_derivative))),
        },
        Algorithm {
            name: "rotation-vector",
            doc: "rotation vector with coning correction (`firmware.coning_samples`, `firmware.increment_rule`)",
            make: |fw, step_s| {
                Ok(Box::new(RotationVector::<T>::new(fw.coning_samples as usize, fw.increment_rule, step_s)))
            },
        },
        Algorithm {
            name: "dcm",
            doc: "direction cosine matrix with drift cancellation (`[firmware.dcm]`)",
            make: |fw, step_s| Ok(Box::new(Dcm::<T>::new(&fw.dcm, step_s))),
        },
        Algorithm {
            name: "wing",
            doc: "the wing-angle unit: zero, hinge axis and 12-state filter, α out every update (`firmware.alignment_s`: the zero's time)",
            make: |fw, step_s| Ok(Box::new(WingUnit::<T>::new(step_s, fw.accel_g_m_s2, fw.alignment_s)?)),
        },
    ]
}

/// The registered names, as a profile error lists them: "`rk4`, `rotation-vector`, …".
pub fn algorithm_names() -> String {
    algorithms::<f64>().iter().map(|a| format!("`{}`", a.name)).collect::<Vec<_>>().join(", ")
}

/// The update `firmware.algorithm` names, for an update period of `step_s` seconds.
pub fn attitude_update<T: Scalar>(fw: &profile::Firmware, step_s: f64) -> MadeUpdate<T> {
    match algorithms::<T>().into_iter().find(|a| a.name == fw.algorithm) {
        Some(a) => (a.make)(fw, step_s),
        None => Err(Error::Profile(format!(
            "key `firmware.algorithm` = \"{}\": expected one of {}",
            fw.algorithm,
            algorithm_names()
        ))),
    }
}

/// Samples one update of the profile's algorithm takes (what the schedule gathers).
pub fn samples_per_update(fw: &profile::Firmware) -> Result<usize> {
    Ok(attitude_update::<f64>(fw, 1.0)?.samples_per_update())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `firmware_model/SCHEMA.md` lists `firmware.algorithm`'s values and what each is as the
    /// registry has them, in its order.
    #[test]
    fn the_schema_lists_the_registered_algorithms() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../firmware_model/SCHEMA.md");
        let schema = std::fs::read_to_string(path).unwrap();
        let row = schema.lines().find(|l| l.starts_with("| `firmware.algorithm` |")).expect("a firmware.algorithm row");
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        let described: Vec<String> = algorithms::<f64>().iter().map(|a| format!("`{}`: {}", a.name, a.doc)).collect();
        let want = [
            "",
            "`firmware.algorithm`",
            &algorithm_names(),
            "`rk4`",
            &format!("attitude update: {}", described.join("; ")),
            "",
        ];
        assert_eq!(
            cells, want,
            "firmware_model/SCHEMA.md's row is stale: write it as the registry (firmware/algorithms.rs) has it"
        );
    }

    #[test]
    fn an_unknown_algorithm_is_a_profile_error_naming_the_key_and_the_choices() {
        let fw = profile::Firmware { algorithm: "rk5".into(), ..Default::default() };
        let err = attitude_update::<f64>(&fw, 0.008).unwrap_err().to_string();
        assert!(
            err.contains("key `firmware.algorithm` = \"rk5\": expected one of `rk4`, `rotation-vector`, `dcm`, `wing`"),
            "{err}"
        );
    }
}
