//! IEEE single precision as the C28x FPU (FPU32) and TI's fastRTS library compute it.
//!
//! Semantics (spec `f28335.md`, "FPU (FPU32) numerics"):
//! - every `+ − ×` result is rounded in the mode of the RND32 bit: `C28xF32<false>` rounds to nearest even
//!   (what compiled C runs after `c_int00`), `C28xF32<true>` rounds toward zero (RND32's reset value, hand
//!   assembly without the RTS start-up). Round toward zero is computed exactly: an f32×f32 product is exact in
//!   f64, an f32+f32 sum is the f64 sum plus its TwoSum error term, then truncated toward zero.
//! - denormal inputs and results are flushed to +0 (a result is flushed when it is subnormal after rounding;
//!   the FPU's exact tininess point is not published), and −0 is stored as +0, so every stored value is
//!   canonical: +0, a normal number, or ±∞.
//! - the FPU has no NaN ("NaN is treated as ∞"). Where IEEE would produce NaN the model produces ∞ with the
//!   sign IEEE's sign rule gives: ∞·0 → ∞ with the XOR of the operands' signs, ∞ − ∞ → ∞ with the first
//!   operand's sign. This choice reproduces the sign fix-up (`NEGF32 R0H,R0H,EQ`) in TI's `FS$$DIV`, which
//!   only yields A/0 = ±∞ with A's sign under it. `from_f64(NaN)` gives +∞.
//! - overflow follows IEEE for the mode: ±∞ when rounding to nearest, ±`f32::MAX` when truncating.
//! - division and square root are TI's fastRTS sequences, not correctly rounded: an `EINVF32` /
//!   `EISQRTF32` estimate (modelled, see [`EstimateModel`]) refined by two Newton–Raphson steps, every
//!   intermediate rounded in the mode. `A/B`: `Ye = est(1/B)`, twice `Ye = Ye·(2 − Ye·B)`, then `A·Ye`;
//!   a zero dividend gives 0 (TI documents 0/0 = 0 for the shipped `FS$$DIV`; the FPU's 0·∞ result that
//!   decides it is not published), and B = 0 negates A first as the routine does. `sqrt(X)`: `Ye =
//!   est(1/√X)`, `Ye = Ye·(1.5 − (Ye·Ye)·(X·0.5))`, `Ye = Ye·(1.5 − Ye·(Ye·(X·0.5)))` (the two steps
//!   associate differently in TI's source, reproduced here), then `X·Ye`; X = 0 forces Ye = 0. Negative X
//!   (IEEE: NaN estimate → ∞ here) gives −∞; infinite divisors and radicands are outside what the firmware
//!   does and simply follow the rules above.
//! - sin, cos, atan, atan2, asin: fastRTS is accurate to about 1 ulp; the model evaluates them in f64 and
//!   rounds once in the mode, so results may differ from the target library by an ulp.

use super::{pow2, QClass, Scalar};
use std::cell::Cell;
use std::fmt;
use std::ops::{Add, Div, Mul, Neg, Sub};
use std::sync::OnceLock;

/// How the unpublished `EINVF32` / `EISQRTF32` estimate tables are modelled. TI states "about 8 bits";
/// two Newton–Raphson steps square the relative error twice (e ≤ 2⁻⁸ → ≈ 2⁻³²), far below an f32 ulp, so
/// the choice only shows in the last bit of rare results (measured by [`fastrts_accuracy`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum EstimateModel {
    /// A 256-entry ROM as hardware estimators are built: indexed by the top 8 fraction bits of the input
    /// (and the exponent's parity for 1/√x); each entry is the function at the interval's midpoint rounded to
    /// 8 fraction bits. Relative error ≤ 2⁻⁸ + 2⁻¹⁸.
    #[default]
    Table8,
    /// The exact reciprocal (or 1/√x) rounded to nearest at 8 fraction bits. Relative error ≤ 2⁻⁹.
    Rounded8,
    /// The exact reciprocal (or 1/√x) truncated to 8 fraction bits. Relative error < 2⁻⁸.
    Truncated8,
}

impl EstimateModel {
    /// Every model, for sweeps and reports.
    pub const ALL: [EstimateModel; 3] = [EstimateModel::Table8, EstimateModel::Rounded8, EstimateModel::Truncated8];

    /// Short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            EstimateModel::Table8 => "table8",
            EstimateModel::Rounded8 => "rounded8",
            EstimateModel::Truncated8 => "truncated8",
        }
    }

    /// Upper bound of the estimate's relative error |est·f(x)⁻¹ − 1|, derived in the variant docs.
    pub fn max_relative_error(self) -> f64 {
        match self {
            // ½ interval (≤ 2⁻⁹ relative) then ½ ulp of the 9-bit entry (≤ 2⁻⁹): (1+2⁻⁹)² − 1.
            EstimateModel::Table8 => (1.0 + 2f64.powi(-9)).powi(2) - 1.0,
            EstimateModel::Rounded8 => 2f64.powi(-9),
            EstimateModel::Truncated8 => 2f64.powi(-8),
        }
    }
}

/// This thread's estimate model and the last division's refined reciprocal under it.
#[derive(Clone, Copy)]
struct EstimateState {
    model: EstimateModel,
    /// (divisor bits, round toward zero, refined reciprocal) of the last division: the reciprocal depends on
    /// nothing else, and the firmware's divisors come in runs (`/ two` four times per quaternion derivative,
    /// `/ mo` four times per normalisation): about two thirds of its divisions repeat the previous divisor.
    /// NaN bits (never a canonical value) when empty.
    last_reciprocal: (u32, bool, f32),
}

impl EstimateState {
    const fn new(model: EstimateModel) -> Self {
        EstimateState { model, last_reciprocal: (f32::NAN.to_bits(), false, f32::NAN) }
    }
}

thread_local! {
    /// The estimate state of this thread. A thread-local, because operators have no context argument and the
    /// model is a per-run experiment setting, not part of a value.
    static ESTIMATE: Cell<EstimateState> = const { Cell::new(EstimateState::new(EstimateModel::Table8)) };
}

/// The estimate model in force on this thread.
pub fn estimate_model() -> EstimateModel {
    ESTIMATE.with(Cell::get).model
}

/// Run `f` with `model` as this thread's estimate model; the previous model is restored afterwards, also
/// when `f` unwinds.
pub fn with_estimate_model<R>(model: EstimateModel, f: impl FnOnce() -> R) -> R {
    super::with_setting(&ESTIMATE, EstimateState::new(model), f)
}

/// `b`'s refined reciprocal under this thread's model, reused when `b` was the last divisor (same mode).
#[inline(always)]
fn remembered_reciprocal<const RZ: bool>(b: f32) -> f32 {
    ESTIMATE.with(|state| {
        let current = state.get();
        let (bits, rz, ye) = current.last_reciprocal;
        if bits == b.to_bits() && rz == RZ {
            return ye;
        }
        let ye = refined_reciprocal::<RZ>(b, current.model);
        state.set(EstimateState { last_reciprocal: (b.to_bits(), RZ, ye), ..current });
        ye
    })
}

