//! The slab against closed forms: Airy/etalon amplitudes for an isotropic layer, energy
//! conservation, the retarder limit, the incoherent thick-plate limit (Mitsuba's
//! `thindielectric` formula), and the path expansion against the exact sum.

use birefringent::optics::frame::PlaneFrame;
use birefringent::optics::medium::Uniaxial;
use birefringent::params::Thickness;
use birefringent::plate::paths::PathExpansion;
use birefringent::plate::slab::{Slab, Want};
use birefringent::C64;
use nalgebra::{Matrix2, Vector3};

mod common;
use common::Rng;

fn re(x: f64) -> C64 {
    C64::new(x, 0.0)
}

/// Textbook interface amplitudes (r_s, r_p, t_s, t_p) from index n1 to n2 at incidence
/// parameter beta (p basis k̂ × ŝ).
fn fresnel(n1: C64, n2: C64, beta: f64) -> [C64; 4] {
    let b2 = re(beta * beta);
    let w1 = (n1 * n1 - b2).sqrt();
    let w2 = (n2 * n2 - b2).sqrt();
    let rs = (w1 - w2) / (w1 + w2);
    let rp = (n2 * n2 * w1 - n1 * n1 * w2) / (n2 * n2 * w1 + n1 * n1 * w2);
    let ts = re(2.0) * w1 / (w1 + w2);
    let tp = re(2.0) * n1 * n2 * w1 / (n2 * n2 * w1 + n1 * n1 * w2);
    [rs, rp, ts, tp]
}

#[test]
fn isotropic_layer_is_the_airy_etalon() {
    let mut worst = 0.0f64;
    for (n1, n2, n3) in [
        (1.0, 1.5, 1.0),
        (1.0, 2.4, 1.33),
        (1.2, C64::new(1.8, 0.05).re, 1.0),
    ] {
        let (n1, n3) = (re(n1), re(n3));
        for n2 in [re(n2), C64::new(n2, 0.02)] {
            for d in [10.0, 333.0, 2500.0, 1e5] {
                for deg in [0.0, 20.0, 45.0, 70.0, 85.0] {
                    let beta = n1.re * f64::to_radians(deg).sin();
                    let slab = Slab::new(
                        n1,
                        Uniaxial::isotropic(n2).unwrap(),
                        n3,
                        Thickness::from_nm(d).unwrap(),
                    )
                    .unwrap();
                    let optics = slab
                        .optics(&PlaneFrame::from_azimuth(0.4), re(beta))
                        .unwrap();
                    let lambda = 550.0;
                    let j = optics.jones(lambda, Want::BOTH).unwrap();
                    let (r, t) = (j.r.unwrap(), j.t.unwrap());
                    let a = fresnel(n1, n2, beta);
                    let b = fresnel(n2, n3, beta);
                    let q2 = (n2 * n2 - re(beta * beta)).sqrt();
                    let ph = (C64::new(0.0, std::f64::consts::TAU * d / lambda) * q2).exp();
                    // Airy: r = (r12 + r23 e^{2iδ}) / (1 + r12 r23 e^{2iδ}), t = t12 t23 e^{iδ} / (...)
                    let flux = ((n3 * n3 - re(beta * beta)).sqrt()
                        / (n1 * n1 - re(beta * beta)).sqrt())
                    .re;
                    for (k, (rk, tk)) in [
                        (0usize, (r[(0, 0)], t[(0, 0)])),
                        (1, (r[(1, 1)], t[(1, 1)])),
                    ] {
                        let den = re(1.0) + a[k] * b[k] * ph * ph;
                        let r_want = (a[k] + b[k] * ph * ph) / den;
                        let mut t_want = a[2 + k] * b[2 + k] * ph / den;
                        // Flux normalisation (eq. S19): |t|² is the power fraction.
                        t_want *= flux.sqrt();
                        let e = (rk - r_want).norm().max((tk - t_want).norm());
                        if e > 1e-12 {
                            println!("{n1} {n2} {n3} d {d} deg {deg} k {k}: r {rk} vs {r_want}, t {tk} vs {t_want}");
                        }
                        worst = worst.max(e);
                    }
                    assert!(
                        r[(0, 1)].norm() + r[(1, 0)].norm() + t[(0, 1)].norm() + t[(1, 0)].norm()
                            < 1e-14
                    );
                }
            }
        }
    }
    println!("Airy: worst amplitude error {worst:e}");
    assert!(worst < 1e-12);
}

