//! Normal modes of a uniaxial (or isotropic) medium for a given incidence parameter.
//!
//! Working frame of this module (the "plane-of-incidence frame"): `z` is the surface normal
//! pointing into the upper (exterior) medium, `x` is the direction of the tangential wave
//! vector shared by every wave at the interface, `y = z × x` is the s direction. Every wave has
//! the wave vector `k = k0 (β, 0, q)`: `β = K/k0` is the incidence parameter (eq. S1) and
//! `q` the normal component (eq. S9). Lengths of wave vectors are in units of `k0`, so
//! nothing here depends on the wavelength (the supplemental's "note regarding k").

use crate::cmath::{self, Scalar};
use crate::optics::fields::{Fields, Wave};
use crate::optics::medium::Uniaxial;
use crate::real::complex::{self as cx, Cx};
use crate::real::{Mask, Real};
use nalgebra::Vector3;
use num_complex::Complex64 as C64;

/// A complex 3-vector.
pub type C3<T = f64> = Vector3<Cx<T>>;

/// Which polarisation family a mode belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeKind {
    /// Isotropic medium, electric field perpendicular to the plane of incidence.
    S,
    /// Isotropic medium, electric field in the plane of incidence: `E = k̂ × ŷ`.
    P,
    /// Ordinary wave of a uniaxial medium: `E ⟂ A`.
    O,
    /// Extraordinary wave of a uniaxial medium.
    E,
}

/// One plane-wave normal mode: `E(r) = e · exp(i k0 (β x + q z))`, `H = k × E` (in units where
/// the vacuum impedance is 1 and `μ = 1`).
///
/// Normalisation: s/p modes of isotropic media use the textbook bilinear basis `E_s = ŷ`,
/// `E_p = k̂ × ŷ` with `k̂ = k/η` (so Fresnel amplitudes are the textbook ones, for complex `η`
/// too); o/e modes of anisotropic media have unit Hermitian norm `|E| = 1` with the phase of
/// the closed-form construction of [`crate::optics::fields`] (real for real wave vectors).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mode<T: Real = f64> {
    /// Polarisation family.
    pub kind: ModeKind,
    /// Tangential wave-vector component `β = K/k0` (eq. S1).
    pub beta: Cx<T>,
    /// Normal wave-vector component `q/k0` (eq. S9).
    pub q: Cx<T>,
    /// Electric field (eq. S10).
    pub e: C3<T>,
    /// Magnetic field `k × E` (eq. S2).
    pub h: C3<T>,
    /// Normal Poynting flux `½ Re(E × H*)_z` of the unit-amplitude mode (positive upwards).
    pub flux: T,
}

impl<T: Real> Mode<T> {
    /// The wave vector `(β, 0, q)` in units of `k0`.
    pub fn wave_vector(&self) -> C3<T> {
        wave_vector(self.beta, self.q)
    }

    /// The tangential field components `(E_x, E_y, H_x, H_y)` matched at a boundary (eq. S18).
    pub fn tangential(&self) -> [Cx<T>; 4] {
        [self.e.x, self.e.y, self.h.x, self.h.y]
    }

    /// Time-averaged Poynting vector `½ Re(E × H*)` of the unit-amplitude mode at the surface.
    pub fn poynting(&self) -> Vector3<T> {
        let hc = self.h.map(|c| c.conj());
        let c = self.e.cross(&hc);
        Vector3::new(c.x.re * 0.5, c.y.re * 0.5, c.z.re * 0.5)
    }

    /// Normal component of the Poynting vector: the power this mode carries through the surface
    /// per unit area (positive upwards).
    pub fn flux(&self) -> T {
        self.flux
    }

    /// True for a wave that carries (numerically) no power through the surface although its
    /// field does not vanish: an evanescent wave past `K_max` (eq. S15) in a lossless medium.
    /// (An e-wave past `K_max` keeps a real part of `q`; only its flux tells.)
    pub fn is_evanescent(&self) -> T::Mask {
        let scale = norm(&self.e) * norm(&self.h);
        self.flux().abs().le(scale * 1e-12)
    }
}

/// The Hermitian norm of a complex 3-vector.
fn norm<T: Real>(v: &C3<T>) -> T {
    (cx::norm_sqr(v.x) + cx::norm_sqr(v.y) + cx::norm_sqr(v.z)).sqrt()
}

