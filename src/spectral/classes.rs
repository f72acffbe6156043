//! The plate over the channels of a weight set, pair of path classes by pair (the paper's
//! closed form, with amplitudes interpolated across the band): the method for plates whose
//! o and e waves drift apart faster than any node level follows (thick, strongly birefringent
//! plates), where each fringe must be integrated exactly.
//!
//! Each Jones matrix is a sum over path classes `J(k) = Σ_c A_c(k) e^{ik d Q_c(k)}`
//! ([`crate::plate::paths`]); the coherency's pairs of classes are grouped by what their
//! spectral factor depends on ([`crate::spectral::layout`]). A group oscillates as
//! `e^{iφ_Δ(k)}` around its group path `G_Δ = φ_Δ'(k₀)` and integrates against every channel
//! by the fringe rules of [`crate::quadrature::fringe`]:
//!
//! ```text
//! ∫ w_c(k) K_Δ(k) dk = e^{iφ_Δ(k₀)} Σ_p P_Δ(k_p) W_pc(G_Δ),
//! P_Δ(k) = Σ_(a,b) cross(A_a, A_b)(k) e^{−kd Im(Q_a + Q_b)} e^{i(φ_Δ(k) − φ_Δ(k₀) − G_Δ (k − k₀))}
//! ```
//! `P_Δ` is smooth (amplitudes, absorption and the residual curvature of the phase): its
//! amplitudes come from the exact blocks at the nodes of one level ([`Amplitudes`]; coarser for
//! weaker groups), interpolated to its phase nodes, where its phase and attenuation are exact.
//! Every node's share is a scalar per channel, `ω_ic = Σ_p factor_p W_pc L_i(k_p)`, so the pairs
//! are summed once per amplitude node. A group whose residual phase no level resolves (strong
//! dispersion in thick plates) takes a shared product-integration rule of as many points as its
//! chirp needs ([`Integration::dense`]). Groups whose fringe is invisible in every channel are dropped; orders
//! beyond the coherent ones are the incoherent tail of [`crate::plate::paths`]. The budget of
//! every approximation: [`crate::quadrature::budget`].

use crate::colour::weights::WeightSet;
use crate::error::Result;
use crate::optics::mueller;
use crate::plate::paths::{ClassAmplitudes, Lobe};
use crate::plate::slab::{Output, SlabMueller, Want};
use crate::quadrature::budget::{DROP, NODE_ERROR, ORDER_TAIL};
use crate::quadrature::chebyshev;
use crate::quadrature::fringe;
use crate::quadrature::nodes::{self, LEVELS, MAX_NODES};
use crate::scratch::{Pool, Pooled};
use crate::spectral::amplitudes::traversal_q;
use crate::spectral::layout::{self, Group, Layout, MAX_ORDER};
use crate::spectral::survey::Survey;
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;

/// How the path-class method integrates a plate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orders {
    /// Highest coherent order (the rest is the incoherent tail).
    pub order: usize,
    /// Pairs of different orders can be visible (a round trip within the coherence of the
    /// weights).
    pub cross_orders: bool,
    /// The tail's share of the light, `ρ^{2(N+1)}/(1 − ρ²)`, for its node level.
    pub tail_strength: f64,
}

/// The level of the nodes through which a chirped group's phase is interpolated.
const PHASE_LEVEL: usize = 4;

/// The plan for `survey` over `set`: the coherent order `N` is the first whose next order's
/// pairs fall below [`ORDER_TAIL`] (across orders: `ρⁿ` times the visibility of `n` round
/// trips; within an order, where mode conversions keep paths of equal counts coherent:
/// `ρ^{2n}`), at most [`MAX_ORDER`] (beyond, the tail takes the rest: plates near grazing
/// incidence, where the round trip reflects nearly everything; docs/physics.md §4, "Known
/// limitations", gives that error as measured). `None` if the orders do not converge (`ρ ≥ 1`).
pub fn plan(s: &Survey, set: WeightSet) -> Option<Orders> {
    let rho = s.rho;
    // `ρ ≥ 1` or NaN: the orders do not converge.
    if rho.is_nan() || rho >= 1.0 {
        return None;
    }
    let rule = fringe::rule(set, 0);
    // The nearest fringe of a pair one round trip apart: a round trip less the split of one
    // traversal each way (pairs that differ in the modes of more traversals as well are weaker
    // by the mode conversions that separate them), at each wavenumber of the survey's span: a
    // chirped fringe's local frequency is its group path there, never below the least of these
    // (taking the shortest round trip at one end of the band and the widest split at the other
    // would call thick dispersive plates' orders coherent that are not).
    let nearest = s
        .group_path_range(|g| {
            let split = (g[1] - g[0]).abs().max((g[3] - g[2]).abs());
            g[0].min(g[1]) + g[2].min(g[3]) - 2.0 * split
        })
        .0;
    // The n-th round trip weighs at most C ρⁿ (the survey's transient).
    let sum = s.transient / (1.0 - rho);
    let order = (0..=MAX_ORDER)
        .find(|&n| {
            let next = (n + 1) as f64;
            let across = rho.powf(next) * rule.visibility_beyond(next * nearest);
            let within = rho.powf(2.0 * next);
            sum * across.max(within) < ORDER_TAIL
        })
        .unwrap_or(MAX_ORDER);
    let cross_orders = 2.0 * rho * sum * rule.visibility_beyond(nearest.max(0.0)) >= DROP;
    Some(Orders {
        order,
        cross_orders,
        tail_strength: s.transient * s.transient * rho.powi(2 * (order as i32 + 1))
            / (1.0 - rho * rho),
    })
}

