//! The stack with the internal round trips of its thick layers summed incoherently: the model
//! the spectral integration evaluates at each wavenumber (docs/physics.md §8).
//!
//! A camera channel or a band weighs the stack's spectrum with a weight whose Fourier transform
//! vanishes beyond a coherence length (the *reach*, [`crate::stack::plan`]). Paths whose
//! group paths differ by more than the reach do not interfere in the integrated result. A layer
//! is *thick* when its shortest internal round trip is longer than the reach: two paths that
//! differ by a round trip in it (or by different round trips) are then incoherent, while paths
//! with the same reflections that differ only in their modes (o or e in each traversal; group
//! paths differing by `d Δn_g`, the birefringent colours) stay coherent. Summing the
//! coherencies `J ⊗ J*` (Mueller matrices, which compose as the Jones matrices do) of every
//! sequence of reflections keeps exactly those pairs. Thin layers, whose round trips are within
//! the reach, are kept coherent with everything next to them: a run of thin layers between two
//! thick ones (or the exterior or exit) is a *segment*, solved in amplitudes (its four Redheffer
//! blocks) and then turned into Mueller blocks.
//!
//! From the bottom up, the part of the stack below a plane is its reflection `Γ` and
//! transmission `τ` from above; while only thin layers lie below, these are the amplitudes of
//! [`crate::stack::exact`]; at the first thick layer they become Mueller matrices, and above
//! every thick layer the segment over it `A` (Mueller blocks `R, T` from above, `R', T'` from
//! below) is joined to them by the same star product in Mueller space:
//!
//! ```text
//! Γ' = M(P↑) Γ M(P↓),  τ' = τ M(P↓)                        (through the thick layer)
//! Γ ← R + T' Γ' (I − R' Γ')⁻¹ T,   τ ← τ' (I − R' Γ')⁻¹ T    (the incoherent sum of round trips)
//! ```
//! A thick layer whose o/e coherence no combination of layers brings within the reach (a
//! millimetre of calcite alone) is also *depolarising* in the plan: its `M(P)` keeps the powers
//! of its two modes and drops their cross term, which no weight would see. Without thick layers
//! the model is the exact stack.

use crate::cmath;
use crate::error::Result;
use crate::optics::mueller;
use crate::plate::slab::{inverse, phase_factors, scale, SlabMueller, Want};
use crate::stack::exact::{resonance, StackBlocks, R_DOWN, R_UP, T_DOWN, T_UP};
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;

/// How each layer of a stack is treated for one spectrum (decided by
/// [`crate::stack::plan::StackPlan`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Coherence {
    /// Per layer: its round trips are incoherent.
    pub thick: Vec<bool>,
    /// Per layer: the cross term of its two modes is kept (always for thin layers).
    pub keep_modes: Vec<bool>,
}

impl Coherence {
    /// Every layer coherent: the exact stack.
    pub fn exact(layers: usize) -> Self {
        Coherence {
            thick: vec![false; layers],
            keep_modes: vec![true; layers],
        }
    }

    /// True if no layer is thick (the model is then the exact stack).
    pub fn is_exact(&self) -> bool {
        !self.thick.iter().any(|&t| t)
    }

    /// The thick layers from the bottom up, each with the first interface of the segment above
    /// it (the interface below the next thick layer up, or 0).
    fn thick_from_bottom(&self) -> Vec<(usize, usize)> {
        let thick: Vec<usize> = (0..self.thick.len()).filter(|&j| self.thick[j]).collect();
        thick
            .iter()
            .enumerate()
            .rev()
            .map(|(k, &j)| (j, if k == 0 { 0 } else { thick[k - 1] + 1 }))
            .collect()
    }
}

/// Mueller blocks `[R, T, R', T']` of a segment (the order of [`crate::stack::exact::InterfaceBlocks`]).
type MuellerBlocks = [Matrix4<f64>; 4];

/// What does not change between wavenumbers: the thick layers from the bottom up with the
/// first interface of the segment above each ([`Coherence::thick_from_bottom`]), and, when the
/// interface blocks do not change either (a stack without dispersion), the Mueller blocks of
/// segments that are a single interface.
#[derive(Clone, Debug, Default)]
pub struct Prepared {
    /// `(thick layer, first interface of the segment above it)`, from the bottom up.
    thick: Vec<(usize, usize)>,
    /// Per thick layer, the blocks of the segment above it if that is one interface (and they
    /// are fixed).
    above: Vec<Option<MuellerBlocks>>,
    /// `(M(Γ), M(τ))` of the bottom segment if it is the exit interface alone (and fixed).
    bottom: Option<(Matrix4<f64>, Matrix4<f64>)>,
}

impl Prepared {
    /// The structure of `coherence`, without fixed blocks.
    pub fn structure(coherence: &Coherence) -> Self {
        let thick = coherence.thick_from_bottom();
        Prepared {
            above: vec![None; thick.len()],
            thick,
            bottom: None,
        }
    }

