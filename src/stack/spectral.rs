//! A stack integrated over colour channels and narrow bands (docs/physics.md §8).
//!
//! **Channels** (a weight set's three Gaussian fits): the model of [`crate::stack::coherence`]
//! under the set's [`StackPlan`] (thick layers' round trips incoherent) evaluated at the Chebyshev
//! points of the shared product-integration rule [`chebyshev::rule`], whose point count
//! [`chebyshev::points`] takes from the plan's frequencies: every oscillation of amplitude `a` is
//! integrated to `a · error ≤ 1e-5` of the light ([`chebyshev::TOLERANCE`]), at most 1024 points
//! (a stack that needs more, rare once invisible cross terms are dropped, takes 1024). Each
//! point serves all three channels. A dispersive stack's interface blocks are interpolated
//! across the rule's support ([`Interpolant`]), its phases computed exactly at every point.
//!
//! **A narrow band** (one Gaussian `N(μ, σ)`, the plugins' `filter_bandwidth`): the same
//! model under the band's plan, by composite 8-point Gauss–Legendre panels over `μ ± 6.5σ` with
//! at most half a period of the fastest significant oscillation per panel (`a_n ≥ 1e-5`,
//! [`chebyshev::points`]'s amplitudes), at least 16 panels.
//!
//! **Exact** ([`Accuracy::Exact`]): every layer coherent (the exact stack) at the Chebyshev
//! points; refused (naming `spectrum.method`) if more than 1024 are needed.
//!
//! The budget, measured against dense quadrature of the exact stack with the tabulated 1-nm
//! weights on random stacks (`tests/stack_spectral.rs`; the benchmark's validation run takes more
//! stacks): mean CIEDE2000 ≤ 0.1, worst ≤ 0.5, as for one plate.

use crate::band::Gaussian;
use crate::colour::weights::WeightSet;
use crate::error::{Error, Result};
use crate::optics::frame::PlaneFrame;
use crate::plate::slab::{Output, SlabMueller, Want};
use crate::quadrature::chebyshev::{self, TOLERANCE};
use crate::quadrature::hermite;
use crate::quadrature::interpolate::{self, Interpolant};
use crate::quadrature::Accuracy;
use crate::spectral::model::ThinModel;
use crate::spectral::route::{self, Route};
use crate::stack::coherence::{self, Coherence, Prepared};
use crate::stack::exact::{layer_q_into, StackBlocks};
use crate::stack::plan::{layer_paths, reflectances, LayerPaths, StackPlan, Weight};
use crate::stack::survey::StackSurvey;
use crate::stack::Stack;
use nalgebra::Matrix4;
use num_complex::Complex64 as C64;
use std::cell::OnceCell;
use std::f64::consts::TAU;

/// Largest accepted error of the interpolated interface blocks at the check points
/// ([`Interpolant`]), relative to the largest value: the blocks enter the light linearly or
/// quadratically (amplitudes of at most 1), so an error of 1e-7 is a hundred times below the
/// rules' tolerance of 1e-5 (the phases, which need far more digits, are computed exactly).
pub const INTERPOLATION_TOLERANCE: f64 = 1e-7;
/// Trailing Chebyshev coefficients of the blocks are dropped while their sum stays below this,
/// relative to the largest value.
const INTERPOLATION_TRUNCATION: f64 = 1e-8;

/// Most panels of a narrow band's rule (8 points each).
pub const MAX_PANELS: usize = 512;

/// A stack at one incidence, evaluated at a wavelength, over a band or over channels.
pub struct StackModel<'a> {
    stack: &'a Stack,
    frame: PlaneFrame,
    beta: C64,
    /// Without dispersion the interfaces do not depend on the wavelength: solved once.
    fixed: OnceCell<StackBlocks>,
}

impl<'a> StackModel<'a> {
    /// The model of `stack` for incidence parameter `beta` in the plane of `frame`.
    pub fn new(stack: &'a Stack, frame: PlaneFrame, beta: C64) -> Self {
        StackModel {
            stack,
            frame,
            beta,
            fixed: OnceCell::new(),
        }
    }

    /// The exact blocks at wavenumber `k`.
    fn solve(&self, k: f64) -> Result<StackBlocks> {
        StackBlocks::new(self.stack, TAU / k, &self.frame, self.beta)
    }

