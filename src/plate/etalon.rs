//! The isotropic fast path of the plate: a lossless isotropic layer (`η_o = η_e`, real, no
//! dispersion) between two isotropic media is two independent Airy etalons, one for s and one
//! for p, and its Mueller matrices follow in closed form, exactly at one wavelength and
//! exactly over a Gaussian band (no linearisation is needed: the phase is linear in `k`).
//!
//! With the interface amplitudes of [`crate::optics::fresnel`] (1: top from above, 3: top from below,
//! 2: bottom from above), per polarisation `x ∈ {s, p}` and `h = exp(2 i k d w)` the phase of
//! one internal round trip (`w = sqrt(η² − β²)` of the layer):
//!
//! ```text
//! T_x(k) = τ_x Σ_{m≥0} ρ_x^m h^m            τ_x = t₁ t₂ √(P_exit/P_ext),  ρ_x = r₃ r₂
//! R_x(k) = r₁ + u_x Σ_{m≥1} ρ_x^{m−1} h^m    u_x = t₁ r₂ t₃
//! ```
//! (the slab of [`crate::plate::slab`] with diagonal blocks, up to the common single-pass phase of
//! `T`, which cancels in every power term). The Jones matrices are diagonal, so the Mueller
//! matrix needs only the coherencies `C_xy = ⟨conj(A_x) A_y⟩` (docs/physics.md §4). Over the
//! band `G(k; μ, σ)`, a pair of paths whose round-trip counts differ by `Δ` keeps
//! `⟨h^Δ⟩ = h(μ)^Δ g(Δ)` with `g(Δ) = exp(−2 σ² d² w² Δ²)`, so the double sums over paths
//! collapse to single sums over `Δ` (geometric sums over the common count):
//!
//! ```text
//! B_xy = 1 + Σ_{Δ≥1} g(Δ) [(ρ_y h)^Δ + conj(ρ_x h)^Δ],      S_y = h Σ_{j≥0} g(j+1) (ρ_y h)^j
//! C_xy(T) = conj(τ_x) τ_y B_xy / (1 − conj(ρ_x) ρ_y)
//! C_xy(R) = conj(r₁ₓ) r₁ᵧ + conj(r₁ₓ) u_y S_y + r₁ᵧ conj(u_x S_x) + conj(u_x) u_y B_xy / (1 − conj(ρ_x) ρ_y)
//! ```
//! At one wavelength (`g ≡ 1`) the sums are geometric: `B_xy = (1 − conj(ρ_x)ρ_y) /
//! ((1 − ρ_y h)(1 − conj(ρ_x h)))`, `S_y = h/(1 − ρ_y h)` (Airy's formulas); for a band
//! thicker than the coherence length only `Δ = 0` survives (the incoherent sum
//! `T₁T₂/(1 − R₃R₂)` per polarisation).

use crate::band::Gaussian;
use crate::optics::fresnel::{normal_component, Fresnel};
use crate::optics::mueller;
use crate::plate::slab::Output;
use crate::plate::slab::{SlabMueller, Want};
use num_complex::Complex64 as C64;

/// Series terms below this (relative to the leading term 1) are dropped.
const SERIES_TOLERANCE: f64 = 1e-13;
/// Longest series summed; beyond (thin plates near grazing incidence, `|ρ| → 1` with little
/// band damping) the caller uses the general method.
const MAX_TERMS: usize = 4096;

/// A lossless isotropic layer between isotropic media at one incidence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Etalon {
    r1: [C64; 2],
    u: [C64; 2],
    rho: [C64; 2],
    tau: [C64; 2],
    /// `w` of the layer (real: the layer is lossless and the wave propagates in it).
    w: f64,
    thickness_nm: f64,
}

/// Coherencies of a diagonal Jones matrix: `⟨|A_s|²⟩`, `⟨conj(A_s) A_p⟩`, `⟨|A_p|²⟩`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Diagonal {
    ss: f64,
    sp: C64,
    pp: f64,
}

impl Etalon {
    /// The etalon of a layer of index `layer` and thickness `thickness_nm` between `top`
    /// (light arrives from there) and `bottom`, for incidence parameter `beta`. `None` unless
    /// the fast path applies: real layer index with a propagating wave in it (`β < η`), and
    /// non-singular interfaces.
    pub fn new(top: C64, layer: C64, bottom: C64, beta: C64, thickness_nm: f64) -> Option<Self> {
        let w = normal_component(layer, beta);
        if layer.im != 0.0 || w.im != 0.0 || w.re <= 0.0 || beta.im != 0.0 {
            return None;
        }
        let upper = Fresnel::new(top, layer, beta)?;
        let lower = Fresnel::new(layer, bottom, beta)?;
        let (w_top, w_bottom) = (normal_component(top, beta), normal_component(bottom, beta));
        // Flux per unit amplitude is ∝ Re w for both s and p of a real-index medium.
        let flux = if w_bottom.re > 0.0 && w_top.re > 0.0 {
            (w_bottom.re / w_top.re).sqrt()
        } else {
            0.0
        };
        let each = |f: &dyn Fn(usize) -> C64| [f(0), f(1)];
        Some(Etalon {
            r1: upper.r_above,
            u: each(&|x| upper.t_above[x] * lower.r_above[x] * upper.t_below[x]),
            rho: each(&|x| upper.r_below[x] * lower.r_above[x]),
            tau: each(&|x| upper.t_above[x] * lower.t_above[x] * flux),
            w: w.re,
            thickness_nm,
        })
    }

