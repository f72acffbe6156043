//! Per-lane choice between two values of any shape built from [`Real`] numbers: `if` on the
//! host, Dr.Jit's `select` in a recorded program ([`crate::real::Mask::when`]).

use crate::real::{Mask, Real};
use nalgebra::{Matrix2, Matrix4, Vector2, Vector3, Vector4};
use num_complex::Complex;

/// A value that can be chosen per lane by a mask `M`.
pub trait Select<M>: Sized {
    /// `a` where `m` holds, `b` elsewhere.
    fn select(m: M, a: Self, b: Self) -> Self;
}

impl Select<bool> for f64 {
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m {
            a
        } else {
            b
        }
    }
}

impl<T: Real> Select<T::Mask> for Complex<T> {
    #[inline(always)]
    fn select(m: T::Mask, a: Self, b: Self) -> Self {
        Complex::new(T::select(m, a.re, b.re), T::select(m, a.im, b.im))
    }
}

impl<M: Mask, S: Select<M>, const N: usize> Select<M> for [S; N] {
    #[inline(always)]
    fn select(m: M, a: Self, b: Self) -> Self {
        let mut b = b.into_iter();
        a.map(|a| S::select(m, a, b.next().expect("same length")))
    }
}

impl<M: Mask, A: Select<M>, B: Select<M>> Select<M> for (A, B) {
    #[inline(always)]
    fn select(m: M, a: Self, b: Self) -> Self {
        (A::select(m, a.0, b.0), B::select(m, a.1, b.1))
    }
}

impl<M: Mask, A: Select<M>, B: Select<M>, C: Select<M>> Select<M> for (A, B, C) {
    #[inline(always)]
    fn select(m: M, a: Self, b: Self) -> Self {
        (
            A::select(m, a.0, b.0),
            B::select(m, a.1, b.1),
            C::select(m, a.2, b.2),
        )
    }
}

/// Element-wise choice for nalgebra's fixed-size vectors and matrices.
macro_rules! select_matrix {
    ($($t:ident),*) => {$(
        impl<M: Mask, S: Select<M> + nalgebra::Scalar> Select<M> for $t<S> {
            #[inline(always)]
            fn select(m: M, a: Self, b: Self) -> Self {
                a.zip_map(&b, |a, b| S::select(m, a, b))
            }
        }
    )*};
}
select_matrix!(Vector2, Vector3, Vector4, Matrix2, Matrix4);

impl Select<bool> for bool {
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m {
            a
        } else {
            b
        }
    }
}
