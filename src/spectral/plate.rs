//! A plate whose indices may depend on wavelength: what spectral integration evaluates at
//! each wavelength it needs.

use crate::error::Result;
use crate::material::Material;
use crate::medium::Uniaxial;
use crate::slab::Slab;
use nalgebra::Vector3;
use num_complex::Complex64 as C64;

/// A uniaxial plate between isotropic media, with possibly dispersive principal indices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plate {
    /// The plate's material.
    pub material: Material,
    /// Added to `Re η_e` (photoelastic stress).
    pub birefringence: f64,
    /// Exterior (incident side) index.
    pub ext: C64,
    /// Exit side index.
    pub exit: C64,
    /// Optic axis, local frame.
    pub axis: Vector3<f64>,
    /// Thickness (nm).
    pub thickness_nm: f64,
}

impl Plate {
    /// The slab at `lambda_nm`.
    pub fn at(&self, lambda_nm: f64) -> Result<Slab> {
        let (eo, ee) = self.material.indices(lambda_nm, self.birefringence)?;
        Slab::new(
            self.ext,
            Uniaxial::new(eo, ee, self.axis)?,
            self.exit,
            self.thickness_nm,
        )
    }

    /// True if any index varies with wavelength.
    pub fn is_dispersive(&self) -> bool {
        self.material.is_dispersive()
    }
}
