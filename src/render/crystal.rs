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
use crate::optics::clear_lobes::{self, each_clear_lobe, Arrival};
use crate::optics::lobes::{scatter, Lobe};
use crate::optics::modes::ModeKind;
use crate::optics::mueller::reversed;
use crate::optics::surface::{Incident, Surface};
use crate::render::isotropic;
use crate::render::slots::{crystal_slot, Slots, CRYSTAL_SLOTS};
use crate::render::{PathLobe, Transport};
use nalgebra::Vector3;

/// How a surface event is computed: the closed form of [`crate::optics::clear_lobes`] where it
/// applies, or always the general interface solve (the reference).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Solve {
    Fastest,
    General,
}

/// Lobes of a bulk crystal surface seen from `wi` (unit, local; `wi.z < 0` is inside). A
/// lossless isotropic crystal takes the closed form of [`crate::render::isotropic`], a lossless
/// birefringent one that of [`crate::optics::clear_lobes`]. Absorbing anisotropic crystals are
/// refused (an error naming `kappa_o` or `kappa_e`): their per-ray powers are not defined (see
/// the error message); isotropic absorbing media (metals, lossy dielectrics) are opaque, with
/// the reflection lobe alone (module documentation).
pub fn crystal_lobes(
    surface: &Surface,
    wi: Vector3<f64>,
    transport: Transport,
) -> Result<Vec<PathLobe>> {
    refuse_absorbing_birefringence(surface)?;
    let Some(wi) = checked_direction(wi)? else {
        return Ok(Vec::new());
    };
    // At most six lobes (from inside: each crystal wave's two reflections and refraction).
    let mut lobes = Vec::with_capacity(6);
    if let Some((reflection, refraction)) = isotropic::crystal_lobes(surface, wi, transport) {
        lobes.push(reflection);
        lobes.extend(refraction);
        return Ok(lobes);
    }
    each_lobe(surface, wi, transport, Solve::Fastest, |_, l| lobes.push(l))?;
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

/// [`crystal_lobes`] by the general computation (every case, isotropic and clear crystals
/// included, through the interface's solve): the reference the fast paths are tested against.
pub fn crystal_lobes_full(
    surface: &Surface,
    wi: Vector3<f64>,
    transport: Transport,
) -> Result<Vec<PathLobe>> {
    let Some(wi) = checked_direction(wi)? else {
        return Ok(Vec::new());
    };
    let mut lobes = Vec::new();
    each_lobe(surface, wi, transport, Solve::General, |_, l| lobes.push(l))?;
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
    fill_crystal_slots(surface, wi, transport, &mut slots)?;
    Ok(slots)
}

/// [`crystal_slots`] written into `slots` (every slot is set).
pub fn fill_crystal_slots(
    surface: &Surface,
    wi: Vector3<f64>,
    transport: Transport,
    slots: &mut Slots<CRYSTAL_SLOTS>,
) -> Result<()> {
    *slots = [None; CRYSTAL_SLOTS];
    refuse_absorbing_birefringence(surface)?;
    let Some(wi) = checked_direction(wi)? else {
        return Ok(());
    };
    if let Some((reflection, refraction)) = isotropic::crystal_lobes(surface, wi, transport) {
        // Reflection (component 0) and refraction (1) of an isotropic crystal, whose rays
        // count as o-rays.
        let crystal = Some(ModeKind::O);
        let (near, far) = if wi.z < 0.0 {
            (crystal, None)
        } else {
            (None, crystal)
        };
        slots[crystal_slot(near, near)] = Some(reflection);
        slots[crystal_slot(near, far)] = refraction;
        return Ok(());
    }
    each_lobe(surface, wi, transport, Solve::Fastest, |slot, l| {
        slots[slot] = Some(l)
    })
}

/// Calls `f(slot, lobe)` for every lobe seen from `wi` (unit, `wi.z != 0`), each event computed
/// as `solve` says.
fn each_lobe(
    surface: &Surface,
    wi: Vector3<f64>,
    transport: Transport,
    solve: Solve,
    mut f: impl FnMut(usize, PathLobe),
) -> Result<()> {
    let opaque = opaque(surface);
    if wi.z < 0.0 && opaque {
        return Ok(()); // no light inside an opaque bulk
    }
    let clear = solve == Solve::Fastest && clear_lobes::applies(surface);
    // The lobes of light arriving as the crystal wave `mode` (`None`: from the exterior).
    let mut event = |mode: Option<ModeKind>| -> Result<()> {
        let incident = mode.map_or(Incident::Outside, Incident::Inside);
        let mut out = |arrival: &Arrival, reflected: bool, l: &Lobe| {
            if let Some((slot, lobe)) = path_lobe(arrival, mode, reflected, l, opaque, transport) {
                f(slot, lobe);
            }
        };
        if clear {
            each_clear_lobe(surface, wi, incident, out)?;
        } else {
            let e = scatter(surface, wi, incident)?;
            let arrival = Arrival {
                direction: e.incident_direction,
                stokes_x: e.incident_stokes_x,
                ray_index: e.incident_ray_index,
            };
            for l in e.reflected.iter().flatten() {
                out(&arrival, true, l);
            }
            for l in e.transmitted.iter().flatten() {
                out(&arrival, false, l);
            }
        }
        Ok(())
    };
    if wi.z > 0.0 {
        return event(None);
    }
    // Light arrives from inside along each crystal wave that can travel there.
    event(Some(ModeKind::O))?;
    if !surface.crystal.is_isotropic() {
        event(Some(ModeKind::E))?;
    }
    Ok(())
}

/// The slot and the lobe a path tracer samples for the outgoing wave `l` of light arriving as
/// `arrival` in the crystal mode `incident` (`None`: from the exterior): a reflection is
/// component 0, a transmission 1 or 2 by its crystal-side mode; `None` for a refraction into an
/// `opaque` bulk (absorbed at the surface).
fn path_lobe(
    arrival: &Arrival,
    incident: Option<ModeKind>,
    reflected: bool,
    l: &Lobe,
    opaque: bool,
    transport: Transport,
) -> Option<(usize, PathLobe)> {
    let component = match (reflected, incident.unwrap_or(l.kind)) {
        (true, _) => 0,
        (false, ModeKind::E) => 2,
        (false, _) => 1,
    };
    if opaque && component != 0 {
        return None;
    }
    // The crystal mode of the outgoing wave (None outside): a reflection stays on the incident
    // side; a transmission from outside enters as its own mode.
    let mode = match (reflected, incident) {
        (true, inc) => inc.map(|_| l.kind),
        (false, None) => Some(l.kind),
        (false, Some(_)) => None,
    };
    let ratio = l.ray_index / arrival.ray_index;
    let lobe = match transport {
        Transport::Importance => PathLobe::new(
            component,
            l.direction,
            (arrival.stokes_x, l.stokes_x),
            l.mueller,
            ratio,
        ),
        Transport::Radiance => PathLobe::new(
            component,
            l.direction,
            (l.stokes_x, arrival.stokes_x),
            reversed(&l.mueller) * (arrival.ray_index / l.ray_index).powi(2),
            ratio,
        ),
    };
    Some((crystal_slot(incident, mode), lobe))
}

/// Whether the crystal's bulk is opaque (any absorption): light refracted into it is absorbed
/// at the surface and none arrives from inside (see the module documentation).
pub fn opaque(surface: &Surface) -> bool {
    !surface.crystal.is_lossless()
}
