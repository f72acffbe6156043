//! The isotropic fast paths against the full computation they replace: the closed-form
//! Fresnel interface against the 4x4 boundary solve, and the etalon plate (exact and
//! band-integrated) against the general slab and the general band integration.

use birefringent::band::narrow_band;
use birefringent::colour::weights::{gaussians, WeightSet};
use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::optics::interface::Interface;
use birefringent::optics::medium::Uniaxial;
use birefringent::optics::modes::modes;
use birefringent::params::Thickness;
use birefringent::plate::etalon::Etalon;
use birefringent::plate::slab::Output;
use birefringent::plate::slab::Want;
use birefringent::plate::Plate;
use birefringent::quadrature::Accuracy;
use birefringent::spectral::gaussian::{band_with, Method};
use birefringent::spectral::model::{PlateModel, ThinModel};
use birefringent::C64;
use nalgebra::{Matrix4, Vector3};

mod common;
use common::Rng;

fn re(x: f64) -> C64 {
    C64::new(x, 0.0)
}

/// Random isotropic pair, incidence up to grazing from the upper medium, both sides clear or
/// the lower one absorbing (a metal-like or dyed medium); TIR whenever n1 > n2.
#[test]
fn fresnel_interface_equals_the_4x4_solve() {
    let mut rng = Rng::new(71);
    let (mut worst, mut tir) = (0.0f64, 0);
    for _ in 0..20_000 {
        let n1 = rng.range(1.0, 3.0);
        let n2 = if rng.chance(0.25) {
            C64::new(rng.range(0.1, 3.0), rng.range(0.0, 8.0))
        } else {
            re(rng.range(1.0, 3.0))
        };
        let beta = re(n1 * rng.range(0.0, 0.99999));
        tir += usize::from(beta.re > n2.re && n2.im == 0.0);
        let (a, b) = (
            Uniaxial::isotropic(re(n1)).unwrap(),
            Uniaxial::isotropic(n2).unwrap(),
        );
        let fast = Interface::new(&a, &b, beta).unwrap();
        let full = Interface::from_modes(modes(&a, beta), modes(&b, beta)).unwrap();
        let err = (fast.s - full.s).norm() / full.s.norm();
        worst = worst.max(err);
    }
    println!("Fresnel vs 4x4: worst relative difference of S {worst:e} ({tir} TIR cases)");
    // Both are direct solves of the same 4 equations (the 4x4 with partial pivoting): they
    // agree to rounding, amplified at most by the conditioning near grazing (1e-5 from it).
    assert!(worst < 1e-11, "{worst:e}");
    assert!(tir > 1000);
}

fn random_isotropic_plate(rng: &mut Rng, thickness_nm: f64) -> Plate {
    let n = rng.range(1.05, 2.6);
    Plate {
        material: Material::constant(re(n), re(n)).unwrap(),
        birefringence: 0.0,
        ext: re(rng.range(1.0, 1.8)),
        exit: re(rng.range(1.0, 2.0)),
        axis: rng.unit_vector(),
        thickness_nm,
    }
}

fn frame_beta(rng: &mut Rng, plate: &Plate, max_deg: f64) -> (PlaneFrame, C64) {
    let frame = PlaneFrame::from_azimuth(rng.range(0.0, std::f64::consts::TAU));
    let theta = rng.range(0.0, max_deg).to_radians();
    (frame, plate.ext * theta.sin())
}

fn diff(a: &Option<Matrix4<f64>>, b: &Option<Matrix4<f64>>) -> f64 {
    (a.unwrap() - b.unwrap()).abs().max()
}

