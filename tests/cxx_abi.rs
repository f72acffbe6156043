//! The generated C++ header of the bridge (`birefringent/src/ffi/mod.rs.h`) matches the
//! library: a C++ program compiled against it (tests/cpp/abi_check.cpp) links the static
//! library, sees the same bounds and version, gets an exception with the core's message from a
//! refused material, and the same numbers, bit for bit, as the Rust side of the same calls
//! (mixed materials, sides, modes and broadcast columns; a band spectrum, the sRGB channels, a
//! crystal; failing lanes and a refused call).

use birefringent::ffi::bridge::{
    CrystalLanes, PlateCall, PlateLanes, Samples, Status, Transport as T,
};
use birefringent::ffi::{
    band_spectrum, new_materials, sample_crystal, sample_plate, srgb_spectrum,
};
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
    let cxx = std::env::var("CXX").unwrap_or_else(|_| "c++".into());
    // The generated headers of this package's build script (the same bridge as the library's).
    let include = Path::new(env!("OUT_DIR")).join("cxxbridge/include");
    let out = Command::new(cxx)
        .args(["-std=c++17", "-Wall", "-Werror"])
        .arg(format!("-I{}", include.display()))
        .arg(root().join("tests/cpp/abi_check.cpp"))
        .arg(lib)
        .args(["-lpthread", "-ldl", "-lm", "-o"])
        .arg(&exe)
        .output()
        .expect("C++ compiler runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let run = Command::new(&exe).output().unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    std::fs::remove_dir_all(&dir).ok();
    String::from_utf8(run.stdout).unwrap()
}

/// The printed form of a batch's outputs, as abi_check.cpp prints it.
fn printed(tag: &str, rc: Status, s: &Samples, n: usize, channels: usize) -> Vec<String> {
    let mut v = vec![format!("{tag} {} [{}]", rc.repr, s.message)];
    let g = |x: f64| format!("{x:?}");
    for i in 0..n {
        let mut line = format!(
            "lane {} {} {} {} {} {} {}",
            s.status[i].repr,
            s.component[i],
            g(s.pdf[i]),
            g(s.eta[i]),
            g(s.wo[0][i]),
            g(s.wo[1][i]),
            g(s.wo[2][i])
        );
        for c in 0..channels {
            let at = c * n + i;
            for k in 0..3 {
                line += &format!(" {} {}", g(s.in_stokes_x[k][at]), g(s.out_stokes_x[k][at]));
            }
            for k in 0..16 {
                line += &format!(" {}", g(s.value[k][at]));
            }
        }
        v.push(line);
    }
    v
}

/// Parses a printed line into its tokens, numbers as f64 bits (C's %.17g and Rust's `{:?}`
/// spell the same double differently; both round-trip exactly).
fn tokens(line: &str) -> Vec<String> {
    line.split(' ')
        .map(|t| match t.parse::<f64>() {
            Ok(x) => format!("{:016x}", x.to_bits()),
            Err(_) => t.to_string(),
        })
        .collect()
}

fn same_lines(c: &[&str], rust: &[String]) {
    assert_eq!(c.len(), rust.len());
    for (a, b) in c.iter().zip(rust) {
        assert_eq!(tokens(a), tokens(b), "C++: {a}\nRust: {b}");
    }
}

/// Owned output columns for `n` lanes of `channels` channels.
struct Out {
    status: Vec<Status>,
    component: Vec<u32>,
    cols: Vec<Vec<f64>>,
}

impl Out {
    fn new(n: usize, channels: usize) -> Self {
        Out {
            status: vec![Status::Ok; n],
            component: vec![0; n],
            cols: (0..2 + 3)
                .map(|_| vec![0.0; n])
                .chain((0..6 + 16).map(|_| vec![0.0; n * channels]))
                .collect(),
        }
    }

