//! A plate's interface blocks across the visible band: solved exactly at the Chebyshev–Lobatto
//! nodes of one level ([`crate::spectral::nodes`]) and interpolated between them. The blocks
//! depend on the wavelength only through the principal indices, so the level is the one whose
//! nodes interpolate the indices to [`INDEX_TOLERANCE`]; a weaker contribution can take a
//! coarser level ([`Amplitudes::level_for`]), each level's interpolation error of the indices
//! being known.

use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::optics::modes::ModeKind;
use crate::plate::slab::{SlabBlocks, BLOCK_VALUES};
use crate::plate::Plate;
use crate::spectral::fringe;
use crate::spectral::nodes::{self, FINEST, LEVELS, MAX_NODES};
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;

/// Amplitude nodes are added until the indices' interpolation between them is this close
/// (relative) for a contribution of unit strength: the Fresnel amplitudes then follow to about
/// the same relative accuracy (a few 1e-5 of the light, below what CIEDE2000 resolves).
pub const INDEX_TOLERANCE: f64 = 3e-4;

/// The blocks of a plate at the nodes of one level.
pub struct Amplitudes {
    /// The level (index into [`LEVELS`]).
    pub level: usize,
    /// The blocks at each of the level's nodes, and their values.
    pub blocks: Vec<(SlabBlocks, [C64; BLOCK_VALUES])>,
    /// An isotropic layer: s and p share their phase (one mode count).
    pub merged: bool,
    /// The indices' largest relative interpolation error on each level (zero without
    /// dispersion).
    errors: [f64; LEVELS.len()],
}

/// The phase per traversal `[o↓, e↓, o↑, e↑]` (the factor of `k d` in a class's phase) from
/// the layer's normal components.
pub fn traversal_q(q: &[C64; 4]) -> [C64; 4] {
    [-q[0], -q[1], q[2], q[3]]
}

/// The indices' largest relative interpolation error on each level, checked at the finest
/// level's nodes (zero without dispersion).
fn index_errors(plate: &Plate) -> Result<[f64; LEVELS.len()]> {
    let mut errors = [0.0; LEVELS.len()];
    if !plate.is_dispersive() {
        return Ok(errors);
    }
    let (k0, a) = fringe::band();
    let finest = &nodes::level(FINEST).nodes;
    let mut indices = [[C64::new(0.0, 0.0); 2]; MAX_NODES];
    for (x, t) in indices.iter_mut().zip(finest) {
        let (o, e) = plate
            .material
            .indices(TAU / (k0 + a * t), plate.birefringence)?;
        *x = [o, e];
    }
    for (l, e) in errors.iter_mut().enumerate().take(FINEST) {
        let lv = nodes::level(l);
        *e = (0..MAX_NODES)
            .flat_map(|j| (0..2).map(move |m| (j, m)))
            .map(|(j, m)| {
                let v: C64 = lv
                    .in_finest
                    .iter()
                    .zip(&lv.to_finest[j])
                    .map(|(&i, w)| indices[i][m] * w)
                    .sum();
                (v - indices[j][m]).norm() / indices[j][m].norm()
            })
            .fold(0.0, f64::max);
    }
    Ok(errors)
}

impl Amplitudes {
    /// The blocks of `plate` for incidence `beta` in the plane of `frame`, on the level that
    /// a contribution of unit strength needs.
    pub fn new(plate: &Plate, frame: &PlaneFrame, beta: C64) -> Result<Self> {
        let errors = index_errors(plate)?;
        let level = (0..LEVELS.len())
            .find(|&l| errors[l] <= INDEX_TOLERANCE)
            .unwrap_or(FINEST);
        let (k0, a) = fringe::band();
        let mut blocks = Vec::with_capacity(LEVELS[level]);
        let mut merged = false;
        for t in &nodes::level(level).nodes {
            let optics = plate.at(TAU / (k0 + a * t))?.optics(frame, beta)?;
            merged = optics.layer_modes().down[0].kind == ModeKind::S;
            let b = optics.blocks();
            blocks.push((b, b.values()));
        }
        Ok(Amplitudes {
            level,
            blocks,
            merged,
            errors,
        })
    }

    /// The blocks at the band's centre (a node of every level).
    pub fn centre(&self) -> &SlabBlocks {
        &self.blocks[self.blocks.len() / 2].0
    }

    /// The coarsest level (at most [`Amplitudes::level`]) on which a contribution of
    /// `strength` (relative to the direct light) meets [`INDEX_TOLERANCE`].
    pub fn level_for(&self, strength: f64) -> usize {
        (0..self.level)
            .find(|&l| strength * self.errors[l] <= INDEX_TOLERANCE)
            .unwrap_or(self.level)
    }

    /// The blocks at node `i` of level `level` (`level ≤` [`Amplitudes::level`]).
    pub fn at(&self, level: usize, i: usize) -> &SlabBlocks {
        let own = nodes::level(self.level);
        let finest = nodes::level(level).in_finest[i];
        let n = own
            .in_finest
            .iter()
            .position(|&f| f == finest)
            .expect("a coarser level's nodes are among the finer level's");
        &self.blocks[n].0
    }

    /// `d(k Re Q)/dk` per traversal at the centre: the derivative of the interpolant of
    /// `k Re Q(k)` through the nodes (`Re Q` without dispersion).
    pub fn group_indices(&self) -> [f64; 4] {
        if self.blocks.len() == 1 {
            return traversal_q(&self.blocks[0].0.q).map(|x| x.re);
        }
        let (k0, a) = fringe::band();
        let lv = nodes::level(self.level);
        let mut g = [0.0; 4];
        for (((b, _), t), w) in self.blocks.iter().zip(&lv.nodes).zip(&lv.slope) {
            let q = traversal_q(&b.q);
            for (gm, qm) in g.iter_mut().zip(q) {
                *gm += (k0 + a * t) * qm.re * w / a;
            }
        }
        g
    }
}
