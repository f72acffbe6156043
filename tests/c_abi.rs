//! The C header `cpp/include/birefringent.h` matches the library: a C program compiled against
//! it links the static library, sees the same struct sizes and the same numbers as the Rust API,
//! and gets error codes and messages for invalid input.

use birefringent::ffi::{BfrComplex, BfrGeometry, BfrMaterialDesc, BfrPathLobe};
use birefringent::material::Material;
use birefringent::optics::medium::Uniaxial;
use birefringent::optics::surface::Surface;
use birefringent::params::Thickness;
use birefringent::render::crystal::crystal_lobes;
use birefringent::render::plate::{plate_lobes, PlateQuery, Spectrum};
use birefringent::render::Transport;
use birefringent::spectral::weights::WeightSet;
use birefringent::C64;
use nalgebra::Vector3;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Builds the release static library (a no-op when up to date) and returns its path.
fn static_lib() -> PathBuf {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(cargo)
        .args(["build", "--release", "--lib", "--quiet"])
        .current_dir(root())
        .status()
        .expect("cargo runs");
    assert!(status.success());
    let dir = std::env::var("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|_| root().join("target"));
    dir.join("release/libbirefringent.a")
}

fn compile_and_run(lib: &Path) -> String {
    let dir = std::env::temp_dir().join(format!("bfr_abi_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let exe = dir.join("abi_check");
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let out = Command::new(cc)
        .args(["-std=c99", "-Wall", "-Werror"])
        .arg(format!("-I{}", root().join("cpp/include").display()))
        .arg(root().join("tests/c/abi_check.c"))
        .arg(lib)
        .args(["-lpthread", "-ldl", "-lm", "-o"])
        .arg(&exe)
        .output()
        .expect("C compiler runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let run = Command::new(&exe).output().unwrap();
    assert!(run.status.success());
    std::fs::remove_dir_all(&dir).ok();
    String::from_utf8(run.stdout).unwrap()
}

fn numbers(line: &str) -> Vec<f64> {
    line.split(' ')
        .skip(1)
        .map(|x| x.parse().unwrap())
        .collect()
}

fn expect_lobe(line: &str, l: Option<&birefringent::render::PathLobe>) {
    let f = numbers(line);
    match l {
        None => assert_eq!(f[0], 0.0, "{line}"),
        Some(l) => {
            let want = [
                1.0,
                l.component as f64,
                l.wo.x,
                l.wo.y,
                l.wo.z,
                l.weight,
                l.mueller[(1, 1)],
                l.eta,
            ];
            assert_eq!(f, want, "C and Rust disagree");
        }
    }
}

#[test]
fn c_program_agrees_with_the_rust_api() {
    let text = compile_and_run(&static_lib());
    let lines: Vec<&str> = text.lines().collect();
    let sizes: Vec<usize> = lines[0]
        .split(' ')
        .skip(1)
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(
        sizes,
        [
            std::mem::size_of::<BfrComplex>(),
            std::mem::size_of::<BfrMaterialDesc>(),
            std::mem::size_of::<BfrGeometry>(),
            std::mem::size_of::<BfrPathLobe>()
        ]
    );
    assert_eq!(lines[1], format!("version {}", env!("CARGO_PKG_VERSION")));
    let calcite = Material::named("calcite", 0.0, 0.0).unwrap();
    let (eo, ee) = calcite.indices(589.3, 0.0).unwrap();
    assert_eq!(numbers(lines[2]), [0.0, eo.re, ee.re]);

    let axis = Vector3::new(0.7021, 0.0, 0.7120);
    let s = Surface::new(C64::new(1.0, 0.0), Uniaxial::new(eo, ee, axis).unwrap()).unwrap();
    let wi = Vector3::new(0.3, 0.2, (1.0f64 - 0.13).sqrt());
    let mut at = 3;
    for t in [Transport::Radiance, Transport::Importance] {
        assert_eq!(numbers(lines[at])[1], 0.0, "{}", lines[at]);
        let lobes = crystal_lobes(&s, wi, t).unwrap();
        for k in 0..6 {
            expect_lobe(lines[at + 1 + k], lobes.get(k));
        }
        at += 7;
    }
    assert_eq!(lines[at], "plate 0");
    let both = PlateQuery::new(
        calcite,
        0.0,
        C64::new(1.0, 0.0),
        C64::new(1.0, 0.0),
        axis,
        Thickness::from_nm(2500.0).unwrap(),
        true,
        true,
        false,
    )
    .unwrap();
    let band = Spectrum::Band {
        wavelength_nm: 550.0,
        fwhm_nm: 0.0,
    };
    let p = plate_lobes(&both, &band, wi, Transport::Radiance).unwrap();
    expect_lobe(lines[at + 1], p[0][0].as_ref());
    expect_lobe(lines[at + 2], p[0][1].as_ref());
    let q = PlateQuery::new(
        calcite,
        0.0,
        C64::new(1.0, 0.0),
        C64::new(1.0, 0.0),
        axis,
        Thickness::from_nm(2500.0).unwrap(),
        false,
        true,
        true,
    )
    .unwrap();
    let rgb = plate_lobes(
        &q,
        &Spectrum::Weights(WeightSet::SrgbD65),
        wi,
        Transport::Importance,
    )
    .unwrap();
    let f = numbers(lines[at + 3]);
    assert_eq!(
        f,
        [
            0.0,
            rgb[0][1].unwrap().weight,
            rgb[1][1].unwrap().weight,
            rgb[2][1].unwrap().weight,
            0.0
        ]
    );
    // Three wavelengths in one query equal three single queries (band-filtered, 4 nm).
    assert_eq!(lines[at + 4], "bands 0");
    for (i, wavelength_nm) in [450.0, 550.0, 650.0].into_iter().enumerate() {
        let band = Spectrum::Band {
            wavelength_nm,
            fwhm_nm: 4.0,
        };
        let p = plate_lobes(&both, &band, wi, Transport::Radiance).unwrap();
        expect_lobe(lines[at + 5 + 2 * i], p[0][0].as_ref());
        expect_lobe(lines[at + 6 + 2 * i], p[0][1].as_ref());
    }
    assert_eq!(
        lines[at + 11],
        "too many 1 count: must be 1 to 4 wavelengths, got 5"
    );
    let at = at + 8;
    assert!(lines[at + 4].starts_with("bad material 1 material: unknown crystal 'unobtainium'"));
    assert!(
        lines[at + 5].starts_with("bad axis 1 optic_axis:"),
        "{}",
        lines[at + 5]
    );
    assert_eq!(lines[at + 6], "truncated 1 [transport]");
    assert_eq!(lines[at + 7], "null 1 geometry: null pointer");
}
