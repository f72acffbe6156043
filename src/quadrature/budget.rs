//! The error budget of the closed-form integration over colour channels: what every
//! approximation of [`crate::spectral::route`]'s methods may leave, in one place.
//!
//! The perceptual budget is a mean CIEDE2000 of 0.1 and a worst of 0.5 against dense quadrature
//! of the exact plate with the tabulated weights (measured in `tests/spectral_rgb.rs`, its
//! near-grazing plate included, and on the extended set of `make bench`: 0-89.5 degrees, 0 µm
//! up; each route against dense quadrature with the fitted weights in
//! `tests/spectral_routes.rs`). Near black, where CIELAB is steepest (`L* = 903 Y`,
//! `a* ≈ 3900 (X − Y)`), an error of 1e-4 in a channel is already 0.4, so each approximation is
//! held to 1e-5 absolute, in units of the white response 1. The Gaussian fits of the weights
//! add their own error (1.7e-3 to 7.9e-3 in L1, mostly at path differences beyond 10 µm), which
//! dominates.

/// A group of fringes (or a family of cross-order pairs) whose amplitude times its visibility
/// is below this is dropped.
pub const DROP: f64 = 1e-5;

/// Largest interpolation error a fringe's slow factor may leave on its nodes (times its
/// amplitude).
pub const NODE_ERROR: f64 = 1e-5;

/// Coherent orders of the path classes are kept until the coherence of the next ones falls
/// below this; the rest is the incoherent tail.
pub const ORDER_TAIL: f64 = 1e-5;

/// A traversal attenuated by more than `e^{−ATTENUATED}` over the whole band carries nothing
/// (its phase rate does not size any rule).
pub const ATTENUATED: f64 = 40.0;

/// The error of interpolating `e^{iωt}` (or `e^{−ωt}`) on `n` Chebyshev–Lobatto nodes of
/// `[−1, 1]`: its Chebyshev coefficients are `2 J_j(ω)` (`2 I_j(ω)`), at most
/// `2 (ω/2)^j / j!` times `e^{ω²/4(j+1)}`, and the interpolant errs by at most twice the sum of
/// those it leaves out (aliasing), `≈ 4 (ω/2)^n / n!` while `ω < n`. One node: the
/// function's whole variation, `|ω|`.
pub fn interpolation_error(n: usize, omega: f64) -> f64 {
    let half = 0.5 * omega.abs();
    if n == 1 {
        return omega.abs();
    }
    let term = (1..=n).fold(4.0, |e, j| e * half / j as f64);
    term * (half * half / (n as f64 + 1.0)).exp()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::nodes::{lobatto, LEVELS};
    use num_complex::Complex64 as C64;

    /// The bound holds for the actual interpolant of `e^{iωt}` on each level's nodes, measured
    /// on a fine grid (barycentric evaluation), from slow to fast oscillations.
    #[test]
    fn interpolation_error_bounds_the_interpolant() {
        for &n in &LEVELS[1..] {
            let x = lobatto(n);
            for omega in [0.01, 0.1, 0.5, 1.0, 2.0, 4.0, 7.0, 10.0] {
                let f = |t: f64| C64::new(0.0, omega * t).exp();
                let mut basis = vec![C64::new(0.0, 0.0); n];
                let mut worst = 0.0f64;
                for s in 0..=400 {
                    let t = -1.0 + 2.0 * s as f64 / 400.0;
                    crate::quadrature::nodes::lagrange(&x, C64::new(t, 0.0), &mut basis);
                    let p: C64 = x.iter().zip(&basis).map(|(&xi, b)| f(xi) * b).sum();
                    worst = worst.max((p - f(t)).norm());
                }
                // Beyond the bound, the rounding of the barycentric evaluation (~1e-15).
                let bound = interpolation_error(n, omega);
                assert!(
                    worst <= bound.max(1e-13),
                    "n {n}, omega {omega}: {worst:e} > {bound:e}"
                );
            }
        }
    }
}
