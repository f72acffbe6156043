//! Product-integration rules for a fringe against a colour channel: the weights `W_ic(G)` with
//!
//! ```text
//! ∫ w_c(k) P(k) e^{iG(k − k₀)} dk = Σ_i P(k_i) W_ic(G)      for every polynomial P of degree < n,
//! W_ic(G) = ∫ w_c(k) L_i(k) e^{iG(k − k₀)} dk
//! ```
//! on the `n` Chebyshev–Lobatto nodes `k_i` of the visible band (`L_i` their Lagrange basis,
//! `k₀` the band's centre). A path-difference class of the plate oscillates as `e^{iφ(k)}` with
//! a slowly varying amplitude; written as `e^{iφ(k₀)} e^{iG(k − k₀)} P(k)` with `G = φ'(k₀)` its
//! group path, `P` (amplitude and residual phase) is smooth, so a few nodes integrate it
//! (Filon's idea, L. N. G. Filon, Proc. R. Soc. Edinb. 49, 1928: interpolate the slow factor,
//! integrate the oscillation exactly).
//!
//! The channel weights are the Gaussian fits of [`crate::colour::weights`], and the weights
//! are exact for them: for `X ~ N(μ, σ²)` and a polynomial `L`,
//! `E[L(X) e^{iGX}] = e^{iGμ − σ²G²/2} E[L(μ + iσ²G + σZ)]` (completing the square), and the
//! expectation is a Gauss–Hermite sum of `⌈n/2⌉` points, exact for degree `n − 1`. `W_ic` is
//! tabulated in `G` per weight set and node count and interpolated (cubic, step [`STEP_NM`]: the
//! error is below 1e-5 of the white response). The table is built where a query first needs
//! it, [`CHUNK`] rows at a time, each row from the Chebyshev form of the Lagrange basis,
//! `L_i = Σ_m D_mi T_m` (`D` the nodes' discrete cosine transform), so that a Gaussian's
//! `E[T_m(c + s Z)]` for every `m` costs one three-term recurrence per Hermite point (no
//! division); the visibilities are closed forms, `Σ_i W_ic(G) = Σ_j a_j e^{iG(μ_j − k₀) −
//! σ_j²G²/2}` (the basis sums to 1). A first query pays only for the rows it reads.

use crate::colour::weights::{gaussians, WeightSet};
use crate::quadrature::hermite;
use crate::quadrature::nodes::{self, lobatto, LEVELS, MAX_NODES};
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;
use std::sync::OnceLock;

/// The band the nodes span: the wavelengths Mitsuba samples and the tables cover (nm). The
/// Gaussian fits put less than 1.1e-5 of their mass outside it.
pub const BAND_NM: (f64, f64) = (360.0, 830.0);

/// Table step in the group path `G` (nm). The weights oscillate in `G` no faster than
/// `e^{iG(μ_j − k₀)}`, `|μ_j − k₀| < 7.5e-3` rad/nm: 0.15 rad per step, where cubic interpolation
/// is exact to ~1e-5 relative.
pub const STEP_NM: f64 = 20.0;

/// Weights below this (relative to the white response 1) are not tabulated: the table ends
/// where every Gaussian's `|a| e^{−σ²G²/2}` falls below it.
pub const NEGLIGIBLE: f64 = 1e-7;

/// Rows of the table built at once.
pub const CHUNK: usize = 4;

/// The rule of one weight set and node count.
pub struct FringeRule {
    set: WeightSet,
    /// Nodes `k_i` (rad/nm), descending (Lobatto order `cos(π i/(n−1))`).
    nodes: Vec<f64>,
    /// `W_ic(m STEP_NM)` at index `m n + i` of chunk `m / CHUNK`, channels last, built on
    /// first use.
    chunks: Vec<OnceLock<Box<[[C64; 3]]>>>,
    /// Entries of the table per node (`G` from 0 to `(rows − 1) STEP_NM`).
    rows: usize,
    /// `max_c |Σ_i W_ic(G)|` (the visibility of a fringe of constant amplitude) per row.
    visibility: &'static [f64],
    /// The largest visibility at this row or beyond (a bound for every `|G'| ≥ G`).
    beyond: &'static [f64],
}