/// A kept group: where it lies in its layout and how it is integrated.
#[derive(Clone, Copy)]
struct Placed {
    lobe: usize,
    group: usize,
    /// Level of its amplitude nodes.
    amplitude_level: usize,
    /// Level of its phase nodes; `None`: a chirped group ([`Integration::dense`]).
    level: Option<usize>,
    strength: f64,
    group_path: f64,
    /// The highest order of its classes.
    order: usize,
    /// Its node shares `ω_ic`: a range of [`Work::omega`], one per amplitude node.
    omega: usize,
}

/// The working memory of one integration (per thread, reused).
struct Work {
    classes: ClassAmplitudes,
    placed: Vec<Placed>,
    omega: Vec<[C64; 3]>,
    norms: Vec<f64>,
    /// `Q` per traversal at each finest-level node that a phase uses.
    q: [Option<[C64; 4]>; MAX_NODES],
    /// The traversals' phase series of the query (computed by its first chirped group).
    series: Option<TraversalSeries>,
    /// The traversals' phases on the shared rules the chirped groups use (one per rung).
    chirped: Vec<TraversalPhases>,
    /// Per class `a` of a lobe summed by [`Sums::Classes`]: `B_ac` per channel at the current
    /// node, and the node it was last cleared at (`u32::MAX`: never).
    class_sums: Vec<([Matrix2<C64>; 3], u32)>,
    /// The slots of [`Work::class_sums`] with a `B_ac` at the current node (reflected
    /// classes first, then transmitted ones).
    touched: Vec<u32>,
}

/// Nodes of [`PHASE_LEVEL`].
const PHASE_NODES: usize = LEVELS[PHASE_LEVEL];

/// The Chebyshev series of the four traversals' `Re Q_m` and `Im Q_m` through their exact
/// values at the nodes of [`PHASE_LEVEL`] (`Q` is analytic around the band: they converge
/// geometrically); a group's phase series is `Δ ·` these, its attenuation's `Σ ·` these.
#[derive(Clone, Copy)]
struct TraversalSeries {
    re: [[f64; PHASE_NODES]; 4],
    im: [[f64; PHASE_NODES]; 4],
}

impl TraversalSeries {
    fn new(q: &[Option<[C64; 4]>; MAX_NODES]) -> Self {
        let lv = nodes::level(PHASE_LEVEL);
        let series = |m: usize, im: bool| -> [f64; PHASE_NODES] {
            let v: [f64; PHASE_NODES] = std::array::from_fn(|i| {
                let x = q[lv.in_finest[i]].expect("the phase level's phases are computed")[m];
                if im {
                    x.im
                } else {
                    x.re
                }
            });
            let mut c = [0.0; PHASE_NODES];
            nodes::chebyshev_into(&v, &mut c);
            c
        };
        TraversalSeries {
            re: std::array::from_fn(|m| series(m, false)),
            im: std::array::from_fn(|m| series(m, true)),
        }
    }

    /// `Δ · c` of four series.
    fn combine(c: &[[f64; PHASE_NODES]; 4], delta: &[f64; 4]) -> [f64; PHASE_NODES] {
        std::array::from_fn(|i| (0..4).map(|m| delta[m] * c[m][i]).sum())
    }
}

/// The four traversals' phases `k d Re Q_m(k)` and attenuations `k d Im Q_m(k)` at every point
/// of one shared rule, from [`TraversalSeries`]: evaluated once per query and rule, then every
/// chirped group's phase is `Δ · phase` and its attenuation `Σ · attenuation`
/// ([`Integration::dense`]). The tables of a thread are kept between queries (`fresh` marks
/// those of the current one), so a query refills them without allocating.
struct TraversalPhases {
    points: usize,
    fresh: bool,
    phase: Vec<[f64; 4]>,
    attenuation: Vec<[f64; 4]>,
}

