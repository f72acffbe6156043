//! The plate over a spectrum: its Mueller matrices integrated over a Gaussian band or over the
//! channels of a weight set ([`crate::colour`]), with the plate-independent rules of
//! [`crate::quadrature`].

pub mod amplitudes;
pub mod classes;
pub mod dense;
pub mod envelope;
pub mod gaussian;
pub mod group;
pub mod layout;
pub mod model;
pub mod narrow;
pub mod pointwise;
pub mod reference;
pub mod route;
pub mod survey;
