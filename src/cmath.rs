//! Fast complex elementary functions and small dense solves used on hot paths.

use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;
use std::ops::{Add, Mul, Neg, Sub};

/// The field of a small dense solve: `f64`, or `C64` when imaginary parts are present (a
/// system whose entries are all real is solved in real arithmetic, to the same result).
pub trait Scalar:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Mul<f64, Output = Self>
    + Neg<Output = Self>
{
    /// Zero.
    const ZERO: Self;
    /// One.
    const ONE: Self;
    /// `|z|²`.
    fn norm_sqr(self) -> f64;
    /// `1/z` ([`inv`] for complex numbers: `z̄ · (1/|z|²)`, as for real ones).
    fn inverse(self) -> Self;
    /// Complex conjugate.
    fn conj(self) -> Self;
    /// Real part.
    fn re(self) -> f64;
    /// As a complex number.
    fn complex(self) -> C64;
}

impl Scalar for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline(always)]
    fn norm_sqr(self) -> f64 {
        self * self
    }
    #[inline(always)]
    fn inverse(self) -> Self {
        self * (1.0 / (self * self))
    }
    #[inline(always)]
    fn conj(self) -> Self {
        self
    }
    #[inline(always)]
    fn re(self) -> f64 {
        self
    }
    #[inline(always)]
    fn complex(self) -> C64 {
        C64::new(self, 0.0)
    }
}

impl Scalar for C64 {
    const ZERO: Self = C64::new(0.0, 0.0);
    const ONE: Self = C64::new(1.0, 0.0);
    #[inline(always)]
    fn norm_sqr(self) -> f64 {
        C64::norm_sqr(&self)
    }
    #[inline(always)]
    fn inverse(self) -> Self {
        inv(self)
    }
    #[inline(always)]
    fn conj(self) -> Self {
        C64::conj(&self)
    }
    #[inline(always)]
    fn re(self) -> f64 {
        self.re
    }
    #[inline(always)]
    fn complex(self) -> C64 {
        self
    }
}

/// Principal square root (`Re ≥ 0`, branch cut on the negative real axis, `sqrt(−x ± 0i) =
/// ±i√x`), by the algebraic formula without trigonometry and without cancellation.
#[inline]
pub fn sqrt(z: C64) -> C64 {
    if z.im == 0.0 {
        return if z.re >= 0.0 {
            C64::new(z.re.sqrt(), z.im)
        } else {
            C64::new(0.0, (-z.re).sqrt().copysign(z.im))
        };
    }
    let m = z.re.hypot(z.im);
    if z.re >= 0.0 {
        let t = (0.5 * (m + z.re)).sqrt();
        C64::new(t, z.im / (2.0 * t))
    } else {
        let t = (0.5 * (m - z.re)).sqrt();
        C64::new(z.im.abs() / (2.0 * t), t.copysign(z.im))
    }
}

/// `1/z` with one real division (`z̄ · (1/|z|²)`); within an ulp or two of `z.inv()`.
#[inline]
pub fn inv(z: C64) -> C64 {
    let r = 1.0 / z.norm_sqr();
    C64::new(z.re * r, -z.im * r)
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
pub fn solve4_columns<T: Scalar + nalgebra::Scalar, const N: usize>(
    a: &Matrix4<T>,
    b: &[Matrix4<T>; N],
) -> Option<[Matrix4<T>; N]> {
    // Rows of A, and of every B, eliminated together.
    let mut m: [[T; 4]; 4] = std::array::from_fn(|i| std::array::from_fn(|j| a[(i, j)]));
    let mut r: [[[T; 4]; N]; 4] =
        std::array::from_fn(|i| std::array::from_fn(|k| std::array::from_fn(|j| b[k][(i, j)])));
    let scale = a.iter().map(|z| z.norm_sqr()).fold(0.0, f64::max);
    for col in 0..4 {
        let mut pivot = col;
        for i in col + 1..4 {
            if m[i][col].norm_sqr() > m[pivot][col].norm_sqr() {
                pivot = i;
            }
        }
        let p = m[pivot][col];
        if p.norm_sqr().is_nan() || p.norm_sqr() <= 1e-300 * scale {
            return None;
        }
        m.swap(col, pivot);
        r.swap(col, pivot);
        let inv = p.inverse();
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
    Some(std::array::from_fn(|k| Matrix4::from_fn(|i, j| r[i][k][j])))
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
pub fn mul2(a: &Matrix2<C64>, b: &Matrix2<C64>) -> Matrix2<C64> {
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
