//! Compiles the C++ shim (src/*.cpp) against the headers of the `mitsuba`, `drjit` and
//! `nanobind` wheels of a Python environment and links it with libmitsuba and Dr.Jit.
//!
//! The wheels are those of the site-packages directory `MITSUBA_SITE_PACKAGES`; `MITSUBA_WHEELS`
//! names their versions (e.g. `drjit-1.5.0 mitsuba-3.9.1 nanobind-2.14.0`, the names of their
//! dist-info directories; `make plugin-lib` passes both, and the Python build backend,
//! build_backend/, runs that). The build is keyed on the versions, not on the directory: another
//! environment with the same wheels (pip's isolated build environment) reuses it. The libraries
//! linked against are copied into the build directory for that reason.
//!
//! The compile flags below must match the flags the PyPI wheels are built with: above all
//! `-march=ivybridge`, which sets Dr.Jit's array padding and so the layout of Mitsuba's structs
//! (a mismatch compiles, loads and renders garbage). The library finds libmitsuba and libdrjit
//! through RUNPATHs relative to itself (`$ORIGIN/../mitsuba`, `$ORIGIN/../drjit`): installed,
//! the package directory sits beside `mitsuba/` and `drjit/` in site-packages.

use std::path::{Path, PathBuf};

/// The wheels whose headers and libraries the shim is built against.
const WHEELS: [&str; 3] = ["drjit", "mitsuba", "nanobind"];

/// `name-version` of each wheel installed in `site` (its dist-info directory), sorted.
fn installed(site: &Path) -> Vec<String> {
    let entries = std::fs::read_dir(site)
        .unwrap_or_else(|e| panic!("MITSUBA_SITE_PACKAGES ({}): {e}", site.display()));
    let mut found: Vec<String> = entries
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter_map(|n| n.strip_suffix(".dist-info").map(str::to_string))
        .filter(|n| WHEELS.iter().any(|w| n.starts_with(&format!("{w}-"))))
        .collect();
    found.sort();
    found
}

/// The libraries the plugin links, copied from `site` into `dir`.
fn copy_libraries(site: &Path, dir: &Path) {
    std::fs::create_dir_all(dir).expect("build directory");
    for lib in [
        "mitsuba/libmitsuba.so",
        "drjit/libdrjit-core.so",
        "drjit/libdrjit-extra.so",
        "drjit/libnanothread.so",
    ] {
        let from = site.join(lib);
        let to = dir.join(from.file_name().expect("a file name"));
        std::fs::copy(&from, &to).unwrap_or_else(|e| {
            panic!(
                "{}: {e}; MITSUBA_SITE_PACKAGES must hold the mitsuba and drjit wheels",
                from.display()
            )
        });
    }
}

fn main() {
    println!("cargo:rerun-if-env-changed=MITSUBA_WHEELS");
    let site = std::env::var_os("MITSUBA_SITE_PACKAGES").map(PathBuf::from).expect(
        "MITSUBA_SITE_PACKAGES must name the site-packages directory of the mitsuba, drjit and \
         nanobind wheels (make plugin-lib sets it)",
    );
    let wheels = std::env::var("MITSUBA_WHEELS").unwrap_or_default();
    let mut given: Vec<String> = wheels.split_whitespace().map(str::to_string).collect();
    given.sort();
    let found = installed(&site);
    if given != found || found.len() != WHEELS.len() {
        panic!(
            "MITSUBA_WHEELS ({given:?}) must name the {WHEELS:?} wheels installed in \
             MITSUBA_SITE_PACKAGES ({}): found {found:?}",
            site.display()
        );
    }

    let sources = [
        "src/thinbirefringent.cpp",
        "src/birefringent.cpp",
        "src/birefringentstack.cpp",
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
        "mitsuba/include",
        "drjit/include",
        "nanobind/include",
        "nanobind/ext/robin_map/include",
    ] {
        let dir = site.join(dir);
        build
            .flag("-isystem")
            .flag(dir.to_str().expect("UTF-8 path"));
    }
    build.compile("mitsuba-birefringent-shim");

    let libs = PathBuf::from(std::env::var("OUT_DIR").expect("OUT_DIR")).join("wheels");
    copy_libraries(&site, &libs);
    println!("cargo:rustc-link-search=native={}", libs.display());
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
    // Every source and header of the shim (cargo scans the directory).
    println!("cargo:rerun-if-changed=src");
}
