//! The product-integration rule of a weight set on Chebyshev points: one rule shared by the
//! three channels, for a spectrum that varies slowly over the visible range (thin plates and
//! films, stacks; the plate's use: [`crate::spectral::pointwise`]).
//!
//! `∫ w_c(k) M(k) dk` for the channels `c` of a fitted weight set ([`gaussians`]) by product
//! integration on the weights' support `[lo, hi]` (every Gaussian's `μ ± 6σ`): `M` is sampled
//! at `N` Chebyshev points `k_j` and replaced by its interpolating polynomial, which is
//! integrated against each weight exactly, `Σ_j W_cj M(k_j)` with
//! `W_cj = (1/N) Σ_{n<N} (2 − δ_n0) T_n(t_j) μ_cn` and the weight's Chebyshev moments
//! `μ_cn = ∫ w_c(k) T_n(t(k)) dk` (computed once, in `θ = arccos t`, where every integrand is
//! smooth). Each point serves all three channels. Interpolation on Chebyshev points
//! resolves an oscillation of `Φ` radians across the support with about `Φ/2` points, and the
//! moments take the weights' own shape exactly; a composite Gauss–Legendre rule needs more
//! nodes for both (at the same tolerance, 1e-7, the random plates of `tests/spectral_shared.rs`
//! needed 56 Chebyshev points at the median against 256 Gauss–Legendre nodes).
//!
//! **How many points.** The plate's spectrum is a sum of oscillations `A(k) e^{iωk}`: the
//! direct paths' birefringent phase difference (amplitude up to 1, `ω ≤ ω_b`, the largest
//! difference of the modes' group paths), and per order `n` of internal round trips an
//! amplitude of at most `a_n = ρⁿ / (1 − ρ)²` relative to the direct light (`ρ` the spectral
//! norm of the round-trip matrix; the factor sums the pairs of paths whose orders differ by
//! `n`) at `ω ≤ n ω₁ + ω_b` (`ω₁` the largest group round trip, at the centre and the blue end
//! of the weights' bulk). The error of a rule on one oscillation is known exactly:
//! `|Σ_i w_c(k_i) e^{iωk_i} − Σ_j a_j e^{iωμ_j − σ_j²ω²/2}|` (the fitted weights' Fourier
//! transform is a sum of Gaussians), tabulated per rule over `ω`. The rule used is the
//! smallest of [`LADDER`] whose error, times each oscillation's amplitude, stays below
//! [`TOLERANCE`] for every channel (frequencies × [`SPAN_MARGIN`]): low orders, which carry the
//! light, are resolved to many digits, high orders only as far as their weight needs, and the
//! weights' shape is in the moments.
//!
//! **The points and their weights** depend only on the weight set and the number of points:
//! they are computed once per (set, rung of [`LADDER`]) and kept, with the rule's error table.

use crate::band::Gaussian;
use crate::colour::weights::{gaussians, WeightSet};
use crate::quadrature::hermite;
use crate::quadrature::nodes::{self, LEVELS, MAX_NODES};
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;
use std::sync::OnceLock;

/// Largest error (absolute, in units of the light carried by the direct paths) the rule may make
/// on any oscillation: 1/200 of the fitted weights' own error bound (the L1 norm of the fit
/// residual, 1.7e-3 to 2.8e-3 per channel, [`crate::colour::weights::fourier_error_bound`])
/// and a thousand times below a visible difference (a CIEDE2000 of 1 is ~1e-2 of the signal).
pub const TOLERANCE: f64 = 1e-5;

/// Margin on the estimated frequencies (the group round trip is evaluated at two wavenumbers;
/// elsewhere it can be larger by a few per cent).
pub const SPAN_MARGIN: f64 = 1.3;

/// Numbers of Chebyshev points of the rules (at most 1024 plate evaluations).
pub const LADDER: [usize; 25] = [
    16, 20, 24, 28, 32, 40, 48, 56, 64, 80, 96, 112, 128, 160, 192, 224, 256, 320, 384, 448, 512,
    640, 768, 896, 1024,
];