    /// Mueller matrices (Mitsuba's convention, s/p frames, power fractions) exactly at
    /// `lambda_nm`.
    pub fn mueller(&self, lambda_nm: f64, want: Want, output: Output) -> SlabMueller {
        let h = self.round_trip(std::f64::consts::TAU / lambda_nm);
        let b = |x: usize, y: usize| {
            (1.0 - self.rho[x].conj() * self.rho[y])
                / ((1.0 - self.rho[y] * h) * (1.0 - self.rho[x] * h).conj())
        };
        let s = |y: usize| h / (1.0 - self.rho[y] * h);
        self.assemble(&b, &s, want, output)
    }

    /// The terms the band average over the unit-mass Gaussian `g` sums ([`Etalon::band`]): the
    /// first `Δ` where `max|ρ|^Δ g(Δ)` falls below `SERIES_TOLERANCE`; `None` beyond
    /// `MAX_TERMS` (4096: thin plates near grazing incidence, `|ρ| → 1` with little band damping).
    pub fn band_terms(&self, g: &Gaussian) -> Option<usize> {
        let a = 2.0 * (g.sigma * self.thickness_nm * self.w).powi(2);
        let largest = self.rho[0].norm().max(self.rho[1].norm());
        // ln(max|ρ|^Δ g(Δ)) = Δ ln max|ρ| − a Δ²: decreasing in Δ.
        let log = |d: f64| d * largest.ln() - a * d * d;
        let tolerance = SERIES_TOLERANCE.ln();
        (1..=MAX_TERMS).find(|&d| log(d as f64) < tolerance)
    }

    /// Mueller matrices averaged over the unit-mass Gaussian band `g` (in wavenumber);
    /// `None` if the series would need more than `MAX_TERMS` (4096) terms
    /// ([`Etalon::band_terms`]).
    pub fn band(&self, g: &Gaussian, want: Want, output: Output) -> Option<SlabMueller> {
        let terms = self.band_terms(g)?;
        let h = self.round_trip(g.mu);
        let a = 2.0 * (g.sigma * self.thickness_nm * self.w).powi(2);
        let rh = [self.rho[0] * h, self.rho[1] * h];
        // Partial sums P_x = Σ_{Δ≥1} g(Δ) (ρ_x h)^Δ and Q_x = Σ_{j≥0} g(j+1) (ρ_x h)^j.
        let (mut p, mut q) = ([C64::new(0.0, 0.0); 2], [C64::new(0.0, 0.0); 2]);
        let mut power = [C64::new(1.0, 0.0); 2]; // (ρ_x h)^(Δ−1)
        let (mut gd, step, mut ratio) = (1.0f64, (-2.0 * a).exp(), (-a).exp());
        for _ in 1..=terms {
            gd *= ratio; // g(Δ) = exp(−a Δ²), by g(Δ) = g(Δ−1) exp(−a (2Δ − 1))
            ratio *= step;
            for x in 0..2 {
                q[x] += power[x] * gd;
                power[x] *= rh[x];
                p[x] += power[x] * gd;
            }
        }
        let b = |x: usize, y: usize| 1.0 + p[y] + p[x].conj();
        let s = |y: usize| h * q[y];
        Some(self.assemble(&b, &s, want, output))
    }

    /// True if orders one round trip apart keep no coherence over `g` (`g(1) < e^{-40}`): the
    /// band average is then the incoherent sum, the same for every such band.
    pub fn is_incoherent(&self, g: &Gaussian) -> bool {
        2.0 * (g.sigma * self.thickness_nm * self.w).powi(2) > 40.0
    }

    /// `exp(2 i k d w)`.
    fn round_trip(&self, k: f64) -> C64 {
        C64::from_polar(1.0, 2.0 * k * self.thickness_nm * self.w)
    }

    /// Coherencies from the sums `B_xy` and `S_y` (module docs), then Mueller matrices.
    fn assemble(
        &self,
        b: &dyn Fn(usize, usize) -> C64,
        s: &dyn Fn(usize) -> C64,
        want: Want,
        output: Output,
    ) -> SlabMueller {
        // B_xy / (1 − conj(ρ_x) ρ_y) and S_y, each evaluated once (pairs ss, sp, pp).
        let g = |x: usize, y: usize| b(x, y) / (1.0 - self.rho[x].conj() * self.rho[y]);
        let zero = C64::new(0.0, 0.0);
        let sp = if output == Output::Mueller {
            g(0, 1)
        } else {
            zero
        };
        let geo = [[g(0, 0), sp], [sp, g(1, 1)]];
        let geometric = |x: usize, y: usize| geo[x][y];
        let sv = if want.reflection {
            [s(0), s(1)]
        } else {
            [zero, zero]
        };
        let s = |y: usize| sv[y];
        let pairs = |c: &dyn Fn(usize, usize) -> C64| Diagonal {
            ss: c(0, 0).re,
            sp: match output {
                Output::Mueller => c(0, 1),
                Output::Intensity => C64::new(0.0, 0.0),
            },
            pp: c(1, 1).re,
        };
        let t = want
            .transmission
            .then(|| pairs(&|x, y| self.tau[x].conj() * self.tau[y] * geometric(x, y)));
        let r = want.reflection.then(|| {
            let (r1, u) = (&self.r1, &self.u);
            pairs(&|x, y| {
                r1[x].conj() * r1[y]
                    + r1[x].conj() * u[y] * s(y)
                    + r1[y] * (u[x] * s(x)).conj()
                    + u[x].conj() * u[y] * geometric(x, y)
            })
        });
        let to_mueller = |d: Diagonal| match output {
            Output::Mueller => mueller::from_diagonal(d.ss, d.sp, d.pp),
            Output::Intensity => {
                let mut m = nalgebra::Matrix4::zeros();
                m[(0, 0)] = 0.5 * (d.ss + d.pp);
                m
            }
        };
        SlabMueller {
            r: r.map(to_mueller),
            t: t.map(to_mueller),
        }
    }
}
