//! A stack on the plate's router (issue 30, item 3): its survey reads the same invariants as a
//! plate's (amplitude nodes, group paths, reflectances) and the same evanescence criterion, so a
//! layer whose wave turns evanescent inside the band (a branch point no interpolant of the
//! nodes follows) is solved at every point of its rule, and matches dense quadrature of the
//! exact stack; a stack without one is interpolated from its nodes.

use birefringent::colour::weights::{fourier_error_bound, weight_per_nm, WeightSet};
use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::params::Thickness;
use birefringent::plate::slab::{Output, Want};
use birefringent::quadrature::Accuracy;
use birefringent::spectral::model::ThinModel;
use birefringent::stack::spectral::StackModel;
use birefringent::stack::survey::StackSurvey;
use birefringent::stack::{Layer, Stack};
use birefringent::C64;
use nalgebra::{Matrix4, Vector3};

/// Trapezoid quadrature of `w_c(λ) M(λ)` of the exact stack over 360-830 nm, `step` nm.
fn dense(model: &StackModel, step: f64) -> [[Matrix4<f64>; 2]; 3] {
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

/// A calcite layer (its e-wave turns evanescent inside the band under BK7 at 82 degrees: the
/// plate's case of `tests/spectral_evanescent.rs`, found by the plugin fuzzer) on a quartz one,
/// in BK7; and the same stack at 40 degrees, where nothing turns evanescent. Every Mueller entry
/// of every channel within the fitted weights' error bound plus 2e-4, as for the plate.
#[test]
fn a_stack_turning_evanescent_is_solved_at_every_point() {
    let layer = |name: &str, axis: Vector3<f64>, um: f64| {
        Layer::new(
            Material::named(name, 0.0, 0.0).unwrap(),
            0.0,
            axis,
            Thickness::from_nm(um * 1e3).unwrap(),
        )
        .unwrap()
    };
    let bk7 = C64::new(1.5046, 0.0);
    let stack = Stack::new(
        vec![
            layer("calcite", Vector3::new(1.0, 0.0, 0.0), 1.0),
            layer("quartz", Vector3::new(0.2, 0.9, 0.3), 2.0),
        ],
        bk7,
        bk7,
    )
    .unwrap();
    let frame = PlaneFrame::from_azimuth(266.127f64.to_radians());
    let bound: f64 = (0..3)
        .map(|c| fourier_error_bound(WeightSet::SrgbD65, c))
        .fold(0.0, f64::max)
        + 2e-4;
    for (theta, evanescent) in [(81.8949f64, true), (40.0, false)] {
        let beta = C64::new(1.5046 * theta.to_radians().sin(), 0.0);
        let survey = StackSurvey::new(&stack, frame, beta).unwrap();
        assert_eq!(survey.interpolable, !evanescent, "{theta} degrees");
        let model = StackModel::new(&stack, frame, beta);
        let got = model
            .channels(
                WeightSet::SrgbD65,
                Want::BOTH,
                Output::Mueller,
                Accuracy::Perceptual,
            )
            .unwrap();
        let want = dense(&model, 0.02);
        let mut worst = 0.0f64;
        for (g, w) in got.iter().zip(&want) {
            worst = worst
                .max((g.r.unwrap() - w[0]).abs().max())
                .max((g.t.unwrap() - w[1]).abs().max());
        }
        println!("{theta} degrees: worst |dM| {worst:e} (bound {bound:e})");
        assert!(worst < bound, "{theta} degrees: {worst:e}");
    }
}
