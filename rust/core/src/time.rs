//! Integer virtual time. Every instant is a whole number of picoseconds since power-on, and every
//! clock converts its own cycle counts to picoseconds exactly (rational arithmetic, floor), so no
//! float error accumulates over hours of emulated time and runs are bit-reproducible.

/// Picoseconds since power-on. `u64` covers 213 days.
pub type Ps = u64;

/// Picoseconds in one second.
pub const PS_PER_S: u64 = 1_000_000_000_000;

/// Seconds as f64 from picoseconds (for reports only, never for scheduling).
pub fn ps_to_s(t: Ps) -> f64 {
    t as f64 / PS_PER_S as f64
}

/// Picoseconds from seconds, rounded to nearest (for configuration input only).
pub fn s_to_ps(s: f64) -> Ps {
    (s * PS_PER_S as f64).round().max(0.0) as Ps
}

/// Exact division of u64 values by a fixed divisor, with the reciprocal computed once: a multiply
/// (high half of a 64×64-bit product) and at most one correction instead of a hardware divide, which
/// costs several times more and sits on the emulator's per-frame path (every time conversion).
///
/// With r = ⌊(2⁶⁴ − 1)/d⌋, the estimate ⌊n·r/2⁶⁴⌋ is ⌊n/d⌋ or one less (2⁶⁴ − d·r ≤ d, so the
/// estimate errs by less than n/2⁶⁴ < 1); the remainder test fixes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Divisor {
    d: u64,
    reciprocal: u64,
}

impl Divisor {
    /// Division by `d` (> 0; a zero divisor is clamped to 1, which callers rule out).
    pub fn new(d: u64) -> Self {
        let d = d.max(1);
        Divisor { d, reciprocal: u64::MAX / d }
    }

    /// The divisor.
    pub fn get(self) -> u64 {
        self.d
    }

    /// ⌊n / d⌋ and n mod d.
    pub fn div_rem(self, n: u64) -> (u64, u64) {
        let q = ((n as u128 * self.reciprocal as u128) >> 64) as u64;
        let r = n - q * self.d;
        if r >= self.d {
            (q + 1, r - self.d)
        } else {
            (q, r)
        }
    }

    /// ⌊n / d⌋.
    pub fn quotient(self, n: u64) -> u64 {
        self.div_rem(n).0
    }

    /// ⌈n / d⌉.
    pub fn div_ceil(self, n: u64) -> u64 {
        let (q, r) = self.div_rem(n);
        q + u64::from(r != 0)
    }
}

/// A clock of rational frequency `num/den` hertz.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Clock {
    num: u64,
    den: u64,
    /// One cycle is `ps_num/ps_den` ps, reduced (a function of num/den, so equality is unchanged):
    /// lets `cycles_to_ps` use one u64 multiply and divide when the product fits (the hot path).
    ps_num: Divisor,
    ps_den: Divisor,
}

impl Clock {
    /// A clock of `num/den` Hz. Panics only on a zero numerator or denominator, which callers rule
    /// out when they validate their configuration.
    pub fn new(num: u64, den: u64) -> Self {
        assert!(num > 0 && den > 0, "clock frequency must be positive");
        let g = gcd(num, den);
        let (num, den) = (num / g, den / g);
        let ps_total = PS_PER_S as u128 * den as u128;
        let h = gcd128(ps_total, num as u128);
        // When the reduced numerator does not fit u64 the fast path is disabled (u64::MAX overflows).
        let ps_num = u64::try_from(ps_total / h).unwrap_or(u64::MAX);
        Clock { num, den, ps_num: Divisor::new(ps_num), ps_den: Divisor::new((num as u128 / h) as u64) }
    }

    /// A clock of a whole number of hertz.
    pub fn from_hz(hz: u64) -> Self {
        Clock::new(hz, 1)
    }

    /// This clock divided by `div` (a prescaler).
    pub fn divided(self, div: u64) -> Self {
        Clock::new(self.num, self.den * div)
    }

    /// This clock multiplied by `mul` (a PLL).
    pub fn multiplied(self, mul: u64) -> Self {
        Clock::new(self.num * mul, self.den)
    }

    /// This clock off by `ppb` parts per billion (positive = fast).
    pub fn skewed_ppb(self, ppb: i64) -> Self {
        let scale = 1_000_000_000i64 + ppb;
        assert!(scale > 0, "clock skew must leave a positive frequency");
        Clock::new(self.num * scale as u64, self.den * 1_000_000_000)
    }

    /// Frequency in hertz (for reports).
    pub fn hz(self) -> f64 {
        self.num as f64 / self.den as f64
    }

    /// Period in seconds (for reports).
    pub fn period_s(self) -> f64 {
        self.den as f64 / self.num as f64
    }

