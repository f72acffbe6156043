//! Fast complex elementary functions and small dense solves used on hot paths.

use crate::error::{Error, Result};
use crate::real::complex::{self, Cx};
use crate::real::{Mask, Real, Select};
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;
use std::ops::{Add, Mul, Neg, Sub};

/// The field of a small dense solve or a field computation over the real numbers `R` (`f64`
/// on the host, a recorded number in a program): `R` itself, or `Complex<R>` when imaginary
/// parts are present (a system whose entries are all real is solved in real arithmetic, to the
/// same result).
pub trait Scalar<R: Real>:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Mul<R, Output = Self>
    + Neg<Output = Self>
    + Select<R::Mask>
{
    /// Zero.
    fn zero() -> Self;
    /// One.
    fn one() -> Self;
    /// `|z|²`.
    fn norm_sqr(self) -> R;
    /// `1/z` ([`inv`] for complex numbers: `z̄ · (1/|z|²)`, as for real ones).
    fn inverse(self) -> Self;
    /// Complex conjugate.
    fn conj(self) -> Self;
    /// Real part.
    fn re(self) -> R;
    /// As a complex number.
    fn complex(self) -> Cx<R>;
}

impl<R: Real> Scalar<R> for R {
    #[inline(always)]
    fn zero() -> Self {
        R::zero()
    }
    #[inline(always)]
    fn one() -> Self {
        R::one()
    }
    #[inline(always)]
    fn norm_sqr(self) -> R {
        self * self
    }
    #[inline(always)]
    fn inverse(self) -> Self {
        self * (self * self).recip()
    }
    #[inline(always)]
    fn conj(self) -> Self {
        self
    }
    #[inline(always)]
    fn re(self) -> R {
        self
    }
    #[inline(always)]
    fn complex(self) -> Cx<R> {
        Cx::new(self, R::zero())
    }
}

impl<R: Real> Scalar<R> for Cx<R> {
    #[inline(always)]
    fn zero() -> Self {
        Cx::new(R::zero(), R::zero())
    }
    #[inline(always)]
    fn one() -> Self {
        Cx::new(R::one(), R::zero())
    }
    #[inline(always)]
    fn norm_sqr(self) -> R {
        self.re * self.re + self.im * self.im
    }
    #[inline(always)]
    fn inverse(self) -> Self {
        complex::inv(self)
    }
    #[inline(always)]
    fn conj(self) -> Self {
        Cx::new(self.re, -self.im)
    }
    #[inline(always)]
    fn re(self) -> R {
        self.re
    }
    #[inline(always)]
    fn complex(self) -> Cx<R> {
        self
    }
}

/// Principal square root (`Re ≥ 0`, branch cut on the negative real axis, `sqrt(−x ± 0i) =
/// ±i√x`): [`complex::sqrt`] on `f64`.
#[inline]
pub fn sqrt(z: C64) -> C64 {
    complex::sqrt(z)
}

/// `1/z` with one real division (`z̄ · (1/|z|²)`); within an ulp or two of `z.inv()`.
#[inline]
pub fn inv(z: C64) -> C64 {
    complex::inv(z)
}

/// Solves `A X = B` for a 4×4 complex `A` and 4×4 `B` by Gaussian elimination with partial
/// pivoting; `None` if `A` is singular to working precision. A system whose entries are all
/// real (lossless media, propagating waves) is solved in real arithmetic, the same steps.
pub fn solve4(a: &Matrix4<C64>, b: &Matrix4<C64>) -> Option<Matrix4<C64>> {
    if a.iter().chain(b.iter()).all(|z| z.im == 0.0) {
        let x = solve4_columns(&a.map(|z| z.re), &[b.map(|z| z.re)])?;
        return Some(x[0].map(|v| C64::new(v, 0.0)));
    }
    let x = solve4_columns(a, &[*b])?;
    Some(x[0])
}