    /// The structure of `coherence` and the fixed single-interface segments of `blocks`.
    pub fn new(blocks: &StackBlocks, coherence: &Coherence) -> Self {
        let mut p = Self::structure(coherence);
        let n = blocks.layers();
        let Some(&(lowest, _)) = p.thick.first() else {
            return p;
        };
        p.above = p
            .thick
            .iter()
            .map(|&(j, a)| (a == j).then(|| blocks.interfaces[j].map(|m| mueller::from_jones(&m))))
            .collect();
        p.bottom = (lowest == n - 1).then(|| {
            let last = &blocks.interfaces[n];
            (
                mueller::from_jones(&last[R_DOWN]),
                mueller::from_jones(&last[T_DOWN]),
            )
        });
        p
    }
}

/// The Mueller matrices (Mitsuba's convention, s/p frames, power fractions) of the stack of
/// `blocks` at `lambda_nm` under `coherence` (module docs). `prepared`: from
/// [`Prepared::new`] of the same blocks, or [`Prepared::structure`] of `coherence`.
pub fn mueller(
    blocks: &StackBlocks,
    coherence: &Coherence,
    prepared: &Prepared,
    lambda_nm: f64,
    want: Want,
) -> Result<SlabMueller> {
    if coherence.is_exact() {
        return blocks.mueller(lambda_nm, want);
    }
    let thick = &prepared.thick;
    let n = blocks.layers();
    // The bottom segment (thin layers under the lowest thick layer) in amplitudes.
    let lowest = thick[0].0;
    let (mut gamma, mut tau) = match prepared.bottom {
        Some(b) => b,
        None => {
            let (g, t) = from_above(blocks, lowest + 1, n, lambda_nm)?;
            (mueller::from_jones(&g), mueller::from_jones(&t))
        }
    };
    for (k, &(j, a)) in thick.iter().enumerate() {
        let (pd, pu) = phase_factors(blocks.thickness_nm[j], lambda_nm, &blocks.q[j]);
        let keep = coherence.keep_modes[j];
        let (md, mu) = (diagonal(pd, keep), diagonal(pu, keep));
        // M(P) is block diagonal (2×2 blocks on modes 0-1 and 2-3): multiplied by its blocks.
        let g = times_diagonal(&diagonal_times(&mu, &gamma), &md);
        let t = times_diagonal(&tau, &md);
        let seg = match prepared.above[k] {
            Some(s) => s,
            None => segment(blocks, a, j, lambda_nm)?.map(|m| mueller::from_jones(&m)),
        };
        let d = (Matrix4::identity() - mul4(&seg[R_UP], &g))
            .try_inverse()
            .ok_or_else(resonance)?;
        let y = mul4(&d, &seg[T_DOWN]);
        tau = mul4(&t, &y);
        gamma = seg[R_DOWN] + mul4(&seg[T_UP], &mul4(&g, &y));
    }
    Ok(SlabMueller {
        r: want.reflection.then_some(gamma),
        t: want.transmission.then(|| tau * blocks.flux),
    })
}

/// `a b` of real 4×4 matrices, written out on the column-major storage (the generic product
/// does not unroll).
#[inline]
fn mul4(a: &Matrix4<f64>, b: &Matrix4<f64>) -> Matrix4<f64> {
    let (a, b) = (a.as_slice(), b.as_slice());
    let mut out = [0.0; 16];
    for j in 0..4 {
        for i in 0..4 {
            out[4 * j + i] = a[i] * b[4 * j]
                + a[4 + i] * b[4 * j + 1]
                + a[8 + i] * b[4 * j + 2]
                + a[12 + i] * b[4 * j + 3];
        }
    }
    Matrix4::from_column_slice(&out)
}

/// `D m` for `D` block diagonal ([`diagonal`]: rows 0-1 and 2-3 mix in pairs).
#[inline]
fn diagonal_times(d: &Matrix4<f64>, m: &Matrix4<f64>) -> Matrix4<f64> {
    let (d, m) = (d.as_slice(), m.as_slice());
    let mut out = [0.0; 16];
    for j in 0..4 {
        for i in 0..4 {
            let b = i & !1;
            out[4 * j + i] = d[4 * b + i] * m[4 * j + b] + d[4 * (b + 1) + i] * m[4 * j + b + 1];
        }
    }
    Matrix4::from_column_slice(&out)
}

/// `m D` for `D` block diagonal ([`diagonal`]: columns 0-1 and 2-3 mix in pairs).
#[inline]
fn times_diagonal(m: &Matrix4<f64>, d: &Matrix4<f64>) -> Matrix4<f64> {
    let (m, d) = (m.as_slice(), d.as_slice());
    let mut out = [0.0; 16];
    for j in 0..4 {
        let b = j & !1;
        for i in 0..4 {
            out[4 * j + i] = m[4 * b + i] * d[4 * j + b] + m[4 * (b + 1) + i] * d[4 * j + b + 1];
        }
    }
    Matrix4::from_column_slice(&out)
}

