//! The lobes of a bulk crystal's surface (reflection, ordinary and extraordinary refraction)
//! as a path tracer samples them (see [`crate::render`] for the transport modes), over the
//! reals of [`crate::real`]: on the host, and recorded as the program the shim replays
//! ([`sample_exact`]). A decision about a lane (the side `wi` looks from, total internal
//! reflection, an isotropic or absorbing crystal whose indices are a program's inputs) is a
//! mask there, and the lobes of every outcome are kept with the masks of their lanes.
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
use crate::material::{check_clear_index, Material};
use crate::optics::clear_lobes::{clear_event, Arrival};
use crate::optics::lobes::{scatter, Lobe};
use crate::optics::medium::Uniaxial;
use crate::optics::modes::ModeKind;
use crate::optics::mueller::reversed;
use crate::optics::surface::{Incident, Surface};
use crate::plate::slab::Output;
use crate::real::complex as cx;
use crate::real::{Mask, Real, Select};
use crate::render::choice::{self, Sampled};
use crate::render::isotropic;
use crate::render::slots::{crystal_component, crystal_slot, Slots, CRYSTAL_SLOTS};
use crate::render::{PathLobe, Transport};
use nalgebra::{Matrix4, Vector3};
use num_complex::Complex64 as C64;

/// Lobes of a bulk crystal surface seen from `wi` (unit, local; `wi.z < 0` is inside). An
/// isotropic crystal takes the closed form of [`crate::render::isotropic`], a lossless
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
    let Some((wi, lit)) = checked_direction(wi)? else {
        return Ok(Vec::new());
    };
    // At most six lobes (from inside: each crystal wave's two reflections and refraction).
    let mut lobes = Vec::with_capacity(6);
    each_lobe(surface, wi, lit, transport, |_, l| lobes.push(l))?;
    Ok(lobes)
}

/// Absorbing anisotropic crystals are refused (see [`crystal_lobes`]), naming the absorbing
/// index's parameter; while recording, the lanes where the crystal is both.
fn refuse_absorbing_birefringence<T: Real>(surface: &Surface<T>) -> Result<()> {
    let c = &surface.crystal;
    (!c.is_isotropic() & !c.is_lossless()).fail(|| {
        let absorbing = if c.eta_o.im.value() != Some(0.0) {
            "kappa_o"
        } else {
            "kappa_e"
        };
        Error::new(
            absorbing,
            "an absorbing birefringent crystal cannot be rendered as a bulk surface: inside it the o and e waves are not power-orthogonal (their fluxes do not add), so the power of each refracted ray is undefined and lobe weights would not conserve energy. Use thinbirefringent for a dichroic plate (its transmission is exact), or kappa_o = kappa_e = 0 here",
        )
    })
}

/// `wi` normalised, and where it is not exactly grazing (no lobes there); `None` where that is
/// known; an error unless unit. While recording, lanes that are not unit or graze compute on
/// the normal instead (finite numbers, and no light).
fn checked_direction<T: Real>(wi: Vector3<T>) -> Result<Option<(Vector3<T>, T::Mask)>> {
    let finite = wi.iter().fold(T::Mask::cst(true), |m, x| m & x.finite());
    let norm = wi.dot(&wi).sqrt();
    let unit = finite & (norm - T::one()).abs().lt(T::cst(1e-4));
    (!unit).fail(|| Error::new("wi", "must be a unit vector"))?;
    let grazing = wi.z.equals(T::zero());
    if grazing.surely() {
        return Ok(None);
    }
    let wi = wi / norm;
    let unsafe_lane = !unit | grazing;
    let wi = if unsafe_lane.known() == Some(false) {
        wi
    } else {
        let (zero, one) = (T::zero(), T::one());
        Select::select(unsafe_lane, Vector3::new(zero, zero, one), wi)
    };
    Ok(Some((wi, !grazing)))
}

/// [`crystal_lobes`] by the general computation (every case, isotropic and clear crystals
/// included, through the interface's solve): the reference the fast paths are tested against.
pub fn crystal_lobes_full(
    surface: &Surface,
    wi: Vector3<f64>,
    transport: Transport,
) -> Result<Vec<PathLobe>> {
    let Some((wi, _)) = checked_direction(wi)? else {
        return Ok(Vec::new());
    };
    let mut lobes = Vec::new();
    each_general_lobe(surface, wi, transport, |_, l| lobes.push(l))?;
    Ok(lobes)
}

/// [`crystal_slots`] by the general computation ([`crystal_lobes_full`] in slots): the reference
/// of the recorded program's tests.
pub fn crystal_slots_full(
    surface: &Surface,
    wi: Vector3<f64>,
    transport: Transport,
) -> Result<Slots<CRYSTAL_SLOTS>> {
    let mut slots = [None; CRYSTAL_SLOTS];
    if let Some((wi, _)) = checked_direction(wi)? {
        each_general_lobe(surface, wi, transport, |slot, l| slots[slot] = Some(l))?;
    }
    Ok(slots)
}

