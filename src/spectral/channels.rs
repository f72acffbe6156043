//! The plate integrated over the three channels of a weight set, path class by path class
//! (the paper's closed form, with amplitudes interpolated across the band).
//!
//! Each Jones matrix is a sum over path classes `J(k) = Σ_c A_c(k) e^{ik d Q_c(k)}`
//! ([`crate::plate::paths`]); the coherency's pairs of classes are grouped by what their
//! spectral factor depends on ([`crate::spectral::pairs`]). A group oscillates as
//! `e^{iφ_Δ(k)}` around its group path `G_Δ = φ_Δ'(k₀)` and integrates against every channel
//! by the fringe rules of [`crate::spectral::fringe`]:
//!
//! ```text
//! ∫ w_c(k) K_Δ(k) dk = e^{iφ_Δ(k₀)} Σ_i P_Δ(k_i) W_ic(G_Δ),
//! P_Δ(k) = Σ_(a,b) cross(A_a, A_b)(k) e^{−kd Im(Q_a + Q_b)} e^{i(φ_Δ(k) − φ_Δ(k₀) − G_Δ (k − k₀))}
//! ```
//! `P_Δ` is smooth (amplitudes, absorption and the residual curvature of the phase), so each
//! group takes as few nodes as its accuracy needs: its amplitudes come from the exact blocks
//! at the nodes of one level ([`crate::spectral::amplitudes`]; coarser for weaker groups),
//! interpolated to its phase nodes, where its phase and attenuation are exact. A group whose
//! residual phase no level resolves (strong dispersion in thick plates) is integrated Gaussian
//! by Gaussian of the fitted weights instead, its phase expanded to second order about each
//! Gaussian's centre (the paper's method, exact for a quadratic phase). Groups whose fringe is
//! invisible in every channel (`|G_Δ|` beyond the coherence of the weights) are dropped; orders
//! beyond the coherent ones are the incoherent tail of [`crate::plate::paths`].
//!
//! Error budget (absolute, in units of the white response 1). The perceptual budget is a mean
//! CIEDE2000 of 0.1 and a worst of 0.5 against the tabulated weights; near black, where
//! CIELAB is steepest (`L* = 903 Y`, `a* ≈ 3900 (X − Y)`), an error of 1e-4 in a channel is
//! already 0.4, so every approximation here is held to 1e-5: [`DROP`] per dropped group,
//! [`NODE_ERROR`] per group for its nodes, [`ORDER_TAIL`] for the coherence of the orders left
//! to the tail, and [`crate::spectral::amplitudes::AMPLITUDE_TOLERANCE`] for the
//! amplitudes. The fits of the weights add their own error (1.7e-3 to 7.9e-3 in L1, mostly at
//! path differences beyond 10 µm), which dominates (`tests/spectral_rgb.rs`).

use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::optics::mueller;
use crate::plate::paths::{Counts, PathClass, PathExpansion};
use crate::plate::slab::{Output, SlabBlocks, SlabMueller, Want};
use crate::plate::Plate;
use crate::spectral::amplitudes::{least_attenuation, traversal_q, Amplitudes};
use crate::spectral::fringe::{self, FringeRule};
use crate::spectral::hermite;
use crate::spectral::nodes::{self, FINEST, LEVELS, MAX_NODES};
use crate::spectral::pairs::{
    self, add_scaled, cross_add, dot, Group, Pair, Selection, INTENSITY_ENTRIES,
};
use crate::spectral::shared;
use crate::spectral::weights::{gaussians, WeightSet};
use nalgebra::{Matrix2, Matrix4, Vector2};
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;

/// A group whose amplitude times its fringe's visibility is below this is dropped.
pub const DROP: f64 = 1e-5;
/// Largest interpolation error a group's nodes may leave (times its amplitude).
pub const NODE_ERROR: f64 = 1e-5;
/// Coherent orders are kept until the coherence of the next ones is below this.
pub const ORDER_TAIL: f64 = 1e-5;
/// Most coherent orders: a plate that needs more is not served by this method.
pub const MAX_ORDER: usize = 8;