/// [`solve4`] for several right-hand sides at once (one elimination), in the arithmetic of `T`.
pub fn solve4_columns<T: Scalar<f64> + nalgebra::Scalar, const N: usize>(
    a: &Matrix4<T>,
    b: &[Matrix4<T>; N],
) -> Option<[Matrix4<T>; N]> {
    eliminate4(a, b).ok()
}

/// Solves `A X = B` for a 4×4 `A` and `N` right-hand sides by Gauss–Jordan elimination with
/// partial pivoting, over the reals `R` (the pivot row of each column is the one of largest
/// modulus, moved up by per-lane exchanges); fails where a pivot is below `1e-300` of the
/// largest entry of `A` (squared moduli) or NaN: the singular error of an interface.
pub fn eliminate4<R: Real, T: Scalar<R> + nalgebra::Scalar, const N: usize>(
    a: &Matrix4<T>,
    b: &[Matrix4<T>; N],
) -> Result<[Matrix4<T>; N]> {
    // Rows of A, and of every B, eliminated together.
    let mut m: [[T; 4]; 4] = std::array::from_fn(|i| std::array::from_fn(|j| a[(i, j)]));
    let mut r: [[[T; 4]; N]; 4] =
        std::array::from_fn(|i| std::array::from_fn(|k| std::array::from_fn(|j| b[k][(i, j)])));
    let scale = a
        .iter()
        .map(|z| z.norm_sqr())
        .fold(R::zero(), |acc, x| acc.max(x));
    for col in 0..4 {
        for i in col + 1..4 {
            let larger = m[i][col].norm_sqr().gt(m[col][col].norm_sqr());
            if larger.known() != Some(false) {
                let (top, other) = (m[col], m[i]);
                m[col] = Select::select(larger, other, top);
                m[i] = Select::select(larger, top, other);
                let (top, other) = (r[col], r[i]);
                r[col] = Select::select(larger, other, top);
                r[i] = Select::select(larger, top, other);
            }
        }
        let p = m[col][col];
        let negligible = !p.norm_sqr().gt(scale * 1e-300);
        negligible.fail(singular)?;
        let inv = negligible.when(T::one, || p).inverse();
        for v in m[col].iter_mut().skip(col) {
            *v = *v * inv;
        }
        for block in r[col].iter_mut() {
            for v in block.iter_mut() {
                *v = *v * inv;
            }
        }
        let (pm, pr) = (m[col], r[col]);
        for i in 0..4 {
            if i == col {
                continue;
            }
            let f = m[i][col];
            for j in col..4 {
                m[i][j] = m[i][j] - f * pm[j];
            }
            for (block, pb) in r[i].iter_mut().zip(&pr) {
                for (v, pv) in block.iter_mut().zip(pb) {
                    *v = *v - f * *pv;
                }
            }
        }
    }
    Ok(std::array::from_fn(|k| Matrix4::from_fn(|i, j| r[i][k][j])))
}

/// The error of a singular boundary system.
pub(crate) fn singular() -> Error {
    Error::new(
        "interface",
        "the boundary system is singular for this incidence (a guided or degenerate mode)",
    )
}

/// `a b` for 4×4 complex matrices, written out (the generic product is several times slower).
#[inline]
pub fn mul4(a: &Matrix4<C64>, b: &Matrix4<C64>) -> Matrix4<C64> {
    let mut out = Matrix4::zeros();
    for j in 0..4 {
        for k in 0..4 {
            let bkj = b[(k, j)];
            for i in 0..4 {
                out[(i, j)] += a[(i, k)] * bkj;
            }
        }
    }
    out
}

/// `a b`, written out.
#[inline(always)]
pub fn mul2<T: Real>(a: &Matrix2<Cx<T>>, b: &Matrix2<Cx<T>>) -> Matrix2<Cx<T>> {
    Matrix2::new(
        a[(0, 0)] * b[(0, 0)] + a[(0, 1)] * b[(1, 0)],
        a[(0, 0)] * b[(0, 1)] + a[(0, 1)] * b[(1, 1)],
        a[(1, 0)] * b[(0, 0)] + a[(1, 1)] * b[(1, 0)],
        a[(1, 0)] * b[(0, 1)] + a[(1, 1)] * b[(1, 1)],
    )
}

