//! The media fields shared by every calculator subcommand.

use super::input::Fields;
use crate::error::{Error, Result};
use crate::material::crystals;
use crate::material::{check_kappa, Material};
use crate::optics::medium::Uniaxial;
use nalgebra::Vector3;
use num_complex::Complex64 as C64;

/// Wavelength, exterior index and crystal read from the input.
pub struct Media {
    /// Vacuum wavelength in nm.
    pub wavelength_nm: f64,
    /// Exterior (isotropic) index.
    pub ext: C64,
    /// The crystal at `wavelength_nm`, optic axis in the local frame.
    pub crystal: Uniaxial,
    /// Its indices as functions of wavelength.
    pub material: Material,
    /// Warnings for the output (a named crystal's fit extrapolated at `wavelength_nm`).
    pub warnings: Vec<String>,
}

/// Reads `wavelength_nm`, `ext_ior`, `eta_o`/`eta_e` or `material`, `kappa_o`, `kappa_e` and
/// `optic_axis`.
pub fn read(f: &mut Fields) -> Result<Media> {
    let wavelength_nm = f.required_number("wavelength_nm")?;
    if wavelength_nm <= 0.0 {
        return Err(Error::new("wavelength_nm", "must be > 0"));
    }
    let ext = read_ior(f, "ext_ior")?.unwrap_or(C64::new(1.0, 0.0));
    let material = read_material(f)?;
    let warnings = material
        .coverage(wavelength_nm, wavelength_nm)?
        .into_iter()
        .collect();
    let (eta_o, eta_e) = material.indices(wavelength_nm, 0.0)?;
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
        material,
        warnings,
    })
}

/// An isotropic index given as a number, `[re, im]` or a material name (Mitsuba's IOR names).
pub fn read_ior(f: &mut Fields, name: &'static str) -> Result<Option<C64>> {
    let Some(v) = f.get(name) else {
        return Ok(None);
    };
    if let Some(s) = v.as_str() {
        return named_ior(name, s).map(Some);
    }
    super::input::complex(name, v).map(Some)
}

/// An isotropic material by name (Mitsuba's IOR table), or an error listing the names.
fn named_ior(name: &str, s: &str) -> Result<C64> {
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

/// The material from `eta_o`/`eta_e` or `material`, plus optional `kappa_o`/`kappa_e`.
pub(super) fn read_material(f: &mut Fields) -> Result<Material> {
    let name = f.string("material")?;
    let (eo, ee) = (f.complex("eta_o")?, f.complex("eta_e")?);
    let (ko, ke) = (f.number("kappa_o")?, f.number("kappa_e")?);
    match (name, eo, ee) {
        (Some(m), None, None) => Material::named(m, ko.unwrap_or(0.0), ke.unwrap_or(0.0)),
        (Some(_), _, _) => Err(Error::new(
            "material",
            "give either material or eta_o and eta_e, not both",
        )),
        (None, Some(o), Some(e)) => {
            let add = |name: &str, eta: C64, kappa: Option<f64>| match kappa {
                Some(_) if eta.im != 0.0 => Err(Error::new(
                    name,
                    "the index already has an imaginary part; give one or the other",
                )),
                Some(k) => Ok(C64::new(eta.re, check_kappa(name, k)?)),
                None => Ok(eta),
            };
            Material::constant(add("kappa_o", o, ko)?, add("kappa_e", e, ke)?)
        }
        (None, None, None) => Err(Error::new("eta_o", "give eta_o and eta_e, or material")),
        (None, Some(_), None) => Err(Error::new("eta_e", "is required with eta_o")),
        (None, None, Some(_)) => Err(Error::new("eta_o", "is required with eta_e")),
    }
}