impl Mode {
    /// Unit ray (Poynting) direction (eq. S12); `None` if the mode carries no power.
    pub fn ray_direction(&self) -> Option<Vector3<f64>> {
        let s = self.poynting();
        let n = s.norm();
        (n > 0.0 && n.is_finite()).then(|| s / n)
    }

    /// Unit wave-normal direction `Re(k)/|Re(k)|` (eq. S11).
    pub fn wave_direction(&self) -> Vector3<f64> {
        let k = Vector3::new(self.beta.re, 0.0, self.q.re);
        let n = k.norm();
        if n > 0.0 {
            k / n
        } else {
            Vector3::z() * self.q.im.signum()
        }
    }

    /// Effective index `sqrt(q² + β²)` seen by the wave (eq. S13); complex with absorption.
    pub fn effective_index(&self) -> C64 {
        cmath::sqrt(self.q * self.q + self.beta * self.beta)
    }

    /// Ray (phase) index along the Poynting direction, `Re(η_ef) ⟨W, I⟩` (eq. S14);
    /// `None` for a mode that carries no power.
    pub fn ray_index(&self) -> Option<f64> {
        let ray = self.ray_direction()?;
        Some(self.effective_index().re * self.wave_direction().dot(&ray))
    }
}

/// The four modes of a medium: two travelling/decaying downwards (`-z`), two upwards.
/// Order within each pair: `[o, e]` for anisotropic media, `[s, p]` for isotropic ones.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeSet<T: Real = f64> {
    /// Modes carrying power (or decaying) towards `-z`.
    pub down: [Mode<T>; 2],
    /// Modes carrying power (or decaying) towards `+z`.
    pub up: [Mode<T>; 2],
}

/// `(β, 0, q)`.
pub fn wave_vector<T: Real>(beta: Cx<T>, q: Cx<T>) -> C3<T> {
    Vector3::new(beta, Cx::new(T::zero(), T::zero()), q)
}

/// The normal modes of `medium` (its axis given in the working frame) for incidence parameter
/// `beta` (eqs. S9-S10). Isotropic media get s/p modes (where that is known while recording:
/// else the uniaxial modes, which hold for equal indices too).
#[inline(always)]
pub fn modes<T: Real>(medium: &Uniaxial<T>, beta: Cx<T>) -> ModeSet<T> {
    if medium.is_isotropic().surely() {
        isotropic_modes(medium.eta_o, beta)
    } else {
        uniaxial_modes(medium, beta)
    }
}

/// The normal components `q/k0` of the four modes, `[o↓, e↓, o↑, e↑]` (`[s, p, s, p]` for an
/// isotropic medium), without the fields: the same roots and branches as [`modes`], at a
/// fraction of its cost (for the phases of a layer whose amplitudes are known).
pub fn normal_components<T: Real>(medium: &Uniaxial<T>, beta: Cx<T>) -> [Cx<T>; 4] {
    if medium.is_isotropic().surely() {
        let (qo_up, qo_down) = up_down(cx::sqrt(normal_squared(medium.eta_o, beta)));
        return [qo_down, qo_down, qo_up, qo_up];
    }
    uniaxial_normals(medium, beta).0
}

/// The normal components `[o↓, e↓, o↑, e↑]` of a (non-isotropic) uniaxial medium, as
/// [`uniaxial_modes`] takes them, and the up-going e-wave's `w = a q⁺ + b = (εk)_z` (real
/// when the e-wave propagates in a lossless medium: its exact flux, [`Fields::extraordinary`]).
#[inline]
pub(crate) fn uniaxial_normals<T: Real>(medium: &Uniaxial<T>, beta: Cx<T>) -> ([Cx<T>; 4], Cx<T>) {
    let (qo_up, qo_down) = up_down(cx::sqrt(normal_squared(medium.eta_o, beta)));
    let (qe_up, qe_down, w) = extraordinary_q_w(medium, beta);
    ([qo_down, qe_down, qo_up, qe_up], w)
}

