//! The program of a `birefringent` crystal surface's sample.

use super::{channel_count, core_transport, output, outputs, Program};
use crate::error::{Error, Result};
use crate::ffi::bridge::{CrystalInput, CrystalRecipe};
use crate::ffi::materials::Materials;
use crate::material::check_clear_index;
use crate::optics::medium::Uniaxial;
use crate::real::{Mask, Real};
use crate::record::{self, Output, Var};
use crate::render::crystal::{sample_exact, ExactCrystal};
use crate::render::Transport;
use crate::C64;
use nalgebra::Vector3;

/// Records the sample of a `birefringent` crystal surface over `recipe.channels` exact
/// wavelengths (see `bridge::record_crystal`).
pub fn record_crystal(materials: &Materials, recipe: &CrystalRecipe) -> Result<Box<Program>> {
    let material = *materials.get(recipe.material)?;
    let transport = core_transport(recipe.transport)?;
    let channels = channel_count(recipe.channels)?;
    let ext = check_clear_index("ext_ior", C64::new(recipe.ext_ior, 0.0))?.re;
    if recipe.kappas_are_inputs && !material.is_isotropic() {
        return Err(Error::new(
            "kappa_o",
            "has no derivative for a birefringent crystal: it cannot absorb (an absorbing birefringent bulk is refused, see kappa_o), so kappa_o and kappa_e stay 0; keep kappa_o and kappa_e out of the optimisation",
        ));
    }
    if !recipe.axis_is_input {
        let one = C64::new(1.0, 0.0);
        Uniaxial::new(one, one, recipe.optic_axis.into())?;
    }
    let inputs = CrystalInput::Wavelength0.repr as usize + channels;
    let p = record::record(inputs, |x| {
        let input = |k: CrystalInput| x[k.repr as usize];
        let given = |k: CrystalInput, value: f64, is_input: bool| {
            if is_input {
                input(k)
            } else {
                Var::cst(value)
            }
        };
        // The ordinary or the extraordinary input of a pair. An isotropic crystal stays
        // isotropic: both indices are the pair's mean (moving one alone would split its
        // refraction into o and e rays), so each carries half the derivative along the pair.
        let isotropic = material.is_isotropic();
        let pair = |extraordinary: bool, (o, e): (CrystalInput, CrystalInput), value, is_input| {
            if isotropic && is_input {
                (input(o) + input(e)) * Var::cst(0.5)
            } else {
                given(if extraordinary { e } else { o }, value, is_input)
            }
        };
        let indices = (CrystalInput::EtaO, CrystalInput::EtaE);
        let kappas = (CrystalInput::KappaO, CrystalInput::KappaE);
        let material = material.lifted(
            |e, n| pair(e, indices, n, recipe.indices_are_inputs),
            |e, kappa| pair(e, kappas, kappa, recipe.kappas_are_inputs),
        );
        let a = recipe.optic_axis;
        let axis = Vector3::new(
            given(CrystalInput::AxisX, a[0], recipe.axis_is_input),
            given(CrystalInput::AxisY, a[1], recipe.axis_is_input),
            given(CrystalInput::AxisZ, a[2], recipe.axis_is_input),
        );
        let norm = axis.dot(&axis).sqrt();
        let invalid = !norm.finite() | norm.le(Var::cst(1e-300));
        invalid.fail(|| Error::new("optic_axis", "must be a finite non-zero vector"))?;
        // The failing lanes compute with the normal instead (finite numbers).
        let (zero, one) = (Var::cst(0.0), Var::cst(1.0));
        let q = ExactCrystal {
            material,
            ext: Var::cst(ext),
            axis: invalid.when(|| Vector3::new(zero, zero, one), || axis),
            output: output(recipe.intensity_only),
        };
        let wi = Vector3::new(
            input(CrystalInput::WiX),
            input(CrystalInput::WiY),
            input(CrystalInput::WiZ),
        );
        let first = CrystalInput::Wavelength0.repr as usize;
        let lambda = |c: usize| x[first + c.min(channels - 1)];
        let sample = Sample {
            q: &q,
            wi,
            u: input(CrystalInput::Sample),
            transport,
            components: recipe.components,
        };
        match channels {
            1 => sample.over::<1>(lambda),
            2 => sample.over::<2>(lambda),
            3 => sample.over::<3>(lambda),
            _ => sample.over::<4>(lambda),
        }
    })?;
    Ok(Box::new(Program::new(p)))
}

/// A recorded sample's query, but for its wavelengths.
struct Sample<'a> {
    q: &'a ExactCrystal<Var>,
    wi: Vector3<Var>,
    u: Var,
    transport: Transport,
    components: u32,
}

impl Sample<'_> {
    /// The outputs of the sample over `C` wavelengths, `lambda(c)` each.
    fn over<const C: usize>(&self, lambda: impl Fn(usize) -> Var) -> Result<Vec<Output>> {
        let wavelengths: [Var; C] = std::array::from_fn(lambda);
        let s = sample_exact(
            self.q,
            &wavelengths,
            self.wi,
            self.u,
            self.transport,
            self.components,
        )?;
        outputs(&s)
    }
}
