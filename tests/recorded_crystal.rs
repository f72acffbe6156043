//! The crystal surface's recorded program (`ffi::record_crystal`, what the shim replays in
//! Mitsuba's JIT variants) against the host: run in `f64` on random lanes it equals the generic
//! sample run on `f64` directly (`render::crystal::sample_exact`), and that equals the scalar
//! query of the bridge (`crystal_slots` at each wavelength, then `choose`) and the general
//! computation (`crystal_slots_full`: every event through the interface's 4x4 solve), over
//! named crystals, constant birefringent and isotropic indices and absorbing isotropic ones
//! (opaque), from outside and inside (light arriving as the o- and the e-ray) and exactly
//! grazing, both transport modes, every set of components, a random optic axis, incidence to
//! 89.5 degrees and one to four wavelengths, with the axis, the indices and the extinctions
//! inputs of the program or its constants. Inputs that make a lane other than its recipe's
//! material (an isotropic material's indices made birefringent by a texture, a clear one's made
//! absorbing, and the converse) are the decisions the program cannot make while recording:
//! such a lane takes its own lobes (or fails: an absorbing birefringent crystal, a zero axis),
//! and no value the program computes is NaN or infinite, not even in an outcome it discards.
//!
//! Tolerances. The program runs the generic code's `f64` operations, constants folded; where
//! a decision is not known while recording (an index that is an input, the side, total
//! internal reflection) it computes every outcome and selects, and where a medium is not known
//! to be lossless it takes complex arithmetic, which on real numbers rounds as the real one
//! does (`optics::fields`' test). So program and direct run agree to rounding: observed worst
//! 2.3e-16 (printed), asserted 1e-13 relative to the outputs' size (power fractions over a
//! probability, at most a few), leaving room for a compiler's fused operations. The generic
//! sample and the bridge's route run the same code: observed equal, asserted 1e-12. The
//! general computation solves the same boundary equations by elimination with pivoting, which
//! `tests/crystal_fast_path.rs` bounds by 1e-12 of the largest Mueller entry and
//! `tests/sampling.rs` by 3e-12 for the opaque reflection: observed 1e-13, asserted 1e-9 after
//! the division by the probability (at least 1e-3 for the lanes compared; lanes where the two
//! choose different slots, u on a boundary, are skipped, fewer than 1 %).

use birefringent::ffi::bridge::{CrystalInput, CrystalRecipe, SampleOutput, Transport as T};
use birefringent::ffi::{new_materials, record_crystal, Materials};
use birefringent::material::Material;
use birefringent::optics::medium::Uniaxial;
use birefringent::optics::surface::Surface;
use birefringent::render::choice::choose;
use birefringent::render::crystal::{
    crystal_slots, crystal_slots_full, sample_exact, ExactCrystal,
};
use birefringent::render::slots::{crystal_component, Slots, CRYSTAL_SLOTS};
use birefringent::render::Transport;
use birefringent::C64;
use nalgebra::Vector3;
use std::f64::consts::FRAC_PI_2;

mod common;
use common::{assert_every_value_finite, compare_outputs, sample_outputs, Rng};

/// The kinds of material of a lane's recipe.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Named(&'static str),
    Birefringent,
    Isotropic,
    Opaque,
}

/// One random lane of a crystal query, in the plugin's units.
#[derive(Clone, Debug)]
struct Lane {
    kind: Kind,
    /// The recipe's material.
    material: u32,
    /// The lane's `(Re η_o, Re η_e, κ_o, κ_e)`: its inputs where the recipe makes them inputs
    /// (a texture's values, which may differ from the material's), else the material's.
    eta: (f64, f64, f64, f64),
    axis: Vector3<f64>,
    ext: f64,
    wi: Vector3<f64>,
    u: f64,
    wavelengths: Vec<f64>,
    transport: Transport,
    components: u32,
    intensity_only: bool,
    inputs: (bool, bool, bool),
    /// The axis input is zero (an invalid texture value): the lane fails.
    zero_axis: bool,
}

