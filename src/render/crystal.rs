//! The lobes of a bulk crystal's surface (reflection, ordinary and extraordinary refraction)
//! as a path tracer samples them (see [`crate::render`] for the transport modes).
//!
//! **An absorbing bulk medium is opaque**, as Mitsuba's `conductor` is: light refracted into a
//! crystal with any `κ > 0` (only isotropic ones are accepted, see [`crystal_lobes`]) is
//! absorbed at the surface. From outside only the reflection lobe exists (a renderer picks it
//! with probability 1, its weight is its Mueller matrix: the Fresnel reflection of the
//! complex index), and from inside there are no lobes, in both transport modes. The bulk is
//! taken as many absorption lengths thick (κ = 10⁻⁴ at 500 nm already attenuates by e⁻¹ over
//! 0.4 mm); a weakly absorbing transparent solid is a lossless crystal (κ = 0) with an
//! absorbing interior medium instead. Keeping the refracted wave would not be well defined
//! either: its power fraction leaves out the flux of the incident and reflected waves'
//! interference inside the medium, and the time-reversed (Radiance) weight of a refraction
//! into it grows without bound as Re(n) → 0 (about `|n|²/Re(n)⁴` times the Importance
//! weight: 47,000 for silver at normal incidence). [`opaque`] makes this decision.

use crate::error::{Error, Result};
use crate::optics::lobes::{scatter, Event, Lobe};
use crate::optics::modes::ModeKind;
use crate::optics::mueller::reversed;
use crate::optics::surface::{Incident, Surface};
use crate::render::isotropic;
use crate::render::slots::{crystal_slot, Slots, CRYSTAL_SLOTS};
use crate::render::{PathLobe, Transport};
use nalgebra::Vector3;

/// The forward events of light arriving along `−towards` (exterior, or each crystal mode that
/// can travel there), with the incident crystal mode.
fn forward_events(
    surface: &Surface,
    towards: Vector3<f64>,
) -> Result<Vec<(Option<ModeKind>, Event)>> {
    if towards.z > 0.0 {
        return Ok(vec![(None, scatter(surface, towards, Incident::Outside)?)]);
    }
    let kinds: &[ModeKind] = if surface.crystal.is_isotropic() {
        &[ModeKind::O]
    } else {
        &[ModeKind::O, ModeKind::E]
    };
    kinds
        .iter()
        .map(|&k| Ok((Some(k), scatter(surface, towards, Incident::Inside(k))?)))
        .collect()
}

/// The outgoing lobes of an event whose incident crystal mode is `incident` (`None`: from
/// the exterior), with their components: reflections are 0; a transmission is 1 or 2 by its
/// crystal-side mode.
fn outgoing(event: &Event, incident: Option<ModeKind>) -> impl Iterator<Item = (usize, Lobe)> + '_ {
    let by_mode = |m: ModeKind| if m == ModeKind::E { 2 } else { 1 };
    let reflected = event.reflected.iter().flatten().map(|l| (0, *l));
    let transmitted = event
        .transmitted
        .iter()
        .flatten()
        .map(move |l| (by_mode(incident.unwrap_or(l.kind)), *l));
    reflected.chain(transmitted)
}

/// Lobes of a bulk crystal surface seen from `wi` (unit, local; `wi.z < 0` is inside). A
/// lossless isotropic crystal takes the closed form of [`crate::render::isotropic`]. Absorbing
/// anisotropic crystals are refused (an error naming `kappa_o` or `kappa_e`): their per-ray powers are not
/// defined (see the error message); isotropic absorbing media (metals, lossy dielectrics) are
/// opaque, with the reflection lobe alone (module documentation).
pub fn crystal_lobes(
    surface: &Surface,
    wi: Vector3<f64>,
    transport: Transport,
) -> Result<Vec<PathLobe>> {
    refuse_absorbing_birefringence(surface)?;
    let Some(wi) = checked_direction(wi)? else {
        return Ok(Vec::new());
    };
    if let Some(lobes) = isotropic::crystal_lobes(surface, wi, transport) {
        return Ok(lobes);
    }
    let mut lobes = Vec::new();
    each_lobe(surface, wi, transport, |_, l| lobes.push(l))?;
    Ok(lobes)
}