/// Picks the root pair `(−b ± w)/a` so that the first returned value is the up-going one,
/// also returning the `w` of the up-going root (`a q⁺ + b = w`, `a q⁻ + b = −w`).
///
/// A mode goes up if it decays upwards (`Im q > 0`); for (numerically) lossless propagation,
/// where `Im` carries no information, if its Poynting flux points up, which for both o and e
/// waves is the sign of `Re(w/a)` (the e-wave ray is `∝ ε k`, whose normal part is `a q + b`).
/// For passive media both criteria agree wherever both apply.
#[inline]
fn up_down_w<T: Real>(a: Cx<T>, b: Cx<T>, w: Cx<T>) -> (Cx<T>, Cx<T>, Cx<T>) {
    let inv_a = cx::inv(a);
    let w = goes_down(w * inv_a).when(|| -w, || w);
    ((w - b) * inv_a, (-w - b) * inv_a, w)
}

/// [`up_down_w`] for `a = 1`, `b = 0` (o, s and p waves: `q = ±w`), `(q⁺, q⁻)`.
#[inline]
fn up_down<T: Real>(w: Cx<T>) -> (Cx<T>, Cx<T>) {
    let w = goes_down(w).when(|| -w, || w);
    (w, -w)
}

/// True if the root `q = u` of `q = ±u` is the down-going one (criterion of [`up_down_w`]).
#[inline]
fn goes_down<T: Real>(u: Cx<T>) -> T::Mask {
    let zero = T::zero();
    u.im.abs()
        .gt(u.re.abs() * 1e-9)
        .when(|| u.im.lt(zero), || u.re.lt(zero))
}

/// `η² − β²` evaluated as `(η − β)(η + β)`, exact near grazing/critical incidence.
fn normal_squared<T: Real>(eta: Cx<T>, beta: Cx<T>) -> Cx<T> {
    (eta - beta) * (eta + beta)
}

/// s and p modes of an isotropic medium of index `eta`: `E_s = ŷ`, `H_s = k × ŷ = (−q, 0, β)`,
/// `E_p = k̂ × ŷ = (−q, 0, β)/η`, `H_p = k × E_p = (0, −(q² + β²)/η, 0)` (written out: the zero
/// components are exact), fluxes `½ Re(E_x H_y* − E_y H_x*)`.
#[inline(always)]
pub fn isotropic_modes<T: Real>(eta: Cx<T>, beta: Cx<T>) -> ModeSet<T> {
    let zero = Cx::new(T::zero(), T::zero());
    let one = Cx::new(T::one(), T::zero());
    let (q_up, q_down) = up_down(cx::sqrt(normal_squared(eta, beta)));
    let inv_eta = cx::inv(eta);
    let pair = |q: Cx<T>| {
        let (ex, ez) = (-q * inv_eta, beta * inv_eta);
        let hy = q * ex - beta * ez;
        [
            Mode {
                kind: ModeKind::S,
                beta,
                q,
                e: Vector3::new(zero, one, zero),
                h: Vector3::new(-q, zero, beta),
                flux: q.re * 0.5,
            },
            Mode {
                kind: ModeKind::P,
                beta,
                q,
                e: Vector3::new(ex, zero, ez),
                h: Vector3::new(zero, hy, zero),
                flux: (ex * hy.conj()).re * 0.5,
            },
        ]
    };
    ModeSet {
        down: pair(q_down),
        up: pair(q_up),
    }
}

/// Normal components of the extraordinary wave, `(q_e⁺, q_e⁻)` (eq. S9).
///
/// From `kᵀ ε k = ε_o ε_e` with `k = (β, 0, q)`: `a q² + 2 b q + c = 0`, `a = ε_o + Δε A_z²`,
/// `b = Δε β A_x A_z`, discriminant `ε_o [ε_e a − β² (ε_e − Δε A_y²)]`.
pub fn extraordinary_q<T: Real>(medium: &Uniaxial<T>, beta: Cx<T>) -> (Cx<T>, Cx<T>) {
    let (up, down, _) = extraordinary_q_w(medium, beta);
    (up, down)
}

/// True where the medium is lossless and `β` real (known while recording when the indices
/// are constants): the e-wave's coefficients are then real.
fn real_coefficients<T: Real>(medium: &Uniaxial<T>, beta: Cx<T>) -> T::Mask {
    medium.is_lossless() & beta.im.equals(T::zero())
}

