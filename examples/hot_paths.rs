//! Instruction counts of the per-query hot paths of the plugins, for `valgrind --tool=callgrind`
//! (counts are repeatable whatever else the machine does, unlike times):
//!
//! ```text
//! cargo build --release --example hot_paths
//! valgrind --tool=callgrind target/release/examples/hot_paths <case> 1     # set-up alone
//! valgrind --tool=callgrind target/release/examples/hot_paths <case> 1001  # + 1000 queries
//! ```
//! The difference of the two totals over 1000 is the cost of one query. Cases: `interface`
//! (air → calcite-like crystal, 4x4 solve), `crystal_iso` / `crystal_calcite` (bulk surface
//! lobes, Radiance, from outside; `crystal_iso_inside` / `crystal_calcite_inside` from inside, the
//! directions mirrored, partly beyond the critical angle), `lane_glass` / `lane_calcite` (what a
//! spectral variant asks per path vertex: `sample_crystal` with one lane of four wavelengths,
//! every other query from inside; glass 1.5 or dispersive calcite), `plate_*` (`plate_lobes`, Radiance, both lobes: isotropic 1 mm plate
//! exact / 4 nm band / sRGB, quartz 20 um, 60 um, calcite 1 mm and a 3 mm photoelastic-like
//! plate in a 4 nm band, a 0.5 um lithium niobate film in sRGB: in air, and as in the thin_film
//! scene, x-cut on black silica, `plate_film_scene_rgb`; the four exact wavelengths of one path
//! of a spectral variant through a 20 um quartz plate, `plate_quartz_4exact`, and through a 3 mm
//! photoelastic plate, `plate_stress_4exact`; in sRGB, the quartz plates of 0, 5 and 150 um and
//! the 3 mm photoelastic plate of the overhead benchmark, `plate_quartz0_rgb`,
//! `plate_quartz5_rgb`, `plate_quartz150_rgb`, `plate_stress_rgb`). Directions: 64 on a spiral up
//! to `THETA_MAX` degrees from the normal (default 45, the directions plugin/README.md's counts
//! are quoted for). `angle:<material>:<thickness_nm>:<theta_deg>`: the sRGB query of a render
//! (`plate_lobes`, both lobes, full Mueller, Radiance) through a plate of a named crystal (axis
//! `(1, 1, 0)`) from one direction at `theta_deg` (azimuth 30 degrees), e.g.
//! `angle:quartz:5000:80`: the cases of the spectral integral's profile (issue 20: 0, 45, 80
//! and 89 degrees; 0, 5 and 150 um).

use birefringent::colour::weights::WeightSet;
use birefringent::ffi::bridge::{CrystalLanes, Samples, Status, Transport as BridgeTransport};
use birefringent::ffi::{new_materials, sample_crystal};
use birefringent::material::Material;
use birefringent::optics::interface::Interface;
use birefringent::optics::medium::Uniaxial;
use birefringent::optics::surface::Surface;
use birefringent::params::Thickness;
use birefringent::render::crystal::crystal_lobes;
use birefringent::render::plate::{plate_lobes, PlateQuery};
use birefringent::render::thin::Spectrum;
use birefringent::render::Transport;
use birefringent::C64;
use nalgebra::Vector3;
use std::hint::black_box;

fn dirs(n: usize) -> Vec<Vector3<f64>> {
    (0..n)
        .map(|i| {
            let max: f64 = std::env::var("THETA_MAX")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(45.0);
            let t = max.to_radians() * (i as f64 + 0.5) / n as f64;
            let p = 2.399963 * i as f64;
            Vector3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
        })
        .collect()
}

/// The four wavelengths (nm) a spectral variant traces along one path, exact.
fn four() -> Spectrum {
    Spectrum::Bands {
        wavelengths_nm: [412.0, 512.0, 612.0, 712.0],
        count: 4,
        fwhm_nm: 0.0,
    }
}

