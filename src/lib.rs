//! Exact optics of uniaxial birefringent media, after S. Steinberg, "Analytic Spectral
//! Integration of Birefringence-Induced Iridescence", Computer Graphics Forum 38(4), 2019.
//! Equation numbers S1..S26 refer to that paper's supplemental material.
//!
//! Everything is computed in `f64`. Time convention: `exp(i (k·r − ω t))`, absorbing indices
//! `n + iκ` with `κ ≥ 0`.

pub mod band;
pub mod calc;
pub mod cmath;
pub mod colour;
pub mod error;
pub mod ffi;
pub mod material;
pub mod optics;
pub mod params;
pub mod plate;
pub mod quadrature;
pub mod real;
pub mod record;
pub mod render;
pub mod scratch;
pub mod spectral;
pub mod stack;

pub use error::{Error, ErrorKind, Result};
pub use num_complex::Complex64 as C64;
