//! The stack's recorded program (`ffi::record_stack`, what the shim replays in Mitsuba's JIT
//! variants) against the host: run in `f64` on random lanes it equals the generic sample run
//! on `f64` directly (`render::stack::sample_exact_stack`), and that equals the scalar query of
//! the bridge over an exact spectrum (`stack_lobes`: the stack's model of `stack::spectral` at
//! each wavelength, then `choose`), over one to six layers of named and constant, isotropic,
//! absorbing and dichroic materials, 0 to 1000 um each, random axes, both sides, both transport
//! modes, every set of components, one to four wavelengths and incidence to 89.5 degrees. One
//! layer's program equals the plate's (`ffi::record_plate`) on the same lanes.
//!
//! Tolerances. The recording folds constants and shares equal instructions but otherwise runs
//! the same `f64` operations; where an index is an input the program cannot know that a layer
//! is isotropic and takes the uniaxial modes, other arithmetic for the same layer. So program
//! and direct run agree to rounding of the phases `k d q`: a few ulps of the largest phase
//! (about `2π n d / λ` summed over the layers), 1e-13 times (1 + 10 D / λ) relative with `D`
//! the stack's thickness. The bridge's scalar query reaches the same stack by other
//! arithmetic (axes normalised twice, the wavelength through its wavenumber), so the generic
//! sample agrees with it to rounding of a multiple-reflection sum: 1e-9 absolute on power
//! fractions of at most 1. The plate's program sums one layer's paths by the slab's closed
//! form instead of the recursion, with the exterior's modes taken as uniaxial where its index
//! is not known to be the exit's: the same tolerance as program against direct run.

use birefringent::ffi::bridge::{
    PlateInput, PlateRecipe, StackInput, StackLayerInput, StackLayerRecipe, StackRecipe,
    Transport as T,
};
use birefringent::ffi::{new_materials, record_plate, record_stack, Materials};
use birefringent::optics::frame::rotated_about_normal;
use birefringent::params::{Length, Thickness};
use birefringent::render::stack::{stack_lobes, ExactStack, StackQuery};
use birefringent::render::Transport;
use birefringent::stack::{Layer, Stack};
use birefringent::C64;
use nalgebra::Vector3;

mod common;
use common::samples::{assert_program_outputs, assert_scalar_route, direct, exact_bands, Path};
use common::Rng;

/// One random layer, in the plugin's units.
#[derive(Clone, Debug)]
struct LaneLayer {
    material: u32,
    eta: (f64, f64, f64, f64),
    axis: Vector3<f64>,
    angle_deg: f64,
    thickness_um: f64,
    thickness_scale: f64,
    birefringence: f64,
    birefringence_scale: f64,
    inputs: (bool, bool, bool),
}

/// One random lane of a stack query.
#[derive(Clone, Debug)]
struct Lane {
    layers: Vec<LaneLayer>,
    ext: f64,
    exit: f64,
    wi: Vector3<f64>,
    u: f64,
    wavelengths: Vec<f64>,
    transport: Transport,
    components: u32,
    absorbing_exit: bool,
    intensity_only: bool,
}

