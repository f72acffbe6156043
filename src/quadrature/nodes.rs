//! The nested Chebyshev–Lobatto nodes of the visible band, `t_i = cos(π i/(n−1))` on
//! `[−1, 1]` for `n` of [`LEVELS`] (each level's nodes are among the next level's), their
//! Lagrange bases (barycentric form, weights `(−1)^i` halved at both ends; Berrut & Trefethen,
//! SIAM Review 46, 2004) and the real matrices that interpolate values on one level to the
//! nodes of a finer one, computed once.

use num_complex::Complex64 as C64;
use std::sync::OnceLock;

/// Node counts of the nested levels.
pub const LEVELS: [usize; 6] = [1, 3, 5, 9, 17, 33];
/// Where across the band (`t`) a plate's group paths are sampled
/// ([`crate::spectral::survey`]): both ends, the centre and half-way (with normal dispersion they
/// vary monotonically, with one curvature).
pub const SPAN: [f64; 5] = [-1.0, -0.5, 0.0, 0.5, 1.0];

/// The finest level's index.
pub const FINEST: usize = LEVELS.len() - 1;
/// Most nodes of any level.
pub const MAX_NODES: usize = LEVELS[FINEST];

/// The Chebyshev–Lobatto nodes of `n` points on `[−1, 1]` (`n = 1`: the centre), exactly
/// symmetric with an exact 0 in the middle, so that the nodes of nested levels compare equal.
pub fn lobatto(n: usize) -> Vec<f64> {
    if n <= 1 {
        return vec![0.0];
    }
    (0..n)
        .map(|i| {
            let (j, sign) = if 2 * i < n - 1 {
                (i, 1.0)
            } else {
                (n - 1 - i, -1.0)
            };
            if 2 * j == n - 1 {
                0.0
            } else {
                sign * (std::f64::consts::PI * j as f64 / (n - 1) as f64).cos()
            }
        })
        .collect()
}

/// The Lagrange basis of the Lobatto nodes `x` at a complex point `z`, written into `out`.
pub fn lagrange(x: &[f64], z: C64, out: &mut [C64]) {
    let n = x.len();
    if n == 1 {
        out[0] = C64::new(1.0, 0.0);
        return;
    }
    if let Some(j) = (z.im == 0.0)
        .then(|| x.iter().position(|&xi| z.re == xi))
        .flatten()
    {
        out[..n].iter_mut().enumerate().for_each(|(i, o)| {
            *o = C64::new(if i == j { 1.0 } else { 0.0 }, 0.0);
        });
        return;
    }
    let mut total = C64::new(0.0, 0.0);
    for (i, &xi) in x.iter().enumerate() {
        let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
        let w = if i == 0 || i == n - 1 {
            0.5 * sign
        } else {
            sign
        };
        out[i] = w / (z - xi);
        total += out[i];
    }
    out[..n].iter_mut().for_each(|o| *o /= total);
}

/// One level's nodes and what is derived from them.
pub struct Level {
    /// The nodes `t_i`.
    pub nodes: Vec<f64>,
    /// For each node, its index among the finest level's nodes.
    pub in_finest: Vec<usize>,
    /// `to_finest[j][i]`: the Lagrange basis of this level at finest node `j` (interpolation
    /// of this level's values to every finest node).
    pub to_finest: Vec<Vec<f64>>,
    /// `slope[i]`: the derivative at `t = 0` of the Lagrange basis (zero for one node).
    pub slope: Vec<f64>,
    /// `span_slopes[s][i]`: the derivative of the Lagrange basis at `SPAN[s]` (zero for one
    /// node).
    pub span_slopes: [Vec<f64>; SPAN.len()],
    /// `dct[m][i]`: the Chebyshev coefficient `c_m` of the interpolant per unit value at node
    /// `i` (`(2 − δ)/(n − 1) · w_i cos(π m i/(n − 1))`, `w_i` halved at both ends and `δ` for
    /// `m = 0, n − 1`; [`chebyshev`]).
    pub dct: Vec<Vec<f64>>,
}

