//! A plate's interface blocks across the visible band: solved exactly at the Chebyshev–Lobatto
//! nodes of one level ([`crate::quadrature::nodes`]) and interpolated between them.
//!
//! The level follows the blocks' own Chebyshev coefficients. For a function analytic around
//! the band they decay geometrically, `|c_m| ≈ C r^m`, and the interpolant on `n` nodes errs by
//! about `2 Σ_{m≥n} |c_m| ≈ 2 |c_{n−1}| r/(1 − r)` (Trefethen, *Approximation Theory and
//! Approximation Practice*, ch. 4 and 8). A dispersive plate starts on 5 nodes and refines only
//! while that estimate exceeds [`AMPLITUDE_TOLERANCE`]; a coarser level's error, for a weaker
//! contribution ([`Amplitudes::level_for`]), is the sum of the coefficients it leaves out, read
//! off the same series (nothing is solved or interpolated to measure it). The amplitudes' own
//! variation decides, not the indices': near grazing incidence or a critical angle a Fresnel
//! amplitude changes much faster than the indices it depends on.

use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::optics::modes::ModeKind;
use crate::plate::slab::{SlabBlocks, BLOCK_VALUES};
use crate::plate::Plate;
use crate::quadrature::fringe;
use crate::quadrature::nodes::{self, series_tail, FINEST, LEVELS, MAX_NODES, SPAN};
use crate::scratch::{Pool, Pooled};
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;

/// Largest interpolation error of a block entry (flux-normalised amplitudes, at most ~1) for a
/// contribution of unit strength: a Mueller entry then errs by ~6e-5 of the light. Measured
/// effect: the 5-node level (whose error is 3.5e-6 to 1.3e-5 for quartz and calcite) instead of
/// 9 nodes changes colours by a mean CIEDE2000 of 0.0004-0.0008 and at most 0.014-0.027 (on
/// the validation plates of `tests/spectral_rgb.rs`), far inside the budget of
/// [`crate::quadrature::budget`].
pub const AMPLITUDE_TOLERANCE: f64 = 3e-5;

/// The level a dispersive plate starts on (5 nodes: the blocks of every named crystal but
/// rutile, whose coefficients decay ~3.5x per degree near its ultraviolet pole, meet the
/// tolerance there).
const FIRST_DISPERSIVE_LEVEL: usize = 2;

/// The block values that are amplitudes (the four interface blocks' entries and the flux
/// factor; the normal components, also stored, are taken exactly wherever a phase needs them).
const AMPLITUDE_VALUES: [usize; 25] = [
    0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 28,
];