    /// The blocks at `lambda_nm`: solved once without dispersion.
    fn blocks(&self, lambda_nm: f64) -> Result<StackBlocks> {
        if self.stack.is_dispersive() {
            return self.solve(TAU / lambda_nm);
        }
        if let Some(b) = self.fixed.get() {
            return Ok(b.clone());
        }
        let b = self.solve(TAU / lambda_nm)?;
        Ok(self.fixed.get_or_init(|| b).clone())
    }

    /// The layers' group paths at wavenumbers `ks` and the interfaces' reflectances at the
    /// first of them: what [`StackPlan`]s are made of.
    pub fn paths(&self, ks: &[f64]) -> Result<(Vec<LayerPaths>, Vec<f64>)> {
        Ok((
            layer_paths(self.stack, &self.frame, self.beta, ks)?,
            reflectances(self.stack, TAU / ks[0], &self.frame, self.beta)?,
        ))
    }

    /// The plan for `weight`, the group paths taken at wavenumbers `ks`.
    pub fn plan(&self, ks: &[f64], weight: &Weight, exact: bool) -> Result<StackPlan> {
        let (paths, r) = self.paths(ks)?;
        Ok(StackPlan::new(&paths, &r, weight, exact))
    }

    /// Over the unit-mass Gaussian `g` times its amplitude (module docs): the partially
    /// coherent model at [`Accuracy::Perceptual`], the exact stack at [`Accuracy::Exact`].
    fn gaussian(
        &self,
        g: &Gaussian,
        want: Want,
        output: Output,
        accuracy: Accuracy,
    ) -> Result<SlabMueller> {
        let plan = self.plan(
            &[g.mu, g.mu + 3.0 * g.sigma],
            &Weight::of_band(g.sigma),
            accuracy == Accuracy::Exact,
        )?;
        let omega = fastest(&plan);
        let panels =
            ((13.0 * g.sigma * omega / std::f64::consts::PI).ceil() as usize).clamp(16, MAX_PANELS);
        let nodes: Vec<(f64, [f64; 3])> = hermite::composite_normal(panels)
            .into_iter()
            .map(|(x, w)| (g.mu + g.sigma * x, [g.amplitude * w, 0.0, 0.0]))
            .collect();
        let (lo, hi) = (g.mu - 6.5 * g.sigma, g.mu + 6.5 * g.sigma);
        let [m, _, _] = self.quadrature(&nodes, (lo, hi), &plan.coherence, want, output)?;
        Ok(m)
    }

    /// `Σ_j w_cj M(k_j)` over `nodes` `(k_j, [w_cj])` inside `support`, of the model under
    /// `coherence` (blocks fixed, interpolated across `support`, or exact at each node).
    fn quadrature(
        &self,
        nodes: &[(f64, [f64; 3])],
        support: (f64, f64),
        coherence: &Coherence,
        want: Want,
        output: Output,
    ) -> Result<[SlabMueller; 3]> {
        let centre = 0.5 * (support.0 + support.1);
        let mut acc = [[Matrix4::zeros(); 2]; 3];
        let mut add = |m: &SlabMueller, w: &[f64; 3]| {
            let lobes = [m.r, m.t];
            for (sums, wc) in acc.iter_mut().zip(w) {
                for (sum, lobe) in sums.iter_mut().zip(&lobes) {
                    match (lobe, output) {
                        (Some(x), Output::Mueller) => *sum += x * *wc,
                        (Some(x), Output::Intensity) => sum[(0, 0)] += x[(0, 0)] * wc,
                        (None, _) => {}
                    }
                }
            }
        };
        if !self.stack.is_dispersive() {
            let blocks = self.blocks(TAU / centre)?;
            let prepared = Prepared::new(&blocks, coherence);
            for (k, w) in nodes {
                add(
                    &coherence::mueller(&blocks, coherence, &prepared, TAU / k, want)?,
                    w,
                );
            }
        } else {
            let values = |k: f64| self.solve(k).map(|b| b.values());
            // Interpolating pays when there are more nodes than the interpolant solves.
            let interpolant = if nodes.len() > 2 * interpolate::NODES {
                Interpolant::new(
                    support,
                    (INTERPOLATION_TOLERANCE, INTERPOLATION_TRUNCATION),
                    &values,
                )?
            } else {
                None
            };
            let prepared = Prepared::structure(coherence);
            let mut blocks = self.solve(centre)?;
            let mut v = blocks.values();
            for (k, w) in nodes {
                match &interpolant {
                    Some(f) => {
                        f.at_into(*k, &mut v);
                        blocks.set_values(&v);
                        layer_q_into(self.stack, TAU / k, &self.frame, self.beta, &mut blocks.q)?;
                    }
                    None => blocks = self.solve(*k)?,
                }
                add(
                    &coherence::mueller(&blocks, coherence, &prepared, TAU / k, want)?,
                    w,
                );
            }
        }
        Ok(acc.map(|[r, t]| SlabMueller {
            r: want.reflection.then_some(r),
            t: want.transmission.then_some(t),
        }))
    }
}

