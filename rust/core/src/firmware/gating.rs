//! The guards a fusing attitude algorithm (the DCM, the VQF-class filter) puts around its references:
//! what it does when a gyro axis clips ([`ClipGuard`]) and when the magnetic field is not the earth's
//! ([`MagGate`]). Both are firmware state in the numeric type; both report what they do as events
//! ([`Events`], drained by the ISR after each update with the update's time).
//!
//! Clipping. The ADIS16407 clips each output at its 14-bit limit (0x1FFF / 0x2000) and sets DIAG_STAT's
//! overrange flag, which raises EA (bit 14) in every output word of the burst; the decode flags each
//! axis whose code is at the limit (`DecodeReport::saturated`). While a gyro axis is clipped its rate is
//! only a lower bound of the true one: the attitude update integrates it (nothing better is known) but
//! raises the accelerometer's (and a trusted magnetometer's) gain by `clip_gain` and freezes any
//! integrator, from the first clipped sample until `clip_recovery_s` after the last one; the error
//! the clip left then decays with the raised gain's time constant.
//!
//! Magnetic disturbance. The field's norm and its dip (the angle below the horizontal, taken with the
//! current attitude) are compared with a reference learned at rest (|ω| below `rest_gyro_dps` and |f|
//! within `rest_accel_g` of g for `rest_s`): a field whose norm is off by more than `norm_tol` of the
//! reference or whose dip is off by more than `dip_tol_deg`, or a field with a clipped axis,
//! is not used; yaw runs on the gyro meanwhile. A rejection longer than `relearn_s` adopts the field's
//! low-passed norm and dip as the new reference (a disturbance that lasts is the new field: an
//! attached magnet, a different room). Until the first rest the field is taken unchecked.

use super::Vec3;
use crate::events::Severity;
use crate::numerics::{QClass, Scalar};
use crate::profile;

/// Events an attitude algorithm raised during one update: (kind, severity, message).
pub type Events = Vec<(&'static str, Severity, String)>;

/// What the clip guard says of one update.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClipState {
    /// No clip within the recovery time: normal gains.
    Normal,
    /// A gyro axis clipped in this update or within the recovery time: raised gains, no integrator.
    Raised,
}

/// The gyro clip guard (see the module doc).
#[derive(Debug, Clone)]
pub struct ClipGuard {
    /// Updates the raised gain lasts after the last clipped one.
    recovery_steps: u32,
    /// Updates of raised gain left (0: normal).
    left: u32,
    /// The axes clipped in the previous update (bit i: axis i).
    previous: u8,
    /// Updates clipped since the raised gain began (reported when it ends).
    clipped_updates: u32,
    step_s: f64,
}

impl ClipGuard {
    /// A guard whose raised gain lasts `recovery_s` after the last clipped update of `step_s`.
    pub fn new(recovery_s: f64, step_s: f64) -> Self {
        let recovery_steps = (recovery_s / step_s).round().clamp(0.0, u32::MAX as f64) as u32;
        ClipGuard { recovery_steps, left: 0, previous: 0, clipped_updates: 0, step_s }
    }

    /// Forget everything (the attitude was overwritten).
    pub fn restart(&mut self) {
        self.left = 0;
        self.previous = 0;
        self.clipped_updates = 0;
    }

    /// One update whose samples had the gyro axes `clipped` (bit i: axis i) at their limit.
    pub fn update(&mut self, clipped: u8, events: &mut Events) -> ClipState {
        let clipped = clipped & 0b111;
        if clipped != 0 {
            if clipped & !self.previous != 0 {
                events.push((
                    "gyro_clipped",
                    Severity::Warning,
                    format!(
                        "gyro axis {} at its full-scale code: its rate is a lower bound; the reference gains are \
                         raised until {:.3} s after the last clipped sample",
                        axes(clipped),
                        self.recovery_steps as f64 * self.step_s
                    ),
                ));
            }
            self.clipped_updates += 1;
            self.left = self.recovery_steps.max(1);
        } else if self.left > 0 {
            self.left -= 1;
            if self.left == 0 {
                events.push((
                    "clip_recovered",
                    Severity::Info,
                    format!(
                        "no gyro clip for {:.3} s: normal gains again ({} clipped updates)",
                        self.recovery_steps as f64 * self.step_s,
                        self.clipped_updates
                    ),
                ));
                self.clipped_updates = 0;
            }
        }
        self.previous = clipped;
        if self.left > 0 {
            ClipState::Raised
        } else {
            ClipState::Normal
        }
    }

