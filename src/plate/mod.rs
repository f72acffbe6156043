//! The plane-parallel plate at one wavelength: the slab's exact optics ([`slab`]), its
//! path-class expansion ([`paths`]) and the closed form of a lossless isotropic layer
//! ([`etalon`]); and [`Plate`], a plate whose indices may depend on wavelength, which is what
//! spectral integration evaluates at each wavelength it needs.

pub mod etalon;
pub mod paths;
pub mod slab;

use crate::error::Result;
use crate::material::Material;
use crate::optics::frame::PlaneFrame;
use crate::optics::medium::Uniaxial;
use crate::plate::etalon::Etalon;
use crate::plate::slab::Slab;
use crate::real::complex::Cx;
use crate::real::Real;
use nalgebra::Vector3;
use num_complex::Complex64 as C64;

/// A uniaxial plate between isotropic media, with possibly dispersive principal indices.
///
/// Its parameters are validated where the plate is assembled from a caller's input
/// ([`crate::render::plate::PlateQuery::new`], the calculator's reader): real exterior and exit
/// indices, a unit optic axis, a [`crate::params::Thickness`]. [`Plate::at`] relies on that.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plate<T: Real = f64> {
    /// The plate's material.
    pub material: Material<T>,
    /// Added to `Re η_e` (photoelastic stress).
    pub birefringence: T,
    /// Exterior (incident side) index.
    pub ext: Cx<T>,
    /// Exit side index.
    pub exit: Cx<T>,
    /// Optic axis, local frame (any non-zero length: [`Plate::at`] normalises it).
    pub axis: Vector3<T>,
    /// Thickness (nm).
    pub thickness_nm: T,
}

impl<T: Real> Plate<T> {
    /// The slab at `lambda_nm` (the plate's own parameters are not checked again: the indices
    /// at the wavelength are).
    pub fn at(&self, lambda_nm: T) -> Result<Slab<T>> {
        let (eta_o, eta_e) = self.material.indices(lambda_nm, self.birefringence)?;
        Ok(Slab {
            top: Uniaxial::isotropic_unchecked(self.ext),
            layer: Uniaxial {
                eta_o,
                eta_e,
                axis: self.axis / self.axis.dot(&self.axis).sqrt(),
            },
            bottom: Uniaxial::isotropic_unchecked(self.exit),
            thickness_nm: self.thickness_nm,
        })
    }
}

impl Plate {
    /// The layer's normal components `[o↓, e↓, o↑, e↑]` at `lambda_nm` for incidence parameter
    /// `beta` in the plane of `frame` (what [`Slab::layer_q`] gives, without building the slab).
    pub fn layer_q(&self, lambda_nm: f64, frame: &PlaneFrame, beta: C64) -> Result<[C64; 4]> {
        let (eo, ee) = self.material.indices(lambda_nm, self.birefringence)?;
        let layer = Uniaxial::new(eo, ee, frame.to_working(self.axis))?;
        Ok(crate::optics::modes::normal_components(&layer, beta))
    }

    /// True if any index varies with wavelength.
    pub fn is_dispersive(&self) -> bool {
        self.material.is_dispersive()
    }

    /// The isotropic fast path ([`Etalon`]) for incidence parameter `beta`, where it applies:
    /// a non-dispersive plate with `η_o = η_e` real and no added birefringence, the wave
    /// propagating in it. (The layer's indices do not depend on `lambda_nm` then; it only
    /// selects where [`Material::indices`] is evaluated.)
    pub fn etalon(&self, lambda_nm: f64, beta: C64) -> Option<Etalon> {
        if self.is_dispersive() || self.birefringence != 0.0 {
            return None;
        }
        let (eo, ee) = self.material.indices(lambda_nm, 0.0).ok()?;
        if eo != ee {
            return None;
        }
        Etalon::new(self.ext, eo, self.exit, beta, self.thickness_nm)
    }
}
