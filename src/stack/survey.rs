//! What a stack at one incidence looks like across the visible band before its method is chosen,
//! as the plate's survey ([`crate::spectral::survey`]) reads a plate: the exact blocks at the
//! Chebyshev–Lobatto nodes of as many levels as their own variation needs (read off the decay of
//! their Chebyshev coefficients, to [`TOLERANCE`] of the largest value), the layers' group paths
//! across the band from the same nodes, the interfaces' reflectances, and whether a wave turns
//! evanescent inside the band in some layer (a branch point no interpolant of the nodes
//! follows: the same criterion as the plate's, [`crate::spectral::amplitudes::least_attenuation`]).
//! [`crate::spectral::route::rule`] decides from it; the stack's method then starts from the
//! solved nodes.

use crate::colour::weights::{gaussians, WeightSet};
use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::quadrature::fringe;
use crate::quadrature::nodes::{self, series_tail, FINEST, SPAN};
use crate::stack::exact::StackBlocks;
use crate::stack::plan::{reflectances, LayerPaths};
use crate::stack::Stack;
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;

/// Largest interpolation error of the blocks between the nodes, relative to the largest value:
/// the blocks enter the light linearly or quadratically (amplitudes of at most 1), so 1e-7 is a
/// hundred times below the rules' tolerance of 1e-5 (the phases, which need far more digits,
/// are computed exactly at every point).
pub const TOLERANCE: f64 = 1e-7;

/// The level a dispersive stack starts on (5 nodes, as the plate's survey).
const FIRST_DISPERSIVE_LEVEL: usize = 2;

/// A stack at one incidence, surveyed across the band.
pub struct StackSurvey<'a> {
    /// The stack.
    pub stack: &'a Stack,
    /// Its plane of incidence.
    pub frame: PlaneFrame,
    /// The incidence parameter.
    pub beta: C64,
    /// The level of the nodes (index into [`LEVELS`]).
    pub level: usize,
    /// The exact blocks at the level's nodes, in its order.
    pub nodes: Vec<StackBlocks>,
    /// Per layer and per `t` of [`SPAN`], `d · d(k Re Q)/dk` of the four traversals
    /// `[o↓, e↓, o↑, e↑]` (nm): their group paths across the band.
    pub group_paths: Vec<[[f64; 4]; SPAN.len()]>,
    /// Each interface's largest flux reflectance at the band's centre.
    pub reflectance: Vec<f64>,
    /// True if the nodes' interpolant follows the blocks across the band: no wave turns
    /// evanescent inside it and the finest level meets [`TOLERANCE`].
    pub interpolable: bool,
}

impl<'a> StackSurvey<'a> {
    /// Solves `stack` at the nodes for incidence `beta` in the plane of `frame`.
    pub fn new(stack: &'a Stack, frame: PlaneFrame, beta: C64) -> Result<Self> {
        let (k0, a) = fringe::band();
        let solve = |t: f64| StackBlocks::new(stack, TAU / (k0 + a * t), &frame, beta);
        let mut level = if stack.is_dispersive() {
            FIRST_DISPERSIVE_LEVEL
        } else {
            0
        };
        // The blocks at the finest level's nodes, solved as the levels need them.
        let mut solved: Vec<Option<StackBlocks>> = vec![None; nodes::MAX_NODES];
        let converged = loop {
            let lv = nodes::level(level);
            for (&j, &t) in lv.in_finest.iter().zip(&lv.nodes) {
                if solved[j].is_none() {
                    solved[j] = Some(solve(t)?);
                }
            }
            if level == 0 {
                break true;
            }
            let values: Vec<Vec<C64>> = lv
                .in_finest
                .iter()
                .map(|&j| solved[j].as_ref().expect("solved").values())
                .collect();
            if tail(&values, level) <= TOLERANCE {
                break true;
            }
            if level == FINEST {
                break false;
            }
            level += 1;
        };
        let lv = nodes::level(level);
        let nodes: Vec<StackBlocks> = lv
            .in_finest
            .iter()
            .map(|&j| solved[j].take().expect("solved"))
            .collect();
        let evanescent = turns_evanescent(&nodes, level);
        Ok(StackSurvey {
            stack,
            frame,
            beta,
            level,
            group_paths: group_paths(stack, &nodes, level),
            reflectance: reflectances(stack, TAU / k0, &frame, beta)?,
            interpolable: converged && !evanescent,
            nodes,
        })
    }
}