/// The largest singular value of a 2x2 complex matrix: `σ² = (‖A‖²_F + √(‖A‖⁴_F − 4|det A|²))/2`
/// (the norm of `Aⁿ` is at most its `n`-th power; the Frobenius norm would overestimate it by up
/// to `√2ⁿ`).
pub fn spectral_norm(a: &nalgebra::Matrix2<C64>) -> f64 {
    let f2 = a.norm_squared();
    let det = (a[(0, 0)] * a[(1, 1)] - a[(0, 1)] * a[(1, 0)]).norm_sqr();
    (0.5 * (f2 + (f2 * f2 - 4.0 * det).max(0.0).sqrt())).sqrt()
}

/// Uniform numbers in `[0, 1)` from a 64-bit linear congruential generator (Knuth's MMIX
/// constants, the top 53 bits): reproducible inputs for the unit tests.
#[cfg(test)]
pub(crate) fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sqrt_matches_the_principal_branch() {
        for (re, im) in [
            (2.0, 0.0),
            (-2.0, 0.0),
            (-2.0, -0.0),
            (0.0, 0.0),
            (1e-300, 3.0),
            (-4.0, 1e-20),
            (-4.0, -1e-20),
            (3.0, -4.0),
            (-3.0, 4.0),
        ] {
            let z = C64::new(re, im);
            let (a, b) = (sqrt(z), z.sqrt());
            assert!(
                (a - b).norm() <= 1e-15 * b.norm().max(1e-300),
                "{z}: {a} vs {b}"
            );
            assert!((a * a - z).norm() <= 1e-15 * z.norm().max(1e-300));
        }
    }

    #[test]
    fn solve4_inverts() {
        let a = Matrix4::from_fn(|i, j| {
            C64::new((i * 3 + j) as f64 % 5.0 - 1.7, (i + 2 * j) as f64 % 3.0)
        });
        let b = Matrix4::from_fn(|i, j| C64::new(i as f64 - j as f64, 0.5));
        let x = solve4(&a, &b).unwrap();
        assert!((a * x - b).norm() < 1e-12);
        assert!(solve4(&Matrix4::zeros(), &b).is_none());
    }

    /// A real system takes the real arithmetic, which does what the complex one does on it bit
    /// for bit (products and sums with zero imaginary parts round like real ones).
    #[test]
    fn solve4_of_a_real_system_is_the_complex_solve() {
        let mut uniform = uniform(11);
        let mut next = || 4.0 * uniform() - 2.0;
        for _ in 0..1000 {
            let a = Matrix4::from_fn(|_, _| C64::new(next(), 0.0));
            let b = Matrix4::from_fn(|_, _| C64::new(next(), 0.0));
            let real = solve4(&a, &b).unwrap();
            let complex = solve4_columns(&a, &[b]).unwrap()[0];
            for (r, c) in real.iter().zip(complex.iter()) {
                assert_eq!(r.re, c.re);
                assert_eq!(c.im, 0.0);
            }
        }
    }

    /// Against the square root of the largest eigenvalue of `A†A`, on random matrices.
    #[test]
    fn spectral_norm_is_the_largest_singular_value() {
        let mut uniform = uniform(3);
        let mut next = || 2.0 * uniform() - 1.0;
        for _ in 0..1000 {
            let a = nalgebra::Matrix2::from_fn(|_, _| C64::new(next(), next()));
            let h = a.adjoint() * a;
            let (p, q) = ((h[(0, 0)] + h[(1, 1)]).re, (h[(0, 0)] - h[(1, 1)]).re);
            let largest = 0.5 * (p + (q * q + 4.0 * h[(0, 1)].norm_sqr()).sqrt());
            assert!((spectral_norm(&a) - largest.sqrt()).abs() < 1e-12 * (1.0 + largest));
        }
    }
}
