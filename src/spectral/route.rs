//! Every decision of how a plate is integrated over a spectrum, made once, here, from what the
//! plate is (its model: [`model`]) and from its surveys alone ([`Survey`] across the visible
//! band, [`BandSurvey`] around one Gaussian of a band), with one cost model ([`Cost`]), before
//! any method starts. Nothing is solved again to decide, and no method falls back to another.
//!
//! * [`model`]: a lossless isotropic plate without dispersion is two Airy etalons, the others
//!   the general plate;
//! * [`channels`]: the method that integrates the general plate over a weight set's channels
//!   ([`Route`]), to [`Accuracy::Perceptual`] or [`Accuracy::Exact`];
//! * [`etalon_serves`] and [`gaussian`]: the method of one Gaussian of a band (or of a
//!   channel's fit, where the exact rule does not serve the channels at once).

use crate::band::Gaussian;
use crate::colour::weights::{gaussians, WeightSet};
use crate::error::{Error, Result};
use crate::plate::etalon::Etalon;
use crate::plate::paths::Lobe;
use crate::plate::Plate;
use crate::quadrature::chebyshev::{self, LADDER};
use crate::quadrature::fringe;
use crate::quadrature::hermite;
use crate::quadrature::nodes::{LEVELS, SPAN};
use crate::quadrature::Accuracy;
use crate::spectral::classes;
use crate::spectral::envelope;
use crate::spectral::gaussian::{coherent_order, Method, MAX_ORDER, PAIR_CUTOFF};
use crate::spectral::survey::{BandSurvey, Survey};
use num_complex::Complex64 as C64;

/// The model of a plate at incidence parameter `beta`: two Airy etalons where
/// [`Plate::etalon`] applies (a lossless isotropic layer without dispersion: exact in closed form
/// at one wavelength and over every Gaussian), `None` for the general plate. Decided from the
/// plate's properties alone (the etalon's indices do not depend on the wavelength: any one
/// selects where they are evaluated).
pub fn model(plate: &Plate, beta: C64) -> Option<Etalon> {
    plate.etalon(550.0, beta)
}

/// The method that integrates the general plate over a weight set's channels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Route {
    /// The exact plate solved at every point of the weight set's Chebyshev rule of this many
    /// points ([`crate::spectral::pointwise`], blocks interpolated only where a checked
    /// interpolant reproduces them to 1e-10): where a wave turns evanescent inside the band (a
    /// branch point no interpolant of the survey follows), and the exact accuracy's rule.
    Pointwise(usize),
    /// The exact plate on a Chebyshev rule of this many points, its blocks interpolated from the
    /// amplitude nodes ([`crate::spectral::dense`]).
    Dense(usize),
    /// Every order in closed form ([`crate::spectral::envelope`]).
    Envelope(envelope::Envelope),
    /// Pairs of path classes ([`crate::spectral::classes`]).
    Classes(classes::Orders),
    /// Each Gaussian of each channel on its own route ([`gaussian`]): the exact accuracy where
    /// no rule of [`LADDER`] resolves the plate's spectrum.
    Gaussians,
}