/// The visibility of a constant fringe per table row of `set`, `max_c |Σ_j a_j e^{iG(μ_j − k₀) −
/// σ_j²G²/2}|` (the basis sums to 1: module docs), and its running maximum from each row on;
/// computed once per weight set (every level shares them), each Gaussian's factor by a
/// recurrence over the rows (a phasor and `e^{−σ²S²(2m+1)/2}` per step `S`).
fn visibilities(set: WeightSet, rows: usize) -> (&'static [f64], &'static [f64]) {
    type Both = OnceLock<(Vec<f64>, Vec<f64>)>;
    static ALL: [Both; WeightSet::ALL.len()] = [const { OnceLock::new() }; WeightSet::ALL.len()];
    let (v, b) = ALL[set.index()].get_or_init(|| {
        let (k0, _) = band();
        let mut sums = vec![[C64::new(0.0, 0.0); 3]; rows];
        for (c, channel) in (0..3).map(|c| (c, gaussians(set, c))) {
            for g in channel {
                let turn = C64::from_polar(1.0, STEP_NM * (g.mu - k0));
                let q = (-(g.sigma * STEP_NM).powi(2)).exp();
                let (mut term, mut ratio) = (
                    C64::new(g.amplitude, 0.0),
                    (-0.5 * (g.sigma * STEP_NM).powi(2)).exp(),
                );
                for row in sums.iter_mut() {
                    row[c] += term;
                    term *= turn * ratio;
                    ratio *= q;
                }
            }
        }
        let visibility: Vec<f64> = sums
            .iter()
            .map(|r| r.iter().map(|z| z.norm()).fold(0.0, f64::max))
            .collect();
        let mut beyond = visibility.clone();
        for m in (0..rows.saturating_sub(1)).rev() {
            beyond[m] = beyond[m].max(beyond[m + 1]);
        }
        (visibility, beyond)
    });
    (v, b)
}

/// Centre and half width (rad/nm) of [`BAND_NM`] in wavenumber.
pub fn band() -> (f64, f64) {
    let (lo, hi) = (TAU / BAND_NM.1, TAU / BAND_NM.0);
    (0.5 * (lo + hi), 0.5 * (hi - lo))
}

/// `|a| e^{−σ²G²/2}` stays above [`NEGLIGIBLE`] up to this `G` for some Gaussian of `set`.
fn reach(set: WeightSet) -> f64 {
    (0..3)
        .flat_map(|c| gaussians(set, c).iter())
        .filter(|g| g.amplitude.abs() > NEGLIGIBLE)
        .map(|g| (2.0 * (g.amplitude.abs() / NEGLIGIBLE).ln()).sqrt() / g.sigma)
        .fold(0.0, f64::max)
}

/// `Σ_j a_j e^{−σ_j²G²/2} e^{iG(μ_j − k₀)} E[T_m(c_j + s Z)]` for `m < n`, `Z` standard normal,
/// `c_j = (μ_j − k₀ + iσ_j²G)/a`, `s = σ_j/a` (module docs), over the Gaussians of `channel`
/// whose envelope is above 1e-3 of [`NEGLIGIBLE`], into `out`.
fn chebyshev_moments(set: WeightSet, channel: usize, n: usize, big_g: f64, out: &mut [C64]) {
    let (k0, a) = band();
    let gh = hermite::rule(n.div_ceil(2));
    out[..n].fill(C64::new(0.0, 0.0));
    for g in gaussians(set, channel).iter().filter(|g| {
        g.amplitude.abs() * (-0.5 * (g.sigma * big_g).powi(2)).exp() > 1e-3 * NEGLIGIBLE
    }) {
        let envelope =
            C64::new(-0.5 * (g.sigma * big_g).powi(2), big_g * (g.mu - k0)).exp() * g.amplitude;
        let centre = C64::new(g.mu - k0, g.sigma * g.sigma * big_g) / a;
        for &(z, w) in gh {
            let x = centre + g.sigma / a * z;
            let weight = envelope * w;
            // T_0 = 1, T_1 = x, T_{m+1} = 2x T_m − T_{m−1}.
            let (mut previous, mut current) = (C64::new(1.0, 0.0), x);
            out[0] += weight;
            for o in out[1..n].iter_mut() {
                *o += weight * current;
                (previous, current) = (current, 2.0 * x * current - previous);
            }
        }
    }
}

