//! The batch entry points: each lane is the scalar query of the core (a plate's or a crystal's
//! lobes in their fixed slots, per channel, then the choice of one), written to the outputs.
//! Nothing is allocated per lane here; panics are caught per lane.

use super::bridge::{
    Bounds, CrystalLanes, PlateCall, PlateLanes, Samples, Status, Transport as BridgeTransport,
};
use super::columns::{Column, Columns3, Wavelengths, MAX_CHANNELS};
use super::guard::{guarded, status};
use super::materials::Materials;
use super::samples::Output;
use super::spectrum::PlateSpectrum;
use crate::error::{Error, Result};
use crate::material::Material;
use crate::optics::frame::rotated_about_normal;
use crate::optics::medium::Uniaxial;
use crate::optics::surface::Surface;
use crate::params::{Length, Thickness};
use crate::render::choice::{choose, Choice};
use crate::render::crystal::fill_crystal_slots;
use crate::render::plate::{plate_lobes, PlateQuery};
use crate::render::slots::{crystal_component, plate_component, Slots, CRYSTAL_SLOTS, PLATE_SLOTS};
use crate::render::thin::{Spectrum, MAX_BANDS};
use crate::render::Transport;
use crate::C64;
use nalgebra::Vector3;

const _: () = assert!(MAX_CHANNELS == MAX_BANDS);
const _: () = assert!(Bounds::MaxChannels.repr as usize == MAX_CHANNELS);
const _: () = assert!(Bounds::PlateComponents.repr as usize == PLATE_SLOTS);

/// One lane's lobes per channel: filled in place by a lane (a crystal's are 8 KB, which moving
/// by value cost more than computing an isotropic crystal's lobes).
pub(super) type Lobes<const S: usize> = [Slots<S>; MAX_CHANNELS];

/// Samples a plate lobe in every lane (see `bridge::sample_plate`).
pub fn sample_plate(
    materials: &Materials,
    spectrum: &PlateSpectrum,
    call: &PlateCall,
    lanes: &PlateLanes,
    out: &mut Samples,
) -> Status {
    plate_batch(materials, spectrum, call, lanes, out)
}

/// Samples a crystal lobe in every lane (see `bridge::sample_crystal`).
pub fn sample_crystal(
    materials: &Materials,
    components: u32,
    lanes: &CrystalLanes,
    out: &mut Samples,
) -> Status {
    crystal_batch(materials, components, lanes, out)
}

fn plate_batch(
    materials: &Materials,
    spectrum: &PlateSpectrum,
    call: &PlateCall,
    lanes: &PlateLanes,
    out: &mut Samples,
) -> Status {
    let run = || {
        let cols = PlateColumns::new(lanes)?;
        spectrum.check_wavelength_columns(cols.common.wavelengths.count())?;
        let channels = spectrum.channels(cols.common.wavelengths.count());
        let mut output = Output::new(out, lanes.count, channels)?;
        let lane = |i, lobes: &mut _| plate_lane(materials, spectrum, call, &cols, i, lobes);
        write_lanes(
            &mut output,
            lanes.count,
            &cols.common.active,
            lane,
            plate_component,
        );
        Ok(output.status())
    };
    finish(guarded(run), out)
}

fn crystal_batch(
    materials: &Materials,
    components: u32,
    lanes: &CrystalLanes,
    out: &mut Samples,
) -> Status {
    let run = || {
        let cols = CrystalColumns::new(lanes)?;
        let channels = cols.common.wavelengths.count();
        if channels == 0 {
            return Err(Error::new(
                "wavelengths_nm",
                "at least one column is needed",
            ));
        }
        let mut output = Output::new(out, lanes.count, channels)?;
        let lane = |i, lobes: &mut _| crystal_lane(materials, components, &cols, i, lobes);
        write_lanes(
            &mut output,
            lanes.count,
            &cols.common.active,
            lane,
            crystal_component,
        );
        Ok(output.status())
    };
    finish(guarded(run), out)
}

/// The call's status; a call that failed as a whole leaves its message.
pub(super) fn finish(r: Result<Status>, out: &mut Samples) -> Status {
    r.unwrap_or_else(|e| {
        out.message = e.to_string();
        status(&e)
    })
}

/// Computes each of the call's `count` lanes (`lane(i, lobes)`, skipping inactive ones) and
/// writes it. A lane fills the channels' slots of `lobes` (one buffer for the call) and returns
/// the chosen slot, if any.
pub(super) fn write_lanes<const S: usize>(
    output: &mut Output,
    count: usize,
    active: &Column<u8>,
    lane: impl Fn(usize, &mut Lobes<S>) -> Result<Option<Choice>>,
    component: fn(usize) -> usize,
) {
    let mut lobes = [[None; S]; MAX_CHANNELS];
    for i in 0..count {
        if active.at(i) == 0 {
            output.nothing(i);
            continue;
        }
        let written = guarded(|| lane(i, &mut lobes)).and_then(|choice| match choice {
            Some(choice) => {
                let channels = &lobes[..output.channels()];
                output.write(i, channels, choice, component(choice.slot))
            }
            None => {
                output.nothing(i);
                Ok(())
            }
        });
        if let Err(e) = written {
            output.fail(i, &e);
        }
    }
}