fn random_lane(rng: &mut Rng, materials: &mut Materials) -> Lane {
    let named = ["calcite", "quartz", "rutile", "sapphire", "mgf2", "linbo3"];
    let kind = match rng.index(4) {
        0 => Kind::Named(named[rng.index(named.len())]),
        1 => Kind::Birefringent,
        2 => Kind::Isotropic,
        _ => Kind::Opaque,
    };
    let n = rng.range(1.3, 2.6);
    let mut eta = match kind {
        Kind::Named(_) => (0.0, 0.0, 0.0, 0.0),
        Kind::Birefringent => (n, rng.range(1.3, 2.6), 0.0, 0.0),
        Kind::Isotropic => (n, n, 0.0, 0.0),
        Kind::Opaque => {
            let (n, kappa) = if rng.chance(0.5) {
                (rng.range(0.1, 2.0), rng.range(1.0, 5.0))
            } else {
                (n, 10f64.powf(rng.range(-6.0, -1.0)))
            };
            (n, n, kappa, kappa)
        }
    };
    let material = match kind {
        Kind::Named(name) => materials.add_named(name, 0.0, 0.0),
        _ => materials.add_constant(eta.0, eta.1, eta.2, eta.3),
    }
    .unwrap();
    // Extinction is an input only of a crystal that can absorb (an isotropic one): a
    // birefringent crystal's kappa has no derivative and is refused (below).
    let isotropic = matches!(kind, Kind::Isotropic | Kind::Opaque);
    let inputs = (
        rng.chance(0.5),
        rng.chance(0.5),
        isotropic && rng.chance(0.5),
    );
    // A texture gives some lanes other values than the material's: an isotropic material
    // birefringent indices and a birefringent one equal indices, a clear material absorption
    // and an absorbing one none (what the program cannot know while recording).
    if inputs.1 && !matches!(kind, Kind::Named(_)) && rng.chance(0.3) {
        eta.1 = if eta.0 == eta.1 {
            eta.0 * rng.range(0.8, 1.25)
        } else {
            eta.0
        };
    }
    if inputs.2 && rng.chance(0.3) {
        let kappa = if eta.2 > 0.0 {
            0.0
        } else {
            10f64.powf(rng.range(-6.0, 0.5))
        };
        (eta.2, eta.3) = (kappa, kappa);
    }
    let theta = if rng.chance(0.15) {
        rng.range(85.0, 89.5)
    } else {
        rng.range(0.0, 85.0)
    }
    .to_radians();
    let phi = rng.range(0.0, std::f64::consts::TAU);
    let side = if rng.chance(0.5) { 1.0 } else { -1.0 };
    // Exactly grazing lanes (no light) too.
    let grazing = rng.chance(0.02);
    let theta = if grazing { FRAC_PI_2 } else { theta };
    let wi = Vector3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        if grazing {
            0.0 * side
        } else {
            side * theta.cos()
        },
    );
    let channels = if rng.chance(0.5) { 4 } else { 1 + rng.index(3) };
    Lane {
        kind,
        material,
        eta,
        axis: rng.unit_vector() * rng.range(0.5, 2.0),
        ext: rng.range(1.0, 1.8),
        wi,
        u: rng.uniform(),
        wavelengths: (0..channels).map(|_| rng.range(360.0, 830.0)).collect(),
        transport: if rng.chance(0.5) {
            Transport::Radiance
        } else {
            Transport::Importance
        },
        components: 1 + rng.index(7) as u32,
        intensity_only: rng.chance(0.25),
        inputs,
        zero_axis: inputs.0 && rng.chance(0.02),
    }
}

impl Lane {
    fn recipe(&self) -> CrystalRecipe {
        CrystalRecipe {
            material: self.material,
            transport: match self.transport {
                Transport::Radiance => T::Radiance,
                Transport::Importance => T::Importance,
            },
            components: self.components,
            channels: self.wavelengths.len() as u32,
            intensity_only: self.intensity_only,
            ext_ior: self.ext,
            optic_axis: self.axis.into(),
            axis_is_input: self.inputs.0,
            indices_are_inputs: self.inputs.1,
            kappas_are_inputs: self.inputs.2,
        }
    }

    /// The program's inputs.
    fn inputs(&self) -> Vec<f64> {
        let mut x = vec![0.0; CrystalInput::Wavelength0.repr as usize];
        let mut set = |k: CrystalInput, v: f64| x[k.repr as usize] = v;
        set(CrystalInput::WiX, self.wi.x);
        set(CrystalInput::WiY, self.wi.y);
        set(CrystalInput::WiZ, self.wi.z);
        set(CrystalInput::Sample, self.u);
        let axis = self.axis();
        set(CrystalInput::AxisX, axis.x);
        set(CrystalInput::AxisY, axis.y);
        set(CrystalInput::AxisZ, axis.z);
        set(CrystalInput::EtaO, self.eta.0);
        set(CrystalInput::EtaE, self.eta.1);
        set(CrystalInput::KappaO, self.eta.2);
        set(CrystalInput::KappaE, self.eta.3);
        x.extend(&self.wavelengths);
        x
    }

