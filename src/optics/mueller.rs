//! Jones → Mueller, converted once into Mitsuba's convention.
//!
//! The core's fields vary as `exp(−iωt)`; Mitsuba's as `exp(+iωt)` (absorbing index `n − iκ`),
//! so a core Jones matrix `J` is Mitsuba's `conj(J)`. With Mitsuba's Stokes definitions
//! (frame `(x, y, k)` right-handed, `S = (|Ex|²+|Ey|², |Ex|²−|Ey|², 2Re(Ex* Ey), 2Im(Ex* Ey))`)
//! the Mueller matrix is `M = Re(A (J_m ⊗ J_m*) A⁻¹)`, `J_m = conj(J)`,
//! `A = [[1,0,0,1],[1,0,0,−1],[0,1,1,0],[0,i,−i,0]]`. Written out below entry by entry.

use crate::real::complex::{self as cx, Cx};
use crate::real::Real;
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;

/// The Mueller matrix (Mitsuba's convention) of a core Jones matrix `j` (rows = output
/// components, columns = input components, both in `(x, y)` Stokes frames).
///
/// Written out as `M_ij = ½ tr(σ_i J_m σ_j J_m†)` with Mitsuba's Stokes basis `σ₀ = I`,
/// `σ₁ = diag(1, −1)`, `σ₂ = [[0,1],[1,0]]`, `σ₃ = [[0,−i],[i,0]]` (a real-arithmetic closed
/// form; equal to `from_coherency(&coherency(j))`, which the tests check).
pub fn from_jones<T: Real>(j: &Matrix2<Cx<T>>) -> Matrix4<T> {
    // Columns a, b of Mitsuba's Jones matrix conj(J).
    let (a0, a1) = (j[(0, 0)].conj(), j[(1, 0)].conj());
    let (b0, b1) = (j[(0, 1)].conj(), j[(1, 1)].conj());
    let (p, q, r, s) = (a0.norm_sqr(), a1.norm_sqr(), b0.norm_sqr(), b1.norm_sqr());
    let x = a1 * a0.conj();
    let y = b1 * b0.conj();
    let u = a1 * b0.conj();
    let v = b1 * a0.conj();
    let w00 = a0 * b0.conj();
    let w11 = a1 * b1.conj();
    let (two, half) = (T::cst(2.0), T::cst(0.5));
    // B_j = J σ_j J† as (B00, B11, B10) for j = 0..3; i (v − u) written out.
    let vu = v - u;
    let bs = [
        (p + r, q + s, x + y),
        (p - r, q - s, x - y),
        (two * w00.re, two * w11.re, u + v),
        (two * w00.im, two * w11.im, Cx::new(-vu.im, vu.re)),
    ];
    let mut m = Matrix4::from_element(T::zero());
    for (col, (b00, b11, b10)) in bs.into_iter().enumerate() {
        m[(0, col)] = half * (b00 + b11);
        m[(1, col)] = half * (b00 - b11);
        m[(2, col)] = b10.re;
        m[(3, col)] = b10.im;
    }
    m
}

/// [`from_jones`] of `[[a, b], [0, 0]]` (light leaving in the `x` state of its frame only, as a
/// crystal wave does), written out: rows 0 and 1 are
/// `(½(|a|² + |b|²), ½(|a|² − |b|²), Re(ā b), Im(ā b))`, rows 2 and 3 zero.
pub fn from_jones_row<T: Real>(a: Cx<T>, b: Cx<T>) -> Matrix4<T> {
    let (p, r) = (cx::norm_sqr(a), cx::norm_sqr(b));
    let w = a.conj() * b;
    let row = [(p + r) * 0.5, (p - r) * 0.5, w.re, w.im];
    Matrix4::from_fn(|i, j| if i < 2 { row[j] } else { T::zero() })
}

/// [`from_jones`] of `[[a, 0], [c, 0]]` (light arriving in the `x` state of its frame only, as a
/// crystal wave does), written out: columns 0 and 1 are
/// `(½(|a|² + |c|²), ½(|a|² − |c|²), Re(c̄ a), Im(c̄ a))`, columns 2 and 3 zero.
pub fn from_jones_column<T: Real>(a: Cx<T>, c: Cx<T>) -> Matrix4<T> {
    let (p, q) = (cx::norm_sqr(a), cx::norm_sqr(c));
    let x = c.conj() * a;
    let column = [(p + q) * 0.5, (p - q) * 0.5, x.re, x.im];
    Matrix4::from_fn(|i, j| if j < 2 { column[i] } else { T::zero() })
}

/// The coherency superoperator `K(J) = J_m ⊗ conj(J_m) = conj(J) ⊗ J`: it maps the vectorised
/// coherency matrix (Mitsuba's convention) of the input to that of the output, and composes
/// like the Jones matrices do (`K(J₁J₂) = K(J₁)K(J₂)`). Sums of `K` over incoherent paths and
/// band-integrated sums over coherent pairs of paths are still coherency superoperators.
pub fn coherency(j: &Matrix2<C64>) -> Matrix4<C64> {
    cross(j, j)
}

