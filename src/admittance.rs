//! Admittance reduction of the boundary system (seed eqs. S17-S18) when one of the two media is
//! isotropic: the 4x4 solve of [`crate::interface`] becomes one 2x2 solve plus
//! back-substitution, with the same scattering matrix.
//!
//! Write the continuity of tangential `ψ = (E_x, E_y, H_x, H_y)` (seed eq. S18) as
//! `I x_in + O x_out = A_out y_out + A_in y_in`: `I`, `O` are the incoming and outgoing s/p
//! modes of the isotropic medium (amplitudes `x`), `A_in`, `A_out` those of the other medium
//! (amplitudes `y`), incoming amplitudes known. An isotropic s mode has only `(E_y, H_x)`, a
//! p mode only `(E_x, H_y)`, so for each polarisation `k` the linear form
//!
//! ```text
//! C_k(ψ) = h_k^O ψ_E(k) − e_k^O ψ_H(k)        (E(s) = E_y, H(s) = H_x; E(p) = E_x, H(p) = H_y)
//! ```
//! (the outgoing wave's admittance `h/e` turned into a row that annihilates it) vanishes on
//! `O` and is diagonal on `I`: `C(I) = diag(g)`, `g_k = h_k^O e_k^I − e_k^O h_k^I`. Applying `C`
//! eliminates the unknown isotropic amplitudes `x_out` and leaves the 2x2 system
//!
//! ```text
//! L y_out = diag(g) x_in − C(A_in) y_in,      L = C(A_out)
//! ```
//! for the outgoing amplitudes of the other medium (both directions of incidence at once:
//! two right-hand-side blocks). `x_out` follows from one of the two equations of its
//! polarisation (`E` or `H` row, whichever coefficient of `O` is larger). The 4x4 system is
//! singular exactly when `L` is (the eliminating transformation is invertible: `e^O_s = 1`).

use crate::cmath;
use num_complex::Complex64 as C64;

/// A complex 2x2 matrix as rows.
pub type M2 = [[C64; 2]; 2];

/// Outgoing amplitudes for unit incoming ones: rows are the outgoing waves (two each side),
/// columns the incoming waves `[x_in s, x_in p, y_in 0, y_in 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solution {
    /// Outgoing waves of the isotropic medium, `[s, p]`.
    pub x: [[C64; 4]; 2],
    /// Outgoing waves of the other medium.
    pub y: [[C64; 4]; 2],
}

/// The `(E, H)` components of `ψ = (E_x, E_y, H_x, H_y)` matched for polarisation `k`
/// (0: s, `(E_y, H_x)`; 1: p, `(E_x, H_y)`).
#[inline(always)]
fn eh(psi: &[C64; 4], k: usize) -> (C64, C64) {
    if k == 0 {
        (psi[1], psi[2])
    } else {
        (psi[0], psi[3])
    }
}

/// Solves the boundary system with the isotropic medium's modes `iso_in`, `iso_out` (`[s, p]`,
/// tangential `ψ`) and the other medium's `other_in`, `other_out` (any two modes each).
/// `None` if the reduced system is singular to working precision.
#[inline]
pub fn solve(
    iso_in: &[[C64; 4]; 2],
    iso_out: &[[C64; 4]; 2],
    other_in: &[[C64; 4]; 2],
    other_out: &[[C64; 4]; 2],
) -> Option<Solution> {
    let zero = C64::new(0.0, 0.0);
    let mut l = [[zero; 2]; 2];
    let mut rhs = [[zero; 4]; 2];
    for k in 0..2 {
        let (eo, ho) = eh(&iso_out[k], k);
        let c = |psi: &[C64; 4]| {
            let (e, h) = eh(psi, k);
            ho * e - eo * h
        };
        rhs[k][k] = c(&iso_in[k]);
        for j in 0..2 {
            l[k][j] = c(&other_out[j]);
            rhs[k][2 + j] = -c(&other_in[j]);
        }
    }
    let y = solve2(&l, &rhs)?;
    let x = [
        back_substitute(0, iso_in, iso_out, other_in, other_out, &y),
        back_substitute(1, iso_in, iso_out, other_in, other_out, &y),
    ];
    Some(Solution { x, y })
}