impl TraversalPhases {
    fn fill(&mut self, s: &Survey, rule: &chebyshev::Rule, series: &TraversalSeries) {
        let (k0, a) = fringe::band();
        let d = s.plate.thickness_nm;
        let at = |c: &[[f64; PHASE_NODES]; 4], k: f64| -> [f64; 4] {
            let t = (k - k0) / a;
            std::array::from_fn(|m| k * d * nodes::chebyshev_at(&c[m], t))
        };
        self.phase.clear();
        self.attenuation.clear();
        self.phase
            .extend(rule.nodes.iter().map(|&(k, _)| at(&series.re, k)));
        self.attenuation
            .extend(rule.nodes.iter().map(|&(k, _)| at(&series.im, k)));
        self.points = rule.nodes.len();
        self.fresh = true;
    }
}

thread_local! {
    static WORK: Pool<Work> = const { std::cell::RefCell::new(Vec::new()) };
}

fn work() -> Pooled<Work> {
    let mut w = Pooled::take(&WORK, || {
        Box::new(Work {
            classes: ClassAmplitudes::with_capacity(MAX_ORDER),
            placed: Vec::new(),
            omega: Vec::new(),
            norms: Vec::new(),
            q: [None; MAX_NODES],
            series: None,
            chirped: Vec::new(),
            class_sums: Vec::new(),
            touched: Vec::new(),
        })
    });
    w.placed.clear();
    w.omega.clear();
    w.series = None;
    w.chirped.iter_mut().for_each(|t| t.fresh = false);
    w.q = [None; MAX_NODES];
    w
}

/// How the pairs of a lobe's groups are summed into its coherency at an amplitude node
/// `i`, `K_ic = Σ_g ω_gic Σ_(a,b)∈g w_ab cross(A_a, A_b)` (`w` = 1 for a class with itself, 2
/// otherwise); both orders of summation give the same value to rounding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sums {
    /// Per group its pair sum `S_g = Σ w cross(A_a, A_b)` (16 complex products a pair), then
    /// `ω_gic S_g` per channel (48 a group).
    Pairs,
    /// Pair-free: per class `a`, `B_ac = Σ_(a,b) w ω_gic A_b` over its pairs (12 a pair), then
    /// one `cross(A_a, B_ac)` per channel (48 a class).
    Classes,
    /// Per lobe, the one of the two with fewer products for its kept groups (`16 P + 48 G`
    /// against `12 P + 48 C` for `P` pairs in `G` groups of `C` first classes): the classes'
    /// sums where a lobe's pairs spread over many groups (thin plates, many visible fringes),
    /// the groups' where a few groups hold many pairs (thick plates: the diagonal groups).
    Cheaper,
}

/// `∫ w_c M` for the channels of `set` by `plan` (module docs).
pub fn channels(
    s: &Survey,
    plan: &Orders,
    set: WeightSet,
    want: Want,
    output: Output,
) -> Result<[SlabMueller; 3]> {
    channels_summed(s, plan, set, want, output, Sums::Cheaper)
}

