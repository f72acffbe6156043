//! The path-class expansion of the slab (eqs. S20-S26, docs/physics.md §4).
//!
//! Expanding `(I − D)⁻¹ = Σₙ Dⁿ` writes each Jones matrix as a sum over path classes
//! `J(k) = Σ_c A_c exp(i k d Q_c)`: a class collects every internal path with the same number of
//! o and e traversals in each direction (`counts = [o↓, e↓, o↑, e↑]`), which share the phase
//! `k d Q_c`, `Q_c = −n_o↓ q_o↓ − n_e↓ q_e↓ + n_o↑ q_o↑ + n_e↑ q_e↑` (the supplemental's `k d ΔP_c`
//! for a plane-parallel plate). Amplitudes `A_c` are products of interface coefficients and do not
//! depend on `k` at fixed indices. Orders beyond the chosen `N` are summed incoherently in
//! closed form ([`IncoherentTail`]).

use crate::optics::mueller;
use crate::plate::slab::{SlabOptics, Want};
use nalgebra::{Matrix2, Matrix4, Vector4};
use num_complex::Complex64 as C64;
use std::collections::BTreeMap;

/// Traversal counts `[o↓, e↓, o↑, e↑]` of a path class.
pub type Counts = [u16; 4];

/// One path class of the reflected or transmitted field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathClass {
    /// Traversals per mode and direction.
    pub counts: Counts,
    /// Number of internal round trips.
    pub order: usize,
    /// `Q_c`: the class's phase is `k0 d Q_c` (complex with absorption).
    pub q: C64,
    /// Flux-normalised Jones amplitude (s/p in and out).
    pub amplitude: Matrix2<C64>,
}

/// The closed-form incoherent sum of all orders `> N` (docs/physics.md §4): coherence between
/// o and e, and between different paths, is dropped; mode populations propagate with
/// `|P|²` and reflect with `|r|²`. Stored as Mueller matrices (Mitsuba's convention).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IncoherentTail {
    /// Reflection of orders `> N` (zero if not asked for).
    pub r: Matrix4<f64>,
    /// Transmission of orders `> N` (zero if not asked for).
    pub t: Matrix4<f64>,
}

/// Path classes of orders `0..=N` and the incoherent remainder, at one wavelength.
#[derive(Clone, Debug, PartialEq)]
pub struct PathExpansion {
    /// Reflected classes, the direct top reflection first (counts all zero, order 0).
    pub reflection: Vec<PathClass>,
    /// Transmitted classes.
    pub transmission: Vec<PathClass>,
    /// Highest coherent order `N`.
    pub order: usize,
    /// Slab thickness (nm).
    pub thickness_nm: f64,
    /// Orders `> N`, incoherent.
    pub tail: IncoherentTail,
}

/// Internal amplitudes by class (rows o, e of the layer; columns s, p of the input), ordered
/// by counts so that every sum is evaluated in the same order.
type State = BTreeMap<Counts, Matrix2<C64>>;

/// Squared amplitude below which an internal path class is dropped.
const NEGLIGIBLE: f64 = 1e-30;

/// Splits each class by the mode it travels in (`dir` 0: down, 1: up). An isotropic layer has
/// one phase for both modes, so both rows count as the first mode.
fn traverse(state: &State, dir: usize, isotropic: bool) -> State {
    let mut out = State::new();
    for (counts, m) in state {
        for mode in 0..2 {
            let mut row = Matrix2::zeros();
            row.set_row(mode, &m.row(mode));
            // Paths this weak cannot matter (amplitude < 1e-15 of the incident wave).
            if row.iter().map(|z| z.norm_sqr()).sum::<f64>() < NEGLIGIBLE {
                continue;
            }
            let mut c = *counts;
            c[2 * dir + if isotropic { 0 } else { mode }] += 1;
            *out.entry(c).or_insert_with(Matrix2::zeros) += row;
        }
    }
    out
}