/// The columns both queries share.
struct CommonColumns<'a> {
    active: Column<'a, u8>,
    material: Column<'a, u32>,
    transport: Column<'a, BridgeTransport>,
    sample: Column<'a, f64>,
    wi: Columns3<'a>,
    wavelengths: Wavelengths<'a>,
    ext_ior: Column<'a, f64>,
    optic_axis: Columns3<'a>,
}

impl<'a> CommonColumns<'a> {
    #[allow(clippy::too_many_arguments)]
    fn new(
        n: usize,
        active: &'a [u8],
        material: &'a [u32],
        transport: &'a [BridgeTransport],
        sample: &'a [f64],
        wi: &[&'a [f64]; 3],
        wavelengths: &[&'a [f64]],
        ext_ior: &'a [f64],
        optic_axis: &[&'a [f64]; 3],
    ) -> Result<Self> {
        Ok(CommonColumns {
            active: Column::new("active", active, n)?,
            material: Column::new("material", material, n)?,
            transport: Column::new("transport", transport, n)?,
            sample: Column::new("sample", sample, n)?,
            wi: Columns3::new("wi", wi, n)?,
            wavelengths: Wavelengths::new(wavelengths, n)?,
            ext_ior: Column::new("ext_ior", ext_ior, n)?,
            optic_axis: Columns3::new("optic_axis", optic_axis, n)?,
        })
    }

    /// Lane `i`'s transport mode and lobe-choosing number.
    fn transport_and_sample(&self, i: usize) -> Result<(Transport, f64)> {
        transport_and_sample(&self.transport, &self.sample, i)
    }
}

/// Lane `i`'s transport mode and lobe-choosing number, checked.
pub(super) fn transport_and_sample(
    transport: &Column<BridgeTransport>,
    sample: &Column<f64>,
    i: usize,
) -> Result<(Transport, f64)> {
    let transport = match transport.at(i) {
        BridgeTransport::Radiance => Transport::Radiance,
        BridgeTransport::Importance => Transport::Importance,
        t => {
            return Err(Error::new(
                "transport",
                format!("must be Radiance (0) or Importance (1), got {}", t.repr),
            ))
        }
    };
    let u = sample.at(i);
    if !(0.0..=1.0).contains(&u) {
        return Err(Error::new(
            "sample",
            format!("must be within [0, 1], got {u}"),
        ));
    }
    Ok((transport, u))
}

struct PlateColumns<'a> {
    common: CommonColumns<'a>,
    exit_ior: Column<'a, f64>,
    axis_angle_deg: Column<'a, f64>,
    thickness_nm: Column<'a, f64>,
    birefringence: Column<'a, f64>,
}

impl<'a> PlateColumns<'a> {
    fn new(l: &PlateLanes<'a>) -> Result<Self> {
        let n = l.count;
        Ok(PlateColumns {
            common: CommonColumns::new(
                n,
                l.active,
                l.material,
                l.transport,
                l.sample,
                &l.wi,
                l.wavelengths_nm,
                l.ext_ior,
                &l.optic_axis,
            )?,
            exit_ior: Column::new("exit_ior", l.exit_ior, n)?,
            axis_angle_deg: Column::new("axis_angle_deg", l.axis_angle_deg, n)?,
            thickness_nm: Column::new("thickness_nm", l.thickness_nm, n)?,
            birefringence: Column::new("birefringence", l.birefringence, n)?,
        })
    }
}

struct CrystalColumns<'a> {
    common: CommonColumns<'a>,
}

impl<'a> CrystalColumns<'a> {
    fn new(l: &CrystalLanes<'a>) -> Result<Self> {
        Ok(CrystalColumns {
            common: CommonColumns::new(
                l.count,
                l.active,
                l.material,
                l.transport,
                l.sample,
                &l.wi,
                l.wavelengths_nm,
                l.ext_ior,
                &l.optic_axis,
            )?,
        })
    }
}

/// `axis` rotated about the local normal by `degrees` ([`rotated_about_normal`]), which must be
/// finite (the plugin's `axis_angle`).
pub(super) fn rotated_about(axis: Vector3<f64>, degrees: f64) -> Result<Vector3<f64>> {
    if !degrees.is_finite() {
        return Err(Error::new(
            "axis_angle",
            format!("must be a finite number (degrees), got {degrees}"),
        ));
    }
    if degrees == 0.0 {
        return Ok(axis);
    }
    Ok(rotated_about_normal(axis, degrees))
}

/// True if component `k` is enabled in the bit set `components`.
pub(super) fn enabled(components: u32, k: usize) -> bool {
    k < 32 && components & (1 << k) != 0
}

/// The plate's lobes per channel of lane `i` over `spectrum`.
fn plate_at(
    materials: &Materials,
    call: &PlateCall,
    cols: &PlateColumns,
    i: usize,
    spectrum: &Spectrum,
    transport: Transport,
) -> Result<Vec<Slots<PLATE_SLOTS>>> {
    let c = &cols.common;
    let q = PlateQuery::new(
        *materials.get(c.material.at(i))?,
        cols.birefringence.at(i),
        C64::new(c.ext_ior.at(i), 0.0),
        C64::new(cols.exit_ior.at(i), 0.0),
        rotated_about(c.optic_axis.at(i), cols.axis_angle_deg.at(i))?,
        Thickness::new("thickness", cols.thickness_nm.at(i), Length::Micrometres)?,
        enabled(call.components, 0),
        enabled(call.components, 1),
        call.intensity_only,
    )?
    .with_absorbing_exit(call.absorbing_exit);
    plate_lobes(&q, spectrum, c.wi.at(i), transport)
}

/// Lane `i` of a plate batch: the scalar plate query and the choice of its lobe.
fn plate_lane(
    materials: &Materials,
    spectrum: &PlateSpectrum,
    call: &PlateCall,
    cols: &PlateColumns,
    i: usize,
    lobes: &mut Lobes<PLATE_SLOTS>,
) -> Result<Option<Choice>> {
    let c = &cols.common;
    let (transport, u) = c.transport_and_sample(i)?;
    let (s, pick) = spectrum.lane(c.wavelengths.at(i), c.wavelengths.count());
    let per_channel = plate_at(materials, call, cols, i, &s, transport)?;
    Ok(choose_thin(&per_channel, pick, call, u, lobes))
}

/// The lobe of a thin element (a plate or a stack) over the channels of its query, and the
/// channels the query keeps (`pick`: one of them, for a mono variant's channel) written to
/// `lobes`.
pub(super) fn choose_thin(
    per_channel: &[Slots<PLATE_SLOTS>],
    pick: Option<usize>,
    call: &PlateCall,
    u: f64,
    lobes: &mut Lobes<PLATE_SLOTS>,
) -> Option<Choice> {
    // The lobe is chosen over every channel of the set, also when the query keeps one: the
    // passes of a channel render then choose alike, and their remaining noise (which lobe a
    // path follows) scales the channels together (no colour noise).
    let choice = choose(
        per_channel,
        |slot| enabled(call.components, plate_component(slot)),
        u,
    );
    match pick {
        Some(k) => lobes[0] = per_channel[k],
        None => {
            for (l, p) in lobes.iter_mut().zip(per_channel) {
                *l = *p;
            }
        }
    }
    let kept = |choice: Choice| Choice {
        hero: if pick.is_some() { 0 } else { choice.hero },
        ..choice
    };
    choice.map(kept)
}

/// The crystal's slots per wavelength of lane `i` (`material`, `axis` and `wi`: the lane's or a
/// moved point's), into `slots` (one per wavelength column).
fn crystal_at(
    cols: &CrystalColumns,
    i: usize,
    (material, axis, wi): (&Material, Vector3<f64>, Vector3<f64>),
    transport: Transport,
    slots: &mut [Slots<CRYSTAL_SLOTS>],
) -> Result<()> {
    let c = &cols.common;
    let ext = C64::new(c.ext_ior.at(i), 0.0);
    let mut last: Option<(C64, C64)> = None;
    for k in 0..slots.len() {
        let indices = material.indices(c.wavelengths.at(i)[k], 0.0)?;
        if last == Some(indices) {
            // The same indices (a constant material) give the same lobes, bit for bit.
            slots[k] = slots[k - 1];
            continue;
        }
        let surface = Surface::new(ext, Uniaxial::new(indices.0, indices.1, axis)?)?;
        fill_crystal_slots(&surface, wi, transport, &mut slots[k])?;
        last = Some(indices);
    }
    Ok(())
}

/// Lane `i` of a crystal batch: the crystal's slots at each wavelength and the choice.
fn crystal_lane(
    materials: &Materials,
    components: u32,
    cols: &CrystalColumns,
    i: usize,
    lobes: &mut Lobes<CRYSTAL_SLOTS>,
) -> Result<Option<Choice>> {
    let c = &cols.common;
    let (transport, u) = c.transport_and_sample(i)?;
    let material = materials.get(c.material.at(i))?;
    let channels = c.wavelengths.count();
    let lane = (material, c.optic_axis.at(i), c.wi.at(i));
    crystal_at(cols, i, lane, transport, &mut lobes[..channels])?;
    Ok(choose(
        &lobes[..channels],
        |slot| enabled(components, crystal_component(slot)),
        u,
    ))
}
