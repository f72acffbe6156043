//! The exact plate on a shared product-integration rule of the weights
//! ([`crate::quadrature::chebyshev`]), its interface blocks interpolated from the survey's amplitude
//! nodes (polynomials of the level's degree, exact at the nodes, within
//! [`crate::spectral::amplitudes::AMPLITUDE_TOLERANCE`] between them) and its phases from the
//! interpolated normal components: the route of the plates no closed form serves
//! ([`crate::spectral::route`]). Every point solves the plate once and serves the three
//! channels.

use crate::colour::weights::WeightSet;
use crate::error::Result;
use crate::plate::slab::{Output, SlabBlocks, SlabMueller, Want, BLOCK_VALUES};
use crate::quadrature::chebyshev;
use crate::quadrature::nodes::{self, MAX_NODES};
use crate::spectral::survey::Survey;
use nalgebra::Matrix4;
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;

/// `∫ w_c M` for the channels of `set` on the shared rule of `points` points.
pub fn channels(
    s: &Survey,
    points: usize,
    set: WeightSet,
    want: Want,
    output: Output,
) -> Result<[SlabMueller; 3]> {
    let rule = chebyshev::rule(set, points);
    let level = s.amplitudes.level;
    let lv = nodes::level(level);
    let n = lv.nodes.len();
    let thickness = s.plate.thickness_nm;
    // Each node's values, once.
    let mut values = [[C64::new(0.0, 0.0); BLOCK_VALUES]; MAX_NODES];
    for (v, &j) in values.iter_mut().zip(&lv.in_finest) {
        *v = s.amplitudes.exact(j).expect("an amplitude node").values();
    }
    let basis = chebyshev::node_basis(set, points, level);
    let mut acc = [[Matrix4::<f64>::zeros(); 2]; 3];
    let mut v = [C64::new(0.0, 0.0); BLOCK_VALUES];
    for (&(k, w), b) in rule.nodes.iter().zip(basis.chunks_exact(n)) {
        let blocks = if n == 1 {
            *s.amplitudes.centre()
        } else {
            v.iter_mut().for_each(|x| *x = C64::new(0.0, 0.0));
            for (node, &bi) in values[..n].iter().zip(b) {
                for (x, y) in v.iter_mut().zip(node) {
                    *x += y * bi;
                }
            }
            SlabBlocks::from_values(&v, thickness)
        };
        let m = blocks.mueller(TAU / k, want)?;
        for (sums, wc) in acc.iter_mut().zip(w) {
            for (sum, lobe) in sums.iter_mut().zip([m.r, m.t]) {
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
