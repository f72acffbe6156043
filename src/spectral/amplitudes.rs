//! A plate's interface blocks across the visible band: solved exactly at the Chebyshev–Lobatto
//! nodes of one level ([`crate::spectral::nodes`]) and interpolated between them. The level
//! is the coarsest whose interpolant's last two Chebyshev coefficients (an upper estimate of
//! its error: the coefficients of functions analytic around the band decay geometrically)
//! stay within [`AMPLITUDE_TOLERANCE`] for every block entry; the levels are nested, so each
//! refinement solves only the new nodes. A weaker contribution can take a coarser level
//! ([`Amplitudes::level_for`]): each coarser level's error is measured at the finer nodes.
//! The amplitudes' own variation decides, not the indices': near grazing incidence or a
//! critical angle a Fresnel amplitude changes much faster than the indices it depends on.

use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::optics::modes::ModeKind;
use crate::plate::slab::{SlabBlocks, BLOCK_VALUES};
use crate::plate::Plate;
use crate::spectral::fringe;
use crate::spectral::nodes::{self, FINEST, LEVELS, MAX_NODES};
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;

/// Largest interpolation error of a block entry (flux-normalised amplitudes, at most ~1) for a
/// contribution of unit strength: a Mueller entry then errs by ~2e-5 of the light, below what
/// CIEDE2000 resolves even near black (`crate::spectral::channels`' budget).
pub const AMPLITUDE_TOLERANCE: f64 = 1e-5;

/// The block values that are amplitudes (the four interface blocks' entries and the flux
/// factor; the normal components, also stored, are taken exactly wherever a phase needs them).
const AMPLITUDE_VALUES: [usize; 25] = [
    0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 28,
];

/// The blocks of a plate at the nodes of one level.
pub struct Amplitudes {
    /// The level (index into [`LEVELS`]).
    pub level: usize,
    /// The blocks at each of the level's nodes, and their values.
    pub blocks: Vec<(SlabBlocks, [C64; BLOCK_VALUES])>,
    /// An isotropic layer: s and p share their phase (one mode count).
    pub merged: bool,
    /// Each coarser level's largest interpolation error of a block entry, measured at the
    /// nodes of [`Amplitudes::level`] (zero without dispersion).
    errors: [f64; LEVELS.len()],
}

/// The phase per traversal `[o↓, e↓, o↑, e↑]` (the factor of `k d` in a class's phase) from
/// the layer's normal components.
pub fn traversal_q(q: &[C64; 4]) -> [C64; 4] {
    [-q[0], -q[1], q[2], q[3]]
}

