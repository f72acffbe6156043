//! Closed-form spectral integration of the plate's Mueller matrices (docs/physics.md §4).
//!
//! A spectral weight `w(k)` (camera channel × illuminant, or a narrow band around one sampled
//! wavelength) is a sum of Gaussians in wavenumber `k = 2π/λ`. Each Mueller matrix is a double
//! sum over path classes `c, c'` of `cross(A_c, A_c') exp(i k d (Q_c' − Q̄_c))`; linearising the
//! phase around the Gaussian's centre `μ` (phase path difference for the oscillation, group path
//! difference `d/dk (k Q)` for the decay) each pair integrates in closed form:
//!
//! ```text
//! ∫ G(k; μ, σ) exp(i k d ΔQ(k)) dk ≈ exp(i μ d ΔQ(μ) − σ² Φ₁² / (2 (1 − i Φ₂ σ²))) / √(1 − i Φ₂ σ²)
//! Φ₁ = d Δ(Q + μ Q')   (group path difference),   Φ₂ = d Δ(2 Q' + μ Q'')   (its dispersion)
//! ```
//! which is exact for a phase quadratic in `k` (`Φ₂ = 0` without dispersion gives the plain
//! Gaussian decay of docs/physics.md §4). Absorption enters `Φ₁` as its imaginary part (exact
//! for an attenuation `exp(−k d Im ΔQ)` linear in `k`); Fresnel amplitudes are evaluated at `μ`
//! (they vary slowly). Orders beyond `N` are the
//! incoherent closed-form tail of [`crate::plate::paths`]. Pairs whose group path difference is far
//! beyond the coherence length `1/σ` are skipped (their factor is below `e^{-18}`).
//!
//! The methods of one Gaussian ([`Method`]), each started from the Gaussian's survey
//! ([`BandSurvey`]); which one serves it is decided in [`crate::spectral::route::gaussian`]: a
//! lossless isotropic plate is two Airy etalons ([`crate::plate::etalon`], exact for Gaussians,
//! [`etalon_sum`]), a narrow Gaussian through any plate the matrix etalon of
//! [`crate::spectral::narrow`] where its residual phases are resolved by a few nodes; otherwise
//! the path classes above or a quadrature of the exact plate.

use crate::band::Gaussian;
use crate::cmath;
use crate::error::{Error, Result};
use crate::optics::frame::PlaneFrame;
use crate::optics::mueller;
use crate::plate::etalon::Etalon;
use crate::plate::paths::{PathClass, PathExpansion};
use crate::plate::slab::{Output, SlabMueller, SlabOptics, Want};
use crate::plate::Plate;
use crate::quadrature::hermite;
use crate::spectral::group::Dispersion;
use crate::spectral::narrow;
use crate::spectral::survey::BandSurvey;
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;

/// Highest coherent order of the path classes; the incoherent tail takes the rest.
pub const MAX_ORDER: usize = 12;
/// Pairs of classes whose amplitude product is below this contribute nothing visible.
const PAIR_NEGLIGIBLE: f64 = 1e-12;

/// Coherent order used for plates thicker than the coherence length.
pub const THICK_ORDER: usize = 2;
/// Pairs with `σ d |ΔG| > PAIR_CUTOFF` are incoherent (factor < e^{-18} ≈ 1.5e-8).
pub const PAIR_CUTOFF: f64 = 6.0;

/// How one Gaussian of a band is integrated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// The narrow-band closed form ([`crate::spectral::narrow`]), where the survey found it
    /// serves.
    Narrow,
    /// Path classes up to the given coherent order (`None`: [`coherent_order`]).
    Paths(Option<usize>),
    /// Gauss–Hermite quadrature of the exact plate with this many nodes.
    Hermite(usize),
    /// Composite Gauss–Legendre quadrature of the exact plate with this many 8-node panels
    /// over ±6.5σ (many strongly interfering orders, e.g. near grazing incidence).
    Panels(usize),
}

/// The plate's reflection and transmission Mueller matrices (s/p frames, power fractions,
/// zero where not wanted) averaged over the unit-mass Gaussian of `s` by `method`.
pub fn gaussian(
    s: &BandSurvey,
    method: Method,
    want: Want,
    output: Output,
) -> Result<(Matrix4<f64>, Matrix4<f64>)> {
    let g = &s.g;
    let lambda = TAU / g.mu;
    Ok(match method {
        Method::Narrow => {
            let plan = s.narrow.as_ref().ok_or_else(|| {
                Error::new(
                    "spectrum",
                    "the narrow-band closed form does not serve this band",
                )
            })?;
            narrow::band(plan, want)
        }
        Method::Hermite(n) => quadrature_rule(&|l| node(s, l, want), g, hermite::rule(n))?,
        Method::Panels(p) => {
            quadrature_rule(&|l| node(s, l, want), g, &hermite::composite_normal(p))?
        }
        Method::Paths(order) => {
            let order = order.unwrap_or_else(|| coherent_order(s));
            let paths = PathExpansion::new(&s.optics, order, lambda, want);
            let sum = |classes: &[PathClass], tail: &Matrix4<f64>| {
                band_sum(classes, &paths, g, &s.dispersion, output) + tail
            };
            (
                sum(&paths.reflection, &paths.tail.r),
                sum(&paths.transmission, &paths.tail.t),
            )
        }
    })
}

