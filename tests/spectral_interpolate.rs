//! The interpolated blocks of a dispersive plate (`quadrature::interpolate`) against the exact
//! blocks (both interfaces solved at the wavenumber) and the plate's Mueller matrices from each.

use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::plate::slab::Want;
use birefringent::spectral::pointwise::BlockInterpolant;
use birefringent::C64;

mod common;
use common::Rng;

#[test]
fn interpolated_blocks_match_the_exact_plate_across_the_visible() {
    let mut rng = Rng::new(81);
    let names = [
        "quartz", "calcite", "sapphire", "linbo3", "mgf2", "bbo", "kdp", "rutile",
    ];
    let (lo, hi) = (std::f64::consts::TAU / 830.0, std::f64::consts::TAU / 360.0);
    let (mut worst, mut accepted, mut refused) = (0.0f64, 0, 0);
    for i in 0..200 {
        let material = Material::named(names[i % names.len()], 0.0, 0.0).unwrap();
        let plate = common::random_plate(&mut rng, material, (1.0, 1.6), (1.0, 4.0));
        let frame = PlaneFrame::from_azimuth(rng.range(0.0, 6.3));
        let beta = C64::new(rng.range(0.0, 0.95), 0.0);
        let exact = |k: f64| {
            Ok(plate
                .at(std::f64::consts::TAU / k)?
                .optics(&frame, beta)?
                .blocks())
        };
        let Some(f) = BlockInterpolant::new(lo, hi, plate.thickness_nm, &exact).unwrap() else {
            refused += 1;
            continue;
        };
        accepted += 1;
        for _ in 0..20 {
            let k = rng.range(lo, hi);
            let lambda = std::f64::consts::TAU / k;
            let (a, b) = (f.at(k), exact(k).unwrap());
            let (ma, mb) = (
                a.mueller(lambda, Want::BOTH).unwrap(),
                b.mueller(lambda, Want::BOTH).unwrap(),
            );
            let e = (ma.r.unwrap() - mb.r.unwrap())
                .abs()
                .max()
                .max((ma.t.unwrap() - mb.t.unwrap()).abs().max());
            worst = worst.max(e);
        }
    }
    println!("interpolated blocks: {accepted} plates accepted, {refused} refused; worst Mueller difference {worst:e}");
    // Accepted interpolants reproduce the blocks to TOLERANCE (1e-10) at their check points;
    // between them the smooth Sellmeier dispersion keeps the error of the same order, amplified
    // in the Mueller matrices by the phases k d q of plates up to 10 um (k d <= 170). Measured
    // worst 9.7e-10 (this code and these 200 plates); bound 3e-9, a factor 3 above it, a fixed
    // number (re-measure when the interpolation or its TOLERANCE changes).
    assert!(worst < 3e-9, "{worst:e}");
    assert!(accepted > 150, "{accepted} accepted");
}