    /// The material the lane has: the recipe's, with the lane's inputs.
    fn host_material(&self) -> Material {
        let (no, ne, ko, ke) = self.lane_eta();
        match self.kind {
            Kind::Named(name) => Material::named(name, ko, ke),
            _ => Material::constant(C64::new(no, ko), C64::new(ne, ke)),
        }
        .unwrap()
    }

    /// The indices the lane's crystal has: its inputs, except that a crystal isotropic when
    /// recorded stays isotropic, its pairs of inputs replaced by their means.
    fn lane_eta(&self) -> (f64, f64, f64, f64) {
        let (mut no, mut ne, mut ko, mut ke) = self.eta;
        if matches!(self.kind, Kind::Isotropic | Kind::Opaque) {
            if self.inputs.1 {
                (no, ne) = (0.5 * (no + ne), 0.5 * (no + ne));
            }
            if self.inputs.2 {
                (ko, ke) = (0.5 * (ko + ke), 0.5 * (ko + ke));
            }
        }
        (no, ne, ko, ke)
    }

    /// The lane's optic axis.
    fn axis(&self) -> Vector3<f64> {
        if self.zero_axis {
            Vector3::zeros()
        } else {
            self.axis
        }
    }

    /// True if the lane's crystal is birefringent and absorbing, or its axis zero: refused.
    fn refused(&self) -> bool {
        let (no, ne, ko, ke) = self.lane_eta();
        let birefringent = matches!(self.kind, Kind::Named(_)) || no != ne || ko != ke;
        self.zero_axis || (birefringent && (ko > 0.0 || ke > 0.0))
    }

    /// The generic sample run on `f64`, as the program's outputs (without the failure mask);
    /// `None` where it fails.
    fn direct(&self) -> Option<Vec<f64>> {
        match self.wavelengths.len() {
            1 => self.direct_in::<1>(),
            2 => self.direct_in::<2>(),
            3 => self.direct_in::<3>(),
            _ => self.direct_in::<4>(),
        }
    }

    fn direct_in<const C: usize>(&self) -> Option<Vec<f64>> {
        let material = self.host_material();
        let q = ExactCrystal::new(material, self.ext, self.axis(), self.intensity_only).ok()?;
        let w: [f64; C] = std::array::from_fn(|k| self.wavelengths[k]);
        let s = sample_exact(&q, &w, self.wi, self.u, self.transport, self.components).ok()?;
        Some(sample_outputs(&s))
    }

    /// The lane's slots at each wavelength, through `slots` (a scalar route of the host).
    fn slots(
        &self,
        slots: impl Fn(&Surface, Vector3<f64>, Transport) -> Option<Slots<CRYSTAL_SLOTS>>,
    ) -> Option<Vec<Slots<CRYSTAL_SLOTS>>> {
        let material = self.host_material();
        let ext = C64::new(self.ext, 0.0);
        self.wavelengths
            .iter()
            .map(|&l| {
                let (eo, ee) = material.indices(l, 0.0).unwrap();
                let s = Surface::new(ext, Uniaxial::new(eo, ee, self.axis).unwrap()).unwrap();
                slots(&s, self.wi, self.transport)
            })
            .collect()
    }
}

/// Closeness relative to the outputs' size (power fractions over a probability).
fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

/// Two Stokes x axes that are the same frame (`x` and `−x` give the same Stokes vectors).
fn same_axis(a: &[f64], b: Vector3<f64>, tol: f64) -> bool {
    let a = Vector3::new(a[0], a[1], a[2]);
    (a - b).norm().min((a + b).norm()) <= tol
}

