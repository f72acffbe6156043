//! The program of a `thinbirefringent` plate's sample.

use super::{core_transport, outputs, Program};
use crate::error::{Error, Result};
use crate::ffi::bridge::{PlateInput, PlateRecipe};
use crate::ffi::materials::Materials;
use crate::material::{Index, Material};
use crate::optics::frame::rotated_about_normal;
use crate::params::{Length, Thickness};
use crate::plate::slab::{Output as Intensity, Want};
use crate::plate::Plate;
use crate::real::complex::Cx;
use crate::real::{Mask, Real};
use crate::record::{self, Var};
use crate::render::plate::{sample_exact, ExactPlate, MAX_BANDS};
use nalgebra::Vector3;

/// Records the sample of a `thinbirefringent` plate over `recipe.channels` exact wavelengths
/// (see `bridge::record_plate`).
pub fn record_plate(materials: &Materials, recipe: &PlateRecipe) -> Result<Box<Program>> {
    let material = *materials.get(recipe.material)?;
    let transport = core_transport(recipe.transport)?;
    let channels = recipe.channels as usize;
    if !(1..=MAX_BANDS).contains(&channels) {
        return Err(Error::new(
            "channels",
            format!("must be 1 to {MAX_BANDS}, got {channels}"),
        ));
    }
    let inputs = PlateInput::Wavelength0.repr as usize + channels;
    let p = record::record(inputs, |x| {
        let input = |k: PlateInput| x[k.repr as usize];
        let q = recorded_plate(&material, recipe, &input)?;
        let wi = Vector3::new(
            input(PlateInput::WiX),
            input(PlateInput::WiY),
            input(PlateInput::WiZ),
        );
        let u = input(PlateInput::Sample);
        let first = PlateInput::Wavelength0.repr as usize;
        let lambda = |c: usize| x[first + c.min(channels - 1)];
        let s = |components| match channels {
            1 => outputs(&sample_exact(
                &q,
                &[lambda(0)],
                wi,
                u,
                transport,
                components,
            )?),
            2 => outputs(&sample_exact(
                &q,
                &[lambda(0), lambda(1)],
                wi,
                u,
                transport,
                components,
            )?),
            3 => outputs(&sample_exact(
                &q,
                &std::array::from_fn::<_, 3, _>(lambda),
                wi,
                u,
                transport,
                components,
            )?),
            _ => outputs(&sample_exact(
                &q,
                &std::array::from_fn::<_, 4, _>(lambda),
                wi,
                u,
                transport,
                components,
            )?),
        };
        s(recipe.components)
    })?;
    Ok(Box::new(Program::new(p)))
}

/// The plate of `recipe` with its per-lane values and the parameters that carry derivatives
/// as inputs, the others as constants.
fn recorded_plate(
    material: &Material,
    recipe: &PlateRecipe,
    input: &impl Fn(PlateInput) -> Var,
) -> Result<ExactPlate<Var>> {
    let given = |k: PlateInput, value: f64, is_input: bool| {
        if is_input {
            input(k)
        } else {
            Var::cst(value)
        }
    };
    let lift = |index: &Index, (re, im): (PlateInput, PlateInput)| match *index {
        Index::Constant(n) => Index::Constant(Cx::new(
            given(re, n.re, recipe.indices_are_inputs),
            given(im, n.im, recipe.kappas_are_inputs),
        )),
        Index::Crystal {
            crystal,
            extraordinary,
            kappa,
        } => Index::Crystal {
            crystal,
            extraordinary,
            kappa: given(im, kappa, recipe.kappas_are_inputs),
        },
    };
    let material = Material {
        eta_o: lift(&material.eta_o, (PlateInput::EtaO, PlateInput::KappaO)),
        eta_e: lift(&material.eta_e, (PlateInput::EtaE, PlateInput::KappaE)),
    };
    let a = recipe.optic_axis;
    let axis = Vector3::new(
        given(PlateInput::AxisX, a[0], recipe.axis_is_input),
        given(PlateInput::AxisY, a[1], recipe.axis_is_input),
        given(PlateInput::AxisZ, a[2], recipe.axis_is_input),
    );
    let angle = given(PlateInput::AxisAngle, 0.0, recipe.has_axis_angle);
    (!angle.finite()).fail(|| Error::new("axis_angle", "must be a finite number (degrees)"))?;
    let thickness = input(PlateInput::Thickness) * (1000.0 * recipe.thickness_scale);
    let birefringence = given(PlateInput::Birefringence, 0.0, recipe.has_birefringence)
        * recipe.birefringence_scale;
    (!birefringence.finite()).fail(|| Error::new("birefringence", "must be finite"))?;
    let real = |n: f64| Cx::new(Var::cst(n), Var::cst(0.0));
    Ok(ExactPlate {
        plate: Plate {
            material,
            birefringence,
            ext: real(recipe.ext_ior),
            exit: real(recipe.exit_ior),
            axis: rotated_about_normal(axis, angle),
            thickness_nm: Thickness::checked("thickness", thickness, Length::Micrometres)?,
        },
        want: Want {
            reflection: recipe.components & 1 != 0,
            transmission: recipe.components & 2 != 0,
        },
        output: if recipe.intensity_only {
            Intensity::Intensity
        } else {
            Intensity::Mueller
        },
        absorbing_exit: recipe.absorbing_exit,
    })
}