/// [`channels`] with the pairs summed by `sums`.
pub fn channels_summed(
    s: &Survey,
    plan: &Orders,
    set: WeightSet,
    want: Want,
    output: Output,
    sums: Sums,
) -> Result<[SlabMueller; 3]> {
    let mut w = work();
    let w = &mut *w;
    let lobes = [want.reflection, want.transmission];
    let absorbing = traversal_q(&s.amplitudes.centre().q)
        .iter()
        .any(|q| q.im != 0.0);
    let loss = s.loss.unwrap_or([0.0; 4]);
    let layouts = [Lobe::Reflection, Lobe::Transmission]
        .map(|l| layout::layout(l, plan.order, absorbing, plan.cross_orders));
    // The classes at the centre decide which groups are kept.
    w.classes.expand(s.amplitudes.centre(), plan.order, want);
    for (l, layout) in layouts.iter().enumerate() {
        if lobes[l] {
            select(
                s,
                plan,
                set,
                l,
                layout,
                &w.classes,
                &loss,
                &mut w.norms,
                &mut w.placed,
            );
        }
    }
    phases(s, w)?;
    let by_classes = [0, 1].map(|l| match sums {
        Sums::Pairs => false,
        Sums::Classes => true,
        Sums::Cheaper => classes_cheaper(layouts[l], w.placed.iter().filter(|p| p.lobe == l)),
    });
    // Every slot cleared at its first use in a node (`u32::MAX`: at none yet).
    w.class_sums.clear();
    w.class_sums.resize(
        layouts[0].counts.len() + layouts[1].counts.len(),
        ([Matrix2::zeros(); 3], u32::MAX),
    );
    let it = Integration { s, set };
    for p in 0..w.placed.len() {
        let start = w.omega.len();
        w.placed[p].omega = start;
        let n = LEVELS[w.placed[p].amplitude_level];
        w.omega.resize(start + n, [C64::new(0.0, 0.0); 3]);
        let placed = w.placed[p];
        let group = &layouts[placed.lobe].groups[placed.group];
        it.shares(
            &placed,
            group,
            &w.q,
            &mut w.series,
            &mut w.chirped,
            &mut w.omega[start..start + n],
        );
    }
    let tail_level = s.amplitudes.level_for(plan.tail_strength);
    let mut acc = [[Matrix4::<C64>::zeros(); 2]; 3];
    let mut tails = [[Matrix4::<f64>::zeros(); 2]; 3];
    let own = nodes::level(s.amplitudes.level);
    let tail_rule = fringe::rule(set, tail_level);
    let (k0, a) = fringe::band();
    // The centre first: its classes are still expanded from the selection.
    let centre = own.nodes.len() / 2;
    let visit = std::iter::once(centre).chain((0..own.nodes.len()).filter(|&i| i != centre));
    for i in visit {
        let (j, t) = (own.in_finest[i], own.nodes[i]);
        // Node j's index in each level (None where it is not one of the level's nodes).
        let index: [Option<usize>; LEVELS.len()] =
            std::array::from_fn(|l| nodes::level(l).in_finest.iter().position(|&f| f == j));
        let uses = |level: usize| index[level].is_some();
        let with_tail = uses(tail_level);
        let order = w
            .placed
            .iter()
            .filter(|p| uses(p.amplitude_level))
            .map(|p| p.order)
            .max();
        let order = if with_tail { Some(plan.order) } else { order };
        let Some(order) = order else { continue };
        let blocks = s.amplitudes.exact(j).expect("an amplitude node");
        if i != centre || order != plan.order {
            w.classes.expand(blocks, order, want);
        }
        for p in w.placed.iter() {
            let Some(node) = index[p.amplitude_level] else {
                continue;
            };
            let layout = layouts[p.lobe];
            let shares = &w.omega[p.omega + node];
            let group = &layout.groups[p.group];
            if by_classes[p.lobe] {
                let amps = lobe_amplitudes(&w.classes, p.lobe);
                let offset = p.lobe * layouts[0].counts.len();
                for &(a, b) in &layout.pairs[group.pairs.clone()] {
                    let slot = offset + a as usize;
                    let (sum, stamp) = &mut w.class_sums[slot];
                    if *stamp != i as u32 {
                        *stamp = i as u32;
                        *sum = [Matrix2::zeros(); 3];
                        w.touched.push(slot as u32);
                    }
                    let weight = if a == b { 1.0 } else { 2.0 };
                    for (b_c, share) in sum.iter_mut().zip(shares) {
                        *b_c += amps[b as usize] * (share * weight);
                    }
                }
                continue;
            }
            let m = pair_sum(layout, group, &w.classes, p.lobe, output);
            for (acc_c, share) in acc.iter_mut().zip(shares) {
                add_scaled(&mut acc_c[p.lobe], &m, *share, output);
            }
        }
        // The classes' sums of both lobes (a lobe's classes in its own range of `class_sums`).
        let reflected = layouts[0].counts.len();
        for slot in w.touched.drain(..) {
            let slot = slot as usize;
            let (l, a) = if slot < reflected {
                (0, slot)
            } else {
                (1, slot - reflected)
            };
            let x = &lobe_amplitudes(&w.classes, l)[a];
            for (acc_c, b_c) in acc.iter_mut().zip(&w.class_sums[slot].0) {
                cross_add(&mut acc_c[l], x, b_c, 1.0, output == Output::Intensity);
            }
        }
        if let Some(node) = index[tail_level] {
            let lambda = TAU / (k0 + a * t);
            let tail = w.classes.tail(blocks, s.amplitudes.merged, lambda, want);
            let wt = tail_rule.weight(0.0, node);
            for (c, t_c) in tails.iter_mut().enumerate() {
                t_c[0] += tail.r * wt[c].re;
                t_c[1] += tail.t * wt[c].re;
            }
        }
    }
    Ok(std::array::from_fn(|c| {
        let lobe = |l: usize| {
            lobes[l].then(|| {
                let m = match output {
                    Output::Mueller => mueller::from_coherency(&acc[c][l]),
                    Output::Intensity => {
                        let mut m = Matrix4::zeros();
                        m[(0, 0)] = 0.5
                            * INTENSITY_ENTRIES
                                .iter()
                                .map(|e| acc[c][l][*e])
                                .sum::<C64>()
                                .re;
                        m
                    }
                } + tails[c][l];
                output
                    .keep(SlabMueller {
                        r: Some(m),
                        t: None,
                    })
                    .r
                    .expect("kept")
            })
        };
        SlabMueller {
            r: lobe(0),
            t: lobe(1),
        }
    }))
}