/// `M(diag(a, b))` in the convention of [`mueller::from_jones`] (written out: `v = a b̄`), with
/// the cross term of the two modes dropped unless `keep`.
#[inline]
pub fn diagonal(p: [C64; 2], keep: bool) -> Matrix4<f64> {
    let (s, d) = (
        0.5 * (p[0].norm_sqr() + p[1].norm_sqr()),
        0.5 * (p[0].norm_sqr() - p[1].norm_sqr()),
    );
    let v = if keep {
        p[0] * p[1].conj()
    } else {
        C64::new(0.0, 0.0)
    };
    Matrix4::new(
        s, d, 0.0, 0.0, //
        d, s, 0.0, 0.0, //
        0.0, 0.0, v.re, -v.im, //
        0.0, 0.0, v.im, v.re,
    )
}

/// `(Γ, τ)` from above of interfaces `first..=last` and the thin layers between them (the
/// recursion of [`crate::stack::exact`]), referred to the top of interface `first`; `τ` without
/// the flux factor.
fn from_above(
    blocks: &StackBlocks,
    first: usize,
    last: usize,
    lambda_nm: f64,
) -> Result<(Matrix2<C64>, Matrix2<C64>)> {
    let bottom = &blocks.interfaces[last];
    let (mut gamma, mut tau) = (bottom[R_DOWN], bottom[T_DOWN]);
    for j in (first..last).rev() {
        let (pd, pu) = phase_factors(blocks.thickness_nm[j], lambda_nm, &blocks.q[j]);
        let g = scale(&pu, &gamma, &pd);
        let t = scale(&[C64::new(1.0, 0.0); 2], &tau, &pd);
        let iface = &blocks.interfaces[j];
        let x = inverse(&(Matrix2::identity() - cmath::mul2(&iface[R_UP], &g)))
            .map_err(|_| resonance())?;
        let y = cmath::mul2(&x, &iface[T_DOWN]);
        tau = cmath::mul2(&t, &y);
        gamma = iface[R_DOWN] + cmath::mul2(&iface[T_UP], &cmath::mul2(&g, &y));
    }
    Ok((gamma, tau))
}

/// The four amplitude blocks `[R, T, R', T']` of interfaces `first..=last` with the thin layers
/// between them (Redheffer star products from the top down; reference planes at the top of
/// interface `first` and the bottom of interface `last`).
fn segment(
    blocks: &StackBlocks,
    first: usize,
    last: usize,
    lambda_nm: f64,
) -> Result<[Matrix2<C64>; 4]> {
    let mut s = blocks.interfaces[first];
    let one = [C64::new(1.0, 0.0); 2];
    for l in first..last {
        let (pd, pu) = phase_factors(blocks.thickness_nm[l], lambda_nm, &blocks.q[l]);
        s[T_DOWN] = scale(&pd, &s[T_DOWN], &one);
        s[R_UP] = scale(&pd, &s[R_UP], &pu);
        s[T_UP] = scale(&one, &s[T_UP], &pu);
        s = star(&s, &blocks.interfaces[l + 1])?;
    }
    Ok(s)
}

/// The Redheffer star product of `a` (above) and `b` (below), blocks `[R, T, R', T']`.
fn star(a: &[Matrix2<C64>; 4], b: &[Matrix2<C64>; 4]) -> Result<[Matrix2<C64>; 4]> {
    let id = Matrix2::identity();
    let mul = cmath::mul2;
    let d = inverse(&(id - mul(&a[R_UP], &b[R_DOWN]))).map_err(|_| resonance())?;
    let e = inverse(&(id - mul(&b[R_DOWN], &a[R_UP]))).map_err(|_| resonance())?;
    let da = mul(&d, &a[T_DOWN]);
    let eb = mul(&e, &b[T_UP]);
    Ok([
        a[R_DOWN] + mul(&a[T_UP], &mul(&b[R_DOWN], &da)),
        mul(&b[T_DOWN], &da),
        b[R_UP] + mul(&b[T_DOWN], &mul(&a[R_UP], &eb)),
        mul(&a[T_UP], &eb),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The written-out diagonal Mueller matrix is `from_jones` of the diagonal Jones matrix,
    /// and the written-out products are the products.
    #[test]
    fn diagonal_is_from_jones() {
        let (a, b) = (C64::new(0.3, -0.7), C64::new(-0.2, 0.5));
        let m = mueller::from_jones(&Matrix2::new(a, C64::new(0.0, 0.0), C64::new(0.0, 0.0), b));
        let d = diagonal([a, b], true);
        assert!((d - m).norm() < 1e-15);
        let x = Matrix4::from_fn(|i, j| ((3 * i + 7 * j) % 11) as f64 - 4.5);
        assert!((mul4(&x, &d.transpose()) - x * d.transpose()).norm() < 1e-13);
        assert!((diagonal_times(&d, &x) - d * x).norm() < 1e-13);
        assert!((times_diagonal(&x, &d) - x * d).norm() < 1e-13);
    }
}
