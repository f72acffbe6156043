//! Exact optics of uniaxial birefringent media, after S. Steinberg, "Analytic Spectral
//! Integration of Birefringence-Induced Iridescence", Computer Graphics Forum 38(4), 2019.
//! Equation numbers S1..S26 refer to that paper's supplemental material.
//!
//! Everything is computed in `f64`. Time convention: `exp(i (k·r − ω t))`, absorbing indices
//! `n + iκ` with `κ ≥ 0`.

pub mod admittance;
pub mod calc;
pub mod cmath;
pub mod crystals;
pub mod dispersion;
pub mod error;
pub mod etalon;
pub mod ffi;
pub mod fields;
pub mod frame;
pub mod fresnel;
pub mod interface;
pub mod isotropic;
pub mod lobes;
pub mod material;
pub mod medium;
pub mod modes;
pub mod mueller;
pub mod paths;
pub mod sampling;
pub mod slab;
pub mod spectral;
pub mod surface;

pub use error::{Error, Result};
pub use num_complex::Complex64 as C64;
