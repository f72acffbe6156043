//! Path-tracer lobes: every source found by time reversal really sends light along `wi`,
//! Radiance and Importance agree on the isotropic dielectric (Mitsuba's own weights), and
//! energy is conserved in Importance mode.

use birefringent::optics::medium::Uniaxial;
use birefringent::optics::surface::Surface;
use birefringent::params::Thickness;
use birefringent::render::crystal::crystal_lobes;
use birefringent::render::Transport;
use birefringent::C64;
use nalgebra::Vector3;

mod common;
use common::Rng;

#[test]
fn every_time_reversed_source_is_found_and_importance_conserves_energy() {
    let mut rng = Rng::new(31);
    let (mut cases, mut missing, mut worst) = (0, 0, 0.0f64);
    for _ in 0..5_000 {
        let crystal = Uniaxial::new(
            C64::new(rng.range(1.3, 2.0), 0.0),
            C64::new(rng.range(1.3, 2.0), 0.0),
            rng.unit_vector(),
        )
        .unwrap();
        let s = Surface::new(C64::new(1.0, 0.0), crystal).unwrap();
        let wi = rng.unit_vector();
        if wi.z.abs() < 0.05 {
            continue;
        }
        let imp = crystal_lobes(&s, wi, Transport::Importance).unwrap();
        let rad = crystal_lobes(&s, wi, Transport::Radiance).unwrap();
        cases += 1;
        if rad.len() != imp.len() {
            missing += 1;
        }
        // Importance from outside: unpolarised power is conserved (lossless).
        if wi.z > 0.0 {
            let total: f64 = imp.iter().map(|l| l.weight).sum();
            worst = worst.max((total - 1.0).abs());
        }
    }
    println!("{cases} cases, {missing} with a missing source, worst energy error {worst:e}");
    assert_eq!(missing, 0);
    assert!(worst < 1e-11);
}

#[test]
fn isotropic_crystal_weights_are_mitsubas_dielectric_weights() {
    // Mitsuba 3.9.1's dielectric (int 1.5, ext 1.0) at wi = 60 deg, Radiance mode: R weight /
    // pdf has M00 = 1 with pdf = R = 0.08919; T has M00/pdf = 1/1.5² (docs/mitsuba.md §3).
    let s = Surface::new(
        C64::new(1.0, 0.0),
        Uniaxial::isotropic(C64::new(1.5, 0.0)).unwrap(),
    )
    .unwrap();
    let (t, p) = (60f64.to_radians(), 30f64.to_radians());
    let wi = Vector3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
    let rad = crystal_lobes(&s, wi, Transport::Radiance).unwrap();
    let r = rad.iter().find(|l| l.component == 0).unwrap();
    let tr = rad.iter().find(|l| l.component == 1).unwrap();
    assert!((r.weight - 0.08919).abs() < 1e-5, "{}", r.weight);
    assert!((r.wo - Vector3::new(-0.75, -0.433013, 0.5)).norm() < 1e-5);
    assert!((tr.wo - Vector3::new(-0.5, -0.288675, -0.816497)).norm() < 1e-5);
    assert!((tr.weight / (1.0 - r.weight) - 1.0 / 2.25).abs() < 1e-12);
    assert!((tr.eta - 1.5).abs() < 1e-12);
    let imp = crystal_lobes(&s, wi, Transport::Importance).unwrap();
    let ti = imp.iter().find(|l| l.component == 1).unwrap();
    assert!(
        (ti.weight - (1.0 - r.weight)).abs() < 1e-12,
        "no radiance scaling in Importance"
    );
}

