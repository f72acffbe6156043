//! A narrow band through a birefringent plate in closed form: the plate as a matrix etalon.
//!
//! Across a narrow band (σ ≪ μ) the interface amplitudes barely change (they are taken at the
//! centre, as the pair sums of [`crate::spectral::gaussian`] do) and each traversal of the
//! layer in mode `j` has the phase `μ d Q_j + κ d G_j` at `k = μ + κ` (`G_j = Q_j + μ Q_j'`
//! its group index). Write `G_j = ḡ + δ_j`: the common part `ḡ` is the fast phase of the
//! internal round trips, `h = exp(2 i κ d ḡ)` per round trip; the residuals `δ_j` (the
//! birefringent group differences) are slow. With `P↓(κ) = diag(p_j e^{i κ d δ_j})` (`p_j` the
//! propagation at the centre), `D(κ) = r₃ P↑ r₂ P↓` and `Aₙ = X D(κ)ⁿ t₁` (`X = t₂ P↓` times
//! the flux factor for transmission), the coherency is a double sum over orders whose pairs
//! `(n, n + Δ)` carry `h^Δ`. The Gaussian average of `e^{i κ a} F(κ)` (`κ = σ x`, `x` standard
//! normal, `a = 2 Δ d ḡ`) is, shifting the contour,
//!
//! ```text
//! ⟨e^{i κ a} F(κ)⟩ = e^{−σ² a²/2} E_x[F(σ x + i σ² a)]
//! ```
//! exact for entire `F`; `F` varies slowly in `κ` (the residual phases), so a few Gauss–Hermite
//! nodes give `E_x` (their number set by the largest residual path difference over the band).
//! Summing the orders with Kronecker products (`Ā(z) = conj(A(z̄))` the continuation of the
//! conjugated amplitude):
//!
//! ```text
//! Σₙ Āₙ(z) ⊗ Aₙ₊Δ(z) = (X̄ ⊗ X) (I − D̄ ⊗ D)⁻¹ (I ⊗ D^Δ) (t̄₁ ⊗ t₁)        (Δ ≥ 0)
//! ```
//! and for reflection `R = r₁ + Σ_{n≥1} hⁿ V Dⁿ⁻¹ t₁` (`V = t₃ P↑ r₂ P↓`), the same with `V` for
//! `X` plus the cross terms of `r₁` with each order. Pairs with `Δ < 0` are the mirror images:
//! `Āₘ ⊗ Aₙ = S conj(Āₙ ⊗ Aₘ) S` (`S` swaps the Kronecker factors). Exact for phases linear in
//! `κ` over the band and amplitudes constant: the same model as the pair sums, with every
//! internal order included. The residuals are complex (absorption varies across the band with
//! `Im G_j`) and also carry the curvature `κ² C_j/2` of each traversal's phase.

use crate::band::Gaussian;
use crate::cmath;
use crate::plate::slab::{SlabOptics, Want};
use crate::quadrature::hermite;
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;

/// Gaussians with `σ ≤ NARROW_BAND μ` (FWHM up to ~13 nm at 550 nm) are narrow: the closed form
/// takes the interface amplitudes at the centre (they change by ~|dη/dλ| × band width, ~1e-5
/// relative for 4 nm).
pub const NARROW_BAND: f64 = 0.01;
/// A mode attenuated by more than `exp(−ATTENUATED)` in one traversal carries nothing.
const ATTENUATED: f64 = 40.0;
/// Orders whose pair weight `g(Δ) ‖D‖^Δ` falls below this are dropped.
const SERIES_TOLERANCE: f64 = 1e-13;
/// Longest order series; beyond, the caller uses the general method.
const MAX_TERMS: usize = 512;
/// Most Gauss–Hermite nodes spent on the residual phases; beyond, the general method.
pub const MAX_NODES: usize = 48;
/// Accuracy asked of the Gauss–Hermite rule for the residual phases (for a pair of weight 1).
const NODE_TOLERANCE: f64 = 1e-9;

/// How the phase `k d Q_j(k)` of one traversal of the layer varies around the centre `μ`
/// (per unit thickness): `μ Q_j + κ G_j + κ² C_j/2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Traversal {
    /// `d(k Q)/dk`: the group index, its imaginary part the attenuation rate (complex `Q`).
    pub group: C64,
    /// `d²(k Q)/dk²` (group velocity dispersion).
    pub curvature: f64,
}