/// The largest estimated interpolation error of the values on `level`'s nodes (the geometric
/// tail of their Chebyshev coefficients, [`series_tail`]), relative to the largest value.
fn tail(values: &[Vec<C64>], level: usize) -> f64 {
    let lv = nodes::level(level);
    let n = lv.nodes.len();
    let largest = values
        .iter()
        .flatten()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
        .max(1e-300);
    let mut magnitudes = vec![0.0; n];
    (0..values[0].len())
        .map(|e| {
            for (mag, row) in magnitudes.iter_mut().zip(&lv.dct) {
                let c: C64 = row.iter().zip(values).map(|(w, v)| v[e] * *w).sum();
                *mag = c.norm();
            }
            series_tail(&magnitudes) / largest
        })
        .fold(0.0, f64::max)
}

/// True if some layer's wave turns evanescent inside the band: a clear layer's `q` leaves the
/// real axis, a weakly absorbing layer's decay overtakes its oscillation (`|Im q| > |Re q|`),
/// between the band's centre and either end (the ends are nodes of every level from 3 nodes on;
/// without dispersion nothing changes across the band).
fn turns_evanescent(nodes: &[StackBlocks], level: usize) -> bool {
    if level == 0 {
        return false;
    }
    let flags = |b: &StackBlocks| -> Vec<[(bool, bool); 4]> {
        b.q.iter()
            .map(|q| q.map(|x| (x.im != 0.0, x.im.abs() > x.re.abs())))
            .collect()
    };
    let centre = flags(&nodes[nodes.len() / 2]);
    [&nodes[0], &nodes[nodes.len() - 1]]
        .iter()
        .any(|b| flags(b) != centre)
}

/// `d · d(k Re Q)/dk` per layer, traversal and `t` of [`SPAN`] (`Q = (−q↓, −q↓, q↑, q↑)`), the
/// derivative of the interpolant of `k Q(k)` through the nodes (`Q` itself without dispersion).
fn group_paths(stack: &Stack, nodes: &[StackBlocks], level: usize) -> Vec<[[f64; 4]; SPAN.len()]> {
    let (k0, a) = fringe::band();
    let lv = nodes::level(level);
    let sign = [-1.0, -1.0, 1.0, 1.0];
    (0..stack.layers.len())
        .map(|j| {
            let d = stack.layers[j].thickness_nm;
            if level == 0 {
                let q = nodes[0].q[j];
                return [std::array::from_fn(|m| d * sign[m] * q[m].re); SPAN.len()];
            }
            std::array::from_fn(|s| {
                std::array::from_fn(|m| {
                    let slope: f64 = nodes
                        .iter()
                        .zip(&lv.nodes)
                        .zip(&lv.span_slopes[s])
                        .map(|((b, t), w)| sign[m] * b.q[j][m].re * (k0 + a * t) / a * w)
                        .sum();
                    d * slope
                })
            })
        })
        .collect()
}

impl StackSurvey<'_> {
    /// Each layer's group paths ([`LayerPaths`]: the largest split and traversal, the shortest
    /// round trip) over the band where the weights of `set` have their bulk (up to `μ + 3σ` of
    /// the bluest Gaussian, as the plate's route: the SPAN points below it and, linearly, at it).
    pub fn layer_paths(&self, set: WeightSet) -> Vec<LayerPaths> {
        let (k0, a) = fringe::band();
        let bulk = (0..3)
            .flat_map(|c| gaussians(set, c).iter())
            .map(|g| g.mu + 3.0 * g.sigma)
            .fold(0.0, f64::max);
        let t_bulk = ((bulk - k0) / a).min(1.0);
        self.group_paths
            .iter()
            .map(|g| {
                let mut out = LayerPaths {
                    round_trip: f64::INFINITY,
                    ..Default::default()
                };
                let mut add = |g: &[f64; 4]| {
                    out.split = out.split.max((g[0] - g[1]).abs().max((g[2] - g[3]).abs()));
                    out.path = out.path.max(g.iter().fold(0.0f64, |m, x| m.max(x.abs())));
                    let trip = (0..2)
                        .flat_map(|d| (2..4).map(move |u| (d, u)))
                        .map(|(d, u)| g[d] + g[u])
                        .fold(f64::INFINITY, f64::min);
                    out.round_trip = out.round_trip.min(trip);
                };
                for (i, &t) in SPAN.iter().enumerate() {
                    if t <= t_bulk {
                        add(&g[i]);
                    } else if i > 0 {
                        let f = (t_bulk - SPAN[i - 1]) / (t - SPAN[i - 1]);
                        add(&std::array::from_fn(|m| {
                            g[i - 1][m] + f * (g[i][m] - g[i - 1][m])
                        }));
                        break;
                    }
                }
                out
            })
            .collect()
    }
}