    /// Put the guard in its raised state (the timing model's costliest path).
    pub fn to_raised(&mut self) {
        self.left = self.recovery_steps.max(1);
    }
}

fn axes(mask: u8) -> String {
    ["x", "y", "z"]
        .iter()
        .enumerate()
        .filter(|(i, _)| mask & (1 << i) != 0)
        .map(|(_, a)| *a)
        .collect::<Vec<_>>()
        .join("")
}

/// Rest detection on the step's mean rate and the latest specific force.
#[derive(Debug, Clone)]
pub struct RestDetector<T> {
    rate2: T,
    accel_lo2: T,
    accel_hi2: T,
    need: u32,
    count: u32,
}

impl<T: Scalar> RestDetector<T> {
    /// At rest after `rest_s` of updates with |ω| < `rate_dps` and ||f| − g| < `accel_g`·g.
    pub fn new(p: &profile::MagGate, g: f64, step_s: f64) -> Self {
        let w = p.rest_gyro_dps.to_radians();
        let (lo, hi) = ((g * (1.0 - p.rest_accel_g)).max(0.0), g * (1.0 + p.rest_accel_g));
        RestDetector {
            rate2: T::from_f64(w * w, QClass::Generic),
            accel_lo2: T::from_f64(lo * lo, QClass::Generic),
            accel_hi2: T::from_f64(hi * hi, QClass::Generic),
            need: (p.rest_s / step_s).round().max(1.0) as u32,
            count: 0,
        }
    }

    /// One update: true once the rest has lasted long enough.
    pub fn update(&mut self, w: &Vec3<T>, f: Option<&Vec3<T>>) -> bool {
        let still_rate = dot(w, w).to_class(QClass::Generic) < self.rate2;
        let still_f = f.is_some_and(|f| {
            let s = dot(f, f).to_class(QClass::Generic);
            s > self.accel_lo2 && s < self.accel_hi2
        });
        if still_rate && still_f {
            self.count = self.count.saturating_add(1);
        } else {
            self.count = 0;
        }
        self.count >= self.need
    }

    /// Forget the rest seen so far.
    pub fn restart(&mut self) {
        self.count = 0;
    }
}

/// Why a field was not used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reject {
    Clipped,
    Norm,
    Dip,
}

/// The magnetic disturbance gate (see the module doc).
#[derive(Debug, Clone)]
pub struct MagGate<T> {
    enabled: bool,
    norm_tol: T,
    dip_tol: T,
    /// Reference (|m|, m_up/|m|); None until learned.
    reference: Option<(T, T)>,
    /// Low-pass of (|m|, m_up/|m|) over the fields seen (the re-learning candidate and the rest mean).
    lp: Option<(T, T)>,
    /// Coefficient of the low-pass, T/τ.
    alpha: T,
    relearn_steps: u32,
    rejected: u32,
    reason: Option<Reject>,
    step_s: f64,
}

impl<T: Scalar> MagGate<T> {
    /// The gate of a `[firmware.mag_gate]` section for updates of `step_s`.
    pub fn new(p: &profile::MagGate, step_s: f64) -> Self {
        // The low-pass's time constant: the rest time (the reference is the field's mean at rest).
        let alpha = (step_s / p.rest_s.max(step_s)).min(1.0);
        MagGate {
            enabled: p.enabled,
            norm_tol: T::from_f64(p.norm_tol, QClass::Quat),
            dip_tol: T::from_f64(p.dip_tol_deg.to_radians(), QClass::Angle),
            reference: None,
            lp: None,
            alpha: T::from_f64(alpha, QClass::Quat),
            relearn_steps: (p.relearn_s / step_s).round().clamp(1.0, u32::MAX as f64) as u32,
            rejected: 0,
            reason: None,
            step_s,
        }
    }

