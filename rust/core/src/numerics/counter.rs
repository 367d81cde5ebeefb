//! `Counted`: f64 values that tally every operation, so the timing model can cost each firmware stage
//! from what the generic algorithm actually executed (cycles per op come from the spec, not from here).
//!
//! Values and control flow are exactly those of f64 (every method forwards to the f64 implementation), so
//! the same branches are taken as in the golden reference. Tallies live in a thread-local (operators have
//! no context argument); [`count`] scopes them, [`snapshot`] reads the running tally for per-stage
//! differences. What counts as one operation:
//! - `+ − × ÷` and negation: one each; `sqrt`, `sin`, `cos`, `atan`, `atan2`, `asin`, `abs`: one each;
//! - comparisons: one per `==`/`!=` or `<`, `<=`, `>`, `>=`, `partial_cmp` (a `CMPF32` each);
//! - `from_i32`: an int→float conversion; `from_f64`: a constant (or input) loaded;
//! - `mul_i32`: what it is on the backend counted (see [`count_as`]): on a float target an int→float
//!   conversion and a multiplication (`(float)n * x`), on IQ one integer multiply `_IQmpyI32`;
//! - `div_to`, `mul_to`: a division, a multiplication (as `/`, `*`); `from_f64_range`: a constant;
//! - `to_f64` and `to_class` are free (no instruction on a float target).
//!
//! The generic firmware differs between float and fixed point where [`Scalar::fixed_point`] says so (the
//! decode's folded scale constant): [`count_as`] selects which firmware the counts are those of.

use super::{QClass, Scalar};
use std::cell::Cell;
use std::cmp::Ordering;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