#[test]
fn the_recorded_program_equals_the_host_sample() {
    let mut rng = Rng::new(2029);
    let mut materials = new_materials();
    let (mut valid, mut inside, mut refused, mut grazing) = (0, 0, 0, 0);
    let mut worst = 0.0f64;
    let mut slots_seen = [0; CRYSTAL_SLOTS];
    // Lanes of isotropic materials (recipe) that are not (inputs), and the converse; of clear
    // materials that absorb, and the converse.
    let (mut isotropy_changed, mut absorption_changed) = (0, 0);
    for _ in 0..2500 {
        let lane = random_lane(&mut rng, &mut materials);
        let program = record_crystal(&materials, &lane.recipe()).unwrap();
        let got = program.recorded().run(&lane.inputs());
        assert_eq!(got.len(), SampleOutput::Count.repr as usize + 1);
        let failed = got[SampleOutput::Count.repr as usize];
        assert_every_value_finite(program.recorded(), &lane.inputs(), &lane);
        let recipe = materials.get(lane.material).unwrap();
        let host = lane.host_material();
        isotropy_changed += usize::from(recipe.is_isotropic() != host.is_isotropic());
        let absorbs = |m: &Material| m.indices(550.0, 0.0).unwrap().0.im > 0.0;
        absorption_changed += usize::from(absorbs(recipe) != absorbs(&host));
        if lane.refused() {
            assert_eq!(failed, 1.0, "{lane:?} not refused");
            assert!(lane.direct().is_none());
            refused += 1;
            continue;
        }
        assert_eq!(failed, 0.0, "{lane:?} failed");
        let want = lane.direct().unwrap();
        let channels = lane.wavelengths.len();
        worst = worst.max(compare_outputs(&got, &want, channels, 1e-13, &lane));
        grazing += usize::from(lane.wi.z == 0.0);
        assert!(lane.wi.z != 0.0 || got[0] == 0.0, "{lane:?}");
        if got[0] != 0.0 {
            valid += 1;
            slots_seen[got[1] as usize] += 1;
            inside += usize::from(lane.wi.z < 0.0);
        }
    }
    println!(
        "program vs generic sample: worst {worst:e}; {valid} lanes sampled a lobe ({inside} from \
         inside), by slot {slots_seen:?}; {refused} refused, {grazing} grazing; isotropy changed by the inputs in \
         {isotropy_changed}, absorption in {absorption_changed}"
    );
    assert!(valid > 1200, "{valid} lanes sample a lobe");
    assert!(inside > 400, "{inside} lanes from inside sample a lobe");
    assert!(slots_seen.iter().all(|&n| n >= 10), "{slots_seen:?}");
    // Refused: a zero optic axis (2 % of the lanes with the axis an input), a birefringent
    // absorbing lane (an absorbing named crystal).
    assert!(refused > 20 && grazing > 10 && isotropy_changed > 50 && absorption_changed > 50);
}

/// The generic sample on `f64` against a scalar route (the slots of each wavelength, then
/// `choose`), gathered as the bridge writes a lane, to `tol`; returns the lanes compared.
fn compare_with_route(
    seed: u64,
    tol: f64,
    slots: impl Fn(&Surface, Vector3<f64>, Transport) -> Option<Slots<CRYSTAL_SLOTS>>,
) -> (usize, f64) {
    let mut rng = Rng::new(seed);
    let mut materials = new_materials();
    let (mut compared, mut skipped, mut worst) = (0, 0, 0.0f64);
    let mut close = |a: f64, b: f64, tol: f64| {
        worst = worst.max((a - b).abs() / (1.0 + a.abs().max(b.abs())));
        close(a, b, tol)
    };
    for _ in 0..2500 {
        let lane = random_lane(&mut rng, &mut materials);
        let (Some(lobes), Some(got)) = (lane.slots(&slots), lane.direct()) else {
            assert!(lane.refused(), "{lane:?}");
            continue;
        };
        let enabled = |slot: usize| lane.components & (1 << crystal_component(slot)) != 0;
        let choice = choose(&lobes, enabled, lane.u);
        assert_eq!(got[0] != 0.0, choice.is_some(), "{lane:?}");
        let Some(choice) = choice else { continue };
        // The general route may choose a neighbouring slot where u lies on a boundary, and
        // divides its rounding by the probability.
        let loose = tol > 1e-12;
        if loose && (got[1] != choice.slot as f64 || choice.pdf < 1e-3) {
            skipped += 1;
            continue;
        }
        assert_eq!(got[1], choice.slot as f64, "{lane:?}");
        let hero = lobes[choice.hero][choice.slot].unwrap();
        assert_eq!(got[2], crystal_component(choice.slot) as f64);
        assert!(
            close(got[3], choice.pdf, tol),
            "pdf {} vs {}",
            got[3],
            choice.pdf
        );
        assert!(close(got[4], hero.eta, tol), "{lane:?}");
        for k in 0..3 {
            assert!(close(got[5 + k], hero.wo[k], tol), "{lane:?}");
        }
        let per = SampleOutput::PerChannel.repr as usize;
        let first = SampleOutput::Channel0.repr as usize;
        for (c, slots) in lobes.iter().enumerate() {
            let base = first + per * c;
            let lobe = slots[choice.slot].unwrap_or(hero);
            assert!(same_axis(&got[base..base + 3], lobe.in_stokes_x, tol));
            assert!(same_axis(&got[base + 3..base + 6], lobe.out_stokes_x, tol));
            let m = slots[choice.slot].map(|l| l.mueller / choice.pdf);
            for e in 0..16 {
                let kept = !lane.intensity_only || e == 0;
                let want = m.filter(|_| kept).map_or(0.0, |m| m[(e / 4, e % 4)]);
                let g = got[base + 6 + e];
                assert!(
                    close(g, want, tol),
                    "channel {c} entry {e}: {g} vs {want}\n{lane:?}"
                );
            }
        }
        compared += 1;
    }
    assert!(skipped * 100 < compared, "{skipped} lanes skipped");
    (compared, worst)
}

