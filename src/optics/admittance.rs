//! Admittance reduction of the boundary system (eqs. S17-S18) when one of the two media is
//! isotropic: the 4x4 solve of [`crate::optics::interface`] becomes one 2x2 solve plus
//! back-substitution, with the same scattering matrix.
//!
//! Write the continuity of tangential `ψ = (E_x, E_y, H_x, H_y)` (eq. S18) as
//! `I x_in + O x_out = A_out y_out + A_in y_in`: `I`, `O` are the incoming and outgoing s/p
//! modes of the isotropic medium (amplitudes `x`), `A_in`, `A_out` those of the other medium
//! (amplitudes `y`), incoming amplitudes known. An isotropic s mode has only `(E_y, H_x)`, a
//! p mode only `(E_x, H_y)`: polarisation `k` of the isotropic medium appears in two rows of
//! the system only, `E(k)` and `H(k)` (`E(s) = E_y`, `H(s) = H_x`; `E(p) = E_x`, `H(p) = H_y`).
//! The outgoing wave's admittance `Y_k = h_k^O / e_k^O` turns them into the linear form
//!
//! ```text
//! C_k(ψ) = Y_k ψ_E(k) − ψ_H(k)      (or ψ_E(k) − ψ_H(k)/Y_k when |h_k^O| > |e_k^O|)
//! ```
//! that vanishes on `O` and is diagonal on `I`: `C(I) = diag(g)`. Applying `C` eliminates the
//! unknown isotropic amplitudes `x_out` and leaves the 2x2 system
//!
//! ```text
//! L y_out = diag(g) x_in − C(A_in) y_in,      L = C(A_out)
//! ```
//! for the outgoing amplitudes of the other medium (both directions of incidence at once:
//! two right-hand-side blocks). `x_out` follows from the `E(k)` row, or the `H(k)` row when
//! `|h_k^O| > |e_k^O|` (the same choice: the form's coefficients stay bounded by 1). The
//! eliminating transformation is invertible, so the 4x4 system is singular exactly when `L` is.

use crate::cmath::{singular, Scalar};
use crate::error::Result;
use crate::real::complex::Cx;
use crate::real::{Mask, Real};

/// Outgoing amplitudes for unit incoming ones: rows are the outgoing waves (two each side),
/// columns the incoming waves `[x_in s, x_in p, y_in 0, y_in 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solution<T> {
    /// Outgoing waves of the isotropic medium, `[s, p]`.
    pub x: [[T; 4]; 2],
    /// Outgoing waves of the other medium.
    pub y: [[T; 4]; 2],
}

/// Tangential fields of a pair of modes.
type Pair<T> = [[T; 4]; 2];

/// Indices in `ψ = (E_x, E_y, H_x, H_y)` of the `(E, H)` rows of polarisation `k` (0: s,
/// `(E_y, H_x)`; 1: p, `(E_x, H_y)`).
const ROWS: [(usize, usize); 2] = [(1, 2), (0, 3)];

/// Solves the boundary system with the isotropic medium's modes `iso_in`, `iso_out` (`[s, p]`,
/// tangential `ψ`) and the other medium's `other_in`, `other_out` (any two modes each).
/// Fails where the reduced system is singular to working precision ([`singular`]).
///
/// When every field is real (lossless media, propagating waves: the common case) the same
/// steps run in real arithmetic, which is what the complex ones reduce to then.
#[inline]
pub fn solve<R: Real>(
    iso_in: &Pair<Cx<R>>,
    iso_out: &Pair<Cx<R>>,
    other_in: &Pair<Cx<R>>,
    other_out: &Pair<Cx<R>>,
) -> Result<Solution<Cx<R>>> {
    let all = [iso_in, iso_out, other_in, other_out];
    let zero = R::zero();
    let real_fields = all
        .iter()
        .flat_map(|p| p.iter().flatten())
        .fold(R::Mask::cst(true), |m, z| m & z.im.equals(zero));
    if real_fields.surely() {
        let s = solve_in(
            &real(iso_in),
            &real(iso_out),
            &real(other_in),
            &real(other_out),
        )?;
        return Ok(Solution {
            x: complex(&s.x),
            y: complex(&s.y),
        });
    }
    solve_in(iso_in, iso_out, other_in, other_out)
}

/// The real parts.
#[inline(always)]
fn real<R: Real>(p: &Pair<Cx<R>>) -> Pair<R> {
    let r = |m: &[Cx<R>; 4]| [m[0].re, m[1].re, m[2].re, m[3].re];
    [r(&p[0]), r(&p[1])]
}

