//! The plate over the channels of a weight set with every internal order in closed form: the
//! exact plate's coherency sampled at the Chebyshev–Lobatto nodes of the band, whole or split
//! into families of pairs of orders a fixed number of round trips apart, each family's fast
//! common oscillation integrated exactly by the fringe rules of [`crate::quadrature::fringe`].
//!
//! **Families of orders.** With the internal round trip `D = r₃ P↑ r₂ P↓` and a reference phase
//! `φ(k) = G (k − k₀)` per round trip (`G` the round trip's middle group path), write
//! `D = e^{iφ} D̃`. Transmission is `J = Σₙ e^{inφ} X D̃ⁿ t₁` (`X = √f t₂ P↓`), and its coherency
//! `conj(J) ⊗ J` groups the pairs of orders `(m, m + Δ)`:
//!
//! ```text
//! K = Σ_Δ≥0 e^{iΔφ} F_Δ + Σ_Δ≥1 e^{−iΔφ} S conj(F_Δ) S,
//! F_Δ = Σ_m conj(X D̃ᵐ t₁) ⊗ X D̃^{m+Δ} t₁ = (X̄ ⊗ X) (I − D̄̃ ⊗ D̃)⁻¹ (t̄₁ ⊗ D̃^Δ t₁)
//! ```
//! (`S` swaps the Kronecker factors; the resolvent sums every order, the matrix etalon of
//! [`crate::spectral::narrow`] at real wavenumbers). Reflection is the same with
//! `Ṽ = e^{−iφ} t₃ P↑ r₂ P↓` for `X`, plus the direct `r₁` and its cross terms with each order,
//! `conj(r₁) ⊗ Ṽ D̃^{Δ−1} t₁`. `F_Δ` keeps only what differs from the reference within a
//! family (the o/e split, dispersion, absorption): slow where this method is chosen, so each
//! family integrates as `∫ w_c e^{iΔφ} F_Δ = Σ_i W_ic(ΔG) F_Δ(k_i)` on the nodes `k_i`
//! ([`crate::quadrature::fringe`]). By Cayley–Hamilton `D̃^Δ = α_Δ I + β_Δ D̃`, so every family at a
//! node comes from two solves with one factorisation, `Y₀ = (I − D̄̃ ⊗ D̃)⁻¹ (t̄₁ ⊗ t₁)` and
//! `Y₁` with `D̃ t₁`: per channel `Σ_Δ W_ic(ΔG) F_Δ(k_i) = (X̄ ⊗ X)(α Y₀ + β Y₁)` with
//! `α = Σ_Δ W_ic(ΔG) α_Δ` (and `β` likewise). Families beyond the last visible one
//! ([`crate::quadrature::fringe::FringeRule::visibility_beyond`]) are dropped; the rest is exact
//! up to the interpolation of each family's slow factor on the nodes.
//!
//! **The whole plate.** Where the plate's spectrum is slow altogether (thin plates, a plate of
//! zero thickness), no family is split off: the exact plate at each node with the weights of
//! `G = 0`, `Σ_i W_ic(0) M(k_i)`, exact for a polynomial spectrum of degree below the node count.
//!
//! **Nodes.** A pair of orders whose `n` traversals each deviate from the reference by at most
//! `δ` in group path and `x` in attenuation across the half band `a` has a slow factor varying
//! as `e^{i n (δ a + x) t}`; its weight is at most `ρ^s` (`s` the pair's round trips, `ρ` the
//! survey's bound on a round trip's norm). The level is the coarsest whose
//! [`crate::quadrature::budget::interpolation_error`], summed over the pairs with these weights,
//! meets [`crate::quadrature::budget::NODE_ERROR`].

use crate::cmath;
use crate::colour::weights::WeightSet;
use crate::error::{Error, Result};
use crate::optics::mueller;
use crate::plate::slab::{Output, SlabBlocks, SlabMueller, Want};
use crate::quadrature::budget::{DROP, NODE_ERROR};
use crate::quadrature::fringe;
use crate::quadrature::nodes::{self, LEVELS};
use crate::spectral::survey::Survey;
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;

