//! The isotropic fast path of [`crate::render::crystal::crystal_lobes`]: a lossless isotropic
//! "crystal" (`η_o = η_e` real) is a dielectric interface, and its lobes follow in closed form
//! (what Mitsuba's `dielectric` computes, here in this core's frames and conventions).
//!
//! Every wave of the event lies in one plane of incidence and its Jones basis is the s/p mode
//! basis (`x = s`, `y = d × s`, [`crate::optics::lobes`]), so each lobe's Jones matrix is diagonal: the
//! Fresnel amplitudes of [`crate::optics::fresnel`], flux-normalised (`τ = t √(w_far/w_near)`, the
//! same factor for s and p in real-index media). Radiance mode needs the transfer from the
//! source at `wo` into `wi`: for a lossless isotropic interface it is the same Mueller matrix
//! (reflection: the same angle on the same side; transmission: reciprocity of the
//! flux-normalised amplitudes, `τ(θ₁ → θ₂) = τ(θ₂ → θ₁)`), scaled by the radiance factor
//! `(n_wi/n_wo)²` as in the general path.

use crate::optics::frame::PlaneFrame;
use crate::optics::fresnel::{normal_component, Fresnel};
use crate::optics::mueller;
use crate::optics::surface::Surface;
use crate::render::{PathLobe, Transport};
use nalgebra::Vector3;
use num_complex::Complex64 as C64;

/// The lobes seen from `wi` (unit, local, `wi.z ≠ 0`): the reflection (component 0) and, unless
/// it is totally reflected, the refraction (component 1); `None` if the fast path does not apply
/// (an anisotropic or absorbing crystal).
pub fn crystal_lobes(
    surface: &Surface,
    wi: Vector3<f64>,
    transport: Transport,
) -> Option<(PathLobe, Option<PathLobe>)> {
    let crystal = surface.crystal.eta_o;
    if !surface.crystal.is_isotropic() || crystal.im != 0.0 {
        return None;
    }
    let (ext, outside) = (surface.exterior.eta_o, wi.z > 0.0);
    let (near, far) = if outside {
        (ext, crystal)
    } else {
        (crystal, ext)
    };
    let beta = near * (wi.x * wi.x + wi.y * wi.y).sqrt();
    let f = Fresnel::new(ext, crystal, beta)?;
    let (r, t) = if outside {
        (f.r_above, f.t_above)
    } else {
        (f.r_below, f.t_below)
    };
    let reflected = Vector3::new(-wi.x, -wi.y, wi.z);
    let reflection = lobe(0, wi, reflected, r, 1.0, transport);
    let ratio = near.re / far.re;
    let sin2 = ratio * ratio * (wi.x * wi.x + wi.y * wi.y);
    let refraction = (sin2 < 1.0).then(|| {
        let cos = (1.0 - sin2).sqrt();
        let wo = Vector3::new(-wi.x * ratio, -wi.y * ratio, -wi.z.signum() * cos);
        let flux = (normal_component(far, beta).re / normal_component(near, beta).re).sqrt();
        let tau = [t[0] * flux, t[1] * flux];
        lobe(1, wi, wo, tau, far.re / near.re, transport)
    });
    Some((reflection, refraction))
}

/// One lobe with flux-normalised s/p amplitudes `a`; `n_ratio = n_wo / n_wi`.
fn lobe(
    component: usize,
    wi: Vector3<f64>,
    wo: Vector3<f64>,
    a: [C64; 2],
    n_ratio: f64,
    transport: Transport,
) -> PathLobe {
    let m = mueller::from_diagonal(a[0].norm_sqr(), a[0].conj() * a[1], a[1].norm_sqr());
    // The light arrives from `towards` (wi forward, wo by time reversal); its plane-of-incidence
    // frame gives the s axis of every wave of the event.
    let (towards, scale) = match transport {
        Transport::Importance => (wi, 1.0),
        Transport::Radiance => (wo, 1.0 / (n_ratio * n_ratio)),
    };
    let s = PlaneFrame::from_direction(towards).s;
    PathLobe::new(component, wo, (s, s), m * scale, n_ratio)
}