/// The blocks of a plate at the nodes of one level, kept where they were solved (by their
/// index among the finest level's nodes).
pub struct Amplitudes {
    /// The level (index into [`LEVELS`]).
    pub level: usize,
    /// The blocks at the finest-level node `j`, for the nodes of [`Amplitudes::level`].
    solved: Pooled<Nodes>,
    /// An isotropic layer: s and p share their phase (one mode count).
    pub merged: bool,
    /// The estimated interpolation error of a block entry on each level up to
    /// [`Amplitudes::level`] (zero without dispersion).
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
        let mut out = Amplitudes {
            level: if plate.is_dispersive() {
                FIRST_DISPERSIVE_LEVEL
            } else {
                0
            },
            solved: take_nodes(),
            merged: false,
            errors: [0.0; LEVELS.len()],
        };
        loop {
            let lv = nodes::level(out.level);
            for (&j, t) in lv.in_finest.iter().zip(&lv.nodes) {
                if out.solved.blocks[j].is_none() {
                    let optics = plate.at(TAU / (k0 + a * t))?.optics(frame, beta)?;
                    out.merged = optics.layer_modes().down[0].kind == ModeKind::S;
                    let b = optics.blocks();
                    out.solved.values[j] = b.values();
                    out.solved.blocks[j] = Some(b);
                }
            }
            if out.level == 0 {
                return Ok(out);
            }
            out.errors = out.estimated_errors();
            if out.errors[out.level] <= AMPLITUDE_TOLERANCE || out.level == FINEST {
                return Ok(out);
            }
            out.level += 1;
        }
    }

    /// The blocks at the band's centre (a node of every level).
    pub fn centre(&self) -> &SlabBlocks {
        self.exact(MAX_NODES / 2)
            .expect("the centre is a node of every level")
    }

    /// The exact blocks at finest-level node `j`, if it is one of the level's nodes.
    pub fn exact(&self, j: usize) -> Option<&SlabBlocks> {
        self.solved.blocks[j].as_ref()
    }

    /// The blocks at node `i` of `level` (`level ≤` [`Amplitudes::level`]).
    pub fn at(&self, level: usize, i: usize) -> &SlabBlocks {
        self.exact(nodes::level(level).in_finest[i])
            .expect("a coarser level's nodes are among the finer level's")
    }

    /// The blocks at finest-level node `j`: exact at the level's own nodes, else interpolated
    /// from them (the normal components `q` too; callers that need exact phases replace them).
    pub fn interpolated(&self, j: usize) -> SlabBlocks {
        if let Some(b) = self.exact(j) {
            return *b;
        }
        let lv = nodes::level(self.level);
        let mut v = [C64::new(0.0, 0.0); BLOCK_VALUES];
        for (&node, w) in lv.in_finest.iter().zip(&lv.to_finest[j]) {
            let values = self.solved.values[node];
            for (o, x) in v.iter_mut().zip(values) {
                *o += x * *w;
            }
        }
        SlabBlocks::from_values(&v, self.centre().thickness_nm)
    }

    /// The coarsest level (at most [`Amplitudes::level`]) on which a contribution of
    /// `strength` (relative to the direct light) meets [`AMPLITUDE_TOLERANCE`].
    pub fn level_for(&self, strength: f64) -> usize {
        (0..self.level)
            .find(|&l| strength * self.errors[l] <= AMPLITUDE_TOLERANCE)
            .unwrap_or(self.level)
    }

    /// `d(k Q)/dk` per traversal at each `t` of [`SPAN`] across the band (`k = k₀ + a t`; real
    /// part: the group index; imaginary part: the rate of the attenuation exponent), the
    /// derivative of the interpolant of `k Q(k)` through the nodes (`Q` itself without
    /// dispersion).
    pub fn group_indices(&self) -> [[C64; 4]; SPAN.len()] {
        if self.level == 0 {
            return [traversal_q(&self.centre().q); SPAN.len()];
        }
        let (k0, a) = fringe::band();
        let lv = nodes::level(self.level);
        let mut g = [[C64::new(0.0, 0.0); 4]; SPAN.len()];
        for (i, (&j, tn)) in lv.in_finest.iter().zip(&lv.nodes).enumerate() {
            let kq = traversal_q(&self.solved.blocks[j].as_ref().expect("solved").q)
                .map(|q| q * ((k0 + a * tn) / a));
            for (gs, w) in g.iter_mut().zip(&lv.span_slopes) {
                for (gm, q) in gs.iter_mut().zip(kq) {
                    *gm += q * w[i];
                }
            }
        }
        g
    }

    /// Every level's estimated error (module docs) from the Chebyshev coefficients of the
    /// amplitude entries on [`Amplitudes::level`], the largest over the entries.
    fn estimated_errors(&self) -> [f64; LEVELS.len()] {
        let lv = nodes::level(self.level);
        let n = lv.nodes.len();
        let values = &self.solved.values;
        let mut errors = [0.0f64; LEVELS.len()];
        let mut magnitudes = [0.0; MAX_NODES];
        for &e in &AMPLITUDE_VALUES {
            // The entry's Chebyshev coefficients, c_m = Σ_i dct[m][i] v_i.
            for (mag, row) in magnitudes.iter_mut().zip(&lv.dct) {
                let c: C64 = row
                    .iter()
                    .zip(&lv.in_finest)
                    .map(|(w, &j)| values[j][e] * *w)
                    .sum();
                *mag = c.norm_sqr().sqrt();
            }
            let own = series_tail(&magnitudes[..n]);
            for (l, err) in errors.iter_mut().enumerate().take(self.level + 1) {
                let left_out: f64 = magnitudes[LEVELS[l].min(n)..n].iter().sum();
                *err = err.max(2.0 * left_out + own);
            }
        }
        errors
    }
}

/// The blocks at every finest-level node (`None` where not solved) and their values, taken
/// from a per-thread pool ([`crate::scratch`]): a query neither allocates them nor moves them.
struct Nodes {
    blocks: [Option<SlabBlocks>; MAX_NODES],
    values: [[C64; BLOCK_VALUES]; MAX_NODES],
}

thread_local! {
    static POOL: Pool<Nodes> = const { std::cell::RefCell::new(Vec::new()) };
}

/// [`Nodes`] from the pool, cleared.
fn take_nodes() -> Pooled<Nodes> {
    let mut n = Pooled::take(&POOL, || {
        Box::new(Nodes {
            blocks: [None; MAX_NODES],
            values: [[C64::new(0.0, 0.0); BLOCK_VALUES]; MAX_NODES],
        })
    });
    n.blocks.iter_mut().for_each(|b| *b = None);
    n
}

