//! How a stack is integrated over one spectrum: which layers are thick (their round trips
//! beyond the weight's coherence length), whose modes stay coherent, and how fast the resulting
//! spectrum oscillates, which sizes the rules of [`crate::stack::spectral`].
//!
//! **Reach.** A weight `w(k) = Σ_j a_j N(k; μ_j, σ_j)` sees a fringe `e^{iGk}` of group path `G`
//! with the visibility `|Σ_j a_j e^{−σ_j² G²/2}|`; beyond the *reach*, where every term is below
//! [`NEGLIGIBLE`] (of the white response), nothing of the fringe survives the integral.
//!
//! **Group paths.** A traversal of layer `j` in mode `m` has the phase `k d_j Q_m(k)` (`Q = −q↓`
//! going down, `q↑` going up); its group path is `d_j (Q_m + k Q_m')` (real parts; `Q'` by
//! central differences of the exact normal components). Per layer: the largest difference
//! between the two modes of one direction (`split`, the birefringent fringe of one traversal),
//! the largest traversal (`path`) and the shortest round trip (`round_trip`).
//!
//! **Thick layers** have `round_trip > reach`: their round trips are summed incoherently
//! ([`crate::stack::coherence`]), exact to the visibility at the reach. A thick layer's own
//! modes stay coherent unless `split` exceeds the reach by more than three traversals of every
//! other kept layer could make up (a term of the Mueller matrix with one internal round trip
//! traverses a layer at most three times): then its cross term is invisible and dropped.
//!
//! **Frequencies** for the rules (as [`crate::quadrature::chebyshev::points`] takes them): the direct
//! light oscillates at most at `ω_b = Σ_j split_j` (coherent layers; thick ones only if their
//! modes are kept), each further round trip adds at most `ω₁ = 2 (Σ_thin path_j + Σ_thick split_j)`,
//! with a relative strength `ρ = Σ_{i<l} ρ_il` over pairs of interfaces: `r_i r_l` (flux
//! amplitudes, the largest of either side) when only thin layers lie between them, `r_i² r_l²`
//! (powers) when a thick one does.

use crate::colour::weights::{gaussians, WeightSet};
use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::quadrature::chebyshev::TOLERANCE;
use crate::stack::coherence::Coherence;
use crate::stack::exact::{interfaces, layer_q};
use crate::stack::Stack;
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;

/// Visibility below which a fringe is invisible (relative to the white response; the
/// threshold of the fringe tables, [`crate::quadrature::fringe::NEGLIGIBLE`]).
pub const NEGLIGIBLE: f64 = 1e-7;

/// The reach of one Gaussian of mass `a` and width `sigma` (rad/nm).
pub fn reach_of_gaussian(a: f64, sigma: f64) -> f64 {
    (2.0 * (a / NEGLIGIBLE).ln()).sqrt() / sigma
}

/// Largest visibility of a round trip [`StackPlan::thicken`] sums incoherently: its orders' cross
/// terms, at most this fraction of the light they carry, are dropped.
pub const THICKEN: f64 = 1e-3;

/// Group paths of one layer (nm), see the module docs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LayerPaths {
    /// Largest group path difference of the two modes in one traversal.
    pub split: f64,
    /// Largest group path of one traversal.
    pub path: f64,
    /// Shortest group path of one round trip.
    pub round_trip: f64,
}

/// The plan of one stack, incidence and spectrum.
#[derive(Clone, Debug, PartialEq)]
pub struct StackPlan {
    /// Which layers are thick and whose modes stay coherent.
    pub coherence: Coherence,
    /// Largest frequency of the direct light (nm).
    pub omega_b: f64,
    /// Largest frequency added per round trip (nm).
    pub omega_1: f64,
    /// Relative strength of one round trip.
    pub rho: f64,
}

