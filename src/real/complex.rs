//! Complex elementary functions over any [`Real`]: the principal square root, the reciprocal
//! and the exponential, with the branches of the `f64` originals as per-lane choices.

use crate::real::{Mask, Real};
use num_complex::Complex;

/// A complex number of the per-wavelength physics.
pub type Cx<T> = Complex<T>;

/// The complex constant `re + i im`.
#[inline(always)]
pub fn cx<T: Real>(re: f64, im: f64) -> Cx<T> {
    Complex::new(T::cst(re), T::cst(im))
}

/// The real number `x` as a complex one.
#[inline(always)]
pub fn real<T: Real>(x: T) -> Cx<T> {
    Complex::new(x, T::zero())
}

/// Principal square root (`Re ≥ 0`, branch cut on the negative real axis, `sqrt(−x ± 0i) =
/// ±i√x`), by the algebraic formula without trigonometry and without cancellation.
#[inline]
pub fn sqrt<T: Real>(z: Cx<T>) -> Cx<T> {
    let zero = T::zero();
    z.im.equals(zero).when(
        || {
            z.re.ge(zero).when(
                || Complex::new(z.re.safe_sqrt(), z.im),
                || Complex::new(zero, (-z.re).safe_sqrt().copysign(z.im)),
            )
        },
        || {
            let m = z.re.hypot(z.im);
            z.re.ge(zero).when(
                || {
                    let t = ((m + z.re) * 0.5).safe_sqrt();
                    Complex::new(t, z.im / nonzero(t * 2.0))
                },
                || {
                    let t = ((m - z.re) * 0.5).safe_sqrt();
                    Complex::new(z.im.abs() / nonzero(t * 2.0), t.copysign(z.im))
                },
            )
        },
    )
}

/// `x`, or the smallest normal number where `x` is smaller: a denominator that is positive
/// wherever its branch is taken, kept finite in the lanes that discard the branch (whose
/// derivatives would otherwise be NaN while recording).
#[inline(always)]
fn nonzero<T: Real>(x: T) -> T {
    x.max(T::cst(f64::MIN_POSITIVE))
}

/// `1/z` with one real division (`z̄ · (1/|z|²)`).
#[inline(always)]
pub fn inv<T: Real>(z: Cx<T>) -> Cx<T> {
    let r = (z.re * z.re + z.im * z.im).recip();
    Complex::new(z.re * r, -z.im * r)
}

/// `e^z`; for a purely imaginary `z` (a lossless layer's phase) without the real exponential.
#[inline(always)]
pub fn exp<T: Real>(z: Cx<T>) -> Cx<T> {
    let (s, c) = z.im.sin_cos();
    z.re.equals(T::zero()).when(
        || Complex::new(c, s),
        || {
            let m = z.re.exp();
            Complex::new(c * m, s * m)
        },
    )
}

/// `|z|²`.
#[inline(always)]
pub fn norm_sqr<T: Real>(z: Cx<T>) -> T {
    z.re * z.re + z.im * z.im
}

/// True where the imaginary part is exactly zero.
#[inline(always)]
pub fn is_real<T: Real>(z: Cx<T>) -> T::Mask {
    z.im.equals(T::zero())
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64 as C64;

    /// The generic square root on `f64` is the principal branch, signed zeros included.
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
        assert_eq!(sqrt(C64::new(-4.0, -0.0)), C64::new(0.0, -2.0));
    }

    #[test]
    fn exp_and_inv() {
        for z in [
            C64::new(0.0, 3.0),
            C64::new(-0.5, 2.0),
            C64::new(1.5, -0.25),
        ] {
            assert!((exp(z) - z.exp()).norm() < 1e-15 * z.exp().norm());
            assert!((inv(z) * z - C64::new(1.0, 0.0)).norm() < 1e-15);
        }
    }
}