impl ThinModel for StackModel<'_> {
    /// Exactly at `lambda_nm` (s/p frames, power fractions).
    fn at(&self, lambda_nm: f64, want: Want, output: Output) -> Result<SlabMueller> {
        let m = match self.fixed.get() {
            Some(b) if !self.stack.is_dispersive() => b.mueller(lambda_nm, want)?,
            _ => self.blocks(lambda_nm)?.mueller(lambda_nm, want)?,
        };
        Ok(output.keep(m))
    }

    /// Gaussian by Gaussian (module docs).
    fn band(
        &self,
        band: &[Gaussian],
        want: Want,
        output: Output,
        accuracy: Accuracy,
    ) -> Result<SlabMueller> {
        let (mut r, mut t) = (Matrix4::zeros(), Matrix4::zeros());
        for g in band {
            let m = self.gaussian(g, want, output, accuracy)?;
            r += m.r.unwrap_or_default();
            t += m.t.unwrap_or_default();
        }
        Ok(SlabMueller {
            r: want.reflection.then_some(r),
            t: want.transmission.then_some(t),
        })
    }

    /// Over the three channels of `set`: the partially coherent model at
    /// [`Accuracy::Perceptual`], the exact stack at [`Accuracy::Exact`] (module docs).
    fn channels(
        &self,
        set: WeightSet,
        want: Want,
        output: Output,
        accuracy: Accuracy,
    ) -> Result<[SlabMueller; 3]> {
        let exact = accuracy == Accuracy::Exact;
        let survey = StackSurvey::new(self.stack, self.frame, self.beta)?;
        let weight = Weight::of_set(set);
        let paths = survey.layer_paths(set);
        let r = &survey.reflectance;
        let mut plan = StackPlan::new(&paths, r, &weight, exact);
        let points = |p: &StackPlan| chebyshev::points(set, p.omega_1, p.omega_b, p.rho, 1.0);
        // Too many coherent orders for any rule: the longest round trips become incoherent.
        while points(&plan).is_none() && !exact {
            match plan.thicken(&paths, r, &weight) {
                Some(p) => plan = p,
                None => break,
            }
        }
        let (points, interpolated) =
            match route::rule(survey.interpolable, points(&plan), accuracy)? {
                Route::Dense(p) => (p, true),
                Route::Pointwise(p) => (p, false),
                other => unreachable!("a stack's rule route: {other:?}"),
            };
        let rule = chebyshev::rule(set, points);
        let prepared = Prepared::structure(&plan.coherence);
        let mut acc = [[Matrix4::zeros(); 2]; 3];
        let n = survey.nodes.len();
        let values: Vec<Vec<C64>> = survey.nodes.iter().map(|b| b.values()).collect();
        let basis = chebyshev::node_basis(set, points, survey.level);
        let mut blocks = survey.nodes[n / 2].clone();
        let mut v = blocks.values();
        let fixed = if n == 1 {
            Prepared::new(&blocks, &plan.coherence)
        } else {
            Prepared::structure(&plan.coherence)
        };
        for (j, (k, w)) in rule.nodes.iter().enumerate() {
            let m = if n == 1 {
                // Without dispersion the blocks, and the layers' q, are the same everywhere.
                coherence::mueller(&blocks, &plan.coherence, &fixed, TAU / k, want)?
            } else {
                if interpolated {
                    v.iter_mut().for_each(|x| *x = C64::new(0.0, 0.0));
                    for (node, &bi) in values.iter().zip(&basis[j * n..(j + 1) * n]) {
                        for (x, y) in v.iter_mut().zip(node) {
                            *x += y * bi;
                        }
                    }
                    blocks.set_values(&v);
                    layer_q_into(self.stack, TAU / k, &self.frame, self.beta, &mut blocks.q)?;
                } else {
                    blocks = self.solve(*k)?;
                }
                coherence::mueller(&blocks, &plan.coherence, &prepared, TAU / k, want)?
            };
            add_weighted(&mut acc, &m, w, output);
        }
        Ok(acc.map(|[r, t]| SlabMueller {
            r: want.reflection.then_some(r),
            t: want.transmission.then_some(t),
        }))
    }
}