/// Group paths of every layer at wavenumbers `ks` (the largest `split`/`path` and the shortest
/// `round_trip` over them).
pub fn layer_paths(
    stack: &Stack,
    frame: &PlaneFrame,
    beta: C64,
    ks: &[f64],
) -> Result<Vec<LayerPaths>> {
    let n = stack.layers.len();
    let mut out = vec![
        LayerPaths {
            round_trip: f64::INFINITY,
            ..Default::default()
        };
        n
    ];
    for &k in ks {
        let h = 1e-3 * k;
        let qs = |k: f64| layer_q(stack, TAU / k, frame, beta);
        let q0 = qs(k)?;
        let (qp, qm) = if stack.is_dispersive() {
            (qs(k + h)?, qs(k - h)?)
        } else {
            (q0.clone(), q0.clone())
        };
        for j in 0..n {
            // Traversal phase per unit thickness Q = (−q↓, −q↓, q↑, q↑), and its group path.
            let sign = [-1.0, -1.0, 1.0, 1.0];
            let g: [f64; 4] = std::array::from_fn(|i| {
                let dq = (qp[j][i] - qm[j][i]).re / (2.0 * h);
                sign[i] * (q0[j][i].re + k * dq)
            });
            let d = stack.layers[j].thickness_nm;
            let l = &mut out[j];
            l.split = l
                .split
                .max(d * (g[0] - g[1]).abs().max((g[2] - g[3]).abs()));
            l.path = l
                .path
                .max(d * g.iter().fold(0.0f64, |a, &x| a.max(x.abs())));
            let trip = (0..2)
                .flat_map(|a| (2..4).map(move |b| (a, b)))
                .map(|(a, b)| g[a] + g[b])
                .fold(f64::INFINITY, f64::min);
            l.round_trip = l.round_trip.min(d * trip);
        }
    }
    Ok(out)
}

/// The largest flux reflectance of each interface (from either side, any input
/// polarisation: the largest column sum of its reflection power ratios), at `lambda_nm`.
pub fn reflectances(
    stack: &Stack,
    lambda_nm: f64,
    frame: &PlaneFrame,
    beta: C64,
) -> Result<Vec<f64>> {
    Ok(interfaces(stack, lambda_nm, frame, beta)?
        .iter()
        .map(|i| {
            let p = i.power();
            let column = |c: usize, rows: [usize; 2]| p[(rows[0], c)] + p[(rows[1], c)];
            [
                column(0, [0, 1]),
                column(1, [0, 1]),
                column(2, [2, 3]),
                column(3, [2, 3]),
            ]
            .into_iter()
            .fold(0.0, f64::max)
            .min(1.0)
        })
        .collect())
}

/// What a spectral weight sees of a fringe: its reach and its visibility `V(G)` (the largest,
/// over its channels, of `Σ_j |a_j| e^{−σ_j² G²/2}`).
#[derive(Clone, Debug)]
pub struct Weight {
    /// `(|a_j|, σ_j)` of every Gaussian of every channel, per channel.
    channels: Vec<Vec<(f64, f64)>>,
}

impl Weight {
    /// The three channels of a weight set.
    pub fn of_set(set: WeightSet) -> Self {
        Weight {
            channels: (0..3)
                .map(|c| {
                    gaussians(set, c)
                        .iter()
                        .map(|g| (g.amplitude.abs(), g.sigma))
                        .collect()
                })
                .collect(),
        }
    }

    /// One Gaussian band of unit mass and width `sigma` (rad/nm).
    pub fn of_band(sigma: f64) -> Self {
        Weight {
            channels: vec![vec![(1.0, sigma)]],
        }
    }