/// The exact plate at `lambda` for a quadrature over the Gaussian of `s`. Across a narrow band
/// a dispersive plate keeps the interface amplitudes of the centre (they change by ~|dη/dλ| ×
/// band width, ~1e-5 relative for 4 nm) and takes each node's own phases (the normal components
/// of its modes there, exact).
fn node(s: &BandSurvey, lambda: f64, want: Want) -> Result<SlabMueller> {
    let g = &s.g;
    if !s.plate.is_dispersive() {
        s.optics.mueller(lambda, want)
    } else if g.sigma <= narrow::NARROW_BAND * g.mu {
        let q = s.plate.at(lambda)?.layer_q(&s.frame, s.beta);
        s.optics.mueller_with_phases(lambda, &q, want)
    } else {
        s.plate
            .at(lambda)?
            .optics(&s.frame, s.beta)?
            .mueller(lambda, want)
    }
}

/// `Σ_j a_j` × `method` over Gaussian `j` of `band` for every Gaussian (the forced method of the
/// tests of each method and of the benchmarks; [`crate::spectral::model::PlateModel::band`]
/// routes each Gaussian).
pub fn band_with(
    plate: &Plate,
    frame: &PlaneFrame,
    beta: C64,
    band: &[Gaussian],
    want: Want,
    output: Output,
    method: Method,
) -> Result<SlabMueller> {
    if band.is_empty() {
        return Err(Error::new("spectrum", "empty spectral band"));
    }
    let (mut r, mut t) = (Matrix4::zeros(), Matrix4::zeros());
    for g in band {
        let optics = plate.at(TAU / g.mu)?.optics(frame, beta)?;
        let s = BandSurvey::new(plate, *frame, beta, g, optics)?;
        let (mr, mt) = gaussian(&s, method, want, output)?;
        r += mr * g.amplitude;
        t += mt * g.amplitude;
    }
    Ok(output.keep(SlabMueller {
        r: want.reflection.then_some(r),
        t: want.transmission.then_some(t),
    }))
}

/// The narrow-band closed form of `plate` over one unit-mass Gaussian `g`, where it serves
/// (`None` elsewhere).
pub fn narrow_closed_form(
    plate: &Plate,
    frame: &PlaneFrame,
    beta: C64,
    g: &Gaussian,
    want: Want,
) -> Result<Option<SlabMueller>> {
    let optics = plate.at(TAU / g.mu)?.optics(frame, beta)?;
    let s = BandSurvey::new(plate, *frame, beta, g, optics)?;
    Ok(s.narrow.as_ref().map(|n| {
        let (r, t) = narrow::band(n, want);
        SlabMueller {
            r: want.reflection.then_some(r),
            t: want.transmission.then_some(t),
        }
    }))
}

/// `Σ_j a_j` × the etalon over Gaussian `j` (`None` if a series is too long). Thick plates
/// give every Gaussian the same incoherent sum: it is evaluated once (and kept in `incoherent`
/// for further bands).
pub fn etalon_sum(
    etalon: &Etalon,
    band: &[Gaussian],
    want: Want,
    output: Output,
    incoherent: &mut Option<SlabMueller>,
) -> Option<SlabMueller> {
    let (mut r, mut t) = (Matrix4::zeros(), Matrix4::zeros());
    let mut weight = 0.0; // of the incoherent Gaussians
    for g in band {
        if etalon.is_incoherent(g) {
            if incoherent.is_none() {
                *incoherent = Some(etalon.band(g, want, output)?);
            }
            weight += g.amplitude;
            continue;
        }
        let m = etalon.band(g, want, output)?;
        r += m.r.unwrap_or_default() * g.amplitude;
        t += m.t.unwrap_or_default() * g.amplitude;
    }
    if let Some(m) = incoherent.filter(|_| weight != 0.0) {
        r += m.r.unwrap_or_default() * weight;
        t += m.t.unwrap_or_default() * weight;
    }
    Some(SlabMueller {
        r: want.reflection.then_some(r),
        t: want.transmission.then_some(t),
    })
}