/// Where the closed form serves the plate `optics` (solved at the band's centre) over the
/// unit-mass Gaussian `g`, given how the phases of the four traversals `[o↓, e↓, o↑, e↑]` vary
/// across it (`traversals`): the plate over the band with its orders and its Gauss–Hermite rule
/// per order difference, checked once here so that [`band`] cannot fail. `None` where it does
/// not serve (too many orders or nodes, or an order series that would not converge at some
/// node once shifted into the complex plane: plates near grazing incidence, very thick and
/// strongly birefringent ones); [`crate::spectral::route`] then chooses another method.
pub fn plan(optics: &SlabOptics, g: &Gaussian, traversals: &[Traversal; 4]) -> Option<Narrow> {
    if g.sigma > NARROW_BAND * g.mu {
        return None;
    }
    let layer = Layer::new(optics, g, traversals)?;
    let mut nodes = [0u8; MAX_TERMS + 1];
    let mut count = 0;
    for (delta, slot) in nodes.iter_mut().enumerate().take(layer.orders + 1) {
        let gd = layer.coherence(delta);
        if gd == 0.0 {
            break;
        }
        // The pairs Δ orders apart weigh at most g(Δ) ‖D‖^Δ: their rule needs less accuracy.
        let weight = gd * layer.rho.powi(delta as i32);
        let phase = if delta == 0 {
            layer.phase_same
        } else {
            layer.phase_orders
        };
        let n = hermite_nodes(phase, NODE_TOLERANCE / weight.max(1e-300))?;
        let x = hermite::rule(n).last().map_or(0.0, |r| r.0);
        if !layer.converges(g, delta, x) {
            return None;
        }
        *slot = n as u8;
        count = delta + 1;
    }
    Some(Narrow {
        layer,
        sigma: g.sigma,
        nodes,
        count,
    })
}

/// The closed form of one plate over one band, as [`plan`] checked it.
pub struct Narrow {
    layer: Layer,
    sigma: f64,
    /// Gauss–Hermite nodes per order difference `Δ < count`.
    nodes: [u8; MAX_TERMS + 1],
    count: usize,
}

impl Narrow {
    /// The exact plate evaluations (complex nodes) the closed form costs.
    pub fn nodes(&self) -> usize {
        self.nodes[..self.count]
            .iter()
            .map(|&n| usize::from(n))
            .sum()
    }
}

/// The band-averaged Mueller matrices `(R, T)` (zero where not wanted) of the plan `n`.
pub fn band(n: &Narrow, want: Want) -> (Matrix4<f64>, Matrix4<f64>) {
    let plate = &n.layer;
    let sigma = n.sigma;
    let mut c_t = Matrix4::<C64>::zeros();
    let mut c_r = Matrix4::<C64>::zeros();
    let mut mirrored_t = Matrix4::<C64>::zeros();
    let mut mirrored_r = Matrix4::<C64>::zeros();
    let t1_bar = plate.t1.map(|z| z.conj());
    for delta in 0..n.count {
        let gd = plate.coherence(delta);
        for &(x, w) in hermite::rule(usize::from(n.nodes[delta])) {
            let z = C64::new(sigma * x, sigma * sigma * plate.fast(delta));
            let m = plate.at(z);
            // (I ⊗ D^Δ)(t̄₁ ⊗ t₁) = t̄₁ ⊗ D^Δ t₁.
            let before = power(&m.d, delta.saturating_sub(1)); // D^(Δ−1), also for R below
            let dt1 = if delta == 0 {
                plate.t1
            } else {
                m.d * before * plate.t1
            };
            let rhs = kron(&t1_bar, &dt1);
            // The series converges here ([`Layer::converges`]): the system is regular.
            let y = cmath::solve4(&(Matrix4::identity() - kron(&m.d_bar, &m.d)), &rhs)
                .expect("regular: ‖D̄ ⊗ D‖ < 1 at every node, checked by the plan");
            let weight = C64::new(w * gd, 0.0);
            let (target_t, target_r) = if delta == 0 {
                (&mut c_t, &mut c_r)
            } else {
                (&mut mirrored_t, &mut mirrored_r)
            };
            if want.transmission {
                *target_t += kron(&m.x_bar, &m.x) * y * weight;
            }
            if want.reflection {
                *target_r += kron(&m.v_bar, &m.v) * y * weight;
                if delta >= 1 {
                    // r₁ (no round trip) with order `delta`: conj(r₁) ⊗ V D^(Δ−1) t₁.
                    let u = m.v * before * plate.t1;
                    mirrored_r += kron(&plate.r1.map(|z| z.conj()), &u) * weight;
                }
            }
        }
    }
    let close = |c: Matrix4<C64>, mirrored: Matrix4<C64>| {
        crate::optics::mueller::from_coherency(&(c + mirrored + swap(&mirrored.map(|z| z.conj()))))
    };
    let t = if want.transmission {
        close(
            c_t * C64::new(plate.flux, 0.0),
            mirrored_t * C64::new(plate.flux, 0.0),
        )
    } else {
        Matrix4::zeros()
    };
    let r = if want.reflection {
        let direct = kron(&plate.r1.map(|z| z.conj()), &plate.r1);
        close(c_r + direct, mirrored_r)
    } else {
        Matrix4::zeros()
    };
    (r, t)
}

