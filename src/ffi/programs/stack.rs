//! The program of a `birefringentstack`'s sample: per layer the inputs of a plate
//! ([`super::layer`]), and the path's.

use super::layer::{recorded_layer, Param, Settings};
use super::{channel_count, core_transport, output, outputs, wanted, Program};
use crate::error::{Error, Result};
use crate::ffi::bridge::{StackInput, StackLayerInput, StackLayerRecipe, StackRecipe};
use crate::ffi::materials::Materials;
use crate::material::check_clear_index;
use crate::real::complex::Cx;
use crate::real::{Mask, Real};
use crate::record::{self, Flag, Output, Var};
use crate::render::stack::{sample_exact_stack, ExactStack};
use crate::render::Transport;
use crate::stack::{in_layer, Stack};
use crate::C64;
use nalgebra::Vector3;

/// Records the sample of a `birefringentstack` over `recipe.channels` exact wavelengths (see
/// `bridge::record_stack`). A layer's invalid parameter is reported under its name,
/// `layers[k].material`.
pub fn record_stack(materials: &Materials, recipe: &StackRecipe) -> Result<Box<Program>> {
    let transport = core_transport(recipe.transport)?;
    let channels = channel_count(recipe.channels)?;
    if recipe.layers.is_empty() {
        return Err(Error::new("layers", "a stack needs at least one layer"));
    }
    let ext = check_clear_index("ext_ior", C64::new(recipe.ext_ior, 0.0))?.re;
    let exit = check_clear_index("exit_ior", C64::new(recipe.exit_ior, 0.0))?.re;
    let layer_materials = recipe
        .layers
        .iter()
        .enumerate()
        .map(|(k, l)| materials.get(l.material).map_err(|e| in_layer(k, e)))
        .collect::<Result<Vec<_>>>()?;
    let (first, stride) = (
        StackInput::Layer0.repr as usize,
        StackLayerInput::Stride.repr as usize,
    );
    let p = record::record(first + stride * recipe.layers.len(), |x| {
        let layers = recipe
            .layers
            .iter()
            .zip(&layer_materials)
            .enumerate()
            .map(|(k, (l, material))| {
                let block = &x[first + k * stride..first + (k + 1) * stride];
                recorded_layer(material, &settings(l), &|p| block[layer_input(p)])
                    .map_err(|e| in_layer(k, e))
            })
            .collect::<Result<Vec<_>>>()?;
        let real = |n: f64| Cx::new(Var::cst(n), Var::cst(0.0));
        let q = ExactStack {
            stack: Stack {
                layers,
                ext: real(ext),
                exit: real(exit),
            },
            below: Flag::cst(false),
            want: wanted(recipe.components),
            output: output(recipe.intensity_only),
            absorbing_exit: recipe.absorbing_exit,
        };
        let path = |k: StackInput| x[k.repr as usize];
        let path = Path {
            wi: Vector3::new(
                path(StackInput::WiX),
                path(StackInput::WiY),
                path(StackInput::WiZ),
            ),
            u: path(StackInput::Sample),
            wavelengths: &x[StackInput::Wavelength0.repr as usize..][..channels],
            transport,
            components: recipe.components,
        };
        match channels {
            1 => path.sample::<1>(&q),
            2 => path.sample::<2>(&q),
            3 => path.sample::<3>(&q),
            _ => path.sample::<4>(&q),
        }
    })?;
    Ok(Box::new(Program::new(p)))
}

/// A layer's recipe as the plate's settings.
fn settings(l: &StackLayerRecipe) -> Settings {
    Settings {
        thickness_scale: l.thickness_scale,
        has_birefringence: l.has_birefringence,
        birefringence_scale: l.birefringence_scale,
        has_axis_angle: l.has_axis_angle,
        optic_axis: l.optic_axis,
        axis_is_input: l.axis_is_input,
        indices_are_inputs: l.indices_are_inputs,
        kappas_are_inputs: l.kappas_are_inputs,
    }
}

/// Where a layer's parameter lies in its block of inputs.
fn layer_input(p: Param) -> usize {
    let i = match p {
        Param::Thickness => StackLayerInput::Thickness,
        Param::Birefringence => StackLayerInput::Birefringence,
        Param::AxisAngle => StackLayerInput::AxisAngle,
        Param::AxisX => StackLayerInput::AxisX,
        Param::AxisY => StackLayerInput::AxisY,
        Param::AxisZ => StackLayerInput::AxisZ,
        Param::EtaO => StackLayerInput::EtaO,
        Param::EtaE => StackLayerInput::EtaE,
        Param::KappaO => StackLayerInput::KappaO,
        Param::KappaE => StackLayerInput::KappaE,
    };
    i.repr as usize
}

/// The path's recorded values.
struct Path<'a> {
    wi: Vector3<Var>,
    u: Var,
    wavelengths: &'a [Var],
    transport: Transport,
    components: u32,
}

impl Path<'_> {
    /// The sample of `q` over the path's first `C` wavelengths, as the program's outputs.
    fn sample<const C: usize>(&self, q: &ExactStack<Var>) -> Result<Vec<Output>> {
        let w: [Var; C] = std::array::from_fn(|c| self.wavelengths[c]);
        let s = sample_exact_stack(q, &w, self.wi, self.u, self.transport, self.components)?;
        outputs(&s)
    }
}