/// Exact plate at one wavelength: Airy closed form vs the general slab (4x4 interfaces,
/// `(I − D)⁻¹`), all 16 Mueller elements of R and T, thickness 10 nm to 5 mm, up to 89.9 deg,
/// TIR at the exit included.
#[test]
fn etalon_equals_the_general_slab_at_one_wavelength() {
    let mut rng = Rng::new(72);
    let (mut worst, mut tried) = (0.0f64, 0);
    for _ in 0..5_000 {
        let d = 10f64.powf(rng.range(1.0, 6.7));
        let plate = random_isotropic_plate(&mut rng, d);
        let (frame, beta) = frame_beta(&mut rng, &plate, 89.9);
        let lambda = rng.range(380.0, 780.0);
        let Some(e) = plate.etalon(lambda, beta) else {
            continue; // TIR at the top of the layer: the general path (tested below)
        };
        tried += 1;
        let fast = e.mueller(lambda, Want::BOTH, Output::Mueller);
        let full = plate
            .at(lambda)
            .unwrap()
            .optics(&frame, beta)
            .unwrap()
            .mueller(lambda, Want::BOTH)
            .unwrap();
        worst = worst
            .max(diff(&fast.r, &full.r))
            .max(diff(&fast.t, &full.t));
    }
    println!("etalon vs general slab: worst Mueller element difference {worst:e} over {tried}");
    // Power fractions <= 1; the phase k d w of a 5 mm plate is ~6e4 rad, so both carry a
    // rounding error ~1e-16 * 6e4 in the phase: 1e-10 bounds the difference.
    assert!(worst < 1e-10, "{worst:e}");
    assert!(tried > 4_000);
}

/// Over a Gaussian band: the etalon's closed form (exact for Gaussians) vs composite
/// Gauss–Legendre quadrature of the exact general slab (200 panels of 8 nodes over ±6.5σ) for
/// thin plates, and vs the general path-class sum (coherent orders + incoherent tail) for thick
/// plates. Bands: 4 nm around one wavelength, and the sRGB Gaussians.
#[test]
fn etalon_band_equals_the_general_band_integration() {
    let mut rng = Rng::new(73);
    let (mut worst_thin, mut worst_thick) = (0.0f64, 0.0f64);
    let srgb: Vec<_> = (0..3)
        .flat_map(|c| gaussians(WeightSet::SrgbD65, c).iter())
        .collect();
    for i in 0..400 {
        let thick = i % 2 == 1;
        let d = if thick {
            10f64.powf(rng.range(5.0, 6.7)) // 100 um - 5 mm: incoherent beyond a few orders
        } else {
            10f64.powf(rng.range(1.0, 3.0)) // 10 nm - 1 um
        };
        let plate = random_isotropic_plate(&mut rng, d);
        let (frame, beta) = frame_beta(&mut rng, &plate, 80.0);
        let g = if rng.chance(0.5) {
            narrow_band(rng.range(400.0, 700.0), 4.0)
        } else {
            *srgb[rng.index(srgb.len())]
        };
        let band = [birefringent::band::Gaussian {
            amplitude: 1.0,
            ..g
        }];
        if plate.etalon(550.0, beta).is_none() {
            continue;
        }
        let model = PlateModel::new(&plate, frame, beta);
        assert!(model.etalon().is_some());
        let fast = model
            .band(&band, Want::BOTH, Output::Mueller, Accuracy::Perceptual)
            .unwrap();
        let method = if thick {
            Method::Paths(None)
        } else {
            Method::Panels(200)
        };
        let full = band_with(
            &plate,
            &frame,
            beta,
            &band,
            Want::BOTH,
            Output::Mueller,
            method,
        )
        .unwrap();
        let e = diff(&fast.r, &full.r).max(diff(&fast.t, &full.t));
        if thick {
            worst_thick = worst_thick.max(e);
        } else {
            worst_thin = worst_thin.max(e);
        }
    }
    println!(
        "etalon band vs panels (thin): {worst_thin:e}; vs path classes (thick): {worst_thick:e}"
    );
    // 1600 nodes resolve the <= ~10 oscillations of these spectra over the band to ~1e-12; the
    // path classes carry the incoherent tail's neglect of pairs beyond the cut-off e^-18.
    assert!(worst_thin < 1e-9, "{worst_thin:e}");
    assert!(worst_thick < 1e-7, "{worst_thick:e}");
}