/// An f32 as the C28x FPU holds it; `RZ` selects round toward zero (else round to nearest even).
/// The wrapped value is always canonical (no NaN, no subnormal, no −0), so derived comparisons are the
/// FPU's `CMPF32`.
#[derive(Clone, Copy, PartialEq, PartialOrd, Default)]
#[repr(transparent)]
pub struct C28xF32<const RZ: bool>(f32);

/// C28x single precision, round to nearest even (RND32 = 1, compiled C).
pub type C28xF32Rn = C28xF32<false>;
/// C28x single precision, round toward zero (RND32 = 0, the reset value).
pub type C28xF32Rz = C28xF32<true>;

impl<const RZ: bool> fmt::Debug for C28xF32<RZ> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}{}", self.0, if RZ { "_rz" } else { "_rn" })
    }
}

impl<const RZ: bool> C28xF32<RZ> {
    /// An f32 as the FPU would load it: subnormals and −0 become +0, NaN becomes +∞.
    #[inline]
    pub fn new(x: f32) -> Self {
        C28xF32(canonical(x, false))
    }

    f32_target!(bits);

    /// `EINVF32`: the hardware reciprocal estimate under the thread's [`EstimateModel`].
    #[inline]
    pub fn einvf32(self) -> Self {
        C28xF32(recip_estimate(self.0, estimate_model()))
    }

    /// `EISQRTF32`: the hardware 1/√x estimate under the thread's [`EstimateModel`].
    #[inline]
    pub fn eisqrtf32(self) -> Self {
        C28xF32(isqrt_estimate(self.0, estimate_model()))
    }

    /// fastRTS `isqrt`: 1/√x as `EISQRTF32` plus the two Newton–Raphson steps of `sqrt`, without the final
    /// multiplication (x = 0 gives +∞, the estimate of 0).
    #[inline]
    pub fn isqrt(self) -> Self {
        C28xF32(isqrt_refined::<RZ>(self.0, estimate_model()))
    }
}

/// Flush a subnormal or −0 to +0; ∞ and normals pass.
#[inline(always)]
fn flush(x: f32) -> f32 {
    if x.abs() < f32::MIN_POSITIVE {
        0.0
    } else {
        x
    }
}

/// The FPU's replacement for an IEEE NaN: ∞ with the given sign.
#[inline(always)]
fn invalid(negative: bool) -> f32 {
    if negative {
        f32::NEG_INFINITY
    } else {
        f32::INFINITY
    }
}

/// The next f32 toward zero from a nonzero `r` (∞ → ±MAX).
#[inline(always)]
fn step_toward_zero(r: f32) -> f32 {
    f32::from_bits(r.to_bits() - 1)
}

/// Round the exact real `hi + lo` to f32, where `hi` is that real rounded to nearest in f64 and `lo` the
/// exact remainder. Round to nearest: `hi as f32` equals the directly rounded result because f64 carries
/// more than 2·24+2 bits (double rounding is innocuous for +, −, ×). Round toward zero: truncate `hi`, and
/// step once more toward zero if `hi` itself is an f32 and the remainder points toward zero.
#[inline(always)]
fn round_f64<const RZ: bool>(hi: f64, lo: f64) -> f32 {
    let r = hi as f32;
    if !RZ || !hi.is_finite() {
        return r;
    }
    let back = r as f64;
    let overshoots = back.abs() > hi.abs();
    let remainder_inward = back == hi && lo != 0.0 && (lo > 0.0) != (hi > 0.0);
    if overshoots || remainder_inward {
        step_toward_zero(r)
    } else {
        r
    }
}

/// A rounded result made canonical: NaN becomes ∞ with the sign `negative_if_invalid` (see module docs),
/// subnormals and ±0 become +0. One comparison serves the usual case: `|r| ≥ MIN_POSITIVE` is false for
/// NaN, zeros and subnormals alike, and true for normals and ±∞, which pass unchanged.
#[inline(always)]
fn canonical(r: f32, negative_if_invalid: bool) -> f32 {
    if r.abs() >= f32::MIN_POSITIVE {
        r
    } else if r.is_nan() {
        invalid(negative_if_invalid)
    } else {
        0.0
    }
}

/// `a + b` rounded in the mode, before canonicalisation (may be NaN or subnormal).
#[inline(always)]
fn rounded_add<const RZ: bool>(a: f32, b: f32) -> f32 {
    if RZ {
        let (x, y) = (a as f64, b as f64);
        let s = x + y;
        // TwoSum: x + y = s + err exactly (err is NaN only for infinite inputs, where s decides).
        let bb = s - x;
        let err = (x - (s - bb)) + (y - bb);
        round_f64::<true>(s, err)
    } else {
        a + b
    }
}

/// `a · b` rounded in the mode, before canonicalisation (may be NaN or subnormal).
#[inline(always)]
fn rounded_mul<const RZ: bool>(a: f32, b: f32) -> f32 {
    if RZ {
        round_f64::<true>(a as f64 * b as f64, 0.0)
    } else {
        a * b
    }
}

/// `ADDF32` on canonical operands.
#[inline(always)]
fn add<const RZ: bool>(a: f32, b: f32) -> f32 {
    canonical(rounded_add::<RZ>(a, b), a < 0.0)
}

/// `SUBF32` on canonical operands.
#[inline(always)]
fn sub<const RZ: bool>(a: f32, b: f32) -> f32 {
    // −b is exact, and the ∞ − ∞ sign rule (first operand) is the same as for a + (−b).
    add::<RZ>(a, -b)
}

/// `MPYF32` on canonical operands.
#[inline(always)]
fn mul<const RZ: bool>(a: f32, b: f32) -> f32 {
    canonical(rounded_mul::<RZ>(a, b), (a < 0.0) != (b < 0.0))
}

/// `NEGF32` (−0 stays +0).
#[inline(always)]
fn neg(a: f32) -> f32 {
    flush(-a)
}

/// Round a positive normal f64 to `FRACTION_BITS` fraction bits, to nearest (ties away) or truncating.
#[inline(always)]
fn round_fraction(v: f64, nearest: bool) -> f64 {
    const DROP: u32 = 52 - ESTIMATE_FRACTION_BITS;
    let bits = v.to_bits();
    let bits = if nearest { bits + (1 << (DROP - 1)) } else { bits };
    f64::from_bits(bits & !((1u64 << DROP) - 1))
}

/// Fraction bits of a modelled hardware estimate ("≈ 8-bit estimate").
const ESTIMATE_FRACTION_BITS: u32 = 8;

/// Entries of the modelled estimate ROM (`EstimateModel::Table8`).
const TABLE_ENTRIES: usize = 1 << ESTIMATE_FRACTION_BITS;

