//! Values that vary slowly across a spectrum (a plate's or a stack's interface blocks, which
//! depend on the wavelength only through the indices: Sellmeier fits away from their poles),
//! interpolated by a checked Chebyshev series (e.g. Trefethen, *Approximation Theory and
//! Approximation Practice*, ch. 3), so that a quadrature over a wide band pays for the exact
//! solves only at a few nodes and for the phases at every point.
//!
//! The interpolant is accepted only if it reproduces the exact values at check points between
//! the nodes to the caller's tolerance (relative to the largest value). [`NODES`] Chebyshev
//! nodes serve most crystals across the visible; strongly dispersive ones (rutile, whose
//! coefficients decay only ~3x per degree near its UV absorption) are tried again with
//! [`MORE_NODES`]. Otherwise (a critical angle or a degenerate mode inside the band, where the
//! values are not smooth) the caller solves every point exactly.

use crate::error::Result;
use num_complex::Complex64 as C64;

/// Chebyshev nodes of the interpolant.
pub const NODES: usize = 16;
/// Chebyshev nodes of the second attempt.
pub const MORE_NODES: usize = 32;
/// Where the interpolant is checked, in `[−1, 1]` (between nodes, ends included).
const CHECKS: [f64; 4] = [-0.999, -0.61, 0.17, 0.93];

/// Chebyshev coefficients of a vector of complex values on `[lo, hi]` (wavenumbers).
pub struct Interpolant {
    /// The coefficient of `T_n` of value `i` at `n · width + i`.
    coefficients: Vec<C64>,
    width: usize,
    lo: f64,
    hi: f64,
}

/// The series without its trailing coefficients as long as their magnitudes sum to at most
/// `budget` (`|T_n| ≤ 1` on the interval: that sum bounds the change of every value).
fn truncated(mut c: Vec<C64>, width: usize, budget: f64) -> Vec<C64> {
    let mut dropped = 0.0;
    while c.len() > width {
        let last = c[c.len() - width..]
            .iter()
            .map(|z| z.norm())
            .fold(0.0, f64::max);
        if dropped + last > budget {
            break;
        }
        dropped += last;
        c.truncate(c.len() - width);
    }
    c
}

impl Interpolant {
    /// Interpolates `exact(k)` on `[lo, hi]` with [`NODES`], else [`MORE_NODES`] nodes, its
    /// trailing coefficients dropped while their sum stays below `truncation` of the largest
    /// value; `Ok(None)` if both miss the exact values at the check points by more than
    /// `tolerance` of the largest value.
    pub fn new(
        (lo, hi): (f64, f64),
        (tolerance, truncation): (f64, f64),
        exact: &dyn Fn(f64) -> Result<Vec<C64>>,
    ) -> Result<Option<Self>> {
        for nodes in [NODES, MORE_NODES] {
            if let Some(f) = Self::with_nodes(nodes, (lo, hi), (tolerance, truncation), exact)? {
                return Ok(Some(f));
            }
        }
        Ok(None)
    }

    /// The interpolant with `nodes` Chebyshev nodes, if it passes its check.
    fn with_nodes(
        nodes: usize,
        (lo, hi): (f64, f64),
        (tolerance, truncation): (f64, f64),
        exact: &dyn Fn(f64) -> Result<Vec<C64>>,
    ) -> Result<Option<Self>> {
        let k_of = |t: f64| 0.5 * (lo + hi) + 0.5 * (hi - lo) * t;
        let angle = |j: usize| std::f64::consts::PI * (j as f64 + 0.5) / nodes as f64;
        let samples: Vec<Vec<C64>> = (0..nodes)
            .map(|j| exact(k_of(angle(j).cos())))
            .collect::<Result<_>>()?;
        let width = samples[0].len();
        let mut coefficients = vec![C64::new(0.0, 0.0); nodes * width];
        for (n, c) in coefficients.chunks_exact_mut(width).enumerate() {
            let scale = if n == 0 { 1.0 } else { 2.0 } / nodes as f64;
            for (j, s) in samples.iter().enumerate() {
                let w = scale * (n as f64 * angle(j)).cos();
                for (ci, si) in c.iter_mut().zip(s) {
                    *ci += si * w;
                }
            }
        }
        let largest = samples
            .iter()
            .flatten()
            .map(|z| z.norm())
            .fold(0.0, f64::max);
        let f = Interpolant {
            coefficients: truncated(coefficients, width, truncation * largest),
            width,
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
            if err.is_nan() || err > tolerance * largest {
                return Ok(None);
            }
        }
        Ok(Some(f))
    }

    /// The interpolated values at wavenumber `k` (inside `[lo, hi]`).
    pub fn at(&self, k: f64) -> Vec<C64> {
        let mut out = vec![C64::new(0.0, 0.0); self.width];
        self.at_into(k, &mut out);
        out
    }

    /// [`Interpolant::at`] into `out`: `Σ_n c_n T_n(t)` for every value at once, `T_n` by
    /// their three-term recurrence (stable on `[−1, 1]`, where `|T_n| ≤ 1`); one multiply-add
    /// per value and degree.
    pub fn at_into(&self, k: f64, out: &mut [C64]) {
        let t = (2.0 * k - self.lo - self.hi) / (self.hi - self.lo);
        let mut degrees = self.coefficients.chunks_exact(self.width);
        out.copy_from_slice(degrees.next().expect("at least one coefficient"));
        let (mut previous, mut current) = (1.0, t);
        for c in degrees {
            for (o, ci) in out.iter_mut().zip(c) {
                *o += ci * current;
            }
            (previous, current) = (current, 2.0 * t * current - previous);
        }
    }
}
