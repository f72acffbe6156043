//! The analytic sRGB integral of plates between media denser than the plate, near and beyond
//! the critical angle, where the waves in the layer are evanescent at some or all wavelengths
//! (frustrated total reflection) and the Fresnel amplitudes vary much faster across the band
//! than the indices: against dense quadrature of the exact plate with the tabulated weights.

use birefringent::colour::weights::{fourier_error_bound, weight_per_nm, WeightSet};
use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::params::Thickness;
use birefringent::plate::slab::{Output, Want};
use birefringent::plate::Plate;
use birefringent::quadrature::Accuracy;
use birefringent::spectral::model::{PlateModel, ThinModel};
use birefringent::C64;
use nalgebra::{Matrix4, Vector3};

mod common;
use common::Rng;

/// Trapezoid quadrature of `w_c(λ) M(λ)` over the tables' 360-830 nm, `step` nm: per channel
/// `[R, T]`.
fn dense(model: &PlateModel, step: f64) -> [[Matrix4<f64>; 2]; 3] {
    let n = (470.0 / step).round() as usize;
    let mut out = [[Matrix4::zeros(); 2]; 3];
    for j in 0..=n {
        let lambda = 360.0 + 470.0 * j as f64 / n as f64;
        let end = if j == 0 || j == n { 0.5 } else { 1.0 };
        let m = model.at(lambda, Want::BOTH, Output::Mueller).unwrap();
        for (c, o) in out.iter_mut().enumerate() {
            let w = weight_per_nm(WeightSet::SrgbD65, c, lambda) * end * 470.0 / n as f64;
            o[0] += m.r.unwrap_or_default() * w;
            o[1] += m.t.unwrap_or_default() * w;
        }
    }
    out
}

/// Quartz, calcite and sapphire plates (10 nm to 100 µm) in media of index 1.5-1.7 at 55-80
/// degrees, total reflection at the exit face included: every Mueller entry of every channel
/// within the fitted weights' own error bound (the L1 norm of the fit residual, which bounds
/// the fit's error on any spectrum of magnitude ≤ 1) plus 2e-4 for the method; measured worst
/// 1.7e-3 (a thick plate: the fit's share). Before the amplitude nodes followed the amplitudes
/// themselves and attenuation entered the strength of a pair, such plates erred by up to
/// 3e-2, and an evanescent 2 mm plate gave 7e25. Beyond 80 degrees, and where a wave turns
/// evanescent inside the band, the exact rule serves the plate with its own, larger errors
/// (docs/physics.md, known limitations).
#[test]
fn plates_between_denser_media_match_dense_quadrature() {
    let mut rng = Rng::new(95);
    let names = ["quartz", "calcite", "sapphire"];
    let bound: f64 = (0..3)
        .map(|c| fourier_error_bound(WeightSet::SrgbD65, c))
        .fold(0.0, f64::max)
        + 2e-4;
    let (mut worst, mut tested, mut skipped) = (0.0f64, 0, 0);
    for i in 0..60 {
        let d = 10f64.powf(rng.range(1.0, 5.0));
        let ambient = rng.range(1.5, 1.7);
        let plate = Plate {
            material: Material::named(names[i % 3], 0.0, 0.0).unwrap(),
            birefringence: 0.0,
            ext: C64::new(ambient, 0.0),
            exit: C64::new(rng.range(1.0, 1.7), 0.0),
            axis: rng.unit_vector(),
            thickness_nm: Thickness::from_nm(d).unwrap().nm(),
        };
        let theta = rng.range(55.0f64, 80.0).to_radians();
        let phi = rng.range(0.0, std::f64::consts::TAU);
        let wi = Vector3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        );
        let frame = PlaneFrame::from_direction(wi);
        let beta = C64::new(ambient * theta.sin(), 0.0);
        // A wave that turns evanescent at a critical wavelength inside the band is served by
        // the exact rule, whose interpolants do not follow the branch point there (a known
        // limitation, docs/physics.md); the cases here are evanescent everywhere or nowhere.
        let evanescent = |lambda: f64| {
            plate
                .layer_q(lambda, &frame, beta)
                .unwrap()
                .map(|q| q.im != 0.0)
        };
        if evanescent(360.0) != evanescent(830.0) {
            skipped += 1;
            continue;
        }
        let model = PlateModel::new(
            &plate,
            PlaneFrame::from_direction(wi),
            C64::new(ambient * theta.sin(), 0.0),
        );
        let fast = model
            .channels(
                WeightSet::SrgbD65,
                Want::BOTH,
                Output::Mueller,
                Accuracy::Perceptual,
            )
            .unwrap();
        // Fringes of the round trip (group path up to ~3.6 d) sampled 20 times per period.
        let step = (360.0f64 * 360.0 / (3.6 * d) / 20.0).min(0.5);
        let reference = dense(&model, step);
        tested += 1;
        for c in 0..3 {
            let e = (fast[c].r.unwrap() - reference[c][0]).abs().max().max(
                (fast[c].t.unwrap_or_default() - reference[c][1])
                    .abs()
                    .max(),
            );
            worst = worst.max(e);
        }
    }
    println!(
        "plates between denser media: {tested} plates ({skipped} with a critical wavelength skipped), worst {worst:e} (bound {bound:e})"
    );
    assert!(
        tested >= 30 && skipped < tested,
        "{tested} tested, {skipped} skipped"
    );
    assert!(worst < bound, "{worst:e}");
}