/// The smallest round-trip phase index `min Re(q↑ − q↓)` of the layer (its group path per
/// unit thickness for one internal round trip, up to dispersion).
fn round_trip(optics: &SlabOptics) -> f64 {
    let m = optics.layer_modes();
    (0..2)
        .flat_map(|a| (0..2).map(move |b| (m.up[a].q - m.down[b].q).re))
        .fold(f64::INFINITY, f64::min)
}

/// The coherent order `N` of the path classes over the Gaussian of `s`: enough round trips for
/// the amplitude to fall below [`crate::spectral::survey::ORDER_TOLERANCE`], at most
/// [`MAX_ORDER`]; at most [`THICK_ORDER`] if a round trip is longer than the coherence length
/// (then orders only interfere with paths of the same traversal counts, which the incoherent
/// tail would miss only at the first orders, where mode conversions still carry weight).
pub fn coherent_order(s: &BandSurvey) -> usize {
    let cap = if s.g.sigma * s.optics.thickness_nm * round_trip(&s.optics) > PAIR_CUTOFF {
        THICK_ORDER
    } else {
        MAX_ORDER
    };
    s.orders.min(MAX_ORDER).min(cap)
}

/// `Σ_i w_i M(μ + σ x_i)`: a quadrature rule for the normal law applied to the exact plate
/// over one Gaussian. A convex combination of exact Mueller matrices, so energy is conserved
/// exactly.
fn quadrature_rule(
    node: &dyn Fn(f64) -> Result<SlabMueller>,
    g: &Gaussian,
    rule: &[(f64, f64)],
) -> Result<(Matrix4<f64>, Matrix4<f64>)> {
    let (mut r, mut t) = (Matrix4::zeros(), Matrix4::zeros());
    for &(x, w) in rule {
        let k = g.mu + g.sigma * x;
        if k <= 0.0 {
            continue;
        }
        let lambda = std::f64::consts::TAU / k;
        let m = node(lambda)?;
        r += m.r.unwrap_or_default() * w;
        t += m.t.unwrap_or_default() * w;
    }
    Ok((r, t))
}

/// `Σ_{c,c'} F_cc' cross(A_c, A_c')` as a Mueller matrix, `F` the closed-form Gaussian
/// integral of the pair's phase.
fn band_sum(
    classes: &[PathClass],
    paths: &PathExpansion,
    g: &Gaussian,
    disp: &Dispersion,
    output: Output,
) -> Matrix4<f64> {
    let d = paths.thickness_nm;
    let sum = |c: &PathClass, x: &[f64; 4]| -> f64 {
        c.counts.iter().zip(x).map(|(n, x)| x * f64::from(*n)).sum()
    };
    // Per class: group term Q + μ Q' and curvature term 2 Q' + μ Q''.
    let gs: Vec<(f64, f64)> = classes
        .iter()
        .map(|c| {
            let (d1, d2) = (sum(c, &disp.d1), sum(c, &disp.d2));
            (c.q.re + g.mu * d1, 2.0 * d1 + g.mu * d2)
        })
        .collect();
    let s2 = g.sigma * g.sigma;
    let i = C64::new(0.0, 1.0);
    let mut k = Matrix4::<C64>::zeros();
    let mut m00 = 0.0;
    let norms: Vec<f64> = classes.iter().map(|c| c.amplitude.norm()).collect();
    for (a, ca) in classes.iter().enumerate() {
        let mut b = Matrix2::<C64>::zeros();
        for (c, cc) in classes.iter().enumerate() {
            let re1 = d * (gs[c].0 - gs[a].0);
            if g.sigma * re1.abs() > PAIR_CUTOFF || norms[a] * norms[c] < PAIR_NEGLIGIBLE {
                continue;
            }
            // Absorption makes the exponent complex; the integral stays exact for an
            // attenuation linear in k, as long as it does not move the band's centre by more
            // than a band width (beyond, the Gaussian model of the band no longer holds and the
            // term is attenuated to ~e^{-μ/σ} anyway).
            let im1 = (d * (cc.q.im + ca.q.im)).min(1.0 / g.sigma);
            let phi1 = C64::new(re1, im1);
            let phi2 = d * (gs[c].1 - gs[a].1);
            let den = C64::new(1.0, -phi2 * s2);
            let phase = i * g.mu * d * (cc.q - ca.q.conj());
            b += cc.amplitude * (phase - 0.5 * s2 * phi1 * phi1 / den).exp() / cmath::sqrt(den);
        }
        match output {
            Output::Mueller => k += mueller::cross(&ca.amplitude, &b),
            Output::Intensity => {
                m00 += 0.5 * ca.amplitude.zip_map(&b, |x, y| x.conj() * y).sum().re
            }
        }
    }
    match output {
        Output::Mueller => mueller::from_coherency(&k),
        Output::Intensity => {
            let mut m = Matrix4::zeros();
            m[(0, 0)] = m00;
            m
        }
    }
}
