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
//! **Frequencies** for the rules (as [`crate::spectral::shared::points`] takes them): the direct
//! light oscillates at most at `ω_b = Σ_j split_j` (coherent layers; thick ones only if their
//! modes are kept), each further round trip adds at most `ω₁ = 2 (Σ_thin path_j + Σ_thick split_j)`,
//! with a relative strength `ρ = Σ_{i<l} ρ_il` over pairs of interfaces: `r_i r_l` (flux
//! amplitudes, the largest of either side) when only thin layers lie between them, `r_i² r_l²`
//! (powers) when a thick one does.

use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::spectral::weights::{gaussians, WeightSet};
use crate::stack::coherence::Coherence;
use crate::stack::exact::{interfaces, layer_q};
use crate::stack::Stack;
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;

/// Visibility below which a fringe is invisible (relative to the white response; the
/// threshold of the fringe tables, [`crate::spectral::fringe::NEGLIGIBLE`]).
pub const NEGLIGIBLE: f64 = 1e-7;

/// The reach (nm of group path) of a weight set: the largest `G` at which some Gaussian of it
/// keeps `|a| e^{−σ²G²/2} > NEGLIGIBLE`.
pub fn reach_of_set(set: WeightSet) -> f64 {
    (0..3)
        .flat_map(|c| gaussians(set, c).iter())
        .filter(|g| g.amplitude.abs() > NEGLIGIBLE)
        .map(|g| reach_of_gaussian(g.amplitude.abs(), g.sigma))
        .fold(0.0, f64::max)
}

/// The reach of one Gaussian of mass `a` and width `sigma` (rad/nm).
pub fn reach_of_gaussian(a: f64, sigma: f64) -> f64 {
    (2.0 * (a / NEGLIGIBLE).ln()).sqrt() / sigma
}

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
pub struct Plan {
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

impl Plan {
    /// The plan for a weight of reach `reach` (nm), from the layers' group paths `paths` and the
    /// interfaces' reflectances `reflectance`; `exact`: every layer coherent (the exact stack).
    pub fn new(paths: &[LayerPaths], reflectance: &[f64], reach: f64, exact: bool) -> Self {
        let n = paths.len();
        let thick: Vec<bool> = paths
            .iter()
            .map(|p| !exact && p.round_trip > reach)
            .collect();
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
        Plan {
            coherence: Coherence { thick, keep_modes },
            omega_b,
            omega_1: 2.0 * per_trip,
            rho,
        }
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
        let zero_order = [paths(9_500.0, 3e6), paths(9_400.0, 3e6)];
        let p = Plan::new(&zero_order, &r, 7_000.0, false);
        assert_eq!(p.coherence.thick, vec![true, true]);
        assert_eq!(p.coherence.keep_modes, vec![true, true]);
        let lone = [paths(170_000.0, 3e6), paths(100.0, 3e3)];
        let p = Plan::new(&lone, &r, 7_000.0, false);
        assert_eq!(p.coherence.thick, vec![true, false]);
        assert_eq!(p.coherence.keep_modes, vec![false, true]);
        assert!((p.omega_b - 100.0).abs() < 1e-9);
        let exact = Plan::new(&lone, &r, 7_000.0, true);
        assert!(exact.coherence.is_exact());
        // Reflections across a thick layer count as powers, within thin ones as amplitudes.
        assert!((p.rho - (0.04f64 * 0.04)).abs() < 1e-12);
        assert!((exact.rho - 0.04).abs() < 1e-12);
    }
}
