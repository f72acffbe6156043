//! A narrow band through a birefringent plate in closed form: the plate as a matrix etalon.
//!
//! Across a band narrow enough that the interface amplitudes and the layer's birefringent
//! phase differences do not change (σ ≪ μ and `σ d |G_j − ḡ| ≪ 1`), the only fast variation
//! is the common phase of the internal round trips. With the wavenumber `k = μ + κ`, each
//! traversal of the layer in mode `j` has the phase `μ d Q_j + κ d G_j` (`G_j = Q_j + μ Q_j'`
//! its group index); writing `G_j = ḡ + δ_j` and neglecting `κ d δ_j`, one round trip is
//! `D(k) = h D̃` with `D̃ = r₃ P↑(μ) r₂ P↓(μ)` (the exact round trip at the centre) and the
//! scalar `h = exp(2 i κ d ḡ)`. Then `J_T = t₂ P↓ Σₙ hⁿ D̃ⁿ t₁` and, as for the scalar
//! etalon ([`crate::etalon`]), a pair of orders `(n, n + Δ)` keeps `⟨h^Δ⟩ = g(Δ) =
//! exp(−2 σ² d² ḡ² Δ²)` of its coherence. With Kronecker products (`cross(A, B) = conj(A) ⊗ B`,
//! [`crate::mueller::cross`]) the double sum over orders becomes a geometric series of
//! `K = conj(D̃) ⊗ D̃`:
//!
//! ```text
//! Σ_{n,m} g(m − n) conj(Aₙ) ⊗ Aₘ = (conj X ⊗ X) (I − K)⁻¹ B (conj t₁ ⊗ t₁),   Aₙ = X D̃ⁿ t₁
//! B = I + I ⊗ P + conj(P) ⊗ I,      P = Σ_{Δ≥1} g(Δ) D̃^Δ
//! ```
//! with `X = t₂ P↓` for transmission (times the flux factor), and for reflection
//! `R = r₁ + Σ_{n≥1} hⁿ V D̃ⁿ⁻¹ t₁` (`V = t₃ P↑ r₂ P↓`):
//! `⟨conj R ⊗ R⟩ = conj r₁ ⊗ r₁ + conj r₁ ⊗ V S t₁ + conj(V S t₁) ⊗ r₁ + (conj V ⊗ V)(I − K)⁻¹ B
//! (conj t₁ ⊗ t₁)`, `S = Σ_{j≥0} g(j + 1) D̃ʲ`. The neglected residual changes the coherence
//! of a pair by at most `σ² Φ²/2`, `Φ` its residual group path difference, which
//! [`RESIDUAL_MAX`] bounds (tests/spectral_narrow.rs measures the error against dense
//! quadrature).

use crate::cmath;
use crate::mueller;
use crate::slab::{SlabOptics, Want};
use crate::spectral::weights::Gaussian;
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;

/// Largest residual `σ d max_j |G_j − ḡ|` (radians per band width) of the propagating modes
/// for which the closed form is used.
pub const RESIDUAL_MAX: f64 = 0.01;
/// A mode attenuated by more than `exp(−ATTENUATED)` in one traversal carries nothing.
const ATTENUATED: f64 = 40.0;
/// Series terms below this are dropped.
const SERIES_TOLERANCE: f64 = 1e-13;
/// Longest series; beyond, the caller uses the general method.
const MAX_TERMS: usize = 4096;

/// The band-averaged Mueller matrices `(R, T)` (zero where not wanted) of the plate `optics`
/// (solved at the band's centre) over the unit-mass Gaussian `g`, given the group indices
/// `group` of the four traversals `[o↓, e↓, o↑, e↑]` at the centre. `None` if the residual is
/// too large or the series too long.
pub fn band(
    optics: &SlabOptics,
    g: &Gaussian,
    group: &[f64; 4],
    want: Want,
) -> Option<(Matrix4<f64>, Matrix4<f64>)> {
    let lambda = std::f64::consts::TAU / g.mu;
    let d = optics.thickness_nm;
    let m = optics.layer_modes();
    let q = [-m.down[0].q, -m.down[1].q, m.up[0].q, m.up[1].q];
    let live: Vec<f64> = (0..4)
        .filter(|&j| g.mu * d * q[j].im < ATTENUATED)
        .map(|j| group[j])
        .collect();
    let (lo, hi) = live
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
            (l.min(x), h.max(x))
        });
    let gbar = if live.is_empty() {
        0.0
    } else {
        0.5 * (lo + hi)
    };
    if !live.is_empty() && g.sigma * d * 0.5 * (hi - lo) > RESIDUAL_MAX {
        return None;
    }
    let (pd, pu) = optics.propagation(lambda);
    let (t1, r1) = (optics.top.t_above(), optics.top.r_above());
    let (t3, r3) = (optics.top.t_below(), optics.top.r_below());
    let (t2, r2) = (optics.bottom.t_above(), optics.bottom.r_above());
    let dt = r3 * pu * r2 * pd;
    let a = 2.0 * (g.sigma * d * gbar).powi(2);
    let (p, s) = series(&dt, a)?;
    let one = Matrix2::<C64>::identity();
    let b = Matrix4::identity() + mueller::cross(&one, &p) + mueller::cross(&p, &one);
    let k = Matrix4::identity() - mueller::cross(&dt, &dt);
    let y = cmath::solve4(&k, &(b * mueller::cross(&t1, &t1)))?;
    let t = if want.transmission {
        let x = t2 * pd * C64::new(optics.transmission_flux_ratio().sqrt(), 0.0);
        mueller::from_coherency(&(mueller::cross(&x, &x) * y))
    } else {
        Matrix4::zeros()
    };
    let r = if want.reflection {
        let v = t3 * pu * r2 * pd;
        let vst = v * s * t1;
        let c = mueller::cross(&r1, &r1)
            + mueller::cross(&r1, &vst)
            + mueller::cross(&vst, &r1)
            + mueller::cross(&v, &v) * y;
        mueller::from_coherency(&c)
    } else {
        Matrix4::zeros()
    };
    Some((r, t))
}

/// `P = Σ_{Δ≥1} g(Δ) D̃^Δ` and `S = Σ_{j≥0} g(j + 1) D̃ʲ` with `g(Δ) = exp(−a Δ²)`.
fn series(dt: &Matrix2<C64>, a: f64) -> Option<(Matrix2<C64>, Matrix2<C64>)> {
    let (mut p, mut s) = (Matrix2::zeros(), Matrix2::zeros());
    let mut power = Matrix2::<C64>::identity(); // D̃^(Δ−1)
    let (mut gd, step, mut ratio) = (1.0f64, (-2.0 * a).exp(), (-a).exp());
    for _ in 1..=MAX_TERMS {
        gd *= ratio; // g(Δ) = g(Δ−1) exp(−a (2Δ − 1))
        ratio *= step;
        s += power * C64::new(gd, 0.0);
        power *= *dt;
        p += power * C64::new(gd, 0.0);
        if power.norm() * gd < SERIES_TOLERANCE {
            return Some((p, s));
        }
    }
    None
}
