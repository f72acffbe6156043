//! A dispersive plate's amplitudes across a spectrum, interpolated: the interface blocks, the
//! layer's normal components and the flux factor ([`SlabBlocks`]) depend on the wavelength only
//! through the indices, which vary slowly (Sellmeier fits away from their poles), while the
//! propagation phases `k d q` oscillate. A quadrature of the plate over a wide band needs the
//! exact plate at hundreds of wavenumbers; solving both interfaces at a few Chebyshev nodes
//! and interpolating the blocks (a Chebyshev series, e.g. Trefethen, *Approximation Theory and
//! Approximation Practice*, ch. 3) gives each quadrature node for the cost of the phases.
//!
//! The interpolant is accepted only if it reproduces the exact blocks at check points between
//! the nodes to [`TOLERANCE`] (relative to the largest value). [`NODES`] Chebyshev nodes serve
//! most crystals across the visible; strongly dispersive ones (rutile, whose coefficients decay
//! only ~3x per degree near its UV absorption) are tried again with [`MORE_NODES`]. Otherwise (a
//! critical angle or a degenerate mode inside the band, where the blocks are not smooth) the
//! caller solves every node exactly.

use crate::error::Result;
use crate::plate::slab::{SlabBlocks, BLOCK_VALUES};
use num_complex::Complex64 as C64;

/// Chebyshev nodes of the interpolant.
pub const NODES: usize = 16;
/// Chebyshev nodes of the second attempt.
pub const MORE_NODES: usize = 32;
/// Largest accepted interpolation error at the check points, relative to the largest value.
pub const TOLERANCE: f64 = 1e-10;
/// Where the interpolant is checked, in `[−1, 1]` (between nodes, ends included).
const CHECKS: [f64; 4] = [-0.999, -0.61, 0.17, 0.93];

/// Chebyshev coefficients of every value of the blocks on `[lo, hi]` (wavenumbers).
pub struct BlockInterpolant {
    coefficients: Vec<[C64; BLOCK_VALUES]>,
    lo: f64,
    hi: f64,
    thickness_nm: f64,
}

/// The series without its trailing coefficients as long as their magnitudes sum to at most
/// `budget` (`|T_n| ≤ 1` on the interval: that sum bounds the change of every value).
fn truncated(mut c: Vec<[C64; BLOCK_VALUES]>, budget: f64) -> Vec<[C64; BLOCK_VALUES]> {
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

impl BlockInterpolant {
    /// Interpolates `exact(k)` on `[lo, hi]` with [`NODES`], else [`MORE_NODES`] nodes;
    /// `Ok(None)` if both checks fail.
    pub fn new(
        lo: f64,
        hi: f64,
        thickness_nm: f64,
        exact: &dyn Fn(f64) -> Result<SlabBlocks>,
    ) -> Result<Option<Self>> {
        for nodes in [NODES, MORE_NODES] {
            if let Some(f) = Self::with_nodes(nodes, lo, hi, thickness_nm, exact)? {
                return Ok(Some(f));
            }
        }
        Ok(None)
    }

    /// The interpolant with `nodes` Chebyshev nodes, if it passes its check.
    fn with_nodes(
        nodes: usize,
        lo: f64,
        hi: f64,
        thickness_nm: f64,
        exact: &dyn Fn(f64) -> Result<SlabBlocks>,
    ) -> Result<Option<Self>> {
        let k_of = |t: f64| 0.5 * (lo + hi) + 0.5 * (hi - lo) * t;
        let angle = |j: usize| std::f64::consts::PI * (j as f64 + 0.5) / nodes as f64;
        let samples: Vec<[C64; BLOCK_VALUES]> = (0..nodes)
            .map(|j| exact(k_of(angle(j).cos())).map(|b| b.values()))
            .collect::<Result<_>>()?;
        let coefficients = (0..nodes)
            .map(|n| {
                let scale = if n == 0 { 1.0 } else { 2.0 } / nodes as f64;
                let mut c = [C64::new(0.0, 0.0); BLOCK_VALUES];
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
            .flat_map(|s| s.iter().map(|z| z.norm()))
            .fold(0.0, f64::max);
        let f = BlockInterpolant {
            coefficients: truncated(coefficients, 0.1 * TOLERANCE * largest),
            lo,
            hi,
            thickness_nm,
        };
        for t in CHECKS {
            let (want, got) = (exact(k_of(t))?.values(), f.values(k_of(t)));
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

    /// The interpolated blocks at wavenumber `k` (inside `[lo, hi]`).
    pub fn at(&self, k: f64) -> SlabBlocks {
        SlabBlocks::from_values(&self.values(k), self.thickness_nm)
    }

    /// `Σ_n c_n T_n(t)` for every value at once, `T_n` by their three-term recurrence (stable
    /// on `[−1, 1]`, where `|T_n| ≤ 1`); one multiply-add per value and degree.
    fn values(&self, k: f64) -> [C64; BLOCK_VALUES] {
        let t = (2.0 * k - self.lo - self.hi) / (self.hi - self.lo);
        let mut out = self.coefficients[0];
        let (mut previous, mut current) = (1.0, t);
        for c in &self.coefficients[1..] {
            for (o, ci) in out.iter_mut().zip(c) {
                *o += ci * current;
            }
            (previous, current) = (current, 2.0 * t * current - previous);
        }
        out
    }
}
