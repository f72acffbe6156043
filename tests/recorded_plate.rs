//! The plate's recorded program (`ffi::record_plate`, what the shim replays in Mitsuba's JIT
//! variants) against the host: run in `f64` on random lanes it equals the generic sample run
//! on `f64` directly (`render::plate::sample_exact`), and that equals the scalar query of the
//! bridge (`ffi::sample_plate` over an exact spectrum: `plate_lobes`, the plate's models of
//! `spectral::model`, then the choice), over named and constant, isotropic, absorbing and
//! dichroic materials, both sides, both transport modes, every set of components, one to four
//! wavelengths, thicknesses from 0 to 1 mm and incidence to 89.5 degrees.
//!
//! Tolerance: the recording folds constants and shares equal instructions, but otherwise runs
//! the same `f64` operations; where an index is an input the program cannot know that the
//! layer is isotropic and takes the uniaxial modes, other arithmetic for the same plate. So
//! program and direct run agree to rounding of the phases `k d q`: a few ulps of the largest
//! phase (about `2π n d / λ`), 1e-13 times (1 + 10 d / λ) relative;
//! the bridge's scalar query reaches the same plate by other arithmetic (the isotropic etalon,
//! interfaces solved once per plate), so the generic sample agrees with it to rounding of a
//! multiple-reflection sum (1e-9 absolute on power fractions of at most 1).

use birefringent::ffi::bridge::{PlateInput, PlateRecipe, Transport as T};
use birefringent::ffi::{new_materials, record_plate, Materials};
use birefringent::material::Material;
use birefringent::params::{Length, Thickness};
use birefringent::render::plate::{plate_lobes, ExactPlate, PlateQuery};
use birefringent::render::Transport;
use birefringent::C64;
use nalgebra::Vector3;

mod common;
use common::samples::{assert_program_outputs, assert_scalar_route, direct, exact_bands, Path};
use common::Rng;

/// One random lane of a plate query, in the plugin's units.
#[derive(Clone, Debug)]
struct Lane {
    material: u32,
    eta: (f64, f64, f64, f64),
    axis: Vector3<f64>,
    angle_deg: f64,
    thickness_um: f64,
    thickness_scale: f64,
    birefringence: f64,
    ext: f64,
    exit: f64,
    wi: Vector3<f64>,
    u: f64,
    wavelengths: Vec<f64>,
    transport: Transport,
    components: u32,
    absorbing_exit: bool,
    intensity_only: bool,
    inputs: (bool, bool, bool),
}

fn random_lane(rng: &mut Rng, materials: &mut Materials) -> Lane {
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
    let material = if rng.chance(0.5) {
        materials
            .add_named(named[rng.index(named.len())], kappa_o, kappa_e)
            .unwrap()
    } else {
        materials
            .add_constant(eta_o, eta_e, kappa_o, kappa_e)
            .unwrap()
    };
    let theta = if rng.chance(0.1) {
        rng.range(85.0, 89.5)
    } else {
        rng.range(0.0, 85.0)
    }
    .to_radians();
    let phi = rng.range(0.0, std::f64::consts::TAU);
    let side = if rng.chance(0.5) { 1.0 } else { -1.0 };
    let wi = Vector3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        side * theta.cos(),
    );
    let ext = rng.range(1.0, 1.6);
    let channels = if rng.chance(0.5) { 4 } else { 1 + rng.index(3) };
    Lane {
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
        thickness_scale: if rng.chance(0.3) {
            rng.range(0.5, 2.0)
        } else {
            1.0
        },
        birefringence: if rng.chance(0.3) {
            rng.range(-0.01, 0.01)
        } else {
            0.0
        },
        ext,
        exit: if rng.chance(0.5) {
            ext
        } else {
            rng.range(1.0, 1.8)
        },
        wi,
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
        inputs: (rng.chance(0.5), rng.chance(0.5), rng.chance(0.5)),
    }
}

impl Lane {
    fn recipe(&self) -> PlateRecipe {
        PlateRecipe {
            material: self.material,
            transport: match self.transport {
                Transport::Radiance => T::Radiance,
                Transport::Importance => T::Importance,
            },
            components: self.components,
            channels: self.wavelengths.len() as u32,
            intensity_only: self.intensity_only,
            absorbing_exit: self.absorbing_exit,
            ext_ior: self.ext,
            exit_ior: self.exit,
            thickness_scale: self.thickness_scale,
            has_birefringence: self.birefringence != 0.0,
            birefringence_scale: 1.0,
            has_axis_angle: self.angle_deg != 0.0,
            optic_axis: self.axis.into(),
            axis_is_input: self.inputs.0,
            indices_are_inputs: self.inputs.1,
            kappas_are_inputs: self.inputs.2,
        }
    }