impl FringeRule {
    fn build(set: WeightSet, level: usize) -> Self {
        let (k0, a) = band();
        let n = LEVELS[level];
        let x = lobatto(n);
        let rows = (reach(set) / STEP_NM).ceil() as usize + 3;
        let (visibility, beyond) = visibilities(set, rows);
        FringeRule {
            set,
            nodes: x.iter().map(|t| k0 + a * t).collect(),
            chunks: (0..rows.div_ceil(CHUNK)).map(|_| OnceLock::new()).collect(),
            rows,
            visibility,
            beyond,
        }
    }

    /// Rows `CHUNK chunk ..` of the table: `W_ic(G) = Σ_m D_mi M_mc(G)` with the Gaussians'
    /// Chebyshev moments `M` ([`chebyshev_moments`]) and the level's transform `D`.
    fn chunk(&self, chunk: usize) -> &[[C64; 3]] {
        self.chunks[chunk].get_or_init(|| {
            let n = self.nodes.len();
            let level = LEVELS.iter().position(|&l| l == n).expect("a level");
            let dct = &nodes::level(level).dct;
            let first = chunk * CHUNK;
            let last = (first + CHUNK).min(self.rows);
            let mut table = vec![[C64::new(0.0, 0.0); 3]; (last - first) * n];
            let mut moments = [C64::new(0.0, 0.0); MAX_NODES];
            for m in first..last {
                let big_g = m as f64 * STEP_NM;
                for c in 0..3 {
                    chebyshev_moments(self.set, c, n, big_g, &mut moments);
                    let row = &mut table[(m - first) * n..(m - first + 1) * n];
                    for (i, entry) in row.iter_mut().enumerate() {
                        // One node: L_0 = 1 (the transform's end weights halve a single node).
                        entry[c] = if n == 1 {
                            moments[0]
                        } else {
                            (0..n).map(|k| moments[k] * dct[k][i]).sum()
                        };
                    }
                }
            }
            table.into_boxed_slice()
        })
    }

    /// Row `m`'s entry of node `i`.
    fn entry(&self, m: usize, i: usize) -> &[C64; 3] {
        let n = self.nodes.len();
        &self.chunk(m / CHUNK)[(m % CHUNK) * n + i]
    }

    /// The nodes `k_i` (rad/nm).
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }

    /// Largest `|G|` (nm) with a non-zero weight.
    pub fn reach(&self) -> f64 {
        (self.rows - 3) as f64 * STEP_NM
    }

    /// `max_c |F_c(G)|`: how visible a fringe of group path `G` with a constant amplitude is in
    /// the most sensitive channel (1 at `G = 0`, nearest table row).
    pub fn visibility(&self, g: f64) -> f64 {
        let m = (g.abs() * (1.0 / STEP_NM)).round() as usize;
        if m >= self.rows - 2 {
            0.0
        } else {
            self.visibility[m]
        }
    }

    /// The largest visibility of any fringe with `|G'| ≥ |G|` (a monotone bound of
    /// [`FringeRule::visibility`], from the table row at or below `|G|`).
    pub fn visibility_beyond(&self, g: f64) -> f64 {
        let m = (g.abs() * (1.0 / STEP_NM)).floor();
        if m.is_nan() || m >= (self.rows - 2) as f64 {
            0.0
        } else {
            self.beyond[m as usize]
        }
    }

    /// The weights `W_ic(G)` into `out[i][c]` (zero beyond [`FringeRule::reach`]).
    pub fn weights(&self, g: f64, out: &mut [[C64; 3]]) {
        for (i, o) in out.iter_mut().take(self.nodes.len()).enumerate() {
            *o = self.weight(g, i);
        }
    }

    /// The weights `W_ic(G)` of node `i` (zero beyond [`FringeRule::reach`]): cubic
    /// interpolation between the table's rows.
    pub fn weight(&self, g: f64, i: usize) -> [C64; 3] {
        let s = g.abs() / STEP_NM;
        let mut out = [C64::new(0.0, 0.0); 3];
        if s.is_nan() || s >= (self.rows - 2) as f64 {
            return out;
        }
        let m = s.floor() as usize;
        let t = s - m as f64;
        // Cubic Lagrange weights on rows m − 1 .. m + 2.
        let l = [
            -t * (t - 1.0) * (t - 2.0) / 6.0,
            (t + 1.0) * (t - 1.0) * (t - 2.0) / 2.0,
            -(t + 1.0) * t * (t - 2.0) / 2.0,
            (t + 1.0) * t * (t - 1.0) / 6.0,
        ];
        for (r, lr) in l.iter().enumerate() {
            // Row m − 1 < 0 is row 1 conjugated (W(−G) = conj W(G): real weight and basis).
            let (row, flip) = match (m + r).checked_sub(1) {
                Some(row) => (row, false),
                None => (1, true),
            };
            let w = self.entry(row, i);
            for c in 0..3 {
                out[c] += if flip { w[c].conj() } else { w[c] } * lr;
            }
        }
        if g < 0.0 {
            out.iter_mut().for_each(|v| *v = v.conj());
        }
        out
    }
}