/// The generic sample on `f64` equals the bridge's scalar route (`crystal_slots` at each
/// wavelength, then `choose`).
#[test]
fn the_generic_sample_equals_the_scalar_route() {
    let (compared, worst) = compare_with_route(31, 1e-12, |s, wi, t| crystal_slots(s, wi, t).ok());
    println!("generic sample vs crystal_slots: worst {worst:e} over {compared} lanes");
    assert!(compared > 1200, "{compared} lanes compared");
}

/// The generic sample on `f64` equals the general computation of every event
/// (`crystal_slots_full`).
#[test]
fn the_generic_sample_equals_the_general_computation() {
    let (compared, worst) =
        compare_with_route(37, 1e-9, |s, wi, t| crystal_slots_full(s, wi, t).ok());
    println!("generic sample vs crystal_slots_full: worst {worst:e} over {compared} lanes");
    assert!(compared > 1200, "{compared} lanes compared");
}

/// Decisions known from the recipe are made while recording (an isotropic material takes the
/// isotropic closed form alone, an absorbing one its reflection alone, a material whose
/// indices do not depend on the wavelength is solved once), those that depend on an input are
/// not (an isotropic material whose indices are inputs records the birefringent lobes too):
/// seen in the programs' sizes (printed).
#[test]
fn decisions_known_from_the_recipe_are_made_while_recording() {
    let mut materials = new_materials();
    let calcite = materials.add_named("calcite", 0.0, 0.0).unwrap();
    let birefringent = materials.add_constant(1.6, 1.5, 0.0, 0.0).unwrap();
    let glass = materials.add_constant(1.5, 1.5, 0.0, 0.0).unwrap();
    let metal = materials.add_constant(0.2, 0.2, 3.0, 3.0).unwrap();
    let size = |material: u32, inputs: bool, channels: u32| {
        let recipe = CrystalRecipe {
            material,
            transport: T::Radiance,
            components: 7,
            channels,
            intensity_only: false,
            ext_ior: 1.0,
            optic_axis: [0.3, 0.2, 0.9],
            axis_is_input: inputs,
            indices_are_inputs: inputs,
            kappas_are_inputs: inputs && material != calcite && material != birefringent,
        };
        record_crystal(&materials, &recipe).unwrap().operations()
    };
    let (calcite, calcite_4) = (size(calcite, false, 1), size(calcite, false, 4));
    let (crystal, crystal_inputs) = (size(birefringent, false, 4), size(birefringent, true, 4));
    let (glass, glass_inputs) = (size(glass, false, 4), size(glass, true, 4));
    let metal = size(metal, false, 4);
    println!(
        "operations: calcite {calcite} (4 wavelengths {calcite_4}), constant birefringent \
         {crystal} (inputs {crystal_inputs}), glass {glass} (inputs {glass_inputs}), metal {metal}"
    );
    assert!(4 * glass < crystal && 4 * metal < crystal);
    assert!(calcite_4 > 3 * calcite && crystal < calcite);
    // An isotropic crystal stays isotropic with its indices as inputs (their mean): its program
    // keeps the closed form of a dielectric interface.
    assert!(glass_inputs < 2 * glass && 4 * glass_inputs < crystal_inputs);
}

/// Extinction carrying derivatives on a birefringent crystal (which cannot absorb) is refused
/// when its program is recorded, naming kappa_o and the reason, instead of a derivative of 0.
#[test]
fn birefringent_extinction_inputs_are_refused() {
    let mut materials = new_materials();
    let calcite = materials.add_named("calcite", 0.0, 0.0).unwrap();
    let glass = materials.add_constant(1.5, 1.5, 0.0, 0.0).unwrap();
    let recipe = |material: u32| CrystalRecipe {
        material,
        transport: T::Radiance,
        components: 7,
        channels: 4,
        intensity_only: false,
        ext_ior: 1.0,
        optic_axis: [0.0, 0.0, 1.0],
        axis_is_input: false,
        indices_are_inputs: false,
        kappas_are_inputs: true,
    };
    let refused = record_crystal(&materials, &recipe(calcite)).err().unwrap();
    let message = refused.to_string();
    assert!(
        message.contains("kappa_o") && message.contains("cannot absorb"),
        "{message}"
    );
    assert!(record_crystal(&materials, &recipe(glass)).is_ok());
}