    fn samples(&mut self) -> Samples<'_> {
        let mut c = self.cols.iter_mut().map(|v| v.as_mut_slice());
        let mut next = || c.next().unwrap();
        Samples {
            status: &mut self.status,
            component: &mut self.component,
            pdf: next(),
            eta: next(),
            wo: [next(), next(), next()],
            in_stokes_x: [next(), next(), next()],
            out_stokes_x: [next(), next(), next()],
            value: std::array::from_fn(|_| next()),
            message: String::new(),
        }
    }
}

#[test]
fn cxx_program_agrees_with_the_rust_side() {
    let text = compile_and_run(&static_lib());
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], format!("version {}", env!("CARGO_PKG_VERSION")));
    assert_eq!(lines[1], "bounds 4 2 3");
    assert_eq!(lines[2], "materials 0 1 0 1");
    assert!(
        lines[3].starts_with("bad material [material: unknown crystal 'unobtainium'; the catalogue's names: calcite, quartz (crystalline quartz), "),
        "{}",
        lines[3]
    );

    // The same calls from Rust.
    let mut m = new_materials();
    m.add_named("calcite", 0.0, 0.0).unwrap();
    m.add_constant(1.5, 1.5, 0.0, 0.0).unwrap();
    let n = 3;
    let (wx, wy) = ([0.3, -0.2, 0.0], [0.2, 0.1, 0.6]);
    let wz = [
        (1.0f64 - 0.13).sqrt(),
        -(1.0f64 - 0.05).sqrt(),
        (1.0f64 - 0.36).sqrt(),
    ];
    let (l0, l1, l2) = ([450.0, 500.0, 650.0], [550.0], [600.0, 610.0, 620.0]);
    let waves: [&[f64]; 3] = [&l0, &l1, &l2];
    let transport = [T::Radiance, T::Importance, T::Importance];
    let p = PlateLanes {
        count: n,
        active: &[1, 1, 1],
        material: &[0, 1, 0],
        transport: &transport,
        sample: &[0.1, 0.5, 0.9],
        wi: [&wx, &wy, &wz],
        wavelengths_nm: &waves,
        ext_ior: &[1.0],
        exit_ior: &[1.33],
        optic_axis: [&[0.7021], &[0.0], &[0.7120]],
        axis_angle_deg: &[0.0],
        thickness_nm: &[2500.0],
        birefringence: &[0.0],
    };
    let call = PlateCall {
        components: 3,
        intensity_only: false,
        absorbing_exit: false,
    };
    // The lines of one call starting at `at`; returns the next line's index.
    let check = |at: usize, tag: &str, channels: usize, run: &dyn Fn(&mut Samples) -> Status| {
        let mut out = Out::new(n, channels);
        let mut s = out.samples();
        let rc = run(&mut s);
        same_lines(&lines[at..at + 1 + n], &printed(tag, rc, &s, n, channels));
        at + 1 + n
    };
    let band = band_spectrum(4.0);
    let at = check(4, "plate", 3, &|s| sample_plate(&m, &band, &call, &p, s));
    assert!(
        lines[at].starts_with("wide band 1 1 [filter_bandwidth: must be within [0, 112.5] nm"),
        "{}",
        lines[at]
    );
    let srgb = srgb_spectrum();
    let rgb = PlateLanes {
        wavelengths_nm: &[],
        ..p
    };
    let at = check(at + 1, "rgb", 3, &|s| {
        sample_plate(&m, &srgb, &call, &rgb, s)
    });
    let c = CrystalLanes {
        count: n,
        active: p.active,
        material: p.material,
        transport: p.transport,
        sample: p.sample,
        wi: p.wi,
        wavelengths_nm: p.wavelengths_nm,
        ext_ior: p.ext_ior,
        optic_axis: p.optic_axis,
    };
    let at = check(at, "crystal", 3, &|s| sample_crystal(&m, 7, &c, s));
    assert_eq!(
        lines[at], "bad axis 1 1 [optic_axis: must be a non-zero vector]",
        "{}",
        lines[at]
    );
    assert!(
        lines[at + 1].starts_with("short column 1 [sample: column of 2 values for 3 lanes"),
        "{}",
        lines[at + 1]
    );
    assert_eq!(lines.len(), at + 2);
}