/// Thick plate, band much wider than the fringes: the incoherent sum per polarisation,
/// `T = T₁T₂/(1 − R₃R₂)` (textbook, e.g. the thick-slab limit in Born & Wolf §7.6), at normal
/// incidence where s and p agree.
#[test]
fn thick_etalon_is_the_incoherent_sum() {
    let (n, d) = (1.5f64, 2e6);
    let r = ((n - 1.0) / (n + 1.0)).powi(2);
    let e = Etalon::new(re(1.0), re(n), re(1.0), re(0.0), d).unwrap();
    let m = e
        .band(&narrow_band(550.0, 4.0), Want::BOTH, Output::Intensity)
        .unwrap();
    let (t_inc, r_inc) = (
        (1.0 - r).powi(2) / (1.0 - r * r),
        r + (1.0 - r).powi(2) * r / (1.0 - r * r),
    );
    let (t, rr) = (m.t.unwrap()[(0, 0)], m.r.unwrap()[(0, 0)]);
    println!("thick etalon: T {t} (incoherent {t_inc}), R {rr} (incoherent {r_inc})");
    assert!((t - t_inc).abs() < 1e-14 && (rr - r_inc).abs() < 1e-14);
}

/// Where the fast path does not apply it is not taken: absorbing or birefringent layers, an
/// evanescent wave in the layer, dispersive materials.
#[test]
fn fast_path_declines_what_it_cannot_do() {
    let plate = |m: Material, b: f64| Plate {
        material: m,
        birefringence: b,
        ext: re(1.0),
        exit: re(1.0),
        axis: Vector3::z(),
        thickness_nm: 1e3,
    };
    let iso = Material::constant(re(1.5), re(1.5)).unwrap();
    assert!(plate(iso, 0.0).etalon(550.0, re(0.5)).is_some());
    assert!(plate(iso, 1e-4).etalon(550.0, re(0.5)).is_none());
    let dyed = Material::constant(C64::new(1.5, 1e-3), C64::new(1.5, 1e-3)).unwrap();
    assert!(plate(dyed, 0.0).etalon(550.0, re(0.5)).is_none());
    let quartz = Material::named("quartz", 0.0, 0.0).unwrap();
    assert!(plate(quartz, 0.0).etalon(550.0, re(0.5)).is_none());
    let mut gap = plate(Material::constant(re(1.0), re(1.0)).unwrap(), 0.0);
    gap.ext = re(1.5);
    assert!(gap.etalon(550.0, re(1.2)).is_none()); // frustrated TIR: general path
}