/// [`extraordinary_q`] and the up-going `w = a q⁺ + b`. A lossless medium at real `β` has
/// real coefficients, and real roots unless the e-wave is evanescent: then the same steps run
/// in real arithmetic (what the complex ones reduce to).
#[inline]
fn extraordinary_q_w<T: Real>(medium: &Uniaxial<T>, beta: Cx<T>) -> (Cx<T>, Cx<T>, Cx<T>) {
    if real_coefficients(medium, beta).surely() {
        let (eps_o, eps_e) = (medium.eps_o().re, medium.eps_e().re);
        let (a, b, disc) = extraordinary_coefficients(eps_o, eps_e, &medium.axis, beta.re);
        let c = |x: T| cx::real(x);
        return disc.ge(T::zero()).when(
            || {
                let w = disc.safe_sqrt();
                let inv_a = Scalar::inverse(a);
                let w = (w * inv_a).lt(T::zero()).when(|| -w, || w);
                (c((w - b) * inv_a), c((-w - b) * inv_a), c(w))
            },
            || up_down_w(c(a), c(b), cx::sqrt(c(disc))),
        );
    }
    let (a, b, disc) =
        extraordinary_coefficients(medium.eps_o(), medium.eps_e(), &medium.axis, beta);
    up_down_w(a, b, cx::sqrt(disc))
}

/// `(a, b, disc)` of [`extraordinary_q`]: `a q² + 2 b q + c = 0` with the discriminant
/// `b² − a c = ε_o [ε_e a − β² (ε_e − Δε A_y²)]`.
#[inline(always)]
fn extraordinary_coefficients<R: Real, T: Scalar<R>>(
    eps_o: T,
    eps_e: T,
    axis: &Vector3<R>,
    beta: T,
) -> (T, T, T) {
    let d = eps_e - eps_o;
    let a = eps_o + d * axis.z * axis.z;
    let b = d * beta * axis.x * axis.z;
    let disc = eps_o * (eps_e * a - beta * beta * (eps_e - d * axis.y * axis.y));
    (a, b, disc)
}

/// Maximal incidence parameters `(K_o^max, K_e^max)/k0` beyond which the o and e waves are
/// evanescent (eq. S15). For the e-wave: `K² = ε_e (ε_o + Δε A_z²) / (ε_e − Δε A_y²)`, with
/// `A_z` the normal and `A_y` the s (out-of-plane) component of the axis. (S15 as printed has the
/// in-plane tangential component in the denominator; the discriminant of eq. S9 gives the
/// out-of-plane one, which is what is implemented and tested.)
pub fn k_max(medium: &Uniaxial) -> (C64, C64) {
    let (eo, ee) = (medium.eps_o(), medium.eps_e());
    let d = ee - eo;
    let ax = medium.axis;
    let ke = (ee * (eo + d * ax.z * ax.z) / (ee - d * ax.y * ax.y)).sqrt();
    (medium.eta_o, ke)
}

/// o and e modes of a (non-isotropic) uniaxial medium (eqs. S9-S10), fields from
/// [`crate::optics::fields`]: in real arithmetic when every wave vector and field is real (lossless
/// medium, real `β`, both waves propagating), else in complex arithmetic.
#[inline(always)]
pub fn uniaxial_modes<T: Real>(medium: &Uniaxial<T>, beta: Cx<T>) -> ModeSet<T> {
    let qo_squared = normal_squared(medium.eta_o, beta);
    let (qo_up, qo_down) = up_down(cx::sqrt(qo_squared));
    let (qe_up, qe_down, w) = extraordinary_q_w(medium, beta);
    let q = [qo_down, qe_down, qo_up, qe_up];
    // The e-wave's exact flux: a lossless medium at real β (known per medium), where the
    // e-wave propagates (w real).
    let lossless = real_coefficients(medium, beta);
    let ek_z = lossless
        .known()
        .is_none_or(|l| l)
        .then(|| (lossless & w.im.equals(T::zero()), w.re));
    let real_fields = lossless
        & w.im.equals(T::zero())
        & qo_squared.im.equals(T::zero())
        & qo_squared.re.ge(T::zero());
    if real_fields.surely() {
        let (eps_o, eps_e) = (medium.eps_o().re, medium.eps_e().re);
        let fields = Fields::new(eps_o, eps_e, medium.axis, beta.re);
        let q_re = [q[0].re, q[1].re, q[2].re, q[3].re];
        uniaxial_pairs(&fields, beta, q_re, q, ek_z)
    } else {
        let fields = Fields::new(medium.eps_o(), medium.eps_e(), medium.axis, beta);
        uniaxial_pairs(&fields, beta, q, q, ek_z)
    }
}