/// `∫ w_c(k) M(k) dk` for the channels of `set` (module docs), or `None` if the plate needs more
/// coherent orders than [`MAX_ORDER`] (thin plates of high index near grazing incidence),
/// or a wave in it turns evanescent inside the band ([`least_attenuation`]). Where the shared rule
/// of the exact plate costs less (thin, strongly dispersive plates: many groups integrated
/// Gaussian by Gaussian), that rule integrates it.
pub fn channels(
    plate: &Plate,
    frame: &PlaneFrame,
    beta: C64,
    set: WeightSet,
    want: Want,
    output: Output,
) -> Result<Option<[SlabMueller; 3]>> {
    let amplitudes = Amplitudes::new(plate, frame, beta)?;
    let Some(loss) = least_attenuation(plate, frame, beta, &amplitudes.centre().q)? else {
        return Ok(None);
    };
    let group = amplitudes.group_indices();
    // The shortest round trip's group path (nm): o or e down, o or e up.
    let round_trip = plate.thickness_nm * (group[0].min(group[1]) + group[2].min(group[3]));
    let rule = fringe::rule(set, 0);
    let Some((order, rho)) = coherent_order(amplitudes.centre(), round_trip, rule) else {
        return Ok(None);
    };
    let it = Integration {
        plate,
        frame,
        beta,
        set,
        want,
        output,
        group,
        loss,
        centre_q: traversal_q(&amplitudes.centre().q).map(|q| q.re),
        amplitudes,
        order,
        // The tail's share of the light, `Σ_{n>N} ρ^{2n}`, for its node level.
        tail_strength: rho.powi(2 * (order as i32 + 1)) / (1.0 - rho * rho),
    };
    it.run()
}

/// The coherent order `N` and the round trip's spectral norm `ρ` (with its attenuation).
/// Paths `n` round trips apart interfere with amplitude `ρⁿ` times the visibility of a fringe
/// of `n` round-trip group paths (vanishing in thick plates), and paths of the same order with
/// their o/e split, `ρ^{2n}`: `N` is the first order whose next one falls below
/// [`ORDER_TAIL`] on both counts. `None` beyond [`MAX_ORDER`].
fn coherent_order(b: &SlabBlocks, round_trip: f64, rule: &FringeRule) -> Option<(usize, f64)> {
    let kd = fringe::band().0 * b.thickness_nm;
    let att = |q: C64| C64::new((-(kd * q.im).abs()).exp(), 0.0);
    let pd = Matrix2::from_diagonal(&Vector2::new(att(b.q[0]), att(b.q[1])));
    let pu = Matrix2::from_diagonal(&Vector2::new(att(b.q[2]), att(b.q[3])));
    let rho = crate::cmath::spectral_norm(&(b.r3 * pu * b.r2 * pd));
    if rho.is_nan() || rho >= 1.0 {
        return None;
    }
    let sum = 1.0 / (1.0 - rho); // Σ over the pairs' common orders
    (0..=MAX_ORDER)
        .find(|&n| {
            let next = (n + 1) as f64;
            let across = rho.powf(next) * rule.visibility(next * round_trip);
            let within = rho.powf(2.0 * next);
            sum * across.max(within) < ORDER_TAIL
        })
        .map(|n| (n, rho))
}

/// A group and where it is evaluated.
struct Placed {
    group: Group,
    /// Level of its amplitude nodes.
    amplitude_level: usize,
    /// Level of its phase nodes (at least the amplitudes'); `None`: Gaussian by Gaussian.
    level: Option<usize>,
    /// `Σ weight cross(A_a, A_b)` (no phase, no attenuation) at its amplitude nodes.
    amplitude: Vec<Matrix4<C64>>,
}

