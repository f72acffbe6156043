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
//! [`Method::Auto`] first takes the closed forms that need no choice of order: a lossless
//! isotropic plate is two Airy etalons ([`crate::plate::etalon`], exact for Gaussians), and a narrow
//! Gaussian (σ ≤ [`NARROW_BAND`] μ) through any plate is the matrix etalon of
//! [`crate::spectral::narrow`] where its residual phases are resolved by a few nodes. The
//! shared quadrature of [`integrate_set`] interpolates a dispersive plate's interface blocks
//! across the band ([`crate::quadrature::interpolate`]) and sizes its rule order by order
//! ([`crate::quadrature::chebyshev`]).

use crate::band::Gaussian;
use crate::cmath;
use crate::colour::weights::{gaussians, WeightSet};
use crate::error::{Error, Result};
use crate::optics::frame::PlaneFrame;
use crate::optics::mueller;
use crate::plate::etalon::Etalon;
use crate::plate::paths::{PathClass, PathExpansion};
use crate::plate::slab::{Output, SlabMueller, SlabOptics, Want};
use crate::plate::Plate;
use crate::quadrature::hermite;
use crate::spectral::group::{dispersion, group_round_trips, Dispersion};
use crate::spectral::narrow;
use crate::spectral::pointwise;
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;

/// Highest coherent order ever used; the incoherent tail takes the rest.
pub const MAX_ORDER: usize = 12;
/// Orders are added until the round-trip amplitude falls below this.
pub const ORDER_TOLERANCE: f64 = 1e-5;
/// Pairs of classes whose amplitude product is below this contribute nothing visible.
const PAIR_NEGLIGIBLE: f64 = 1e-12;

/// Coherent order used for plates thicker than the coherence length.
pub const THICK_ORDER: usize = 2;
/// Pairs with `σ d |ΔG| > PAIR_CUTOFF` are incoherent (factor < e^{-18} ≈ 1.5e-8).
pub const PAIR_CUTOFF: f64 = 6.0;

/// How the Gaussians of a band are integrated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Chosen per Gaussian from the plate's round-trip path difference `D`, the number of
    /// significant round trips and the coherence length `1/σ` (see `auto`): Gauss–Hermite
    /// quadrature of the exact plate when the integrand oscillates slowly over the band, the
    /// closed-form path-class sum otherwise.
    Auto,
    /// Path classes up to the given coherent order (`None`: chosen automatically).
    Paths(Option<usize>),
    /// Gauss–Hermite quadrature of the exact plate with this many nodes.
    Hermite(usize),
    /// Composite Gauss–Legendre quadrature of the exact plate with this many 8-node panels
    /// over ±6.5σ (many strongly interfering orders, e.g. near grazing incidence).
    Panels(usize),
}

/// Gaussians with `σ ≤ NARROW_BAND μ` (FWHM up to ~13 nm at 550 nm) are narrow: a quadrature
/// of a dispersive plate over them solves the interfaces once, at the centre.
pub const NARROW_BAND: f64 = 0.01;

/// Largest oscillation (radians per band width) [`Method::Auto`] integrates by Gauss–Hermite.
pub const HERMITE_LIMIT: f64 = 10.0;

/// Integrates the plate's reflection/transmission Mueller matrices over the band
/// `Σ_j a_j G(k; μ_j, σ_j)` (Mitsuba's convention, s/p frames, power fractions).
pub fn band(
    plate: &Plate,
    frame: &PlaneFrame,
    beta: C64,
    band: &[Gaussian],
    want: Want,
    output: Output,
) -> Result<SlabMueller> {
    band_with(plate, frame, beta, band, want, output, Method::Auto)
}