/// Defines the operation kinds once: the `OpCounts` fields and their tally slots.
macro_rules! op_kinds {
    ($($(#[$doc:meta])* $field:ident),* $(,)?) => {
        /// Operations executed, by kind.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
        pub struct OpCounts {
            $($(#[$doc])* pub $field: u64,)*
        }

        #[allow(non_camel_case_types)]
        #[derive(Clone, Copy)]
        enum Op {
            $($field,)*
        }

        const KINDS: usize = [$(Op::$field),*].len();

        impl OpCounts {
            fn from_array(a: [u64; KINDS]) -> Self {
                OpCounts { $($field: a[Op::$field as usize],)* }
            }
            fn to_array(self) -> [u64; KINDS] {
                let mut a = [0; KINDS];
                $(a[Op::$field as usize] = self.$field;)*
                a
            }
        }
    };
}

op_kinds! {
    /// Additions.
    adds,
    /// Subtractions.
    subs,
    /// Multiplications.
    muls,
    /// Divisions.
    divs,
    /// Square roots.
    sqrts,
    /// Sines.
    sins,
    /// Cosines.
    coss,
    /// Arc tangents.
    atans,
    /// Four-quadrant arc tangents.
    atan2s,
    /// Arc sines.
    asins,
    /// Absolute values.
    abs,
    /// Negations.
    negs,
    /// Comparisons (`==`, `<`, … each one).
    comparisons,
    /// Integer → float conversions.
    int_to_float,
    /// Constants (and inputs) loaded with `from_f64`.
    constants,
    /// Integer × fixed-point multiplications `_IQmpyI32` (counted only for the fixed-point firmware).
    int_muls,
    /// Integer operations beside the arithmetic: add, subtract, logic, shift, compare ([`Work`]).
    int_ops,
    /// Loads of integer data from memory ([`Work`]; a float operand's move is in its operation's price).
    loads,
    /// Stores of integer data to memory ([`Work`]).
    stores,
    /// Conditional branches ([`Work`]).
    cond_branches,
    /// Unconditional branches taken ([`Work`]).
    branches,
    /// Calls of the firmware's own functions ([`Work`]).
    calls,
    /// Their returns ([`Work`]).
    returns,
}

/// Integer, memory and control work the firmware's code does beside its arithmetic, as its C source
/// executes it (the timing model's count: [`Scalar::work`]; see `c28x-costs.toml` `[instructions]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Work {
    /// Integer operations (ADD, AND, XOR, CMP, ...).
    pub int_ops: u8,
    /// Loads of integer data.
    pub loads: u8,
    /// Stores of integer data.
    pub stores: u8,
    /// Conditional branches.
    pub cond_branches: u8,
    /// Unconditional branches taken.
    pub branches: u8,
    /// Calls of a function of the firmware, each with its return.
    pub calls: u8,
}

impl Work {
    /// One pass of a counted loop: the counter's increment and compare, the conditional branch back.
    pub const LOOP_PASS: Work = Work { int_ops: 2, cond_branches: 1, ..Work::NONE };
    /// Nothing.
    pub const NONE: Work = Work { int_ops: 0, loads: 0, stores: 0, cond_branches: 0, branches: 0, calls: 0 };
    /// A call of a function of the firmware with `args` argument moves, and its return.
    pub const fn call(args: u8) -> Work {
        Work { int_ops: args, calls: 1, ..Work::NONE }
    }
}

/// Tally `w` (the counting type's [`Scalar::work`]).
fn tally_work(w: Work) {
    TALLY.with(|t| {
        for (op, n) in [
            (Op::int_ops, w.int_ops),
            (Op::loads, w.loads),
            (Op::stores, w.stores),
            (Op::cond_branches, w.cond_branches),
            (Op::branches, w.branches),
            (Op::calls, w.calls),
            (Op::returns, w.calls),
        ] {
            let slot = &t[op as usize];
            slot.set(slot.get() + u64::from(n));
        }
    });
}

impl OpCounts {
    /// All operations together.
    pub fn total(&self) -> u64 {
        self.to_array().iter().sum()
    }

    fn zip(self, other: OpCounts, f: impl Fn(u64, u64) -> u64) -> OpCounts {
        let (a, b) = (self.to_array(), other.to_array());
        OpCounts::from_array(std::array::from_fn(|i| f(a[i], b[i])))
    }
}

impl Add for OpCounts {
    type Output = OpCounts;
    fn add(self, rhs: OpCounts) -> OpCounts {
        self.zip(rhs, u64::saturating_add)
    }
}

impl AddAssign for OpCounts {
    fn add_assign(&mut self, rhs: OpCounts) {
        *self = *self + rhs;
    }
}

impl Sub for OpCounts {
    type Output = OpCounts;
    /// Per-kind difference, for a stage = later snapshot − earlier snapshot. Saturates at 0, because a
    /// negative count has no meaning (it only arises from subtracting in the wrong order).
    fn sub(self, rhs: OpCounts) -> OpCounts {
        self.zip(rhs, u64::saturating_sub)
    }
}

thread_local! {
    static TALLY: [Cell<u64>; KINDS] = const { [const { Cell::new(0) }; KINDS] };
    static FIXED_POINT: Cell<bool> = const { Cell::new(false) };
}

/// Run `f` counting the firmware of a fixed-point backend (`fixed_point` true: IQ) or of a float one
/// (false, also the default outside any scope); the previous setting is restored afterwards.
pub fn count_as<R>(fixed_point: bool, f: impl FnOnce() -> R) -> R {
    super::with_setting(&FIXED_POINT, fixed_point, f)
}

#[inline]
fn tally(op: Op) {
    TALLY.with(|t| {
        let slot = &t[op as usize];
        slot.set(slot.get() + 1);
    });
}

fn store(counts: OpCounts) {
    let a = counts.to_array();
    TALLY.with(|t| t.iter().zip(a).for_each(|(slot, v)| slot.set(v)));
}

/// The running tally of the innermost [`count`] scope on this thread (everything since the thread
/// started outside any scope). Subtract two snapshots for the operations of the code between them.
pub fn snapshot() -> OpCounts {
    OpCounts::from_array(TALLY.with(|t| std::array::from_fn(|i| t[i].get())))
}

/// Run `f` and return its result with the operations it executed on this thread. Scopes nest: the
/// operations are also added to the enclosing scope's tally (also when `f` unwinds).
pub fn count<R>(f: impl FnOnce() -> R) -> (R, OpCounts) {
    struct Restore(OpCounts);
    impl Drop for Restore {
        fn drop(&mut self) {
            store(self.0 + snapshot());
        }
    }
    let restore = Restore(snapshot());
    store(OpCounts::default());
    let result = f();
    let inner = snapshot();
    drop(restore);
    (result, inner)
}

/// An f64 whose every operation is tallied (timing model only; not a firmware numeric backend).
#[derive(Debug, Clone, Copy, Default)]
pub struct Counted(pub f64);

impl PartialEq for Counted {
    fn eq(&self, other: &Self) -> bool {
        tally(Op::comparisons);
        self.0 == other.0
    }
}

impl PartialOrd for Counted {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        tally(Op::comparisons);
        self.0.partial_cmp(&other.0)
    }
}

/// Implements a binary operator by forwarding to f64 and tallying `op`.
macro_rules! counted_binop {
    ($trait:ident, $method:ident, $op:ident) => {
        impl $trait for Counted {
            type Output = Counted;
            #[inline]
            fn $method(self, rhs: Counted) -> Counted {
                tally(Op::$op);
                Counted(self.0.$method(rhs.0))
            }
        }
    };
}

counted_binop!(Add, add, adds);
counted_binop!(Sub, sub, subs);
counted_binop!(Mul, mul, muls);

impl Div for Counted {
    type Output = Counted;
    /// A division by a power of two (±2^k, e.g. the published `/2` and `T1/2` with `#define T1`) is
    /// exact as a multiplication by its reciprocal, and cl2000 strength-reduces it to MPYF32 (or a
    /// shift for IQ): it is counted as a multiplication. Any other divisor costs a fastRTS division.
    #[inline]
    fn div(self, rhs: Counted) -> Counted {
        let (mantissa, _) = frexp(rhs.0);
        tally(if mantissa.abs() == 0.5 { Op::muls } else { Op::divs });
        Counted(self.0 / rhs.0)
    }
}

/// Mantissa in [0.5, 1) and exponent of a finite non-zero x (0 for zero and non-finite values).
fn frexp(x: f64) -> (f64, i32) {
    if x == 0.0 || !x.is_finite() {
        return (0.0, 0);
    }
    let bits = x.to_bits();
    let exp = ((bits >> 52) & 0x7FF) as i32;
    if exp == 0 {
        // Subnormal: scale into the normal range first.
        let (m, e) = frexp(x * 2f64.powi(64));
        return (m, e - 64);
    }
    let m = f64::from_bits((bits & !(0x7FFu64 << 52)) | (1022u64 << 52));
    (m, exp - 1022)
}

impl Neg for Counted {
    type Output = Counted;
    #[inline]
    fn neg(self) -> Counted {
        tally(Op::negs);
        Counted(-self.0)
    }
}

impl Scalar for Counted {
    const NAME: &'static str = "counted";

    fn from_f64(x: f64, class: QClass) -> Self {
        tally(Op::constants);
        Counted(<f64 as Scalar>::from_f64(x, class))
    }
    fn from_i32(x: i32, class: QClass) -> Self {
        tally(Op::int_to_float);
        Counted(<f64 as Scalar>::from_i32(x, class))
    }
    fn to_f64(self) -> f64 {
        self.0
    }
    fn fixed_point() -> bool {
        FIXED_POINT.with(|c| c.get())
    }
    fn mul_i32(self, n: i32) -> Self {
        if Self::fixed_point() {
            tally(Op::int_muls);
            Counted(n as f64 * self.0)
        } else {
            Counted::from_i32(n, QClass::Generic) * self
        }
    }
    fn sqrt(self) -> Self {
        tally(Op::sqrts);
        Counted(Scalar::sqrt(self.0))
    }
    fn sin(self) -> Self {
        tally(Op::sins);
        Counted(Scalar::sin(self.0))
    }
    fn cos(self) -> Self {
        tally(Op::coss);
        Counted(Scalar::cos(self.0))
    }
    fn atan(self) -> Self {
        tally(Op::atans);
        Counted(Scalar::atan(self.0))
    }
    fn atan2(self, x: Self) -> Self {
        tally(Op::atan2s);
        Counted(Scalar::atan2(self.0, x.0))
    }
    fn asin(self) -> Self {
        tally(Op::asins);
        Counted(Scalar::asin(self.0))
    }
    fn abs(self) -> Self {
        tally(Op::abs);
        Counted(Scalar::abs(self.0))
    }
    fn work(w: Work) {
        tally_work(w);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A firmware-like expression, generic so the same code runs in f64 and counted.
    fn sample<T: Scalar>(a: T, b: T) -> T {
        let two = T::from_f64(2.0, QClass::Generic);
        let n = T::from_i32(3, QClass::Generic);
        let norm = (a * a + b * b).sqrt();
        let angle = b.atan2(a);
        if norm > two {
            (norm - two) / n + angle.sin().abs()
        } else {
            -(angle.cos() * n) + (a / norm).asin() + b.atan()
        }
    }

    #[test]
    fn tallies_a_known_expression() {
        let (v, c) = count(|| sample(Counted(3.0), Counted(4.0)));
        assert_eq!(v.0.to_bits(), sample(3.0f64, 4.0f64).to_bits(), "same value as f64");
        let want = OpCounts {
            adds: 2,
            subs: 1,
            muls: 2,
            divs: 1,
            sqrts: 1,
            sins: 1,
            atan2s: 1,
            abs: 1,
            comparisons: 1,
            int_to_float: 1,
            constants: 1,
            ..OpCounts::default()
        };
        assert_eq!(c, want);
        assert_eq!(c.total(), 13);
        // The other branch: the same control flow as f64 is taken.
        let (v, c) = count(|| sample(Counted(0.6), Counted(0.7)));
        assert_eq!(v.0.to_bits(), sample(0.6f64, 0.7f64).to_bits());
        assert_eq!((c.coss, c.asins, c.atans, c.negs, c.muls, c.sins), (1, 1, 1, 1, 3, 0));
    }

    #[test]
    fn scopes_nest_and_snapshots_subtract() {
        let ((), outer) = count(|| {
            let _ = Counted(1.0) + Counted(2.0);
            let before = snapshot();
            let ((), inner) = count(|| {
                let _ = Counted(1.0) * Counted(2.0) * Counted(3.0);
            });
            assert_eq!((inner.muls, inner.adds), (2, 0));
            let stage = snapshot() - before;
            assert_eq!(stage, inner, "the inner scope's ops reach the outer tally");
            let _ = Counted(1.0) == Counted(1.0);
        });
        assert_eq!((outer.adds, outer.muls, outer.comparisons), (1, 2, 1));
        let sum = outer + outer;
        assert_eq!(sum.muls, 4);
        assert_eq!((outer - sum).total(), 0, "saturates instead of going negative");
        let mut acc = OpCounts::default();
        acc += outer;
        assert_eq!(acc, outer);
    }

    #[test]
    fn unwinding_keeps_the_outer_tally() {
        let ((), outer) = count(|| {
            let r = std::panic::catch_unwind(|| {
                count(|| {
                    let _ = Counted(1.0) / Counted(3.0);
                    panic!("stage failed");
                })
            });
            assert!(r.is_err());
        });
        assert_eq!(outer.divs, 1);
    }
}

#[cfg(test)]
mod integer_multiply {
    use super::*;

    #[test]
    fn mul_i32_counts_as_the_backend_executes_it() {
        let (v, c) = count(|| Counted(0.25).mul_i32(-3));
        assert_eq!((v.0, c.int_to_float, c.muls, c.int_muls), (-0.75, 1, 1, 0), "float: I32TOF32 + MPYF32");
        let (v, c) = count_as(true, || count(|| Counted(0.25).mul_i32(-3)));
        assert_eq!((v.0, c.int_to_float, c.muls, c.int_muls), (-0.75, 0, 0, 1), "IQ: one _IQmpyI32");
        assert!(!Counted::fixed_point(), "the setting is scoped");
        let (_, c) = count(|| Counted(1.0).div_to(Counted(3.0), QClass::Rate).mul_to(Counted(3.0), QClass::Quat));
        assert_eq!((c.divs, c.muls), (1, 1));
    }
}

#[cfg(test)]
mod work {
    use super::*;

    /// The integer and control work is tallied by the counting type only, each call with its return.
    #[test]
    fn work_is_tallied_by_kind() {
        let w = Work { int_ops: 3, loads: 1, stores: 2, cond_branches: 1, branches: 1, calls: 1 };
        let ((), c) = count(|| {
            <Counted as Scalar>::work(w);
            <Counted as Scalar>::work(Work::LOOP_PASS);
            <f64 as Scalar>::work(w);
        });
        assert_eq!((c.int_ops, c.loads, c.stores, c.cond_branches, c.branches), (5, 1, 2, 2, 1));
        assert_eq!((c.calls, c.returns), (1, 1));
        assert_eq!(c.total(), 13);
        let ((), c) = count(|| <Counted as Scalar>::work(Work::call(2)));
        assert_eq!((c.int_ops, c.calls, c.returns), (2, 1, 1));
    }
}

#[cfg(test)]
mod strength_reduction {
    use super::*;

    #[test]
    fn division_by_a_power_of_two_counts_as_a_multiplication() {
        let (_, c) =
            count(|| (Counted(3.0) / Counted(2.0), Counted(3.0) / Counted(0.25), Counted(3.0) / Counted(-8.0)));
        assert_eq!((c.muls, c.divs), (3, 0));
        let (_, c) = count(|| (Counted(3.0) / Counted(6.0), Counted(3.0) / Counted(0.3)));
        assert_eq!((c.muls, c.divs), (0, 2));
    }
}