/// The intensity-only contract (`PlateCall::intensity_only` of the bridge): only M00 is computed, every other
/// Mueller entry is zero, and M00 equals the full query's; exact and band-filtered, isotropic
/// and birefringent plates (the fuzzer found the exact birefringent plate returning all 16).
#[test]
fn intensity_only_plate_queries_return_m00_alone() {
    use birefringent::material::Material;
    use birefringent::render::plate::{plate_lobes, PlateQuery};
    use birefringent::render::thin::Spectrum;
    let mut rng = Rng::new(33);
    for i in 0..200 {
        let material = if i % 2 == 0 {
            Material::constant(C64::new(1.5, 0.0), C64::new(1.5, 0.0)).unwrap()
        } else {
            Material::named("quartz", 0.0, 0.0).unwrap()
        };
        let query = |intensity| {
            PlateQuery::new(
                material,
                0.0,
                C64::new(1.0, 0.0),
                C64::new(1.2, 0.0),
                Vector3::new(1.0, 0.5, 0.3),
                Thickness::from_nm(20_000.0).unwrap(),
                true,
                true,
                intensity,
            )
            .unwrap()
        };
        let fwhm_nm = if i % 4 < 2 { 0.0 } else { 4.0 };
        let s = Spectrum::Band {
            wavelength_nm: rng.range(400.0, 700.0),
            fwhm_nm,
        };
        let wi = rng.unit_vector();
        if wi.z.abs() < 0.05 {
            continue;
        }
        let m00 = plate_lobes(&query(true), &s, wi, Transport::Radiance).unwrap();
        let full = plate_lobes(&query(false), &s, wi, Transport::Radiance).unwrap();
        for (a, b) in m00[0].iter().zip(&full[0]) {
            let (Some(a), Some(b)) = (a, b) else { continue };
            assert!((a.mueller[(0, 0)] - b.mueller[(0, 0)]).abs() < 1e-12);
            let rest: f64 = a.mueller.iter().skip(1).map(|x| x.abs()).sum();
            assert_eq!(rest, 0.0, "intensity-only query returned {}", a.mueller);
        }
    }
}

/// An absorbing exit medium: the reflection lobe of the plain plate alone from above, nothing
/// from below.
#[test]
fn absorbing_exit_keeps_the_front_reflection_only() {
    use birefringent::material::Material;
    use birefringent::render::plate::{plate_lobes, PlateQuery};
    use birefringent::render::thin::Spectrum;
    let mut rng = Rng::new(34);
    let q = PlateQuery::new(
        Material::named("quartz", 0.0, 0.0).unwrap(),
        0.0,
        C64::new(1.0, 0.0),
        C64::new(1.458, 0.0),
        Vector3::new(1.0, 1.0, 0.0),
        Thickness::from_nm(700.0).unwrap(),
        true,
        true,
        false,
    )
    .unwrap();
    let black = q.with_absorbing_exit(true);
    for _ in 0..200 {
        let wi = rng.unit_vector();
        let s = Spectrum::Band {
            wavelength_nm: rng.range(400.0, 700.0),
            fwhm_nm: 4.0,
        };
        for t in [Transport::Radiance, Transport::Importance] {
            let (a, b) = (
                plate_lobes(&black, &s, wi, t).unwrap(),
                plate_lobes(&q, &s, wi, t).unwrap(),
            );
            assert!(a[0][1].is_none(), "a transmission lobe");
            if wi.z < 0.0 {
                assert!(
                    a[0][0].is_none(),
                    "light from inside the absorbing exit medium"
                );
            } else if let (Some(x), Some(y)) = (a[0][0], b[0][0]) {
                assert_eq!(x.mueller, y.mueller);
            } else {
                panic!("reflection lobe missing for {wi:?}");
            }
        }
    }
}

