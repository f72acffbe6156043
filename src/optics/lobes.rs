//! A surface event as a renderer sees it: each outgoing wave that carries power becomes a lobe
//! with its ray direction, its Stokes frame and its Mueller matrix (Mitsuba's convention).
//!
//! Stokes frames: an exterior wave uses `x = s` (perpendicular to the plane of incidence) and
//! `y = d × s` — Mitsuba's s/p frame, so its Jones basis is the s/p mode basis. A crystal wave is
//! linearly polarised along its own field (exactly so without absorption); its frame has `x`
//! along the major axis of that field, made perpendicular to the ray, and `y = d × x`. A ray
//! inside the crystal therefore carries its mode in its polarisation: an o- or e-wave
//! arriving from inside couples only the `x` component of its Stokes frame.
//!
//! Jones matrices are flux-normalised: `|J e|²` is the power fraction carried by the outgoing
//! wave (eq. S19), so the Mueller matrix's `M00` is the power ratio for unpolarised light.

use crate::error::{Error, Result};
use crate::optics::frame::PlaneFrame;
use crate::optics::modes::{extraordinary_wave_vector_from_ray, Mode, ModeKind};
use crate::optics::mueller;
use crate::optics::surface::{Incident, Solved, Surface};
use crate::real::complex::{self as cx, Cx};
use crate::real::{Mask, Real};
use nalgebra::{Matrix2, Matrix4, Vector2, Vector3};
use num_complex::Complex64 as C64;

/// One outgoing wave, over the reals `T` (`f64` on the host).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lobe<T: Real = f64> {
    /// `S` for an exterior wave (s and p together), `O` or `E` for a crystal wave.
    pub kind: ModeKind,
    /// Unit ray (Poynting) direction, local frame, pointing away from the surface.
    pub direction: Vector3<T>,
    /// Unit wave normal, local frame.
    pub wave_normal: Vector3<T>,
    /// `x` axis of this wave's Stokes frame (`y = direction × x`).
    pub stokes_x: Vector3<T>,
    /// Flux-normalised Jones matrix, incident frame → this wave's frame (core convention).
    pub jones: Matrix2<Cx<T>>,
    /// Its Mueller matrix in Mitsuba's convention.
    pub mueller: Matrix4<T>,
    /// Ray index of the outgoing wave (eq. S14).
    pub ray_index: T,
}

/// All lobes of one surface event.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Event {
    /// Unit propagation direction of the incident wave (ray direction), local frame.
    pub incident_direction: Vector3<f64>,
    /// `x` axis of the incident wave's Stokes frame.
    pub incident_stokes_x: Vector3<f64>,
    /// Ray index of the incident wave (eq. S14).
    pub incident_ray_index: f64,
    /// Outside incidence: `[exterior wave, —]`; inside: `[o, e]` (waves into the crystal).
    pub reflected: [Option<Lobe>; 2],
    /// Outside incidence: `[o, e]`; inside: `[exterior wave, —]`.
    pub transmitted: [Option<Lobe>; 2],
}

/// The lobes of light arriving at `surface` from the local direction `towards_light` (unit).
///
/// For [`Incident::Outside`], `towards_light.z > 0`. For [`Incident::Inside`], `towards_light`
/// is minus the ray (Poynting) direction of the o- or e-wave inside (`towards_light.z < 0`);
/// the e-wave's wave normal follows from its ray in closed form. An isotropic crystal
/// (`η_o = η_e`) has s/p waves that share one direction: they form one lobe with a full Jones
/// matrix, and light from inside arrives in both.
pub fn scatter(
    surface: &Surface,
    towards_light: Vector3<f64>,
    incident: Incident,
) -> Result<Event> {
    let (frame, beta) = incidence(surface, towards_light, incident, true)?;
    let sv = surface.solve(frame, beta)?;
    let i = &sv.interface;
    let iso = surface.crystal.is_isotropic();
    let input = match incident {
        Incident::Outside => Group::Pair([0, 1]),
        Incident::Inside(_) if iso => Group::Pair([2, 3]),
        Incident::Inside(ModeKind::E) => Group::Single(3),
        Incident::Inside(_) => Group::Single(2),
    };
    let in_modes = [
        &i.upper.down[0],
        &i.upper.down[1],
        &i.lower.up[0],
        &i.lower.up[1],
    ];
    let out_modes = [
        &i.upper.up[0],
        &i.upper.up[1],
        &i.lower.down[0],
        &i.lower.down[1],
    ];
    let first_in = in_modes[input.first()];
    let p_in = first_in.flux.abs();
    if p_in.is_nan() || p_in <= 0.0 {
        return Err(Error::new(
            "direction",
            "the incident wave carries no power through the surface (grazing)",
        ));
    }
    let (in_x, in_c) = match input {
        Group::Pair(_) => (
            frame.s,
            Vector2::new(C64::new(1.0, 0.0), C64::new(0.0, 0.0)),
        ),
        Group::Single(_) => crystal_frame(&sv, first_in),
    };
    let make = |group: Group| -> Option<Lobe> {
        let mode = out_modes[group.first()];
        if !carries_power(mode) {
            return None;
        }
        let row = |r: usize| -> Vector2<C64> {
            match input {
                Group::Pair([c0, c1]) => Vector2::new(i.s[(r, c0)], i.s[(r, c1)]),
                Group::Single(c) => Vector2::new(i.s[(r, c)] / in_c.x, C64::new(0.0, 0.0)),
            }
        };
        let (x, amplitudes) = match group {
            Group::Pair([r0, r1]) => (
                frame.s,
                Matrix2::from_rows(&[row(r0).transpose(), row(r1).transpose()]),
            ),
            Group::Single(r) => {
                let (x, c) = crystal_frame(&sv, mode);
                (x, c * row(r).transpose())
            }
        };
        let jones = amplitudes * C64::new((mode.flux.abs() / p_in).sqrt(), 0.0);
        Some(lobe(&sv, mode, x, jones))
    };
    let exterior = make(Group::Pair([0, 1]));
    let crystal = if iso {
        [make(Group::Pair([2, 3])), None]
    } else {
        [make(Group::Single(2)), make(Group::Single(3))]
    };
    let (reflected, transmitted) = match incident {
        Incident::Outside => ([exterior, None], crystal),
        Incident::Inside(_) => (crystal, [exterior, None]),
    };
    Ok(Event {
        incident_direction: -towards_light,
        incident_stokes_x: in_x,
        incident_ray_index: first_in
            .ray_index()
            .unwrap_or(first_in.effective_index().re),
        reflected,
        transmitted,
    })
}