/// Most families of orders split off (the last visible one; more: the method does not serve
/// the plate).
pub const MAX_FAMILIES: usize = 48;

/// How the envelope method integrates a plate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Envelope {
    /// The level of the nodes (index into [`LEVELS`]).
    pub level: usize,
    /// The families of orders split off; `None`: the whole plate at the nodes.
    pub families: Option<Families>,
}

/// Families of pairs of orders `Δ` round trips apart, `Δ = 0 ..= last`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Families {
    /// The reference group path of one round trip (nm).
    pub group_path: f64,
    /// The last visible family.
    pub last: usize,
}

/// What sizes the plan, from the survey (group paths in nm): the reference round trip `G`
/// (the middle, over the band, of the round trip of each direction's base mode: o, or e where
/// o is absorbed), its half range over the band (`chirp`: dispersion), the largest group path
/// difference of the two modes per traversal down and up (`split`), the attenuation tilt per
/// traversal and `ρ`.
struct Rates {
    round_trip: f64,
    chirp: f64,
    split: [f64; 2],
    tilt: f64,
    rho: f64,
    /// The survey's transient `C` (the `n`-th round trip at most `C ρⁿ`).
    transient: f64,
}

impl Rates {
    fn of(s: &Survey) -> Option<Self> {
        if s.rho.is_nan() || s.rho >= 1.0 {
            return None;
        }
        let base = |down: bool| {
            let (o, e) = if down { (0, 1) } else { (2, 3) };
            if s.live(o) {
                Some(o)
            } else if s.live(e) {
                Some(e)
            } else {
                None
            }
        };
        let (Some(bd), Some(bu)) = (base(true), base(false)) else {
            // Nothing crosses the layer: only the direct reflection is left.
            return Some(Rates {
                round_trip: 0.0,
                chirp: 0.0,
                split: [0.0; 2],
                tilt: 0.0,
                rho: 0.0,
                transient: 1.0,
            });
        };
        let (lo, hi) = s.group_path_range(|g| g[bd] + g[bu]);
        let split = [(0, 1), (2, 3)].map(|(o, e)| {
            if s.live(o) && s.live(e) {
                let (lo, hi) = s.group_path_range(|g| g[e] - g[o]);
                lo.abs().max(hi.abs())
            } else {
                0.0
            }
        });
        Some(Rates {
            round_trip: 0.5 * (lo + hi),
            chirp: 0.5 * (hi - lo),
            split,
            tilt: s.attenuation_tilt(),
            rho: s.rho,
            transient: s.transient,
        })
    }

    /// The coarsest level from `first` on whose interpolation error meets [`NODE_ERROR`], for a
    /// slow factor analytic inside the Bernstein ellipses `E_r` of the band (`t = (k − k₀)/a`)
    /// and bounded on `E_r` by `M`: the error on `n` nodes is at most `4 M r^{−n}/(r − 1)`
    /// (Trefethen, *Approximation Theory and Approximation Practice*, Thm 8.2), minimised over
    /// `r` (a geometric grid). On `E_r`, `|Im t| ≤ B = (r − 1/r)/2` and `|Re t| ≤ A = (r + 1/r)/2`;
    /// `bound` gives `M` there, or `None` where the orders no longer converge (then no larger
    /// ellipse does either).
    fn coarsest(&self, first: usize, bound: impl Fn(&Growth) -> Option<f64>) -> Option<usize> {
        let (_, a) = fringe::band();
        let mut best = [f64::INFINITY; LEVELS.len()];
        for e in ellipses() {
            let growth = Growth {
                attenuation: (2.0 * self.tilt * (e.re - 1.0)).exp(),
                split: self.split.map(|x| (x * a * e.im).exp()),
                per_nm: a * e.im,
                rho: self.rho,
            };
            // Each side of a pair of orders carries at most the transient C.
            let Some(m) = bound(&growth).map(|m| m * self.transient * self.transient) else {
                break;
            };
            for (l, b) in best.iter_mut().enumerate().skip(first) {
                *b = b.min(4.0 * m * e.inverse_powers[l] / (e.r - 1.0));
            }
            if best[first] <= NODE_ERROR {
                return Some(first);
            }
        }
        (first..LEVELS.len()).find(|&l| best[l] <= NODE_ERROR)
    }
}