#[test]
fn lossless_slabs_conserve_energy() {
    let mut rng = Rng::new(21);
    let mut worst = 0.0f64;
    for _ in 0..5_000 {
        let layer = Uniaxial::new(
            re(rng.range(1.3, 2.7)),
            re(rng.range(1.3, 2.7)),
            rng.unit_vector(),
        )
        .unwrap();
        let (n1, n3) = (rng.range(1.0, 1.6), rng.range(1.0, 1.6));
        let d = 10f64.powf(rng.range(1.0, 6.7));
        let slab = Slab::new(re(n1), layer, re(n3), Thickness::from_nm(d).unwrap()).unwrap();
        let beta = n1 * rng.range(0.0, 85f64.to_radians()).sin();
        let optics = slab
            .optics(&PlaneFrame::from_azimuth(rng.range(0.0, 6.3)), re(beta))
            .unwrap();
        let j = optics.jones(rng.range(380.0, 780.0), Want::BOTH).unwrap();
        let (r, t) = (j.r.unwrap(), j.t.unwrap());
        for col in 0..2 {
            let p: f64 = (0..2)
                .map(|row| r[(row, col)].norm_sqr() + t[(row, col)].norm_sqr())
                .sum();
            worst = worst.max((p - 1.0).abs());
        }
    }
    println!("slab energy: worst |R+T-1| = {worst:e}");
    assert!(worst < 1e-11);
}

#[test]
fn normal_incidence_direct_path_is_a_linear_retarder_with_fresnel_factors() {
    let (no, ne, d, lambda) = (1.5443, 1.5534, 15_100.0, 589.3);
    for a in [0.0, 0.4, 1.1] {
        let axis = Vector3::new(f64::cos(a), f64::sin(a), 0.0);
        let slab = Slab::new(
            re(1.0),
            Uniaxial::new(re(no), re(ne), axis).unwrap(),
            re(1.0),
            Thickness::from_nm(d).unwrap(),
        )
        .unwrap();
        let frame = PlaneFrame::from_azimuth(0.0);
        let optics = slab.optics(&frame, re(0.0)).unwrap();
        let paths = PathExpansion::new(&optics, 0, lambda, Want::BOTH);
        let (_, j0) = paths.jones(lambda);
        // Expected: R(axis) diag(τ_e e^{iφ_e}, τ_o e^{iφ_o}) R(axis)ᵀ in the s/p basis.
        let tau = |n: f64| 2.0 / (1.0 + n) * 2.0 * n / (n + 1.0);
        let k = std::f64::consts::TAU * d / lambda;
        let (eo, ee) = (
            C64::from_polar(tau(no), k * no),
            C64::from_polar(tau(ne), k * ne),
        );
        // s and p unit vectors of the frame in local coordinates: s = frame.s, p_in = k̂ × s = (−ẑ) × s.
        let s = frame.s;
        let p = Vector3::new(0.0, 0.0, -1.0).cross(&s);
        let (ca, cs) = (axis.dot(&s), axis.dot(&p));
        let e = |x: Vector3<f64>| -> Matrix2<C64> {
            // Projector onto the e (axis) and o (perpendicular) directions in the (s, p) basis.
            let v = nalgebra::Vector2::new(re(x.dot(&s)), re(x.dot(&p)));
            v * v.transpose()
        };
        let o_dir = Vector3::new(0.0, 0.0, -1.0).cross(&axis);
        let want = e(axis) * ee + e(o_dir) * eo;
        assert!(
            (j0 - want).norm() < 1e-12,
            "axis angle {a}: {j0} vs {want} ({ca}, {cs})"
        );
        // Retardance 2π (n_e − n_o) d / λ.
        let ret = (ee / eo).arg();
        let expect =
            (std::f64::consts::TAU * (ne - no) * d / lambda).rem_euclid(std::f64::consts::TAU);
        let got = ret.rem_euclid(std::f64::consts::TAU);
        assert!((got - expect).abs() < 1e-10);
    }
}