/// The lobes of [`crystal_lobes`] in their fixed slots ([`crate::render::slots`]): the same
/// lobes, bit for bit, each at the index of the two waves it joins; over the reals `T`.
pub fn crystal_slots<T: Real>(
    surface: &Surface<T>,
    wi: Vector3<T>,
    transport: Transport,
) -> Result<Slots<CRYSTAL_SLOTS, T>> {
    let mut slots = [None; CRYSTAL_SLOTS];
    fill_crystal_slots(surface, wi, transport, &mut slots)?;
    Ok(slots)
}

/// [`crystal_slots`] written into `slots` (every slot is set).
pub fn fill_crystal_slots<T: Real>(
    surface: &Surface<T>,
    wi: Vector3<T>,
    transport: Transport,
    slots: &mut Slots<CRYSTAL_SLOTS, T>,
) -> Result<()> {
    *slots = [None; CRYSTAL_SLOTS];
    refuse_absorbing_birefringence(surface)?;
    let Some((wi, lit)) = checked_direction(wi)? else {
        return Ok(());
    };
    each_lobe(surface, wi, lit, transport, |slot, l| {
        put(&mut slots[slot], l)
    })
}

/// `lobe` into `slot`: where the slot already holds a lobe of other lanes (another outcome of
/// a decision about the lanes), each lane keeps the one that exists there.
fn put<T: Real>(slot: &mut Option<PathLobe<T>>, lobe: PathLobe<T>) {
    *slot = Some(match *slot {
        Some(old) if old.exists.known() != Some(false) => PathLobe {
            exists: lobe.exists | old.exists,
            ..Select::select(lobe.exists, lobe, old)
        },
        _ => lobe,
    });
}

/// Calls `f(slot, lobe)` for every lobe seen from `wi` (unit; where `lit`, not grazing): those
/// of the isotropic closed form where the crystal is isotropic, of the clear birefringent one
/// elsewhere.
fn each_lobe<T: Real>(
    surface: &Surface<T>,
    wi: Vector3<T>,
    lit: T::Mask,
    transport: Transport,
    mut f: impl FnMut(usize, PathLobe<T>),
) -> Result<()> {
    let iso = surface.crystal.is_isotropic();
    let outside = wi.z.gt(T::zero());
    if iso.known() != Some(false) {
        let live = iso & lit;
        isotropic::each_lobe(surface, wi, outside, transport, |slot, l| {
            f(slot, l.existing(live))
        })?;
    }
    if iso.known() != Some(true) {
        let live = !iso & lit;
        birefringent_lobes(surface, wi, outside, transport, live, |slot, l| {
            f(slot, l.existing(live))
        })?;
    }
    Ok(())
}

/// The lobes of a clear birefringent crystal seen from `wi` (`outside`: where `wi.z > 0`), each
/// to `f(slot, lobe)`; the lanes of `live` fail where an event cannot be computed. Light from
/// inside arrives along each crystal wave that can travel there. Both sides are computed where
/// the side is not known, each from `wi` mirrored to its side.
fn birefringent_lobes<T: Real>(
    surface: &Surface<T>,
    wi: Vector3<T>,
    outside: T::Mask,
    transport: Transport,
    live: T::Mask,
    mut f: impl FnMut(usize, PathLobe<T>),
) -> Result<()> {
    // Lanes where the crystal absorbs are refused (or isotropic: opaque), so the events may
    // take the real parts of its indices (finite numbers in every lane, and lossless
    // arithmetic).
    let c = surface.crystal;
    let surface = if c.is_lossless().surely() {
        *surface
    } else {
        Surface {
            crystal: Uniaxial {
                eta_o: cx::real(c.eta_o.re),
                eta_e: cx::real(c.eta_e.re),
                axis: c.axis,
            },
            ..*surface
        }
    };
    let mut event = |mode: Option<ModeKind>, side: T::Mask, towards: Vector3<T>| {
        let incident = mode.map_or(Incident::Outside, Incident::Inside);
        clear_event(
            &surface,
            towards,
            incident,
            live & side,
            |arrival, reflected, l, carries| {
                if let Some((slot, lobe)) = path_lobe(arrival, mode, reflected, l, false, transport)
                {
                    f(slot, lobe.existing(carries & side));
                }
            },
        )
        .map(|_| ())
    };
    if outside.known() != Some(false) {
        event(None, outside, Vector3::new(wi.x, wi.y, wi.z.abs()))?;
    }
    if outside.known() != Some(true) {
        let inside = Vector3::new(wi.x, wi.y, -wi.z.abs());
        event(Some(ModeKind::O), !outside, inside)?;
        event(Some(ModeKind::E), !outside, inside)?;
    }
    Ok(())
}

