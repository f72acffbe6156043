//! Generates the C++ side of the bridge (`src/ffi/mod.rs`): the header
//! `birefringent/src/ffi/mod.rs.h` (exported to dependent crates' build scripts, for the
//! Mitsuba plugin in `cpp/`) and its glue code, compiled into this library.

fn main() {
    cxx_build::CFG.include_prefix = "birefringent";
    cxx_build::bridge("src/ffi/mod.rs")
        .std("c++17")
        .compile("birefringent-bridge");
    println!("cargo:rerun-if-changed=src/ffi/mod.rs");
}