/// Absorbing anisotropic crystals are refused (see [`crystal_lobes`]), naming the absorbing
/// index's parameter.
fn refuse_absorbing_birefringence(surface: &Surface) -> Result<()> {
    if !surface.crystal.is_isotropic() && !surface.crystal.is_lossless() {
        let absorbing = if surface.crystal.eta_o.im != 0.0 {
            "kappa_o"
        } else {
            "kappa_e"
        };
        return Err(Error::new(
            absorbing,
            "an absorbing birefringent crystal cannot be rendered as a bulk surface: inside it the o and e waves are not power-orthogonal (their fluxes do not add), so the power of each refracted ray is undefined and lobe weights would not conserve energy. Use thinbirefringent for a dichroic plate (its transmission is exact), or kappa_o = kappa_e = 0 here",
        ));
    }
    Ok(())
}

/// `wi` normalised, `None` at exactly grazing incidence (no lobes); an error unless unit.
fn checked_direction(wi: Vector3<f64>) -> Result<Option<Vector3<f64>>> {
    if !(wi.iter().all(|x| x.is_finite()) && (wi.norm() - 1.0).abs() < 1e-4) {
        return Err(Error::new("wi", "must be a unit vector"));
    }
    Ok((wi.z != 0.0).then(|| wi.normalize()))
}

/// [`crystal_lobes`] by the general computation (every case, isotropic ones included): the
/// reference the isotropic fast path is tested against.
pub fn crystal_lobes_full(
    surface: &Surface,
    wi: Vector3<f64>,
    transport: Transport,
) -> Result<Vec<PathLobe>> {
    let Some(wi) = checked_direction(wi)? else {
        return Ok(Vec::new());
    };
    let mut lobes = Vec::new();
    each_lobe(surface, wi, transport, |_, l| lobes.push(l))?;
    Ok(lobes)
}

/// The lobes of [`crystal_lobes`] in their fixed slots ([`crate::render::slots`]): the same
/// lobes, bit for bit, each at the index of the two waves it joins.
pub fn crystal_slots(
    surface: &Surface,
    wi: Vector3<f64>,
    transport: Transport,
) -> Result<Slots<CRYSTAL_SLOTS>> {
    let mut slots = [None; CRYSTAL_SLOTS];
    refuse_absorbing_birefringence(surface)?;
    let Some(wi) = checked_direction(wi)? else {
        return Ok(slots);
    };
    if let Some(lobes) = isotropic::crystal_lobes(surface, wi, transport) {
        // Reflection (component 0) and refraction (1) of an isotropic crystal, whose rays
        // count as o-rays.
        let crystal = Some(ModeKind::O);
        let (near, far) = if wi.z < 0.0 {
            (crystal, None)
        } else {
            (None, crystal)
        };
        for l in lobes {
            let wo_end = if l.component == 0 { near } else { far };
            slots[crystal_slot(near, wo_end)] = Some(l);
        }
        return Ok(slots);
    }
    each_lobe(surface, wi, transport, |slot, l| slots[slot] = Some(l))?;
    Ok(slots)
}

/// Calls `f(slot, lobe)` for every lobe seen from `wi` (unit, `wi.z != 0`), by the general
/// computation.
fn each_lobe(
    surface: &Surface,
    wi: Vector3<f64>,
    transport: Transport,
    mut f: impl FnMut(usize, PathLobe),
) -> Result<()> {
    let opaque = opaque(surface);
    if wi.z < 0.0 && opaque {
        return Ok(()); // no light inside an opaque bulk
    }
    for (inc, event) in forward_events(surface, wi)? {
        for (component, l) in outgoing(&event, inc) {
            if opaque && component != 0 {
                continue; // refracted into the opaque bulk: absorbed at the surface
            }
            // The crystal mode of the outgoing wave (None outside): a reflection stays on the
            // incident side; a transmission from outside enters as its own mode.
            let mode = match (component, inc) {
                (0, inc) => inc.map(|_| l.kind),
                (_, None) => Some(l.kind),
                (_, Some(_)) => None,
            };
            let slot = crystal_slot(inc, mode);
            match transport {
                Transport::Importance => f(
                    slot,
                    PathLobe::new(
                        component,
                        l.direction,
                        (event.incident_stokes_x, l.stokes_x),
                        l.mueller,
                        l.ray_index / event.incident_ray_index,
                    ),
                ),
                Transport::Radiance => f(
                    slot,
                    PathLobe::new(
                        component,
                        l.direction,
                        (l.stokes_x, event.incident_stokes_x),
                        reversed(&l.mueller),
                        l.ray_index / event.incident_ray_index,
                    )
                    .with_radiance_factor((event.incident_ray_index / l.ray_index).powi(2)),
                ),
            }
        }
    }
    Ok(())
}

/// Whether the crystal's bulk is opaque (any absorption): light refracted into it is absorbed
/// at the surface and none arrives from inside (see the module documentation).
pub fn opaque(surface: &Surface) -> bool {
    !surface.crystal.is_lossless()
}