fn random_layer(rng: &mut Rng, materials: &mut Materials, scales: bool) -> LaneLayer {
    let named = ["quartz", "calcite", "rutile", "sapphire", "mgf2", "linbo3"];
    let (kappa_o, kappa_e) = match rng.index(4) {
        0 => (rng.range(0.0, 0.05), rng.range(0.0, 0.05)),
        1 => (0.0, rng.range(0.0, 0.02)),
        _ => (0.0, 0.0),
    };
    let (eta_o, eta_e) = match rng.index(3) {
        0 => {
            let n = rng.range(1.3, 2.0);
            (n, n)
        }
        _ => (rng.range(1.3, 2.6), rng.range(1.3, 2.6)),
    };
    let material = if rng.chance(0.4) {
        materials
            .add_named(named[rng.index(named.len())], kappa_o, kappa_e)
            .unwrap()
    } else {
        materials
            .add_constant(eta_o, eta_e, kappa_o, kappa_e)
            .unwrap()
    };
    let scale = |rng: &mut Rng| {
        if scales || rng.chance(0.3) {
            rng.range(0.5, 2.0)
        } else {
            1.0
        }
    };
    LaneLayer {
        material,
        eta: (eta_o, eta_e, kappa_o, kappa_e),
        axis: rng.unit_vector() * rng.range(0.5, 2.0),
        angle_deg: if rng.chance(0.5) {
            rng.range(-180.0, 180.0)
        } else {
            0.0
        },
        thickness_um: match rng.index(5) {
            0 => 0.0,
            1 => rng.range(0.0, 0.05),
            _ => 10f64.powf(rng.range(-1.0, 3.0)),
        },
        thickness_scale: scale(rng),
        birefringence: if scales || rng.chance(0.3) {
            rng.range(-0.01, 0.01)
        } else {
            0.0
        },
        birefringence_scale: scale(rng),
        inputs: (rng.chance(0.5), rng.chance(0.5), rng.chance(0.5)),
    }
}

/// A lane of `layers` layers (each drawn by [`random_layer`]).
fn random_lane(rng: &mut Rng, materials: &mut Materials, layers: usize, scales: bool) -> Lane {
    let layers = (0..layers)
        .map(|_| random_layer(rng, materials, scales))
        .collect();
    let theta = if rng.chance(0.1) {
        rng.range(85.0, 89.5)
    } else {
        rng.range(0.0, 85.0)
    }
    .to_radians();
    let phi = rng.range(0.0, std::f64::consts::TAU);
    let side = if rng.chance(0.5) { 1.0 } else { -1.0 };
    let ext = rng.range(1.0, 1.6);
    let channels = if rng.chance(0.5) { 4 } else { 1 + rng.index(3) };
    Lane {
        layers,
        ext,
        exit: if rng.chance(0.5) {
            ext
        } else {
            rng.range(1.0, 1.8)
        },
        wi: Vector3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            side * theta.cos(),
        ),
        u: rng.uniform(),
        wavelengths: (0..channels).map(|_| rng.range(360.0, 830.0)).collect(),
        transport: if rng.chance(0.5) {
            Transport::Radiance
        } else {
            Transport::Importance
        },
        components: [1, 2, 3, 3][rng.index(4)],
        absorbing_exit: rng.chance(0.15),
        intensity_only: rng.chance(0.25),
    }
}

fn transport(t: Transport) -> T {
    match t {
        Transport::Radiance => T::Radiance,
        Transport::Importance => T::Importance,
    }
}

impl LaneLayer {
    /// Thickness (nm) as the shim gives it.
    fn nm(&self) -> f64 {
        1000.0 * self.thickness_scale * self.thickness_um
    }

    fn recipe(&self) -> StackLayerRecipe {
        StackLayerRecipe {
            material: self.material,
            thickness_scale: self.thickness_scale,
            has_birefringence: self.birefringence != 0.0,
            birefringence_scale: self.birefringence_scale,
            has_axis_angle: self.angle_deg != 0.0,
            optic_axis: self.axis.into(),
            axis_is_input: self.inputs.0,
            indices_are_inputs: self.inputs.1,
            kappas_are_inputs: self.inputs.2,
        }
    }

    /// The layer's values in `PlateInput`-like order (`StackLayerInput`).
    fn values(&self) -> [(StackLayerInput, PlateInput, f64); 10] {
        use PlateInput as P;
        use StackLayerInput as S;
        [
            (S::Thickness, P::Thickness, self.thickness_um),
            (S::Birefringence, P::Birefringence, self.birefringence),
            (S::AxisAngle, P::AxisAngle, self.angle_deg),
            (S::AxisX, P::AxisX, self.axis.x),
            (S::AxisY, P::AxisY, self.axis.y),
            (S::AxisZ, P::AxisZ, self.axis.z),
            (S::EtaO, P::EtaO, self.eta.0),
            (S::EtaE, P::EtaE, self.eta.1),
            (S::KappaO, P::KappaO, self.eta.2),
            (S::KappaE, P::KappaE, self.eta.3),
        ]
    }

