//! The program of a `thinbirefringent` plate's sample.

use super::layer::{recorded_layer, Param, Settings};
use super::{channel_count, core_transport, output, outputs, wanted, Program};
use crate::error::Result;
use crate::ffi::bridge::{PlateInput, PlateRecipe};
use crate::ffi::materials::Materials;
use crate::material::Material;
use crate::plate::Plate;
use crate::real::complex::Cx;
use crate::real::Real;
use crate::record::{self, Var};
use crate::render::plate::{sample_exact, ExactPlate};
use nalgebra::Vector3;

/// Records the sample of a `thinbirefringent` plate over `recipe.channels` exact wavelengths
/// (see `bridge::record_plate`).
pub fn record_plate(materials: &Materials, recipe: &PlateRecipe) -> Result<Box<Program>> {
    let material = *materials.get(recipe.material)?;
    let transport = core_transport(recipe.transport)?;
    let channels = channel_count(recipe.channels)?;
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
/// as inputs, the others as constants ([`recorded_layer`]).
fn recorded_plate(
    material: &Material,
    recipe: &PlateRecipe,
    input: &impl Fn(PlateInput) -> Var,
) -> Result<ExactPlate<Var>> {
    let settings = Settings {
        thickness_scale: recipe.thickness_scale,
        has_birefringence: recipe.has_birefringence,
        birefringence_scale: recipe.birefringence_scale,
        has_axis_angle: recipe.has_axis_angle,
        optic_axis: recipe.optic_axis,
        axis_is_input: recipe.axis_is_input,
        indices_are_inputs: recipe.indices_are_inputs,
        kappas_are_inputs: recipe.kappas_are_inputs,
    };
    let layer = recorded_layer(material, &settings, &|p| {
        input(match p {
            Param::Thickness => PlateInput::Thickness,
            Param::Birefringence => PlateInput::Birefringence,
            Param::AxisAngle => PlateInput::AxisAngle,
            Param::AxisX => PlateInput::AxisX,
            Param::AxisY => PlateInput::AxisY,
            Param::AxisZ => PlateInput::AxisZ,
            Param::EtaO => PlateInput::EtaO,
            Param::EtaE => PlateInput::EtaE,
            Param::KappaO => PlateInput::KappaO,
            Param::KappaE => PlateInput::KappaE,
        })
    })?;
    let real = |n: f64| Cx::new(Var::cst(n), Var::cst(0.0));
    Ok(ExactPlate {
        plate: Plate {
            material: layer.material,
            birefringence: layer.birefringence,
            ext: real(recipe.ext_ior),
            exit: real(recipe.exit_ior),
            axis: layer.axis,
            thickness_nm: layer.thickness_nm,
        },
        want: wanted(recipe.components),
        output: output(recipe.intensity_only),
        absorbing_exit: recipe.absorbing_exit,
    })
}