/// The groups of lobe `l` worth integrating, with their levels: each class's strength is its
/// norm at the centre times its least attenuation over the band; a group's, the sum over its
/// pairs (2 for a pair of two classes); a group whose strength times its fringe's visibility
/// is below [`DROP`] is dropped, and so is every block whose classes cannot reach it.
#[allow(clippy::too_many_arguments)]
fn select(
    s: &Survey,
    plan: &Orders,
    set: WeightSet,
    l: usize,
    layout: &Layout,
    classes: &ClassAmplitudes,
    loss: &[f64; 4],
    norms: &mut Vec<f64>,
    placed: &mut Vec<Placed>,
) {
    let amps: &[Matrix2<C64>] = if l == 0 {
        &classes.reflection
    } else {
        &classes.transmission
    };
    norms.clear();
    let mut strongest = [0.0f64; MAX_ORDER + 1];
    for (k, c) in layout.counts.iter().enumerate() {
        let attenuation: f64 = (0..4).map(|m| f64::from(c[m]) * loss[m]).sum();
        let n = amps[k].norm() * (-attenuation).exp();
        norms.push(n);
        let o = layout.orders[k] as usize;
        strongest[o] = strongest[o].max(n);
    }
    let rule = fringe::rule(set, 0);
    let g = s.group_path.map(|x| x.re);
    // A group (or a block of them) goes when its strength times its visibility is below DROP.
    let drop = |bound: f64| bound < DROP;
    for block in &layout.blocks {
        let (m, n) = block.orders;
        if m != n && !plan.cross_orders {
            continue;
        }
        let strongest_pair = 2.0 * strongest[m] * strongest[n];
        if drop(strongest_pair * (block.pairs.end - block.pairs.start) as f64) {
            continue;
        }
        for (gi, group) in layout.groups[block.groups.clone()].iter().enumerate() {
            let path = |g: &[f64; 4]| {
                (0..4)
                    .map(|k| f64::from(group.delta[k]) * g[k])
                    .sum::<f64>()
            };
            let group_path = path(&g);
            let visibility = visibility(rule, s.group_path_range(path));
            let most = strongest_pair * (group.pairs.end - group.pairs.start) as f64;
            if visibility == 0.0 || drop(most * visibility) {
                continue;
            }
            let strength: f64 = layout.pairs[group.pairs.clone()]
                .iter()
                .map(|&(a, b)| {
                    let w = if a == b { 1.0 } else { 2.0 };
                    w * norms[a as usize] * norms[b as usize]
                })
                .sum();
            if drop(strength * visibility) {
                continue;
            }
            let amplitude_level = s.amplitudes.level_for(strength);
            let level = phase_level(s, group, strength, group_path, amplitude_level);
            placed.push(Placed {
                lobe: l,
                group: block.groups.start + gi,
                amplitude_level,
                level,
                strength,
                group_path,
                order: n,
                omega: 0,
            });
        }
    }
}

/// The visibility of a fringe whose group path moves over `(lo, hi)` across the band (dispersion:
/// a chirped fringe is seen where its local group path is): that of its one group path when it
/// barely moves, else the largest beyond its nearest, and 1 where it passes through zero.
fn visibility(rule: &fringe::FringeRule, (lo, hi): (f64, f64)) -> f64 {
    if hi - lo < fringe::STEP_NM {
        rule.visibility(0.5 * (lo + hi))
    } else if lo <= 0.0 && hi >= 0.0 {
        1.0
    } else {
        rule.visibility_beyond(lo.abs().min(hi.abs()))
    }
}

/// The phase level a group needs: at least its amplitudes', and enough to interpolate its
/// absorption tilt (`x`: the change of its attenuation exponent across the half band) and its
/// residual phase (`c`: its largest value at the amplitude nodes) to [`NODE_ERROR`] over its
/// strength; `None` if even the finest level does not.
fn phase_level(
    s: &Survey,
    g: &Group,
    strength: f64,
    group_path: f64,
    amplitude_level: usize,
) -> Option<usize> {
    let (_, a) = fringe::band();
    let x = a
        * (0..4)
            .map(|m| f64::from(g.sum[m]) * s.group_path[m].im)
            .sum::<f64>()
            .abs();
    let c = residual(s, g, group_path);
    let tolerance = NODE_ERROR / strength.max(1e-300);
    (amplitude_level..LEVELS.len()).find(|&l| slow_factor_error(LEVELS[l], x, c) <= tolerance)
}