/// The rule of `set` with `LEVELS[level]` nodes, built on first use.
pub fn rule(set: WeightSet, level: usize) -> &'static FringeRule {
    const SETS: usize = WeightSet::ALL.len();
    static RULES: [[OnceLock<FringeRule>; LEVELS.len()]; SETS] =
        [const { [const { OnceLock::new() }; LEVELS.len()] }; SETS];
    let level = level.min(LEVELS.len() - 1);
    RULES[set.index()][level].get_or_init(|| FringeRule::build(set, level))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::weights::fit_per_wavenumber;

    /// `∫ w_c(k) P(k) e^{iG(k − k₀)} dk` of the Gaussian fit by dense composite Gauss–Legendre
    /// quadrature over every Gaussian's ±9σ (written independently of the rule).
    fn dense(set: WeightSet, c: usize, p: &dyn Fn(f64) -> C64, g: f64) -> C64 {
        let (k0, _) = band();
        let (lo, hi) = (0.003, 0.03);
        hermite::composite_interval(lo, hi, 4_000)
            .iter()
            .map(|&(k, w)| {
                C64::new(0.0, g * (k - k0)).exp() * p(k) * fit_per_wavenumber(set, c, k) * w
            })
            .sum()
    }

    /// Each rule integrates polynomials of degree < n times a fringe exactly (up to the table's
    /// interpolation): against dense quadrature, for G on and off the grid, both signs.
    #[test]
    fn rules_integrate_polynomial_fringes() {
        let (k0, a) = band();
        for set in WeightSet::ALL {
            for (level, &n) in LEVELS.iter().enumerate() {
                let r = rule(set, level);
                let mut w = vec![[C64::new(0.0, 0.0); 3]; n];
                let p = |k: f64| {
                    let t = (k - k0) / a;
                    let linear = if n > 1 {
                        C64::new(-0.2, 0.3) * t
                    } else {
                        C64::new(0.0, 0.0)
                    };
                    C64::new(0.7, 0.3) * t.powi(n as i32 - 1) + linear + C64::new(1.0, -0.5)
                };
                let mut worst = 0.0f64;
                for g in [0.0, 137.0, -2511.0, 9_873.3, -31_002.0] {
                    r.weights(g, &mut w);
                    for c in 0..3 {
                        let got: C64 = r.nodes().iter().zip(&w).map(|(&k, wi)| p(k) * wi[c]).sum();
                        let want = dense(set, c, &p, g);
                        worst = worst.max((got - want).norm());
                    }
                }
                // Measured worst 1.4e-7 (srgb-d65; 4-6e-8 for the XYZ sets): the table's cubic
                // interpolation and the dense rule's own error. Bound: 5e-7.
                assert!(worst < 5e-7, "{set:?} n = {n}: {worst:e}");
            }
        }
    }

    #[test]
    fn visibility_is_one_at_zero_and_decays() {
        for set in WeightSet::ALL {
            let r = rule(set, 0);
            assert!((r.visibility(0.0) - 1.0).abs() < 1e-9);
            assert!(r.visibility(20_000.0) < 0.05);
            assert_eq!(r.visibility(2.0 * r.reach() + 1e3), 0.0);
        }
    }
}
