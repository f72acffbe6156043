//! The exact slab against the independent Berreman 4×4 scattering-matrix plate of
//! `tests/common/berreman.rs`: power terms of reflection and transmission over random plates
//! (10 nm to 5 mm, tilted axes, absorbing and strongly dichroic, total internal reflection
//! inside, incidence up to 85°).

use birefringent::optics::frame::PlaneFrame;
use birefringent::optics::medium::Uniaxial;
use birefringent::params::Thickness;
use birefringent::plate::slab::{Slab, Want};
use birefringent::C64;

mod common;
use common::berreman::{plate_reference, to_array};
use common::Rng;

#[test]
fn exact_slab_matches_the_berreman_plate_over_random_plates() {
    let mut rng = Rng::new(51);
    let (mut worst, mut cases, mut tir, mut thick_dichroic) = (0.0f64, 0, 0, 0);
    let mut worst_case = String::new();
    while cases < 1500 {
        let kappa = |rng: &mut Rng| match rng.index(4) {
            0 | 1 => 0.0,
            2 => rng.range(0.0, 0.05),
            _ => rng.range(0.0, 2.0),
        };
        let eta_o = C64::new(rng.range(1.3, 2.6), kappa(&mut rng));
        let eta_e = C64::new(rng.range(1.3, 2.6), kappa(&mut rng));
        let layer = Uniaxial::new(eta_o, eta_e, rng.unit_vector()).unwrap();
        let n1 = rng.range(1.0, 1.8);
        let n3 = if rng.chance(0.3) {
            1.0
        } else {
            rng.range(1.0, 1.8)
        };
        let d = 10f64.powf(rng.range(1.0, 6.7)); // 10 nm .. 5 mm
        let slab = Slab::new(
            C64::new(n1, 0.0),
            layer,
            C64::new(n3, 0.0),
            Thickness::from_nm(d).unwrap(),
        )
        .unwrap();
        let theta = rng.range(0.0, 85f64.to_radians());
        let beta = C64::new(n1 * theta.sin(), 0.0);
        let frame = PlaneFrame::from_azimuth(rng.range(0.0, 6.3));
        let lambda = rng.range(380.0, 780.0);
        let j = slab
            .optics(&frame, beta)
            .unwrap()
            .jones(lambda, Want::BOTH)
            .unwrap();
        let working = layer.with_axis(frame.to_working(layer.axis));
        let reference = plate_reference(
            C64::new(n1 * n1, 0.0),
            to_array(&working.permittivity()),
            C64::new(n3 * n3, 0.0),
            beta,
            d / lambda,
        );
        let (r, t) = (j.r.unwrap(), j.t.unwrap());
        let mut e = 0.0f64;
        for o in 0..2 {
            for i in 0..2 {
                e = e.max((r[(o, i)].norm_sqr() - reference.power_r[(o, i)]).abs());
                e = e.max((t[(o, i)].norm_sqr() - reference.power_t[(o, i)]).abs());
            }
        }
        if e > worst {
            worst = e;
            worst_case =
                format!("n1 {n1} n3 {n3} layer {layer:?} d {d} theta {theta} lambda {lambda}");
        }
        tir += usize::from(beta.re > n3);
        thick_dichroic += usize::from(d > 1e5 && (eta_o.im - eta_e.im).abs() > 0.5);
        cases += 1;
    }
    println!("slab vs Berreman: {cases} plates ({tir} with TIR inside, {thick_dichroic} thick and strongly dichroic), worst power error {worst:e}");
    println!("worst case: {worst_case}");
    assert!(tir > 100 && thick_dichroic > 20);
    assert!(worst < 1e-9, "worst {worst:e}");
}
