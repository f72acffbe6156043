//! The exact plate on a weight set's Chebyshev product-integration rule
//! ([`crate::quadrature::chebyshev`]): `∫ w_c(k) M(k) dk ≈ Σ_j W_cj M(k_j)`, the plate solved at
//! every point `k_j` and serving the three channels at once. Its interface blocks, the layer's
//! normal components and the flux factor ([`SlabBlocks`]) depend on the wavelength only through
//! the indices: without dispersion they are solved once; with it they are interpolated across
//! the rule's support ([`BlockInterpolant`], accepted only where it reproduces the exact blocks
//! to [`TOLERANCE`] at check points between its nodes), else solved at every point (a wave
//! turning evanescent inside the band, a critical angle: where the blocks are not smooth). The
//! phases `k d q` are taken from the (interpolated) normal components at each point.

use crate::colour::weights::WeightSet;
use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::plate::slab::{Output, SlabBlocks, SlabMueller, Want, BLOCK_VALUES};
use crate::plate::Plate;
use crate::quadrature::chebyshev::rule;
use crate::quadrature::interpolate::Interpolant;
use nalgebra::Matrix4;
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;

/// Largest accepted interpolation error of a plate's blocks at the check points, relative to
/// the largest value.
pub const TOLERANCE: f64 = 1e-10;
/// Trailing coefficients of a plate's blocks are dropped while their sum stays below this,
/// relative to the largest value.
const TRUNCATION: f64 = 0.1 * TOLERANCE;

/// `∫ w_c(k) M(k) dk` for the three channels of `set` on the Chebyshev rule of `points` points
/// ([`crate::quadrature::chebyshev`]), the plate solved at every point (module docs).
pub fn channels(
    plate: &Plate,
    frame: &PlaneFrame,
    beta: C64,
    set: WeightSet,
    points: usize,
    want: Want,
    output: Output,
) -> Result<[SlabMueller; 3]> {
    let rule = rule(set, points);
    // The blocks at each node: fixed without dispersion; else interpolated across the band
    // (checked; exact at every node where the interpolant is refused).
    let exact =
        |k: f64| -> Result<SlabBlocks> { Ok(plate.at(TAU / k)?.optics(frame, beta)?.blocks()) };
    let centre = 0.5 * (rule.lo + rule.hi);
    let fixed = if plate.is_dispersive() {
        None
    } else {
        Some(exact(centre)?)
    };
    let interpolant = match fixed {
        Some(_) => None,
        None => BlockInterpolant::new(rule.lo, rule.hi, plate.thickness_nm, &exact)?,
    };
    let mut acc = [[Matrix4::zeros(); 2]; 3];
    for &(k, w) in &rule.nodes {
        let blocks = match (fixed, &interpolant) {
            (Some(b), _) => b,
            (None, Some(f)) => f.at(k),
            (None, None) => exact(k)?,
        };
        let m = blocks.mueller(TAU / k, want)?;
        let lobes = [m.r, m.t];
        for (sums, wc) in acc.iter_mut().zip(w) {
            for (sum, lobe) in sums.iter_mut().zip(&lobes) {
                match (lobe, output) {
                    (Some(x), Output::Mueller) => *sum += x * wc,
                    (Some(x), Output::Intensity) => sum[(0, 0)] += x[(0, 0)] * wc,
                    (None, _) => {}
                }
            }
        }
    }
    Ok(acc.map(|[r, t]| SlabMueller {
        r: want.reflection.then_some(r),
        t: want.transmission.then_some(t),
    }))
}

/// A plate's blocks ([`SlabBlocks::values`]) interpolated by an [`Interpolant`], checked to
/// [`TOLERANCE`].
pub struct BlockInterpolant {
    values: Interpolant,
    thickness_nm: f64,
}

impl BlockInterpolant {
    /// Interpolates `exact(k)` on `[lo, hi]` to [`TOLERANCE`] ([`Interpolant::new`]);
    /// `Ok(None)` if it cannot.
    pub fn new(
        lo: f64,
        hi: f64,
        thickness_nm: f64,
        exact: &dyn Fn(f64) -> Result<SlabBlocks>,
    ) -> Result<Option<Self>> {
        let values = |k: f64| exact(k).map(|b| b.values().to_vec());
        Ok(
            Interpolant::new((lo, hi), (TOLERANCE, TRUNCATION), &values)?.map(|values| {
                BlockInterpolant {
                    values,
                    thickness_nm,
                }
            }),
        )
    }

    /// The interpolated blocks at wavenumber `k` (inside `[lo, hi]`).
    pub fn at(&self, k: f64) -> SlabBlocks {
        let mut v = [C64::new(0.0, 0.0); BLOCK_VALUES];
        self.values.at_into(k, &mut v);
        SlabBlocks::from_values(&v, self.thickness_nm)
    }
}