    /// Forget the reference (a restart of the attitude).
    pub fn restart(&mut self) {
        self.reference = None;
        self.lp = None;
        self.rejected = 0;
        self.reason = None;
    }

    /// Whether the field `m` (body axes) may be used at this update: `up` is navigation up in body
    /// axes (the attitude's third row), `clipped` whether an axis of the field is at its limit,
    /// `at_rest` the rest detector's verdict.
    /// `dip_trusted`: false while the attitude is known to be off (after a gyro clip): the dip, taken with
    /// it, is then not checked (the norm still is).
    pub fn check(
        &mut self,
        m: &Vec3<T>,
        up: &Vec3<T>,
        clipped: bool,
        at_rest: bool,
        dip_trusted: bool,
        events: &mut Events,
    ) -> bool {
        if !self.enabled {
            return true;
        }
        let norm = dot(m, m).sqrt().to_class(QClass::Accel);
        let zero = T::from_f64(0.0, QClass::Accel);
        if norm <= zero {
            return false;
        }
        let up_ratio = dot(m, up).to_class(QClass::Accel).div_to(norm, QClass::Quat);
        let reason = if clipped {
            Some(Reject::Clipped)
        } else if let Some((n_ref, z_ref)) = self.reference {
            let tol = (n_ref * self.norm_tol).to_class(QClass::Accel);
            if (norm - n_ref).abs() > tol {
                Some(Reject::Norm)
            } else if dip_trusted && (up_ratio.asin() - z_ref.asin()).to_class(QClass::Angle).abs() > self.dip_tol {
                Some(Reject::Dip)
            } else {
                None
            }
        } else {
            None
        };
        if !clipped {
            let lp = match self.lp {
                None => (norm, up_ratio),
                Some((n, z)) => (
                    (n + self.alpha * (norm - n)).to_class(QClass::Accel),
                    (z + self.alpha * (up_ratio - z)).to_class(QClass::Quat),
                ),
            };
            self.lp = Some(lp);
            // Learn at rest from an accepted (or the first) field; re-learn after a long rejection.
            if at_rest && reason.is_none() {
                if self.reference.is_none() {
                    events.push((
                        "mag_reference_learned",
                        Severity::Info,
                        format!(
                            "magnetic reference learned at rest: |m| {:.4} gauss, dip {:.2}°",
                            lp.0.to_f64(),
                            -lp.1.to_f64().clamp(-1.0, 1.0).asin().to_degrees()
                        ),
                    ));
                }
                self.reference = Some(lp);
            }
        }
        match reason {
            None => {
                if let Some(r) = self.reason.take() {
                    events.push((
                        "mag_accepted",
                        Severity::Info,
                        format!(
                            "magnetic field usable again after {:.3} s rejected ({})",
                            self.rejected as f64 * self.step_s,
                            describe(r)
                        ),
                    ));
                }
                self.rejected = 0;
                true
            }
            Some(r) => {
                if self.reason.is_none() {
                    let (n_ref, z_ref) = self.reference.map_or((f64::NAN, f64::NAN), |(n, z)| (n.to_f64(), z.to_f64()));
                    events.push((
                        "mag_rejected",
                        Severity::Warning,
                        format!(
                            "magnetic field not used for yaw ({}): |m| {:.4} gauss (reference {:.4}), up ratio {:.3} \
                             (reference {:.3}); yaw on the gyro",
                            describe(r),
                            norm.to_f64(),
                            n_ref,
                            up_ratio.to_f64(),
                            z_ref
                        ),
                    ));
                }
                self.reason = Some(r);
                self.rejected = self.rejected.saturating_add(1);
                if r != Reject::Clipped && self.rejected >= self.relearn_steps {
                    if let Some(lp) = self.lp {
                        events.push((
                            "mag_reference_relearned",
                            Severity::Warning,
                            format!(
                                "magnetic field rejected for {:.3} s: its low-passed |m| {:.4} gauss and up ratio {:.3} \
                                 are the new reference",
                                self.rejected as f64 * self.step_s,
                                lp.0.to_f64(),
                                lp.1.to_f64()
                            ),
                        ));
                        self.reference = Some(lp);
                        self.reason = None;
                        self.rejected = 0;
                    }
                }
                false
            }
        }
    }

