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
//! What a first query would otherwise spend most of its time building (the weights' moments, the
//! error tables, the rules from 256 points) is computed ahead, stored in `chebyshev_tables.bin`
//! and checked against a fresh computation by a unit test ([`tabulate`]).

use crate::band::Gaussian;
use crate::colour::weights::{gaussians, WeightSet};
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

/// Chebyshev moments computed per weight set: those the largest rung's error bound reads (its
/// frequencies up to [`PHASE_PER_POINT`] radians per point, and the Bessel terms beyond them,
/// [`bessel_j`]).
const MOMENTS: usize = 1792;
/// Samples of the weights on Chebyshev points for their Chebyshev series ([`moments`]).
const SAMPLES: usize = 1024;
/// Terms of that series (under `xyz-d65`, the narrowest Gaussians, they fall to 4e-13 of the
/// largest by 640 and to rounding by 768: `tests::moments_are_converged`).
const SERIES: usize = 800;

/// The points `k_j` of a product-integration rule on the weights' support, each with its
/// weight per channel.
pub struct Rule {
    /// `(k_j, [W_cj per channel])`.
    pub nodes: Vec<(f64, [f64; 3])>,
    /// The support `[lo, hi]` (wavenumbers, 1/nm).
    pub lo: f64,
    /// See `lo`.
    pub hi: f64,
    /// The number of points.
    n: usize,
    /// The weight set.
    set: WeightSet,
}

/// The largest rung whose own error table [`smallest_rung`] builds (512 Bessel series of about
/// `2.5 n` terms each: 3 million operations at 256 points, 50 million at 1024).
const EXACT_RUNGS: usize = 256;

/// Frequencies tabulated per rung, up to [`PHASE_PER_POINT`] radians per point over the
/// support's half width.
const FREQUENCIES: usize = 512;
/// Beyond about one radian per point (over the half width) interpolation on Chebyshev points
/// fails (its error is of order 1); the table reaches 1.5.
const PHASE_PER_POINT: f64 = 1.5;

impl Rule {
    /// The rule's largest error on any oscillation `e^{iω'k}` with `ω' ≤ omega` (1 beyond
    /// its table): [`error_bound`].
    pub fn error_at(&self, omega: f64) -> f64 {
        error_bound(self.set, self.n, omega)
    }
}

/// The largest error of the rule of `set` with `points` points (rounded up to a rung of
/// [`LADDER`]) on any oscillation `e^{iω'k}` with `|ω'| ≤ omega` (on a grid of [`FREQUENCIES`]
/// up to [`PHASE_PER_POINT`] radians per point; 1 beyond), of any channel, from a table per rung
/// computed without the rule itself (stored for the rungs up to 256 points, built on first
/// use above). The rule integrates the polynomials of degree
/// `< n` exactly; with `k = c + h t` and `e^{ixt} = Σ_m ε_m i^m J_m(x) T_m(t)` (`x = ωh`) its
/// error is `|Σ_{m≥n} ε_m i^m J_m(x) (μ̃_m − μ_m)|`, `μ_m` the weight's Chebyshev moments and
/// `μ̃_m` the rule's, which on the `n` Chebyshev points are `±μ_r` for the alias `r < n` of `m`
/// (`T_{2qn ± r}(t_j) = (−1)^q T_r(t_j)`, `T_n(t_j) = 0`); the table is its running maximum
/// over the grid.
pub fn error_bound(set: WeightSet, points: usize, omega: f64) -> f64 {
    lookup(set, points, omega, false)
}

/// A cheap rigorous upper bound of [`error_bound`] (its table from bounds on `|J_m|` instead of
/// the Bessel functions: Landau's `|J_m(x)| ≤ 0.674885 m^{−1/3}` below `x`, and from `x` on the
/// smaller of that and Kapteyn's `J_m(m z) ≤ (z e^{√(1−z²)}/(1 + √(1−z²)))^m`, then
/// `J_{m+1}/J_m < x/(2(m + 1) − x)`; each constant or increasing in `x`, so the bound at `ω`
/// covers every `ω' ≤ ω`), cheap enough for a bisection of the ladder ([`smallest_rung`]).
pub fn error_ceiling(set: WeightSet, points: usize, omega: f64) -> f64 {
    lookup(set, points, omega, true)
}