/// The `Table8` ROM: for each interval of the top 8 fraction bits of the input, the function at the
/// interval's midpoint, scaled into [1, 2] and rounded to 8 fraction bits. Built once, on first use.
struct EstimateRom {
    /// 2/c for each interval's midpoint c ∈ [1, 2); every entry lies in [1, 2). Held as f32 (9 significant
    /// bits: exact) for the division's fast path ([`recip_estimate_normal`]).
    recip: [f32; TABLE_ENTRIES],
    /// 2/√c for c = the mantissa midpoint (even exponent) or twice it (odd exponent).
    isqrt: [[f64; TABLE_ENTRIES]; 2],
}

impl EstimateRom {
    fn build() -> EstimateRom {
        let midpoint = |index: usize| 1.0 + (index as f64 + 0.5) / TABLE_ENTRIES as f64;
        EstimateRom {
            recip: std::array::from_fn(|i| round_fraction(2.0 / midpoint(i), true) as f32),
            isqrt: [1.0, 2.0]
                .map(|scale| std::array::from_fn(|i| round_fraction(2.0 / (midpoint(i) * scale).sqrt(), true))),
        }
    }

    fn get() -> &'static EstimateRom {
        static ROM: OnceLock<EstimateRom> = OnceLock::new();
        ROM.get_or_init(EstimateRom::build)
    }
}

/// The ROM index of an f32: its top `ESTIMATE_FRACTION_BITS` fraction bits.
#[inline(always)]
fn table_index(x: f32) -> usize {
    ((x.to_bits() & 0x007F_FFFF) >> (23 - ESTIMATE_FRACTION_BITS)) as usize
}

/// Unbiased exponent of a normal f32.
#[inline(always)]
fn exponent(x: f32) -> i32 {
    ((x.to_bits() >> 23) & 0xFF) as i32 - 127
}

/// Modelled `EINVF32` on a canonical input: 1/0 = +∞ (−0 is +0), 1/±∞ = 0, tiny results flushed.
fn recip_estimate(b: f32, model: EstimateModel) -> f32 {
    if b == 0.0 {
        return f32::INFINITY;
    }
    if b.is_infinite() {
        return 0.0;
    }
    let magnitude = match model {
        EstimateModel::Table8 => EstimateRom::get().recip[table_index(b)] as f64 * 0.5 * pow2(-exponent(b)),
        EstimateModel::Rounded8 => round_fraction(1.0 / (b.abs() as f64), true),
        EstimateModel::Truncated8 => round_fraction(1.0 / (b.abs() as f64), false),
    };
    // The estimate has 9 significant bits: the conversion is exact unless it underflows (then flushed).
    let e = flush(magnitude as f32);
    if b < 0.0 {
        -e
    } else {
        e
    }
}

/// Modelled `EISQRTF32` on a canonical input: x = 0 → +∞, x < 0 → +∞ (IEEE NaN, treated as ∞), +∞ → 0.
fn isqrt_estimate(x: f32, model: EstimateModel) -> f32 {
    if x <= 0.0 {
        return f32::INFINITY;
    }
    if x.is_infinite() {
        return 0.0;
    }
    let e = match model {
        EstimateModel::Table8 => {
            // x = m·2^E; with an odd E the table covers 2m ∈ [2, 4) and E − 1 is even.
            let exp = exponent(x);
            let odd = exp.rem_euclid(2);
            EstimateRom::get().isqrt[odd as usize][table_index(x)] * 0.5 * pow2(-(exp - odd) / 2)
        }
        EstimateModel::Rounded8 => round_fraction(1.0 / (x as f64).sqrt(), true),
        EstimateModel::Truncated8 => round_fraction(1.0 / (x as f64).sqrt(), false),
    };
    flush(e as f32)
}

/// The two Newton–Raphson steps of fastRTS `sqrt`/`isqrt`, in TI's association order.
#[inline(always)]
fn isqrt_refined<const RZ: bool>(x: f32, model: EstimateModel) -> f32 {
    let mut ye = isqrt_estimate(x, model);
    let half_x = mul::<RZ>(x, 0.5);
    let t = mul::<RZ>(mul::<RZ>(ye, ye), half_x);
    ye = mul::<RZ>(ye, sub::<RZ>(1.5, t));
    let t = mul::<RZ>(ye, mul::<RZ>(ye, half_x));
    mul::<RZ>(ye, sub::<RZ>(1.5, t))
}

/// fastRTS `FS$$DIV`.
#[inline(always)]
fn div<const RZ: bool>(a: f32, b: f32, model: EstimateModel) -> f32 {
    divide_by_reciprocal::<RZ>(a, b, || refined_reciprocal::<RZ>(b, model))
}

/// fastRTS `FS$$DIV` given how to obtain B's refined reciprocal (not needed for a zero dividend).
#[inline(always)]
fn divide_by_reciprocal<const RZ: bool>(a: f32, b: f32, reciprocal: impl FnOnce() -> f32) -> f32 {
    if a == 0.0 {
        return 0.0;
    }
    let a = if b == 0.0 { neg(a) } else { a };
    mul::<RZ>(a, reciprocal())
}

/// Divisors whose reciprocal refinement cannot leave the normal range: 2⁻¹²⁶ ≤ |b| < 2¹²⁵.
const RECIPROCAL_STAYS_NORMAL: std::ops::Range<f32> = f32::MIN_POSITIVE..f32::from_bits((125 + 127) << 23);

/// `FS$$DIV`'s reciprocal: the `EINVF32` estimate refined by two Newton–Raphson steps.
///
/// Fast path, bit-identical: for 2⁻¹²⁶ ≤ |B| < 2¹²⁵ no intermediate needs canonicalising. The estimate is
/// within a factor 1 ± 2⁻⁸·(1 + 2⁻¹⁰) of 1/|B| for every model ([`EstimateModel::max_relative_error`]),
/// and a step only shrinks that error (e₁ ≤ e₀² + 4u), so `Ye·B` and `2 − Ye·B` stay within 1 ± 2⁻⁷ and
/// `Ye` within (1 ± 2⁻⁷)/|B| ⊂ (2⁻¹²⁶, 2¹²⁷): all normal and finite, where `canonical` is the identity.
/// Other divisors (0, ±∞, the extremes) take the checked operations.
///
/// Not inlined: a division by the last divisor skips it ([`remembered_reciprocal`]), and that short path is
/// what the firmware's code should inline (measured: inlining this too costs ≈ 1 000 instructions per cycle).
#[inline(never)]
fn refined_reciprocal<const RZ: bool>(b: f32, model: EstimateModel) -> f32 {
    if RECIPROCAL_STAYS_NORMAL.contains(&b.abs()) {
        let step = |ye: f32| rounded_mul::<RZ>(ye, rounded_add::<RZ>(2.0, -rounded_mul::<RZ>(ye, b)));
        step(step(recip_estimate_normal(b, model)))
    } else {
        newton_reciprocal_checked::<RZ>(recip_estimate(b, model), b)
    }
}