/// The largest residual phase `|φ_Δ(k) − φ_Δ(k₀) − G_Δ (k − k₀)|` of a group over the
/// amplitude nodes (zero without dispersion).
fn residual(s: &Survey, g: &Group, group_path: f64) -> f64 {
    if !s.plate.is_dispersive() {
        return 0.0;
    }
    let (k0, a) = fringe::band();
    let d = s.plate.thickness_nm;
    let phase = |j: usize, k: f64| {
        let q = traversal_q(&s.amplitudes.exact(j).expect("an amplitude node").q);
        k * d * (0..4).map(|m| f64::from(g.delta[m]) * q[m].re).sum::<f64>()
    };
    let centre = phase(MAX_NODES / 2, k0);
    let lv = nodes::level(s.amplitudes.level);
    lv.in_finest
        .iter()
        .zip(&lv.nodes)
        .map(|(&j, t)| (phase(j, k0 + a * t) - centre - group_path * a * t).abs())
        .fold(0.0, f64::max)
}

/// The layer's `Q` per traversal at every finest-level node a group's phase uses (exact: at the
/// amplitude nodes from the blocks, elsewhere from the indices; a group's phase needs
/// `k d Δ·Q` to a small fraction of a radian, which interpolated indices do not give in thick
/// plates).
fn phases(s: &Survey, w: &mut Work) -> Result<()> {
    let (k0, a) = fringe::band();
    let finest = w
        .placed
        .iter()
        .map(|p| p.level.unwrap_or(PHASE_LEVEL))
        .max()
        .unwrap_or(0);
    let lv = nodes::level(finest);
    let centre = traversal_q(&s.amplitudes.centre().q);
    for (&j, t) in lv.in_finest.iter().zip(&lv.nodes) {
        w.q[j] = Some(match s.amplitudes.exact(j) {
            Some(b) => traversal_q(&b.q),
            None if s.plate.is_dispersive() => {
                traversal_q(&s.plate.layer_q(TAU / (k0 + a * t), &s.frame, s.beta)?)
            }
            None => centre,
        });
    }
    Ok(())
}

/// What one integration shares between its groups.
struct Integration<'a, 'b> {
    s: &'a Survey<'b>,
    set: WeightSet,
}

impl Integration<'_, '_> {
    /// A group's share per amplitude node and channel, `ω_ic = e^{iφ_Δ(k₀)} Σ_p factor_p W_pc(G)
    /// L_i(k_p)` (module docs), into `out`.
    fn shares(
        &self,
        p: &Placed,
        g: &Group,
        q: &[Option<[C64; 4]>; MAX_NODES],
        series: &mut Option<TraversalSeries>,
        chirped: &mut Vec<TraversalPhases>,
        out: &mut [[C64; 3]],
    ) {
        let Some(level) = p.level else {
            let series = *series.get_or_insert_with(|| TraversalSeries::new(q));
            return self.dense(p, g, &series, chirped, out);
        };
        let (k0, a) = fringe::band();
        let d = self.s.plate.thickness_nm;
        let dot = |x: &[C64; 4], im: bool| -> f64 {
            (0..4)
                .map(|m| {
                    f64::from(if im { g.sum[m] } else { g.delta[m] })
                        * if im { x[m].im } else { x[m].re }
                })
                .sum()
        };
        let centre = q[MAX_NODES / 2].expect("the centre's phase");
        let carrier = C64::from_polar(1.0, k0 * d * dot(&centre, false));
        let rule = fringe::rule(self.set, level);
        let amp = nodes::level(p.amplitude_level);
        let finest = &nodes::level(nodes::FINEST).nodes;
        for (i, &j) in nodes::level(level).in_finest.iter().enumerate() {
            let k = k0 + a * finest[j];
            let qj = q[j].expect("a phase at every node of a used level");
            let residual =
                k * d * dot(&qj, false) - k0 * d * dot(&centre, false) - p.group_path * (k - k0);
            let attenuation = (-k * d * dot(&qj, true)).exp();
            let factor = C64::from_polar(attenuation, residual) * carrier;
            let wpc = rule.weight(p.group_path, i);
            for (n, l) in amp.to_finest[j].iter().enumerate() {
                if *l != 0.0 {
                    for c in 0..3 {
                        out[n][c] += factor * wpc[c] * *l;
                    }
                }
            }
        }
    }

