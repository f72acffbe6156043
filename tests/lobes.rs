//! Renderer lobes of a surface event: energy, Stokes frames, and the isotropic limit against
//! Mitsuba's own Fresnel Mueller matrices (`mueller::specular_reflection/transmission` of
//! Mitsuba 3.9.1, re-derived here from their published formulas, not from our code).

use birefringent::optics::lobes::{scatter, Event, Lobe};
use birefringent::optics::medium::Uniaxial;
use birefringent::optics::modes::ModeKind;
use birefringent::optics::surface::{Incident, Surface};
use birefringent::C64;
use nalgebra::{Matrix4, Vector3, Vector4};

mod common;
use common::Rng;

fn lobes(e: &Event) -> impl Iterator<Item = &Lobe> {
    e.reflected.iter().chain(e.transmitted.iter()).flatten()
}

fn total_power(e: &Event, stokes_in: Vector4<f64>) -> f64 {
    lobes(e).map(|l| (l.mueller * stokes_in)[0]).sum()
}

#[test]
fn lobes_conserve_energy_for_every_polarisation_and_frames_are_transverse() {
    let mut rng = Rng::new(11);
    let states = [
        Vector4::new(1.0, 0.0, 0.0, 0.0),
        Vector4::new(1.0, 1.0, 0.0, 0.0),
        Vector4::new(1.0, -1.0, 0.0, 0.0),
        Vector4::new(1.0, 0.0, 1.0, 0.0),
        Vector4::new(1.0, 0.0, 0.0, 1.0),
    ];
    let mut worst = 0.0f64;
    for case in 0..20_000 {
        let crystal = Uniaxial::new(
            C64::new(rng.range(1.3, 2.7), 0.0),
            C64::new(rng.range(1.3, 2.7), 0.0),
            rng.unit_vector(),
        )
        .unwrap();
        let s = Surface::new(C64::new(rng.range(1.0, 1.6), 0.0), crystal).unwrap();
        let mut w = rng.unit_vector();
        let incident = match case % 3 {
            0 => Incident::Outside,
            1 => Incident::Inside(ModeKind::O),
            _ => Incident::Inside(ModeKind::E),
        };
        let outside = matches!(incident, Incident::Outside);
        if (w.z > 0.0) != outside {
            w.z = -w.z;
        }
        if w.z.abs() < 1e-3 {
            continue;
        }
        let Ok(e) = scatter(&s, w, incident) else {
            panic!("scatter failed for {w:?}");
        };
        for l in lobes(&e) {
            assert!(
                l.stokes_x.dot(&l.direction).abs() < 1e-12,
                "Stokes x not transverse"
            );
            assert!((l.stokes_x.norm() - 1.0).abs() < 1e-12);
            assert!(l.direction.z * if outside { 1.0 } else { -1.0 } != 0.0);
        }
        let inputs: &[Vector4<f64>] = if outside { &states } else { &states[1..2] };
        for st in inputs {
            worst = worst.max((total_power(&e, *st) - 1.0).abs());
        }
    }
    println!("lobes: worst |sum S0 - 1| = {worst:e}");
    assert!(worst < 1e-11);
}

/// Mitsuba's `fresnel_polarized(cos_i, eta)` amplitudes (Verdet convention, index n − iκ,
/// transmitted cosine with Im(η cos_t) <= 0) for light from the side the normal points to.
fn mitsuba_amplitudes(cos_i: f64, eta: C64) -> (C64, C64) {
    let eta = eta.conj(); // Mitsuba's n − iκ
    let ci = C64::new(cos_i, 0.0);
    let mut w = (eta * eta - C64::new(1.0 - cos_i * cos_i, 0.0)).sqrt(); // η cos_t
    if w.im > 0.0 {
        w = -w;
    }
    let ct = w / eta;
    let a_s = (ci - eta * ct) / (ci + eta * ct);
    let a_p = (eta * ci - ct) / (eta * ci + ct);
    (a_s, a_p)
}

/// Mitsuba's `mueller::specular_reflection` from those amplitudes.
fn mitsuba_specular_reflection(cos_i: f64, eta: C64) -> Matrix4<f64> {
    let (a_s, a_p) = mitsuba_amplitudes(cos_i, eta);
    let (rs, rp) = (a_s.norm_sqr(), a_p.norm_sqr());
    let (a, b, c) = (0.5 * (rs + rp), 0.5 * (rs - rp), (rs * rp).sqrt());
    let d = a_p.arg() - a_s.arg();
    Matrix4::new(
        a,
        b,
        0.0,
        0.0,
        b,
        a,
        0.0,
        0.0,
        0.0,
        0.0,
        c * d.cos(),
        -c * d.sin(),
        0.0,
        0.0,
        c * d.sin(),
        c * d.cos(),
    )
}

