//! Compiles the C++ shim (src/*.cpp) against the headers of the `mitsuba`, `drjit` and
//! `nanobind` wheels of a Python environment and links it with libmitsuba and Dr.Jit.
//!
//! The wheels are those of the site-packages directory `MITSUBA_SITE_PACKAGES` (`make
//! plugin-lib` passes it; the Python build backend, build_backend/, runs that). The compile flags
//! below must match the flags the PyPI wheels are built with: above all `-march=ivybridge`, which
//! sets Dr.Jit's array padding and so the layout of Mitsuba's structs (a mismatch compiles,
//! loads and renders garbage). The library finds libmitsuba and libdrjit through RUNPATHs
//! relative to itself (`$ORIGIN/../mitsuba`, `$ORIGIN/../drjit`): installed, the package
//! directory sits beside `mitsuba/` and `drjit/` in site-packages.

use std::path::{Path, PathBuf};

/// Where the wheels are: (mitsuba package dir, drjit package dir, nanobind include dir), in the
/// site-packages directory `site`.
fn wheels(site: &Path) -> (PathBuf, PathBuf, PathBuf) {
    let (mitsuba, drjit) = (site.join("mitsuba"), site.join("drjit"));
    for (dir, file) in [(&mitsuba, "libmitsuba.so"), (&drjit, "libdrjit-core.so")] {
        if !dir.join(file).is_file() {
            panic!(
                "{} not found: MITSUBA_SITE_PACKAGES ({}) must be the site-packages directory \
                 holding the mitsuba, drjit and nanobind wheels the plugin is compiled against \
                 (make setup installs them in .venv/)",
                dir.join(file).display(),
                site.display()
            );
        }
    }
    (mitsuba, drjit, site.join("nanobind/include"))
}

fn main() {
    println!("cargo:rerun-if-env-changed=MITSUBA_SITE_PACKAGES");
    let site = std::env::var_os("MITSUBA_SITE_PACKAGES")
        .map(PathBuf::from)
        .expect("MITSUBA_SITE_PACKAGES must name the site-packages directory of the mitsuba, drjit and nanobind wheels (make plugin-lib sets it)");
    let (mitsuba, drjit, nanobind) = wheels(&site);

    let sources = [
        "src/thinbirefringent.cpp",
        "src/birefringent.cpp",
        "src/register.cpp",
    ];
    let mut build = cxx_build::bridge("src/lib.rs");
    build
        .files(sources)
        .std("c++17")
        .opt_level(2)
        .debug(false)
        .include("src")
        // The wheels' flags (see the module comment).
        .flag("-march=ivybridge")
        .flag("-ffp-contract=fast")
        .flag("-fno-math-errno")
        .define("NDEBUG", None)
        .define("MI_ENABLE_LLVM", "1")
        .define("MI_ENABLE_CUDA", "1")
        .define("MI_ENABLE_EMBREE", "1")
        .define("MI_ENABLE_AUTODIFF", "1")
        .flag("-fvisibility=hidden")
        .flag("-Wall");
    for dir in [
        mitsuba.join("include"),
        drjit.join("include"),
        nanobind.clone(),
        nanobind.join("../ext/robin_map/include"),
    ] {
        build
            .flag("-isystem")
            .flag(dir.to_str().expect("UTF-8 path"));
    }
    build.compile("mitsuba-birefringent-shim");

    for dir in [&mitsuba, &drjit] {
        println!("cargo:rustc-link-search=native={}", dir.display());
    }
    for lib in ["mitsuba", "drjit-core", "drjit-extra", "nanothread"] {
        println!("cargo:rustc-link-lib=dylib={lib}");
    }
    for arg in [
        "-Wl,-rpath,$ORIGIN/../mitsuba:$ORIGIN/../drjit",
        "-Wl,--enable-new-dtags",
        "-Wl,--no-undefined",
        "-Wl,--strip-debug",
    ] {
        println!("cargo:rustc-cdylib-link-arg={arg}");
    }
    for f in sources.iter().chain(&[
        "src/register.h",
        "src/plugins.h",
        "src/params.h",
        "src/bridge.h",
        "src/lobes.h",
    ]) {
        println!("cargo:rerun-if-changed={f}");
    }
    // A new wheel (another Mitsuba or Dr.Jit) means a rebuild.
    println!(
        "cargo:rerun-if-changed={}",
        mitsuba.join("libmitsuba.so").display()
    );
    println!(
        "cargo:rerun-if-changed={}",
        drjit.join("libdrjit-core.so").display()
    );
}
