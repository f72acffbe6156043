//! A dispersive stack's interface blocks across a spectrum, interpolated: they depend on the
//! wavelength only through the indices (smooth Sellmeier fits), while the propagation phases
//! `k d q` oscillate and are computed exactly at every point. A quadrature of hundreds of
//! points then solves the `N + 1` interfaces at a few Chebyshev nodes only (a Chebyshev series,
//! Trefethen, *Approximation Theory and Approximation Practice*, ch. 3).
//!
//! The interpolant is accepted only if it reproduces the exact blocks at check points between
//! its nodes to [`TOLERANCE`] of the largest value; [`NODES`] nodes serve most crystals,
//! [`MORE_NODES`] the strongly dispersive ones; else (a critical angle or a degenerate mode
//! inside the band, where the blocks are not smooth) the caller solves every point exactly.

use crate::error::Result;
use num_complex::Complex64 as C64;

/// Chebyshev nodes of the first attempt.
pub const NODES: usize = 16;
/// Chebyshev nodes of the second attempt.
pub const MORE_NODES: usize = 32;
/// Largest accepted error at the check points, relative to the largest value: the blocks enter
/// the light linearly or quadratically (amplitudes of at most 1), so an error of 1e-7 is a
/// hundred times below the rules' tolerance of 1e-5 (the phases, which need far more digits,
/// are computed exactly).
pub const TOLERANCE: f64 = 1e-7;
/// Trailing coefficients are dropped while their sum stays below this, relative to the largest
/// value.
pub const TRUNCATION: f64 = 1e-8;
/// Where the interpolant is checked, in `[−1, 1]` (between nodes, ends included).
const CHECKS: [f64; 4] = [-0.999, -0.61, 0.17, 0.93];

/// Chebyshev coefficients of a vector of values on `[lo, hi]` (wavenumbers).
pub struct Interpolant {
    /// `coefficients[n][i]`: the coefficient of `T_n` of value `i`.
    coefficients: Vec<Vec<C64>>,
    lo: f64,
    hi: f64,
}

/// The series without its trailing coefficients as long as their magnitudes sum to at most
/// `budget` (`|T_n| ≤ 1` on the interval: that sum bounds the change of every value).
fn truncated(mut c: Vec<Vec<C64>>, budget: f64) -> Vec<Vec<C64>> {
    let mut dropped = 0.0;
    while c.len() > 1 {
        let last = c[c.len() - 1].iter().map(|z| z.norm()).fold(0.0, f64::max);
        if dropped + last > budget {
            break;
        }
        dropped += last;
        c.pop();
    }
    c
}

impl Interpolant {
    /// Interpolates `exact(k)` on `[lo, hi]` with [`NODES`], else [`MORE_NODES`] nodes;
    /// `Ok(None)` if both fail their check.
    pub fn new(lo: f64, hi: f64, exact: &dyn Fn(f64) -> Result<Vec<C64>>) -> Result<Option<Self>> {
        for nodes in [NODES, MORE_NODES] {
            if let Some(f) = Self::with_nodes(nodes, lo, hi, exact)? {
                return Ok(Some(f));
            }
        }
        Ok(None)
    }

    fn with_nodes(
        nodes: usize,
        lo: f64,
        hi: f64,
        exact: &dyn Fn(f64) -> Result<Vec<C64>>,
    ) -> Result<Option<Self>> {
        let k_of = |t: f64| 0.5 * (lo + hi) + 0.5 * (hi - lo) * t;
        let angle = |j: usize| std::f64::consts::PI * (j as f64 + 0.5) / nodes as f64;
        let samples: Vec<Vec<C64>> = (0..nodes)
            .map(|j| exact(k_of(angle(j).cos())))
            .collect::<Result<_>>()?;
        let width = samples[0].len();
        let coefficients = (0..nodes)
            .map(|n| {
                let scale = if n == 0 { 1.0 } else { 2.0 } / nodes as f64;
                let mut c = vec![C64::new(0.0, 0.0); width];
                for (j, s) in samples.iter().enumerate() {
                    let w = scale * (n as f64 * angle(j)).cos();
                    for (ci, si) in c.iter_mut().zip(s) {
                        *ci += si * w;
                    }
                }
                c
            })
            .collect();
        let largest = samples
            .iter()
            .flatten()
            .map(|z| z.norm())
            .fold(0.0, f64::max);
        let f = Interpolant {
            coefficients: truncated(coefficients, TRUNCATION * largest),
            lo,
            hi,
        };
        for t in CHECKS {
            let (want, got) = (exact(k_of(t))?, f.at(k_of(t)));
            let err = want
                .iter()
                .zip(&got)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            if err.is_nan() || err > TOLERANCE * largest {
                return Ok(None);
            }
        }
        Ok(Some(f))
    }

    /// The interpolated values at wavenumber `k` (inside `[lo, hi]`).
    pub fn at(&self, k: f64) -> Vec<C64> {
        let mut out = vec![C64::new(0.0, 0.0); self.coefficients[0].len()];
        self.at_into(k, &mut out);
        out
    }

    /// [`Interpolant::at`] into `out`: `Σ_n c_n T_n(t)` by the three-term recurrence (stable on
    /// `[−1, 1]`).
    pub fn at_into(&self, k: f64, out: &mut [C64]) {
        let t = (2.0 * k - self.lo - self.hi) / (self.hi - self.lo);
        out.copy_from_slice(&self.coefficients[0]);
        let (mut previous, mut current) = (1.0, t);
        for c in &self.coefficients[1..] {
            for (o, ci) in out.iter_mut().zip(c) {
                *o += ci * current;
            }
            (previous, current) = (current, 2.0 * t * current - previous);
        }
    }
}
