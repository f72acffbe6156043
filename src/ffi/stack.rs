//! The batch entry point of stacks: each lane the scalar stack query of the core
//! (`render::stack::stack_lobes` in its fixed slots, per channel, then the choice of one),
//! written to the outputs. Panics are caught per lane.

use super::batch::{
    choose_thin, enabled, finish, rotated_about, transport_and_sample, write_lanes, Lobes,
};
use super::bridge::{PlateCall, Samples, StackLanes, Status, Transport as BridgeTransport};
use super::columns::{Column, Columns3, Wavelengths};
use super::guard::guarded;
use super::materials::Materials;
use super::samples::Output;
use super::spectrum::PlateSpectrum;
use crate::error::{Error, Result};
use crate::params::{Length, Thickness};
use crate::render::choice::Choice;
use crate::render::slots::{plate_component, PLATE_SLOTS};
use crate::render::stack::{stack_lobes, StackQuery};
use crate::stack::{in_layer, Layer, Stack};
use crate::C64;

/// Samples a stack lobe in every lane (see `bridge::sample_stack`).
pub fn sample_stack(
    materials: &Materials,
    spectrum: &PlateSpectrum,
    call: &PlateCall,
    lanes: &StackLanes,
    out: &mut Samples,
) -> Status {
    let run = || {
        let cols = StackColumns::new(lanes)?;
        spectrum.check_wavelength_columns(cols.wavelengths.count())?;
        let channels = spectrum.channels(cols.wavelengths.count());
        let mut output = Output::new(out, lanes.count, channels)?;
        let lane = |i, lobes: &mut _| stack_lane(materials, spectrum, call, &cols, i, lobes);
        write_lanes(
            &mut output,
            lanes.count,
            &cols.active,
            lane,
            plate_component,
        );
        Ok(output.status())
    };
    finish(guarded(run), out)
}

/// The validated columns of a stack batch.
struct StackColumns<'a> {
    active: Column<'a, u8>,
    transport: Column<'a, BridgeTransport>,
    sample: Column<'a, f64>,
    wi: Columns3<'a>,
    wavelengths: Wavelengths<'a>,
    ext_ior: Column<'a, f64>,
    exit_ior: Column<'a, f64>,
    /// Per layer: material, axis.
    material: &'a [u32],
    optic_axis: Columns3<'a>,
    /// Per layer: a column of lanes each.
    axis_angle_deg: Vec<Column<'a, f64>>,
    thickness_nm: Vec<Column<'a, f64>>,
    birefringence: Vec<Column<'a, f64>>,
}

impl<'a> StackColumns<'a> {
    fn new(l: &StackLanes<'a>) -> Result<Self> {
        let (n, layers) = (l.count, l.material.len());
        if layers == 0 {
            return Err(Error::new("layers", "a stack needs at least one layer"));
        }
        let per_layer = |name: &str, columns: &[&'a [f64]]| -> Result<Vec<Column<'a, f64>>> {
            if columns.len() != layers {
                return Err(Error::new(
                    name,
                    format!("{} columns for {layers} layers", columns.len()),
                ));
            }
            columns.iter().map(|c| Column::new(name, c, n)).collect()
        };
        Ok(StackColumns {
            active: Column::new("active", l.active, n)?,
            transport: Column::new("transport", l.transport, n)?,
            sample: Column::new("sample", l.sample, n)?,
            wi: Columns3::new("wi", &l.wi, n)?,
            wavelengths: Wavelengths::new(l.wavelengths_nm, n)?,
            ext_ior: Column::new("ext_ior", l.ext_ior, n)?,
            exit_ior: Column::new("exit_ior", l.exit_ior, n)?,
            material: l.material,
            optic_axis: Columns3::new("optic_axis", &l.optic_axis, layers)?,
            axis_angle_deg: per_layer("axis_angle_deg", l.axis_angle_deg)?,
            thickness_nm: per_layer("thickness_nm", l.thickness_nm)?,
            birefringence: per_layer("birefringence", l.birefringence)?,
        })
    }
}

/// Lane `i` of a stack batch: the scalar stack query and the choice of its lobe. A layer's
/// invalid parameter is reported under its name, `layers[k].thickness`.
fn stack_lane(
    materials: &Materials,
    spectrum: &PlateSpectrum,
    call: &PlateCall,
    cols: &StackColumns,
    i: usize,
    lobes: &mut Lobes<PLATE_SLOTS>,
) -> Result<Option<Choice>> {
    let (transport, u) = transport_and_sample(&cols.transport, &cols.sample, i)?;
    let layers = (0..cols.material.len())
        .map(|k| {
            let layer = || {
                Layer::new(
                    *materials.get(cols.material[k])?,
                    cols.birefringence[k].at(i),
                    rotated_about(cols.optic_axis.at(k), cols.axis_angle_deg[k].at(i))?,
                    Thickness::new("thickness", cols.thickness_nm[k].at(i), Length::Micrometres)?,
                )
            };
            layer().map_err(|e| in_layer(k, e))
        })
        .collect::<Result<Vec<_>>>()?;
    let stack = Stack::new(
        layers,
        C64::new(cols.ext_ior.at(i), 0.0),
        C64::new(cols.exit_ior.at(i), 0.0),
    )?;
    let q = StackQuery::new(
        stack,
        enabled(call.components, 0),
        enabled(call.components, 1),
        call.intensity_only,
    )
    .with_absorbing_exit(call.absorbing_exit);
    let (s, pick) = spectrum.lane(cols.wavelengths.at(i), cols.wavelengths.count());
    let per_channel = stack_lobes(&q, &s, cols.wi.at(i), transport)?;
    Ok(choose_thin(&per_channel, pick, call, u, lobes))
}