/// The route of `survey` over `set` to `accuracy`: the cheapest of the methods that serve the
/// plate, by the cost model below.
///
/// * [`Accuracy::Exact`]: the exact plate on the smallest Chebyshev rule that integrates every
///   oscillation of the survey's frequencies to [`chebyshev::TOLERANCE`] ([`rule_points`]), or
///   Gaussian by Gaussian where none of [`LADDER`] does.
/// * A wave turning evanescent inside the band has a branch point no interpolant follows: the
///   exact plate at every point of the rule ([`Route::Pointwise`]).
/// * Every order in closed form ([`Route::Envelope`]) where its families' slow factors are
///   resolved on at most 33 nodes: thin plates, weak birefringence, and near grazing incidence
///   wherever the modes' splits stay small.
/// * Pairs of path classes ([`Route::Classes`]) where the round trips are invisible (thick
///   plates, their orders mutually incoherent: each o/e fringe exactly, however fast), or where
///   few orders interfere ([`CROSS_ORDERS`]) and their fringes' chirp stays within the finest
///   node level.
/// * The exact plate on a rule of at most 1024 points where neither serves (thin plates of
///   strongly dispersive, strongly birefringent crystals with many interfering orders: thin
///   rutile).
pub fn channels(survey: &Survey, set: WeightSet, accuracy: Accuracy) -> Route {
    let most = LADDER[LADDER.len() - 1];
    if accuracy == Accuracy::Exact {
        return rule_points(survey, set).map_or(Route::Gaussians, Route::Pointwise);
    }
    if survey.loss.is_none() {
        return Route::Pointwise(rule_points(survey, set).unwrap_or(most));
    }
    let envelope = envelope::plan(survey, set);
    // The whole plate at the amplitude nodes costs no more than any other method.
    if let Some(e) = envelope.filter(|e| e.families.is_none() && e.level == survey.amplitudes.level)
    {
        return Route::Envelope(e);
    }
    let classes = classes::plan(survey, set).filter(|c| classes_serve(survey, c));
    match (envelope, classes) {
        (Some(e), Some(c)) => {
            if envelope_cost(survey, &e) <= classes_cost(survey, &c) {
                Route::Envelope(e)
            } else {
                Route::Classes(c)
            }
        }
        (Some(e), None) => Route::Envelope(e),
        (None, Some(c)) => Route::Classes(c),
        (None, None) => Route::Dense(rule_points(survey, set).unwrap_or(most)),
    }
}

/// The points of the smallest Chebyshev rule of `set` that integrates the plate's spectrum to
/// [`chebyshev::TOLERANCE`] ([`chebyshev::points`]), from the survey's frequencies: the largest
/// group path of a round trip (`ω₁`) and of the two modes' split (`ω_b`) over the band where the
/// weights have their bulk (up to `μ + 3σ` of the bluest Gaussian: beyond, that Gaussian is
/// below 1.1 % of its peak, and the dispersion fits of some crystals, extrapolated below their
/// data, grow without physical meaning towards the band's end), and the survey's bound `ρ` on a
/// round trip. `None` if no rule of [`LADDER`] does.
pub fn rule_points(s: &Survey, set: WeightSet) -> Option<usize> {
    let (k0, a) = fringe::band();
    let bulk = (0..3)
        .flat_map(|c| gaussians(set, c).iter())
        .map(|g| g.mu + 3.0 * g.sigma)
        .fold(0.0, f64::max);
    let t_bulk = ((bulk - k0) / a).min(1.0);
    // The group paths at the SPAN points below t_bulk and, linearly, at t_bulk.
    let mut rates = (0.0f64, 0.0f64);
    let mut add = |g: &[f64; 4]| {
        let trip = g[0].max(g[1]) + g[2].max(g[3]);
        let split = (g[1] - g[0]).abs().max((g[3] - g[2]).abs());
        rates = (rates.0.max(trip), rates.1.max(split));
    };
    for (i, &t) in SPAN.iter().enumerate() {
        if t <= t_bulk {
            add(&s.group_paths[i]);
        } else if i > 0 {
            let f = (t_bulk - SPAN[i - 1]) / (t - SPAN[i - 1]);
            let (lo, hi) = (&s.group_paths[i - 1], &s.group_paths[i]);
            add(&std::array::from_fn(|m| lo[m] + f * (hi[m] - lo[m])));
            break;
        }
    }
    chebyshev::points(set, rates.0, rates.1, s.rho, s.transient)
}

/// The route of a thin element that only a Chebyshev rule of its exact model serves (a stack of
/// layers, [`crate::stack::survey`]), from its survey and the points the rule needs for its
/// frequencies ([`chebyshev::points`], `None` beyond [`LADDER`]): its blocks interpolated from
/// the survey's nodes ([`Route::Dense`]) where they are `interpolable` (no wave turning
/// evanescent inside the band, the nodes converged), else solved at every point
/// ([`Route::Pointwise`]); at most [`LADDER`]'s largest rung, which [`Accuracy::Exact`] refuses.
pub fn rule(interpolable: bool, points: Option<usize>, accuracy: Accuracy) -> Result<Route> {
    let most = LADDER[LADDER.len() - 1];
    let points = match (points, accuracy) {
        (Some(p), _) => p,
        (None, Accuracy::Perceptual) => most,
        (None, Accuracy::Exact) => {
            return Err(Error::new(
                "spectrum.method",
                format!(
                    "the exact stack oscillates too fast across the visible for the exact rule \
                     (more than {most} points); use \"analytic\" or \"quadrature\""
                ),
            ))
        }
    };
    Ok(if interpolable {
        Route::Dense(points)
    } else {
        Route::Pointwise(points)
    })
}