/// One Bernstein ellipse `E_r`: `r`, its semi-axes `(r ± 1/r)/2` and `r^{−n}` for each level's
/// node count.
struct Ellipse {
    r: f64,
    re: f64,
    im: f64,
    inverse_powers: [f64; LEVELS.len()],
}

/// The ellipses tried, `r = 1.02 · 1.6ⁱ` up to `10⁷`, computed once.
fn ellipses() -> &'static [Ellipse] {
    static ALL: std::sync::OnceLock<Vec<Ellipse>> = std::sync::OnceLock::new();
    ALL.get_or_init(|| {
        let mut out = Vec::new();
        let mut r = 1.02f64;
        while r < 1e7 {
            out.push(Ellipse {
                r,
                re: 0.5 * (r + 1.0 / r),
                im: 0.5 * (r - 1.0 / r),
                inverse_powers: LEVELS.map(|n| r.powi(-(n as i32))),
            });
            r *= 1.6;
        }
        out
    })
}

/// How much the slow factors grow on one Bernstein ellipse (module docs). The coherency
/// `conj(X D̃ᵐ t₁) ⊗ X D̃ⁿ t₁` continues analytically as `conj(X(t̄) …) ⊗ X(t) …`: a phase common
/// to both modes cancels in each Kronecker factor of the resolvent, so a round trip of
/// `D̄̃ ⊗ D̃` grows only by its traversals' mode splits, `e^{split a |Im t|}` each, and the
/// attenuation tilt `e^{2x(|Re t| − 1)}`; what separates the families, `D̃^Δ`, also grows with the
/// round trip's own residual (its chirp, or its whole group path for the whole plate).
struct Growth {
    attenuation: f64,
    split: [f64; 2],
    per_nm: f64,
    rho: f64,
}

impl Growth {
    /// `ρ_K`, the norm of one round trip of `D̄̃ ⊗ D̃`, if below 1.
    fn kronecker(&self) -> Option<f64> {
        let k = self.rho
            * self.rho
            * self.split[0]
            * self.split[1]
            * self.attenuation
            * self.attenuation;
        (k < 1.0).then_some(k)
    }

    /// The norm of one round trip `D̃` whose own residual group path is `residual` (nm).
    fn round_trip(&self, residual: f64) -> f64 {
        self.rho * (residual * self.per_nm).exp() * self.split[0] * self.split[1] * self.attenuation
    }

    /// `‖X̄ ⊗ X‖` (and `‖V̄ ⊗ V‖`), one traversal each way.
    fn ends(&self) -> f64 {
        self.split[0] * self.split[1] * self.attenuation * self.attenuation
    }

    /// `M` of the families `0 ..= last` (each but the first twice, for its mirror) with a round
    /// trip residual of `residual`: `Σ_Δ w_Δ ρ_D^Δ ‖X̄⊗X‖/(1 − ρ_K)` and the direct reflection's
    /// cross terms `2 ρ_D^{Δ−1} ‖X̄⊗X‖`; `None` if the resolvent diverges, or (`last = None`:
    /// every family) the families do.
    fn families(&self, residual: f64, last: Option<usize>) -> Option<f64> {
        let k = self.kronecker()?;
        let d = self.round_trip(residual);
        let sum = match last {
            Some(last) => (1..=last).map(|n| d.powi(n as i32)).sum::<f64>(),
            None if d < 1.0 => d / (1.0 - d),
            None => return None,
        };
        let cross = if d > 0.0 { sum / d } else { 0.0 };
        Some(self.ends() * ((1.0 + 2.0 * sum) / (1.0 - k) + 2.0 * cross))
    }
}

