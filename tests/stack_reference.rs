//! The exact stack against the independent Berreman 4×4 solution of `tests/common/berreman.rs`
//! (eigenmodes by a QR iteration, interfaces by a general linear solve, layers joined by its own
//! Redheffer star products): complex Jones matrices of reflection and transmission over random
//! stacks of 1 to 10 layers (10 nm to 1 mm each; uniaxial with tilted axes, isotropic, absorbing
//! and strongly dichroic; uniaxial/uniaxial interfaces), incidence up to 85° from an exterior of
//! index 1 to 1.8.

use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::params::Thickness;
use birefringent::plate::slab::Want;
use birefringent::stack::exact::StackBlocks;
use birefringent::stack::{Layer, Stack};
use birefringent::C64;

mod common;
use common::berreman::{try_stack_reference, uniaxial_eps};
use common::Rng;

/// A random layer: constant complex indices (a quarter isotropic), absorbing in about half of
/// them, strongly dichroic in some, a random axis, `10^u` nm thick with `u` in `log10_nm`.
pub fn random_layer(rng: &mut Rng, log10_nm: (f64, f64)) -> Layer {
    let kappa = |rng: &mut Rng| match rng.index(4) {
        0 | 1 => 0.0,
        2 => rng.range(0.0, 0.05),
        _ => rng.range(0.0, 2.0),
    };
    let eta_o = C64::new(rng.range(1.3, 2.6), kappa(rng));
    let eta_e = if rng.chance(0.25) {
        eta_o
    } else {
        C64::new(rng.range(1.3, 2.6), kappa(rng))
    };
    Layer::new(
        Material::constant(eta_o, eta_e).unwrap(),
        0.0,
        rng.unit_vector(),
        Thickness::from_nm(10f64.powf(rng.range(log10_nm.0, log10_nm.1))).unwrap(),
    )
    .unwrap()
}

#[test]
fn exact_stack_matches_the_berreman_stack_over_random_stacks() {
    let mut rng = Rng::new(24);
    let (mut worst, mut cases, mut skipped, mut absorbing, mut many) = (0.0f64, 0, 0, 0, 0);
    let mut worst_case = String::new();
    while cases < 600 {
        let n = 1 + rng.index(10);
        let layers: Vec<Layer> = (0..n).map(|_| random_layer(&mut rng, (1.0, 6.0))).collect();
        let n1 = rng.range(1.0, 1.8);
        let n3 = if rng.chance(0.3) {
            1.0
        } else {
            rng.range(1.0, 1.8)
        };
        let stack = Stack::new(layers, C64::new(n1, 0.0), C64::new(n3, 0.0)).unwrap();
        let theta = rng.range(0.0, 85f64.to_radians());
        let beta = C64::new(n1 * theta.sin(), 0.0);
        let frame = PlaneFrame::from_azimuth(rng.range(0.0, 6.3));
        let lambda = rng.range(380.0, 780.0);
        let eps: Vec<_> = stack
            .media(lambda, &frame)
            .unwrap()
            .iter()
            .map(|m| m.permittivity())
            .collect();
        let layers: Vec<_> = (0..n)
            .map(|j| (eps[j + 1], stack.layers[j].thickness_nm / lambda))
            .collect();
        let Ok(reference) = try_stack_reference(
            C64::new(n1 * n1, 0.0),
            &layers,
            C64::new(n3 * n3, 0.0),
            beta,
        ) else {
            skipped += 1;
            continue;
        };
        let j = StackBlocks::new(&stack, lambda, &frame, beta)
            .unwrap()
            .jones(lambda, Want::BOTH)
            .unwrap();
        let (r, t) = (j.r.unwrap(), j.t.unwrap());
        let f = reference.flux_ratio.sqrt();
        let mut e = 0.0f64;
        for o in 0..2 {
            for i in 0..2 {
                e = e.max((r[(o, i)] - reference.r[(o, i)]).norm());
                e = e.max((t[(o, i)] - reference.t[(o, i)] * f).norm());
                e = e.max((t[(o, i)].norm_sqr() - reference.power_t[(o, i)]).abs());
                e = e.max((r[(o, i)].norm_sqr() - reference.power_r[(o, i)]).abs());
            }
        }
        if e > worst {
            worst = e;
            worst_case = format!("{stack:?} theta {theta} lambda {lambda}");
        }
        absorbing += usize::from(stack.layers.iter().any(|l| {
            let (o, e) = l.material.indices(lambda, 0.0).unwrap();
            (o.im - e.im).abs() > 0.5
        }));
        many += usize::from(n >= 8);
        cases += 1;
    }
    println!(
        "stack vs Berreman: {cases} stacks ({skipped} skipped: reference degenerate; {absorbing} \
         strongly dichroic, {many} of 8-10 layers), worst Jones error {worst:e}"
    );
    println!("worst case: {worst_case}");
    assert!(skipped < 30 && absorbing > 100 && many > 100);
    assert!(worst < 1e-9, "worst {worst:e}");
}

#[test]
fn uniaxial_eps_is_the_medium_permittivity() {
    // The helper the reference builds from agrees with the core's tensor (same physics, eq. S6).
    let m = birefringent::optics::medium::Uniaxial::new(
        C64::new(1.5, 0.01),
        C64::new(1.7, 0.3),
        nalgebra::Vector3::new(0.2, -0.4, 0.9),
    )
    .unwrap();
    let e = uniaxial_eps(m.eta_o, m.eta_e, m.axis);
    assert!((e - m.permittivity()).norm() < 1e-14);
}