/// True if the etalon's closed form serves the Gaussian `g` (its series is not too long:
/// [`Etalon::band_terms`]); else the Gaussian takes the general plate's route.
pub fn etalon_serves(etalon: &Etalon, g: &Gaussian) -> bool {
    etalon.band_terms(g).is_some()
}

/// The method of the Gaussian of `s`: the cheapest of those that serve it.
///
/// * the narrow-band closed form, where the survey found it serves;
/// * Gauss–Hermite quadrature of the exact plate where the integrand oscillates by at most
///   [`HERMITE_LIMIT`] radians over the band (with `a = σ D` per round trip and `N` the round
///   trips whose amplitude exceeds the survey's tolerance, `a (N + 1)`): `8 + 3x + x²` nodes
///   integrate `exp(i x X)` to ~1e-6 up to `x = 10` (128 nodes). The group path (not the phase
///   path) sets how fast it oscillates: strongly dispersive media (rutile's group index reaches
///   ~9 near 360 nm) oscillate much faster than their phase index suggests;
/// * the path classes' closed form where the orders are mutually incoherent (a round trip
///   beyond the coherence length) or at most [`MAX_ORDER`] of them interfere (validated against
///   dense quadrature in `tests/spectral_band.rs`);
/// * composite Gauss–Legendre panels of the exact plate (about 2 per oscillation of the highest
///   significant order over ±6.5σ, at most [`MAX_PANELS`]): always.
pub fn gaussian(s: &BandSurvey) -> Method {
    let g = &s.g;
    let d = s.optics.thickness_nm;
    let (rt_min, rt_max) = s.round_trips;
    let n = s.orders;
    let x = g.sigma * d * rt_max * (n as f64 + 1.0);
    let per_node = if !s.plate.is_dispersive() {
        COST_MUELLER
    } else if s.narrow.is_some() || g.sigma <= crate::spectral::narrow::NARROW_BAND * g.mu {
        COST_PHASES
    } else {
        COST_SOLVE
    };
    let mut best = {
        let panels = ((13.0 * x / std::f64::consts::PI).ceil() as usize).clamp(16, MAX_PANELS);
        (8.0 * panels as f64 * per_node, Method::Panels(panels))
    };
    let mut consider = |cost: f64, m: Method| {
        if cost < best.0 {
            best = (cost, m);
        }
    };
    if let Some(narrow) = &s.narrow {
        consider(narrow.nodes() as f64 * COST_NARROW_NODE, Method::Narrow);
    }
    if x <= HERMITE_LIMIT {
        let nodes = ((8.0 + 3.0 * x + x * x).ceil() as usize).min(hermite::MAX_NODES);
        consider(nodes as f64 * per_node, Method::Hermite(nodes));
    }
    let thick = g.sigma * d * rt_min > PAIR_CUTOFF;
    if thick || n <= MAX_ORDER {
        // ~K² pair terms for K ≈ (N + 2)³/3 classes of both lobes.
        let k = (coherent_order(s) as f64 + 2.0).powi(3) / 3.0;
        consider(k * k * COST_BAND_PAIR, Method::Paths(None));
    }
    best.1
}

/// Largest oscillation (radians per band width) that [`gaussian`] integrates by Gauss–Hermite.
pub const HERMITE_LIMIT: f64 = 10.0;

/// Most panels [`gaussian`] spends on one Gaussian (4096 plate evaluations). Only plates near
/// grazing incidence with hundreds of strongly interfering orders ask for more; there the rule
/// under-resolves the fastest orders (whose weight is then ≲ 1e-3 of the band): the result stays
/// a convex combination of exact Mueller matrices, so energy is still conserved, and a query
/// costs at most a few milliseconds instead of seconds.
pub const MAX_PANELS: usize = 512;