/// [`recip_estimate`] for |b| in [`RECIPROCAL_STAYS_NORMAL`], where the estimate is normal and no special
/// case applies. `Table8` in f32: the ROM entry e ∈ [1, 2) times 2^(−1−E) (E = b's exponent, −126…124) is
/// exact and normal, the same value as the general path's f64 product converted to f32.
#[inline(always)]
fn recip_estimate_normal(b: f32, model: EstimateModel) -> f32 {
    match model {
        EstimateModel::Table8 => {
            let scale = f32::from_bits(((126 - exponent(b)) as u32) << 23); // 2^(−1−E)
            (EstimateRom::get().recip[table_index(b)] * scale).copysign(b)
        }
        _ => recip_estimate(b, model),
    }
}

/// Two steps `Ye = Ye·(2 − Ye·B)`, every operation canonicalised as the FPU stores it.
#[inline(always)]
fn newton_reciprocal_checked<const RZ: bool>(ye: f32, b: f32) -> f32 {
    let step = |ye: f32| mul::<RZ>(ye, sub::<RZ>(2.0, mul::<RZ>(ye, b)));
    step(step(ye))
}

/// fastRTS `sqrt`.
#[inline(always)]
fn sqrt<const RZ: bool>(x: f32, model: EstimateModel) -> f32 {
    if x == 0.0 {
        return 0.0;
    }
    mul::<RZ>(x, isqrt_refined::<RZ>(x, model))
}

/// A library result computed in f64, rounded once in the mode (fastRTS accuracy, see module docs).
#[inline(always)]
fn from_library<const RZ: bool>(y: f64) -> C28xF32<RZ> {
    C28xF32::new(round_f64::<RZ>(y, 0.0))
}

/// `$trait` by the FPU operation of the same name in the mode (`add`, `sub`, `mul` above).
macro_rules! binop {
    ($trait:ident, $method:ident) => {
        impl<const RZ: bool> $trait for C28xF32<RZ> {
            type Output = Self;
            #[inline]
            fn $method(self, rhs: Self) -> Self {
                C28xF32($method::<RZ>(self.0, rhs.0))
            }
        }
    };
}

binop!(Add, add);
binop!(Sub, sub);
binop!(Mul, mul);

impl<const RZ: bool> Div for C28xF32<RZ> {
    type Output = Self;
    #[inline]
    fn div(self, rhs: Self) -> Self {
        C28xF32(divide_by_reciprocal::<RZ>(self.0, rhs.0, || remembered_reciprocal::<RZ>(rhs.0)))
    }
}

impl<const RZ: bool> Neg for C28xF32<RZ> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        C28xF32(neg(self.0))
    }
}

impl<const RZ: bool> Scalar for C28xF32<RZ> {
    const NAME: &'static str = if RZ { "c28x-f32-rz" } else { "c28x-f32" };

    /// The compiler rounds constants to nearest whatever RND32 says.
    #[inline]
    fn from_f64(x: f64, _: QClass) -> Self {
        C28xF32::new(x as f32)
    }
    /// `I32TOF32` rounds in the mode.
    #[inline]
    fn from_i32(x: i32, _: QClass) -> Self {
        C28xF32::new(round_f64::<RZ>(x as f64, 0.0))
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self.0 as f64
    }
    #[inline]
    fn sqrt(self) -> Self {
        C28xF32(sqrt::<RZ>(self.0, estimate_model()))
    }
    f32_target!(library);
    #[inline]
    fn abs(self) -> Self {
        C28xF32(self.0.abs())
    }
}

/// Accuracy of the modelled fastRTS division and square root against the exact result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FastRtsAccuracy {
    /// Largest |computed − exact| in ulps of the exact result, division.
    pub div_max_ulp: f64,
    /// Largest error in ulps, square root.
    pub sqrt_max_ulp: f64,
    /// Fraction of divisions not equal to the correctly rounded (in the mode) quotient.
    pub div_not_correctly_rounded: f64,
    /// Fraction of square roots not equal to the correctly rounded root.
    pub sqrt_not_correctly_rounded: f64,
}

/// |computed − exact| in units of the last place of `exact` (an f32 ulp at `exact`'s binade).
pub fn ulp_error(computed: f32, exact: f64) -> f64 {
    let binade = ((exact.abs().to_bits() >> 52) as i32) - 1023;
    (computed as f64 - exact).abs() / pow2(binade - 23)
}