/// The least attenuation exponent per traversal over the band, `d min_k k Im Q_m(k)` (zero for
/// a clear layer), from the blocks at the band's centre and both ends: a path class's
/// amplitude, times `e^{−Σ counts · this}`, bounds its light anywhere in the band. `None` where
/// a clear layer's wave turns evanescent inside the band (frustrated total reflection at a
/// critical wavelength: its phase has a branch point there, which no interpolant across the
/// band follows). With normal dispersion the indices are monotonic across the band, so the
/// evanescence of a mode changes at most once and the three points see every change. The ends
/// are nodes of every level from 3 nodes on; without dispersion `Q` is the same everywhere
/// (then least at the longest wavelength).
pub fn least_attenuation(plate: &Plate, amplitudes: &Amplitudes) -> Option<[f64; 4]> {
    let (k0, a) = fringe::band();
    let centre = traversal_q(&amplitudes.centre().q);
    let ends = if amplitudes.level == 0 {
        [centre, centre]
    } else {
        [0, MAX_NODES - 1].map(|j| traversal_q(&amplitudes.exact(j).expect("an end node").q))
    };
    // Lobatto order: finest node 0 is t = 1 (the short-wave end), the last t = −1.
    let points = [(k0, centre), (k0 + a, ends[0]), (k0 - a, ends[1])];
    // A clear layer's wave turns evanescent where `q` leaves the real axis (a tilted axis's
    // evanescent e-wave keeps a real part); a weakly absorbing layer's (every `q` complex) where
    // its decay overtakes its oscillation, `|Im q| > |Re q|` (with a kappa of 1e-20 the first
    // test alone saw no change, and the methods that need smooth amplitudes returned NaN).
    let evanescent = |q: &[C64; 4]| q.map(|x| (x.im != 0.0, x.im.abs() > x.re.abs()));
    if points
        .iter()
        .any(|(_, q)| evanescent(q) != evanescent(&centre))
    {
        return None;
    }
    let d = plate.thickness_nm;
    Some(std::array::from_fn(|m| {
        points
            .iter()
            .map(|(k, q)| d * k * q[m].im.max(0.0))
            .fold(f64::INFINITY, f64::min)
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Material;
    use crate::optics::frame::PlaneFrame;
    use nalgebra::Vector3;

    fn plate(name: &str) -> Plate {
        Plate {
            material: Material::named(name, 0.0, 0.0).unwrap(),
            birefringence: 0.0,
            ext: C64::new(1.0, 0.0),
            exit: C64::new(1.5, 0.0),
            axis: Vector3::new(0.3, -0.5, 0.7).normalize(),
            thickness_nm: 1e4,
        }
    }

    /// A wave that turns evanescent inside the band is seen whether the layer is clear or barely
    /// absorbing (calcite with kappa_e = 4e-272 under BK7 at 82 degrees, where the e wave turns
    /// evanescent: the plugin fuzzer's case; the tiny kappa had hidden it, and the channel
    /// integration's round trip diverged).
    #[test]
    fn a_wave_turning_evanescent_is_seen_in_a_barely_absorbing_layer() {
        let frame = PlaneFrame::from_azimuth(266.127f64.to_radians());
        let beta = C64::new(1.5046 * 81.8949f64.to_radians().sin(), 0.0);
        for kappa_e in [0.0, 3.9394976309445163e-272, 1e-12] {
            let p = Plate {
                material: Material::named("calcite", 0.0, kappa_e).unwrap(),
                birefringence: 0.0,
                ext: C64::new(1.5046, 0.0),
                exit: C64::new(1.5046, 0.0),
                axis: Vector3::new(1.0, 0.0, 0.0),
                thickness_nm: 1e3,
            };
            let amp = Amplitudes::new(&p, &frame, beta).unwrap();
            assert!(least_attenuation(&p, &amp).is_none(), "kappa_e {kappa_e}");
        }
    }

    /// The estimate bounds the interpolant's actual error at every finest node, for each level
    /// up to the one chosen (the error of a coarser level is the sum of the coefficients it
    /// leaves out; the own level's, the geometric tail).
    #[test]
    fn estimated_errors_bound_the_interpolation_error() {
        let (k0, a) = fringe::band();
        let frame = PlaneFrame::from_azimuth(0.4);
        for name in ["quartz", "calcite", "sapphire", "mgf2", "rutile"] {
            let p = plate(name);
            for theta in [0.0f64, 40.0, 75.0, 88.0] {
                let beta = C64::new(theta.to_radians().sin(), 0.0);
                let amp = Amplitudes::new(&p, &frame, beta).unwrap();
                let finest = &nodes::level(FINEST).nodes;
                for l in 1..=amp.level {
                    let lv = nodes::level(l);
                    let mut worst = 0.0f64;
                    for (j, t) in finest.iter().enumerate() {
                        let exact = p
                            .at(TAU / (k0 + a * t))
                            .unwrap()
                            .optics(&frame, beta)
                            .unwrap()
                            .blocks()
                            .values();
                        for &e in &AMPLITUDE_VALUES {
                            let v: C64 = lv
                                .in_finest
                                .iter()
                                .zip(&lv.to_finest[j])
                                .map(|(&n, w)| amp.solved.values[n][e] * *w)
                                .sum();
                            worst = worst.max((v - exact[e]).norm());
                        }
                    }
                    assert!(
                        worst <= amp.errors[l] + 1e-12,
                        "{name} at {theta} deg, level {l}: error {worst:e} > estimate {:e}",
                        amp.errors[l]
                    );
                }
                assert!(
                    amp.errors[amp.level] <= AMPLITUDE_TOLERANCE || amp.level == FINEST,
                    "{name} {theta}"
                );
                // Every crystal but rutile meets the tolerance on 5 nodes at moderate incidence
                // (the level that the coefficients' decay must not overestimate).
                if name != "rutile" && theta < 50.0 {
                    assert_eq!(amp.level, 2, "{name} at {theta} deg");
                }
            }
        }
    }
}