impl Level {
    fn build(level: usize) -> Self {
        let nodes = lobatto(LEVELS[level]);
        let finest = lobatto(MAX_NODES);
        let n = nodes.len();
        let in_finest = nodes
            .iter()
            .map(|t| {
                finest
                    .iter()
                    .position(|f| f == t)
                    .expect("levels are nested")
            })
            .collect();
        let mut basis = vec![C64::new(0.0, 0.0); n];
        let to_finest = finest
            .iter()
            .map(|&t| {
                lagrange(&nodes, C64::new(t, 0.0), &mut basis);
                basis.iter().map(|b| b.re).collect()
            })
            .collect();
        // d/dt of L_i at 0 by a complex step (exact to rounding for a polynomial:
        // Im L_i(i h) / h, h tiny; L_i is real on the real axis).
        let h = 1e-20;
        lagrange(&nodes, C64::new(0.0, h), &mut basis);
        let slope = if n == 1 {
            vec![0.0]
        } else {
            // L_i(ih) = L_i(0) + ih L_i'(0) − h² L_i''(0)/2 − ...: the imaginary part over h.
            basis.iter().map(|b| b.im / h).collect()
        };
        let span_slopes = SPAN.map(|t| {
            if n == 1 {
                return vec![0.0];
            }
            lagrange(&nodes, C64::new(t, h), &mut basis);
            basis.iter().map(|b| b.im / h).collect()
        });
        let last = n.saturating_sub(1).max(1);
        let dct = (0..n)
            .map(|m| {
                let scale = if m == 0 || m == n - 1 { 1.0 } else { 2.0 } / last as f64;
                (0..n)
                    .map(|i| {
                        let w = if i == 0 || i == n - 1 { 0.5 } else { 1.0 };
                        scale * w * (std::f64::consts::PI * (m * i) as f64 / last as f64).cos()
                    })
                    .collect()
            })
            .collect();
        Level {
            nodes,
            in_finest,
            to_finest,
            slope,
            span_slopes,
            dct,
        }
    }
}

/// The level of index `level` (into [`LEVELS`]), built once.
pub fn level(level: usize) -> &'static Level {
    static ALL: [OnceLock<Level>; LEVELS.len()] = [const { OnceLock::new() }; LEVELS.len()];
    ALL[level.min(FINEST)].get_or_init(|| Level::build(level.min(FINEST)))
}

/// The Chebyshev coefficients `c_m` of the polynomial through the values `v_i` at the Lobatto
/// nodes of `v.len()` points (`p(t) = Σ_m c_m T_m(t)`; the discrete cosine transform of type I).
pub fn chebyshev(v: &[f64]) -> Vec<f64> {
    let mut c = vec![0.0; v.len()];
    chebyshev_into(v, &mut c);
    c
}

/// [`chebyshev`] into `out` (no allocation).
pub fn chebyshev_into(v: &[f64], out: &mut [f64]) {
    let n = v.len();
    if n == 1 {
        out[0] = v[0];
        return;
    }
    let l = LEVELS
        .iter()
        .position(|&m| m == n)
        .expect("values on the nodes of a level");
    for (o, row) in out.iter_mut().zip(&level(l).dct) {
        *o = row.iter().zip(v).map(|(w, x)| w * x).sum();
    }
}

/// `(p(t), p'(t), p''(t))` of `p = Σ_m c_m T_m` (Chebyshev recurrences for `T_m` and its
/// derivatives: `T'_{m+1} = 2 T_m + 2t T'_m − T'_{m−1}`, likewise for `T''`).
pub fn chebyshev_eval(c: &[f64], t: f64) -> (f64, f64, f64) {
    let (mut t0, mut t1) = (1.0, t);
    let (mut d0, mut d1) = (0.0, 1.0);
    let (mut s0, mut s1) = (0.0, 0.0);
    let (mut p, mut dp, mut sp) = (c[0], 0.0, 0.0);
    for &cm in &c[1..] {
        p += cm * t1;
        dp += cm * d1;
        sp += cm * s1;
        let t2 = 2.0 * t * t1 - t0;
        let d2 = 2.0 * t1 + 2.0 * t * d1 - d0;
        let s2 = 4.0 * d1 + 2.0 * t * s1 - s0;
        (t0, t1, d0, d1, s0, s1) = (t1, t2, d1, d2, s1, s2);
    }
    (p, dp, sp)
}

/// `p(t) = Σ_m c_m T_m(t)` (Clenshaw's recurrence).
pub fn chebyshev_at(c: &[f64], t: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    for &cm in c[1..].iter().rev() {
        (b1, b2) = (2.0 * t * b1 - b2 + cm, b1);
    }
    t * b1 - b2 + c[0]
}

