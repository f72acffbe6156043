//! A plate's parameters, or one layer's of a stack, as a program records them: the texture
//! values (thickness; birefringence and axis angle where the plate has them) as inputs, the optic axis and the
//! material's indices and extinctions as inputs where the recipe says so (the parameters
//! derivatives are taken with respect to), the others as constants.

use crate::error::{Error, Result};
use crate::material::{Index, Material};
use crate::optics::frame::rotated_about_normal;
use crate::params::{Length, Thickness};
use crate::real::complex::Cx;
use crate::real::{Mask, Real};
use crate::record::Var;
use crate::stack::Layer;
use nalgebra::Vector3;

/// A per-lane value of a plate or layer, whatever the program's input numbering.
#[derive(Clone, Copy, Debug)]
pub(super) enum Param {
    /// The thickness texture's value (um, before `thickness_scale`).
    Thickness,
    /// The birefringence texture's value (before `birefringence_scale`).
    Birefringence,
    /// The axis angle texture's value (degrees).
    AxisAngle,
    /// The optic axis, x.
    AxisX,
    /// The optic axis, y.
    AxisY,
    /// The optic axis, z.
    AxisZ,
    /// `Re η_o` of constant indices.
    EtaO,
    /// `Re η_e` of constant indices.
    EtaE,
    /// `κ_o`.
    KappaO,
    /// `κ_e`.
    KappaE,
}

/// How a plate's or layer's parameters are recorded: the plugin's scales and optic axis, and
/// which values are inputs.
#[derive(Clone, Copy, Debug)]
pub(super) struct Settings {
    pub thickness_scale: f64,
    /// A birefringence texture (else its input is not read: 0).
    pub has_birefringence: bool,
    pub birefringence_scale: f64,
    /// An axis angle texture (else its input is not read: 0).
    pub has_axis_angle: bool,
    pub optic_axis: [f64; 3],
    pub axis_is_input: bool,
    pub indices_are_inputs: bool,
    pub kappas_are_inputs: bool,
}

/// The layer of `material` under `settings`, its per-lane values read by `input`: lanes whose
/// axis angle or birefringence is not finite, or whose thickness lies outside [0, 1 m], fail.
pub(super) fn recorded_layer(
    material: &Material,
    settings: &Settings,
    input: &impl Fn(Param) -> Var,
) -> Result<Layer<Var>> {
    let given = |k: Param, value: f64, is_input: bool| {
        if is_input {
            input(k)
        } else {
            Var::cst(value)
        }
    };
    let lift = |index: &Index, (re, im): (Param, Param)| match *index {
        Index::Constant(n) => Index::Constant(Cx::new(
            given(re, n.re, settings.indices_are_inputs),
            given(im, n.im, settings.kappas_are_inputs),
        )),
        Index::Crystal {
            crystal,
            extraordinary,
            kappa,
        } => Index::Crystal {
            crystal,
            extraordinary,
            kappa: given(im, kappa, settings.kappas_are_inputs),
        },
    };
    let material = Material {
        eta_o: lift(&material.eta_o, (Param::EtaO, Param::KappaO)),
        eta_e: lift(&material.eta_e, (Param::EtaE, Param::KappaE)),
    };
    let a = settings.optic_axis;
    let axis = Vector3::new(
        given(Param::AxisX, a[0], settings.axis_is_input),
        given(Param::AxisY, a[1], settings.axis_is_input),
        given(Param::AxisZ, a[2], settings.axis_is_input),
    );
    let angle = given(Param::AxisAngle, 0.0, settings.has_axis_angle);
    (!angle.finite()).fail(|| Error::new("axis_angle", "must be a finite number (degrees)"))?;
    let thickness = input(Param::Thickness) * (1000.0 * settings.thickness_scale);
    let birefringence =
        given(Param::Birefringence, 0.0, settings.has_birefringence) * settings.birefringence_scale;
    (!birefringence.finite()).fail(|| Error::new("birefringence", "must be finite"))?;
    Ok(Layer {
        material,
        birefringence,
        axis: rotated_about_normal(axis, angle),
        thickness_nm: Thickness::checked("thickness", thickness, Length::Micrometres)?,
    })
}