    /// A group whose residual phase no level resolves (the chirp of a thick, strongly
    /// dispersive plate), on a shared product-integration rule of the weights
    /// ([`crate::quadrature::chebyshev`]): `ω_ic = Σ_j W_jc e^{iφ(k_j) − α(k_j)} L_i(k_j)` with its
    /// phase `φ(k) = k d Δ·Re Q(k)` and attenuation `α(k) = k d Σ·Im Q(k)` from their Chebyshev
    /// interpolants through the exact values at the nodes of [`PHASE_LEVEL`] (`Q` is analytic
    /// around the band: they converge geometrically) and its amplitude interpolated between its
    /// amplitude nodes. The rule is the smallest whose error on an oscillation as fast as the
    /// group's fastest local fringe (`max |φ'|`) meets [`NODE_ERROR`] over its strength, at most
    /// the largest rung (1024 points).
    fn dense(
        &self,
        p: &Placed,
        g: &Group,
        series: &TraversalSeries,
        chirped: &mut Vec<TraversalPhases>,
        out: &mut [[C64; 3]],
    ) {
        let (k0, a) = fringe::band();
        let d = self.s.plate.thickness_nm;
        let delta = g.delta.map(f64::from);
        let sum = g.sum.map(f64::from);
        let dot =
            |x: &[f64; 4], y: &[f64; 4]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2] + x[3] * y[3];
        let phase = TraversalSeries::combine(&series.re, &delta);
        // The fastest local fringe, d(k d f(t))/dk = d (f + k f'(t)/a), over the band.
        let fastest = (0..=16)
            .map(|s| {
                let t = -1.0 + s as f64 / 8.0;
                let (f, f1, _) = nodes::chebyshev_eval(&phase, t);
                (d * (f + (k0 + a * t) * f1 / a)).abs()
            })
            .fold(0.0, f64::max);
        let tolerance = NODE_ERROR / p.strength.max(1e-300);
        let points = chebyshev::smallest_rung(self.set, |error| {
            error(chebyshev::SPAN_MARGIN * fastest) <= tolerance
        })
        .unwrap_or(chebyshev::LADDER[chebyshev::LADDER.len() - 1]);
        let rule = chebyshev::rule(self.set, points);
        let i = match chirped.iter().position(|t| t.points == rule.nodes.len()) {
            Some(i) => i,
            None => {
                chirped.push(TraversalPhases {
                    points: rule.nodes.len(),
                    fresh: false,
                    phase: Vec::with_capacity(rule.nodes.len()),
                    attenuation: Vec::with_capacity(rule.nodes.len()),
                });
                chirped.len() - 1
            }
        };
        if !chirped[i].fresh {
            chirped[i].fill(self.s, rule, series);
        }
        let table = &chirped[i];
        let bases = chebyshev::node_basis(self.set, points, p.amplitude_level);
        let n = LEVELS[p.amplitude_level];
        let rows = rule.nodes.iter().zip(bases.chunks_exact(n));
        for (((_, w), basis), (phi, alpha)) in rows.zip(table.phase.iter().zip(&table.attenuation))
        {
            let factor = C64::from_polar((-dot(&sum, alpha)).exp(), dot(&delta, phi));
            let fw = [factor * w[0], factor * w[1], factor * w[2]];
            for (o, l) in out.iter_mut().zip(basis) {
                for c in 0..3 {
                    o[c] += fw[c] * *l;
                }
            }
        }
    }
}

/// The amplitudes of lobe `l`'s classes (0: reflection, 1: transmission).
fn lobe_amplitudes(classes: &ClassAmplitudes, l: usize) -> &[Matrix2<C64>] {
    if l == 0 {
        &classes.reflection
    } else {
        &classes.transmission
    }
}

/// True if [`Sums::Classes`] takes fewer complex products than [`Sums::Pairs`] for a lobe's
/// kept groups `placed` (the costs of [`Sums`]).
fn classes_cheaper<'a>(layout: &Layout, placed: impl Iterator<Item = &'a Placed>) -> bool {
    let (mut pairs, mut groups) = (0usize, 0usize);
    // A lobe has at most 385 classes (reflection at `MAX_ORDER`); a class beyond would only
    // be miscounted, never summed wrongly.
    let mut first = [false; 512];
    let mut classes = 0usize;
    for p in placed {
        let range = layout.groups[p.group].pairs.clone();
        pairs += range.len();
        groups += 1;
        for &(a, _) in &layout.pairs[range] {
            let seen = &mut first[(a as usize).min(first.len() - 1)];
            classes += usize::from(!*seen);
            *seen = true;
        }
    }
    12 * pairs + 48 * classes < 16 * pairs + 48 * groups
}