/// The plan for `survey` over `set`: the whole plate or families of orders, whichever needs
/// fewer node evaluations (a family split costs about three evaluations of the plate per node);
/// `None` if neither resolves the plate on the finest level.
pub fn plan(s: &Survey, set: WeightSet) -> Option<Envelope> {
    let rates = Rates::of(s)?;
    let first = s.amplitudes.level;
    // The whole plate: every family, a round trip's whole group path in each.
    let full = rates.round_trip.abs() + rates.chirp;
    let whole = rates
        .coarsest(first, |g| g.families(full, None))
        .map(|level| Envelope {
            level,
            families: None,
        });
    if whole.is_some_and(|w| w.level == first) {
        return whole;
    }
    let split = last_family(&rates, set).and_then(|last| {
        rates
            .coarsest(first, |g| g.families(rates.chirp, Some(last)))
            .map(|level| Envelope {
                level,
                families: Some(Families {
                    group_path: rates.round_trip,
                    last,
                }),
            })
    });
    let cost = |p: &Envelope| LEVELS[p.level] as f64 * if p.families.is_some() { 3.0 } else { 1.0 };
    match (whole, split) {
        (Some(w), Some(f)) => Some(if cost(&f) < cost(&w) { f } else { w }),
        (w, f) => w.or(f),
    }
}

/// The last family `Δ` whose fringes are visible. A pair `(m, m + Δ)` fringes at `Δ` round
/// trips (each `G ± chirp` across the band) plus the mode splits of at most `2m + Δ + 1`
/// traversals, and weighs at most `2 ρ^{2m+Δ}`: the pairs of up to `m*` round trips each
/// (`ρ^{2m*}` below `10⁻² DROP` of the geometric sums) are bounded by the visibility of their
/// nearest fringe ([`fringe::FringeRule::visibility_beyond`]), the others at full visibility; the
/// families dropped stay below [`DROP`] together. `None` if the families do not separate or
/// more than [`MAX_FAMILIES`] are visible.
fn last_family(r: &Rates, set: WeightSet) -> Option<usize> {
    let rule = fringe::rule(set, 0);
    let split = r.split[0].max(r.split[1]);
    let g = r.round_trip.abs() - r.chirp - 2.0 * split;
    if g <= 0.0 {
        return None;
    }
    let geometric = r.transient * r.transient / (1.0 - r.rho * r.rho);
    let remainder = 1e-2 * DROP * (1.0 - r.rho) / geometric;
    let strong = if r.rho > 0.0 && remainder < 1.0 {
        (remainder.ln() / (2.0 * r.rho.ln())).ceil()
    } else {
        0.0
    };
    let nearest = |d: usize| d as f64 * g - (2.0 * strong + 1.0) * split;
    let bound = |d: usize| {
        2.0 * r.rho.powi(d as i32) * geometric * rule.visibility_beyond(nearest(d).max(0.0))
    };
    // Families from `end` on are invisible (their nearest fringe beyond the table) or, past
    // the cap, bounded at full visibility by the geometric rest.
    let cap = 4 * MAX_FAMILIES;
    let mut end = 1;
    while end <= cap && nearest(end) < rule.reach() {
        end += 1;
    }
    let mut rest = if end > cap {
        2.0 * r.rho.powi(end as i32) * geometric / (1.0 - r.rho)
    } else {
        0.0
    } + 0.5 * DROP;
    for d in (1..end).rev() {
        rest += bound(d);
        if rest > DROP {
            return (d <= MAX_FAMILIES).then_some(d);
        }
    }
    Some(0)
}