/// The cross term `conj(J₁) ⊗ J₂` of two coherent contributions (`coherency(J) = cross(J, J)`):
/// entry `(2 r₁ + r₂, 2 c₁ + c₂)` is `conj(J₁[r₁][c₁]) J₂[r₂][c₂]`.
pub fn cross(j1: &Matrix2<C64>, j2: &Matrix2<C64>) -> Matrix4<C64> {
    Matrix4::from_fn(|r, c| j1[(r / 2, c / 2)].conj() * j2[(r % 2, c % 2)])
}

/// The Mueller matrix of a coherency superoperator that is diagonal, `diag(ss, sp, conj(sp),
/// pp)`: that of a diagonal Jones matrix `diag(a, b)` (or of a sum of such), with `ss = |a|²`,
/// `sp = conj(a) b`, `pp = |b|²` (or their averages). `from_coherency` written out:
/// `M₀₀ = M₁₁ = (ss + pp)/2`, `M₀₁ = M₁₀ = (ss − pp)/2`, `M₂₂ = M₃₃ = Re sp`,
/// `M₂₃ = −M₃₂ = Im sp`.
pub fn from_diagonal<T: Real>(ss: T, sp: Cx<T>, pp: T) -> Matrix4<T> {
    let (a, d) = ((ss + pp) * 0.5, (ss - pp) * 0.5);
    let z = T::zero();
    Matrix4::new(
        a, d, z, z, //
        d, a, z, z, //
        z, z, sp.re, sp.im, //
        z, z, -sp.im, sp.re,
    )
}

/// The Mueller matrix `Re(A K A⁻¹)` of a coherency superoperator, written out: `A` has only
/// the entries 0, ±1, ±i, so `B = K A⁻¹ = ½ K A†` takes the column combinations
/// `(K₀ + K₃, K₀ − K₃, K₁ + K₂, i (K₂ − K₁))/2` and `A B` the row combinations
/// `(B₀ + B₃, B₀ − B₃, B₁ + B₂, i (B₁ − B₂))` (equal to the matrix products; tested).
pub fn from_coherency(k: &Matrix4<C64>) -> Matrix4<f64> {
    let i = C64::new(0.0, 1.0);
    let b = Matrix4::from_fn(|r, j| {
        0.5 * match j {
            0 => k[(r, 0)] + k[(r, 3)],
            1 => k[(r, 0)] - k[(r, 3)],
            2 => k[(r, 1)] + k[(r, 2)],
            _ => i * (k[(r, 2)] - k[(r, 1)]),
        }
    });
    Matrix4::from_fn(|r, j| {
        match r {
            0 => b[(0, j)] + b[(3, j)],
            1 => b[(0, j)] - b[(3, j)],
            2 => b[(1, j)] + b[(2, j)],
            _ => i * (b[(1, j)] - b[(2, j)]),
        }
        .re
    })
}

