//! The C header `cpp/include/birefringent.h` matches the library: a C program compiled against
//! it links the static library, sees the same struct sizes and the same numbers as the Rust API,
//! and gets error codes and messages for invalid input.

use birefringent::ffi::{BfrComplex, BfrEvent, BfrLobe, BfrSurface};
use birefringent::lobes::scatter;
use birefringent::medium::Uniaxial;
use birefringent::surface::{Incident, Surface};
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
    root().join("target/release/libbirefringent.a")
}

fn compile_and_run(lib: &Path) -> String {
    let dir = std::env::temp_dir().join(format!("bfr_abi_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let exe = dir.join("abi_check");
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let out = Command::new(cc)
        .arg("-std=c99")
        .arg("-Wall")
        .arg("-Werror")
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
    String::from_utf8(run.stdout).unwrap()
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
            std::mem::size_of::<BfrSurface>(),
            std::mem::size_of::<BfrLobe>(),
            std::mem::size_of::<BfrEvent>()
        ]
    );
    assert_eq!(lines[1], format!("version {}", env!("CARGO_PKG_VERSION")));
    assert_eq!(lines[2], "rc 0");

    let crystal = Uniaxial::new(
        C64::new(1.6584, 0.0),
        C64::new(1.4864, 0.0),
        Vector3::new(0.7021, 0.0, 0.7120),
    )
    .unwrap();
    let s = Surface::new(C64::new(1.0, 0.0), crystal).unwrap();
    let w = Vector3::new(0.3, 0.2, (1.0f64 - 0.13).sqrt());
    let e = scatter(&s, w, Incident::Outside).unwrap();
    let lobes = [
        e.reflected[0],
        e.reflected[1],
        e.transmitted[0],
        e.transmitted[1],
    ];
    for (line, lobe) in lines[3..7].iter().zip(lobes) {
        let f: Vec<f64> = line
            .split(' ')
            .skip(1)
            .map(|x| x.parse().unwrap())
            .collect();
        match lobe {
            None => assert_eq!(f[0], 0.0),
            Some(l) => {
                assert_eq!(f[0], 1.0);
                let want = [
                    l.direction.x,
                    l.direction.y,
                    l.direction.z,
                    l.mueller[(0, 0)],
                    l.mueller[(1, 1)],
                ];
                assert_eq!(&f[2..], &want, "C and Rust disagree");
            }
        }
    }
    assert!(lines[7].starts_with("bad 1 optic_axis:"), "{}", lines[7]);
    assert_eq!(lines[8], "truncated 1 [inciden]");
    assert_eq!(lines[9], "null 1 null pointer argument");
}