impl PathExpansion {
    /// Expands `optics` to order `n_max` (round trips), evaluating the incoherent tail's
    /// attenuation at `lambda_nm`.
    pub fn new(optics: &SlabOptics, n_max: usize, lambda_nm: f64, want: Want) -> Self {
        let m = optics.layer_modes();
        let qs = [-m.down[0].q, -m.down[1].q, m.up[0].q, m.up[1].q];
        let isotropic = m.down[0].kind == crate::optics::modes::ModeKind::S;
        let (t1, r1) = (optics.top.t_above(), optics.top.r_above());
        let (t3, r3) = (optics.top.t_below(), optics.top.r_below());
        let (t2, r2) = (optics.bottom.t_above(), optics.bottom.r_above());
        let ft = C64::new(optics.transmission_flux_ratio().sqrt(), 0.0);
        let class = |counts: Counts, order: usize, amplitude: Matrix2<C64>| PathClass {
            counts,
            order,
            q: counts.iter().zip(qs).map(|(n, q)| q * f64::from(*n)).sum(),
            amplitude,
        };
        let mut reflection = Vec::new();
        let mut transmission = Vec::new();
        if want.reflection {
            reflection.push(class([0; 4], 0, r1));
        }
        let mut state: State = [([0; 4], t1)].into_iter().collect();
        for order in 0..=n_max {
            let down = traverse(&state, 0, isotropic);
            if want.transmission {
                transmission.extend(down.iter().map(|(c, a)| class(*c, order, t2 * a * ft)));
            }
            let up = traverse(
                &down.iter().map(|(c, a)| (*c, r2 * a)).collect(),
                1,
                isotropic,
            );
            if want.reflection {
                reflection.extend(up.iter().map(|(c, a)| class(*c, order, t3 * a)));
            }
            state = up.iter().map(|(c, a)| (*c, r3 * a)).collect();
        }
        let tail = IncoherentTail::new(optics, &state, lambda_nm, want);
        PathExpansion {
            reflection,
            transmission,
            order: n_max,
            thickness_nm: optics.thickness_nm,
            tail,
        }
    }

    /// The coherent Jones matrices `(J_R, J_T)` of orders `0..=N` at `lambda_nm` (no tail).
    pub fn jones(&self, lambda_nm: f64) -> (Matrix2<C64>, Matrix2<C64>) {
        let kd = std::f64::consts::TAU * self.thickness_nm / lambda_nm;
        let sum = |cs: &[PathClass]| {
            cs.iter()
                .map(|c| c.amplitude * (C64::new(0.0, kd) * c.q).exp())
                .sum::<Matrix2<C64>>()
        };
        (sum(&self.reflection), sum(&self.transmission))
    }
}

impl IncoherentTail {
    /// The incoherent sum of every order after the classes in `state` (internal amplitudes
    /// just below the top surface, before the next downward traversal), as coherency
    /// superoperators: `X₀ = P̄↓ Σ_c K(A_c)`, one round trip `P̄↓ K(r₃) P̄↑ K(r₂)`, summed as
    /// `(I − RT)⁻¹`. `P̄` keeps only the populations of modes with different phases (o/e), but
    /// the full coherency of an isotropic layer's s and p, which share their phase.
    fn new(optics: &SlabOptics, state: &State, lambda_nm: f64, want: Want) -> Self {
        let m = optics.layer_modes();
        let isotropic = m.down[0].kind == crate::optics::modes::ModeKind::S;
        let kd = std::f64::consts::TAU * optics.thickness_nm / lambda_nm;
        let att = |q: C64, sign: f64| (-2.0 * sign * kd * q.im).exp();
        let prop = |a: [f64; 2]| -> Matrix4<C64> {
            let c = |x: f64| C64::new(x, 0.0);
            if isotropic {
                Matrix4::identity() * c(a[0])
            } else {
                Matrix4::from_diagonal(&Vector4::new(c(a[0]), c(0.0), c(0.0), c(a[1])))
            }
        };
        let pd = prop([att(m.down[0].q, -1.0), att(m.down[1].q, -1.0)]);
        let pu = prop([att(m.up[0].q, 1.0), att(m.up[1].q, 1.0)]);
        let k = mueller::coherency;
        let x0 = pd * state.values().map(k).sum::<Matrix4<C64>>();
        let (r2, r3) = (optics.bottom.r_above(), optics.top.r_below());
        let after_bottom = pu * k(&r2);
        let rt = pd * k(&r3) * after_bottom;
        let total = (Matrix4::identity() - rt)
            .try_inverse()
            .map(|inv| inv * x0)
            .unwrap_or_else(Matrix4::zeros);
        let ft = C64::new(optics.transmission_flux_ratio().sqrt(), 0.0);
        let t = if want.transmission {
            mueller::from_coherency(&(k(&(optics.bottom.t_above() * ft)) * total))
        } else {
            Matrix4::zeros()
        };
        let r = if want.reflection {
            mueller::from_coherency(&(k(&optics.top.t_below()) * after_bottom * total))
        } else {
            Matrix4::zeros()
        };
        IncoherentTail { r, t }
    }
}