/// The classes of both lobes at one amplitude node, sorted by counts, and the tail there.
struct Classes {
    lobes: [Vec<PathClass>; 2],
    tail: Option<[Matrix4<f64>; 2]>,
}

impl Classes {
    fn class(&self, lobe: usize, counts: &Counts) -> Option<&PathClass> {
        let v = &self.lobes[lobe];
        v.binary_search_by(|c| c.counts.cmp(counts))
            .ok()
            .map(|i| &v[i])
    }
}

/// Everything one integration over a weight set needs.
struct Integration<'a> {
    plate: &'a Plate,
    frame: &'a PlaneFrame,
    beta: C64,
    set: WeightSet,
    want: Want,
    output: Output,
    amplitudes: Amplitudes,
    /// Coherent order of the expansion.
    order: usize,
    /// Group index per traversal at the centre (`d(k Re Q)/dk`).
    group: [f64; 4],
    /// The least attenuation exponent per traversal over the band.
    loss: [f64; 4],
    /// `Re Q` per traversal at the centre.
    centre_q: [f64; 4],
    /// The incoherent tail's strength (relative to the direct light).
    tail_strength: f64,
}

impl Integration<'_> {
    /// The integration (by the shared exact rule where that is cheaper).
    fn run(&self) -> Result<Option<[SlabMueller; 3]>> {
        let lobes = [self.want.reflection, self.want.transmission];
        let tail_level = self.amplitudes.level_for(self.tail_strength);
        let centre = self.classes(0, 0, self.order, tail_level == 0);
        let mut placed: [Vec<Placed>; 2] = [Vec::new(), Vec::new()];
        let mut pairs: [Vec<Pair>; 2] = [Vec::new(), Vec::new()];
        for lobe in 0..2 {
            if lobes[lobe] {
                let g = pairs::groups(&centre.lobes[lobe], &self.selection());
                placed[lobe] = self.place(g.groups);
                pairs[lobe] = g.pairs;
            }
        }
        if let Some(points) = self.cheaper_exact_rule(&placed, &pairs)? {
            return shared::quadrature(
                self.plate,
                self.frame,
                self.beta,
                self.set,
                points,
                self.want,
                self.output,
            )
            .map(Some);
        }
        // The classes at every node of the amplitudes' level that a group or the tail uses,
        // each to the highest order needed there.
        let own = nodes::level(self.amplitudes.level);
        let mut classes: Vec<Option<Classes>> = (0..own.nodes.len()).map(|_| None).collect();
        let centre_index = own.nodes.len() / 2;
        for (i, &j) in own.in_finest.iter().enumerate() {
            if i == centre_index {
                continue;
            }
            let uses = |level: usize| nodes::level(level).in_finest.contains(&j);
            let with_tail = uses(tail_level);
            let order = placed
                .iter()
                .flatten()
                .filter(|p| uses(p.amplitude_level))
                .map(|p| p.group.order)
                .max();
            let order = if with_tail { Some(self.order) } else { order };
            if let Some(order) = order {
                classes[i] = Some(self.classes(self.amplitudes.level, i, order, with_tail));
            }
        }
        classes[centre_index] = Some(centre);
        let intensity = self.output == Output::Intensity;
        for (lobe, list) in placed.iter_mut().enumerate() {
            for p in list.iter_mut() {
                p.amplitude = (0..LEVELS[p.amplitude_level])
                    .map(|i| {
                        let c = classes[self.own_index(p.amplitude_level, i)]
                            .as_ref()
                            .expect("classes at every amplitude node a group uses");
                        let mut m = Matrix4::zeros();
                        for (ca, cb, w) in &pairs[lobe][p.group.pairs.clone()] {
                            if let (Some(x), Some(y)) = (c.class(lobe, ca), c.class(lobe, cb)) {
                                cross_add(&mut m, &x.amplitude, &y.amplitude, *w, intensity);
                            }
                        }
                        m
                    })
                    .collect();
            }
        }
        let q = self.phases(&placed)?;
        let mut out = [SlabMueller { r: None, t: None }; 3];
        for lobe in 0..2 {
            if !lobes[lobe] {
                continue;
            }
            let k = self.integrate(&placed[lobe], &q);
            let tail = self.tail(lobe, tail_level, &classes);
            for c in 0..3 {
                let m = match self.output {
                    Output::Mueller => mueller::from_coherency(&k[c]),
                    Output::Intensity => {
                        let mut m = Matrix4::zeros();
                        m[(0, 0)] =
                            0.5 * INTENSITY_ENTRIES.iter().map(|e| k[c][*e]).sum::<C64>().re;
                        m
                    }
                } + tail[c];
                if lobe == 0 {
                    out[c].r = Some(m);
                } else {
                    out[c].t = Some(m);
                }
            }
        }
        Ok(Some(out.map(|m| self.output.keep(m))))
    }

    /// The points of the shared rule of the exact plate ([`crate::spectral::shared`]) if it
    /// costs less than this integration would. Both costs are linear models fitted (least squares, median
    /// relative error 14 %) to their measured times on the 500 validation plates of
    /// `examples/bench_core.rs`, in microseconds of one core: this method `4.3` per amplitude
    /// node, `0.12` per phase node of every group, `15` per group integrated Gaussian by
    /// Gaussian, `0.62` per group and `0.031` per pair and amplitude node; the shared rule `0.34`
    /// per point, and `112` for the interpolant of a dispersive plate's blocks. The shared
    /// rule's plan (itself ~3 µs) is only asked for when the groups cost more than its cheapest
    /// rule could.
    fn cheaper_exact_rule(
        &self,
        placed: &[Vec<Placed>; 2],
        pairs: &[Vec<Pair>; 2],
    ) -> Result<Option<usize>> {
        let amplitude_nodes = LEVELS[self.amplitudes.level] as f64;
        let groups: f64 = placed
            .iter()
            .flatten()
            .map(|p| 0.62 + p.level.map_or(15.0, |l| 0.12 * LEVELS[l] as f64))
            .sum();
        let pairs = 0.031 * amplitude_nodes * pairs.iter().map(|p| p.len()).sum::<usize>() as f64;
        let ours = 4.3 * amplitude_nodes + groups + pairs;
        let interpolant = if self.plate.is_dispersive() {
            112.0
        } else {
            0.0
        };
        let exact = |points: f64| 0.34 * points + interpolant;
        if ours <= exact(shared::LADDER[0] as f64) {
            return Ok(None);
        }
        Ok(shared::plan(self.plate, self.frame, self.beta, self.set)?
            .filter(|&points| exact(points as f64) < ours))
    }

    /// The index among the amplitudes' own nodes of node `i` of level `level`.
    fn own_index(&self, level: usize, i: usize) -> usize {
        let j = nodes::level(level).in_finest[i];
        nodes::level(self.amplitudes.level)
            .in_finest
            .iter()
            .position(|&f| f == j)
            .expect("a coarser level's nodes are among the finer level's")
    }

    /// What decides which pairs are kept.
    fn selection(&self) -> Selection<'static> {
        Selection {
            thickness_nm: self.plate.thickness_nm,
            group: self.group,
            absorbing: traversal_q(&self.amplitudes.centre().q)
                .iter()
                .any(|q| q.im != 0.0),
            loss: self.loss,
            rule: fringe::rule(self.set, 0),
            drop: DROP,
        }
    }

    /// The classes at node `i` of `level` up to `order` (and the tail if asked).
    fn classes(&self, level: usize, i: usize, order: usize, with_tail: bool) -> Classes {
        let (k0, a) = fringe::band();
        let t = nodes::level(level).nodes[i];
        let e = PathExpansion::from_blocks(
            self.amplitudes.at(level, i),
            self.amplitudes.merged,
            order,
            self.want,
            with_tail.then_some(TAU / (k0 + a * t)),
        );
        let sorted = |mut v: Vec<PathClass>| {
            v.sort_by_key(|c| c.counts);
            v
        };
        Classes {
            lobes: [sorted(e.reflection), sorted(e.transmission)],
            tail: with_tail.then_some([e.tail.r, e.tail.t]),
        }
    }

    /// Each group's amplitude level and phase level.
    fn place(&self, groups: Vec<Group>) -> Vec<Placed> {
        groups
            .into_iter()
            .map(|g| {
                let amplitude_level = self.amplitudes.level_for(g.strength);
                let level = self.level(&g, amplitude_level);
                Placed {
                    group: g,
                    amplitude_level,
                    level,
                    amplitude: Vec::new(),
                }
            })
            .collect()
    }

    /// The phase level a group needs: at least its amplitudes', and enough to interpolate its
    /// absorption tilt (`x`: the change of its attenuation exponent across the half band) and
    /// its residual phase (`c`: its largest value at the amplitude nodes) to [`NODE_ERROR`]
    /// over its strength; `None` if even the finest level does not.
    fn level(&self, g: &Group, amplitude_level: usize) -> Option<usize> {
        let (_, a) = fringe::band();
        let d = self.plate.thickness_nm;
        let q = traversal_q(&self.amplitudes.centre().q);
        let x = a
            * d
            * (0..4)
                .map(|m| f64::from(g.sum[m]) * q[m].im)
                .sum::<f64>()
                .abs();
        let c = self.residual(g);
        let tolerance = NODE_ERROR / g.strength.max(1e-300);
        (amplitude_level..LEVELS.len()).find(|&l| interpolation_error(LEVELS[l], x, c) <= tolerance)
    }

    /// The largest residual phase `|φ_Δ(k) − φ_Δ(k₀) − G_Δ (k − k₀)|` of a group over the
    /// amplitude nodes (zero without dispersion).
    fn residual(&self, g: &Group) -> f64 {
        let (k0, a) = fringe::band();
        let d = self.plate.thickness_nm;
        self.amplitudes
            .blocks
            .iter()
            .zip(&nodes::level(self.amplitudes.level).nodes)
            .map(|((b, _), t)| {
                let q = traversal_q(&b.q).map(|x| x.re);
                let k = k0 + a * t;
                (k * d * dot(&g.delta, &q)
                    - k0 * d * dot(&g.delta, &self.centre_q)
                    - g.group_path * (k - k0))
                    .abs()
            })
            .fold(0.0, f64::max)
    }

    /// The layer's `Q` per traversal at every node of the finest level the groups use (by
    /// finest index; `None` elsewhere): exact at the amplitude nodes and, with dispersion, at
    /// every other node too (a group's phase needs `k d Δ·Q` to a small fraction of a radian,
    /// which interpolated indices do not give in thick plates).
    fn phases(&self, placed: &[Vec<Placed>; 2]) -> Result<Vec<Option<[C64; 4]>>> {
        let (k0, a) = fringe::band();
        let finest = placed
            .iter()
            .flatten()
            .map(|p| p.level.unwrap_or(FINEST))
            .max()
            .unwrap_or(0);
        let mut q: Vec<Option<[C64; 4]>> = vec![None; MAX_NODES];
        let own = nodes::level(self.amplitudes.level);
        for (i, &j) in own.in_finest.iter().enumerate() {
            q[j] = Some(traversal_q(&self.amplitudes.blocks[i].0.q));
        }
        let lv = nodes::level(finest);
        for (&j, t) in lv.in_finest.iter().zip(&lv.nodes) {
            if q[j].is_none() {
                q[j] = Some(if self.plate.is_dispersive() {
                    traversal_q(
                        &self
                            .plate
                            .layer_q(TAU / (k0 + a * t), self.frame, self.beta)?,
                    )
                } else {
                    traversal_q(&self.amplitudes.centre().q)
                });
            }
        }
        Ok(q)
    }

    /// `Σ_groups e^{iφ_Δ(k₀)} Σ_i P_Δ(k_i) W_ic(G_Δ)` per channel (coherency superoperators),
    /// `P_Δ` from the group's amplitudes interpolated between its amplitude nodes and its
    /// exact phase and attenuation at each phase node.
    fn integrate(&self, placed: &[Placed], q: &[Option<[C64; 4]>]) -> [Matrix4<C64>; 3] {
        let (k0, a) = fringe::band();
        let d = self.plate.thickness_nm;
        let intensity = self.output == Output::Intensity;
        let finest = &nodes::level(FINEST).nodes;
        let mut acc = [Matrix4::<C64>::zeros(); 3];
        let mut weights = [[C64::new(0.0, 0.0); 3]; MAX_NODES];
        for p in placed {
            let Some(level) = p.level else {
                self.integrate_per_gaussian(p, q, &mut acc);
                continue;
            };
            let g = &p.group;
            let amp = nodes::level(p.amplitude_level);
            fringe::rule(self.set, level).weights(g.group_path, &mut weights);
            let carrier = C64::from_polar(1.0, k0 * d * dot(&g.delta, &self.centre_q));
            // Σ_i factor_i W_ic L_n(k_i): the weight of amplitude node n in channel c, so that
            // each group's 4x4 values are touched once per channel.
            let mut per_node = [[C64::new(0.0, 0.0); 3]; MAX_NODES];
            for (i, &j) in nodes::level(level).in_finest.iter().enumerate() {
                let k = k0 + a * finest[j];
                let qj = q[j]
                    .as_ref()
                    .expect("a phase at every node of a used level");
                let residual = k * d * dot(&g.delta, &qj.map(|x| x.re))
                    - k0 * d * dot(&g.delta, &self.centre_q)
                    - g.group_path * (k - k0);
                let attenuation = (-k * d * dot(&g.sum, &qj.map(|x| x.im))).exp();
                let factor = C64::from_polar(attenuation, residual) * carrier;
                for (n, l) in amp.to_finest[j].iter().enumerate() {
                    if *l != 0.0 {
                        for c in 0..3 {
                            per_node[n][c] += factor * weights[i][c] * *l;
                        }
                    }
                }
            }
            for (n, value) in p.amplitude.iter().enumerate() {
                for (c, acc_c) in acc.iter_mut().enumerate() {
                    add_scaled(acc_c, value, per_node[n][c], intensity);
                }
            }
        }
        acc
    }

    /// A group whose phase no level resolves, Gaussian by Gaussian of the fitted weights. Its
    /// phase `φ(k) = k d Δ·Re Q(k)` and attenuation `α(k) = k d Σ·Im Q(k)` are the Chebyshev
    /// interpolants through their exact values at the finest nodes (functions analytic around
    /// the band: the interpolants converge geometrically), its amplitude `C(k)` is interpolated
    /// between its amplitude nodes. With `b = φ'(μ) + i α'(μ)`, `c = φ''(μ)` and `R(k)` what is
    /// left of `C e^{iφ − α}` after its quadratic part (amplitude and the cubic and higher
    /// terms of the phase: slowly varying), completing the square gives
    /// `∫ N(k; μ, σ) e^{ib(k − μ) + ic(k − μ)²/2} R(k) dk = F E[R(μ + iσ'² b + σ' Z)]` with the
    /// complex width `σ'² = σ²/(1 − icσ²)` and `F` the paper's closed form
    /// ([`gaussian_fringe`]); the expectation is a Gauss–Hermite sum of as many points as
    /// [`GAUSS_HERMITE`] gives (`R` is analytic).
    fn integrate_per_gaussian(
        &self,
        p: &Placed,
        q: &[Option<[C64; 4]>],
        acc: &mut [Matrix4<C64>; 3],
    ) {
        let (k0, a) = fringe::band();
        let d = self.plate.thickness_nm;
        let g = &p.group;
        let intensity = self.output == Output::Intensity;
        let at = |j: usize| q[j].expect("the finest level's phases are computed");
        let phase: Vec<f64> = (0..MAX_NODES)
            .map(|j| dot(&g.delta, &at(j).map(|x| x.re)))
            .collect();
        let loss: Vec<f64> = (0..MAX_NODES)
            .map(|j| dot(&g.sum, &at(j).map(|x| x.im)))
            .collect();
        let lossless = g.sum == [0; 4];
        let (phase, loss) = (nodes::chebyshev(&phase), nodes::chebyshev(&loss));
        // `iφ(k) − α(k)` at a complex wavenumber.
        let exponent = |k: C64| {
            let t = (k - k0) / a;
            let i = C64::new(0.0, 1.0);
            let alpha = if lossless {
                C64::new(0.0, 0.0)
            } else {
                nodes::chebyshev_at(&loss, t)
            };
            k * d * (i * nodes::chebyshev_at(&phase, t) - alpha)
        };
        let amp = &nodes::level(p.amplitude_level).nodes;
        let mut basis = [C64::new(0.0, 0.0); MAX_NODES];
        // Σ over the Gaussians of each amplitude node's weight, per channel.
        let mut per_node = [[C64::new(0.0, 0.0); 3]; MAX_NODES];
        for c in 0..3 {
            for gauss in gaussians(self.set, c) {
                let mu = gauss.mu;
                let t = (mu - k0) / a;
                let (f, f1, f2) = nodes::chebyshev_eval(&phase, t);
                let (s, s1, s2) = if lossless {
                    (0.0, 0.0, 0.0)
                } else {
                    nodes::chebyshev_eval(&loss, t)
                };
                // b = d(k f)/dk + i d(k s)/dk, c likewise of second order; d/dk = (1/a) d/dt.
                let (f1, f2, s1, s2) = (f1 / a, f2 / (a * a), s1 / a, s2 / (a * a));
                let b = C64::new(d * (f + mu * f1), d * (s + mu * s1));
                let curvature = C64::new(d * (2.0 * f1 + mu * f2), d * (2.0 * s1 + mu * s2));
                let centre = exponent(C64::new(mu, 0.0));
                let closed = gaussian_fringe(gauss, b, curvature);
                if closed.norm() * g.strength < NEGLIGIBLE_TERM {
                    continue;
                }
                let width2 = gauss.sigma * gauss.sigma
                    / (1.0 - C64::new(0.0, 1.0) * curvature * gauss.sigma * gauss.sigma);
                let width = crate::cmath::sqrt(width2);
                let shift = C64::new(mu, 0.0) + C64::new(0.0, 1.0) * width2 * b;
                let i = C64::new(0.0, 1.0);
                let remainder = |k: C64| {
                    let x = k - mu;
                    exponent(k) - centre - i * b * x - 0.5 * i * curvature * x * x
                };
                // The cubic and higher terms two widths out (`r`) decide the points.
                let weight = closed.norm() * g.strength;
                let points = if weight < NODE_ERROR * 1e-2 {
                    1
                } else {
                    let r = [-2.0, 2.0]
                        .map(|z| remainder(C64::new(mu + z * gauss.sigma, 0.0)).norm())
                        .into_iter()
                        .fold(0.0, f64::max);
                    GAUSS_HERMITE
                        .iter()
                        .find(|(_, error)| weight * error(r) <= NODE_ERROR * 1e-1)
                        .map_or(GAUSS_HERMITE[GAUSS_HERMITE.len() - 1].0, |p| p.0)
                };
                let scale = centre.exp() * closed;
                for &(z, w) in hermite::rule(points) {
                    let k = shift + width * z;
                    nodes::lagrange(amp, (k - k0) / a, &mut basis);
                    let factor = remainder(k).exp() * w * scale;
                    for (pn, l) in per_node.iter_mut().zip(&basis[..amp.len()]) {
                        pn[c] += l * factor;
                    }
                }
            }
        }
        for (m, w) in p.amplitude.iter().zip(&per_node) {
            for (c, acc_c) in acc.iter_mut().enumerate() {
                add_scaled(acc_c, m, w[c], intensity);
            }
        }
    }

    /// `Σ_i tail(k_i) W_ic(0)`: the incoherent tail over the nodes of its level.
    fn tail(&self, lobe: usize, level: usize, classes: &[Option<Classes>]) -> [Matrix4<f64>; 3] {
        let mut w = [[C64::new(0.0, 0.0); 3]; MAX_NODES];
        fringe::rule(self.set, level).weights(0.0, &mut w);
        let mut out = [Matrix4::zeros(); 3];
        for i in 0..LEVELS[level] {
            let tail = classes[self.own_index(level, i)]
                .as_ref()
                .and_then(|c| c.tail)
                .expect("the tail at every node of its level");
            for (c, o) in out.iter_mut().enumerate() {
                *o += tail[lobe] * w[i][c].re;
            }
        }
        out
    }
}

