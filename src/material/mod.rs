//! A uniaxial material: its two principal complex indices as functions of wavelength.

pub mod crystals;
pub mod dispersion;

use crate::error::{Error, Result};
use crate::material::crystals::Crystal;
use num_complex::Complex64 as C64;

/// Vacuum wavelengths accepted (nm): X-rays to millimetre waves; the optics is continuum
/// electrodynamics, so anything beyond is outside the model (and outside f64's comfort).
pub const WAVELENGTH_RANGE: (f64, f64) = (1.0, 1e6);

/// Fails (naming `wavelength_nm`) outside [`WAVELENGTH_RANGE`] or for NaN.
pub fn check_wavelength(lambda_nm: f64) -> Result<()> {
    if (WAVELENGTH_RANGE.0..=WAVELENGTH_RANGE.1).contains(&lambda_nm) {
        Ok(())
    } else {
        Err(Error::new(
            "wavelength_nm",
            format!(
                "must be within [{}, {}] nm, got {lambda_nm}",
                WAVELENGTH_RANGE.0, WAVELENGTH_RANGE.1
            ),
        ))
    }
}

/// One principal index: `n(λ) + iκ`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Index {
    /// Wavelength-independent.
    Constant(C64),
    /// A named crystal's ordinary or extraordinary dispersion, plus a constant extinction.
    Crystal {
        /// The crystal's dispersion data.
        crystal: &'static Crystal,
        /// `true` for the extraordinary index.
        extraordinary: bool,
        /// Extinction coefficient κ.
        kappa: f64,
    },
}

impl Index {
    /// The complex index at `lambda_nm`. Crystal fits are evaluated outside their range too
    /// (see [`Material::out_of_range`]).
    pub fn at(&self, lambda_nm: f64) -> C64 {
        match *self {
            Index::Constant(n) => n,
            Index::Crystal {
                crystal,
                extraordinary,
                kappa,
            } => {
                let d = if extraordinary {
                    &crystal.extraordinary
                } else {
                    &crystal.ordinary
                };
                C64::new(d.index(lambda_nm), kappa)
            }
        }
    }

    /// True if the index varies with wavelength.
    pub fn is_dispersive(&self) -> bool {
        matches!(self, Index::Crystal { .. })
    }
}

/// Ordinary and extraordinary indices of a uniaxial material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Ordinary index.
    pub eta_o: Index,
    /// Extraordinary index.
    pub eta_e: Index,
}

impl Material {
    /// Constant indices (validated).
    pub fn constant(eta_o: C64, eta_e: C64) -> Result<Self> {
        Ok(Material {
            eta_o: Index::Constant(check_index("eta_o", eta_o)?),
            eta_e: Index::Constant(check_index("eta_e", eta_e)?),
        })
    }

    /// A named crystal with extinction coefficients `kappa_o`, `kappa_e`.
    pub fn named(name: &str, kappa_o: f64, kappa_e: f64) -> Result<Self> {
        let crystal = crystals::crystal(name).ok_or_else(|| {
            Error::new(
                "material",
                format!(
                    "unknown crystal '{name}' (known: {})",
                    crystals::crystal_names().join(", ")
                ),
            )
        })?;
        check_kappa("kappa_o", kappa_o)?;
        check_kappa("kappa_e", kappa_e)?;
        let index = |extraordinary, kappa| Index::Crystal {
            crystal,
            extraordinary,
            kappa,
        };
        Ok(Material {
            eta_o: index(false, kappa_o),
            eta_e: index(true, kappa_e),
        })
    }

