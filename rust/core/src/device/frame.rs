//! What one frame did at a part of the ADIS16xxx family (its record, the rules it broke) and the
//! timing rules in integer form: what the part ([`super::adis`]) and its SPI protocol
//! ([`super::slave`]) share, below both.

use crate::time::Ps;

/// The timing or protocol rules one frame broke, as bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub struct Violations(pub u16);

impl Violations {
    /// SCLK faster than allowed.
    pub const SCLK_TOO_FAST: Violations = Violations(1 << 0);
    /// Too little time since the previous frame.
    pub const STALL_TOO_SHORT: Violations = Violations(1 << 1);
    /// CS↓ too close to the first SCLK edge.
    pub const CS_SETUP: Violations = Violations(1 << 2);
    /// CS↑ too close to the last SCLK edge.
    pub const CS_HOLD: Violations = Violations(1 << 3);
    /// Clocked in another SPI mode than the part's (mode 3).
    pub const SPI_MODE: Violations = Violations(1 << 4);
    /// Not 16 SCLK cycles.
    pub const FRAME_LENGTH: Violations = Violations(1 << 5);
    /// Clocked with CS high.
    pub const NO_CHIP_SELECT: Violations = Violations(1 << 6);
    /// Clocked during a software reset.
    pub const DEVICE_BUSY: Violations = Violations(1 << 7);
    /// Too little time since the previous frame outside a burst started (tDATARATE).
    pub const DATARATE_TOO_SHORT: Violations = Violations(1 << 8);
    /// Clocked before the power-on start-up ended.
    pub const BEFORE_STARTUP: Violations = Violations(1 << 9);
    /// CS high too short between two chip-select windows.
    pub const CS_HIGH_TOO_SHORT: Violations = Violations(1 << 10);

    /// The rules whose breach makes the slave ignore DIN (and corrupt DOUT) in either timing mode.
    pub(super) const IGNORE_DIN: Violations = Violations(
        Violations::FRAME_LENGTH.0
            | Violations::NO_CHIP_SELECT.0
            | Violations::DEVICE_BUSY.0
            | Violations::BEFORE_STARTUP.0,
    );

    const NAMES: [(Violations, &'static str); 11] = [
        (Violations::SCLK_TOO_FAST, "sclk_too_fast"),
        (Violations::STALL_TOO_SHORT, "stall_too_short"),
        (Violations::CS_SETUP, "cs_setup"),
        (Violations::CS_HOLD, "cs_hold"),
        (Violations::SPI_MODE, "spi_mode"),
        (Violations::FRAME_LENGTH, "frame_length"),
        (Violations::NO_CHIP_SELECT, "frame_without_cs"),
        (Violations::DEVICE_BUSY, "device_busy"),
        (Violations::DATARATE_TOO_SHORT, "datarate_too_short"),
        (Violations::BEFORE_STARTUP, "read_before_startup"),
        (Violations::CS_HIGH_TOO_SHORT, "cs_high_too_short"),
    ];

    /// No rule broken.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Every bit of `other` is set.
    pub fn contains(self, other: Violations) -> bool {
        self.0 & other.0 == other.0
    }

    /// Some bit of `other` is set.
    pub fn intersects(self, other: Violations) -> bool {
        self.0 & other.0 != 0
    }

    /// Set the bits of `other`.
    pub fn insert(&mut self, other: Violations) {
        self.0 |= other.0;
    }

    /// The event kinds of the set bits.
    pub fn kinds(self) -> impl Iterator<Item = &'static str> {
        Violations::NAMES.into_iter().filter(move |(v, _)| self.contains(*v)).map(|(_, k)| k)
    }
}

/// What one frame did at the slave (which register and which sample its DOUT carried, how old that
/// sample was, which rules it broke), for the firmware/harness log. Plain `Copy` data; the link's own
/// `bus::FrameRecord` holds the wire-level view of the same frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub struct ReadRecord {
    /// Frames clocked at this slave since power-on, starting at 0.
    pub index: u64,
    /// First SCLK edge.
    pub t_start: Ps,
    /// Last SCLK edge.
    pub t_end: Ps,
    /// Word sampled on DIN.
    pub din: u16,
    /// Word shifted out on DOUT.
    pub dout: u16,
    /// The register whose contents DOUT carries (none after a write, in the first frame, …).
    pub register: Option<u8>,
    /// The internal sample the DOUT word holds (output registers only).
    pub sample_index: Option<u64>,
    /// Age of that sample at the frame's first edge, ps.
    pub sample_age_ps: Option<Ps>,
    /// Rules the frame broke.
    pub violations: Violations,
    /// A burst data frame.
    pub in_burst: bool,
}

/// Whole picoseconds below this are exact in f64, and so is one more.
const EXACT_PS: Ps = 1 << 53;

/// `measured` (whole ps, floored by the bus) falls short of `required` ps, with a 1 ps allowance
/// (the ADIS16xxx family's rules: [`short_by`] with a slack of 1 ps). The per-frame checks use its
/// integer forms [`MinPs`] and [`short_ps`], which give the same answer for every `measured`.
pub(super) fn short(measured: Ps, required_ps: f64) -> bool {
    short_by(measured, required_ps, 1.0)
}

/// The definition of every timing rule: `measured` (whole ps) plus the part's allowance `slack_ps`
/// (`SpiTiming::slack_ps`) falls short of `required_ps`.
pub(super) fn short_by(measured: Ps, required_ps: f64, slack_ps: f64) -> bool {
    (measured as f64) + slack_ps < required_ps
}