/// A mode from its fields (in the arithmetic of `S`).
#[inline(always)]
fn mode<T: Real, S: Scalar<T>>(kind: ModeKind, beta: Cx<T>, q: Cx<T>, wave: Wave<S, T>) -> Mode<T> {
    let c = |v: &[S; 3]| Vector3::new(v[0].complex(), v[1].complex(), v[2].complex());
    Mode {
        kind,
        beta,
        q,
        e: c(&wave.e),
        h: c(&wave.h),
        flux: wave.flux,
    }
}

/// The four modes from `fields` and the normal components `[o↓, e↓, o↑, e↑]` in the arithmetic
/// of `S` (`q_s`) and as stored (`q`); `w` of the up-going e-wave for exact fluxes.
#[inline(always)]
fn uniaxial_pairs<T: Real, S: Scalar<T>>(
    fields: &Fields<S, T>,
    beta: Cx<T>,
    q_s: [S; 4],
    q: [Cx<T>; 4],
    w: Option<(T::Mask, T)>,
) -> ModeSet<T> {
    let (o, e) = (ModeKind::O, ModeKind::E);
    ModeSet {
        down: [
            mode(o, beta, q[0], fields.ordinary(q_s[0])),
            mode(
                e,
                beta,
                q[1],
                fields.extraordinary(q_s[1], w.map(|(m, w)| (m, -w))),
            ),
        ],
        up: [
            mode(o, beta, q[2], fields.ordinary(q_s[2])),
            mode(e, beta, q[3], fields.extraordinary(q_s[3], w)),
        ],
    }
}

/// Wave vector (units of `k0`) of the e-wave whose ray (Poynting) direction is `ray` (unit,
/// same frame as the axis): the inverse of eq. S12 for a lossless uniaxial medium.
///
/// The e-wave's ray is the normal of its index surface `kᵀ ε k = ε_o ε_e`, i.e. `∝ ε k`, hence
/// `k = ε⁻¹ ŝ · sqrt(ε_o ε_e / ŝᵀ ε⁻¹ ŝ)`. Absorption is ignored (real parts of ε are used).
pub fn extraordinary_wave_vector_from_ray<T: Real>(
    medium: &Uniaxial<T>,
    ray: Vector3<T>,
) -> Vector3<T> {
    let (eo, ee) = (medium.eps_o().re, medium.eps_e().re);
    let a = medium.axis;
    let inv = |v: Vector3<T>| v / eo + a * (a.dot(&v) * (ee.recip() - eo.recip()));
    let k = inv(ray);
    k * (eo * ee / ray.dot(&k)).sqrt()
}

/// Effective index of a wave travelling along the unit wave normal `dir`: `η_o` for the o-wave,
/// `η(θ) = sqrt(ε_o ε_e / (d̂ᵀ ε d̂))` for the e-wave (eq. S13 evaluated from the direction).
pub fn index_along(medium: &Uniaxial, kind: ModeKind, dir: Vector3<f64>) -> C64 {
    match kind {
        ModeKind::E if !medium.is_isotropic() => {
            let c = medium.axis.dot(&dir);
            let dtd = medium.eps_o() * (1.0 - c * c) + medium.eps_e() * c * c;
            (medium.eps_o() * medium.eps_e() / dtd).sqrt()
        }
        _ => medium.eta_o,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The real branch of [`extraordinary_q_w`] gives what the complex steps give, bit for bit
    /// (signs of zero imaginary parts aside), for propagating and evanescent e-waves.
    #[test]
    fn real_extraordinary_roots_equal_the_complex_ones() {
        let mut next = crate::cmath::uniform(99);
        let mut evanescent = 0;
        for _ in 0..5000 {
            let axis = Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
            let (no, ne) = (1.2 + 1.8 * next(), 1.2 + 1.8 * next());
            let medium = Uniaxial::new(C64::new(no, 0.0), C64::new(ne, 0.0), axis).unwrap();
            let beta = C64::new(3.0 * next(), 0.0);
            let (a, b, disc) =
                extraordinary_coefficients(medium.eps_o(), medium.eps_e(), &medium.axis, beta);
            let full = up_down_w(a, b, cmath::sqrt(disc));
            let fast = extraordinary_q_w(&medium, beta);
            evanescent += usize::from(full.2.im != 0.0);
            for (x, y) in [(fast.0, full.0), (fast.1, full.1), (fast.2, full.2)] {
                assert!(x == y, "{x} vs {y}");
            }
        }
        assert!(evanescent > 500);
    }
}
