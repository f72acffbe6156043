//! Which method integrates a plate over a weight set's channels: decided once, here, from the
//! survey's invariants ([`Survey`]), before any method starts.

use crate::colour::weights::WeightSet;
use crate::error::Result;
use crate::plate::paths::Lobe;
use crate::quadrature::chebyshev::LADDER;
use crate::quadrature::fringe;
use crate::quadrature::nodes::LEVELS;
use crate::spectral::classes;
use crate::spectral::envelope;
use crate::spectral::layout;
use crate::spectral::pointwise;
use crate::spectral::survey::Survey;

/// The method that serves a plate at one incidence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Route {
    /// A wave turns evanescent inside the band (its phase has a branch point there): the exact
    /// plate, solved at every point of a shared product-integration rule of this many points
    /// ([`crate::quadrature::chebyshev`]).
    Evanescent(usize),
    /// The exact plate on a shared rule of this many points, its blocks interpolated from the
    /// amplitude nodes ([`crate::spectral::dense`]).
    Dense(usize),
    /// Every order in closed form ([`crate::spectral::envelope`]).
    Envelope(envelope::Envelope),
    /// Pairs of path classes ([`crate::spectral::classes`]).
    Classes(classes::Orders),
}

/// The route of `survey` over `set` (module docs): the cheapest of the methods that serve the
/// plate, by the estimated instruction counts below.
///
/// * A wave turning evanescent inside the band has a branch point no interpolant follows: the
///   exact plate on the shared rule ([`Route::Evanescent`]).
/// * Every order in closed form ([`Route::Envelope`]) where its families' slow factors are
///   resolved on at most 33 nodes: thin plates, weak birefringence, and near grazing incidence
///   wherever the modes' splits stay small.
/// * Pairs of path classes ([`Route::Classes`]) where the round trips are invisible (thick
///   plates, their orders mutually incoherent: each o/e fringe exactly, however fast), or where
///   few orders interfere ([`CROSS_ORDERS`]) and their fringes' chirp stays within the finest
///   node level.
/// * The exact plate on a shared rule of at most 1024 points where neither serves (thin plates
///   of strongly dispersive, strongly birefringent crystals with many interfering orders: thin
///   rutile).
pub fn choose(survey: &Survey, set: WeightSet) -> Result<Route> {
    let points = || -> Result<usize> {
        Ok(
            pointwise::exact_points(survey.plate, &survey.frame, survey.beta, set)?
                .unwrap_or(LADDER[LADDER.len() - 1]),
        )
    };
    if survey.loss.is_none() {
        return Ok(Route::Evanescent(points()?));
    }
    let envelope = envelope::plan(survey, set);
    // The whole plate at the amplitude nodes costs no more than any other method.
    if let Some(e) = envelope.filter(|e| e.families.is_none() && e.level == survey.amplitudes.level)
    {
        return Ok(Route::Envelope(e));
    }
    let classes = classes::plan(survey, set).filter(|c| classes_serve(survey, c));
    Ok(match (envelope, classes) {
        (Some(e), Some(c)) => {
            if envelope_cost(survey, &e) <= classes_cost(survey, &c) {
                Route::Envelope(e)
            } else {
                Route::Classes(c)
            }
        }
        (Some(e), None) => Route::Envelope(e),
        (None, Some(c)) => Route::Classes(c),
        (None, None) => Route::Dense(points()?),
    })
}

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

/// Instructions per node of the envelope: the exact plate, or its families' resolvent.
const COST_NODE: f64 = 1500.0;
const COST_FAMILY_NODE: f64 = 4000.0;
/// Instructions per phase node of a dispersive plate off the amplitude nodes (its indices and
/// normal components).
const COST_PHASE: f64 = 1000.0;
/// Instructions per amplitude node and `(N + 1)²` of the path classes (their expansion), and
/// per amplitude node and pair of classes that a query may visit.
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
    let pairs: usize = [Lobe::Reflection, Lobe::Transmission]
        .iter()
        .map(|&l| {
            let layout = layout::layout(l, p.order, false);
            layout
                .blocks
                .iter()
                .filter(|b| p.cross_orders || b.orders.0 == b.orders.1)
                .map(|b| b.pairs.end - b.pairs.start)
                .sum::<usize>()
        })
        .sum();
    LEVELS[s.amplitudes.level] as f64
        * (orders * orders * COST_CLASS_NODE + pairs as f64 * COST_PAIR)
}