/// Most coherent orders for the path classes when pairs of different orders are visible.
pub const CROSS_ORDERS: usize = 3;

/// Largest residual phase (radians) of a fringe across the band that the finest node level
/// resolves ([`crate::spectral::classes`]' `slow_factor_error` on 33 nodes is below 1e-5 up to
/// about 14).
const CHIRP: f64 = 14.0;

/// True if the path classes serve the plate: thick (no pair of different orders visible), or
/// at most [`CROSS_ORDERS`] orders whose fringes' chirp (the spread of a traversal's group path
/// across the band, over the traversals of a pair) stays within [`CHIRP`].
fn classes_serve(s: &Survey, c: &classes::Orders) -> bool {
    if !c.cross_orders {
        return true;
    }
    let (_, a) = fringe::band();
    let spread = (0..4)
        .map(|j| {
            let (lo, hi) = s.group_path_range(|g| g[j]);
            hi - lo
        })
        .fold(0.0, f64::max);
    let traversals = (2 * c.order + 4) as f64;
    c.order <= CROSS_ORDERS && traversals * spread * a / 4.0 <= CHIRP
}

// The cost model: estimated instructions per unit of work of each method (callgrind,
// `examples/hot_paths.rs`), the one scale every choice above compares on.

/// The exact plate at one wavenumber: indices, both interfaces, Jones and Mueller matrices.
const COST_SOLVE: f64 = 6000.0;
/// The Mueller matrices of a plate whose interfaces are solved (without dispersion).
const COST_MUELLER: f64 = 1000.0;
/// The same with the phases of the layer's modes at the wavenumber (indices and normal
/// components: a narrow band of a dispersive plate).
const COST_PHASES: f64 = 2500.0;
/// One complex node of the narrow-band closed form (the order series by a 4×4 solve).
const COST_NARROW_NODE: f64 = 3000.0;
/// One pair of path classes over one Gaussian (its closed-form factor, a 2×2 product).
const COST_BAND_PAIR: f64 = 150.0;
/// The whole plate at one node of the envelope, or its families' resolvent.
const COST_NODE: f64 = 1500.0;
const COST_FAMILY_NODE: f64 = 4000.0;
/// A node of a dispersive plate off the amplitude nodes (its indices and normal components).
const COST_PHASE: f64 = 1000.0;
/// Per amplitude node and `(N + 1)²` of the path classes (their expansion), and per amplitude
/// node and pair of classes that a query may visit.
const COST_CLASS_NODE: f64 = 1500.0;
const COST_PAIR: f64 = 30.0;

fn envelope_cost(s: &Survey, p: &envelope::Envelope) -> f64 {
    let n = LEVELS[p.level] as f64;
    let per = if p.families.is_some() {
        COST_FAMILY_NODE
    } else {
        COST_NODE
    };
    let phases = if s.plate.is_dispersive() {
        (n - LEVELS[s.amplitudes.level] as f64).max(0.0) * COST_PHASE
    } else {
        0.0
    };
    n * per + phases
}

fn classes_cost(s: &Survey, p: &classes::Orders) -> f64 {
    let orders = (p.order + 1) as f64;
    // The pairs of classes a query may visit (of the same order only, where different orders
    // are invisible), counted from the classes per order (no layout is built to decide).
    let pairs: usize = [Lobe::Reflection, Lobe::Transmission]
        .iter()
        .map(|&l| {
            let per_order = |o: usize| l.classes(o) - if o == 0 { 0 } else { l.classes(o - 1) };
            let all = l.classes(p.order);
            if p.cross_orders {
                all * (all + 1) / 2
            } else {
                (0..=p.order)
                    .map(|o| per_order(o) * (per_order(o) + 1) / 2)
                    .sum()
            }
        })
        .sum();
    LEVELS[s.amplitudes.level] as f64
        * (orders * orders * COST_CLASS_NODE + pairs as f64 * COST_PAIR)
}