#[test]
fn thick_isotropic_plate_incoherent_limit_is_the_thindielectric_series() {
    // Averaging the exact slab over a band much wider than its fringe spacing gives, per
    // polarisation, R' = R + T² R / (1 − R²) = 2R / (1 + R) (the series Mitsuba's
    // thindielectric sums); at normal incidence (R_s = R_p) that is thindielectric's M00 exactly.
    let n = 1.5;
    let d = 2e6; // 2 mm
    for deg in [0.0, 30.0, 60.0] {
        let beta = f64::to_radians(deg).sin();
        let slab = Slab::new(
            re(1.0),
            Uniaxial::isotropic(re(n)).unwrap(),
            re(1.0),
            Thickness::from_nm(d).unwrap(),
        )
        .unwrap();
        let optics = slab
            .optics(&PlaneFrame::from_azimuth(0.0), re(beta))
            .unwrap();
        // Average over exactly 20 fringes, uniformly in wavenumber k (the round-trip phase is
        // 2 k q d with q = sqrt(n² − β²)): a periodic trapezoid sum, exact to rounding.
        let (mut rs, mut rp, mut m00) = (0.0, 0.0, 0.0);
        let steps = 4_000;
        let q = (n * n - beta * beta).sqrt();
        let (k0, dk) = (
            std::f64::consts::TAU / 550.0,
            20.0 * std::f64::consts::PI / (q * d),
        );
        for i in 0..steps {
            let lambda = std::f64::consts::TAU / (k0 + dk * i as f64 / steps as f64);
            let j = optics.jones(lambda, Want::BOTH).unwrap();
            let r = j.r.unwrap();
            rs += r[(0, 0)].norm_sqr() / steps as f64;
            rp += r[(1, 1)].norm_sqr() / steps as f64;
            m00 += birefringent::optics::mueller::from_jones(&r)[(0, 0)] / steps as f64;
        }
        let f = fresnel(re(1.0), re(n), beta);
        let (r1s, r1p) = (f[0].norm_sqr(), f[1].norm_sqr());
        let series = |r: f64| 2.0 * r / (1.0 + r);
        assert!(
            (rs - series(r1s)).abs() < 1e-12,
            "{deg}: s {rs} vs {}",
            series(r1s)
        );
        assert!(
            (rp - series(r1p)).abs() < 1e-12,
            "{deg}: p {rp} vs {}",
            series(r1p)
        );
        // The closed-form incoherent tail with N = 0 gives the same without sampling.
        let paths = PathExpansion::new(&optics, 0, 550.0, Want::BOTH);
        let incoherent: f64 = paths
            .reflection
            .iter()
            .map(|c| birefringent::optics::mueller::from_jones(&c.amplitude)[(0, 0)])
            .sum::<f64>()
            + paths.tail.r[(0, 0)];
        assert!((incoherent - 0.5 * (series(r1s) + series(r1p))).abs() < 1e-12);
        if deg == 0.0 {
            let r = 0.5 * (r1s + r1p);
            assert!(
                (m00 - 2.0 * r / (1.0 + r)).abs() < 1e-12,
                "thindielectric at normal incidence"
            );
        }
    }
}

#[test]
fn path_expansion_to_high_order_equals_the_exact_slab() {
    let mut rng = Rng::new(23);
    let mut worst = 0.0f64;
    for case in 0..300 {
        let layer = Uniaxial::new(
            C64::new(
                rng.range(1.3, 2.7),
                if case % 3 == 0 {
                    rng.range(0.0, 0.05)
                } else {
                    0.0
                },
            ),
            re(rng.range(1.3, 2.7)),
            rng.unit_vector(),
        )
        .unwrap();
        let slab = Slab::new(
            re(1.0),
            layer,
            re(rng.range(1.0, 1.6)),
            Thickness::from_nm(rng.range(50.0, 5000.0)).unwrap(),
        )
        .unwrap();
        let beta = rng.range(0.0, 0.95);
        let optics = slab
            .optics(&PlaneFrame::from_azimuth(rng.range(0.0, 6.3)), re(beta))
            .unwrap();
        let lambda = rng.range(400.0, 700.0);
        let exact = optics.jones(lambda, Want::BOTH).unwrap();
        let paths = PathExpansion::new(&optics, 30, lambda, Want::BOTH);
        let (r, t) = paths.jones(lambda);
        worst = worst
            .max((r - exact.r.unwrap()).norm())
            .max((t - exact.t.unwrap()).norm());
    }
    println!("path expansion (N = 30) vs exact: worst {worst:e}");
    // Rounding of a sum over up to ~10^4 complex terms of magnitude <= 1.
    assert!(worst < 1e-11);
}
