//! `birefringence stack`: layers of uniaxial or isotropic media between an isotropic exterior
//! and an exit medium, at one wavelength or over a `spectrum` (docs/physics.md §8).

use super::input::Fields;
use super::interface::read_incidence;
use super::media;
use super::slab::monochromatic_output;
use super::spectrum::{
    band_range, band_weight, channel_names, encode, read_request, step_field, Over, RANGE,
};
use crate::band::{is_exact_band, narrow_band};
use crate::colour::weights::weight_per_nm;
use crate::error::{Error, Result};
use crate::optics::frame::PlaneFrame;
use crate::optics::surface::Surface;
use crate::params::{Length, Thickness};
use crate::plate::slab::{Output, SlabMueller, Want};
use crate::spectral::model::ThinModel;
use crate::stack::exact::StackBlocks;
use crate::stack::spectral::{quadrature, StackModel};
use crate::stack::{in_layer, Layer, Stack};
use nalgebra::Vector3;
use num_complex::Complex64 as C64;
use serde_json::Value;

/// Fields of the `stack` subcommand.
pub const FIELDS: [&str; 9] = [
    "wavelength_nm",
    "ext_ior",
    "exit_ior",
    "theta_deg",
    "phi_deg",
    "beta",
    "side",
    "layers",
    "spectrum",
];

/// Fields of one layer.
pub const LAYER_FIELDS: [&str; 7] = [
    "thickness_um",
    "optic_axis",
    "material",
    "eta_o",
    "eta_e",
    "kappa_o",
    "kappa_e",
];

/// A parsed stack query.
pub struct StackInput {
    /// The stack.
    pub stack: Stack,
    /// Vacuum wavelength (nm).
    pub wavelength_nm: f64,
    /// Plane of incidence.
    pub frame: PlaneFrame,
    /// Incidence parameter.
    pub beta: C64,
    /// Warnings for the output (a named crystal's fit extrapolated).
    pub warnings: Vec<String>,
}

/// Runs the `stack` subcommand on one input object.
pub fn run(input: &Value) -> Result<Value> {
    let mut f = Fields::new(input, &FIELDS)?;
    let q = read(&mut f)?;
    match f.get("spectrum") {
        None => monochromatic(&q),
        Some(spec) => spectrum(&q, spec),
    }
}

/// Reads everything but `spectrum`.
pub fn read(f: &mut Fields) -> Result<StackInput> {
    let wavelength_nm = f.required_number("wavelength_nm")?;
    if wavelength_nm <= 0.0 {
        return Err(Error::new("wavelength_nm", "must be > 0"));
    }
    let ext = media::read_ior(f, "ext_ior")?.unwrap_or(C64::new(1.0, 0.0));
    let exit = media::read_ior(f, "exit_ior")?.unwrap_or(ext);
    let list = match f.get("layers") {
        Some(Value::Array(a)) if !a.is_empty() => a,
        Some(Value::Array(_)) => {
            return Err(Error::new("layers", "must hold at least one layer"));
        }
        Some(v) => {
            return Err(Error::new(
                "layers",
                format!("must be a list of layer objects, got {v}"),
            ))
        }
        None => return Err(Error::new("layers", "is required")),
    };
    let mut warnings = Vec::new();
    let mut layers = Vec::with_capacity(list.len());
    for (i, v) in list.iter().enumerate() {
        let (layer, warning) = read_layer(v, wavelength_nm).map_err(|e| in_layer(i, e))?;
        layers.push(layer);
        warnings.extend(warning);
    }
    let stack = Stack::new(layers, ext, exit)?;
    let first = stack.layers[0];
    let (eo, ee) = first.material.indices(wavelength_nm, 0.0)?;
    let surface = Surface::new(
        ext,
        crate::optics::medium::Uniaxial::new(eo, ee, first.axis)?,
    )?;
    let inc = read_incidence(f, &surface, false)?;
    Ok(StackInput {
        stack,
        wavelength_nm,
        frame: inc.frame,
        beta: inc.beta,
        warnings,
    })
}

