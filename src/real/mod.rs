//! The number type the per-wavelength physics is written in, once: `f64` on the host, or a
//! recorded variable ([`crate::record::Var`]) whose operations become a straight-line program
//! that the shim replays with Dr.Jit arrays inside Mitsuba's kernels.
//!
//! Code generic over [`Real`] branches in two ways. A decision about a lane's values (the root
//! of a mode, total internal reflection) is a [`Mask`] and both outcomes are written as
//! closures: [`Mask::when`] runs only the taken one on `f64` and records both with a `select`
//! otherwise. A shortcut that only saves work (an isotropic medium, real arithmetic for a
//! lossless one) asks [`Mask::known`] and takes the general path when the answer is not known
//! while recording. A lane that cannot be computed ([`Mask::fail`]) is an error on `f64` and a
//! lane without light in a recorded program.

pub mod complex;
pub mod select;

use crate::error::{Error, Result};
use num_complex::Complex;
use num_traits::{Num, NumAssign};
use std::fmt::Debug;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

pub use select::Select;

/// A real number of the per-wavelength physics: `f64`, or a recorded variable.
///
/// The arithmetic of `num_traits::Num` (so that `num_complex::Complex<T>` is a complex number
/// of it), mixed arithmetic with `f64` constants, the elementary functions a kernel has, and
/// comparisons that give a [`Mask`].
pub trait Real:
    Copy
    + Debug
    + Num
    + NumAssign
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + Select<Self::Mask>
    + 'static
{
    /// The result of a comparison.
    type Mask: Mask;

    /// True for a recorded number: its program checks its outputs' finiteness once, at the end
    /// (a non-finite intermediate reaches them), so [`all_finite`] records nothing.
    const RECORDED: bool = false;

    /// The constant `x`.
    fn cst(x: f64) -> Self;
    /// The value, where it is known (always for `f64`; for a constant while recording).
    fn value(self) -> Option<f64>;
    /// `√x`.
    fn sqrt(self) -> Self;
    /// `√max(x, 0)`, whose derivative stays finite at 0 while recording (Dr.Jit's
    /// `safe_sqrt`): for a branch that another lane's value may make negative.
    fn safe_sqrt(self) -> Self;
    /// `sin x`.
    fn sin(self) -> Self;
    /// `cos x`.
    fn cos(self) -> Self;
    /// `(sin x, cos x)`.
    fn sin_cos(self) -> (Self, Self) {
        (self.sin(), self.cos())
    }
    /// `eˣ`.
    fn exp(self) -> Self;
    /// `|x|`.
    fn abs(self) -> Self;
    /// The smaller of two numbers (the other if one is NaN).
    fn min(self, other: Self) -> Self;
    /// The larger of two numbers (the other if one is NaN).
    fn max(self, other: Self) -> Self;
    /// `|self|` with the sign of `sign`.
    fn copysign(self, sign: Self) -> Self;
    /// The same value, through which no derivative flows (Dr.Jit's `detach`).
    fn detach(self) -> Self;
    /// `self < other`.
    fn lt(self, other: Self) -> Self::Mask;
    /// `self <= other`.
    fn le(self, other: Self) -> Self::Mask;
    /// `self > other`.
    fn gt(self, other: Self) -> Self::Mask {
        other.lt(self)
    }
    /// `self >= other`.
    fn ge(self, other: Self) -> Self::Mask {
        other.le(self)
    }
    /// `self == other` (IEEE equality).
    fn equals(self, other: Self) -> Self::Mask;
    /// True unless infinite or NaN.
    fn finite(self) -> Self::Mask;
    /// `1/x`.
    fn recip(self) -> Self {
        Self::one() / self
    }
    /// `x²`.
    fn sqr(self) -> Self {
        self * self
    }
    /// `√(x² + y²)`.
    fn hypot(self, other: Self) -> Self {
        (self * self + other * other).sqrt()
    }
}

/// Where every complex number of `values` is finite: the check of a result that is an error if
/// it is not (a singular system). A recorded program checks its outputs instead ([`Real::RECORDED`]).
pub fn all_finite<'a, T: Real>(values: impl IntoIterator<Item = &'a Complex<T>>) -> T::Mask {
    let yes = T::Mask::cst(true);
    if T::RECORDED {
        return yes;
    }
    values
        .into_iter()
        .fold(yes, |m, z| m & z.re.finite() & z.im.finite())
}

/// The outcome of a comparison per lane: `bool`, or a recorded mask.
pub trait Mask:
    Copy
    + Debug
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + Not<Output = Self>
    + Select<Self>
    + 'static
{
    /// The constant `b`.
    fn cst(b: bool) -> Self;
    /// The value, where it is known (always for `bool`; for a constant while recording).
    fn known(self) -> Option<bool>;
    /// `a()` where the mask holds, `b()` elsewhere: one of them on `bool` (and for a known
    /// mask), both with a `select` while recording.
    #[inline(always)]
    fn when<R: Select<Self>>(self, a: impl FnOnce() -> R, b: impl FnOnce() -> R) -> R {
        match self.known() {
            Some(true) => a(),
            Some(false) => b(),
            None => R::select(self, a(), b()),
        }
    }
    /// True where the mask is known to hold: a shortcut that only saves work is taken where
    /// this says so (never while recording a mask that depends on a lane).
    #[inline(always)]
    fn surely(self) -> bool {
        self.known() == Some(true)
    }
    /// The lanes where the mask holds cannot be computed: on `bool` the error `err`; while
    /// recording, those lanes of the program carry no light (the error only if the mask is
    /// known to hold).
    fn fail(self, err: impl FnOnce() -> Error) -> Result<()>;
}

impl Mask for bool {
    #[inline(always)]
    fn cst(b: bool) -> Self {
        b
    }
    #[inline(always)]
    fn known(self) -> Option<bool> {
        Some(self)
    }
    #[inline(always)]
    fn fail(self, err: impl FnOnce() -> Error) -> Result<()> {
        if self {
            Err(err())
        } else {
            Ok(())
        }
    }
}

impl Real for f64 {
    type Mask = bool;
    #[inline(always)]
    fn cst(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn value(self) -> Option<f64> {
        Some(self)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn safe_sqrt(self) -> Self {
        f64::sqrt(f64::max(self, 0.0))
    }
    #[inline(always)]
    fn sin(self) -> Self {
        f64::sin(self)
    }
    #[inline(always)]
    fn cos(self) -> Self {
        f64::cos(self)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        f64::sin_cos(self)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        f64::exp(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        f64::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f64::max(self, other)
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        f64::copysign(self, sign)
    }
    #[inline(always)]
    fn detach(self) -> Self {
        self
    }
    #[inline(always)]
    fn lt(self, other: Self) -> bool {
        self < other
    }
    #[inline(always)]
    fn le(self, other: Self) -> bool {
        self <= other
    }
    #[inline(always)]
    fn equals(self, other: Self) -> bool {
        self == other
    }
    #[inline(always)]
    fn finite(self) -> bool {
        self.is_finite()
    }
    #[inline(always)]
    fn recip(self) -> Self {
        1.0 / self
    }
    #[inline(always)]
    fn hypot(self, other: Self) -> Self {
        f64::hypot(self, other)
    }
}