/// Row `k` (polarisation) of the isotropic outgoing amplitudes `x_out` for unit incoming
/// amplitudes `[x_in; y_in]` (columns), given the other medium's outgoing ones `y`: one row
/// of `I x_in + O x_out = A_out y_out + A_in y_in`, the `E` row or the `H` row of the
/// polarisation, whichever has the larger coefficient of the outgoing wave.
#[inline(always)]
fn back_substitute(
    k: usize,
    iso_in: &[[C64; 4]; 2],
    iso_out: &[[C64; 4]; 2],
    other_in: &[[C64; 4]; 2],
    other_out: &[[C64; 4]; 2],
    y: &[[C64; 4]; 2],
) -> [C64; 4] {
    let (eo, ho) = eh(&iso_out[k], k);
    let e_row = eo.norm_sqr() >= ho.norm_sqr();
    let pick = |psi: &[C64; 4]| {
        let (e, h) = eh(psi, k);
        if e_row {
            e
        } else {
            h
        }
    };
    let inv = cmath::inv(pick(&iso_out[k]));
    let (a0, a1) = (pick(&other_out[0]), pick(&other_out[1]));
    let mut constant = [C64::new(0.0, 0.0); 4];
    constant[k] = -pick(&iso_in[k]);
    constant[2] = pick(&other_in[0]);
    constant[3] = pick(&other_in[1]);
    let mut x = constant;
    for (col, v) in x.iter_mut().enumerate() {
        *v = (a0 * y[0][col] + a1 * y[1][col] + *v) * inv;
    }
    x
}

/// Solves `L X = B` (2x2 `L`, four right-hand sides) by Gaussian elimination with partial
/// pivoting; `None` if `L` is singular to working precision (the criterion of
/// [`crate::cmath::solve4`]: a pivot below `1e-300` of the largest entry, squared moduli).
#[inline]
fn solve2(l: &M2, b: &[[C64; 4]; 2]) -> Option<[[C64; 4]; 2]> {
    let scale = l.iter().flatten().map(|z| z.norm_sqr()).fold(0.0, f64::max);
    let (top, bottom) = if l[1][0].norm_sqr() > l[0][0].norm_sqr() {
        (1, 0)
    } else {
        (0, 1)
    };
    let p0 = l[top][0];
    if negligible(p0, scale) {
        return None;
    }
    let inv0 = cmath::inv(p0);
    let m = l[bottom][0] * inv0;
    let p1 = l[bottom][1] - m * l[top][1];
    if negligible(p1, scale) {
        return None;
    }
    let inv1 = cmath::inv(p1);
    let mut x = [[C64::new(0.0, 0.0); 4]; 2];
    for col in 0..4 {
        let x1 = (b[bottom][col] - m * b[top][col]) * inv1;
        x[1][col] = x1;
        x[0][col] = (b[top][col] - l[top][1] * x1) * inv0;
    }
    Some(x)
}

/// A pivot too small to divide by (or NaN), relative to `scale` (largest squared modulus).
#[inline]
fn negligible(pivot: C64, scale: f64) -> bool {
    let n = pivot.norm_sqr();
    n.is_nan() || n <= 1e-300 * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve2_inverts_and_detects_singular() {
        let c = |re: f64, im: f64| C64::new(re, im);
        let l = [[c(1e-3, 0.2), c(2.0, -1.0)], [c(0.5, 0.5), c(-0.3, 0.1)]];
        let b = [
            [c(1.0, 0.0), c(0.0, 1.0), c(2.0, -3.0), c(0.1, 0.0)],
            [c(0.0, 0.0), c(1.0, 1.0), c(-1.0, 0.5), c(0.0, 0.7)],
        ];
        let x = solve2(&l, &b).unwrap();
        for i in 0..2 {
            for col in 0..4 {
                let r = l[i][0] * x[0][col] + l[i][1] * x[1][col] - b[i][col];
                assert!(r.norm() < 1e-14, "{r}");
            }
        }
        let s = [[c(1.0, 1.0), c(2.0, 2.0)], [c(0.5, 0.5), c(1.0, 1.0)]];
        assert!(solve2(&s, &b).is_none());
    }
}