/// One layer object (errors under the layer's own field names; the caller prefixes
/// `layers[i].`), and the warning of its named crystal at `wavelength_nm`, if any.
fn read_layer(v: &Value, wavelength_nm: f64) -> Result<(Layer, Option<String>)> {
    if !v.is_object() {
        return Err(Error::new("", format!("must be a layer object, got {v}")));
    }
    let mut f = Fields::new(v, &LAYER_FIELDS)?;
    let material = media::read_material(&mut f)?;
    let (eo, ee) = material.indices(wavelength_nm, 0.0)?;
    let axis = match f.vector3("optic_axis")? {
        Some(a) => a,
        None if eo == ee => Vector3::z(),
        None => {
            return Err(Error::new(
                "optic_axis",
                "is required for a birefringent layer",
            ))
        }
    };
    let thickness = Thickness::new(
        "thickness_um",
        f.required_number("thickness_um")? * 1e3,
        Length::Micrometres,
    )?;
    let warning = material.coverage(wavelength_nm, wavelength_nm)?;
    Ok((Layer::new(material, 0.0, axis, thickness)?, warning))
}

/// The stack exactly at the query's wavelength: the output of `slab`.
fn monochromatic(q: &StackInput) -> Result<Value> {
    let j = StackBlocks::new(&q.stack, q.wavelength_nm, &q.frame, q.beta)?
        .jones(q.wavelength_nm, Want::BOTH)?;
    monochromatic_output("stack", "stack", &j, q.beta, &q.warnings)
}

/// The stack over the `spectrum` object `spec`: the output of `slab` with a spectrum.
fn spectrum(q: &StackInput, spec: &Value) -> Result<Value> {
    let request = read_request(spec, q.wavelength_nm)?;
    let model = StackModel::new(&q.stack, q.frame, q.beta);
    let mut warnings = q.warnings.clone();
    let step = |lo: f64| request.step.unwrap_or_else(|| auto_step(q, lo));
    let results: Vec<SlabMueller> = match request.over {
        Over::Weights(set) => {
            for l in &q.stack.layers {
                warnings.extend(l.material.coverage(RANGE.0, RANGE.1)?);
            }
            warnings.dedup();
            if request.quadrature() {
                (0..3)
                    .map(|c| {
                        quadrature(
                            &q.stack,
                            &q.frame,
                            q.beta,
                            |l| weight_per_nm(set, c, l),
                            RANGE,
                            step(RANGE.0),
                            Want::BOTH,
                        )
                        .map_err(step_field)
                    })
                    .collect::<Result<_>>()?
            } else {
                model
                    .channels(set, Want::BOTH, Output::Mueller, request.accuracy)?
                    .to_vec()
            }
        }
        Over::Band(b) if is_exact_band(b, q.wavelength_nm) => {
            vec![model.at(q.wavelength_nm, Want::BOTH, Output::Mueller)?]
        }
        Over::Band(b) => {
            let g = narrow_band(q.wavelength_nm, b);
            if request.quadrature() {
                let range = band_range(q.wavelength_nm, b);
                vec![quadrature(
                    &q.stack,
                    &q.frame,
                    q.beta,
                    band_weight(g),
                    range,
                    step(range.0),
                    Want::BOTH,
                )
                .map_err(step_field)?]
            } else {
                vec![model.band(&[g], Want::BOTH, Output::Mueller, request.accuracy)?]
            }
        }
    };
    Ok(encode(
        channel_names(&request.over, q.wavelength_nm),
        &results,
        request.method,
        &warnings,
    ))
}

/// A quadrature step resolving the fringes of up to ~10 round trips through the whole stack at
/// the shortest wavelength `lambda_min`: `λ² / (20 · 2 n D · 10)` (`n` the largest index at the
/// query's wavelength, `D` the total thickness), at most 1 nm.
fn auto_step(q: &StackInput, lambda_min: f64) -> f64 {
    let n = q
        .stack
        .layers
        .iter()
        .filter_map(|l| l.material.indices(q.wavelength_nm, 0.0).ok())
        .map(|(o, e)| o.re.max(e.re))
        .fold(1.0, f64::max);
    let opd = 2.0 * n * q.stack.thickness_nm() * 10.0;
    (lambda_min * lambda_min / (20.0 * opd)).clamp(1e-5, 1.0)
}