    /// The visibility of a fringe of constant amplitude and group path `g` (nm).
    pub fn visibility(&self, g: f64) -> f64 {
        self.channels
            .iter()
            .map(|c| {
                c.iter()
                    .map(|&(a, s)| a * (-0.5 * (s * g).powi(2)).exp())
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }

    /// The reach (nm): beyond it every Gaussian is below [`NEGLIGIBLE`].
    pub fn reach(&self) -> f64 {
        self.channels
            .iter()
            .flatten()
            .filter(|(a, _)| *a > NEGLIGIBLE)
            .map(|&(a, s)| reach_of_gaussian(a, s))
            .fold(0.0, f64::max)
    }
}

impl StackPlan {
    /// The plan for `weight`, from the layers' group paths `paths` and the interfaces'
    /// reflectances `reflectance`; `exact`: every layer coherent (the exact stack). A layer is
    /// thick when the strongest round trip across it, `r_i r_l` over the interfaces `i` above
    /// and `l` below it, times the visibility of its own (shortest) round trip is at most
    /// [`TOLERANCE`]: the interference it drops is invisible to that tolerance.
    pub fn new(paths: &[LayerPaths], reflectance: &[f64], weight: &Weight, exact: bool) -> Self {
        let n = paths.len();
        let thick = (0..n)
            .map(|j| {
                let across = (0..=j)
                    .flat_map(|i| (j + 1..=n).map(move |l| (i, l)))
                    .map(|(i, l)| (reflectance[i] * reflectance[l]).sqrt())
                    .fold(0.0, f64::max);
                !exact && across * weight.visibility(paths[j].round_trip) <= TOLERANCE
            })
            .collect();
        Self::with_thick(paths, reflectance, weight.reach(), thick)
    }

    /// The plan with the layers `thick` thick (module docs; `reach` decides the kept modes).
    pub fn with_thick(
        paths: &[LayerPaths],
        reflectance: &[f64],
        reach: f64,
        thick: Vec<bool>,
    ) -> Self {
        let n = paths.len();
        let keep_modes = kept_modes(paths, &thick, reach);
        let mut omega_b = 0.0;
        let mut per_trip = 0.0;
        for j in 0..n {
            if !thick[j] {
                omega_b += paths[j].split;
                per_trip += paths[j].path;
            } else if keep_modes[j] {
                omega_b += paths[j].split;
                per_trip += paths[j].split;
            }
        }
        let mut rho = 0.0;
        for i in 0..=n {
            for l in i + 1..=n {
                let (a, b) = (reflectance[i], reflectance[l]);
                rho += if thick[i..l].iter().any(|&t| t) {
                    a * b
                } else {
                    (a * b).sqrt()
                };
            }
        }
        StackPlan {
            coherence: Coherence { thick, keep_modes },
            omega_b,
            omega_1: 2.0 * per_trip,
            rho,
        }
    }

    /// The same plan with its thin layer of the longest round trip made thick, if the
    /// visibility of that round trip under `weight` is at most [`THICKEN`] (else `None`): for a
    /// spectrum whose coherent orders are too many for any rule (reflectances near 1 at
    /// grazing incidence), orders that barely interfere are summed incoherently.
    pub fn thicken(
        &self,
        paths: &[LayerPaths],
        reflectance: &[f64],
        weight: &Weight,
    ) -> Option<Self> {
        let thick = &self.coherence.thick;
        let j = (0..paths.len())
            .filter(|&j| !thick[j])
            .max_by(|&a, &b| paths[a].round_trip.total_cmp(&paths[b].round_trip))?;
        if weight.visibility(paths[j].round_trip) > THICKEN {
            return None;
        }
        let mut thick = thick.clone();
        thick[j] = true;
        Some(Self::with_thick(paths, reflectance, weight.reach(), thick))
    }
}

/// Which layers keep the cross term of their modes (module docs): thin ones always; a thick one
/// unless its `split` exceeds `reach` plus three times every other kept layer's (the largest
/// dropped first, until none is dropped).
fn kept_modes(paths: &[LayerPaths], thick: &[bool], reach: f64) -> Vec<bool> {
    let mut keep = vec![true; paths.len()];
    loop {
        let total: f64 = (0..paths.len())
            .filter(|&j| keep[j])
            .map(|j| paths[j].split)
            .sum();
        let drop = (0..paths.len())
            .filter(|&j| thick[j] && keep[j])
            .filter(|&j| paths[j].split - 3.0 * (total - paths[j].split) > reach)
            .max_by(|&a, &b| paths[a].split.total_cmp(&paths[b].split));
        match drop {
            Some(j) => keep[j] = false,
            None => return keep,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paths(split: f64, round_trip: f64) -> LayerPaths {
        LayerPaths {
            split,
            path: 0.5 * round_trip,
            round_trip,
        }
    }

    /// Thick layers are those beyond the reach; a lone thick layer of large birefringence loses
    /// its cross term, two that cancel (a zero-order waveplate) keep theirs.
    #[test]
    fn thick_layers_and_kept_modes() {
        let r = [0.04, 0.0, 0.04];
        let w = Weight::of_set(WeightSet::XyzD65);
        let zero_order = [paths(9_500.0, 3e6), paths(9_400.0, 3e6)];
        let p = StackPlan::new(&zero_order, &r, &w, false);
        assert_eq!(p.coherence.thick, vec![true, true]);
        assert_eq!(p.coherence.keep_modes, vec![true, true]);
        let lone = [paths(170_000.0, 3e6), paths(100.0, 3e3)];
        assert!(w.reach() > 3e3 && w.reach() < 3e6);
        let p = StackPlan::new(&lone, &r, &w, false);
        assert_eq!(p.coherence.thick, vec![true, false]);
        assert_eq!(p.coherence.keep_modes, vec![false, true]);
        assert!((p.omega_b - 100.0).abs() < 1e-9);
        let exact = StackPlan::new(&lone, &r, &w, true);
        assert!(exact.coherence.is_exact());
        // Reflections across a thick layer count as powers, within thin ones as amplitudes.
        assert!((p.rho - (0.04f64 * 0.04)).abs() < 1e-12);
        assert!((exact.rho - 0.04).abs() < 1e-12);
    }
}