/// Chebyshev moments computed per weight set (the largest rung).
const MOMENTS: usize = 1024;

/// The points `k_j` of a product-integration rule on the weights' support, each with its
/// weight per channel.
pub struct Rule {
    /// `(k_j, [W_cj per channel])`.
    pub nodes: Vec<(f64, [f64; 3])>,
    /// The support `[lo, hi]` (wavenumbers, 1/nm).
    pub lo: f64,
    /// See `lo`.
    pub hi: f64,
    /// `error[i]`: the largest error of the rule on `e^{iωk}` over the channels and over
    /// `ω ≤ i × step` (module docs).
    error: Vec<f64>,
    /// Frequency step of `error` (nm).
    step: f64,
}

/// Frequencies tabulated per rule, up to [`PHASE_PER_POINT`] radians per point over the
/// support's half width.
const FREQUENCIES: usize = 512;
/// Beyond about one radian per point (over the half width) interpolation on Chebyshev points
/// fails (its error is of order 1); the table reaches 1.5.
const PHASE_PER_POINT: f64 = 1.5;

impl Rule {
    /// The rule's largest error on any oscillation `e^{iω'k}` with `ω' ≤ omega` (1 beyond
    /// its table).
    pub fn error_at(&self, omega: f64) -> f64 {
        let i = (omega / self.step).ceil();
        if i.is_nan() || i >= self.error.len() as f64 {
            1.0
        } else {
            self.error[i.max(0.0) as usize]
        }
    }

    /// The error table (see [`Rule::error_at`]).
    fn tabulate(set: WeightSet, nodes: &[(f64, [f64; 3])], step: f64) -> Vec<f64> {
        let i = C64::new(0.0, 1.0);
        let mut sums = vec![[C64::new(0.0, 0.0); 3]; FREQUENCIES];
        for &(k, w) in nodes {
            // e^{iωk} for ω = 0, step, 2 step, ... by repeated multiplication.
            let (turn, mut phasor) = ((i * step * k).exp(), C64::new(1.0, 0.0));
            for s in sums.iter_mut() {
                for (sc, wc) in s.iter_mut().zip(w) {
                    *sc += phasor * wc;
                }
                phasor *= turn;
            }
        }
        let mut worst = 0.0f64;
        sums.iter()
            .enumerate()
            .map(|(j, s)| {
                let omega = step * j as f64;
                for (c, sc) in s.iter().enumerate() {
                    let exact: C64 = gaussians(set, c)
                        .iter()
                        .map(|g| {
                            g.amplitude * (i * omega * g.mu - 0.5 * (g.sigma * omega).powi(2)).exp()
                        })
                        .sum();
                    worst = worst.max((sc - exact).norm());
                }
                worst
            })
            .collect()
    }
}

/// The Lagrange basis of the nodes of `level` ([`crate::quadrature::nodes`], on the visible band
/// of [`crate::quadrature::fringe::band`]) at every point of the rule of `set` with `points`
/// points (rounded up to a rung of [`LADDER`]): `basis[j][i]` for point `j` and node `i`,
/// computed once.
pub fn node_basis(set: WeightSet, points: usize, level: usize) -> &'static [[f64; MAX_NODES]] {
    const SETS: usize = WeightSet::ALL.len();
    type Basis = OnceLock<Vec<[f64; MAX_NODES]>>;
    static BASES: [[[Basis; LEVELS.len()]; LADDER.len()]; SETS] =
        [const { [const { [const { OnceLock::new() }; LEVELS.len()] }; LADDER.len()] }; SETS];
    let rung = LADDER
        .iter()
        .position(|&r| r >= points)
        .unwrap_or(LADDER.len() - 1);
    let level = level.min(LEVELS.len() - 1);
    BASES[set.index()][rung][level].get_or_init(|| {
        let (k0, a) = crate::quadrature::fringe::band();
        let x = &nodes::level(level).nodes;
        let mut basis = [C64::new(0.0, 0.0); MAX_NODES];
        rule(set, points)
            .nodes
            .iter()
            .map(|&(k, _)| {
                nodes::lagrange(x, C64::new((k - k0) / a, 0.0), &mut basis);
                std::array::from_fn(|i| if i < x.len() { basis[i].re } else { 0.0 })
            })
            .collect()
    })
}