/// Linear sRGB channels are signed: a film whose reflected colour lies outside the sRGB gamut
/// (lithium niobate, 0.285 um, on silica: a saturated cyan-green, R < 0) keeps its negative R in
/// the plugin's lobe, equal to the plate integrated over the sRGB weights (only the rounding
/// guard of non-negative weights clamps at 0). Before this test the lobe clamped R to 0: the
/// thin_film scene's scalar_rgb image was 0.06 (in units of the light) too red there.
#[test]
fn srgb_lobes_keep_negative_channels() {
    use birefringent::colour::weights::WeightSet;
    use birefringent::material::Material;
    use birefringent::optics::frame::PlaneFrame;
    use birefringent::plate::slab::Output;
    use birefringent::plate::slab::Want;
    use birefringent::quadrature::Accuracy;
    use birefringent::render::plate::{plate_lobes, PlateQuery};
    use birefringent::render::thin::Spectrum;
    use birefringent::spectral::model::{PlateModel, ThinModel};
    let q = PlateQuery::new(
        Material::named("linbo3", 0.0, 0.0).unwrap(),
        0.0,
        C64::new(1.0, 0.0),
        C64::new(1.458, 0.0),
        Vector3::new(1.0, 0.0, 0.0),
        Thickness::from_nm(285.0).unwrap(),
        true,
        true,
        true,
    )
    .unwrap()
    .with_absorbing_exit(true);
    let theta = 40f64.to_radians();
    let wi = Vector3::new(0.0, -theta.sin(), theta.cos());
    let spectrum = Spectrum::Weights(WeightSet::SrgbD65);
    let lobes = plate_lobes(&q, &spectrum, wi, Transport::Radiance).unwrap();
    // Radiance: the core solves the plate for light arriving from the reflected direction.
    let wo = Vector3::new(0.0, theta.sin(), theta.cos());
    let direct = PlateModel::new(
        &q.element,
        PlaneFrame::from_direction(wo),
        C64::new(theta.sin(), 0.0),
    )
    .channels(
        WeightSet::SrgbD65,
        Want {
            reflection: true,
            transmission: false,
        },
        Output::Intensity,
        Accuracy::Perceptual,
    )
    .unwrap();
    let r = lobes[0][0].unwrap().weight;
    let expected = direct[0].r.unwrap()[(0, 0)];
    assert!(expected < -0.01, "R = {expected}: not out of gamut");
    // Same computation through the lobe (scale 1 in reflection): equal to rounding.
    assert!((r - expected).abs() < 1e-12, "lobe R {r} vs {expected}");
}

/// Unpolarised, linear and phase terms of the Fresnel reflection from a clear medium `n1` onto
/// `eta` at incidence cosine `cos1` (textbook amplitudes, `n + iκ` convention):
/// `((|r_s|² + |r_p|²)/2, (|r_s|² − |r_p|²)/2, r_s r_p*)`.
fn fresnel_reflection(n1: f64, eta: C64, cos1: f64) -> (f64, f64, C64) {
    let n1 = C64::new(n1, 0.0);
    let c1 = C64::new(cos1, 0.0);
    let c2 = (eta * eta - n1 * n1 * (1.0 - cos1 * cos1)).sqrt() / eta;
    let rs = (n1 * c1 - eta * c2) / (n1 * c1 + eta * c2);
    let rp = (eta * c1 - n1 * c2) / (eta * c1 + n1 * c2);
    let (a, b) = (rs.norm_sqr(), rp.norm_sqr());
    (0.5 * (a + b), 0.5 * (a - b), rs * rp.conj())
}

