//! The exact plate on a weight set's Chebyshev rule (`spectral::pointwise`, its points sized
//! order by order by `quadrature::chebyshev`) against a dense composite Gauss–Legendre rule of
//! the exact plate (both interfaces solved at every node, no interpolation, 1024 panels over the
//! same support; the Chebyshev rule interpolates), Mueller matrices entry by entry.

use birefringent::colour::weights::{gaussians, WeightSet};
use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::plate::slab::Output;
use birefringent::plate::slab::Want;
use birefringent::plate::Plate;
use birefringent::quadrature::chebyshev::support;
use birefringent::quadrature::hermite;
use birefringent::spectral::pointwise;
use birefringent::spectral::route;
use birefringent::spectral::survey::Survey;
use birefringent::C64;
use nalgebra::Matrix4;
use std::f64::consts::TAU;

mod common;
use common::Rng;

/// `∫ w_c(k) M(k) dk` per channel by 1024 panels of 8-point Gauss–Legendre, every node exact.
fn dense(plate: &Plate, frame: &PlaneFrame, beta: C64, set: WeightSet) -> [[Matrix4<f64>; 2]; 3] {
    let (lo, hi) = support(set);
    let mut acc = [[Matrix4::zeros(); 2]; 3];
    for (k, w) in hermite::composite_interval(lo, hi, 1024) {
        let m = plate
            .at(TAU / k)
            .unwrap()
            .optics(frame, beta)
            .unwrap()
            .mueller(TAU / k, Want::BOTH)
            .unwrap();
        for (c, sums) in acc.iter_mut().enumerate() {
            let wc: f64 = gaussians(set, c)
                .iter()
                .map(|g| {
                    let z = (k - g.mu) / g.sigma;
                    g.amplitude * (-0.5 * z * z).exp() / (g.sigma * TAU.sqrt())
                })
                .sum();
            sums[0] += m.r.unwrap() * (w * wc);
            sums[1] += m.t.unwrap() * (w * wc);
        }
    }
    acc
}

#[test]
fn chebyshev_rule_of_the_exact_plate_matches_a_dense_rule() {
    let mut rng = Rng::new(2027);
    let names = ["linbo3", "quartz", "calcite", "sapphire", "mgf2", "rutile"];
    let (mut worst, mut planned, mut declined) = (0.0f64, 0, 0);
    let mut point_counts = Vec::new();
    for i in 0..120 {
        // Dispersive crystals and constant (optionally dichroic) indices; films 20 nm - 10 um,
        // on substrates or free-standing, incidence up to ~72 degrees.
        let material = if i % 4 == 3 {
            let kappa = if i % 8 == 7 { 0.02 } else { 0.0 };
            Material::constant(
                C64::new(rng.range(1.3, 2.6), kappa),
                C64::new(rng.range(1.3, 2.6), 0.0),
            )
            .unwrap()
        } else {
            Material::named(names[i % names.len()], 0.0, 0.0).unwrap()
        };
        let plate = common::random_plate(&mut rng, material, (1.0, 1.7), (1.3, 4.0));
        let frame = PlaneFrame::from_azimuth(rng.range(0.0, TAU));
        let beta = C64::new(rng.range(0.0, 0.95), 0.0);
        let set = WeightSet::ALL[i % 3];
        let survey = Survey::new(&plate, frame, beta).unwrap();
        let Some(points) = route::rule_points(&survey, set) else {
            declined += 1;
            continue;
        };
        planned += 1;
        point_counts.push(points);
        let got = pointwise::channels(
            &plate,
            &frame,
            beta,
            set,
            points,
            Want::BOTH,
            Output::Mueller,
        )
        .unwrap();
        let want = dense(&plate, &frame, beta, set);
        for (g, w) in got.iter().zip(&want) {
            let e = (g.r.unwrap() - w[0])
                .abs()
                .max()
                .max((g.t.unwrap() - w[1]).abs().max());
            worst = worst.max(e);
        }
    }
    point_counts.sort_unstable();
    println!(
        "Chebyshev rule: {planned} plates ({declined} declined), points median {} max {}; worst |dM| vs dense {worst:e}",
        point_counts[point_counts.len() / 2],
        point_counts.last().unwrap()
    );
    // The rule holds each oscillation's error below its TOLERANCE (1e-5), with a conservative
    // amplitude model: measured worst 5.7e-7 (this code and these 120 plates); bound 2e-6, a
    // factor 3.5 above it, a fixed number (a rule that only met its own TOLERANCE, or a looser
    // TOLERANCE, fails here: re-measure when the rule changes). The composite Gauss-Legendre
    // rule of 8 panels the shared quadrature used before gave ~1e-3 here on films below 100 nm.
    assert!(worst < 2e-6, "{worst:e}");
    assert!(planned >= 80, "{planned} planned");
}