/// As complex numbers.
#[inline(always)]
fn complex<R: Real>(p: &Pair<R>) -> Pair<Cx<R>> {
    let c = |m: &[R; 4]| m.map(|x| Cx::new(x, R::zero()));
    [c(&p[0]), c(&p[1])]
}

/// [`solve`] in the arithmetic of `T`.
#[inline]
fn solve_in<R: Real, T: Scalar<R>>(
    iso_in: &Pair<T>,
    iso_out: &Pair<T>,
    other_in: &Pair<T>,
    other_out: &Pair<T>,
) -> Result<Solution<T>> {
    let rows = [Row::new(&iso_out[0], 0), Row::new(&iso_out[1], 1)];
    let mut l = [[T::zero(); 2]; 2];
    let mut rhs = [[T::zero(); 4]; 2];
    for (k, row) in rows.iter().enumerate() {
        rhs[k][k] = row.form(&iso_in[k]);
        for j in 0..2 {
            l[k][j] = row.form(&other_out[j]);
            rhs[k][2 + j] = -row.form(&other_in[j]);
        }
    }
    let y = solve2(&l, &rhs)?;
    let x = [
        rows[0].back_substitute(iso_in, other_in, other_out, &y),
        rows[1].back_substitute(iso_in, other_in, other_out, &y),
    ];
    Ok(Solution { x, y })
}

/// The two rows `E(k)`, `H(k)` of isotropic polarisation `k`, ordered `(lead, second)` so that
/// the outgoing wave's `lead` component is the larger one: the back-substitution row and the
/// normalisation of the eliminating form. Which row leads is a lane's choice.
struct Row<R: Real, T> {
    /// True where the `E(k)` row leads (else the `H(k)` row).
    e_leads: R::Mask,
    /// `1 / lead(O)`.
    inv: T,
    /// `second(O) / lead(O)`: the admittance `Y_k` or its inverse, modulus ≤ 1.
    ratio: T,
    /// The polarisation.
    k: usize,
}

impl<R: Real, T: Scalar<R>> Row<R, T> {
    #[inline(always)]
    fn new(out: &[T; 4], k: usize) -> Self {
        let (e, h) = ROWS[k];
        let e_leads = out[e].norm_sqr().ge(out[h].norm_sqr());
        let lead = T::select(e_leads, out[e], out[h]);
        let second = T::select(e_leads, out[h], out[e]);
        let inv = lead.inverse();
        Row {
            e_leads,
            inv,
            ratio: second * inv,
            k,
        }
    }

    /// `(lead, second)` components of `ψ`.
    #[inline(always)]
    fn split(&self, psi: &[T; 4]) -> (T, T) {
        let (e, h) = ROWS[self.k];
        (
            T::select(self.e_leads, psi[e], psi[h]),
            T::select(self.e_leads, psi[h], psi[e]),
        )
    }

    /// The lead component of `ψ` (its back-substitution row).
    #[inline(always)]
    fn lead(&self, psi: &[T; 4]) -> T {
        self.split(psi).0
    }

    /// Row `k` of the isotropic outgoing amplitudes `x_out` for unit incoming amplitudes
    /// `[x_in; y_in]` (columns), given the other medium's outgoing ones `y`: the lead row of
    /// `I x_in + O x_out = A_out y_out + A_in y_in` solved for `x_out,k`.
    #[inline(always)]
    fn back_substitute(
        &self,
        iso_in: &Pair<T>,
        other_in: &Pair<T>,
        other_out: &Pair<T>,
        y: &Pair<T>,
    ) -> [T; 4] {
        let (a0, a1) = (self.lead(&other_out[0]), self.lead(&other_out[1]));
        let mut x = [T::zero(); 4];
        x[self.k] = -self.lead(&iso_in[self.k]);
        x[2] = self.lead(&other_in[0]);
        x[3] = self.lead(&other_in[1]);
        for (col, v) in x.iter_mut().enumerate() {
            *v = (a0 * y[0][col] + a1 * y[1][col] + *v) * self.inv;
        }
        x
    }

    /// The eliminating form `C_k(ψ) = ratio · lead(ψ) − second(ψ)` (zero on the outgoing
    /// wave; up to a sign and scale the `C_k` of the module docs).
    #[inline(always)]
    fn form(&self, psi: &[T; 4]) -> T {
        let (lead, second) = self.split(psi);
        self.ratio * lead - second
    }
}