/// `Σ_pairs w cross(A_a, A_b)` of a group at one node (`w` = 1 for a class with itself, 2
/// otherwise), all 16 entries or only those of `M00`.
fn pair_sum(
    layout: &Layout,
    g: &Group,
    classes: &ClassAmplitudes,
    lobe: usize,
    output: Output,
) -> Matrix4<C64> {
    let amps = lobe_amplitudes(classes, lobe);
    let mut m = Matrix4::zeros();
    for &(a, b) in &layout.pairs[g.pairs.clone()] {
        let w = if a == b { 1.0 } else { 2.0 };
        cross_add(
            &mut m,
            &amps[a as usize],
            &amps[b as usize],
            w,
            output == Output::Intensity,
        );
    }
    m
}

/// The error of interpolating a group's slow factor on `n` Chebyshev–Lobatto nodes: its
/// absorption tilt `e^{−x t}` (Chebyshev coefficients `2 I_j(x) ≈ 2 (x/2)^j / j!`: the first one
/// not resolved is `j = n`) and its residual phase `e^{ict²} = e^{ic/2} e^{i(c/2) T₂(t)}`
/// (coefficients `2 J_m(c/2) ≈ 2 (c/4)^m / m!` of `T_{2m}`: the first not resolved is
/// `m = ⌊(n−1)/2⌋ + 1`), `t ∈ [−1, 1]` across the band.
fn slow_factor_error(n: usize, x: f64, c: f64) -> f64 {
    let term = |z: f64, j: usize| (1..=j).fold(2.0, |e, i| e * z / i as f64);
    term(0.5 * x, n) + term(0.25 * c, (n - 1) / 2 + 1)
}

/// The entries of a coherency that `M00` needs: `M00 = ½ Re(K₀₀ + K₀₃ + K₃₀ + K₃₃)`.
const INTENSITY_ENTRIES: [(usize, usize); 4] = [(0, 0), (0, 3), (3, 0), (3, 3)];

/// `acc += s conj(x) ⊗ y` (all 16 entries, or with `intensity` only [`INTENSITY_ENTRIES`]).
#[inline]
fn cross_add(acc: &mut Matrix4<C64>, x: &Matrix2<C64>, y: &Matrix2<C64>, s: f64, intensity: bool) {
    let xc = [
        x[(0, 0)].conj() * s,
        x[(0, 1)].conj() * s,
        x[(1, 0)].conj() * s,
        x[(1, 1)].conj() * s,
    ];
    if intensity {
        acc[(0, 0)] += xc[0] * y[(0, 0)];
        acc[(0, 3)] += xc[1] * y[(0, 1)];
        acc[(3, 0)] += xc[2] * y[(1, 0)];
        acc[(3, 3)] += xc[3] * y[(1, 1)];
        return;
    }
    // Kronecker product: entry (2 r1 + r2, 2 c1 + c2) = conj(x[r1][c1]) y[r2][c2].
    for r1 in 0..2 {
        for c1 in 0..2 {
            let xv = xc[2 * r1 + c1];
            for r2 in 0..2 {
                for c2 in 0..2 {
                    acc[(2 * r1 + r2, 2 * c1 + c2)] += xv * y[(r2, c2)];
                }
            }
        }
    }
}

/// `acc += m w` over the entries the output needs.
#[inline]
fn add_scaled(acc: &mut Matrix4<C64>, m: &Matrix4<C64>, w: C64, output: Output) {
    if output == Output::Intensity {
        for e in INTENSITY_ENTRIES {
            acc[e] += m[e] * w;
        }
    } else {
        for (a, x) in acc.as_mut_slice().iter_mut().zip(m.as_slice()) {
            *a += x * w;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cross_add_is_the_kronecker_product() {
        let x = Matrix2::new(
            C64::new(0.3, -0.2),
            C64::new(-0.1, 0.5),
            C64::new(0.7, 0.05),
            C64::new(-0.4, -0.6),
        );
        let y = Matrix2::new(
            C64::new(-0.25, 0.1),
            C64::new(0.6, -0.3),
            C64::new(0.02, 0.9),
            C64::new(0.5, 0.45),
        );
        let mut acc = Matrix4::zeros();
        cross_add(&mut acc, &x, &y, 2.0, false);
        assert!((acc - mueller::cross(&x, &y) * C64::new(2.0, 0.0)).norm() < 1e-15);
        let mut m00 = Matrix4::zeros();
        cross_add(&mut m00, &x, &y, 2.0, true);
        for e in INTENSITY_ENTRIES {
            assert!((m00[e] - acc[e]).norm() < 1e-15);
        }
    }
}
