//! A dispersive plate's amplitudes across a spectrum, interpolated: the interface blocks, the
//! layer's normal components and the flux factor ([`SlabBlocks`]) depend on the wavelength only
//! through the indices, which vary slowly (Sellmeier fits away from their poles), while the
//! propagation phases `k d q` oscillate. A quadrature of the plate over a wide band needs the
//! exact plate at hundreds of wavenumbers; solving both interfaces at a few Chebyshev nodes
//! and interpolating the blocks (Clenshaw's recurrence, e.g. Trefethen, *Approximation Theory
//! and Approximation Practice*, ch. 3) gives each quadrature node for the cost of the phases.
//!
//! The interpolant is accepted only if it reproduces the exact blocks at check points between
//! the nodes to [`TOLERANCE`] (relative to the largest value); otherwise (a critical angle or a
//! degenerate mode inside the band, where the blocks are not smooth) the caller solves every
//! node exactly.

use crate::error::Result;
use crate::slab::{SlabBlocks, BLOCK_VALUES};
use num_complex::Complex64 as C64;

/// Chebyshev nodes of the interpolant.
pub const NODES: usize = 16;
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

impl BlockInterpolant {
    /// Interpolates `exact(k)` on `[lo, hi]`; `Ok(None)` if the check fails.
    pub fn new(
        lo: f64,
        hi: f64,
        thickness_nm: f64,
        exact: &dyn Fn(f64) -> Result<SlabBlocks>,
    ) -> Result<Option<Self>> {
        let k_of = |t: f64| 0.5 * (lo + hi) + 0.5 * (hi - lo) * t;
        let angle = |j: usize| std::f64::consts::PI * (j as f64 + 0.5) / NODES as f64;
        let samples: Vec<[C64; BLOCK_VALUES]> = (0..NODES)
            .map(|j| exact(k_of(angle(j).cos())).map(|b| b.values()))
            .collect::<Result<_>>()?;
        let coefficients = (0..NODES)
            .map(|n| {
                let scale = if n == 0 { 1.0 } else { 2.0 } / NODES as f64;
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
        let f = BlockInterpolant {
            coefficients,
            lo,
            hi,
            thickness_nm,
        };
        let largest = samples
            .iter()
            .flat_map(|s| s.iter().map(|z| z.norm()))
            .fold(0.0, f64::max);
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

    /// Clenshaw's recurrence for every value at once.
    fn values(&self, k: f64) -> [C64; BLOCK_VALUES] {
        let t = (2.0 * k - self.lo - self.hi) / (self.hi - self.lo);
        let zero = C64::new(0.0, 0.0);
        let (mut b1, mut b2) = ([zero; BLOCK_VALUES], [zero; BLOCK_VALUES]);
        for c in self.coefficients[1..].iter().rev() {
            for ((ci, x1), x2) in c.iter().zip(b1.iter_mut()).zip(b2.iter_mut()) {
                let b = ci + *x1 * (2.0 * t) - *x2;
                *x2 = *x1;
                *x1 = b;
            }
        }
        let c0 = &self.coefficients[0];
        std::array::from_fn(|i| c0[i] + b1[i] * t - b2[i])
    }
}