/// `acc[c][lobe] += w_c M_lobe` over the entries the output needs.
fn add_weighted(acc: &mut [[Matrix4<f64>; 2]; 3], m: &SlabMueller, w: &[f64; 3], output: Output) {
    let lobes = [m.r, m.t];
    for (sums, wc) in acc.iter_mut().zip(w) {
        for (sum, lobe) in sums.iter_mut().zip(&lobes) {
            match (lobe, output) {
                (Some(x), Output::Mueller) => *sum += x * *wc,
                (Some(x), Output::Intensity) => sum[(0, 0)] += x[(0, 0)] * wc,
                (None, _) => {}
            }
        }
    }
}

/// Most stack evaluations of one [`quadrature`].
pub const QUADRATURE_MAX: usize = 10_000_000;

/// Dense trapezoid quadrature of the exact stack `∫ weight(λ) M(λ) dλ` over `[lo, hi]` nm with
/// a step of at most `step_nm` (the calculator's reference, `"method": "quadrature"`).
#[allow(clippy::too_many_arguments)]
pub fn quadrature(
    stack: &Stack,
    frame: &PlaneFrame,
    beta: C64,
    weight: impl Fn(f64) -> f64,
    (lo, hi): (f64, f64),
    step_nm: f64,
    want: Want,
) -> Result<SlabMueller> {
    let count = ((hi - lo) / step_nm).ceil().max(1.0);
    if step_nm.is_nan() || step_nm <= 0.0 || count.is_nan() || count > QUADRATURE_MAX as f64 {
        return Err(Error::new(
            "step_nm",
            format!(
                "too small: {count:.3e} stack evaluations over [{lo}, {hi}] nm (at most \
                 {QUADRATURE_MAX:.0e}; minutes of run time)"
            ),
        ));
    }
    let n = count as usize;
    let h = (hi - lo) / n as f64;
    let model = StackModel::new(stack, *frame, beta);
    let (mut r, mut t) = (Matrix4::zeros(), Matrix4::zeros());
    for j in 0..=n {
        let lambda = lo + h * j as f64;
        let w = weight(lambda) * if j == 0 || j == n { 0.5 * h } else { h };
        if w == 0.0 {
            continue;
        }
        let m = model.at(lambda, want, Output::Mueller)?;
        r += m.r.unwrap_or_default() * w;
        t += m.t.unwrap_or_default() * w;
    }
    Ok(SlabMueller {
        r: want.reflection.then_some(r),
        t: want.transmission.then_some(t),
    })
}

/// The fastest oscillation (nm) of the plan whose amplitude `ρⁿ / (1 − ρ)²` after `n` round
/// trips is at least [`TOLERANCE`] (the direct light's `ω_b` always; at most 64 round trips).
pub fn fastest(plan: &StackPlan) -> f64 {
    let mut omega = plan.omega_b;
    if !(0.0..1.0).contains(&plan.rho) {
        return omega + 64.0 * plan.omega_1;
    }
    let mut a = 1.0 / ((1.0 - plan.rho) * (1.0 - plan.rho));
    for n in 1..=64 {
        a *= plan.rho;
        if a < TOLERANCE {
            break;
        }
        omega = plan.omega_b + n as f64 * plan.omega_1;
    }
    omega
}