    /// The validated layer, as the bridge builds it.
    fn layer(&self, materials: &Materials) -> Layer {
        let axis = if self.angle_deg == 0.0 {
            self.axis
        } else {
            rotated_about_normal(self.axis, self.angle_deg)
        };
        Layer::new(
            *materials.get(self.material).unwrap(),
            self.birefringence_scale * self.birefringence,
            axis,
            Thickness::new("thickness", self.nm(), Length::Micrometres).unwrap(),
        )
        .unwrap()
    }
}

impl Lane {
    fn recipe(&self) -> StackRecipe {
        StackRecipe {
            transport: transport(self.transport),
            components: self.components,
            channels: self.wavelengths.len() as u32,
            intensity_only: self.intensity_only,
            absorbing_exit: self.absorbing_exit,
            ext_ior: self.ext,
            exit_ior: self.exit,
            layers: self.layers.iter().map(LaneLayer::recipe).collect(),
        }
    }

    /// The stack program's inputs.
    fn inputs(&self) -> Vec<f64> {
        let first = StackInput::Layer0.repr as usize;
        let stride = StackLayerInput::Stride.repr as usize;
        let mut x = vec![f64::NAN; first + stride * self.layers.len()];
        x[StackInput::WiX.repr as usize] = self.wi.x;
        x[StackInput::WiY.repr as usize] = self.wi.y;
        x[StackInput::WiZ.repr as usize] = self.wi.z;
        x[StackInput::Sample.repr as usize] = self.u;
        for (c, &w) in self.wavelengths.iter().enumerate() {
            x[StackInput::Wavelength0.repr as usize + c] = w;
        }
        for (k, l) in self.layers.iter().enumerate() {
            for (i, _, v) in l.values() {
                x[first + k * stride + i.repr as usize] = v;
            }
        }
        x
    }

    /// The plate's recipe and inputs of a one-layer lane.
    fn plate(&self) -> (PlateRecipe, Vec<f64>) {
        let l = &self.layers[0];
        let recipe = PlateRecipe {
            material: l.material,
            transport: transport(self.transport),
            components: self.components,
            channels: self.wavelengths.len() as u32,
            intensity_only: self.intensity_only,
            absorbing_exit: self.absorbing_exit,
            ext_ior: self.ext,
            exit_ior: self.exit,
            thickness_scale: l.thickness_scale,
            has_birefringence: l.birefringence != 0.0,
            birefringence_scale: l.birefringence_scale,
            has_axis_angle: l.angle_deg != 0.0,
            optic_axis: l.axis.into(),
            axis_is_input: l.inputs.0,
            indices_are_inputs: l.inputs.1,
            kappas_are_inputs: l.inputs.2,
        };
        let mut x = vec![f64::NAN; PlateInput::Wavelength0.repr as usize];
        x[PlateInput::WiX.repr as usize] = self.wi.x;
        x[PlateInput::WiY.repr as usize] = self.wi.y;
        x[PlateInput::WiZ.repr as usize] = self.wi.z;
        x[PlateInput::Sample.repr as usize] = self.u;
        for (_, p, v) in l.values() {
            x[p.repr as usize] = v;
        }
        x.extend(&self.wavelengths);
        (recipe, x)
    }

    /// The validated query of the lane, as the bridge builds it.
    fn query(&self, materials: &Materials) -> StackQuery {
        let stack = Stack::new(
            self.layers.iter().map(|l| l.layer(materials)).collect(),
            C64::new(self.ext, 0.0),
            C64::new(self.exit, 0.0),
        )
        .unwrap();
        StackQuery::new(
            stack,
            self.components & 1 != 0,
            self.components & 2 != 0,
            self.intensity_only,
        )
        .with_absorbing_exit(self.absorbing_exit)
    }