/// Measure the modelled fastRTS division and sqrt under `model` over `samples` random operands (mantissas
/// uniform, exponents uniform in [−20, 20], signs random for division, seeded by `seed`). The exact result
/// is the f64 quotient/root, whose own error (≤ 2⁻⁵³ relative) is negligible at f32 ulp scale.
pub fn fastrts_accuracy<const RZ: bool>(model: EstimateModel, samples: usize, seed: u64) -> FastRtsAccuracy {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut random = |signed: bool| {
        let m: f32 = rng.gen_range(1.0f32..2.0);
        let e: i32 = rng.gen_range(-20..=20);
        let x = m * pow2(e) as f32;
        if signed && rng.gen::<bool>() {
            -x
        } else {
            x
        }
    };
    let mut acc = FastRtsAccuracy {
        div_max_ulp: 0.0,
        sqrt_max_ulp: 0.0,
        div_not_correctly_rounded: 0.0,
        sqrt_not_correctly_rounded: 0.0,
    };
    let (mut div_wrong, mut sqrt_wrong) = (0usize, 0usize);
    for _ in 0..samples {
        let (a, b) = (random(true), random(true));
        let exact = a as f64 / b as f64;
        let q = div::<RZ>(a, b, model);
        acc.div_max_ulp = acc.div_max_ulp.max(ulp_error(q, exact));
        // The f64 quotient is not exact, but RN/RZ of it equals RN/RZ of the real quotient except when the
        // real quotient lies within 2⁻⁵³ of an f32 boundary; no f32 quotient of f32s does (it would need a
        // 78-bit numerator), so this comparison is sound.
        div_wrong += usize::from(q != round_f64::<RZ>(exact, 0.0));
        let x = random(false);
        let exact = (x as f64).sqrt();
        let r = sqrt::<RZ>(x, model);
        acc.sqrt_max_ulp = acc.sqrt_max_ulp.max(ulp_error(r, exact));
        sqrt_wrong += usize::from(r != round_f64::<RZ>(exact, 0.0));
    }
    let n = samples.max(1) as f64;
    acc.div_not_correctly_rounded = div_wrong as f64 / n;
    acc.sqrt_not_correctly_rounded = sqrt_wrong as f64 / n;
    acc
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    type Rn = C28xF32Rn;
    type Rz = C28xF32Rz;

    fn rn(x: f32) -> Rn {
        Rn::new(x)
    }
    fn rz(x: f32) -> Rz {
        Rz::new(x)
    }
    const ULP1: f32 = f32::EPSILON; // 2⁻²³, the ulp of 1.0

    #[test]
    fn rounding_modes_on_known_cases() {
        // 1 + ½ulp: a tie, to even (1) in RN; truncated in RZ.
        let half = ULP1 / 2.0;
        assert_eq!((rn(1.0) + rn(half)).value(), 1.0);
        assert_eq!((rz(1.0) + rz(half)).value(), 1.0);
        // 1 + ¾ulp: up in RN, down in RZ; mirrored for negatives (RZ goes toward zero, i.e. up).
        let three_quarters = 3.0 * ULP1 / 4.0;
        assert_eq!((rn(1.0) + rn(three_quarters)).value(), 1.0 + ULP1);
        assert_eq!((rz(1.0) + rz(three_quarters)).value(), 1.0);
        assert_eq!((rn(-1.0) - rn(three_quarters)).value(), -1.0 - ULP1);
        assert_eq!((rz(-1.0) - rz(three_quarters)).value(), -1.0);
        // (1+ulp) + ½ulp: tie between 1+ulp (odd) and 1+2ulp (even): RN picks even.
        assert_eq!((rn(1.0 + ULP1) + rn(half)).value(), 1.0 + 2.0 * ULP1);
        assert_eq!((rz(1.0 + ULP1) + rz(half)).value(), 1.0 + ULP1);
        // A remainder far below the f64 sum's precision still decides RZ: 1 − 2⁻⁶⁰ truncates to 1 − 2⁻²⁴.
        let tiny = 2f32.powi(-60);
        assert_eq!((rz(1.0) - rz(tiny)).value(), 1.0 - ULP1 / 2.0);
        assert_eq!((rn(1.0) - rn(tiny)).value(), 1.0);
        // 3·(1+ulp) = 3 + 1.5 ulp(3): RN up to 3 + 2ulp(3), RZ down to 3 + ulp(3).
        let ulp3 = 2.0 * ULP1;
        assert_eq!((rn(3.0) * rn(1.0 + ULP1)).value(), 3.0 + 2.0 * ulp3);
        assert_eq!((rz(3.0) * rz(1.0 + ULP1)).value(), 3.0 + ulp3);
        assert_eq!((rz(-3.0) * rz(1.0 + ULP1)).value(), -(3.0 + ulp3));
        // I32TOF32 in the mode: 2²⁴+1 is a tie in RN (to even 2²⁴); 2²⁴+3 is up in RN, down in RZ.
        assert_eq!(Rn::from_i32((1 << 24) + 1, QClass::Generic).value(), 16_777_216.0);
        assert_eq!(Rn::from_i32((1 << 24) + 3, QClass::Generic).value(), 16_777_220.0);
        assert_eq!(Rz::from_i32((1 << 24) + 3, QClass::Generic).value(), 16_777_218.0);
        assert_eq!(Rz::from_i32(-((1 << 24) + 3), QClass::Generic).value(), -16_777_218.0);
        // from_f64 rounds to nearest like the compiler, whatever the mode.
        let x = 1.0 + 0.75 * f32::EPSILON as f64;
        assert_eq!(Rz::from_f64(x, QClass::Generic).value(), 1.0 + ULP1);
    }

    #[test]
    fn overflow_per_mode() {
        assert_eq!((rn(f32::MAX) + rn(f32::MAX)).value(), f32::INFINITY);
        assert_eq!((rz(f32::MAX) + rz(f32::MAX)).value(), f32::MAX);
        assert_eq!((rz(-f32::MAX) * rz(4.0)).value(), -f32::MAX);
        assert_eq!((rz(f32::INFINITY) + rz(1.0)).value(), f32::INFINITY);
    }

    /// Scale of the RZ oracle: every operand and result below is an integer multiple of 2⁻⁷⁶ (operands have
    /// exponents in [−30, 30], so their sums are multiples of 2⁻⁵³, and a nonzero result or its neighbour has
    /// an exponent ≥ −53, i.e. an ulp ≥ 2⁻⁷⁶), and below 2³²·2⁷⁶ = 2¹⁰⁸ in scaled units: i128 is exact.
    const ORACLE_SHIFT: i32 = 53;

    /// A finite f32 as an exact integer multiple of 2⁻⁷⁶.
    fn scaled(x: f32) -> i128 {
        if x == 0.0 {
            return 0;
        }
        let shift = exponent(x) + ORACLE_SHIFT;
        assert!((0..100).contains(&shift), "{x:e} outside the oracle's range");
        let v = (((x.to_bits() & 0x7F_FFFF) | 0x80_0000) as i128) << shift;
        if x < 0.0 {
            -v
        } else {
            v
        }
    }

    #[test]
    fn randomized_rn_is_native_and_rz_truncates() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x28335);
        let random = |rng: &mut rand_chacha::ChaCha8Rng| {
            let m: f32 = rng.gen_range(1.0f32..2.0);
            // Exponents within ±30 keep the i128 oracle exact (see ORACLE_SHIFT) and results normal.
            let x = m * pow2(rng.gen_range(-30..=30)) as f32;
            if rng.gen::<bool>() {
                -x
            } else {
                x
            }
        };
        for _ in 0..200_000 {
            let (a, b) = (random(&mut rng), random(&mut rng));
            // Round to nearest: bit-identical to the host's IEEE f32 (also RN) for normal results.
            for (got, want) in [((rn(a) + rn(b)).value(), a + b), ((rn(a) - rn(b)).value(), a - b)] {
                assert_eq!(got.to_bits(), flush(want).to_bits(), "{a:e} ± {b:e}");
            }
            assert_eq!((rn(a) * rn(b)).value().to_bits(), (a * b).to_bits(), "{a:e} × {b:e}");
            // The shared rounding path in RN mode agrees with native too (TwoSum + f64→f32).
            let s = a as f64 + b as f64;
            assert_eq!(round_f64::<false>(s, 0.0).to_bits(), (a + b).to_bits());
            // Round toward zero, sum: |r| ≤ |exact| < |next(r) away from zero|, same sign (integer oracle).
            let r = (rz(a) + rz(b)).value();
            let exact = scaled(a) + scaled(b);
            if r != 0.0 {
                let away = f32::from_bits(r.to_bits() + 1);
                assert!(scaled(r).abs() <= exact.abs() && exact.abs() < scaled(away).abs(), "{a:e} + {b:e} → {r:e}");
                assert_eq!(r < 0.0, exact < 0, "{a:e} + {b:e}");
            } else {
                assert!(exact.abs() < scaled(f32::MIN_POSITIVE), "{a:e} + {b:e} → 0");
            }
            // Round toward zero, product: the f64 product is exact.
            let p = a as f64 * b as f64;
            let r = (rz(a) * rz(b)).value() as f64;
            let away = f32::from_bits((r as f32).to_bits() + 1) as f64;
            assert!(r.abs() <= p.abs() && p.abs() < away.abs() && (r < 0.0) == (p < 0.0), "{a:e} × {b:e}");
            // RN and RZ differ by at most one ulp, and RZ never has the larger magnitude.
            let (n, z) = ((rn(a) * rn(b)).value(), (rz(a) * rz(b)).value());
            assert!(z.abs() <= n.abs() && n.to_bits() - z.to_bits() <= 1);
        }
    }

    #[test]
    fn flush_to_zero_and_negative_zero() {
        let sub = f32::MIN_POSITIVE / 4.0; // a subnormal
        assert_eq!(rn(sub).value().to_bits(), 0);
        assert_eq!(rn(-0.0).value().to_bits(), 0, "−0 is stored as +0");
        assert_eq!(Rn::from_bits(0x8000_0000).to_bits(), 0);
        assert_eq!(Rn::from_bits(0x0000_0001).to_bits(), 0, "subnormal input from memory");
        // A normal operand with a subnormal result flushes; a subnormal input behaves as zero.
        assert_eq!((rn(f32::MIN_POSITIVE) * rn(0.5)).to_bits(), 0);
        assert_eq!((rz(f32::MIN_POSITIVE) * rz(0.5)).to_bits(), 0);
        assert_eq!((rn(1.5 * f32::MIN_POSITIVE) - rn(f32::MIN_POSITIVE)).to_bits(), 0);
        assert_eq!((rn(1.0) + Rn::from_bits(1)).value(), 1.0);
        // x − x and −(+0) are +0 in both modes.
        assert_eq!((rn(2.5) - rn(2.5)).to_bits(), 0);
        assert_eq!((rz(-2.5) + rz(2.5)).to_bits(), 0);
        assert_eq!((-rn(0.0)).to_bits(), 0);
        assert_eq!((rn(-3.0) * rn(0.0)).to_bits(), 0);
        // −0 compares equal to +0, and nothing is NaN.
        assert!(rn(-0.0) == rn(0.0));
        assert_eq!(rn(f32::NAN).value(), f32::INFINITY);
    }

    #[test]
    fn nan_becomes_signed_infinity() {
        assert_eq!((rn(f32::INFINITY) * rn(0.0)).value(), f32::INFINITY);
        assert_eq!((rn(f32::NEG_INFINITY) * rn(0.0)).value(), f32::NEG_INFINITY);
        assert_eq!((rz(f32::INFINITY) - rz(f32::INFINITY)).value(), f32::INFINITY);
        assert_eq!((rn(f32::NEG_INFINITY) + rn(f32::INFINITY)).value(), f32::NEG_INFINITY);
    }

    #[test]
    fn division_special_cases() {
        for model in EstimateModel::ALL {
            with_estimate_model(model, || {
                assert_eq!((rn(0.0) / rn(0.0)).to_bits(), 0, "0/0 = 0 as fastRTS");
                assert_eq!((rn(0.0) / rn(3.0)).to_bits(), 0);
                assert_eq!((rn(5.0) / rn(0.0)).value(), f32::INFINITY, "A/0 keeps A's sign");
                assert_eq!((rn(-5.0) / rn(0.0)).value(), f32::NEG_INFINITY);
                assert_eq!((rz(-5.0) / rz(-0.0)).value(), f32::NEG_INFINITY, "−0 is +0");
                assert_eq!((rn(6.0) / rn(-3.0)).value(), -2.0);
                assert_eq!(rn(0.0).sqrt().to_bits(), 0);
                assert_eq!(rz(0.0).sqrt().to_bits(), 0);
                assert_eq!(rn(-4.0).sqrt().value(), f32::NEG_INFINITY, "documented model consequence");
                assert_eq!(rn(4.0).sqrt().value(), 2.0);
                assert_eq!(rn(0.0).isqrt().value(), f32::INFINITY);
            });
        }
    }

    /// Canonical f32s that probe the fast paths' edges: zero, the normal range's ends, the fast ranges'
    /// bounds and their neighbours, every power of two, ±∞, each with both signs.
    fn edge_values() -> Vec<f32> {
        let mut v = vec![0.0, f32::MIN_POSITIVE, f32::MAX, f32::INFINITY, 1.0, 1.5, 2.0, 3.0, 6.0, 0.1];
        v.extend((-126..=127).map(|k| pow2(k) as f32));
        for bound in [f32::MIN_POSITIVE, RECIPROCAL_STAYS_NORMAL.end, f32::MAX] {
            v.extend((-3..=3).map(|d: i32| f32::from_bits(bound.to_bits().saturating_add_signed(d))));
        }
        let negated: Vec<f32> = v.iter().map(|x| -x).collect();
        v.extend(negated);
        v.into_iter().map(|x| C28xF32Rn::new(x).value()).collect()
    }

    /// Random canonical f32s: uniform bit patterns (every exponent, as often), canonicalised.
    fn random_bit_patterns(n: usize, seed: u64) -> Vec<f32> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        (0..n).map(|_| C28xF32Rn::from_bits(rng.gen()).value()).collect()
    }

    #[test]
    fn canonical_is_nan_to_infinity_then_flush() {
        // The one-comparison form against the rule written out, over raw results of every class: random bit
        // patterns (NaNs, subnormals, both zeros, normals, infinities) and the class boundaries.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0xCA90);
        let boundaries =
            [0, 1, 0x007F_FFFF, 0x0080_0000, 0x0080_0001, 0x7F7F_FFFF, 0x7F80_0000, 0x7F80_0001, 0x7FC0_0000];
        let patterns = boundaries.into_iter().flat_map(|b: u32| [b, b | 0x8000_0000]);
        for bits in patterns.chain((0..1_000_000).map(|_| rng.gen::<u32>())) {
            let r = f32::from_bits(bits);
            for negative in [false, true] {
                let want = if r.is_nan() { invalid(negative) } else { flush(r) };
                assert_eq!(canonical(r, negative).to_bits(), want.to_bits(), "{bits:#010x}");
            }
        }
    }

    #[test]
    fn reciprocal_fast_path_equals_the_checked_steps() {
        // Every divisor: the fast path (f32 estimate, unchecked steps where they cannot leave the normal range)
        // against the general estimate and the checked steps, bit for bit, in both modes and for every model;
        // also the whole division.
        let mut divisors = edge_values();
        divisors.extend(random_bit_patterns(200_000, 0xD1F));
        // Every ROM cell near 1, and near the fast range's upper end.
        divisors.extend((0..1 << 10).map(|i| 1.0 + i as f32 * 2f32.powi(-10)));
        divisors.extend((0..1 << 10).map(|i| RECIPROCAL_STAYS_NORMAL.end * (0.5 + i as f32 * 2f32.powi(-10))));
        fn check<const RZ: bool>(model: EstimateModel, b: f32) {
            let want = newton_reciprocal_checked::<RZ>(recip_estimate(b, model), b);
            let got = refined_reciprocal::<RZ>(b, model);
            assert_eq!(got.to_bits(), want.to_bits(), "1/{b:e} ({model:?}, rz {RZ})");
            let a = 3.0f32;
            let want = mul::<RZ>(if b == 0.0 { neg(a) } else { a }, want);
            assert_eq!(div::<RZ>(a, b, model).to_bits(), want.to_bits(), "{a}/{b:e} ({model:?}, rz {RZ})");
        }
        for model in EstimateModel::ALL {
            for &b in &divisors {
                check::<false>(model, b);
                check::<true>(model, b);
            }
        }
    }

    #[test]
    fn remembered_reciprocal_equals_the_computed_one() {
        // The operator reuses the last divisor's reciprocal: against `div` computed afresh, with every divisor
        // repeated, both modes interleaved on the same divisor, and nested model changes.
        let mut divisors = edge_values();
        divisors.extend(random_bit_patterns(20_000, 0xBEEF));
        let a = 0.7f32;
        // Modes in the order RN, RZ, RZ, RN: a switch each way, a repeat, and the next check starts in the mode
        // this one ended in (so a reciprocal kept across a model change would be reused).
        let check = |model: EstimateModel, b: f32| {
            let rn_quotient = || {
                assert_eq!((rn(a) / Rn::new(b)).to_bits(), div::<false>(a, b, model).to_bits(), "{b:e} rn {model:?}")
            };
            let rz_quotient =
                || assert_eq!((rz(a) / Rz::new(b)).to_bits(), div::<true>(a, b, model).to_bits(), "{b:e} rz {model:?}");
            rn_quotient();
            rz_quotient();
            rz_quotient();
            rn_quotient();
        };
        let (mut modes_differ, mut models_differ) = (0, 0);
        for &b in &divisors {
            check(EstimateModel::Table8, b);
            modes_differ +=
                usize::from(div::<false>(a, b, EstimateModel::Table8) != div::<true>(a, b, EstimateModel::Table8));
            for model in EstimateModel::ALL {
                // Same divisor right after the outer model's division, then again after the scope ends.
                with_estimate_model(model, || check(model, b));
                check(EstimateModel::Table8, b);
                models_differ += usize::from(div::<false>(a, b, model) != div::<false>(a, b, EstimateModel::Table8));
            }
        }
        // The cases that would expose a stale reciprocal exist in the sample.
        assert!(modes_differ > 1000 && models_differ > 100, "{modes_differ} {models_differ}");
    }

    #[test]
    fn estimates_within_their_stated_error() {
        // Every 8-bit table cell is hit by stepping the mantissa by 2⁻¹⁶ over two binades (both parities).
        for model in EstimateModel::ALL {
            let bound = model.max_relative_error();
            let (mut worst_recip, mut worst_isqrt) = (0f64, 0f64);
            for i in 0..(2 << 16) {
                let x = 1.0 + i as f32 * 2f32.powi(-16);
                for x in [x, -x * 1024.0, x * 2f32.powi(-37)] {
                    let r = recip_estimate(x, model) as f64 * x as f64;
                    worst_recip = worst_recip.max((r - 1.0).abs());
                }
                for x in [x, x * 2f32.powi(-37), x * 2f32.powi(60)] {
                    let r = isqrt_estimate(x, model) as f64 * (x as f64).sqrt();
                    worst_isqrt = worst_isqrt.max((r - 1.0).abs());
                }
            }
            assert!(worst_recip <= bound, "{}: recip {worst_recip:e} > {bound:e}", model.name());
            assert!(worst_isqrt <= bound, "{}: isqrt {worst_isqrt:e} > {bound:e}", model.name());
            // The models are ≈ 8-bit: not much better than the bound either (guards against a silent
            // "exact" estimate that would hide the Newton–Raphson behaviour).
            assert!(worst_recip > bound / 4.0 && worst_isqrt > bound / 8.0, "{}", model.name());
        }
    }

    /// Bounds on the fastRTS error in ulps of the exact result, from the sequence's error analysis, with `u`
    /// the unit roundoff (RN: 2⁻²⁴, RZ: 2⁻²³, each rounding is x(1+ε), |ε| ≤ u) and `e0` the estimate's
    /// relative error. Second-order rounding terms are covered by 10u².
    ///
    /// Division, Ye = (1−e)/B: one step gives Ye(2 − Ye·B) = (1 − e²)/B exactly, so e₁ ≤ e₀² + u(3 + 2e₀). In
    /// the last step the rounding of `Ye·B` (≈ 1) enters with weight p/(2−p) ≤ 1 + 2e₁, then `2 − p`, `Ye·t`
    /// and `A·Ye` one u each: relative error ≤ u(4 + 2e₁) + e₁² + 10u².
    /// Square root, Ye = (1+e)/√X: a step gives (1 − 1.5e² − 0.5e³)/√X; `Ye·(X/2)` and `Ye·(Ye·X/2)` (≈ ½)
    /// enter `1.5 − t` (≈ 1) with weight ≈ ½(1 + 4e) each, then `1.5 − t`, `Ye·t`, `X·Ye`:
    /// e₁ ≤ 1.5e₀²(1+e₀) + 3.5u(1 + 4e₀), result ≤ 3.5u(1 + 4e₁) + 1.5e₁²(1+e₁) + 10u².
    /// The result's ulp is ≥ 2⁻²⁴ of its magnitude, so ulps ≤ relative error · 2²⁴.
    fn ulp_bounds(u: f64, e0: f64) -> (f64, f64) {
        let second_order = 10.0 * u * u;
        let e1 = e0 * e0 + u * (3.0 + 2.0 * e0) + second_order;
        let div_rel = u * (4.0 + 2.0 * e1) + e1 * e1 + second_order;
        let e1 = 1.5 * e0 * e0 * (1.0 + e0) + 3.5 * u * (1.0 + 4.0 * e0) + second_order;
        let sqrt_rel = 3.5 * u * (1.0 + 4.0 * e1) + 1.5 * e1 * e1 * (1.0 + e1) + second_order;
        (div_rel * 2f64.powi(24), sqrt_rel * 2f64.powi(24))
    }

    #[test]
    fn fastrts_error_bounds_per_model() {
        const SAMPLES: usize = 300_000;
        for model in EstimateModel::ALL {
            let e0 = model.max_relative_error();
            let (div_rn, sqrt_rn) = ulp_bounds(2f64.powi(-24), e0);
            let (div_rz, sqrt_rz) = ulp_bounds(2f64.powi(-23), e0);
            let n = fastrts_accuracy::<false>(model, SAMPLES, 7);
            let z = fastrts_accuracy::<true>(model, SAMPLES, 7);
            println!(
                "{:>10}: RN div {:.3} ulp (bound {div_rn:.3}, {:.2}% not CR), sqrt {:.3} ulp (bound {sqrt_rn:.3}, \
                 {:.2}%); RZ div {:.3} ulp (bound {div_rz:.3}, {:.2}%), sqrt {:.3} ulp (bound {sqrt_rz:.3}, {:.2}%)",
                model.name(),
                n.div_max_ulp,
                100.0 * n.div_not_correctly_rounded,
                n.sqrt_max_ulp,
                100.0 * n.sqrt_not_correctly_rounded,
                z.div_max_ulp,
                100.0 * z.div_not_correctly_rounded,
                z.sqrt_max_ulp,
                100.0 * z.sqrt_not_correctly_rounded,
            );
            assert!(n.div_max_ulp <= div_rn && n.sqrt_max_ulp <= sqrt_rn, "{model:?} RN {n:?}");
            assert!(z.div_max_ulp <= div_rz && z.sqrt_max_ulp <= sqrt_rz, "{model:?} RZ {z:?}");
            // Not correctly rounded, as the spec says (a model that always is would be suspicious).
            assert!(n.div_not_correctly_rounded > 0.0 && z.sqrt_not_correctly_rounded > 0.0);
        }
    }

    #[test]
    fn estimate_choice_changes_few_results() {
        // How much the unpublished table matters: the other models' results against Table8, bit for bit.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let n = 200_000;
        let others = [EstimateModel::Rounded8, EstimateModel::Truncated8];
        let mut differing = [[0usize; 2]; 2];
        let mut max_apart = 0u32;
        for _ in 0..n {
            let a: f32 = rng.gen_range(0.5f32..64.0);
            let b: f32 = rng.gen_range(0.5f32..64.0);
            let reference = (div::<false>(a, b, EstimateModel::Table8), sqrt::<false>(a, EstimateModel::Table8));
            for (k, model) in others.into_iter().enumerate() {
                let (q, r) = (div::<false>(a, b, model), sqrt::<false>(a, model));
                differing[k][0] += usize::from(q != reference.0);
                differing[k][1] += usize::from(r != reference.1);
                max_apart = max_apart.max(q.to_bits().abs_diff(reference.0.to_bits()));
                max_apart = max_apart.max(r.to_bits().abs_diff(reference.1.to_bits()));
            }
        }
        for (k, model) in others.into_iter().enumerate() {
            println!(
                "{:>10} vs table8: {:.3}% of quotients, {:.3}% of roots differ (max {max_apart} ulp apart)",
                model.name(),
                100.0 * differing[k][0] as f64 / n as f64,
                100.0 * differing[k][1] as f64 / n as f64
            );
        }
        // Both results lie within the RN bound of the exact value (≤ 4.01 ulp for the quotient), so they are
        // at most 2·4 ulp apart, plus one where the ulp changes at a binade boundary.
        let (div_bound, _) = ulp_bounds(2f64.powi(-24), EstimateModel::Table8.max_relative_error());
        assert!(max_apart as f64 <= 2.0 * div_bound.floor() + 1.0, "models {max_apart} ulp apart");
    }

    #[test]
    fn transcendentals_round_once_in_the_mode() {
        let x = 0.7f32;
        let exact = (x as f64).sin();
        assert_eq!(rn(x).sin().value(), exact as f32);
        let z = rz(x).sin().value() as f64;
        assert!(z <= exact && exact - z < f32::EPSILON as f64);
        assert_eq!(rn(1.0).atan2(rn(0.0)).value(), std::f32::consts::FRAC_PI_2);
        assert_eq!(rn(0.0).atan2(rn(0.0)).to_bits(), 0);
        assert_eq!(rn(2.0).asin().value(), std::f32::consts::FRAC_PI_2, "argument clamped");
        assert_eq!(rn(-2.5).abs().value(), 2.5);
        assert_eq!(Rn::NAME, "c28x-f32");
        assert_eq!(Rz::NAME, "c28x-f32-rz");
    }

    #[test]
    fn values_are_small_and_copy() {
        // The hot path must stay a plain f32 in registers: no heap, no padding, Copy.
        assert_eq!(std::mem::size_of::<Rn>(), 4);
        assert_eq!(std::mem::size_of::<Option<Rz>>(), 8);
        fn is_copy<T: Copy>() {}
        is_copy::<Rn>();
        is_copy::<Rz>();
    }

    /// The report's numbers: 5·10⁶ random divisions and roots per model and mode, plus every f32 in [1, 4)
    /// as a radicand (all mantissas, both exponent parities: exhaustive for sqrt up to scaling by 4^k).
    /// Run with `--ignored --nocapture`.
    #[test]
    #[ignore]
    fn measure_fastrts_large() {
        fn exhaustive_sqrt<const RZ: bool>(model: EstimateModel) -> (f64, f64) {
            let (mut worst, mut wrong, mut n) = (0f64, 0usize, 0usize);
            let mut bits = 1f32.to_bits();
            while bits < 4f32.to_bits() {
                let x = f32::from_bits(bits);
                let exact = (x as f64).sqrt();
                let r = sqrt::<RZ>(x, model);
                worst = worst.max(ulp_error(r, exact));
                wrong += usize::from(r != round_f64::<RZ>(exact, 0.0));
                n += 1;
                bits += 1;
            }
            (worst, wrong as f64 / n as f64)
        }
        for model in EstimateModel::ALL {
            let n = fastrts_accuracy::<false>(model, 5_000_000, 99);
            let z = fastrts_accuracy::<true>(model, 5_000_000, 99);
            let (sn, sn_wrong) = exhaustive_sqrt::<false>(model);
            let (sz, sz_wrong) = exhaustive_sqrt::<true>(model);
            println!(
                "{:>10}: RN div {:.3} ulp ({:.1}% not CR) sqrt {:.3} ulp ({:.1}%) exhaustive sqrt {sn:.3} ulp ({:.1}%) | \
                 RZ div {:.3} ulp ({:.1}%) sqrt {:.3} ulp ({:.1}%) exhaustive sqrt {sz:.3} ulp ({:.1}%)",
                model.name(),
                n.div_max_ulp,
                100.0 * n.div_not_correctly_rounded,
                n.sqrt_max_ulp,
                100.0 * n.sqrt_not_correctly_rounded,
                100.0 * sn_wrong,
                z.div_max_ulp,
                100.0 * z.div_not_correctly_rounded,
                z.sqrt_max_ulp,
                100.0 * z.sqrt_not_correctly_rounded,
                100.0 * sz_wrong,
            );
        }
    }

    /// Throughput of the model's operations (run with `--ignored --nocapture` in release for numbers).
    #[test]
    #[ignore]
    fn bench_ops() {
        use std::hint::black_box;
        use std::time::Instant;
        let n = 20_000_000u32;
        let mut native = 1.0f32;
        let t = Instant::now();
        for _ in 0..n {
            native = black_box(native * 1.000_001 + 1.000_001);
        }
        println!("native f32 mul+add: {:.2} ns/iter ({native})", t.elapsed().as_nanos() as f64 / n as f64);
        let mut acc = rn(1.0);
        let step = rn(1.000_001);
        let t = Instant::now();
        for _ in 0..n {
            acc = black_box(acc * step + step);
        }
        println!("rn mul+add: {:.2} ns/iter ({acc:?})", t.elapsed().as_nanos() as f64 / n as f64);
        let mut acc = rz(1.0);
        let t = Instant::now();
        for _ in 0..n {
            acc = black_box(acc * rz(1.000_001) + rz(1.000_001));
        }
        println!("rz mul+add: {:.2} ns/iter ({acc:?})", t.elapsed().as_nanos() as f64 / n as f64);
        let t = Instant::now();
        let mut acc = rn(2.0);
        for i in 0..n {
            acc = black_box(black_box(rn(i as f32 + 1.0)) / acc).sqrt() + rn(1.0);
        }
        println!("rn div+sqrt+add: {:.2} ns/iter ({acc:?})", t.elapsed().as_nanos() as f64 / n as f64);
    }
}