/// [`integrate`] with a forced [`Method`] (for tests of the shortcuts and benchmarks).
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
    let mut r = Matrix4::zeros();
    let mut t = Matrix4::zeros();
    // Without dispersion the interfaces do not depend on the wavelength: solve them once.
    let fixed = if plate.is_dispersive() {
        None
    } else {
        Some(
            plate
                .at(std::f64::consts::TAU / band[0].mu)?
                .optics(frame, beta)?,
        )
    };
    let optics_at = |lambda: f64| -> Result<SlabOptics> {
        match fixed {
            Some(o) => Ok(o),
            None => plate.at(lambda)?.optics(frame, beta),
        }
    };
    for g in band {
        let lambda = std::f64::consts::TAU / g.mu;
        let optics = optics_at(lambda)?;
        let group = dispersion(plate, frame, beta, g.mu)?;
        if method == Method::Auto && g.sigma <= NARROW_BAND * g.mu {
            if let Some((mr, mt)) =
                narrow::band(&optics, g, &traversals(&optics, &group, g.mu), want)
            {
                r += mr * g.amplitude;
                t += mt * g.amplitude;
                continue;
            }
        }
        let method = match method {
            Method::Auto => auto(
                &optics,
                lambda,
                g.sigma,
                group_round_trips(&optics, &group, g.mu),
            ),
            m => m,
        };
        // The plate's exact Mueller matrices at the nodes of a quadrature over this Gaussian.
        // Across a narrow band a dispersive plate keeps the interface amplitudes of the centre
        // (they change by ~|dη/dλ| × band width, ~1e-5 relative for 4 nm) and takes each node's
        // own phases (the normal components of its modes there, exact).
        let narrow = g.sigma <= NARROW_BAND * g.mu;
        let node = |l: f64| -> Result<SlabMueller> {
            match (fixed, narrow) {
                (Some(o), _) => o.mueller(l, want),
                (None, true) => {
                    optics.mueller_with_phases(l, &plate.at(l)?.layer_q(frame, beta), want)
                }
                (None, false) => plate.at(l)?.optics(frame, beta)?.mueller(l, want),
            }
        };
        let (mr, mt) = match method {
            Method::Hermite(n) => quadrature_rule(&node, g, hermite::rule(n))?,
            Method::Panels(p) => quadrature_rule(&node, g, &hermite::composite_normal(p))?,
            _ => {
                let order = match method {
                    Method::Paths(Some(n)) => n,
                    _ => coherent_order(&optics, lambda, g.sigma),
                };
                let paths = PathExpansion::new(&optics, order, lambda, want);
                let sum = |classes: &[PathClass], tail: &Matrix4<f64>| {
                    band_sum(classes, &paths, g, &group, output) + tail
                };
                (
                    sum(&paths.reflection, &paths.tail.r),
                    sum(&paths.transmission, &paths.tail.t),
                )
            }
        };
        r += mr * g.amplitude;
        t += mt * g.amplitude;
    }
    Ok(output.keep(SlabMueller {
        r: want.reflection.then_some(r),
        t: want.transmission.then_some(t),
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

/// The narrow-band closed form ([`narrow::band`]) of `plate` over one unit-mass Gaussian `g`,
/// where it applies (`None` elsewhere); what [`integrate`] uses for such a Gaussian.
pub fn narrow_closed_form(
    plate: &Plate,
    frame: &PlaneFrame,
    beta: C64,
    g: &Gaussian,
    want: Want,
) -> Result<Option<SlabMueller>> {
    if g.sigma > NARROW_BAND * g.mu {
        return Ok(None);
    }
    let optics = plate
        .at(std::f64::consts::TAU / g.mu)?
        .optics(frame, beta)?;
    let t = traversals(&optics, &dispersion(plate, frame, beta, g.mu)?, g.mu);
    Ok(
        narrow::band(&optics, g, &t, want).map(|(r, t)| SlabMueller {
            r: want.reflection.then_some(r),
            t: want.transmission.then_some(t),
        }),
    )
}

/// How each traversal's phase varies around `mu` ([`narrow::Traversal`]), from the modes at
/// the centre and the dispersion derivatives.
fn traversals(optics: &SlabOptics, disp: &Dispersion, mu: f64) -> [narrow::Traversal; 4] {
    let m = optics.layer_modes();
    let q = [-m.down[0].q, -m.down[1].q, m.up[0].q, m.up[1].q];
    std::array::from_fn(|j| narrow::Traversal {
        group: q[j] + mu * disp.d1[j],
        curvature: 2.0 * disp.d1[j] + mu * disp.d2[j],
    })
}

/// [`Method::Auto`]'s choice for one Gaussian. With `a = σ D` per round trip and `N` the
/// number of round trips whose amplitude exceeds [`ORDER_TOLERANCE`], the integrand oscillates
/// up to `a (N + 1)` radians per band width: Gauss–Hermite with `8 + 3x + x²` nodes integrates
/// `exp(i x X)` to ~1e-6 up to `x = `[`HERMITE_LIMIT`] (128 nodes); beyond, the closed-form path
/// classes take over (validated against dense quadrature in `tests/spectral_band.rs`).
/// The group path (not the phase path) sets how fast the integrand oscillates: strongly
/// dispersive media (rutile's group index reaches ~9 near 360 nm) oscillate much faster than
/// their phase index suggests.
fn auto(optics: &SlabOptics, lambda: f64, sigma: f64, (rt_min, rt_max): (f64, f64)) -> Method {
    let a = sigma * optics.thickness_nm * rt_max;
    let n = amplitude_order(optics, lambda, MAX_PANEL_ORDER);
    let x = a * (n as f64 + 1.0);
    if x <= HERMITE_LIMIT {
        return Method::Hermite(((8.0 + 3.0 * x + x * x).ceil() as usize).min(hermite::MAX_NODES));
    }
    if sigma * optics.thickness_nm * rt_min > PAIR_CUTOFF {
        // Orders mutually incoherent: a few coherent orders and the incoherent tail.
        return Method::Paths(None);
    }
    // Many interfering orders: the coherent path sum (~K² pair terms for K ≈ (N+2)³/3 classes)
    // or ~2 quadrature panels per oscillation of the highest significant order over ±6.5σ
    // (8 exact plates each), whichever costs less (a pair term ~1/40 of a plate evaluation).
    let panels = (((13.0 * x / std::f64::consts::TAU) * 2.0).ceil() as usize).clamp(16, MAX_PANELS);
    let classes = (n as f64 + 2.0).powi(3) / 3.0;
    if n <= MAX_ORDER && classes * classes < 40.0 * 8.0 * panels as f64 {
        Method::Paths(None)
    } else {
        Method::Panels(panels)
    }
}

/// Highest order considered when choosing [`Method::Panels`].
const MAX_PANEL_ORDER: usize = 2000;

/// Most panels [`Method::Auto`] spends on one Gaussian (4096 plate evaluations). Only plates
/// near grazing incidence with hundreds of strongly interfering orders ask for more; there the
/// rule under-resolves the fastest orders (whose weight is then ≲ 1e-3 of the band): the
/// result stays a convex combination of exact Mueller matrices, so energy is still conserved,
/// and a query costs at most a few milliseconds instead of seconds.
pub const MAX_PANELS: usize = 512;

/// Round trips until the internal amplitude falls below [`ORDER_TOLERANCE`] (at most `cap`).
fn amplitude_order(optics: &SlabOptics, lambda: f64, cap: usize) -> usize {
    let (pd, pu) = optics.propagation(lambda);
    let rho = (optics.top.r_below() * pu * optics.bottom.r_above() * pd).norm();
    if rho <= 0.0 {
        0
    } else if rho >= 1.0 {
        cap
    } else {
        ((ORDER_TOLERANCE.ln() / rho.ln()).ceil() as usize)
            .saturating_sub(1)
            .min(cap)
    }
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

/// Integrates a plate that is not an etalon ([`crate::spectral::model`] decides) over the three
/// channels of a weight set at once, every approximation below 1e-5 of the fitted weights:
/// when the plate's spectrum varies slowly over the whole visible range (thin plates: few
/// oscillations of its significant orders across the weights' support), one product-integration
/// rule of the exact plate serves every Gaussian of every channel ([`pointwise`]: at most 1024
/// plate evaluations instead of a quadrature per Gaussian); otherwise each channel goes through
/// [`integrate`].
pub fn channels_exact(
    plate: &Plate,
    frame: &PlaneFrame,
    beta: C64,
    set: WeightSet,
    want: Want,
    output: Output,
) -> Result<[SlabMueller; 3]> {
    match pointwise::exact_points(plate, frame, beta, set)? {
        Some(points) => pointwise::channels(plate, frame, beta, set, points, want, output),
        None => {
            let one = |c: usize| band(plate, frame, beta, gaussians(set, c), want, output);
            Ok([one(0)?, one(1)?, one(2)?])
        }
    }
}

/// The coherent order `N` of the path-class method: enough round trips for the amplitude to
/// fall below [`ORDER_TOLERANCE`]; at most [`THICK_ORDER`] if a round trip is longer than the
/// coherence length (then orders only interfere with paths of the same traversal counts,
/// which the incoherent tail would miss only at the first orders, where mode conversions
/// still carry weight).
fn coherent_order(optics: &SlabOptics, lambda: f64, sigma: f64) -> usize {
    let cap = if sigma * optics.thickness_nm * round_trip(optics) > PAIR_CUTOFF {
        THICK_ORDER
    } else {
        MAX_ORDER
    };
    amplitude_order(optics, lambda, MAX_ORDER).min(cap)
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