/// The support `[lo, hi]` of a weight set: every Gaussian's `μ ± 6σ`.
pub fn support(set: WeightSet) -> (f64, f64) {
    let all = (0..3).flat_map(|c| gaussians(set, c).iter());
    let lo = all
        .clone()
        .map(|g| g.mu - 6.0 * g.sigma)
        .fold(f64::INFINITY, f64::min)
        .max(1e-6);
    let hi = all.map(|g| g.mu + 6.0 * g.sigma).fold(0.0, f64::max);
    (lo, hi)
}

/// The rule for `set` with `points` (rounded up to a rung of [`LADDER`]), computed once.
pub fn rule(set: WeightSet, points: usize) -> &'static Rule {
    const SETS: usize = WeightSet::ALL.len();
    static RULES: [[OnceLock<Rule>; LADDER.len()]; SETS] =
        [const { [const { OnceLock::new() }; LADDER.len()] }; SETS];
    let rung = LADDER
        .iter()
        .position(|&r| r >= points)
        .unwrap_or(LADDER.len() - 1);
    RULES[set.index()][rung].get_or_init(|| {
        let (lo, hi) = support(set);
        let n = LADDER[rung];
        let mu = moments(set);
        let nodes: Vec<(f64, [f64; 3])> = (0..n)
            .map(|j| {
                let t = (std::f64::consts::PI * (j as f64 + 0.5) / n as f64).cos();
                let k = 0.5 * (lo + hi) + 0.5 * (hi - lo) * t;
                // Σ_m (2 − δ_m0)/N T_m(t_j) μ_m, T_m by the recurrence (stable on [−1, 1]).
                let mut w = mu[0].map(|m0| m0 / n as f64);
                let (mut previous, mut current) = (1.0, t);
                for moment in &mu[1..n] {
                    for (wc, mc) in w.iter_mut().zip(moment) {
                        *wc += 2.0 / n as f64 * current * mc;
                    }
                    (previous, current) = (current, 2.0 * t * current - previous);
                }
                (k, w)
            })
            .collect();
        let step = PHASE_PER_POINT * n as f64 / (0.5 * (hi - lo)) / FREQUENCIES as f64;
        let error = Rule::tabulate(set, &nodes, step);
        Rule {
            nodes,
            lo,
            hi,
            error,
            step,
        }
    })
}

/// The Chebyshev moments `μ_cn = ∫ w_c(k) T_n(t(k)) dk` of a weight set on its support,
/// `n < `[`MOMENTS`], computed once: in `θ` (`t = cos θ`, `dk = (hi − lo)/2 sin θ dθ`) by
/// 2048 panels of 8-point Gauss–Legendre over `[0, π]` (at least 4 panels per period of
/// `cos(nθ)`: exact to rounding).
fn moments(set: WeightSet) -> &'static [[f64; 3]] {
    const SETS: usize = WeightSet::ALL.len();
    static MOMENTS_OF: [OnceLock<Vec<[f64; 3]>>; SETS] = [const { OnceLock::new() }; SETS];
    MOMENTS_OF[set.index()].get_or_init(|| {
        let (lo, hi) = support(set);
        let mut mu = vec![[0.0; 3]; MOMENTS];
        for (theta, w) in hermite::composite_interval(0.0, std::f64::consts::PI, 2048) {
            let t = theta.cos();
            let k = 0.5 * (lo + hi) + 0.5 * (hi - lo) * t;
            let jac = w * 0.5 * (hi - lo) * theta.sin();
            let weight = [0, 1, 2].map(|c| {
                jac * gaussians(set, c)
                    .iter()
                    .map(|g| g.amplitude * normal_pdf(k, g))
                    .sum::<f64>()
            });
            // T_n(t) = cos(nθ) by the recurrence.
            let (mut previous, mut current) = (1.0, t);
            for (n, m) in mu.iter_mut().enumerate() {
                let tn = if n == 0 { 1.0 } else { current };
                for (mc, wc) in m.iter_mut().zip(weight) {
                    *mc += tn * wc;
                }
                if n > 0 {
                    (previous, current) = (current, 2.0 * t * current - previous);
                }
            }
        }
        mu
    })
}