/// An absorbing (isotropic) bulk surface is opaque, like Mitsuba's `conductor`
/// (src/render/crystal.rs): from outside the reflection lobe alone, in both transport modes,
/// its Mueller matrix the closed-form Fresnel reflection of the complex index in the s/p frame
/// (Stokes x = s) to 3e-12 (the same amplitudes by another route: measured 2.4e-13 for κ ≥ 1,
/// 9.8e-13 for 1.7 + 0.01i under an exterior of 1.5 at cos θ = 1e-3, near grazing); from
/// inside no lobes (before: Importance returned lobes with weights up to 2.07 for 1.5 + 3i,
/// found by the fuzzer, and from outside a refraction lobe whose Radiance weight was 1470 for
/// silver at normal incidence). Conductors (silver, a gold-like index, the smallest accepted
/// real part with κ = 1) and lossy dielectrics, down to κ = 1e-9 (any absorption makes the bulk
/// opaque: with "opaque" decided above a tolerance, κ = 1e-3 refracted 90 % of the samples and
/// gained energy from inside), exteriors 1 and 1.5.
#[test]
fn absorbing_bulk_surface_is_opaque_like_a_conductor() {
    let mut rng = Rng::new(35);
    let mut worst = 0.0f64;
    for eta in [
        C64::new(0.136125, 4.010625),
        C64::new(0.18, 3.1),
        C64::new(1e-3, 1.0),
        C64::new(1.5, 1.0),
        C64::new(0.5, 1.0),
        C64::new(1.5, 3.0),
        C64::new(1.7, 1e-2),
        C64::new(1.33, 1e-3),
        C64::new(2.4, 1e-6),
        C64::new(1.5, 1e-9),
    ] {
        for ext in [1.0, 1.5] {
            let crystal = Uniaxial::isotropic(eta).unwrap();
            let s = Surface::new(C64::new(ext, 0.0), crystal).unwrap();
            for _ in 0..300 {
                let wi = rng.unit_vector();
                if wi.z.abs() < 1e-3 {
                    continue;
                }
                let mut matrices = Vec::new();
                for t in [Transport::Radiance, Transport::Importance] {
                    let lobes = crystal_lobes(&s, wi, t).unwrap();
                    if wi.z < 0.0 {
                        assert!(lobes.is_empty(), "{eta}: {lobes:?} from inside");
                        continue;
                    }
                    assert_eq!(lobes.len(), 1, "{eta} {t:?}: {lobes:?}");
                    let l = &lobes[0];
                    assert_eq!(l.component, 0);
                    // Rounding of the general event's ray directions: measured 1.2e-13.
                    let dw = (l.wo - Vector3::new(-wi.x, -wi.y, wi.z)).norm();
                    assert!(dw < 1e-12, "{dw:e}");
                    assert_eq!(l.eta, 1.0);
                    // s axis of both frames: perpendicular to the plane of incidence.
                    let s_axis = Vector3::z().cross(&wi).normalize();
                    for x in [l.in_stokes_x, l.out_stokes_x] {
                        assert!(x.cross(&s_axis).norm() < 1e-12, "{x:?} vs {s_axis:?}");
                    }
                    let (a, b, c) = fresnel_reflection(ext, eta, wi.z);
                    let m = l.mueller;
                    let sign =
                        l.in_stokes_x.dot(&s_axis).signum() * l.out_stokes_x.dot(&s_axis).signum();
                    let want = nalgebra::Matrix4::new(
                        a,
                        b,
                        0.0,
                        0.0, //
                        b,
                        a,
                        0.0,
                        0.0, //
                        0.0,
                        0.0,
                        sign * c.re,
                        m[(2, 3)], //
                        0.0,
                        0.0,
                        m[(3, 2)],
                        sign * c.re,
                    );
                    worst = worst.max((m - want).abs().max());
                    worst = worst.max((m[(2, 3)].abs() - c.im.abs()).abs());
                    worst = worst.max((m[(2, 3)] + m[(3, 2)]).abs());
                    assert_eq!(l.weight, m[(0, 0)]);
                    matrices.push(m);
                }
                if wi.z > 0.0 {
                    // Reflection is reciprocal: both modes carry the same matrix.
                    worst = worst.max((matrices[0] - matrices[1]).abs().max());
                }
            }
        }
    }
    println!("opaque absorbing bulk: worst |M - closed form| = {worst:e}");
    assert!(worst < 3e-12);
}

/// A band narrower than `EXACT_BAND` of its wavelength is the exact single-wavelength result;
/// a subnormal width (5e-324 nm, found by the fuzzer) gave NaN before (its Gaussian's width in
/// wavenumber underflowed to 0).
#[test]
fn vanishing_bandwidth_is_exact() {
    use birefringent::material::Material;
    use birefringent::render::plate::{plate_lobes, PlateQuery};
    use birefringent::render::thin::Spectrum;
    let q = PlateQuery::new(
        Material::named("quartz", 0.0, 0.0).unwrap(),
        0.0,
        C64::new(1.0, 0.0),
        C64::new(1.5, 0.0),
        Vector3::new(1.0, 0.5, 0.3),
        Thickness::from_nm(20_000.0).unwrap(),
        true,
        true,
        false,
    )
    .unwrap();
    let wi = Vector3::new(0.3, 0.2, 0.9).normalize();
    let band = |fwhm_nm| Spectrum::Band {
        wavelength_nm: 550.0,
        fwhm_nm,
    };
    let exact = plate_lobes(&q, &band(0.0), wi, Transport::Radiance).unwrap();
    for tiny in [5e-324, 1e-300, 1e-12] {
        let got = plate_lobes(&q, &band(tiny), wi, Transport::Radiance).unwrap();
        assert_eq!(got, exact, "fwhm {tiny}");
    }
    // Just above the threshold the band is integrated (and still finite).
    let above = plate_lobes(&q, &band(1e-6), wi, Transport::Radiance).unwrap();
    assert!(above[0]
        .iter()
        .flatten()
        .all(|l| l.mueller.iter().all(|x| x.is_finite())));
}