/// The plate over one band: centre amplitudes, residual rates and the rule's sizes.
struct Layer {
    r1: Matrix2<C64>,
    t1: Matrix2<C64>,
    r2: Matrix2<C64>,
    t2: Matrix2<C64>,
    r3: Matrix2<C64>,
    t3: Matrix2<C64>,
    /// Propagation factors at the centre, `[o↓, e↓, o↑, e↑]`.
    p: [C64; 4],
    /// Residual group path `d (G_j − ḡ)` of each traversal (nm; imaginary: attenuation).
    residual: [C64; 4],
    /// Phase curvature `d C_j` of each traversal (nm²).
    curvature: [f64; 4],
    /// `2 d ḡ`: the group path of one round trip (nm).
    round_trip: f64,
    /// `σ²`-scaled decay of the coherence between orders: `g(Δ) = exp(−decay Δ²)`.
    decay: f64,
    /// Transmission flux factor `P_exit/P_ext`.
    flux: f64,
    /// Highest order difference kept.
    orders: usize,
    /// Largest residual phase difference over one band width (rad) of a significant pair of
    /// the same order, and of different orders.
    phase_same: f64,
    phase_orders: f64,
    /// `‖D‖` at the centre (Frobenius): the decay of the orders.
    rho: f64,
}

/// The amplitudes of one complex node `z`.
struct AtNode {
    d: Matrix2<C64>,
    d_bar: Matrix2<C64>,
    x: Matrix2<C64>,
    x_bar: Matrix2<C64>,
    v: Matrix2<C64>,
    v_bar: Matrix2<C64>,
}