/// The bulk surface of a lossless isotropic "crystal": the closed-form lobes against the general
/// path (4x4 solve, lobes of each mode, Radiance by reciprocity), every field of every lobe,
/// both transport modes, both sides, TIR from inside included.
#[test]
fn isotropic_crystal_lobes_equal_the_full_computation() {
    use birefringent::optics::surface::Surface;
    use birefringent::render::crystal::{crystal_lobes, crystal_lobes_full};
    use birefringent::render::Transport;
    let mut rng = Rng::new(74);
    let (mut worst, mut cases, mut tir) = (0.0f64, 0, 0);
    for _ in 0..5_000 {
        let n = rng.range(1.05, 3.0);
        let s = Surface::new(re(rng.range(1.0, 1.8)), Uniaxial::isotropic(re(n)).unwrap()).unwrap();
        let wi = rng.unit_vector();
        if wi.z.abs() < 1e-3 {
            continue;
        }
        for t in [Transport::Radiance, Transport::Importance] {
            let fast = crystal_lobes(&s, wi, t).unwrap();
            let full = crystal_lobes_full(&s, wi, t).unwrap();
            assert_eq!(fast.len(), full.len(), "{wi:?} {t:?}");
            tir += usize::from(fast.len() == 1);
            cases += 1;
            for (a, b) in fast.iter().zip(&full) {
                assert_eq!(a.component, b.component);
                // Stokes x axes may differ in sign (a frame turned by 180 degrees: the same
                // Stokes vectors).
                let axis = |x: Vector3<f64>, y: Vector3<f64>| (x - y).norm().min((x + y).norm());
                let e = (a.mueller - b.mueller).abs().max()
                    + (a.wo - b.wo).norm()
                    + axis(a.in_stokes_x, b.in_stokes_x)
                    + axis(a.out_stokes_x, b.out_stokes_x)
                    + (a.eta - b.eta).abs()
                    + (a.weight - b.weight).abs();
                worst = worst.max(e);
            }
        }
    }
    println!(
        "isotropic crystal lobes vs full: worst {worst:e} over {cases} queries ({tir} with TIR)"
    );
    // Both are direct closed-form or direct-solve evaluations of the same quantities: rounding
    // only (the time reversal of the full path recomputes directions, ~1e-15 each).
    assert!(worst < 1e-10, "{worst:e}");
    assert!(tir > 100);
}

/// An isotropic plate solved once for both lobes (reciprocity for the transmission in Radiance
/// mode) against each lobe solved from its own light direction: every field of every lobe, both
/// transport modes, both sides, exact, band-filtered and sRGB spectra.
#[test]
fn isotropic_plate_lobes_shared_equal_per_lobe_solutions() {
    use birefringent::render::plate::{plate_lobes, plate_lobes_full, PlateQuery};
    use birefringent::render::thin::Spectrum;
    use birefringent::render::Transport;
    let mut rng = Rng::new(75);
    let (mut worst, mut lobes) = (0.0f64, 0);
    for i in 0..3_000 {
        let n = rng.range(1.05, 2.6);
        let q = PlateQuery::new(
            Material::constant(re(n), re(n)).unwrap(),
            0.0,
            re(rng.range(1.0, 1.8)),
            re(rng.range(1.0, 1.8)),
            rng.unit_vector(),
            Thickness::from_nm(10f64.powf(rng.range(1.0, 6.5))).unwrap(),
            true,
            true,
            rng.chance(0.3),
        )
        .unwrap();
        let spectrum = match i % 3 {
            0 => Spectrum::Band {
                wavelength_nm: rng.range(400.0, 700.0),
                fwhm_nm: 0.0,
            },
            1 => Spectrum::Band {
                wavelength_nm: rng.range(400.0, 700.0),
                fwhm_nm: 4.0,
            },
            _ => Spectrum::Weights(WeightSet::SrgbD65),
        };
        let wi = rng.unit_vector();
        if wi.z.abs() < 1e-3 {
            continue;
        }
        for t in [Transport::Radiance, Transport::Importance] {
            let fast = plate_lobes(&q, &spectrum, wi, t).unwrap();
            let full = plate_lobes_full(&q, &spectrum, wi, t).unwrap();
            for (a, b) in fast.iter().flatten().zip(full.iter().flatten()) {
                match (a, b) {
                    (Some(a), Some(b)) => {
                        lobes += 1;
                        let e = (a.mueller - b.mueller).abs().max()
                            + (a.wo - b.wo).norm()
                            + (a.in_stokes_x - b.in_stokes_x).norm()
                            + (a.eta - b.eta).abs();
                        worst = worst.max(e);
                    }
                    (None, None) => {}
                    _ => panic!("lobe sets differ: {a:?} vs {b:?}"),
                }
            }
        }
    }
    println!("isotropic plate, shared vs per-lobe solutions: worst {worst:e} over {lobes} lobes");
    // The same closed forms from either side: rounding only (phases k d w up to ~4e4 rad).
    assert!(worst < 1e-10, "{worst:e}");
    assert!(lobes > 10_000);
}

