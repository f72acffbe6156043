//! The path classes' two orders of summation at an amplitude node (`spectral::classes::Sums`):
//! the pair-free sums per class (`Classes`) and the chosen one (`Cheaper`) give the coherency
//! of the groups' pair sums (`Pairs`) to rounding, on random plates of the named crystals at
//! 0, 45, 80 and 89 degrees and 0, 5 and 150 um (and random thicknesses), both lobes, Mueller
//! and intensity outputs. Tolerance 1e-12 of the largest entry of each channel's Mueller
//! matrix: the sums differ only in their order (a few hundred terms of magnitude at most 4).

mod common;

use birefringent::colour::weights::WeightSet;
use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::plate::slab::{Output, SlabMueller, Want};
use birefringent::spectral::classes::{self, Sums};
use birefringent::spectral::survey::Survey;
use birefringent::C64;
use common::Rng;

const CRYSTALS: [&str; 5] = ["quartz", "calcite", "sapphire", "rutile", "mgf2"];

/// The largest difference between the Mueller matrices of `a` and `b` relative to the largest
/// entry of `a` (per channel and lobe).
fn relative(a: &[SlabMueller; 3], b: &[SlabMueller; 3]) -> f64 {
    let mut worst = 0.0f64;
    for (x, y) in a.iter().zip(b) {
        for (p, q) in [(x.r, y.r), (x.t, y.t)] {
            if let (Some(p), Some(q)) = (p, q) {
                let scale = p.amax().max(1e-300);
                worst = worst.max((p - q).amax() / scale);
            }
        }
    }
    worst
}

#[test]
fn pair_free_sums_equal_pair_sums() {
    let mut rng = Rng::new(0x5_0030_0001);
    let mut compared = 0;
    let mut by_classes_differs = false;
    for i in 0..48 {
        let name = CRYSTALS[rng.index(CRYSTALS.len())];
        let thickness_nm = match i % 4 {
            0 => 0.0,
            1 => 5e3,
            2 => 150e3,
            _ => 10f64.powf(rng.range(2.0, 5.0)),
        };
        let theta: f64 = [0.0, 45.0, 80.0, 89.0][(i / 4) % 4];
        let plate = birefringent::plate::Plate {
            material: Material::named(name, 0.0, 0.0).unwrap(),
            birefringence: 0.0,
            ext: C64::new(1.0, 0.0),
            exit: C64::new(rng.range(1.0, 1.6), 0.0),
            axis: rng.unit_vector(),
            thickness_nm,
        };
        let frame = PlaneFrame::from_azimuth(rng.range(0.0, std::f64::consts::TAU));
        let beta = C64::new(theta.to_radians().sin(), 0.0);
        let survey = Survey::new(&plate, frame, beta).unwrap();
        let Some(plan) = classes::plan(&survey, WeightSet::SrgbD65) else {
            continue;
        };
        for output in [Output::Mueller, Output::Intensity] {
            let run = |sums| {
                classes::channels_summed(
                    &survey,
                    &plan,
                    WeightSet::SrgbD65,
                    Want::BOTH,
                    output,
                    sums,
                )
                .unwrap()
            };
            let pairs = run(Sums::Pairs);
            for sums in [Sums::Classes, Sums::Cheaper] {
                let e = relative(&pairs, &run(sums));
                assert!(
                    e <= 1e-12,
                    "{name} {thickness_nm} nm at {theta} deg, order {}, {output:?}, {sums:?}: relative difference {e:e}",
                    plan.order
                );
            }
            by_classes_differs |= relative(&pairs, &run(Sums::Classes)) > 0.0;
            compared += 1;
        }
    }
    assert!(compared >= 80, "only {compared} plates had path classes");
    // The two sums are different code (not one path twice): they round differently somewhere.
    assert!(by_classes_differs);
}