    /// Updates the field has been rejected in a row.
    pub fn rejected_steps(&self) -> u32 {
        self.rejected
    }
}

fn describe(r: Reject) -> &'static str {
    match r {
        Reject::Clipped => "an axis at its full-scale code",
        Reject::Norm => "norm off the reference",
        Reject::Dip => "dip off the reference",
    }
}

fn dot<T: Scalar>(a: &Vec3<T>, b: &Vec3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gate() -> MagGate<f64> {
        MagGate::new(&profile::MagGate { enabled: true, rest_s: 1.0, relearn_s: 10.0, ..Default::default() }, 0.01)
    }

    const UP: Vec3<f64> = [0.0, 0.0, 1.0];
    const FIELD: Vec3<f64> = [0.0, 0.25, -0.433];

    #[test]
    fn a_field_off_in_norm_or_dip_is_rejected_after_the_reference_and_relearned_when_it_lasts() {
        let mut g = gate();
        let mut ev = Events::new();
        for _ in 0..200 {
            assert!(g.check(&FIELD, &UP, false, true, true, &mut ev));
        }
        assert_eq!(ev.iter().filter(|e| e.0 == "mag_reference_learned").count(), 1);
        // 20 % stronger: rejected (norm_tol 10 % by default).
        let strong = FIELD.map(|x| x * 1.2);
        assert!(!g.check(&strong, &UP, false, false, true, &mut ev));
        assert_eq!(ev.last().unwrap().0, "mag_rejected");
        // Same norm, dip turned by 20°: rejected.
        let (s, c) = (20f64.to_radians().sin(), 20f64.to_radians().cos());
        let turned = [0.0, FIELD[1] * c + FIELD[2] * s, -FIELD[1] * s + FIELD[2] * c];
        assert!(!g.check(&turned, &UP, false, false, true, &mut ev));
        // The dip is not checked while the attitude is known to be off.
        assert!(g.check(&turned, &UP, false, false, false, &mut ev));
        assert!(!g.check(&turned, &UP, false, false, true, &mut ev));
        // A clipped axis is never used, whatever the values.
        assert!(!g.check(&FIELD, &UP, true, false, true, &mut ev));
        assert!(g.check(&FIELD, &UP, false, false, true, &mut ev));
        assert_eq!(ev.last().unwrap().0, "mag_accepted");
        // A lasting disturbance becomes the reference after relearn_s (10 s = 1000 updates).
        let mut k = 0;
        while !g.check(&strong, &UP, false, false, true, &mut ev) {
            k += 1;
            assert!(k <= 1000, "never relearned");
        }
        assert_eq!(k, 1000);
        assert!(ev.iter().any(|e| e.0 == "mag_reference_relearned"));
    }

    #[test]
    fn the_clip_guard_raises_from_the_first_clip_to_the_recovery_time_after_the_last() {
        let mut c = ClipGuard::new(0.05, 0.01);
        let mut ev = Events::new();
        assert_eq!(c.update(0, &mut ev), ClipState::Normal);
        assert_eq!(c.update(0b100, &mut ev), ClipState::Raised);
        assert_eq!(ev.len(), 1);
        assert!(ev[0].2.contains("axis z"), "{}", ev[0].2);
        for _ in 0..4 {
            assert_eq!(c.update(0, &mut ev), ClipState::Raised);
        }
        assert_eq!(c.update(0, &mut ev), ClipState::Normal);
        assert_eq!(ev.last().unwrap().0, "clip_recovered");
    }
}
