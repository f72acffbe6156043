//! Which method integrates a plate over a weight set's channels: decided once, here, from the
//! survey's invariants ([`Survey`]), before any method starts.

use crate::error::Result;
use crate::spectral::classes;
use crate::spectral::envelope;
use crate::spectral::nodes::LEVELS;
use crate::spectral::shared;
use crate::spectral::survey::Survey;
use crate::spectral::weights::WeightSet;

/// The method that serves a plate at one incidence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Route {
    /// A wave turns evanescent inside the band: the exact plate on a shared product-integration
    /// rule of this many points ([`crate::spectral::shared`]).
    Dense(usize),
    /// Every order in closed form ([`crate::spectral::envelope`]).
    Envelope(envelope::Plan),
    /// Pairs of path classes ([`crate::spectral::classes`]).
    Classes(classes::Plan),
}

/// The route of `survey` over `set` (module docs): the cheapest of the closed forms that serve
/// the plate, else the exact plate on a shared rule.
///
/// * A wave turning evanescent inside the band has a branch point no interpolant follows: the
///   exact plate on the shared rule ([`Route::Dense`]).
/// * Every order in closed form ([`Route::Envelope`]) where its families' slow factors are
///   resolved on at most 33 nodes: thin plates, weak birefringence, and near grazing incidence
///   wherever the modes' splits stay small.
/// * Pairs of path classes ([`Route::Classes`]) where the round trips are invisible (thick
///   plates, their orders mutually incoherent): each o/e fringe exactly, however fast.
/// * The exact plate on a shared rule where neither serves (thin plates whose modes split fast
///   and whose many orders interfere: thin rutile), at most 1024 points.
///
/// Between the two closed forms the estimated cost decides: `COST_NODE` per envelope node
/// (`COST_FAMILY_NODE` with families), `COST_CLASS_NODE (N + 1)²` per amplitude node of the
/// path classes (in instructions, measured with `examples/hot_paths.rs`).
pub fn choose(survey: &Survey, set: WeightSet) -> Result<Route> {
    let dense = || -> Result<Route> {
        let points = shared::plan(survey.plate, &survey.frame, survey.beta, set)?
            .unwrap_or(shared::LADDER[shared::LADDER.len() - 1]);
        Ok(Route::Dense(points))
    };
    if survey.loss.is_none() {
        return dense();
    }
    let envelope = envelope::plan(survey, set);
    // The whole plate at the amplitude nodes costs no more than any other method.
    if let Some(e) = envelope.filter(|e| e.families.is_none() && e.level == survey.amplitudes.level)
    {
        return Ok(Route::Envelope(e));
    }
    let classes = classes::plan(survey, set).filter(|c| !c.cross_orders);
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
        (None, None) => return dense(),
    })
}

/// Instructions per node of the envelope: the exact plate, or its families' resolvent.
const COST_NODE: f64 = 1500.0;
const COST_FAMILY_NODE: f64 = 4000.0;
/// Instructions per phase node of a dispersive plate off the amplitude nodes (its indices and
/// normal components).
const COST_PHASE: f64 = 1000.0;
/// Instructions per amplitude node and `(N + 1)²` of the path classes.
const COST_CLASS_NODE: f64 = 1500.0;

fn envelope_cost(s: &Survey, p: &envelope::Plan) -> f64 {
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

fn classes_cost(s: &Survey, p: &classes::Plan) -> f64 {
    let orders = (p.order + 1) as f64;
    LEVELS[s.amplitudes.level] as f64 * orders * orders * COST_CLASS_NODE
}