#[test]
fn isotropic_crystal_reflection_is_mitsubas_dielectric_and_conductor() {
    let mut worst = 0.0f64;
    for eta in [
        C64::new(1.5, 0.0),
        C64::new(0.2, 3.1),
        C64::new(1.2, 7.0),
        C64::new(2.4, 0.3),
    ] {
        let s = Surface::new(C64::new(1.0, 0.0), Uniaxial::isotropic(eta).unwrap()).unwrap();
        for k in 0..=89 {
            let th = (k as f64 + 0.5).to_radians();
            let phi = 0.37 * k as f64;
            let w = Vector3::new(th.sin() * phi.cos(), th.sin() * phi.sin(), th.cos());
            let e = scatter(&s, w, Incident::Outside).unwrap();
            let r = e.reflected[0].unwrap();
            let want = mitsuba_specular_reflection(th.cos(), eta);
            worst = worst.max((r.mueller - want).abs().max());
            // Reflected direction and its s axis equal Mitsuba's (s = n × (−wo) normalised).
            let dr = (r.direction - Vector3::new(-w.x, -w.y, w.z)).norm();
            assert!(dr < 1e-13, "{dr:e} {eta} {th}");
            let s_axis = Vector3::z().cross(&w).normalize();
            assert!((r.stokes_x - s_axis).norm() < 1e-14 || (r.stokes_x + s_axis).norm() < 1e-14);
        }
    }
    println!("isotropic reflection vs Mitsuba formula: worst {worst:e}");
    assert!(worst < 1e-12);
}

#[test]
fn isotropic_crystal_total_internal_reflection_is_a_pure_retarder() {
    // From inside glass (1.5) at 50 deg: Mitsuba's dielectric gives cos Δ = 0.708, sin Δ = 0.706
    // (docs/mitsuba.md §3); specular_reflection(cos, 1/1.5) reproduces it.
    let s = Surface::new(
        C64::new(1.0, 0.0),
        Uniaxial::isotropic(C64::new(1.5, 0.0)).unwrap(),
    )
    .unwrap();
    let th = 50f64.to_radians();
    let w = Vector3::new(th.sin(), 0.0, -th.cos());
    let e = scatter(&s, w, Incident::Inside(ModeKind::O)).unwrap();
    let r = e.reflected[0].unwrap();
    assert!(e.transmitted[0].is_none(), "no transmission under TIR");
    let want = mitsuba_specular_reflection(th.cos(), C64::new(1.0 / 1.5, 0.0));
    assert!((r.mueller - want).abs().max() < 1e-12, "{}", r.mueller);
    assert!(
        (r.mueller[(2, 2)] - 0.708).abs() < 1e-3 && (r.mueller[(3, 2)].abs() - 0.706).abs() < 1e-3
    );
}

#[test]
fn isotropic_crystal_transmission_is_mitsubas_specular_transmission() {
    let eta = 1.5;
    let s = Surface::new(
        C64::new(1.0, 0.0),
        Uniaxial::isotropic(C64::new(eta, 0.0)).unwrap(),
    )
    .unwrap();
    for k in 0..89 {
        let th = (k as f64 + 0.5).to_radians();
        let w = Vector3::new(th.sin(), 0.0, th.cos());
        let e = scatter(&s, w, Incident::Outside).unwrap();
        let t = e.transmitted[0].unwrap();
        assert!(e.transmitted[1].is_none());
        let (a_s, a_p) = mitsuba_amplitudes(th.cos(), C64::new(eta, 0.0));
        let (ts, tp) = (1.0 - a_s.norm_sqr(), 1.0 - a_p.norm_sqr());
        let want = Matrix4::new(
            0.5 * (ts + tp),
            0.5 * (ts - tp),
            0.0,
            0.0,
            0.5 * (ts - tp),
            0.5 * (ts + tp),
            0.0,
            0.0,
            0.0,
            0.0,
            (ts * tp).sqrt(),
            0.0,
            0.0,
            0.0,
            0.0,
            (ts * tp).sqrt(),
        );
        assert!(
            (t.mueller - want).abs().max() < 1e-12,
            "{th}: {}",
            t.mueller
        );
    }
}

#[test]
fn crystal_waves_are_linearly_polarised_along_their_field() {
    // A lossless crystal wave's Stokes vector is (P, P, 0, 0) in its frame for any input.
    let crystal = Uniaxial::new(
        C64::new(1.6584, 0.0),
        C64::new(1.4864, 0.0),
        Vector3::new(0.3, 0.5, 0.8),
    )
    .unwrap();
    let s = Surface::new(C64::new(1.0, 0.0), crystal).unwrap();
    let w = Vector3::new(0.4, -0.3, (1.0f64 - 0.25).sqrt());
    let e = scatter(&s, w, Incident::Outside).unwrap();
    for l in e.transmitted.iter().flatten() {
        for st in [
            Vector4::new(1.0, 0.3, -0.2, 0.5),
            Vector4::new(1.0, -1.0, 0.0, 0.0),
        ] {
            let out = l.mueller * st;
            assert!(
                (out[0] - out[1]).abs() < 1e-13 && out[2].abs() < 1e-13 && out[3].abs() < 1e-13
            );
        }
    }
}
