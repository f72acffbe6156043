//! The optics of one interface between isotropic and uniaxial media at one wavelength: the
//! media, their normal modes and fields, the interface's scattering matrix, and the Stokes and
//! Mueller algebra of the light it scatters (eqs. S1-S19).

pub mod admittance;
pub mod clear_lobes;
pub mod fields;
pub mod frame;
pub mod fresnel;
pub mod interface;
pub mod lobes;
pub mod medium;
pub mod modes;
pub mod mueller;
pub mod surface;
pub mod uniaxial_fresnel;