    /// The stack's thickness (nm).
    fn thickness_nm(&self) -> f64 {
        self.layers.iter().map(LaneLayer::nm).sum()
    }

    /// The program's tolerance (module docs).
    fn tolerance(&self) -> f64 {
        let shortest = self
            .wavelengths
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        1e-13 * (1.0 + 10.0 * self.thickness_nm() / shortest)
    }

    /// The path of the lane.
    fn path(&self) -> Path<'_> {
        Path {
            wi: self.wi,
            u: self.u,
            wavelengths: &self.wavelengths,
            transport: self.transport,
            components: self.components,
        }
    }

    /// The generic sample (`render::plate::sample_exact`, as `sample_exact_stack` calls it) run
    /// on `f64`, as the program's outputs (without the failure mask).
    fn direct(&self, materials: &Materials) -> Vec<f64> {
        direct(&ExactStack::of(&self.query(materials)), &self.path())
    }
}

#[test]
fn the_recorded_program_equals_the_host_sample() {
    let mut rng = Rng::new(2029);
    let mut materials = new_materials();
    let (mut lanes, mut valid, mut below) = (0, 0, 0);
    for _ in 0..1500 {
        let layers = 1 + rng.index(6);
        let lane = random_lane(&mut rng, &mut materials, layers, false);
        let program = record_stack(&materials, &lane.recipe()).unwrap();
        let got = program.recorded().run(&lane.inputs());
        let want = lane.direct(&materials);
        assert_program_outputs(&got, &want, lane.wavelengths.len(), lane.tolerance(), &lane);
        lanes += 1;
        valid += usize::from(got[0] != 0.0);
        below += usize::from(got[0] != 0.0 && lane.wi.z < 0.0);
    }
    assert!(valid > lanes / 2, "{valid} of {lanes} lanes sample a lobe");
    assert!(
        below > lanes / 5,
        "{below} of {lanes} lanes sample from below"
    );
}

/// The generic sample on `f64` against the scalar route of the bridge's exact spectrum:
/// `stack_lobes` (the stack's spectral model at each wavelength) and `choose`, gathered as the
/// bridge writes a lane.
#[test]
fn the_generic_sample_equals_the_scalar_route() {
    let mut rng = Rng::new(32);
    let mut materials = new_materials();
    let mut compared = 0;
    for _ in 0..1500 {
        let layers = 1 + rng.index(6);
        let lane = random_lane(&mut rng, &mut materials, layers, false);
        let q = lane.query(&materials);
        let spectrum = exact_bands(&lane.wavelengths);
        let lobes = stack_lobes(&q, &spectrum, lane.wi, lane.transport).unwrap();
        let got = lane.direct(&materials);
        compared += usize::from(assert_scalar_route(&got, &lobes, &lane.path(), &lane));
    }
    assert!(compared > 700, "{compared} lanes compared");
}

/// A stack of one layer is the plate: the two programs agree on the same lanes, the layer's
/// `thickness_scale` and `birefringence_scale` other than 1.
#[test]
fn one_layer_is_the_plate() {
    let mut rng = Rng::new(33);
    let mut materials = new_materials();
    let mut valid = 0;
    for _ in 0..1500 {
        let lane = random_lane(&mut rng, &mut materials, 1, true);
        let stack = record_stack(&materials, &lane.recipe()).unwrap();
        let (recipe, inputs) = lane.plate();
        let plate = record_plate(&materials, &recipe).unwrap();
        let got = stack.recorded().run(&lane.inputs());
        let want = plate.recorded().run(&inputs);
        assert_eq!(want.last(), Some(&0.0), "the plate's lane failed\n{lane:?}");
        assert_program_outputs(&got, &want, lane.wavelengths.len(), lane.tolerance(), &lane);
        valid += usize::from(got[0] != 0.0);
    }
    assert!(valid > 750, "{valid} lanes sample a lobe");
}