    /// Time of `cycles` whole cycles, floored to the picosecond.
    #[inline]
    pub fn cycles_to_ps(self, cycles: u64) -> Ps {
        match cycles.checked_mul(self.ps_num.get()) {
            Some(p) if self.ps_num.get() != u64::MAX => self.ps_den.quotient(p),
            _ => self.cycles_to_ps_wide(cycles),
        }
    }

    /// [`Clock::cycles_to_ps`] in 128-bit arithmetic, when the 64-bit product overflows (rare: out
    /// of line, so the common case inlines small).
    #[cold]
    #[inline(never)]
    fn cycles_to_ps_wide(self, cycles: u64) -> Ps {
        ((cycles as u128 * PS_PER_S as u128 * self.den as u128) / self.num as u128) as Ps
    }

    /// How many of this clock's cycles one cycle of `slower` lasts, when that is a whole number `k`
    /// and this clock's period is at least 1 ps. Then the first cycle boundary of this clock at or
    /// after the time of `slower`'s cycle `n` is exactly cycle `k·n`: that time is floored to the
    /// picosecond, which loses less than 1 ps, less than one period (⌈⌊n·k·P⌋/P⌉ = n·k for P ≥ 1 ps),
    /// so converting through picoseconds can be skipped.
    pub fn cycles_per_cycle_of(self, slower: Clock) -> Option<u64> {
        let this_period_at_least_1_ps = self.num as u128 <= PS_PER_S as u128 * self.den as u128;
        // k = (num/den) / (slower.num/slower.den).
        let n = self.num as u128 * slower.den as u128;
        let d = self.den as u128 * slower.num as u128;
        let whole = n.is_multiple_of(d);
        (this_period_at_least_1_ps && whole).then(|| u64::try_from(n / d).ok()).flatten()
    }

    /// Whole cycles completed by time `t` (floor).
    #[inline]
    pub fn ps_to_cycles(self, t: Ps) -> u64 {
        match t.checked_mul(self.ps_den.get()) {
            Some(n) if self.ps_num.get() != u64::MAX => self.ps_num.quotient(n),
            _ => self.ps_to_cycles_wide(t),
        }
    }

    /// [`Clock::ps_to_cycles`] in 128-bit arithmetic (see [`Clock::cycles_to_ps_wide`]).
    #[cold]
    #[inline(never)]
    fn ps_to_cycles_wide(self, t: Ps) -> u64 {
        ((t as u128 * self.num as u128) / (PS_PER_S as u128 * self.den as u128)) as u64
    }

    /// The first cycle boundary at or after `t`, as a cycle count (ceil).
    #[inline]
    pub fn ps_to_cycles_ceil(self, t: Ps) -> u64 {
        match t.checked_mul(self.ps_den.get()) {
            Some(n) if self.ps_num.get() != u64::MAX => self.ps_num.div_ceil(n),
            _ => self.ps_to_cycles_ceil_wide(t),
        }
    }

    /// [`Clock::ps_to_cycles_ceil`] in 128-bit arithmetic (see [`Clock::cycles_to_ps_wide`]).
    #[cold]
    #[inline(never)]
    fn ps_to_cycles_ceil_wide(self, t: Ps) -> u64 {
        let n = t as u128 * self.num as u128;
        let d = PS_PER_S as u128 * self.den as u128;
        n.div_ceil(d) as u64
    }
}

impl Clock {
    /// Whether every count `c ≤ max_cycles` converts on [`Clock::cycles_to_ps`]'s 64-bit path: then
    /// no such time passes u64 and the times grow with the count.
    #[inline]
    pub fn converts_in_64_bits_up_to(self, max_cycles: u64) -> bool {
        self.ps_num.get() != u64::MAX && max_cycles.checked_mul(self.ps_num.get()).is_some()
    }
}

fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