/// The smallest rung of [`LADDER`] of `set` for which `serves(error)` holds, `error(ω)` the rule's
/// error ([`error_bound`]), assuming more points serve better: bisected on the cheap
/// [`error_ceiling`] (what it accepts, the rule's own error accepts), then walked down rung by
/// rung on the rule's own error, so that only the rungs near the answer build their tables.
pub fn smallest_rung(
    set: WeightSet,
    serves: impl Fn(&dyn Fn(f64) -> f64) -> bool,
) -> Option<usize> {
    let by = |p: usize, ceiling: bool| {
        serves(&|omega| {
            if ceiling {
                error_ceiling(set, p, omega)
            } else {
                error_bound(set, p, omega)
            }
        })
    };
    let first = LADDER.partition_point(|&p| !by(p, true));
    let hi = LADDER
        .get(first)
        .copied()
        .filter(|&p| by(p, true))
        .or_else(|| LADDER.iter().copied().find(|&p| by(p, true)));
    // Below the ceiling's answer, the rule's own error, on the rungs whose tables are cheap
    // (beyond, the ceiling's answer stands: its table is a few times the rule's error there,
    // about one rung).
    let top = hi.map_or(0, |p| LADDER.iter().position(|&r| r == p).unwrap_or(0));
    let mut best = hi;
    for &p in LADDER[..top].iter().rev().filter(|&&p| p <= EXACT_RUNGS) {
        if by(p, false) {
            best = Some(p);
        } else {
            break;
        }
    }
    best
}

fn lookup(set: WeightSet, points: usize, omega: f64, ceiling: bool) -> f64 {
    const SETS: usize = WeightSet::ALL.len();
    type Table = OnceLock<(f64, Vec<f64>)>;
    static TABLES: [[[Table; 2]; LADDER.len()]; SETS] =
        [const { [const { [const { OnceLock::new() }; 2] }; LADDER.len()] }; SETS];
    let rung = LADDER
        .iter()
        .position(|&r| r >= points)
        .unwrap_or(LADDER.len() - 1);
    if let Some(stored) = stored_table(set, rung, ceiling) {
        let i = (omega.abs() / table_step(set, LADDER[rung])).ceil();
        return if i.is_nan() || i >= FREQUENCIES as f64 {
            1.0
        } else {
            stored.at(i as usize)
        };
    }
    let (step, table) = TABLES[set.index()][rung][usize::from(ceiling)]
        .get_or_init(|| error_table(set, LADDER[rung], ceiling, moments(set)));
    let i = (omega.abs() / step).ceil();
    if i.is_nan() || i >= table.len() as f64 {
        1.0
    } else {
        table[i as usize]
    }
}

/// The frequency step of the error tables of `n` points of `set`.
fn table_step(set: WeightSet, n: usize) -> f64 {
    let (lo, hi) = support(set);
    PHASE_PER_POINT * n as f64 / (0.5 * (hi - lo)) / FREQUENCIES as f64
}

/// The tables a first query would otherwise build (about 140 million instructions of the 174
/// million of a 130 um rutile plate's first query), computed once by [`tabulate`] and stored in
/// `chebyshev_tables.bin` (`cargo run --release --example chebyshev_tables` writes it;
/// `tests::stored_tables_are_current` recomputes it): per weight set, in the order of
/// [`WeightSet::ALL`], its [`MOMENTS`] Chebyshev moments (three channels each), the rule's own
/// error table ([`error_bound`]) of every rung up to [`EXACT_RUNGS`] (the only ones
/// [`smallest_rung`] reads), and the ceiling's ([`error_ceiling`]) of every rung, [`FREQUENCIES`]
/// values each, and the weights of every rule from 256 points ([`rule`]); `f64`, little-endian.
static STORED: &[u8] = include_bytes!("chebyshev_tables.bin");

/// Rungs of [`LADDER`] whose rule's own error table is stored.
const STORED_EXACT: usize = {
    let mut i = 0;
    while i < LADDER.len() && LADDER[i] <= EXACT_RUNGS {
        i += 1;
    }
    i
};

