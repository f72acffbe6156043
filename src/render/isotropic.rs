//! The isotropic closed form of [`crate::render::crystal`]: an isotropic "crystal" (`η_o = η_e`)
//! is a dielectric interface, and its lobes follow in closed form (what Mitsuba's `dielectric`
//! computes, here in this core's frames and conventions); an absorbing one is opaque (see
//! [`crate::render::crystal`]): the reflection from outside alone, what Mitsuba's `conductor`
//! computes.
//!
//! Every wave of the event lies in one plane of incidence and its Jones basis is the s/p mode
//! basis (`x = s`, `y = d × s`, [`crate::optics::lobes`]), so each lobe's Jones matrix is diagonal: the
//! Fresnel amplitudes of [`crate::optics::fresnel`], flux-normalised (`τ = t √(w_far/w_near)`, the
//! same factor for s and p in real-index media). Radiance mode needs the transfer from the
//! source at `wo` into `wi`: for a lossless isotropic interface it is the same Mueller matrix
//! (reflection: the same angle on the same side; transmission: reciprocity of the
//! flux-normalised amplitudes, `τ(θ₁ → θ₂) = τ(θ₂ → θ₁)`), scaled by the radiance factor
//! `(n_wi/n_wo)²` as in the general path.

use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::optics::fresnel::{normal_component, Fresnel};
use crate::optics::mueller;
use crate::optics::surface::Surface;
use crate::real::complex::{self as cx, Cx};
use crate::real::{Mask, Real};
use crate::render::{PathLobe, Transport};
use nalgebra::Vector3;

/// The lobes of an isotropic crystal seen from `wi` (unit, local, `wi.z ≠ 0`; `outside`:
/// where `wi.z > 0`), each to `f(slot, lobe)` (slots of [`crate::render::slots`]): the
/// reflection (component 0; slot 0 outside, 4 inside) and, where it is not totally reflected
/// and the crystal does not absorb, the refraction (component 1; slot 1 outside, 3 inside). An
/// absorbing crystal has the reflection from outside alone. The Fresnel amplitudes have no
/// pole away from grazing incidence, so no lane fails.
pub(crate) fn each_lobe<T: Real>(
    surface: &Surface<T>,
    wi: Vector3<T>,
    outside: T::Mask,
    transport: Transport,
    mut f: impl FnMut(usize, PathLobe<T>),
) -> Result<()> {
    let (ext, crystal) = (surface.exterior.eta_o, surface.crystal.eta_o);
    let opaque = !crystal.im.equals(T::zero());
    // No light inside an opaque bulk.
    let lit = outside | !opaque;
    if lit.known() == Some(false) {
        return Ok(());
    }
    let (near, far) = outside.when(|| (ext, crystal), || (crystal, ext));
    let beta = near * (wi.x * wi.x + wi.y * wi.y).sqrt();
    let fresnel = Fresnel::amplitudes(ext, crystal, beta)?;
    let (r, t) = outside.when(
        || (fresnel.r_above, fresnel.t_above),
        || (fresnel.r_below, fresnel.t_below),
    );
    let reflected = Vector3::new(-wi.x, -wi.y, wi.z);
    let reflection = lobe(0, wi, reflected, r, T::one(), transport).existing(lit);
    by_side(&mut f, outside, [0, 4], reflection);
    let ratio = near.re / far.re;
    let sin2 = ratio * ratio * (wi.x * wi.x + wi.y * wi.y);
    let refracts = sin2.lt(T::one()) & !opaque;
    if refracts.known() == Some(false) {
        return Ok(());
    }
    let cos = (T::one() - sin2).safe_sqrt();
    let wo = Vector3::new(-wi.x * ratio, -wi.y * ratio, cos.copysign(-wi.z));
    let flux = (normal_component(far, beta).re / normal_component(near, beta).re).sqrt();
    let tau = [t[0] * flux, t[1] * flux];
    let refraction = lobe(1, wi, wo, tau, far.re / near.re, transport).existing(refracts);
    by_side(&mut f, outside, [1, 3], refraction);
    Ok(())
}

/// `lobe` to `f` in slot `slots[0]` where `outside` holds, `slots[1]` elsewhere.
fn by_side<T: Real>(
    f: &mut impl FnMut(usize, PathLobe<T>),
    outside: T::Mask,
    slots: [usize; 2],
    lobe: PathLobe<T>,
) {
    if outside.known() != Some(false) {
        f(slots[0], lobe.existing(outside));
    }
    if outside.known() != Some(true) {
        f(slots[1], lobe.existing(!outside));
    }
}

/// One lobe with flux-normalised s/p amplitudes `a`; `n_ratio = n_wo / n_wi`.
fn lobe<T: Real>(
    component: usize,
    wi: Vector3<T>,
    wo: Vector3<T>,
    a: [Cx<T>; 2],
    n_ratio: T,
    transport: Transport,
) -> PathLobe<T> {
    let m = mueller::from_diagonal(cx::norm_sqr(a[0]), a[0].conj() * a[1], cx::norm_sqr(a[1]));
    // The light arrives from `towards` (wi forward, wo by time reversal); its plane-of-incidence
    // frame gives the s axis of every wave of the event.
    let (towards, scale) = match transport {
        Transport::Importance => (wi, T::one()),
        Transport::Radiance => (wo, (n_ratio * n_ratio).recip()),
    };
    let s = PlaneFrame::from_direction(towards).s;
    PathLobe::new(component, wo, (s, s), m, n_ratio).with_radiance_factor(scale)
}