    /// The program's inputs.
    fn inputs(&self) -> Vec<f64> {
        let mut x = vec![0.0; PlateInput::Wavelength0.repr as usize];
        let mut set = |k: PlateInput, v: f64| x[k.repr as usize] = v;
        set(PlateInput::WiX, self.wi.x);
        set(PlateInput::WiY, self.wi.y);
        set(PlateInput::WiZ, self.wi.z);
        set(PlateInput::Sample, self.u);
        set(PlateInput::Thickness, self.thickness_um);
        set(PlateInput::Birefringence, self.birefringence);
        set(PlateInput::AxisAngle, self.angle_deg);
        set(PlateInput::AxisX, self.axis.x);
        set(PlateInput::AxisY, self.axis.y);
        set(PlateInput::AxisZ, self.axis.z);
        set(PlateInput::EtaO, self.eta.0);
        set(PlateInput::EtaE, self.eta.1);
        set(PlateInput::KappaO, self.eta.2);
        set(PlateInput::KappaE, self.eta.3);
        x.extend(&self.wavelengths);
        x
    }

    /// The validated query of the lane, as the bridge builds it.
    fn query(&self, materials: &Materials) -> PlateQuery {
        let material: Material = *materials.get(self.material).unwrap();
        let (s, c) = self.angle_deg.to_radians().sin_cos();
        let a = self.axis;
        let axis = if self.angle_deg == 0.0 {
            a
        } else {
            Vector3::new(c * a.x - s * a.y, s * a.x + c * a.y, a.z)
        };
        let nm = 1000.0 * self.thickness_scale * self.thickness_um;
        PlateQuery::new(
            material,
            self.birefringence,
            C64::new(self.ext, 0.0),
            C64::new(self.exit, 0.0),
            axis,
            Thickness::new("thickness", nm, Length::Micrometres).unwrap(),
            self.components & 1 != 0,
            self.components & 2 != 0,
            self.intensity_only,
        )
        .unwrap()
        .with_absorbing_exit(self.absorbing_exit)
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

    /// The generic sample run on `f64`, as the program's outputs (without the failure mask).
    fn direct(&self, materials: &Materials) -> Vec<f64> {
        direct(&ExactPlate::of(&self.query(materials)), &self.path())
    }
}

#[test]
fn the_recorded_program_equals_the_host_sample() {
    let mut rng = Rng::new(2028);
    let mut materials = new_materials();
    let (mut lanes, mut valid) = (0, 0);
    for _ in 0..1500 {
        let lane = random_lane(&mut rng, &mut materials);
        let program = record_plate(&materials, &lane.recipe()).unwrap();
        let got = program.recorded().run(&lane.inputs());
        let want = lane.direct(&materials);
        let shortest = lane
            .wavelengths
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let d_nm = 1000.0 * lane.thickness_scale * lane.thickness_um;
        let tol = 1e-13 * (1.0 + 10.0 * d_nm / shortest);
        assert_program_outputs(&got, &want, lane.wavelengths.len(), tol, &lane);
        lanes += 1;
        valid += usize::from(got[0] != 0.0);
    }
    assert!(valid > lanes / 2, "{valid} of {lanes} lanes sample a lobe");
}

/// The generic sample on `f64` against the scalar route of the bridge's exact spectrum:
/// `plate_lobes` (the plate's spectral models at each wavelength) and `choose`, gathered as the
/// bridge writes a lane.
#[test]
fn the_generic_sample_equals_the_scalar_route() {
    let mut rng = Rng::new(31);
    let mut materials = new_materials();
    let mut compared = 0;
    for _ in 0..1500 {
        let lane = random_lane(&mut rng, &mut materials);
        let q = lane.query(&materials);
        let spectrum = exact_bands(&lane.wavelengths);
        let lobes = plate_lobes(&q, &spectrum, lane.wi, lane.transport).unwrap();
        let got = lane.direct(&materials);
        compared += usize::from(assert_scalar_route(&got, &lobes, &lane.path(), &lane));
    }
    assert!(compared > 700, "{compared} lanes compared");
}

/// Prints the size of typical programs (run with --nocapture).
#[test]
fn program_sizes() {
    let mut materials = new_materials();
    for (name, m) in [
        ("quartz", materials.add_named("quartz", 0.0, 0.0).unwrap()),
        ("glass", materials.add_constant(1.5, 1.5, 0.0, 0.0).unwrap()),
        (
            "aniso const",
            materials.add_constant(1.5, 1.6, 0.0, 0.0).unwrap(),
        ),
    ] {
        for (inputs, exit_ior) in [(false, 1.0), (true, 1.0), (false, 1.5)] {
            let recipe = PlateRecipe {
                material: m,
                transport: T::Radiance,
                components: 3,
                channels: 4,
                intensity_only: false,
                absorbing_exit: false,
                ext_ior: 1.0,
                exit_ior,
                thickness_scale: 1.0,
                has_birefringence: false,
                birefringence_scale: 1.0,
                has_axis_angle: false,
                optic_axis: [1.0, 1.0, 0.0],
                axis_is_input: inputs,
                indices_are_inputs: inputs,
                kappas_are_inputs: inputs,
            };
            let p = record_plate(&materials, &recipe).unwrap();
            println!(
                "{name} inputs {inputs} exit {exit_ior}: {} operations, {} instructions",
                p.operations(),
                p.instructions().len()
            );
            let mut hist = std::collections::BTreeMap::new();
            for i in &p.recorded().instrs {
                *hist.entry(format!("{:?}", i.op)).or_insert(0) += 1;
            }
            println!("    {hist:?}");
        }
    }
}
