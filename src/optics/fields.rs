//! Closed-form o and e fields of a uniaxial medium for known normal components (supplemental eqs.
//! S9-S10), in real or complex arithmetic ([`Scalar`]): lossless media with propagating waves
//! have real fields, and the same steps in `f64` give what the complex ones reduce to.
//!
//! Working frame of [`crate::optics::modes`]: `k = (β, 0, q)` in units of `k0`. The displacement of the
//! o-wave is `D_o ∝ k × A`, that of the e-wave `D_e ∝ k × (k × A)` (both ⟂ k), and
//! `E = ε⁻¹ D` with `ε⁻¹ = I/ε_o + Δ(1/ε) A Aᵀ` (eq. S6); `E` has unit Hermitian norm,
//! `H = k × E` (eq. S2). If `k` is (numerically) along the axis, `k × A` vanishes, o and e
//! are degenerate and `ŷ` stands in for `k × A`; the two fields still span the transverse plane.

use crate::cmath::Scalar;
use crate::real::{Mask, Real};
use nalgebra::Vector3;

/// A 3-vector of the arithmetic `T`.
pub type V3<T> = [T; 3];

/// One mode's fields and normal Poynting flux `½ Re(E × H*)_z`, over the reals `R`.
#[derive(Clone, Copy, Debug)]
pub struct Wave<T, R = f64> {
    /// Electric field, unit Hermitian norm.
    pub e: V3<T>,
    /// Magnetic field `k × E`.
    pub h: V3<T>,
    /// Normal Poynting flux of the unit-amplitude wave (positive upwards).
    pub flux: R,
}

/// What the o and e fields of one medium and incidence parameter share: the axis, `β`, and
/// `ε`, `ε⁻¹` as scalars, so that `ε v` and `ε⁻¹ v` cost a dot product with the (real) axis.
pub struct Fields<T, R = f64> {
    beta: T,
    axis: Vector3<R>,
    eps_o: T,
    delta_eps: T,
    inv_o: T,
    delta_inv: T,
}

impl<R: Real, T: Scalar<R>> Fields<T, R> {
    /// The fields of a medium with permittivities `eps_o`, `eps_e` and unit `axis` at `beta`.
    #[inline(always)]
    pub fn new(eps_o: T, eps_e: T, axis: Vector3<R>, beta: T) -> Self {
        let (inv_o, inv_e) = (eps_o.inverse(), eps_e.inverse());
        Fields {
            beta,
            axis,
            eps_o,
            delta_eps: eps_e - eps_o,
            inv_o,
            delta_inv: inv_e - inv_o,
        }
    }

    /// The o-wave of normal component `q`.
    #[inline(always)]
    pub fn ordinary(&self, q: T) -> Wave<T, R> {
        self.wave(q, normalize(self.ordinary_displacement(q)))
    }

    /// The e-wave of normal component `q`. `ek_z = Some((exact, (εk)_z))` for a lossless medium
    /// (real `β`): where `exact` holds (the wave propagates) its flux is evaluated without
    /// cancellation. Its ray is `∝ ε k` (eq. S12), so `S_z = (S·k) (εk)_z / (kᵀεk)` with
    /// `(εk)_z = a q + b = ±w` known exactly from the root (near `K_max` the direct
    /// `½(E×H*)_z` loses digits).
    #[inline(always)]
    pub fn extraordinary(&self, q: T, ek_z: Option<(R::Mask, R)>) -> Wave<T, R> {
        let d = k_cross(self.beta, q, &self.ordinary_displacement(q));
        let mut wave = self.wave(q, normalize(self.inverse_permittivity_times(&d)));
        if let Some((exact, ek_z)) = ek_z {
            let direct = wave.flux;
            wave.flux = exact.when(
                || {
                    let (e, h) = (&wave.e, &wave.h);
                    // `S·k` with `k = (β, 0, q)` real: only `S_x` and `S_z` of `½ Re(E × H*)`.
                    let s_x = (e[1] * h[2].conj() - e[2] * h[1].conj()).re() * 0.5;
                    let k_eps_k = self.k_eps_k(q).re();
                    (s_x * self.beta.re() + direct * q.re()) * ek_z / k_eps_k
                },
                || direct,
            );
        }
        wave
    }