/// Several wavelengths in one query (`Spectrum::Bands`, what the spectral plugins ask) equal
/// one query per wavelength, isotropic plates (one etalon shared) and birefringent ones alike.
#[test]
fn several_wavelengths_in_one_query_equal_single_queries() {
    use birefringent::render::plate::{plate_lobes, PlateQuery};
    use birefringent::render::thin::{Spectrum, MAX_BANDS};
    use birefringent::render::Transport;
    let mut rng = Rng::new(76);
    let mut worst = 0.0f64;
    for i in 0..400 {
        let material = if i % 2 == 0 {
            let n = rng.range(1.05, 2.6);
            Material::constant(re(n), re(n)).unwrap()
        } else {
            Material::named("quartz", 0.0, 0.0).unwrap()
        };
        let q = PlateQuery::new(
            material,
            0.0,
            re(1.0),
            re(rng.range(1.0, 1.6)),
            rng.unit_vector(),
            Thickness::from_nm(10f64.powf(rng.range(1.0, 6.5))).unwrap(),
            true,
            true,
            false,
        )
        .unwrap();
        let fwhm_nm = if rng.chance(0.3) { 0.0 } else { 4.0 };
        let w: [f64; MAX_BANDS] = std::array::from_fn(|_| rng.range(380.0, 780.0));
        let wi = rng.unit_vector();
        let t = if rng.chance(0.5) {
            Transport::Radiance
        } else {
            Transport::Importance
        };
        let all = plate_lobes(
            &q,
            &Spectrum::Bands {
                wavelengths_nm: w,
                count: MAX_BANDS,
                fwhm_nm,
            },
            wi,
            t,
        )
        .unwrap();
        assert_eq!(all.len(), MAX_BANDS);
        for (c, &wavelength_nm) in w.iter().enumerate() {
            let one = plate_lobes(
                &q,
                &Spectrum::Band {
                    wavelength_nm,
                    fwhm_nm,
                },
                wi,
                t,
            )
            .unwrap();
            for k in 0..2 {
                match (&all[c][k], &one[0][k]) {
                    (Some(a), Some(b)) => worst = worst.max((a.mueller - b.mueller).abs().max()),
                    (None, None) => {}
                    (a, b) => panic!("lobes differ: {a:?} {b:?}"),
                }
            }
        }
    }
    println!("several wavelengths vs single queries: worst {worst:e}");
    // The same computation, only shared; a thick isotropic plate reuses one incoherent sum for
    // every wavelength, whose coherent terms are below e^-40 (~4e-18) of the leading ones.
    assert!(worst < 1e-14, "{worst:e}");
}

/// The shared isotropic path validates the wavelengths as the general path does.
#[test]
fn isotropic_plate_refuses_invalid_wavelengths() {
    use birefringent::render::plate::{plate_lobes, PlateQuery};
    use birefringent::render::thin::Spectrum;
    use birefringent::render::Transport;
    let q = PlateQuery::new(
        Material::constant(re(1.5), re(1.5)).unwrap(),
        0.0,
        re(1.0),
        re(1.0),
        Vector3::z(),
        Thickness::from_nm(1e3).unwrap(),
        true,
        true,
        false,
    )
    .unwrap();
    let wi = Vector3::new(0.3, 0.1, 0.948_683_298_050_513_8);
    for (wavelength_nm, fwhm_nm) in [(f64::NAN, 0.0), (0.5, 0.0), (2e6, 4.0), (550.0, 200.0)] {
        let s = Spectrum::Band {
            wavelength_nm,
            fwhm_nm,
        };
        let e = plate_lobes(&q, &s, wi, Transport::Radiance).unwrap_err();
        assert!(
            ["wavelength_nm", "filter_bandwidth"].contains(&e.parameter.as_str()),
            "{e}"
        );
    }
}