impl Amplitudes {
    /// The blocks of `plate` for incidence `beta` in the plane of `frame`, on the level that
    /// a contribution of unit strength needs (one node without dispersion: the blocks do not
    /// depend on the wavelength).
    pub fn new(plate: &Plate, frame: &PlaneFrame, beta: C64) -> Result<Self> {
        let (k0, a) = fringe::band();
        let mut solved: [Option<(SlabBlocks, [C64; BLOCK_VALUES])>; MAX_NODES] = [None; MAX_NODES];
        let mut merged = false;
        let mut level = if plate.is_dispersive() { 1 } else { 0 };
        loop {
            let lv = nodes::level(level);
            for (&j, t) in lv.in_finest.iter().zip(&lv.nodes) {
                if solved[j].is_none() {
                    let optics = plate.at(TAU / (k0 + a * t))?.optics(frame, beta)?;
                    merged = optics.layer_modes().down[0].kind == ModeKind::S;
                    let b = optics.blocks();
                    solved[j] = Some((b, b.values()));
                }
            }
            let values: Vec<&[C64; BLOCK_VALUES]> = lv
                .in_finest
                .iter()
                .map(|&j| &solved[j].as_ref().expect("solved").1)
                .collect();
            if level == 0
                || level == FINEST
                || chebyshev_tail(level, &values) <= AMPLITUDE_TOLERANCE
            {
                break;
            }
            level += 1;
        }
        let lv = nodes::level(level);
        let blocks: Vec<_> = lv
            .in_finest
            .iter()
            .map(|&j| solved[j].expect("solved"))
            .collect();
        let errors = std::array::from_fn(|l| {
            if l >= level {
                return 0.0;
            }
            measured_error(l, level, &blocks)
        });
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
    /// `strength` (relative to the direct light) meets [`AMPLITUDE_TOLERANCE`].
    pub fn level_for(&self, strength: f64) -> usize {
        (0..self.level)
            .find(|&l| strength * self.errors[l] <= AMPLITUDE_TOLERANCE)
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

/// The least attenuation exponent per traversal over the band, `d min_k k Im Q_m(k)` (zero for
/// a clear layer), from the centre and both band edges: a path class's amplitude, times
/// `e^{−Σ counts · this}`, bounds its light anywhere in the band. `None` where a clear layer's
/// wave turns evanescent inside the band (frustrated total reflection at a critical
/// wavelength: its phase has a branch point there, which no interpolant across the band
/// follows). With normal dispersion the indices are monotonic across the band, so the
/// evanescence of a mode changes at most once and the three points see every change.
pub fn least_attenuation(
    plate: &Plate,
    frame: &PlaneFrame,
    beta: C64,
    centre: &[C64; 4],
) -> Result<Option<[f64; 4]>> {
    let centre = traversal_q(centre);
    if centre.iter().all(|q| q.im == 0.0) && !plate.is_dispersive() {
        return Ok(Some([0.0; 4]));
    }
    let (k0, a) = fringe::band();
    let mut points = vec![(k0, centre)];
    if plate.is_dispersive() {
        for k in [k0 - a, k0 + a] {
            points.push((k, traversal_q(&plate.layer_q(TAU / k, frame, beta)?)));
        }
    } else {
        points.push((k0 - a, centre)); // the same Q everywhere: least at the longest wavelength
    }
    // (An absorbing layer's modes are lossy at every wavelength: only a clear layer changes.)
    let evanescent = |q: &[C64; 4]| q.map(|x| x.im != 0.0);
    if points
        .iter()
        .any(|(_, q)| evanescent(q) != evanescent(&points[0].1))
    {
        return Ok(None);
    }
    let d = plate.thickness_nm;
    Ok(Some(std::array::from_fn(|m| {
        points
            .iter()
            .map(|(k, q)| d * k * q[m].im.max(0.0))
            .fold(f64::INFINITY, f64::min)
    })))
}

/// `|c_{n−2}| + |c_{n−1}|` of the Chebyshev interpolant through `values` (the nodes of
/// `level`), the largest over the amplitude entries.
fn chebyshev_tail(level: usize, values: &[&[C64; BLOCK_VALUES]]) -> f64 {
    let dct = &nodes::level(level).dct;
    let n = dct.len();
    AMPLITUDE_VALUES
        .iter()
        .map(|&e| {
            let coefficient = |m: usize| -> f64 {
                dct[m]
                    .iter()
                    .zip(values)
                    .map(|(w, v)| v[e] * *w)
                    .sum::<C64>()
                    .norm()
            };
            coefficient(n - 2) + coefficient(n - 1)
        })
        .fold(0.0, f64::max)
}

/// The largest error of level `coarse`'s interpolant of the amplitude entries at the nodes of
/// the finer `level`, whose blocks are `blocks`.
fn measured_error(
    coarse: usize,
    level: usize,
    blocks: &[(SlabBlocks, [C64; BLOCK_VALUES])],
) -> f64 {
    let fine = nodes::level(level);
    let lv = nodes::level(coarse);
    let own = |j: usize| {
        fine.in_finest
            .iter()
            .position(|&f| f == j)
            .expect("nested levels")
    };
    let coarse_values: Vec<&[C64; BLOCK_VALUES]> =
        lv.in_finest.iter().map(|&j| &blocks[own(j)].1).collect();
    fine.in_finest
        .iter()
        .zip(blocks)
        .flat_map(|(&j, (_, v))| {
            let basis = &lv.to_finest[j];
            let coarse_values = &coarse_values;
            AMPLITUDE_VALUES.iter().map(move |&e| {
                let interpolated: C64 = basis
                    .iter()
                    .zip(coarse_values)
                    .map(|(w, c)| c[e] * *w)
                    .sum();
                (interpolated - v[e]).norm()
            })
        })
        .fold(0.0, f64::max)
}
