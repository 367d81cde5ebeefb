//! The one place the attitude algorithms are registered (the trait they implement is in
//! `attitude.rs`): one row of [`algorithms`] each, with the name the profile's `firmware.algorithm`
//! gives it, the line `firmware_model/SCHEMA.md` lists it with (a test holds the schema to the
//! table) and how it is made from the profile's `[firmware]` section.
//!
//! Adding one: a file with a type implementing [`AttitudeUpdate`] (and its `mod` line in
//! `firmware/mod.rs`), then one row here.

use super::attitude::{AttitudeUpdate, StepInputs};
use super::dcm::{attitude_from_acc_mag, quat_from_dcm, Dcm};
use super::quat::{dcm, Rk4};
use super::rotvec::RotationVector;
use super::vqf::Vqf;
use super::wing::WingUnit;
use super::{Mat3, Quat, Vec3};
use crate::error::{Error, Result};
use crate::numerics::{QClass, Scalar};
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
            doc: "direction cosine matrix with drift cancellation (`[firmware.dcm]`, `[firmware.mag_gate]`)",
            make: |fw, step_s| Ok(Box::new(Dcm::<T>::with_gate(&fw.dcm, &fw.mag_gate, fw.accel_g_m_s2, step_s))),
        },
        Algorithm {
            name: "vqf",
            doc: "VQF-class filter: strapdown, accelerometer low-pass in an almost-inertial frame, rest and motion gyro-bias estimation, gated magnetometer heading (`[firmware.vqf]`, `[firmware.mag_gate]`)",
            make: |fw, step_s| Ok(Box::new(Vqf::<T>::new(&fw.vqf, &fw.mag_gate, fw.accel_g_m_s2, step_s))),
        },
        Algorithm {
            name: "wing",
            doc: "the wing-angle unit: zero, hinge axis and 12-state filter, α out every update (`firmware.alignment_s`: the zero's time)",
            make: |fw, step_s| {
                let unit = WingUnit::<T>::new(step_s, fw.accel_g_m_s2, fw.alignment_s)?;
                Ok(Box::new(unit.with_temperature_compensation(fw.wing.gyro_bias_tempco_dps_per_c)))
            },
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

/// The profile's attitude algorithm at algorithm level over recorded samples, in the profile's numeric
/// type (`firmware.numeric`): gyro rad/s, specific force m/s², magnetic field gauss, one row per sample,
/// `step_s` apart; one update per sample from the previous and the current rate (the algorithm must
/// take two samples an update: `dcm`, `vqf`), starting from [`attitude_from_acc_mag`] of the first
/// sample. Returns one quaternion (C_b^n, ENU, f64) per sample. No device model: the algorithm alone,
/// as the dataset's baselines run; the inputs are converted into the numeric type as a decode would
/// hand them over.
pub fn run_samples(
    fw: &profile::Firmware,
    step_s: f64,
    gyr: &[Vec3<f64>],
    acc: &[Vec3<f64>],
    mag: &[Vec3<f64>],
) -> Result<Vec<Quat<f64>>> {
    crate::dispatch_numeric!(fw.numeric, T => run_samples_in::<T>(fw, step_s, gyr, acc, mag))
}

fn run_samples_in<T: Scalar>(
    fw: &profile::Firmware,
    step_s: f64,
    gyr: &[Vec3<f64>],
    acc: &[Vec3<f64>],
    mag: &[Vec3<f64>],
) -> Result<Vec<Quat<f64>>> {
    let n = gyr.len();
    if acc.len() != n || mag.len() != n || n == 0 {
        return Err(Error::Input(format!(
            "{} samples: {n} gyro, {} accelerometer and {} magnetometer rows; expected the same number > 0",
            fw.algorithm,
            acc.len(),
            mag.len()
        )));
    }
    let mut update = attitude_update::<T>(fw, step_s)?;
    if update.samples_per_update() != 2 {
        return Err(Error::Config(format!(
            "key `firmware.algorithm` = \"{}\": runs on recorded samples only for an update of two samples (`dcm`, `vqf`)",
            fw.algorithm
        )));
    }
    let r0 = attitude_from_acc_mag(&acc[0], &mag[0]).ok_or_else(|| {
        Error::Input(format!(
            "{} samples: the first accelerometer and magnetometer samples give no attitude (zero or parallel)",
            fw.algorithm
        ))
    })?;
    let to_t = |v: &Vec3<f64>, class: QClass| v.map(|x| T::from_f64(x, class));
    let c0: Mat3<T> = r0.map(|row| row.map(|x| T::from_f64(x, QClass::Quat)));
    let mut q = quat_from_dcm(&c0);
    let mut c = c0;
    let mut out = Vec::with_capacity(n);
    out.push(q.map(|x| x.to_f64()));
    let mut previous = to_t(&gyr[0], QClass::Rate);
    for k in 1..n {
        let current = to_t(&gyr[k], QClass::Rate);
        let rates = [previous, current];
        let inputs = StepInputs {
            specific_force: Some(to_t(&acc[k], QClass::Accel)),
            magnetic_field: Some(to_t(&mag[k], QClass::Accel)),
            ..StepInputs::rates(&rates, None)
        };
        update.step(&mut q, &c, &inputs)?;
        c = update.matrix().unwrap_or_else(|| dcm(&q));
        out.push(q.map(|x| x.to_f64()));
        previous = current;
    }
    Ok(out)
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
            err.contains(
                "key `firmware.algorithm` = \"rk5\": expected one of `rk4`, `rotation-vector`, `dcm`, `vqf`, `wing`"
            ),
            "{err}"
        );
    }
}