/// Solves `L X = B` (2x2 `L`, four right-hand sides) by Gaussian elimination with partial
/// pivoting; fails where `L` is singular to working precision (a pivot below `1e-300` of the
/// largest entry, squared moduli: the criterion of [`crate::cmath::solve4`]).
#[inline]
fn solve2<R: Real, T: Scalar<R>>(l: &[[T; 2]; 2], b: &Pair<T>) -> Result<Pair<T>> {
    let scale = l
        .iter()
        .flatten()
        .map(|z| z.norm_sqr())
        .fold(R::zero(), |a, x| a.max(x));
    // The pivot row is the one with the larger first entry: `top`, the other `bottom`.
    let swap = l[1][0].norm_sqr().gt(l[0][0].norm_sqr());
    let pick = |top: bool, a: T, b: T| {
        if top {
            T::select(swap, b, a)
        } else {
            T::select(swap, a, b)
        }
    };
    let row = |top: bool, i: usize| pick(top, l[0][i], l[1][i]);
    let rhs = |top: bool, col: usize| pick(top, b[0][col], b[1][col]);
    let (top, bottom) = (true, false);
    let p0 = pivot(row(top, 0), scale)?;
    let inv0 = p0.inverse();
    let m = row(bottom, 0) * inv0;
    let p1 = pivot(row(bottom, 1) - m * row(top, 1), scale)?;
    let inv1 = p1.inverse();
    let x1: [T; 4] = std::array::from_fn(|col| (rhs(bottom, col) - m * rhs(top, col)) * inv1);
    let x0 = std::array::from_fn(|col| (rhs(top, col) - row(top, 1) * x1[col]) * inv0);
    Ok([x0, x1])
}

/// `pivot`, or the singular error where it is too small to divide by (or NaN) relative to
/// `scale` (largest squared modulus); while recording such lanes fail and divide by one.
#[inline]
fn pivot<R: Real, T: Scalar<R>>(pivot: T, scale: R) -> Result<T> {
    let n = pivot.norm_sqr();
    let negligible = !n.gt(scale * 1e-300);
    negligible.fail(singular)?;
    Ok(negligible.when(T::one, || pivot))
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64 as C64;

    #[test]
    fn solve2_inverts_and_detects_singular() {
        let c = |re: f64, im: f64| C64::new(re, im);
        let l = [[c(1e-3, 0.2), c(2.0, -1.0)], [c(0.5, 0.5), c(-0.3, 0.1)]];
        let b = [
            [c(1.0, 0.0), c(0.0, 1.0), c(2.0, -3.0), c(0.1, 0.0)],
            [c(0.0, 0.0), c(1.0, 1.0), c(-1.0, 0.5), c(0.0, 0.7)],
        ];
        let x = solve2::<f64, C64>(&l, &b).unwrap();
        for i in 0..2 {
            for col in 0..4 {
                let r = l[i][0] * x[0][col] + l[i][1] * x[1][col] - b[i][col];
                assert!(r.norm() < 1e-14, "{r}");
            }
        }
        let s = [[c(1.0, 1.0), c(2.0, 2.0)], [c(0.5, 0.5), c(1.0, 1.0)]];
        assert!(solve2::<f64, C64>(&s, &b).is_err());
    }

    /// The real arithmetic does exactly what the complex one does on real fields: the same
    /// operations, and complex products with zero imaginary parts round like real ones.
    #[test]
    fn real_arithmetic_equals_complex_arithmetic_on_real_fields() {
        let mut uniform = crate::cmath::uniform(12345);
        let mut next = || 4.0 * uniform() - 2.0;
        for _ in 0..1000 {
            let mut pair = |sp: bool| {
                let mut p = [[0.0; 4]; 2];
                for (k, m) in p.iter_mut().enumerate() {
                    for (i, v) in m.iter_mut().enumerate() {
                        // s/p structure on the isotropic side: s in (E_y, H_x), p in (E_x, H_y).
                        let used = !sp || (k == 0) == (i == 1 || i == 2);
                        *v = if used { next() } else { 0.0 };
                    }
                }
                p
            };
            let (a, b, c, d) = (pair(true), pair(true), pair(false), pair(false));
            let real = solve_in::<f64, f64>(&a, &b, &c, &d).unwrap();
            let z = |p: &Pair<f64>| complex(p);
            let full = solve_in(&z(&a), &z(&b), &z(&c), &z(&d)).unwrap();
            for (r, f) in [(&real.x, &full.x), (&real.y, &full.y)] {
                for (r, f) in r.iter().flatten().zip(f.iter().flatten()) {
                    assert_eq!(*r, f.re);
                    assert_eq!(f.im, 0.0);
                }
            }
        }
    }
}