/// `∫ w_c M` for the channels of `set` by `plan` (module docs).
pub fn channels(
    s: &Survey,
    plan: &Envelope,
    set: WeightSet,
    want: Want,
    output: Output,
) -> Result<[SlabMueller; 3]> {
    let rule = fringe::rule(set, plan.level);
    let lv = nodes::level(plan.level);
    let (k0, a) = fringe::band();
    let mut acc = Accumulator::new(plan.families);
    for (i, (&j, t)) in lv.in_finest.iter().zip(&lv.nodes).enumerate() {
        let k = k0 + a * t;
        let mut b = s.amplitudes.interpolated(j);
        if s.plate.is_dispersive() && s.amplitudes.exact(j).is_none() {
            b.q = s.plate.layer_q(TAU / k, &s.frame, s.beta)?;
        }
        match plan.families {
            None => {
                let w = rule.weight(0.0, i);
                acc.whole(&b, k, want, output, &|c| w[c].re)?
            }
            Some(f) => acc.families(&b, k - k0, f, want, &|d| {
                rule.weight(f.group_path * d as f64, i)
            })?,
        }
    }
    Ok(acc.finish(want, output))
}

/// The sums per channel: Mueller matrices of the whole plate, or the coherencies `H` of the
/// families with the mirrored half still to add (`K = H + S conj(H) S`).
struct Accumulator {
    mueller: [[Matrix4<f64>; 2]; 3],
    half: [[Matrix4<C64>; 2]; 3],
    split: bool,
}

impl Accumulator {
    fn new(families: Option<Families>) -> Self {
        Accumulator {
            mueller: [[Matrix4::zeros(); 2]; 3],
            half: [[Matrix4::zeros(); 2]; 3],
            split: families.is_some(),
        }
    }

    /// The exact plate at wavenumber `k` with the weights `w(c) = W_ic(0)`.
    fn whole(
        &mut self,
        b: &SlabBlocks,
        k: f64,
        want: Want,
        output: Output,
        w: &dyn Fn(usize) -> f64,
    ) -> Result<()> {
        let m = b.mueller(TAU / k, want)?;
        for (c, acc) in self.mueller.iter_mut().enumerate() {
            for (lobe, x) in [m.r, m.t].iter().enumerate() {
                if let Some(x) = x {
                    match output {
                        Output::Mueller => acc[lobe] += x * w(c),
                        Output::Intensity => acc[lobe][(0, 0)] += x[(0, 0)] * w(c),
                    }
                }
            }
        }
        Ok(())
    }

