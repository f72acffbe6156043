//! Gaussian quadrature rules by the Golub–Welsch eigenvalue method: Gauss–Hermite for the
//! standard normal weight (probabilists' Hermite polynomials), cached per node count, and
//! composite Gauss–Legendre panels for strongly oscillating integrands.

use nalgebra::{DMatrix, SymmetricEigen};
use std::sync::OnceLock;

/// Largest node count offered.
pub const MAX_NODES: usize = 128;

/// Nodes `x_i` and weights `w_i` (summing to 1) with `Σ w_i f(x_i) ≈ E[f(X)]`, `X ~ N(0, 1)`,
/// exact for polynomials of degree `< 2n`. `n` is clamped to `1..=MAX_NODES`.
pub fn rule(n: usize) -> &'static [(f64, f64)] {
    static RULES: [OnceLock<Vec<(f64, f64)>>; MAX_NODES] = [const { OnceLock::new() }; MAX_NODES];
    let n = n.clamp(1, MAX_NODES);
    RULES[n - 1].get_or_init(|| golub_welsch(n))
}

/// Nodes and weights of a composite rule for `E[f(X)]`, `X ~ N(0, 1)`, truncated to
/// `|X| ≤ 6.5` (mass lost < 1e-10): `panels` equal panels of 8-point Gauss–Legendre, the
/// weights multiplied by the normal density and renormalised to sum to 1. Use at least 16
/// panels (panels of width ≤ 0.8 resolve the density itself).
pub fn composite_normal(panels: usize) -> Vec<(f64, f64)> {
    static LEGENDRE: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    let gl = LEGENDRE
        .get_or_init(|| jacobi_rule(8, |k| k as f64 / ((4 * k * k - 1) as f64).sqrt(), 2.0));
    let (lo, hi) = (-6.5, 6.5);
    let h = (hi - lo) / panels.max(1) as f64;
    let mut rule = Vec::with_capacity(8 * panels.max(1));
    for p in 0..panels.max(1) {
        let c = lo + h * (p as f64 + 0.5);
        for &(x, w) in gl {
            let t = c + 0.5 * h * x;
            rule.push((t, 0.5 * h * w * (-0.5 * t * t).exp()));
        }
    }
    let total: f64 = rule.iter().map(|r| r.1).sum();
    rule.iter_mut().for_each(|r| r.1 /= total);
    rule
}

/// Composite 8-point Gauss–Legendre nodes and weights on `[lo, hi]` with `panels` equal panels
/// (`Σ w f(x) ≈ ∫ f`).
pub fn composite_interval(lo: f64, hi: f64, panels: usize) -> Vec<(f64, f64)> {
    let gl = legendre8();
    let h = (hi - lo) / panels.max(1) as f64;
    (0..panels.max(1))
        .flat_map(|p| {
            let c = lo + h * (p as f64 + 0.5);
            gl.iter().map(move |&(x, w)| (c + 0.5 * h * x, 0.5 * h * w))
        })
        .collect()
}

/// The 8-point Gauss–Legendre rule on `[−1, 1]`.
fn legendre8() -> &'static [(f64, f64)] {
    static LEGENDRE: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    LEGENDRE.get_or_init(|| jacobi_rule(8, |k| k as f64 / ((4 * k * k - 1) as f64).sqrt(), 2.0))
}

/// Golub–Welsch for a symmetric Jacobi matrix with zero diagonal and off-diagonal `b(k)`,
/// `k = 1..n−1`, and total weight `mu0`.
fn jacobi_rule(n: usize, b: impl Fn(usize) -> f64, mu0: f64) -> Vec<(f64, f64)> {
    let j = DMatrix::from_fn(
        n,
        n,
        |p, q| if p.abs_diff(q) == 1 { b(p.max(q)) } else { 0.0 },
    );
    let eig = SymmetricEigen::new(j);
    let mut rule: Vec<(f64, f64)> = (0..n)
        .map(|i| (eig.eigenvalues[i], mu0 * eig.eigenvectors[(0, i)].powi(2)))
        .collect();
    rule.sort_by(|a, b| a.0.total_cmp(&b.0));
    rule
}

/// The Jacobi matrix of the probabilists' Hermite recurrence `x He_k = He_{k+1} + k He_{k−1}`
/// has zero diagonal and off-diagonal `√k`; its eigenvalues are the nodes and the squared first
/// components of its unit eigenvectors the weights (Golub & Welsch, Math. Comp. 23, 1969).
fn golub_welsch(n: usize) -> Vec<(f64, f64)> {
    jacobi_rule(n, |k| (k as f64).sqrt(), 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moments_and_fourier_transform_of_the_normal_law() {
        for n in [1, 2, 5, 16, 40, MAX_NODES] {
            let r = rule(n);
            let sum: f64 = r.iter().map(|(_, w)| w).sum();
            assert!((sum - 1.0).abs() < 1e-13, "{n}: {sum}");
            // E[X^2] = 1, E[X^4] = 3 (exact for n >= 3).
            if n >= 3 {
                let m2: f64 = r.iter().map(|(x, w)| w * x * x).sum();
                let m4: f64 = r.iter().map(|(x, w)| w * x.powi(4)).sum();
                assert!((m2 - 1.0).abs() < 1e-12 && (m4 - 3.0).abs() < 1e-11);
            }
        }
        // E[cos(aX)] = exp(−a²/2).
        let r = rule(MAX_NODES);
        for a in [0.5, 3.0, 8.0] {
            let c: f64 = r.iter().map(|(x, w)| w * (a * x).cos()).sum();
            assert!((c - (-0.5 * a * a).exp()).abs() < 1e-10, "{a}: {c}");
        }
        // The composite rule resolves fast oscillations with two panels per period over ±6.5
        // (the density `spectral::gaussian::auto` uses).
        for a in [0.5f64, 3.0, 20.0, 60.0] {
            let panels = ((2.0 * 13.0 * a / std::f64::consts::TAU).ceil() as usize).max(16);
            let r = composite_normal(panels);
            let c: f64 = r.iter().map(|(x, w)| w * (a * x).cos()).sum();
            assert!((c - (-0.5 * a * a).exp()).abs() < 1e-9, "{a}: {c}");
        }
    }
}