impl Layer {
    fn new(optics: &SlabOptics, g: &Gaussian, traversals: &[Traversal; 4]) -> Option<Self> {
        let d = optics.thickness_nm;
        let m = optics.layer_modes();
        let q = [-m.down[0].q, -m.down[1].q, m.up[0].q, m.up[1].q];
        let live: [bool; 4] = std::array::from_fn(|j| g.mu * d * q[j].im < ATTENUATED);
        let group = traversals.map(|t| t.group);
        // ḡ: the middle of the live round trips' group indices (a down, b up), halved.
        let (lo, hi) = (0..2)
            .flat_map(|a| (2..4).map(move |b| (a, b)))
            .filter(|&(a, b)| live[a] && live[b])
            .map(|(a, b)| 0.5 * (group[a].re + group[b].re))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
                (l.min(x), h.max(x))
            });
        let gbar = if lo <= hi { 0.5 * (lo + hi) } else { 0.0 };
        let keep = |j: usize, v: C64| if live[j] { v } else { C64::new(0.0, 0.0) };
        let residual: [C64; 4] = std::array::from_fn(|j| keep(j, (group[j] - gbar) * d));
        let curvature: [f64; 4] =
            std::array::from_fn(|j| keep(j, C64::new(d * traversals[j].curvature, 0.0)).re);
        let p = std::array::from_fn(|j| (C64::new(0.0, g.mu * d) * q[j]).exp());
        let mut layer = Layer {
            r1: optics.top.r_above(),
            t1: optics.top.t_above(),
            r2: optics.bottom.r_above(),
            t2: optics.bottom.t_above(),
            r3: optics.top.r_below(),
            t3: optics.top.t_below(),
            p,
            residual,
            curvature,
            round_trip: 2.0 * d * gbar,
            decay: 0.5 * (g.sigma * 2.0 * d * gbar).powi(2),
            flux: optics.transmission_flux_ratio(),
            orders: 0,
            phase_same: 0.0,
            phase_orders: 0.0,
            rho: 0.0,
        };
        let rho = layer.at(C64::new(0.0, 0.0)).d.norm();
        if rho >= 1.0 {
            return None;
        }
        layer.rho = rho;
        layer.orders = (1..=MAX_TERMS)
            .find(|&n| layer.coherence(n) * rho.powi(n as i32) < SERIES_TOLERANCE)?;
        // Residual phases over the band of the pairs that matter (up to 2N + 1 traversals, N
        // the order where the amplitude falls below 1e-3). Pairs of the same order differ only
        // in the mode of each traversal (o/e, same direction); pairs of different orders also
        // by whole round trips (residual r_a↓ + r_b↑ and the curvature).
        let n = (1..=MAX_TERMS).find(|&n| rho.powi(n as i32) < 1e-3)? as f64;
        let (r, c) = (&layer.residual, &layer.curvature);
        let same = (r[1] - r[0]).norm().max((r[3] - r[2]).norm());
        let bend_same = (c[1] - c[0]).abs().max((c[3] - c[2]).abs());
        let trip = (0..2)
            .flat_map(|a| (2..4).map(move |b| (r[a] + r[b]).norm()))
            .fold(0.0, f64::max);
        let bend = c.iter().map(|c| c.abs()).fold(0.0, f64::max);
        let s2 = g.sigma * g.sigma;
        layer.phase_same = (2.0 * n + 1.0) * (g.sigma * same + s2 * bend_same);
        layer.phase_orders =
            layer.phase_same + (2.0 * n + 1.0) * (g.sigma * trip + 2.0 * s2 * bend);
        hermite_nodes(layer.phase_same, NODE_TOLERANCE)?;
        Some(layer)
    }

    /// `g(Δ)`, the coherence kept between orders `Δ` apart.
    fn coherence(&self, delta: usize) -> f64 {
        (-self.decay * (delta * delta) as f64).exp()
    }

    /// The fast group path `a = 2 Δ d ḡ` of `Δ` round trips.
    fn fast(&self, delta: usize) -> f64 {
        self.round_trip * delta as f64
    }

    /// True if the order series converges (`‖D‖ ‖D̄‖ < 1`, Frobenius norms) at every node
    /// `z = σ x + i σ² a` (`a` the fast group path of `delta` round trips) with `|x| ≤ x_max`:
    /// each entry's modulus is log-linear in `x`, so both norms are log-convex in it and their
    /// product is largest at `±x_max`.
    fn converges(&self, g: &Gaussian, delta: usize, x_max: f64) -> bool {
        [-x_max, x_max].iter().all(|&x| {
            let m = self.at(C64::new(g.sigma * x, g.sigma * g.sigma * self.fast(delta)));
            m.d.norm() * m.d_bar.norm() < 1.0
        })
    }

    /// Amplitudes at the complex node `z` (the continuation of `κ`).
    fn at(&self, z: C64) -> AtNode {
        let i = C64::new(0.0, 1.0);
        // exp(i (z r_j + z² c_j/2)) and the continuation of its conjugate.
        let ph: [C64; 4] = std::array::from_fn(|j| {
            self.p[j] * (i * z * (self.residual[j] + 0.5 * z * self.curvature[j])).exp()
        });
        let ph_bar: [C64; 4] = std::array::from_fn(|j| {
            self.p[j].conj()
                * (-i * z * (self.residual[j].conj() + 0.5 * z * self.curvature[j])).exp()
        });
        let diag = |a: C64, b: C64| Matrix2::new(a, C64::new(0.0, 0.0), C64::new(0.0, 0.0), b);
        let (pd, pu) = (diag(ph[0], ph[1]), diag(ph[2], ph[3]));
        let (pdb, pub_) = (diag(ph_bar[0], ph_bar[1]), diag(ph_bar[2], ph_bar[3]));
        let c = |m: &Matrix2<C64>| m.map(|z| z.conj());
        let d = self.r3 * pu * self.r2 * pd;
        let d_bar = c(&self.r3) * pub_ * c(&self.r2) * pdb;
        AtNode {
            d,
            d_bar,
            x: self.t2 * pd,
            x_bar: c(&self.t2) * pdb,
            v: self.t3 * pu * self.r2 * pd,
            v_bar: c(&self.t3) * pub_ * c(&self.r2) * pdb,
        }
    }
}

/// Smallest Gauss–Hermite rule integrating `exp(i x X)` to `tolerance` (error bound
/// `(x²/2)ⁿ/n!`); `None` beyond [`MAX_NODES`].
fn hermite_nodes(x: f64, tolerance: f64) -> Option<usize> {
    let h = 0.5 * x * x;
    let mut bound = 1.0;
    for n in 1..=MAX_NODES {
        bound *= h / n as f64;
        if bound < tolerance {
            return Some(n);
        }
    }
    None
}

/// `a ⊗ b`.
fn kron(a: &Matrix2<C64>, b: &Matrix2<C64>) -> Matrix4<C64> {
    a.kronecker(b)
}

/// `mⁿ`.
fn power(m: &Matrix2<C64>, n: usize) -> Matrix2<C64> {
    (0..n).fold(Matrix2::identity(), |acc, _| acc * m)
}

/// `S M S` with `S` the swap of the two Kronecker factors (indices 1 and 2 exchanged).
fn swap(m: &Matrix4<C64>) -> Matrix4<C64> {
    let p = [0, 2, 1, 3];
    Matrix4::from_fn(|i, j| m[(p[i], p[j])])
}