/// `n` calls of `sample_crystal`, one lane of four wavelengths each (Radiance), alternately
/// from outside and from inside along `ds`: glass (1.5) or dispersive calcite.
fn lanes(calcite: bool, ds: &[Vector3<f64>], n: usize) {
    let mut m = new_materials();
    if calcite {
        m.add_named("calcite", 0.0, 0.0).unwrap();
    } else {
        m.add_constant(1.5, 1.5, 0.0, 0.0).unwrap();
    }
    let waves = [[412.0], [512.0], [612.0], [712.0]];
    let wave_cols: Vec<&[f64]> = waves.iter().map(|w| w.as_slice()).collect();
    // Per-lane columns (pdf, eta, wo) of one value, per-channel ones of four.
    let mut cols: Vec<Vec<f64>> = (0..27)
        .map(|k| vec![0.0; if k < 5 { 1 } else { 4 }])
        .collect();
    let (mut status, mut component) = ([Status::Ok], [0u32]);
    for i in 0..n {
        let d = ds[i % 64];
        let side = if i % 2 == 0 { 1.0 } else { -1.0 };
        let (x, y, z) = ([d.x], [d.y], [side * d.z]);
        let lanes = CrystalLanes {
            count: 1,
            active: &[1],
            material: &[0],
            transport: &[BridgeTransport::Radiance],
            sample: &[0.5],
            wi: [&x, &y, &z],
            wavelengths_nm: &wave_cols,
            ext_ior: &[1.0],
            optic_axis: [&[1.0], &[0.3], &[0.2]],
        };
        let mut c = cols.iter_mut().map(|v| v.as_mut_slice());
        let mut next = || c.next().unwrap();
        let mut s = Samples {
            status: &mut status,
            component: &mut component,
            pdf: next(),
            eta: next(),
            wo: [next(), next(), next()],
            in_stokes_x: [next(), next(), next()],
            out_stokes_x: [next(), next(), next()],
            value: std::array::from_fn(|_| next()),
            message: String::new(),
        };
        assert_eq!(sample_crystal(&m, 7, &lanes, &mut s), Status::Ok);
        black_box(&s.value);
    }
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let case = a[1].as_str();
    let n: usize = a[2].parse().unwrap();
    let ds = dirs(64);
    let c = |x: f64| C64::new(x, 0.0);
    if let Some(spec) = case.strip_prefix("angle:") {
        let parts: Vec<&str> = spec.split(':').collect();
        let [material, thickness, theta] = parts[..] else {
            panic!("angle:<material>:<thickness_nm>:<theta_deg>")
        };
        let (th, theta): (f64, f64) = (thickness.parse().unwrap(), theta.parse().unwrap());
        let q = PlateQuery::new(
            Material::named(material, 0.0, 0.0).unwrap(),
            0.0,
            c(1.0),
            c(1.0),
            Vector3::new(1.0, 1.0, 0.0),
            Thickness::from_nm(th).unwrap(),
            true,
            true,
            false,
        )
        .unwrap();
        let (t, p) = (theta.to_radians(), 30f64.to_radians());
        let wi = Vector3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
        let spectrum = Spectrum::Weights(WeightSet::SrgbD65);
        for _ in 0..n {
            black_box(plate_lobes(&q, &spectrum, black_box(wi), Transport::Radiance).unwrap());
        }
        return;
    }
    match case {
        "interface" => {
            let air = Uniaxial::isotropic(c(1.0)).unwrap();
            let xs: Vec<Uniaxial> = ds
                .iter()
                .map(|d| Uniaxial::new(c(1.658), c(1.486), *d).unwrap())
                .collect();
            for i in 0..n {
                black_box(
                    Interface::new(&air, &xs[i % 64], c(0.6 * (i % 7) as f64 / 7.0)).unwrap(),
                );
            }
        }
        "lane_glass" | "lane_calcite" => lanes(case == "lane_calcite", &ds, n),
        "crystal_iso" | "crystal_calcite" | "crystal_iso_inside" | "crystal_calcite_inside" => {
            let (o, e) = if case.starts_with("crystal_iso") {
                (1.5, 1.5)
            } else {
                (1.658, 1.486)
            };
            let s = Surface::new(
                c(1.0),
                Uniaxial::new(c(o), c(e), Vector3::new(1.0, 0.3, 0.2)).unwrap(),
            )
            .unwrap();
            let side = if case.ends_with("inside") { -1.0 } else { 1.0 };
            for i in 0..n {
                let d = ds[i % 64];
                let wi = Vector3::new(d.x, d.y, side * d.z);
                black_box(crystal_lobes(&s, wi, Transport::Radiance).unwrap());
            }
        }
        _ => {
            let (mat, th, spec) = match case {
                "plate_iso_band" => (
                    Material::constant(c(1.5), c(1.5)).unwrap(),
                    1e6,
                    Spectrum::Band {
                        wavelength_nm: 550.0,
                        fwhm_nm: 4.0,
                    },
                ),
                "plate_iso_exact" => (
                    Material::constant(c(1.5), c(1.5)).unwrap(),
                    1e6,
                    Spectrum::Band {
                        wavelength_nm: 550.0,
                        fwhm_nm: 0.0,
                    },
                ),
                "plate_iso_rgb" => (
                    Material::constant(c(1.5), c(1.5)).unwrap(),
                    1e6,
                    Spectrum::Weights(WeightSet::SrgbD65),
                ),
                "plate_quartz_band" => (
                    Material::named("quartz", 0.0, 0.0).unwrap(),
                    2e4,
                    Spectrum::Band {
                        wavelength_nm: 550.0,
                        fwhm_nm: 4.0,
                    },
                ),
                "plate_quartz_exact" => (
                    Material::named("quartz", 0.0, 0.0).unwrap(),
                    2e4,
                    Spectrum::Band {
                        wavelength_nm: 550.0,
                        fwhm_nm: 0.0,
                    },
                ),
                "plate_quartz_rgb" => (
                    Material::named("quartz", 0.0, 0.0).unwrap(),
                    2e4,
                    Spectrum::Weights(WeightSet::SrgbD65),
                ),
                // The quartz plates and the 3 mm photoelastic plate of the overhead benchmark's
                // anisotropic rows (bench/scenes.py), as scalar_rgb asks for them.
                "plate_quartz0_rgb" | "plate_quartz5_rgb" | "plate_quartz150_rgb" => (
                    Material::named("quartz", 0.0, 0.0).unwrap(),
                    match case {
                        "plate_quartz0_rgb" => 0.0,
                        "plate_quartz5_rgb" => 5e3,
                        _ => 1.5e5,
                    },
                    Spectrum::Weights(WeightSet::SrgbD65),
                ),
                "plate_stress_rgb" => (
                    Material::constant(c(1.5), c(1.5002)).unwrap(),
                    3e6,
                    Spectrum::Weights(WeightSet::SrgbD65),
                ),
                "plate_quartz60_band" => (
                    Material::named("quartz", 0.0, 0.0).unwrap(),
                    6e4,
                    Spectrum::Band {
                        wavelength_nm: 550.0,
                        fwhm_nm: 4.0,
                    },
                ),
                "plate_calcite_thick_band" => (
                    Material::named("calcite", 0.0, 0.0).unwrap(),
                    1e6,
                    Spectrum::Band {
                        wavelength_nm: 550.0,
                        fwhm_nm: 4.0,
                    },
                ),
                "plate_stress_band" => (
                    Material::constant(c(1.5), c(1.5005)).unwrap(),
                    3e6,
                    Spectrum::Band {
                        wavelength_nm: 550.0,
                        fwhm_nm: 4.0,
                    },
                ),
                // What the spectral plugins ask along one path: four exact wavelengths.
                "plate_quartz_4exact" => {
                    (Material::named("quartz", 0.0, 0.0).unwrap(), 2e4, four())
                }
                "plate_stress_4exact" => {
                    (Material::constant(c(1.5), c(1.5002)).unwrap(), 3e6, four())
                }
                "plate_film_scene_rgb" | "plate_film_rgb" => (
                    Material::named("linbo3", 0.0, 0.0).unwrap(),
                    500.0,
                    Spectrum::Weights(WeightSet::SrgbD65),
                ),
                _ => panic!("unknown case"),
            };
            let intensity = case.ends_with("rgb");
            // The thin_film scene's query: x-cut film on black silica (reflection only).
            let scene = case == "plate_film_scene_rgb";
            let (exit, axis) = if scene {
                (1.458, Vector3::new(1.0, 0.0, 0.0))
            } else {
                (1.0, Vector3::new(1.0, 1.0, 0.0))
            };
            let q = PlateQuery::new(
                mat,
                0.0,
                c(1.0),
                c(exit),
                axis,
                Thickness::from_nm(th).unwrap(),
                true,
                true,
                intensity,
            )
            .unwrap()
            .with_absorbing_exit(scene);
            for i in 0..n {
                black_box(plate_lobes(&q, &spec, ds[i % 64], Transport::Radiance).unwrap());
            }
        }
    }
}