    /// The families at `κ = k − k₀` (module docs), `w(Δ) = [W_ic(Δ G)]_c` of this node.
    fn families(
        &mut self,
        b: &SlabBlocks,
        kappa: f64,
        f: Families,
        want: Want,
        w: &dyn Fn(usize) -> [C64; 3],
    ) -> Result<()> {
        let (k0, _) = fringe::band();
        let (pd, pu) = b.propagation(TAU / (k0 + kappa));
        let reference = C64::from_polar(1.0, -f.group_path * kappa);
        // P↑ r₂ P↓ with the reference phase taken out.
        let trip = Matrix2::new(
            pu[0] * b.r2[(0, 0)] * pd[0],
            pu[0] * b.r2[(0, 1)] * pd[1],
            pu[1] * b.r2[(1, 0)] * pd[0],
            pu[1] * b.r2[(1, 1)] * pd[1],
        ) * reference;
        let d = cmath::mul2(&b.r3, &trip);
        let system = Matrix4::identity() - mueller::cross(&d, &d);
        let dt1 = cmath::mul2(&d, &b.t1);
        let rhs = [mueller::cross(&b.t1, &b.t1), mueller::cross(&b.t1, &dt1)];
        let y = cmath::solve4_columns(&system, &rhs).ok_or_else(|| {
            Error::new(
                "slab",
                "internal resonance: the multiple-reflection sum diverges",
            )
        })?;
        let flux = b.flux.sqrt();
        let x = Matrix2::new(
            b.t2[(0, 0)] * pd[0] * flux,
            b.t2[(0, 1)] * pd[1] * flux,
            b.t2[(1, 0)] * pd[0] * flux,
            b.t2[(1, 1)] * pd[1] * flux,
        );
        let lobes = [
            want.reflection.then(|| {
                let v = cmath::mul2(&b.t3, &trip);
                let vv = mueller::cross(&v, &v);
                let vt1 = cmath::mul2(&v, &b.t1);
                let vdt1 = cmath::mul2(&v, &dt1);
                (
                    [vv * y[0], vv * y[1]],
                    Some([
                        mueller::cross(&b.r1, &vt1),
                        mueller::cross(&b.r1, &vdt1),
                        mueller::cross(&b.r1, &b.r1),
                    ]),
                )
            }),
            want.transmission.then(|| {
                let xx = mueller::cross(&x, &x);
                ([cmath::mul4(&xx, &y[0]), cmath::mul4(&xx, &y[1])], None)
            }),
        ];
        // Per channel: α, β of Σ_Δ c_Δ D̃^Δ (c₀ halved: the mirrored half adds the other) and
        // α', β' of Σ_{Δ≥1} c_Δ D̃^{Δ−1} (the direct reflection's cross terms), with
        // D̃^Δ = α_Δ I + β_Δ D̃ by Cayley–Hamilton.
        let tr = d[(0, 0)] + d[(1, 1)];
        let det = d[(0, 0)] * d[(1, 1)] - d[(0, 1)] * d[(1, 0)];
        let zero = C64::new(0.0, 0.0);
        let w0 = w(0).map(|x| x * 0.5);
        let (mut al, mut be) = (w0, [zero; 3]);
        let (mut al1, mut be1) = ([zero; 3], [zero; 3]);
        let (mut pa, mut pb) = (C64::new(1.0, 0.0), zero); // D̃^(Δ−1)
        for dd in 1..=f.last {
            let wd = w(dd);
            let (na, nb) = (-det * pb, pa + tr * pb); // D̃^Δ
            for c in 0..3 {
                al[c] += wd[c] * na;
                be[c] += wd[c] * nb;
                al1[c] += wd[c] * pa;
                be1[c] += wd[c] * pb;
            }
            (pa, pb) = (na, nb);
        }
        for (c, half) in self.half.iter_mut().enumerate() {
            for (lobe, l) in lobes.iter().enumerate() {
                if let Some((z, cross)) = l {
                    half[lobe] += z[0] * al[c] + z[1] * be[c];
                    if let Some(r) = cross {
                        half[lobe] += r[0] * al1[c] + r[1] * be1[c] + r[2] * w0[c];
                    }
                }
            }
        }
        Ok(())
    }

    fn finish(self, want: Want, output: Output) -> [SlabMueller; 3] {
        let wanted = [want.reflection, want.transmission];
        std::array::from_fn(|c| {
            let lobe = |l: usize| {
                wanted[l].then(|| {
                    if !self.split {
                        return self.mueller[c][l];
                    }
                    let h = self.half[c][l];
                    let k = h + swap(&h.map(|z| z.conj()));
                    let m = mueller::from_coherency(&k);
                    match output {
                        Output::Mueller => m,
                        Output::Intensity => {
                            Matrix4::from_fn(|r, q| if r + q == 0 { m[(0, 0)] } else { 0.0 })
                        }
                    }
                })
            };
            SlabMueller {
                r: lobe(0),
                t: lobe(1),
            }
        })
    }
}

/// `S M S` with `S` the swap of the two Kronecker factors (indices 1 and 2 exchanged).
fn swap(m: &Matrix4<C64>) -> Matrix4<C64> {
    let p = [0, 2, 1, 3];
    Matrix4::from_fn(|i, j| m[(p[i], p[j])])
}