/// Gauss–Hermite points per Gaussian of a group integrated Gaussian by Gaussian, with the
/// error they leave for a remainder `e^r = 1 + r + r²/2 + …` whose cubic and higher terms reach
/// `r` two widths from the centre: `n` points integrate polynomials of degree `2n − 1` exactly,
/// so the first term left out is `r` for one point, `r²/2` for two (degree 6), `r³/6` for four
/// and `r⁵/120` for eight.
#[allow(clippy::type_complexity)]
const GAUSS_HERMITE: [(usize, fn(f64) -> f64); 4] = [
    (1, |r| r),
    (2, |r| r * r / 2.0),
    (4, |r| r.powi(3) / 6.0),
    (8, |r| r.powi(5) / 120.0),
];

/// A Gaussian's share of a group below this is left out.
const NEGLIGIBLE_TERM: f64 = 1e-9;

/// `a ∫ N(k; μ, σ) e^{ib(k − μ) + ic(k − μ)²/2} dk = a exp(−σ² b² / (2 (1 − i c σ²))) /
/// √(1 − i c σ²)` (the Gaussian integral; complex `b` and `c` carry the attenuation's slope and
/// curvature). The imaginary part of `b` is capped at `1/σ`: beyond, the attenuation would move
/// the band's centre by more than its width, where the Gaussian model of the band no longer
/// holds and the light is attenuated to `~e^{−μ/σ}` anyway.
fn gaussian_fringe(g: &crate::band::Gaussian, b: C64, c: C64) -> C64 {
    let b = C64::new(b.re, b.im.clamp(-1.0 / g.sigma, 1.0 / g.sigma));
    let s2 = g.sigma * g.sigma;
    let den = 1.0 - C64::new(0.0, 1.0) * c * s2;
    (-0.5 * s2 * b * b / den).exp() / crate::cmath::sqrt(den) * g.amplitude
}

/// The error of interpolating a group's slow factor on `n` Chebyshev–Lobatto nodes: its
/// absorption tilt `e^{−x t}` (Chebyshev coefficients `2 I_j(x) ≈ 2 (x/2)^j / j!`: the first one
/// not resolved is `j = n`) and its residual phase `e^{ict²} = e^{ic/2} e^{i(c/2) T₂(t)}`
/// (coefficients `2 J_m(c/2) ≈ 2 (c/4)^m / m!` of `T_{2m}`: the first not resolved is
/// `m = ⌊(n−1)/2⌋ + 1`), `t ∈ [−1, 1]` across the band.
fn interpolation_error(n: usize, x: f64, c: f64) -> f64 {
    let term = |z: f64, j: usize| (1..=j).fold(2.0, |e, i| e * z / i as f64);
    term(0.5 * x, n) + term(0.25 * c, (n - 1) / 2 + 1)
}