/// Calls `f(slot, lobe)` for every lobe seen from `wi` (unit, `wi.z != 0`), each event
/// through the general interface solve ([`scatter`]).
fn each_general_lobe(
    surface: &Surface,
    wi: Vector3<f64>,
    transport: Transport,
    mut f: impl FnMut(usize, PathLobe),
) -> Result<()> {
    let opaque = opaque(surface);
    if wi.z < 0.0 && opaque {
        return Ok(()); // no light inside an opaque bulk
    }
    // The lobes of light arriving as the crystal wave `mode` (`None`: from the exterior).
    let mut event = |mode: Option<ModeKind>| -> Result<()> {
        let incident = mode.map_or(Incident::Outside, Incident::Inside);
        let e = scatter(surface, wi, incident)?;
        let arrival = Arrival {
            direction: e.incident_direction,
            stokes_x: e.incident_stokes_x,
            ray_index: e.incident_ray_index,
        };
        let lobes = e.reflected.iter().map(|l| (true, l));
        for (reflected, l) in lobes.chain(e.transmitted.iter().map(|l| (false, l))) {
            let Some(l) = l else { continue };
            if let Some((slot, lobe)) = path_lobe(&arrival, mode, reflected, l, opaque, transport) {
                f(slot, lobe);
            }
        }
        Ok(())
    };
    if wi.z > 0.0 {
        return event(None);
    }
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
fn path_lobe<T: Real>(
    arrival: &Arrival<T>,
    incident: Option<ModeKind>,
    reflected: bool,
    l: &Lobe<T>,
    opaque: bool,
    transport: Transport,
) -> Option<(usize, PathLobe<T>)> {
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
        Transport::Radiance => {
            let factor = arrival.ray_index / l.ray_index;
            PathLobe::new(
                component,
                l.direction,
                (l.stokes_x, arrival.stokes_x),
                reversed(&l.mueller),
                ratio,
            )
            .with_radiance_factor(factor * factor)
        }
    };
    Some((crystal_slot(incident, mode), lobe))
}

/// Whether the crystal's bulk is opaque (any absorption): light refracted into it is absorbed
/// at the surface and none arrives from inside (see the module documentation).
pub fn opaque(surface: &Surface) -> bool {
    !surface.crystal.is_lossless()
}

/// A crystal query at exact wavelengths, over the reals `T`: what a spectral renderer asks at
/// the wavelengths it traces along a path, on the host (`f64`) or recorded as a program
/// ([`crate::record`]) whose inputs are the path's and the crystal's per-lane values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExactCrystal<T: Real = f64> {
    /// The crystal's material.
    pub material: Material<T>,
    /// The exterior's (real) index.
    pub ext: T,
    /// The optic axis, local frame (any non-zero length: normalised at each wavelength).
    pub axis: Vector3<T>,
    /// Only `M00` of each lobe (the others zero).
    pub output: Output,
}

impl ExactCrystal {
    /// A validated query: a real exterior index, a finite non-zero axis.
    pub fn new(
        material: Material,
        ext: f64,
        axis: Vector3<f64>,
        intensity_only: bool,
    ) -> Result<Self> {
        let ext = check_clear_index("ext_ior", C64::new(ext, 0.0))?.re;
        Uniaxial::new(C64::new(1.0, 0.0), C64::new(1.5, 0.0), axis)?;
        Ok(ExactCrystal {
            material,
            ext,
            axis,
            output: if intensity_only {
                Output::Intensity
            } else {
                Output::Mueller
            },
        })
    }
}

impl<T: Real> ExactCrystal<T> {
    /// The surface at `lambda_nm` (the indices there are checked).
    pub fn surface_at(&self, lambda_nm: T) -> Result<Surface<T>> {
        let (eta_o, eta_e) = self.material.indices(lambda_nm, T::zero())?;
        Ok(Surface {
            exterior: Uniaxial::isotropic_unchecked(cx::real(self.ext)),
            crystal: Uniaxial {
                eta_o,
                eta_e,
                axis: self.axis / self.axis.dot(&self.axis).sqrt(),
            },
        })
    }
}

/// The lobe a path samples from the crystal surface of `q` at one wavelength per channel seen
/// from `wi`, chosen with the uniform number `u` among the components whose bits `components`
/// sets (0 reflection, 1 ordinary, 2 extraordinary refraction), as Mitsuba's sample
/// ([`choice::sample`]). A material whose indices do not depend on the wavelength is solved
/// once.
pub fn sample_exact<T: Real, const C: usize>(
    q: &ExactCrystal<T>,
    wavelengths: &[T; C],
    wi: Vector3<T>,
    u: T,
    transport: Transport,
    components: u32,
) -> Result<Sampled<T, C>> {
    let mut slots: [Slots<CRYSTAL_SLOTS, T>; C] = [[None; CRYSTAL_SLOTS]; C];
    for (c, &lambda_nm) in wavelengths.iter().enumerate() {
        let surface = q.surface_at(lambda_nm)?;
        if c > 0 && !q.material.is_dispersive() {
            slots[c] = slots[c - 1];
            continue;
        }
        fill_crystal_slots(&surface, wi, transport, &mut slots[c])?;
        if q.output == Output::Intensity {
            for lobe in slots[c].iter_mut().flatten() {
                let m00 = lobe.mueller[(0, 0)];
                lobe.mueller = Matrix4::from_fn(|i, j| if i + j == 0 { m00 } else { T::zero() });
            }
        }
    }
    Ok(choice::sample(
        &slots,
        |slot| components & (1 << crystal_component(slot)) != 0,
        crystal_component,
        u,
    ))
}