/// `2 Σ_{m≥n} |c_m|` beyond the `n` known coefficient magnitudes `c`, for a geometric decay
/// estimated from the last four in pairs (the even and odd parts of a function can decay
/// differently): with `s = |c_{n−1}| + |c_{n−2}|`, `r = √(s / (|c_{n−3}| + |c_{n−4}|))` per
/// coefficient (at most 0.9), `2 s r/(1 − r)`.
pub fn series_tail(c: &[f64]) -> f64 {
    let n = c.len();
    if n < 4 {
        return 0.0;
    }
    // The last two coefficients (even and odd parts can decay at different rates) and the
    // ratio of the last pair to the pair before.
    let (last, before) = (c[n - 1] + c[n - 2], c[n - 3] + c[n - 4]);
    if last == 0.0 {
        return 0.0;
    }
    let r = if before > 0.0 {
        (last / before).sqrt()
    } else {
        1.0
    }
    .min(0.9);
    2.0 * last * r / (1.0 - r)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The coefficients reproduce a polynomial of degree < n, and the evaluation its value and
    /// first two derivatives.
    #[test]
    fn chebyshev_series_of_a_polynomial() {
        for &n in &LEVELS[1..] {
            let p = |t: f64| 0.4 - 1.3 * t + 0.7 * t * t + 0.2 * t.powi(n as i32 - 1);
            let dp = |t: f64| -1.3 + 1.4 * t + 0.2 * (n as f64 - 1.0) * t.powi(n as i32 - 2);
            let d2p = |t: f64| {
                1.4 + 0.2 * (n as f64 - 1.0) * (n as f64 - 2.0) * t.powi((n as i32 - 3).max(0))
            };
            let v: Vec<f64> = lobatto(n).iter().map(|&t| p(t)).collect();
            let c = chebyshev(&v);
            for t in [-0.93, -0.2, 0.0, 0.41, 0.999] {
                assert!((chebyshev_at(&c, t) - p(t)).abs() < 1e-12, "n {n} t {t}");
                let (a, b, e) = chebyshev_eval(&c, t);
                let d2 = if n == 3 { 1.4 + 0.4 } else { d2p(t) };
                assert!((a - p(t)).abs() < 1e-12, "n {n} t {t}: {a} vs {}", p(t));
                assert!((b - dp(t)).abs() < 1e-10, "n {n} t {t}: {b} vs {}", dp(t));
                assert!((e - d2).abs() < 1e-8, "n {n} t {t}: {e} vs {d2}");
            }
        }
    }

    #[test]
    fn levels_are_nested_and_interpolate_polynomials() {
        let finest = &level(FINEST).nodes;
        for (l, &n) in LEVELS.iter().enumerate() {
            let lv = level(l);
            assert_eq!(lv.nodes.len(), n);
            for (i, &j) in lv.in_finest.iter().enumerate() {
                assert_eq!(finest[j], lv.nodes[i]);
            }
            // A polynomial of degree n − 1 is reproduced at every finest node, and its
            // derivative at 0 by the slope weights.
            let p = |t: f64| {
                (0..n)
                    .map(|m| (0.3 + m as f64) * t.powi(m as i32))
                    .sum::<f64>()
            };
            let dp0 = if n > 1 { 1.3 } else { 0.0 };
            for (j, &t) in finest.iter().enumerate() {
                let v: f64 = lv
                    .nodes
                    .iter()
                    .zip(&lv.to_finest[j])
                    .map(|(&x, w)| p(x) * w)
                    .sum();
                assert!(
                    (v - p(t)).abs() < 1e-12 * (1.0 + p(t).abs()),
                    "level {l} at {t}"
                );
            }
            let d: f64 = lv.nodes.iter().zip(&lv.slope).map(|(&x, w)| p(x) * w).sum();
            assert!((d - dp0).abs() < 1e-12, "level {l}: slope {d}");
            for (t, w) in SPAN.iter().zip(&lv.span_slopes) {
                let dp = |t: f64| {
                    (1..n)
                        .map(|m| m as f64 * (0.3 + m as f64) * t.powi(m as i32 - 1))
                        .sum::<f64>()
                };
                let d: f64 = lv.nodes.iter().zip(w).map(|(&x, w)| p(x) * w).sum();
                assert!(
                    (d - dp(*t)).abs() < 1e-9 * (1.0 + dp(*t).abs()),
                    "level {l} at {t}: {d}"
                );
            }
        }
    }
}