/// The unit-mass normal density `G(k; μ, σ)`.
fn normal_pdf(k: f64, g: &Gaussian) -> f64 {
    let z = (k - g.mu) / g.sigma;
    (-0.5 * z * z).exp() / (g.sigma * TAU.sqrt())
}

/// The smallest rung of [`LADDER`] whose rule integrates oscillations of amplitude 1 up to
/// `omega_b` and of amplitude `a_n` up to `n omega_1 + omega_b` to [`TOLERANCE`] (module docs).
pub fn points(set: WeightSet, omega_1: f64, omega_b: f64, rho: f64) -> Option<usize> {
    if !(omega_1.is_finite() && omega_b.is_finite() && (0.0..1.0).contains(&rho)) {
        return None;
    }
    let enough = |p: usize| {
        let rule = rule(set, p);
        let fits = |amplitude: f64, omega: f64| {
            amplitude * rule.error_at(SPAN_MARGIN * omega) <= TOLERANCE
        };
        if !fits(1.0, omega_b) {
            return false;
        }
        let mut a = 1.0 / ((1.0 - rho) * (1.0 - rho));
        for n in 1.. {
            a *= rho;
            if a <= TOLERANCE {
                return true;
            }
            if !fits(a, n as f64 * omega_1 + omega_b) {
                return false;
            }
        }
        unreachable!()
    };
    // More points integrate every oscillation better, so the rungs that suffice are a suffix
    // of the ladder: bisect (a few rungs checked, each check walks the orders), and confirm.
    let first = LADDER.partition_point(|&p| !enough(p));
    LADDER
        .get(first)
        .copied()
        .filter(|&p| enough(p))
        .or_else(|| LADDER.iter().copied().find(|&p| enough(p)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tabulated error is the rule's: a direct evaluation at frequencies off the grid stays
    /// below the table's value for them (the table is a running maximum over its grid).
    #[test]
    fn error_table_bounds_the_rule() {
        for set in WeightSet::ALL {
            let r = rule(set, 16);
            for j in 0..50 {
                let omega = r.step * (0.37 + 7.3 * j as f64);
                for c in 0..3 {
                    let sum: C64 = r
                        .nodes
                        .iter()
                        .map(|&(k, w)| C64::new(0.0, omega * k).exp() * w[c])
                        .sum();
                    let exact: C64 = gaussians(set, c)
                        .iter()
                        .map(|g| {
                            g.amplitude
                                * C64::new(-0.5 * (g.sigma * omega).powi(2), omega * g.mu).exp()
                        })
                        .sum();
                    // Between grid points the error can exceed the grid's running maximum only
                    // by its variation over one step (tiny: 512 steps per rule's range).
                    let e = (sum - exact).norm();
                    assert!(
                        e <= 1.5 * r.error_at(omega) + 1e-12,
                        "{set:?} {c} {omega}: {e}"
                    );
                }
            }
        }
    }

    #[test]
    fn points_grow_with_frequency_and_round_trip() {
        let set = WeightSet::SrgbD65;
        let thin = points(set, 20.0 / 0.011, 0.0, 0.1).unwrap();
        assert!(points(set, 40.0 / 0.011, 0.0, 0.1).unwrap() >= thin);
        assert!(points(set, 20.0 / 0.011, 0.0, 0.5).unwrap() >= thin);
        assert_eq!(points(set, 1e9, 0.0, 0.1), None);
        assert_eq!(points(set, f64::NAN, 0.0, 0.1), None);
        assert_eq!(points(set, 1.0, 0.0, 1.0), None);
    }
}