fn gcd128(mut a: u128, mut b: u128) -> u128 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sysclk_cycles_are_exact_over_long_spans() {
        let sys = Clock::from_hz(30_000_000).multiplied(10).divided(2);
        assert_eq!(sys.hz(), 150e6);
        // 150e6 cycles are exactly one second, even though one cycle is 6666.67 ps.
        assert_eq!(sys.cycles_to_ps(150_000_000), PS_PER_S);
        assert_eq!(sys.cycles_to_ps(1), 6_666);
        assert_eq!(sys.ps_to_cycles(PS_PER_S), 150_000_000);
    }

    #[test]
    fn adis_sample_clock_is_rational() {
        // 819.2 SPS = 4096/5 Hz; 819.2 samples take exactly one second.
        let fs = Clock::new(8192, 10);
        assert_eq!(fs.cycles_to_ps(4096), 5 * PS_PER_S);
        assert_eq!(fs.cycles_to_ps(1), 1_220_703_125);
    }

    #[test]
    fn ceil_and_floor_agree_on_boundaries() {
        let c = Clock::from_hz(37_500_000);
        let t = c.cycles_to_ps(12345);
        assert_eq!(c.ps_to_cycles(t), 12345);
        assert_eq!(c.ps_to_cycles_ceil(t), 12345);
        assert_eq!(c.ps_to_cycles_ceil(t + 1), 12346);
    }

    #[test]
    fn fast_path_equals_the_exact_formula() {
        let exact = |c: Clock, n: u64| ((n as u128 * PS_PER_S as u128 * c.den as u128) / c.num as u128) as Ps;
        let clocks = [
            Clock::new(75_000_000, 2),
            Clock::from_hz(150_000_000),
            Clock::new(8192, 10),
            Clock::new(8192, 10).skewed_ppb(-12_345),
            Clock::from_hz(1),
            Clock::new(7, 3),
        ];
        for c in clocks {
            for n in [0, 1, 2, 3, 799, 12_057, 1 << 20, 1 << 40, u64::MAX / 3, u64::MAX / 80_000 + 1] {
                let n = n.min(u64::MAX / 1_000_000); // keep the exact result inside u64
                assert_eq!(c.cycles_to_ps(n), exact(c, n), "{c:?} {n}");
                let t = n.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 8;
                let d = PS_PER_S as u128 * c.den as u128;
                let num = t as u128 * c.num as u128;
                assert_eq!(c.ps_to_cycles(t) as u128, num / d, "{c:?} {t}");
                assert_eq!(c.ps_to_cycles_ceil(t) as u128, num.div_ceil(d), "{c:?} {t}");
            }
        }
    }

    #[test]
    fn divisor_is_exact() {
        let divisors = [1, 2, 3, 7, 10, 1_000, 20_000, 1_220_703_125, 1 << 32, (1 << 63) + 1, u64::MAX - 1, u64::MAX];
        let mut n = 0x243F_6A88_85A3_08D3u64;
        for d in divisors {
            let div = Divisor::new(d);
            let edge =
                [0, 1, d - 1, d, d.wrapping_add(1), u64::MAX - 1, u64::MAX, u64::MAX / d * d, u64::MAX / d * d - 1];
            for i in 0..10_000 {
                n = n.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                let x = if i < edge.len() { edge[i] } else { n >> (i % 64) };
                assert_eq!(div.div_rem(x), (x / d, x % d), "{x} / {d}");
                assert_eq!(div.div_ceil(x), x.div_ceil(d), "{x} / {d}");
            }
        }
    }

    #[test]
    fn a_whole_ratio_converts_cycle_boundaries_without_picoseconds() {
        let sys = Clock::new(150_000_000, 1);
        // LSPCLK = SYSCLKOUT / (2·LOSPCP) for every LOSPCP, and the reference's 37.5 MHz.
        for div in [1, 2, 4, 6, 14] {
            let lsp = sys.divided(div);
            assert_eq!(sys.cycles_per_cycle_of(lsp), Some(div));
            for n in [0, 1, 2, 3, 7, 12_345, 987_654_321, 1 << 40] {
                assert_eq!(sys.ps_to_cycles_ceil(lsp.cycles_to_ps(n)), div * n, "÷{div} n = {n}");
            }
        }
        assert_eq!(Clock::new(8192, 10).cycles_per_cycle_of(Clock::from_hz(1)), None, "819.2 is not whole");
        assert_eq!(sys.cycles_per_cycle_of(sys.multiplied(2)), None, "a faster clock");
        assert_eq!(Clock::from_hz(2 * PS_PER_S).cycles_per_cycle_of(Clock::from_hz(1)), None, "period below 1 ps");
    }

    #[test]
    fn the_64_bit_bound_is_where_the_product_stops_fitting() {
        let clocks = [
            Clock::new(75_000_000, 2),
            Clock::from_hz(150_000_000),
            Clock::new(8192, 10).skewed_ppb(-12_345),
            Clock::new(7, 3),
            Clock::new(999_999_937, 13),
            Clock::from_hz(3 * PS_PER_S),
        ];
        for clock in clocks {
            let max = u64::MAX / clock.ps_num.get();
            assert!(clock.converts_in_64_bits_up_to(max), "{clock:?}");
            if let Some(past) = max.checked_add(1) {
                assert!(!clock.converts_in_64_bits_up_to(past), "{clock:?}: one cycle past the bound");
            }
            // Both paths floor the same exact quotient: the bound changes the arithmetic, not the time.
            for c in max - 2..=max.saturating_add(2) {
                assert_eq!(clock.cycles_to_ps(c), clock.cycles_to_ps_wide(c), "{clock:?} {c}");
            }
        }
        assert!(!Clock::new(1, 100_000_000).converts_in_64_bits_up_to(0), "a period beyond u64 ps: the 128-bit path");
    }

    #[test]
    fn skew_changes_frequency() {
        let c = Clock::from_hz(1_000_000).skewed_ppb(1000);
        assert!((c.hz() - 1_000_001.0).abs() < 1e-6);
    }
}