    /// `(η_o, η_e)` at `lambda_nm`, with `birefringence` added to `Re η_e` (photoelastic
    /// stress: `n_e − n_o = C (σ₁ − σ₂)` on an isotropic material). Fails (naming the
    /// parameter) if the result is not a valid index.
    pub fn indices(&self, lambda_nm: f64, birefringence: f64) -> Result<(C64, C64)> {
        check_wavelength(lambda_nm)?;
        if !birefringence.is_finite() {
            return Err(Error::new("birefringence", "must be finite"));
        }
        let eo = check_index("eta_o", self.eta_o.at(lambda_nm))?;
        let ee = self.eta_e.at(lambda_nm) + birefringence;
        let ee = check_index(
            if birefringence == 0.0 {
                "eta_e"
            } else {
                "birefringence"
            },
            ee,
        )?;
        Ok((eo, ee))
    }

    /// True if any index varies with wavelength.
    pub fn is_dispersive(&self) -> bool {
        self.eta_o.is_dispersive() || self.eta_e.is_dispersive()
    }

    /// The crystal whose dispersion fit does not cover `[lo, hi]` nm, if any.
    pub fn out_of_range(&self, lo: f64, hi: f64) -> Option<&'static str> {
        [self.eta_o, self.eta_e].iter().find_map(|i| match i {
            Index::Crystal { crystal, .. }
                if crystal.range_nm.0 > lo || crystal.range_nm.1 < hi =>
            {
                Some(crystal.name)
            }
            _ => None,
        })
    }
}

/// Validates the index of an isotropic medium that light arrives from or leaves into: real and
/// `> 0`. (With absorption there the incident plane wave is inhomogeneous and power fractions
/// are undefined.)
pub fn check_clear_index(parameter: &str, eta: C64) -> Result<C64> {
    check_index(parameter, eta)?;
    if eta.im != 0.0 {
        return Err(Error::new(
            parameter,
            "must be real: absorbing exterior or exit media are not supported (the incident wave would be inhomogeneous and power fractions undefined)",
        ));
    }
    Ok(eta)
}

/// Range of the real part of an index (every optical material lies well inside; beyond, the
/// results leave the range of the renderer's single-precision numbers).
pub const INDEX_RANGE: (f64, f64) = (1e-3, 1e3);
/// Largest extinction coefficient `κ` (metals reach ~100 in the infrared).
pub const KAPPA_MAX: f64 = 1e3;

/// Validates an extinction coefficient given on its own (`kappa_o`, `kappa_e`): finite,
/// `0 <= κ <=` [`KAPPA_MAX`], the range [`check_index`] allows for an index's imaginary part.
pub fn check_kappa(parameter: &str, kappa: f64) -> Result<f64> {
    if kappa.is_finite() && (0.0..=KAPPA_MAX).contains(&kappa) {
        Ok(kappa)
    } else {
        Err(Error::new(
            parameter,
            format!("must be within [0, {KAPPA_MAX}], got {kappa}"),
        ))
    }
}

/// Validates one complex index `n + iκ`: finite, `n` within [`INDEX_RANGE`], `0 <= κ <=`
/// [`KAPPA_MAX`].
pub fn check_index(parameter: &str, eta: C64) -> Result<C64> {
    if !eta.re.is_finite() || !eta.im.is_finite() {
        return Err(Error::new(parameter, "must be finite"));
    }
    if eta.re <= 0.0 {
        return Err(Error::new(
            parameter,
            format!("real part of the index must be > 0, got {}", eta.re),
        ));
    }
    if !(INDEX_RANGE.0..=INDEX_RANGE.1).contains(&eta.re) {
        return Err(Error::new(
            parameter,
            format!(
                "real part of the index must be within [{}, {}], got {}",
                INDEX_RANGE.0, INDEX_RANGE.1, eta.re
            ),
        ));
    }
    if eta.im > KAPPA_MAX {
        return Err(Error::new(
            parameter,
            format!(
                "extinction coefficient (imaginary part) must be <= {KAPPA_MAX}, got {}",
                eta.im
            ),
        ));
    }
    if eta.im < 0.0 {
        return Err(Error::new(
            parameter,
            format!(
                "extinction coefficient (imaginary part) must be >= 0 in the n + i kappa convention, got {}",
                eta.im
            ),
        ));
    }
    Ok(eta)
}