/// [`short`] against a whole-ps requirement (the frame's own SCLK period inside a burst). Below 2^53
/// both values and `measured + 1` are exact in f64, so the float rule is the integer one; beyond
/// (2.5 hours) the float rule itself decides.
pub(super) fn short_ps(measured: Ps, required: Ps) -> bool {
    if measured < EXACT_PS && required < EXACT_PS {
        measured + 1 < required
    } else {
        short(measured, required as f64)
    }
}

/// A fixed timing limit as a whole-ps bound, so that a frame's check is one integer comparison instead
/// of a u64 → f64 conversion: `short(m)` equals [`short`]`(m, required_ps)` for every `m`.
///
/// Why that holds: `m as f64` (round to nearest) and `+ 1.0` are non-decreasing in `m`, so the `m`
/// that [`short`] rejects are exactly `0..first_ok` for some `first_ok` in 0…2^64; [`MinPs::new`]
/// finds it by bisection over [`short`] itself (2^64, every u64 short, for an infinite requirement;
/// hence the u128).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct MinPs {
    first_ok: u128,
}

impl MinPs {
    /// The bound of the rule "`measured` must not fall short of `required_ps`" (with the 1 ps
    /// allowance of [`short`]).
    pub fn new(required_ps: f64) -> MinPs {
        MinPs::with_slack(required_ps, 1.0)
    }

    /// The bound of [`short_by`]`(·, required_ps, slack_ps)` (non-decreasing in `measured` for any
    /// slack, as [`short`]).
    pub fn with_slack(required_ps: f64, slack_ps: f64) -> MinPs {
        let short = |m: Ps| short_by(m, required_ps, slack_ps);
        if short(u64::MAX) {
            return MinPs { first_ok: 1 << 64 };
        }
        // Invariant: every m < lo is short, hi is not.
        let (mut lo, mut hi) = (0u64, u64::MAX);
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if short(mid) {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        MinPs { first_ok: u128::from(lo) }
    }

    /// The bound of [`short_ps`] against the whole-ps `required`: `short(m)` equals
    /// `short_ps(m, required)` for every `m`. Below 2^53 that rule is `m + 1 < required` for every `m`
    /// (a larger `m` exceeds `required`), beyond it the float rule, which [`MinPs::new`] bounds.
    pub fn whole(required: Ps) -> MinPs {
        if required < EXACT_PS {
            MinPs { first_ok: u128::from(required.saturating_sub(1)) }
        } else {
            MinPs::new(required as f64)
        }
    }

    /// `measured` breaks the rule.
    pub fn short(self, measured: Ps) -> bool {
        u128::from(measured) < self.first_ok
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Requirements where rounding could bite: zero, halves, values next to whole ps, the f64
    /// precision limit 2^53 and beyond, the top of u64, infinity and NaN, and the profile defaults.
    fn requirements() -> Vec<f64> {
        let mut r = vec![
            0.0,
            -1.0,
            0.5,
            1.0,
            1.5,
            2.0,
            2.5,
            48_800.0,
            9e6,
            1e12 / 2e6,
            1e12 / 1e6,
            1_333_333.5,
            (1u64 << 53) as f64,
            (1u64 << 53) as f64 + 2.0,
            (1u64 << 54) as f64 + 4.0,
            9.2e18,
            u64::MAX as f64,
            1e21,
            f64::INFINITY,
            f64::NAN,
        ];
        for x in r.clone() {
            r.push(f64::from_bits(x.to_bits().wrapping_add(1)));
            r.push(f64::from_bits(x.to_bits().wrapping_sub(1)));
        }
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(8);
        r.extend((0..200).map(|_| rng.gen_range(0.0..2e7)));
        r.extend((0..200).map(|_| 2f64.powf(rng.gen_range(0.0..66.0))));
        r
    }

    #[test]
    fn min_ps_is_the_float_rule_for_every_measured_value() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        for required in requirements() {
            let bound = MinPs::new(required);
            // Around the bound (where the rule flips), at the ends of u64 and at random.
            let edge = bound.first_ok.min(u128::from(u64::MAX)) as u64;
            let near = (0..8).flat_map(|d| [edge.saturating_sub(d), edge.saturating_add(d)]);
            let random = (0..200).map(|_| rng.gen::<u64>() >> rng.gen_range(0..64));
            for m in near.chain([0, 1, u64::MAX - 1, u64::MAX]).chain(random) {
                assert_eq!(bound.short(m), short(m, required), "required {required:e} ps, measured {m} ps");
            }
        }
    }

    #[test]
    fn short_ps_is_the_float_rule() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(10);
        let around = |x: u64| (0..4).flat_map(move |d| [x.saturating_sub(d), x.saturating_add(d)]);
        let special: Vec<u64> = [0, 1_333_333, 1 << 53, 1 << 54, u64::MAX].into_iter().flat_map(around).collect();
        for &required in &special {
            for &m in &special {
                assert_eq!(short_ps(m, required), short(m, required as f64), "{m} against {required}");
                assert_eq!(MinPs::whole(required).short(m), short_ps(m, required), "{m} against {required}");
            }
        }
        for _ in 0..100_000 {
            let required = rng.gen::<u64>() >> rng.gen_range(0..64);
            let m = if rng.gen() {
                required.saturating_sub(rng.gen_range(0..3))
            } else {
                rng.gen::<u64>() >> rng.gen_range(0..64)
            };
            assert_eq!(short_ps(m, required), short(m, required as f64), "{m} against {required}");
            assert_eq!(MinPs::whole(required).short(m), short_ps(m, required), "{m} against {required}");
        }
    }
}