/// The first rung of [`LADDER`] whose rule's weights are stored (from 256 points: below, a rule
/// costs under a million operations to build, above up to 13 million).
const STORED_RULES: usize = STORED_EXACT - 1;

/// Where the stored rules start in a set's block, and how many `f64`s they take.
const RULES_AT: usize = 3 * MOMENTS + (STORED_EXACT + LADDER.len()) * FREQUENCIES;
const RULES_LEN: usize = {
    let (mut i, mut len) = (STORED_RULES, 0);
    while i < LADDER.len() {
        len += 3 * LADDER[i];
        i += 1;
    }
    len
};

/// `f64`s stored per weight set.
const STORED_PER_SET: usize = RULES_AT + RULES_LEN;

/// A run of stored `f64`s.
#[derive(Clone, Copy)]
struct Stored(&'static [u8]);

impl Stored {
    fn at(self, i: usize) -> f64 {
        let b = &self.0[8 * i..8 * i + 8];
        f64::from_le_bytes(b.try_into().expect("eight bytes"))
    }
}

/// `len` stored values from value `start` of `set`'s block; `None` where the file does not hold
/// every set's block (while it is being written: then everything is computed).
fn stored(set: WeightSet, start: usize, len: usize) -> Option<Stored> {
    if STORED.len() != 8 * STORED_PER_SET * WeightSet::ALL.len() {
        return None;
    }
    let base = 8 * (set.index() * STORED_PER_SET + start);
    Some(Stored(&STORED[base..base + 8 * len]))
}

/// The stored error table of `set` at `rung` (the ceiling's with `ceiling`), if stored.
fn stored_table(set: WeightSet, rung: usize, ceiling: bool) -> Option<Stored> {
    let index = if ceiling {
        STORED_EXACT + rung
    } else if rung < STORED_EXACT {
        rung
    } else {
        return None;
    };
    stored(set, 3 * MOMENTS + index * FREQUENCIES, FREQUENCIES)
}

/// The stored weights of the rule of `set` at `rung` (`3 j + c` for point `j`, channel `c`), if
/// stored.
fn stored_rule(set: WeightSet, rung: usize) -> Option<Stored> {
    if rung < STORED_RULES {
        return None;
    }
    let start = RULES_AT + LADDER[STORED_RULES..rung].iter().sum::<usize>() * 3;
    stored(set, start, 3 * LADDER[rung])
}

/// What `chebyshev_tables.bin` holds ([`STORED`]), computed: the moments from the weights' fits
/// ([`computed_moments`]) and the error tables from them ([`error_table`]).
#[doc(hidden)]
pub fn tabulate() -> Vec<u8> {
    let mut out = Vec::with_capacity(8 * STORED_PER_SET * WeightSet::ALL.len());
    for set in WeightSet::ALL {
        let mu = computed_moments(set);
        let values = mu
            .iter()
            .flatten()
            .copied()
            .chain((0..STORED_EXACT).flat_map(|r| error_table(set, LADDER[r], false, &mu).1))
            .chain((0..LADDER.len()).flat_map(|r| error_table(set, LADDER[r], true, &mu).1))
            .chain((STORED_RULES..LADDER.len()).flat_map(|r| {
                let w = rule_weights(LADDER[r], &mu);
                (0..LADDER[r]).flat_map(move |j| [w[0][j], w[1][j], w[2][j]])
            }));
        for v in values {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// The table of [`error_bound`] (or, with `ceiling`, of [`error_ceiling`]) for `n` points: its
/// frequency step and the running maximum of the error (or the bound) at each multiple of it.
fn error_table(set: WeightSet, n: usize, ceiling: bool, mu: &[[f64; 3]]) -> (f64, Vec<f64>) {
    let (lo, hi) = support(set);
    let h = 0.5 * (hi - lo);
    // d_m = μ̃_m − μ_m per channel.
    let d: Vec<[f64; 3]> = (0..MOMENTS)
        .map(|m| {
            let (q, r) = (m / (2 * n), m % (2 * n));
            let sign = if q % 2 == 0 { 1.0 } else { -1.0 };
            let alias = match r.cmp(&n) {
                std::cmp::Ordering::Less => mu[r].map(|x| sign * x),
                std::cmp::Ordering::Equal => [0.0; 3],
                std::cmp::Ordering::Greater => mu[2 * n - r].map(|x| -sign * x),
            };
            std::array::from_fn(|c| if m < n { 0.0 } else { alias[c] - mu[m][c] })
        })
        .collect();
    let step = table_step(set, n);
    let mut below = vec![[0.0; 3]; MOMENTS + 1];
    if ceiling {
        for m in 0..MOMENTS {
            let l = 2.0 * landau(m);
            below[m + 1] = std::array::from_fn(|c| below[m][c] + l * d[m][c].abs());
        }
    }
    let mut bessel = Vec::new();
    let mut worst = 0.0f64;
    let table = (0..FREQUENCIES)
        .map(|s| {
            let x = step * s as f64 * h;
            if ceiling {
                worst = worst.max(ceiling_at(x, n, &d, &below));
                return worst;
            }
            bessel_j(x, &mut bessel);
            // Σ_{m≥n} ε_m i^m J_m(x) d_cm per channel (i^m cycles through 1, i, −1, −i).
            let mut e = [C64::new(0.0, 0.0); 3];
            let top = bessel.len().min(MOMENTS);
            for (m, (jm, dm)) in bessel.iter().zip(&d).enumerate().take(top).skip(n) {
                let im = [
                    C64::new(1.0, 0.0),
                    C64::new(0.0, 1.0),
                    C64::new(-1.0, 0.0),
                    C64::new(0.0, -1.0),
                ][m % 4];
                let f = im * (if m == 0 { 1.0 } else { 2.0 } * jm);
                for (ec, dc) in e.iter_mut().zip(dm) {
                    *ec += f * *dc;
                }
            }
            worst = e.iter().fold(worst, |w, v| w.max(v.norm()));
            worst
        })
        .collect();
    (step, table)
}

/// The bound of [`error_ceiling`] at `x` for `n` points and the moment differences `d`, with
/// `below[m]` the prefix sums of `2 L_m |d_m|` (the terms below `x`).
fn ceiling_at(x: f64, n: usize, d: &[[f64; 3]], below: &[[f64; 3]]) -> f64 {
    let first = (x.ceil() as usize).max(n).min(d.len());
    let mut e: [f64; 3] = std::array::from_fn(|c| below[first][c] - below[n.min(first)][c]);
    let mut k = kapteyn(first, x).min(landau(first));
    for (m, dm) in d.iter().enumerate().skip(first) {
        for (ec, dc) in e.iter_mut().zip(dm) {
            *ec += 2.0 * k * dc.abs();
        }
        k *= x / (2.0 * (m + 1) as f64 - x);
        // The moments are at most ~1: what is left is below any tolerance asked.
        if k < 1e-20 {
            break;
        }
    }
    e.iter().fold(0.0, |w, &v| w.max(v))
}

/// Landau's bound on `|J_m(x)|` for every `x`: `0.674885 m^{−1/3}` (L. Landau, "Monotonicity and
/// bounds on Bessel functions", Electron. J. Differ. Equ. Conf. 4, 2000), 1 for `m = 0`.
fn landau(m: usize) -> f64 {
    if m == 0 {
        1.0
    } else {
        (0.674_885 * (m as f64).powf(-1.0 / 3.0)).min(1.0)
    }
}

/// Kapteyn's bound on `J_m(x)` for `0 ≤ x ≤ m`: `(z e^{√(1−z²)}/(1 + √(1−z²)))^m`, `z = x/m`
/// (Watson, *A Treatise on the Theory of Bessel Functions*, §8.7).
fn kapteyn(m: usize, x: f64) -> f64 {
    if m == 0 {
        return 1.0;
    }
    let z = (x / m as f64).min(1.0);
    if z <= 0.0 {
        return 0.0;
    }
    let s = (1.0 - z * z).sqrt();
    (m as f64 * (z.ln() + s - (1.0 + s).ln())).exp()
}

/// `J_m(x)` for `m = 0 ..` into `out`, as far as they matter (`m` beyond `x + 40 + 12 x^{1/3}`,
/// where they are below 1e-30), by Miller's backward recurrence `J_{m−1} = (2m/x) J_m − J_{m+1}`
/// from a negligible start, normalised by `J_0 + 2 Σ_k J_{2k} = 1` (Abramowitz & Stegun,
/// *Handbook of Mathematical Functions*, 9.12; stable downwards, rescaled against overflow).
fn bessel_j(x: f64, out: &mut Vec<f64>) {
    out.clear();
    if x <= 0.0 {
        out.push(1.0);
        return;
    }
    let top = ((x + 40.0 + 12.0 * x.cbrt()).ceil() as usize + 1) & !1;
    out.resize(top + 2, 0.0);
    out[top] = 1e-280;
    for m in (1..=top).rev() {
        out[m - 1] = 2.0 * m as f64 / x * out[m] - out[m + 1];
        if out[m - 1].abs() > 1e250 {
            out[m - 1..].iter_mut().for_each(|v| *v *= 1e-250);
        }
    }
    let norm = out[0] + 2.0 * out.iter().skip(2).step_by(2).sum::<f64>();
    out.truncate(top);
    out.iter_mut().for_each(|v| *v /= norm);
}

/// The Lagrange basis of the nodes of `level` ([`crate::quadrature::nodes`], on the visible band
/// of [`crate::quadrature::fringe::band`]) at every point of the rule of `set` with `points`
/// points (rounded up to a rung of [`LADDER`]): `basis[j n + i]` for point `j` and node `i`
/// of the level's `n`, computed once.
pub fn node_basis(set: WeightSet, points: usize, level: usize) -> &'static [f64] {
    const SETS: usize = WeightSet::ALL.len();
    type Basis = OnceLock<Vec<f64>>;
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
            .flat_map(|&(k, _)| {
                nodes::lagrange(x, C64::new((k - k0) / a, 0.0), &mut basis);
                basis[..x.len()].iter().map(|b| b.re).collect::<Vec<f64>>()
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
        let t = points_on_interval(n);
        let w = match stored_rule(set, rung) {
            Some(s) => std::array::from_fn(|c| (0..n).map(|j| s.at(3 * j + c)).collect()),
            None => rule_weights(n, moments(set)),
        };
        let nodes: Vec<(f64, [f64; 3])> = (0..n)
            .map(|j| {
                let k = 0.5 * (lo + hi) + 0.5 * (hi - lo) * t[j];
                (k, [w[0][j], w[1][j], w[2][j]])
            })
            .collect();
        Rule {
            nodes,
            lo,
            hi,
            n,
            set,
        }
    })
}

/// The `n` Chebyshev points `t_j = cos(π (j + ½)/n)` on `[−1, 1]`.
fn points_on_interval(n: usize) -> Vec<f64> {
    (0..n)
        .map(|j| (std::f64::consts::PI * (j as f64 + 0.5) / n as f64).cos())
        .collect()
}

/// The weights `W_cj` of the rule of `n` points from the moments `mu`, per channel.
fn rule_weights(n: usize, mu: &[[f64; 3]]) -> [Vec<f64>; 3] {
    // W_cj = Σ_m (2 − δ_m0)/N T_m(t_j) μ_cm, T_m(t_j) by the recurrence (stable on
    // [−1, 1]), a whole column of points per degree (channel by channel: contiguous loops).
    let t = points_on_interval(n);
    let mut w = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    let (mut previous, mut current) = (vec![1.0; n], t.clone());
    for (c, wc) in w.iter_mut().enumerate() {
        wc.iter_mut().for_each(|x| *x = mu[0][c] / n as f64);
    }
    for moment in &mu[1..n] {
        for (c, wc) in w.iter_mut().enumerate() {
            let scale = 2.0 / n as f64 * moment[c];
            for (x, tm) in wc.iter_mut().zip(&current) {
                *x += scale * tm;
            }
        }
        for ((p, q), tj) in previous.iter_mut().zip(current.iter_mut()).zip(&t) {
            let next = 2.0 * tj * *q - *p;
            (*p, *q) = (*q, next);
        }
    }
    w
}

/// The Chebyshev moments `μ_cn = ∫ w_c(k) T_n(t(k)) dk` of a weight set on its support,
/// `n < `[`MOMENTS`], computed once: the weight `f_c(t) = h w_c(c + h t)` (`h` the half width)
/// is expanded in its Chebyshev series ([`SERIES`] terms) from [`SAMPLES`] samples on Chebyshev
/// points,
/// `a_j = (2 − δ_j0)/S Σ_i f(t_i) T_j(t_i)` (spectrally accurate: the Gaussians of the fits span
/// a few hundred coefficients of the support; `tests::moments_are_converged`), and
/// `μ_n = Σ_j a_j ∫ T_j T_n dt` with `∫_{−1}^{1} T_j T_n = (I_{j+n} + I_{|j−n|})/2`,
/// `I_m = 2/(1 − m²)` for even `m`, 0 for odd.
///
/// Read from [`STORED`] (computed there by [`computed_moments`]).
fn moments(set: WeightSet) -> &'static [[f64; 3]] {
    const SETS: usize = WeightSet::ALL.len();
    static MOMENTS_OF: [OnceLock<Vec<[f64; 3]>>; SETS] = [const { OnceLock::new() }; SETS];
    MOMENTS_OF[set.index()].get_or_init(|| match stored(set, 0, 3 * MOMENTS) {
        Some(s) => (0..MOMENTS)
            .map(|m| std::array::from_fn(|c| s.at(3 * m + c)))
            .collect(),
        None => computed_moments(set),
    })
}

/// The moments of [`moments`], computed from the weights' fits.
fn computed_moments(set: WeightSet) -> Vec<[f64; 3]> {
    let a = series(set);
    // ∫ T_m = 2/(1 − m²) for even m, 0 for odd m.
    let integral: Vec<f64> = (0..SERIES + MOMENTS)
        .map(|m| {
            if m % 2 == 1 {
                0.0
            } else {
                2.0 / (1.0 - (m * m) as f64)
            }
        })
        .collect();
    // μ_cn = ½ Σ_j a_jc (I_{j+n} + I_{|j−n|}) over the j of n's parity (the others vanish),
    // channel by channel over contiguous slices.
    let column = |c: usize, parity: usize| -> Vec<f64> {
        a.iter().skip(parity).step_by(2).map(|x| x[c]).collect()
    };
    let columns: [[Vec<f64>; 3]; 2] = [0, 1].map(|p| [0, 1, 2].map(|c| column(c, p)));
    let mut mu = vec![[0.0; 3]; MOMENTS];
    let mut kernel = vec![0.0; SERIES.div_ceil(2)];
    for (n, m) in mu.iter_mut().enumerate() {
        let parity = n % 2;
        let cols = &columns[parity];
        for (i, k) in kernel.iter_mut().enumerate().take(cols[0].len()) {
            let j = 2 * i + parity;
            *k = 0.5 * (integral[j + n] + integral[j.abs_diff(n)]);
        }
        for (mc, col) in m.iter_mut().zip(cols) {
            *mc = dot(col, &kernel[..col.len()]);
        }
    }
    mu
}

/// `Σ x_i y_i` with four partial sums (so that the loop vectorises).
fn dot(x: &[f64], y: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (xs, ys) = (x.chunks_exact(4), y.chunks_exact(4));
    let tail: f64 = xs
        .remainder()
        .iter()
        .zip(ys.remainder())
        .map(|(a, b)| a * b)
        .sum();
    for (a, b) in xs.zip(ys) {
        for k in 0..4 {
            acc[k] += a[k] * b[k];
        }
    }
    acc.iter().sum::<f64>() + tail
}

/// The Chebyshev coefficients `a_jc`, `j <` [`SERIES`], of `h w_c(c + h t)` on the support (see
/// [`moments`]).
fn series(set: WeightSet) -> Vec<[f64; 3]> {
    let (lo, hi) = support(set);
    let (centre, h) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    let s = SAMPLES;
    let samples: Vec<(f64, [f64; 3])> = (0..s)
        .map(|i| {
            let t = (std::f64::consts::PI * (i as f64 + 0.5) / s as f64).cos();
            let k = centre + h * t;
            let f = [0, 1, 2].map(|c| {
                h * gaussians(set, c)
                    .iter()
                    .map(|g| g.amplitude * normal_pdf(k, g))
                    .sum::<f64>()
            });
            (t, f)
        })
        .collect();
    let mut a = vec![[0.0; 3]; SERIES];
    for &(t, f) in &samples {
        // T_j(t) by the recurrence.
        let (mut previous, mut current) = (1.0, t);
        for (j, aj) in a.iter_mut().enumerate() {
            let tj = if j == 0 { 1.0 } else { current };
            for (x, fc) in aj.iter_mut().zip(f) {
                *x += tj * fc;
            }
            if j > 0 {
                (previous, current) = (current, 2.0 * t * current - previous);
            }
        }
    }
    for (j, aj) in a.iter_mut().enumerate() {
        let scale = if j == 0 { 1.0 } else { 2.0 } / s as f64;
        aj.iter_mut().for_each(|x| *x *= scale);
    }
    a
}

/// The unit-mass normal density `G(k; μ, σ)`.
fn normal_pdf(k: f64, g: &Gaussian) -> f64 {
    let z = (k - g.mu) / g.sigma;
    (-0.5 * z * z).exp() / (g.sigma * TAU.sqrt())
}

/// The smallest rung of [`LADDER`] whose rule integrates oscillations of amplitude 1 up to
/// `omega_b` and of amplitude `a_n` up to `n omega_1 + omega_b` to [`TOLERANCE`] (module docs;
/// `a_n = C² ρⁿ/(1 − ρ)²` with the transient `C` of a round trip's first powers, 1 where `ρ`
/// bounds every power).
pub fn points(
    set: WeightSet,
    omega_1: f64,
    omega_b: f64,
    rho: f64,
    transient: f64,
) -> Option<usize> {
    if !(omega_1.is_finite() && omega_b.is_finite() && (0.0..1.0).contains(&rho)) {
        return None;
    }
    smallest_rung(set, |error| {
        let fits = |amplitude: f64, omega: f64| amplitude * error(SPAN_MARGIN * omega) <= TOLERANCE;
        if !fits(1.0, omega_b) {
            return false;
        }
        let mut a = transient * transient / ((1.0 - rho) * (1.0 - rho));
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
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tabulated error is the rule's (computed without the rule, from Bessel functions and
    /// the weights' moments): a direct evaluation of the rule on oscillations at frequencies on
    /// and off the table's grid, for small and large rungs, against the fits' exact Fourier
    /// transforms, stays below the table's value for them, and reaches it.
    #[test]
    fn error_table_is_the_rules() {
        for set in WeightSet::ALL {
            let (lo, hi) = support(set);
            let h = 0.5 * (hi - lo);
            for n in [16, 64, 256, 1024] {
                let r = rule(set, n);
                let (mut worst_ratio, mut tightest) = (0.0f64, f64::INFINITY);
                for j in 0..60 {
                    // Up to the table's end, 1.5 radians per point (beyond, the bound is 1).
                    let omega = (0.013 + 1.48 * j as f64 / 59.0) * n as f64 / h;
                    let bound = error_bound(set, n, omega);
                    let ceiling = error_ceiling(set, n, omega);
                    assert!(
                        ceiling >= bound,
                        "{set:?} n {n} omega {omega}: {ceiling:e} < {bound:e}"
                    );
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
                        // The fits' mass outside the support (below 1e-8) is not in the moments;
                        // between grid points the error can exceed the grid's running maximum by
                        // its variation over one step (512 steps per table).
                        let e = (sum - exact).norm();
                        let bound = 1.5 * bound;
                        assert!(
                            e <= bound + 1e-8,
                            "{set:?} n {n} c {c} omega {omega}: {e:e} > {bound:e}"
                        );
                        if e > 1e-6 {
                            worst_ratio = worst_ratio.max(e / bound);
                            tightest = tightest.min(bound / e);
                        }
                    }
                }
                assert_eq!(error_bound(set, n, 1.51 * n as f64 / h), 1.0);
                println!("{set:?} n {n}: error/bound at most {worst_ratio:.3}, bound/error at least {tightest:.2}");
                if n < 1024 {
                    assert!(worst_ratio > 0.5, "{set:?} n {n}: the table is loose");
                }
            }
        }
    }

    /// The moments from the weights' Chebyshev series equal an independent dense quadrature in
    /// `θ` (`t = cos θ`, 2048 panels of 8-point Gauss–Legendre over `[0, π]`, at least 4 panels
    /// per period of `cos(nθ)`), and the series has converged (its last coefficients are at
    /// rounding level).
    #[test]
    fn moments_are_converged() {
        for set in WeightSet::ALL {
            let a = series(set);
            let largest = a.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
            let last = a[SERIES - 16..]
                .iter()
                .flatten()
                .fold(0.0f64, |m, x| m.max(x.abs()));
            // Rounding of the sums.
            assert!(last < 1e-13 * largest, "{set:?}: {last:e} of {largest:e}");
            let (lo, hi) = support(set);
            let mu = moments(set);
            let mut worst = 0.0f64;
            let rule =
                crate::quadrature::hermite::composite_interval(0.0, std::f64::consts::PI, 2048);
            for n in [0, 1, 2, 7, 100, 333, 1000, MOMENTS - 1] {
                let mut q = [0.0; 3];
                for &(theta, w) in &rule {
                    let k = 0.5 * (lo + hi) + 0.5 * (hi - lo) * theta.cos();
                    let jac = w * 0.5 * (hi - lo) * theta.sin() * (n as f64 * theta).cos();
                    for (c, qc) in q.iter_mut().enumerate() {
                        *qc += jac
                            * gaussians(set, c)
                                .iter()
                                .map(|g| g.amplitude * normal_pdf(k, g))
                                .sum::<f64>();
                    }
                }
                for c in 0..3 {
                    worst = worst.max((q[c] - mu[n][c]).abs());
                }
            }
            assert!(worst < 1e-13, "{set:?}: {worst:e}");
        }
    }

    /// `chebyshev_tables.bin` is what [`tabulate`] computes now (bit for bit where the same
    /// arithmetic and `libm` built it; within 1e-12 of each value elsewhere), so the stored tables
    /// are the rules' own and the first query reads them instead of building them.
    #[test]
    fn stored_tables_are_current() {
        let now = tabulate();
        assert_eq!(
            now.len(),
            STORED.len(),
            "chebyshev_tables.bin is stale: cargo run --release --example chebyshev_tables"
        );
        let value = |b: &[u8]| f64::from_le_bytes(b.try_into().unwrap());
        let (mut differ, mut worst) = (0, 0.0f64);
        for (a, b) in now.chunks_exact(8).zip(STORED.chunks_exact(8)) {
            let (a, b) = (value(a), value(b));
            if a.to_bits() != b.to_bits() {
                differ += 1;
                worst = worst.max((a - b).abs() / a.abs().max(1e-300));
            }
            assert!(
                (a - b).abs() <= 1e-12 * a.abs() + 1e-18,
                "chebyshev_tables.bin is stale ({a:e} stored as {b:e}): cargo run --release --example chebyshev_tables"
            );
        }
        println!(
            "{} values, {differ} not bit for bit (largest relative difference {worst:e})",
            now.len() / 8
        );
        // What the first query reads is what it would otherwise build.
        for set in WeightSet::ALL {
            assert!(moments(set) == computed_moments(set).as_slice() || differ > 0);
        }
    }

    #[test]
    fn points_grow_with_frequency_and_round_trip() {
        let set = WeightSet::SrgbD65;
        let thin = points(set, 20.0 / 0.011, 0.0, 0.1, 1.0).unwrap();
        assert!(points(set, 40.0 / 0.011, 0.0, 0.1, 1.0).unwrap() >= thin);
        assert!(points(set, 20.0 / 0.011, 0.0, 0.5, 1.0).unwrap() >= thin);
        assert_eq!(points(set, 1e9, 0.0, 0.1, 1.0), None);
        assert_eq!(points(set, f64::NAN, 0.0, 0.1, 1.0), None);
        assert_eq!(points(set, 1.0, 0.0, 1.0, 1.0), None);
    }
}