/// The Mueller matrix of the reversed path, `Q Mᵀ Q` with `Q = diag(1, 1, −1, 1)`: the
/// reciprocity theorem for media with symmetric dielectric tensors (Z. Sekera, JOSA 56, 1732,
/// 1966), in Mitsuba's Stokes convention with each beam's frame keeping its `x` axis (the
/// reversed beam's `y = k × x` changes sign, and with it `U`). Light from `−wo` that reaches
/// `wi` retraces the wave that went from `−wi` to `wo`, so one forward solve gives both
/// transport modes of a lobe.
pub fn reversed<T: Real>(m: &Matrix4<T>) -> Matrix4<T> {
    let mut r = m.transpose();
    for i in 0..4 {
        r[(i, 2)] = -r[(i, 2)];
        r[(2, i)] = -r[(2, i)];
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The written-out rank-one forms equal the general one (same operations: exactly).
    #[test]
    fn row_and_column_forms_equal_from_jones() {
        let mut next = crate::cmath::uniform(5);
        let z = C64::new(0.0, 0.0);
        for _ in 0..1000 {
            let mut c = || C64::new(2.0 * next() - 1.0, 2.0 * next() - 1.0);
            let (a, b) = (c(), c());
            assert_eq!(from_jones_row(a, b), from_jones(&Matrix2::new(a, b, z, z)));
            assert_eq!(
                from_jones_column(a, b),
                from_jones(&Matrix2::new(a, z, b, z))
            );
        }
    }

    /// Mitsuba's coherency → Stokes matrix `A`.
    fn a_matrix() -> Matrix4<C64> {
        let (o, z, i) = (C64::new(1.0, 0.0), C64::new(0.0, 0.0), C64::new(0.0, 1.0));
        Matrix4::new(o, z, z, o, o, z, z, -o, z, o, o, z, z, i, -i, z)
    }

    /// `A⁻¹ = ½ A†`.
    fn a_inverse() -> Matrix4<C64> {
        a_matrix().adjoint() * C64::new(0.5, 0.0)
    }

    /// Stokes vector (Mitsuba's definitions) of a core-convention field `(ex, ey)`.
    fn stokes(ex: C64, ey: C64) -> [f64; 4] {
        let (ex, ey) = (ex.conj(), ey.conj()); // Mitsuba's fields
        let c = ex.conj() * ey;
        [
            ex.norm_sqr() + ey.norm_sqr(),
            ex.norm_sqr() - ey.norm_sqr(),
            2.0 * c.re,
            2.0 * c.im,
        ]
    }

    #[test]
    fn mueller_maps_stokes_of_fully_polarised_fields() {
        let j = Matrix2::new(
            C64::new(0.3, -0.2),
            C64::new(-0.1, 0.5),
            C64::new(0.7, 0.05),
            C64::new(-0.4, -0.6),
        );
        let m = from_jones(&j);
        for (ex, ey) in [(1.0, 0.0), (0.3, 0.8), (-0.5, 0.2)] {
            let e = (C64::new(ex, 0.1), C64::new(ey, -0.4));
            let out = (
                j[(0, 0)] * e.0 + j[(0, 1)] * e.1,
                j[(1, 0)] * e.0 + j[(1, 1)] * e.1,
            );
            let (si, so) = (stokes(e.0, e.1), stokes(out.0, out.1));
            for r in 0..4 {
                let got: f64 = (0..4).map(|c| m[(r, c)] * si[c]).sum();
                assert!((got - so[r]).abs() < 1e-14, "row {r}: {got} vs {}", so[r]);
            }
        }
    }

    #[test]
    fn written_out_coherency_algebra_equals_the_matrix_products() {
        let j1 = Matrix2::new(
            C64::new(0.3, -0.2),
            C64::new(-0.1, 0.5),
            C64::new(0.7, 0.05),
            C64::new(-0.4, -0.6),
        );
        let j2 = Matrix2::new(
            C64::new(-0.25, 0.1),
            C64::new(0.6, -0.3),
            C64::new(0.02, 0.9),
            C64::new(0.5, 0.45),
        );
        let kron = j1.map(|z| z.conj()).kronecker(&j2);
        assert!((cross(&j1, &j2) - kron).norm() < 1e-15);
        let k = kron + coherency(&j2) * C64::new(0.3, -0.7);
        let product = (a_matrix() * k * a_inverse()).map(|x| x.re);
        assert!((from_coherency(&k) - product).norm() < 1e-14);
    }

    #[test]
    fn closed_form_equals_the_coherency_product() {
        let j = Matrix2::new(
            C64::new(0.3, -0.2),
            C64::new(-0.1, 0.5),
            C64::new(0.7, 0.05),
            C64::new(-0.4, -0.6),
        );
        assert!((from_jones(&j) - from_coherency(&coherency(&j))).norm() < 1e-14);
    }

    #[test]
    fn retarder_matches_mitsuba_linear_retarder() {
        // Core convention: a wave through index n gains exp(+i k n d); y slower by phi.
        let phi = 0.7f64;
        let j = Matrix2::new(
            C64::new(1.0, 0.0),
            C64::new(0.0, 0.0),
            C64::new(0.0, 0.0),
            C64::from_polar(1.0, phi),
        );
        let m = from_jones(&j);
        // mueller::linear_retarder(phi) of Mitsuba 3.
        let want = Matrix4::new(
            1.0,
            0.0,
            0.0,
            0.0,
            0.0,
            1.0,
            0.0,
            0.0,
            0.0,
            0.0,
            phi.cos(),
            phi.sin(),
            0.0,
            0.0,
            -phi.sin(),
            phi.cos(),
        );
        assert!((m - want).norm() < 1e-15, "{m}");
    }

    #[test]
    fn polarizer_along_x() {
        let o = C64::new(1.0, 0.0);
        let z = C64::new(0.0, 0.0);
        let m = from_jones(&Matrix2::new(o, z, z, z));
        let want = Matrix4::new(
            0.5, 0.5, 0.0, 0.0, 0.5, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
        );
        assert!((m - want).norm() < 1e-15);
    }

    #[test]
    fn diagonal_closed_form_equals_the_coherency_route() {
        let (a, b) = (C64::new(0.3, -0.7), C64::new(-0.45, 0.2));
        let j = Matrix2::new(a, C64::new(0.0, 0.0), C64::new(0.0, 0.0), b);
        let m = from_diagonal(a.norm_sqr(), a.conj() * b, b.norm_sqr());
        assert!((m - from_coherency(&coherency(&j))).norm() < 1e-15);
    }
}
