//! The media fields shared by every calculator subcommand.

use super::input::Fields;
use crate::crystals;
use crate::error::{Error, Result};
use crate::medium::Uniaxial;
use nalgebra::Vector3;
use num_complex::Complex64 as C64;

/// Wavelength, exterior index and crystal read from the input.
pub struct Media {
    /// Vacuum wavelength in nm.
    pub wavelength_nm: f64,
    /// Exterior (isotropic) index.
    pub ext: C64,
    /// The crystal, optic axis in the local frame.
    pub crystal: Uniaxial,
}

/// Reads `wavelength_nm`, `ext_ior`, `eta_o`/`eta_e` or `material`, `kappa_o`, `kappa_e` and
/// `optic_axis`.
pub fn read(f: &mut Fields) -> Result<Media> {
    let wavelength_nm = f.required_number("wavelength_nm")?;
    if wavelength_nm <= 0.0 {
        return Err(Error::new("wavelength_nm", "must be > 0"));
    }
    let ext = read_ior(f, "ext_ior", wavelength_nm)?.unwrap_or(C64::new(1.0, 0.0));
    let (eta_o, eta_e) = read_indices(f, wavelength_nm)?;
    let axis = f.vector3("optic_axis")?;
    let axis = match axis {
        Some(a) => a,
        None if eta_o == eta_e => Vector3::z(),
        None => {
            return Err(Error::new(
                "optic_axis",
                "is required for a birefringent medium",
            ))
        }
    };
    let crystal = Uniaxial::new(eta_o, eta_e, axis)?;
    Ok(Media {
        wavelength_nm,
        ext,
        crystal,
    })
}

/// An isotropic index given as a number, `[re, im]` or a material name (Mitsuba's IOR names).
pub fn read_ior(f: &mut Fields, name: &'static str, wavelength_nm: f64) -> Result<Option<C64>> {
    let Some(v) = f.get(name) else {
        return Ok(None);
    };
    if let Some(s) = v.as_str() {
        return named_ior(name, s, wavelength_nm).map(Some);
    }
    super::input::complex(name, v).map(Some)
}

/// An isotropic material by name: Mitsuba's IOR table, or a named crystal's ordinary index if
/// the crystal is optically isotropic (none are) — otherwise an error listing the names.
fn named_ior(name: &str, s: &str, _wavelength_nm: f64) -> Result<C64> {
    crystals::isotropic_ior(s)
        .map(|n| C64::new(n, 0.0))
        .ok_or_else(|| {
            Error::new(
                name,
                format!(
                    "unknown material '{s}' (known: {})",
                    crystals::isotropic_names().join(", ")
                ),
            )
        })
}

/// `(η_o, η_e)` from `eta_o`/`eta_e` or `material`, plus optional `kappa_o`/`kappa_e`.
fn read_indices(f: &mut Fields, wavelength_nm: f64) -> Result<(C64, C64)> {
    let material = f.string("material")?;
    let (eo, ee) = (f.complex("eta_o")?, f.complex("eta_e")?);
    let (ko, ke) = (f.number("kappa_o")?, f.number("kappa_e")?);
    let (mut eo, mut ee) = match (material, eo, ee) {
        (Some(m), None, None) => crystal_indices(m, wavelength_nm)?,
        (Some(_), _, _) => {
            return Err(Error::new(
                "material",
                "give either material or eta_o and eta_e, not both",
            ))
        }
        (None, Some(o), Some(e)) => (o, e),
        (None, None, None) => return Err(Error::new("eta_o", "give eta_o and eta_e, or material")),
        (None, Some(_), None) => return Err(Error::new("eta_e", "is required with eta_o")),
        (None, None, Some(_)) => return Err(Error::new("eta_o", "is required with eta_e")),
    };
    for (name, eta, kappa) in [("kappa_o", &mut eo, ko), ("kappa_e", &mut ee, ke)] {
        if let Some(k) = kappa {
            if eta.im != 0.0 {
                return Err(Error::new(
                    name,
                    "the index already has an imaginary part; give one or the other",
                ));
            }
            eta.im = k;
        }
    }
    Ok((eo, ee))
}

/// Indices of a named crystal at `wavelength_nm` (error outside its fit's range).
pub fn crystal_indices(name: &str, wavelength_nm: f64) -> Result<(C64, C64)> {
    let c = crystals::crystal(name).ok_or_else(|| {
        Error::new(
            "material",
            format!(
                "unknown crystal '{name}' (known: {})",
                crystals::crystal_names().join(", ")
            ),
        )
    })?;
    let (lo, hi) = c.range_nm;
    if !(lo..=hi).contains(&wavelength_nm) {
        return Err(Error::new(
            "wavelength_nm",
            format!(
                "{wavelength_nm} nm is outside the {lo}-{hi} nm range of the dispersion data for {}",
                c.name
            ),
        ));
    }
    let re = |n: f64| C64::new(n, 0.0);
    Ok((
        re(c.ordinary.index(wavelength_nm)),
        re(c.extraordinary.index(wavelength_nm)),
    ))
}