/// Waves that travel together: an s/p pair (one Jones basis) or one anisotropic mode. Indices
/// are rows (outgoing) or columns (incoming) of the interface's scattering matrix.
#[derive(Clone, Copy)]
enum Group {
    Pair([usize; 2]),
    Single(usize),
}

impl Group {
    fn first(self) -> usize {
        match self {
            Group::Pair([a, _]) => a,
            Group::Single(a) => a,
        }
    }
}

/// The plane of incidence and `β` for a wave arriving from `towards_light`. The lanes of `live`
/// (a recorded event that other lanes discard) fail where the direction is not unit or on the
/// wrong side.
pub(crate) fn incidence<T: Real>(
    surface: &Surface<T>,
    towards_light: Vector3<T>,
    incident: Incident,
    live: T::Mask,
) -> Result<(PlaneFrame<T>, Cx<T>)> {
    let n = towards_light.dot(&towards_light).sqrt();
    let unit = n.finite() & (n - T::one()).abs().le(T::cst(1e-6));
    (live & !unit).fail(|| Error::new("direction", "must be a unit vector"))?;
    let outside = matches!(incident, Incident::Outside);
    let above = towards_light.z.gt(T::zero());
    let wrong_side = if outside { !above } else { above };
    (live & wrong_side).fail(|| {
        Error::new(
            "direction",
            "must point into the exterior (z > 0) for outside incidence, into the crystal (z < 0) for inside",
        )
    })?;
    // The wave normal (in the direction the light travels) decides the plane of incidence.
    let ray = -towards_light;
    let k = match incident {
        Incident::Outside => ray * surface.exterior.eta_o.re,
        Incident::Inside(ModeKind::E) if !surface.crystal.is_isotropic().surely() => {
            extraordinary_wave_vector_from_ray(&surface.crystal, ray)
        }
        Incident::Inside(_) => ray * surface.crystal.eta_o.re,
    };
    let frame = PlaneFrame::from_direction(-k);
    let beta = frame.to_working(k).x.max(T::zero());
    let beta = match incident {
        Incident::Outside => surface.exterior.eta_o * (beta / surface.exterior.eta_o.re),
        _ => cx::real(beta),
    };
    Ok((frame, beta))
}

/// True if the mode carries power away from the surface.
fn carries_power(mode: &Mode) -> bool {
    mode.flux.abs() > 0.0 && !mode.is_evanescent()
}

/// A crystal wave's Stokes `x` axis (major axis of its field, perpendicular to its ray) and its
/// unit Jones vector in that frame.
fn crystal_frame(sv: &Solved, mode: &Mode) -> (Vector3<f64>, Vector2<C64>) {
    let d = sv.ray_local(mode).unwrap_or_else(|| sv.wave_local(mode));
    let c = |v: Vector3<f64>| v.map(|x| C64::new(x, 0.0));
    let e_local = c(sv.frame.u) * mode.e.x + c(sv.frame.s) * mode.e.y + c(Vector3::z()) * mode.e.z;
    // Rotate the phase so that the real part is the ellipse's major axis: θ = ½ arg(E·E).
    let theta = 0.5 * e_local.dot(&e_local).arg();
    let major = e_local.map(|z| (z * C64::from_polar(1.0, -theta)).re);
    let mut x = major - d * d.dot(&major);
    if x.norm() < 1e-12 {
        x = sv.frame.s - d * d.dot(&sv.frame.s);
    }
    let x = x.normalize();
    let y = d.cross(&x);
    let j = Vector2::new(e_local.dot(&c(x)), e_local.dot(&c(y)));
    let n = (j.x.norm_sqr() + j.y.norm_sqr()).sqrt();
    (x, j / C64::new(n, 0.0))
}

fn lobe(sv: &Solved, mode: &Mode, stokes_x: Vector3<f64>, jones: Matrix2<C64>) -> Lobe {
    let kind = match mode.kind {
        ModeKind::S | ModeKind::P => ModeKind::S,
        k => k,
    };
    Lobe {
        kind,
        direction: sv.ray_local(mode).unwrap_or_else(|| sv.wave_local(mode)),
        wave_normal: sv.wave_local(mode),
        stokes_x,
        jones,
        mueller: mueller::from_jones(&jones),
        ray_index: mode.ray_index().unwrap_or(mode.effective_index().re),
    }
}
