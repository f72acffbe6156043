//! The derivative requests of the bridge (`bridge::Tangents`): the inputs asked for, checked
//! once per call, and the output columns each lane's derivatives are written to
//! (`render::tangents` computes them).

use super::bridge::{Tangent, Tangents};
use super::columns::check_output;
use super::guard::guarded;
use super::materials::Materials;
use super::spectrum::PlateSpectrum;
use crate::error::{Error, Result};
use crate::render::tangents::{Columns, Input};

/// See `bridge::plate_tangents_available`.
pub fn plate_tangents_available(
    materials: &Materials,
    spectrum: &PlateSpectrum,
    inputs: &[Tangent],
) -> Result<()> {
    guarded(|| plate_inputs(materials, spectrum, inputs).map(|_| ()))
}

/// See `bridge::crystal_tangents_available`.
pub fn crystal_tangents_available(materials: &Materials, inputs: &[Tangent]) -> Result<()> {
    guarded(|| crystal_inputs(materials, inputs).map(|_| ()))
}

/// The inputs of a plate query's request, validated (see [`plate_tangents_available`]).
pub fn plate_inputs(
    materials: &Materials,
    spectrum: &PlateSpectrum,
    request: &[Tangent],
) -> Result<Vec<Input>> {
    spectrum.check_tangents()?;
    let inputs = known_inputs(request)?;
    check_indices(materials, &inputs)?;
    Ok(inputs)
}

/// The inputs of a crystal query's request, validated (see [`crystal_tangents_available`]).
pub fn crystal_inputs(materials: &Materials, request: &[Tangent]) -> Result<Vec<Input>> {
    let inputs = known_inputs(request)?;
    for &input in &inputs {
        let name = match input {
            Input::Thickness => "thickness",
            Input::Birefringence => "birefringence",
            Input::AxisAngle => "axis_angle",
            _ => continue,
        };
        return Err(Error::new(
            name,
            "is an input of a plate (thinbirefringent), not of a crystal surface",
        ));
    }
    check_indices(materials, &inputs)?;
    for &input in &inputs {
        if matches!(input, Input::KappaO | Input::KappaE)
            && !materials.all().all(|m| m.is_isotropic())
        {
            return Err(Error::new(
                name_of(input),
                "has no derivative for a birefringent crystal: it cannot absorb (an absorbing birefringent bulk is refused, see kappa_o), so kappa_o and kappa_e stay 0; keep them out of the optimisation",
            ));
        }
    }
    Ok(inputs)
}

/// The request's inputs, each known and given at most once.
fn known_inputs(request: &[Tangent]) -> Result<Vec<Input>> {
    let mut inputs = Vec::with_capacity(request.len());
    for t in request {
        let input = match *t {
            Tangent::Thickness => Input::Thickness,
            Tangent::Birefringence => Input::Birefringence,
            Tangent::AxisAngle => Input::AxisAngle,
            Tangent::EtaO => Input::EtaO,
            Tangent::EtaE => Input::EtaE,
            Tangent::KappaO => Input::KappaO,
            Tangent::KappaE => Input::KappaE,
            Tangent::OpticAxis => Input::OpticAxis,
            Tangent::Wi => Input::Wi,
            t => return Err(Error::new("tangents", format!("unknown input {}", t.repr))),
        };
        if inputs.contains(&input) {
            return Err(Error::new(
                "tangents",
                format!("{} asked for twice", name_of(input)),
            ));
        }
        inputs.push(input);
    }
    Ok(inputs)
}

/// `eta_o` and `eta_e` are inputs only of materials with constant indices (a named crystal's
/// dispersion fit is not a parameter).
fn check_indices(materials: &Materials, inputs: &[Input]) -> Result<()> {
    for &input in inputs {
        if matches!(input, Input::EtaO | Input::EtaE) && materials.all().any(|m| m.is_dispersive())
        {
            return Err(Error::new(
                name_of(input),
                "is a parameter only of constant indices (eta_o, eta_e), not of a named crystal's dispersion",
            ));
        }
    }
    Ok(())
}

/// The plugins' name of an input.
fn name_of(input: Input) -> &'static str {
    match input {
        Input::Thickness => "thickness",
        Input::Birefringence => "birefringence",
        Input::AxisAngle => "axis_angle",
        Input::EtaO => "eta_o",
        Input::EtaE => "eta_e",
        Input::KappaO => "kappa_o",
        Input::KappaE => "kappa_e",
        Input::OpticAxis => "optic_axis",
        Input::Wi => "wi",
    }
}

/// The derivative columns of a batch of `count` lanes and `channels` channels, validated.
pub struct TangentOutput<'t, 'a> {
    out: &'t mut Tangents<'a>,
    inputs: Vec<Input>,
    columns: usize,
    count: usize,
    channels: usize,
    full: bool,
}

impl<'t, 'a> TangentOutput<'t, 'a> {
    /// Checks every column's length; `full`: all 16 entries of the weight (else entry 0).
    pub fn new(
        out: &'t mut Tangents<'a>,
        inputs: Vec<Input>,
        count: usize,
        channels: usize,
        full: bool,
    ) -> Result<Self> {
        let columns: usize = inputs.iter().map(|i| i.columns()).sum();
        for c in &out.wo {
            check_output("tangents.wo", c, columns * count, false)?;
        }
        let per = columns * channels * count;
        check_output("tangents.value", out.value[0], per, false)?;
        for c in &out.value[1..] {
            check_output("tangents.value", c, if full { per } else { 0 }, !full)?;
        }
        Ok(TangentOutput {
            out,
            inputs,
            columns,
            count,
            channels,
            full,
        })
    }

    /// The inputs, in order.
    pub fn inputs(&self) -> &[Input] {
        &self.inputs
    }

    /// True if every derivative of `d` that is written is finite.
    pub fn is_finite(&self, d: &Columns) -> bool {
        let entries = if self.full { 16 } else { 1 };
        (0..self.columns).all(|k| {
            d.wo[k].iter().all(|x| x.is_finite())
                && d.value[k][..self.channels]
                    .iter()
                    .all(|v| v[..entries].iter().all(|x| x.is_finite()))
        })
    }

    /// Writes lane `i`'s derivative columns (zero for a lane that samples nothing).
    pub fn write(&mut self, i: usize, d: Option<&Columns>) {
        let (n, channels) = (self.count, self.channels);
        let entries = if self.full { 16 } else { 1 };
        for k in 0..self.columns {
            for (j, c) in self.out.wo.iter_mut().enumerate() {
                c[k * n + i] = d.map_or(0.0, |d| d.wo[k][j]);
            }
            for ch in 0..channels {
                let at = (k * channels + ch) * n + i;
                for (e, c) in self.out.value[..entries].iter_mut().enumerate() {
                    c[at] = d.map_or(0.0, |d| d.value[k][ch][e]);
                }
            }
        }
    }
}