    /// The wave of normal component `q` and field `e`.
    #[inline(always)]
    fn wave(&self, q: T, e: V3<T>) -> Wave<T, R> {
        let h = k_cross(self.beta, q, &e);
        let flux = (e[0] * h[1].conj() - e[1] * h[0].conj()).re() * 0.5;
        Wave { e, h, flux }
    }

    /// `A · v` for the real axis `A`.
    #[inline(always)]
    fn axis_dot(&self, v: &V3<T>) -> T {
        let a = &self.axis;
        v[0] * a.x + v[1] * a.y + v[2] * a.z
    }

    /// `ε⁻¹ v = v/ε_o + Δ(1/ε) A (A·v)`.
    #[inline(always)]
    fn inverse_permittivity_times(&self, v: &V3<T>) -> V3<T> {
        let c = self.delta_inv * self.axis_dot(v);
        let a = &self.axis;
        [
            v[0] * self.inv_o + c * a.x,
            v[1] * self.inv_o + c * a.y,
            v[2] * self.inv_o + c * a.z,
        ]
    }

    /// `kᵀ ε k = ε_o (β² + q²) + Δε (A·k)²` for `k = (β, 0, q)`.
    #[inline(always)]
    fn k_eps_k(&self, q: T) -> T {
        let beta = self.beta;
        let ak = beta * self.axis.x + q * self.axis.z;
        self.eps_o * (beta * beta + q * q) + self.delta_eps * ak * ak
    }

    /// `k × A` for `k = (β, 0, q)`, or `ŷ` when `k` is along the axis (degenerate direction).
    #[inline(always)]
    fn ordinary_displacement(&self, q: T) -> V3<T> {
        let (beta, a) = (self.beta, &self.axis);
        let c = [-(q * a.y), q * a.x - beta * a.z, beta * a.y];
        let tiny = (beta.norm_sqr() + q.norm_sqr()) * 1e-24;
        size(&c)
            .gt(tiny)
            .when(|| c, || [T::zero(), T::one(), T::zero()])
    }
}

/// `k × v` for `k = (β, 0, q)` (eq. S2 for `v = E`), written out for the zero `k_y`.
#[inline(always)]
pub fn k_cross<R: Real, T: Scalar<R>>(beta: T, q: T, v: &V3<T>) -> V3<T> {
    [-(q * v[1]), q * v[0] - beta * v[2], beta * v[1]]
}

/// `|v|²`, the squared Hermitian norm.
#[inline(always)]
fn size<R: Real, T: Scalar<R>>(v: &V3<T>) -> R {
    v[0].norm_sqr() + v[1].norm_sqr() + v[2].norm_sqr()
}

/// `v / |v|` with the Hermitian norm.
#[inline(always)]
fn normalize<R: Real, T: Scalar<R>>(v: V3<T>) -> V3<T> {
    let s = size(&v).sqrt().recip();
    [v[0] * s, v[1] * s, v[2] * s]
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64 as C64;

    /// The real arithmetic does exactly what the complex one does on real inputs (same
    /// operations; complex products with zero imaginary parts round like real ones).
    #[test]
    fn real_arithmetic_equals_complex_arithmetic_on_real_inputs() {
        let mut next = crate::cmath::uniform(777);
        let c = |x: f64| C64::new(x, 0.0);
        for i in 0..2000 {
            let axis = match i % 4 {
                0 => Vector3::z(),
                _ => Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize(),
            };
            let (eps_o, eps_e) = ((1.2 + 1.8 * next()).powi(2), (1.2 + 1.8 * next()).powi(2));
            let (beta, q) = (next(), 2.0 * next() - 1.0);
            let real = Fields::new(eps_o, eps_e, axis, beta);
            let full = Fields::new(c(eps_o), c(eps_e), axis, c(beta));
            let ek_z = Some((true, next()));
            let waves = [
                (real.ordinary(q), full.ordinary(c(q))),
                (real.extraordinary(q, ek_z), full.extraordinary(c(q), ek_z)),
                (real.extraordinary(q, None), full.extraordinary(c(q), None)),
            ];
            for (r, f) in waves {
                assert_eq!(r.flux, f.flux);
                for (r, f) in r.e.iter().chain(&r.h).zip(f.e.iter().chain(&f.h)) {
                    assert_eq!(*r, f.re);
                    assert_eq!(f.im, 0.0);
                }
            }
        }
    }
}
