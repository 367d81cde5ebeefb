//! The lower bound the benchmark suite compares the emulator with: the firmware's RK4 quaternion
//! step alone, in f64, on rates that are already decoded, with nothing else around it (no device,
//! no bus, no decode, no timing, no output). Whatever the emulator does on top of this is overhead.

use crate::firmware::Rk4;
use crate::profile::QuatDerivative;

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
