//! What the benchmark suite compares the emulator with, besides the baselines a user would write:
//! - the lower bound, the firmware's RK4 quaternion step alone, in f64, on rates that are already
//!   decoded, with nothing else around it (no device, no bus, no decode, no timing, no output);
//! - the firmware's stages alone (decode, attitude update, Euler, navigation) on recorded burst
//!   words: the firmware's own share of an emulated cycle, without the board around it.

use crate::firmware::{Firmware, Quat, Rk4};
use crate::profile::{Profile, QuatDerivative, Schedule};
use crate::{Error, Result};

/// Run the RK4 step over `rates` (ω_nb^b, rad/s, one row per half step: step k uses rows 2k, 2k+1,
/// 2k+2, as the half-step schedule does) with step `step_s`; returns the final quaternion (so the
/// loop cannot be optimised away) and the number of steps.
pub fn rk4_lower_bound(rates: &[[f64; 3]], step_s: f64) -> ([f64; 4], u64) {
    let rk4 = Rk4::<f64>::new(step_s, QuatDerivative::Correct);
    let mut q = [1.0, 0.0, 0.0, 0.0];
    let mut steps = 0;
    let mut k = 0;
    while k + 2 < rates.len() {
        rk4.step_quat(&mut q, &[rates[k], rates[k + 1], rates[k + 2]]);
        steps += 1;
        k += 2;
    }
    (q, steps)
}

/// The firmware's stages alone, in f64, as the half-step RK4 firmware runs them on each update:
/// decode the two reads of the update (X/Y/Z GYRO_OUT, X/Y/Z ACCL_OUT of each burst; `reads[0]` is
/// the read the first update starts from), attitude update, Euler extraction, navigation step with
/// the last read's specific force. No device, no SPI, no timing, no output rows: the firmware's own
/// work per emulated cycle. Returns the final quaternion and the number of updates.
pub fn firmware_stages(profile: &Profile, reads: &[[u16; 6]]) -> Result<(Quat<f64>, u64)> {
    let fw = &profile.firmware;
    if fw.algorithm != "rk4" || fw.schedule != Schedule::HalfStep {
        return Err(Error::Config(format!(
            "firmware stages benchmark: firmware.algorithm = {:?}, firmware.schedule = {:?}: expected Rk4 and \
             HalfStep (the reference's update from a read every tick)",
            fw.algorithm, fw.schedule
        )));
    }
    let mut fw = Firmware::<f64>::new(profile)?;
    let Some((first, rest)) = reads.split_first() else {
        return Ok((*fw.quat(), 0));
    };
    let mut rates = [fw.decode(first).rate; 3];
    let mut steps = 0;
    for pair in rest.chunks_exact(2) {
        rates[1] = fw.decode(&pair[0]).rate;
        let last = fw.decode(&pair[1]);
        rates[2] = last.rate;
        fw.update_attitude(&rates)?;
        // Computed as the firmware computes it every update; black_box keeps it from being dropped.
        std::hint::black_box(fw.euler());
        fw.navigate(&last.accel);
        rates[0] = rates[2];
        steps += 1;
    }
    Ok((*fw.quat(), steps))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emulator::tests::{constant_rate, costs};
    use crate::emulator::{Emulator, Progress};

    #[test]
    fn constant_rate_turns_by_rate_times_time() {
        let w = 0.5f64;
        let rates = vec![[0.0, 0.0, w]; 2001];
        let (q, steps) = rk4_lower_bound(&rates, 0.008);
        assert_eq!(steps, 1000);
        // RK4 of a constant rate: the half-angle is w·t/2 to the method's O(h⁵) per step.
        let half = w * 8.0 / 2.0;
        assert!((q[0] - half.cos()).abs() < 1e-9 && (q[3] - half.sin()).abs() < 1e-9, "{q:?}");
    }

    /// The stages alone, fed the words the emulated board read, end at the attitude the emulator
    /// output, bit for bit: they are the same firmware code doing the same work (errors on, so
    /// every read differs; earth rate and navigation on, as in the reference).
    #[test]
    fn firmware_stages_on_the_boards_reads_end_at_the_emulators_attitude() {
        let mut profile = Profile::default();
        profile.firmware.numeric = crate::profile::Numeric::F64;
        profile.errors.preset = "adis16407".into();
        assert!(profile.firmware.earth_rate && profile.firmware.navigation);
        let mut emu = Emulator::<f64>::new(&profile, &costs()).unwrap();
        let (t, p) = constant_rate(3.0, [5.0, -3.0, 20.0]);
        emu.push_input(&t, p).unwrap();
        emu.end_input();
        assert_eq!(emu.run().unwrap(), Progress::Finished);
        let out = emu.take_output();
        let reads: Vec<[u16; 6]> = out.reads.iter().map(|r| std::array::from_fn(|i| r.words[2 + i])).collect();
        let (q, steps) = firmware_stages(&profile, &reads).unwrap();
        assert_eq!(steps as usize, out.cycles.len());
        assert_eq!(q.map(f64::to_bits), out.cycles.last().unwrap().quat.map(f64::to_bits));
    }

    #[test]
    fn firmware_stages_refuses_another_algorithm() {
        let mut profile = Profile::default();
        profile.firmware.algorithm = "rotation-vector".into();
        let e = firmware_stages(&profile, &[[0; 6]; 5]).unwrap_err().to_string();
        assert!(e.contains("firmware.algorithm"), "{e}");
    }
}
