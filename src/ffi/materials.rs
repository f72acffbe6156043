//! The material table of the bridge.

use super::guard::guarded;
use crate::error::{Error, Result};
use crate::material::{check_kappa, Material, RENDER_RANGE_NM};
use crate::params::{angle_warning, thickness_warning, Length, Thickness};
use crate::C64;

/// Materials by index (see `bridge::Materials`), each with the warning of
/// [`Material::coverage`] over [`RENDER_RANGE_NM`] (the wavelengths the plugins evaluate: a named
/// crystal whose data do not reach them), empty if none.
#[derive(Clone, Debug, Default)]
pub struct Materials(Vec<(Material, String)>);

/// An empty table.
pub fn new_materials() -> Box<Materials> {
    Box::default()
}

impl Materials {
    fn push(&mut self, m: Result<Material>) -> Result<u32> {
        let m = m?;
        let warning = guarded(|| m.coverage(RENDER_RANGE_NM.0, RENDER_RANGE_NM.1))?;
        let index = u32::try_from(self.0.len())
            .map_err(|_| Error::new("material", "too many materials in one table"))?;
        self.0.push((m, warning.unwrap_or_default()));
        Ok(index)
    }

    /// See `bridge::Materials::add_named`.
    pub fn add_named(&mut self, name: &str, kappa_o: f64, kappa_e: f64) -> Result<u32> {
        let m = guarded(|| Material::named(name, kappa_o, kappa_e));
        self.push(m)
    }

    /// See `bridge::Materials::add_constant`.
    pub fn add_constant(
        &mut self,
        eta_o: f64,
        eta_e: f64,
        kappa_o: f64,
        kappa_e: f64,
    ) -> Result<u32> {
        let m = guarded(|| {
            let (ko, ke) = (
                check_kappa("kappa_o", kappa_o)?,
                check_kappa("kappa_e", kappa_e)?,
            );
            Material::constant(C64::new(eta_o, ko), C64::new(eta_e, ke))
        });
        self.push(m)
    }

    /// See `bridge::Materials::is_isotropic` (false for an index not in the table).
    pub fn is_isotropic(&self, index: u32) -> bool {
        self.get(index).is_ok_and(|m| m.is_isotropic())
    }

    /// See `bridge::Materials::warning` (empty for an index not in the table).
    pub fn warning(&self, index: u32) -> String {
        self.0
            .get(index as usize)
            .map_or_else(String::new, |(_, w)| w.clone())
    }

    /// See `bridge::Materials::plate_warning` (a thickness warning only for an index in the
    /// table and parameters the load check accepts; that check refuses the others).
    pub fn plate_warning(
        &self,
        index: u32,
        thickness_nm: f64,
        birefringence: f64,
        axis_angle_deg: f64,
    ) -> String {
        let thickness = guarded(|| {
            let m = self.get(index)?;
            let t = Thickness::new("thickness", thickness_nm, Length::Micrometres)?;
            let (eta_o, eta_e) = m.indices(550.0, birefringence)?;
            Ok(thickness_warning(
                "thickness",
                t,
                Length::Micrometres,
                eta_e.re - eta_o.re,
            ))
        });
        let angle = angle_warning("axis_angle", axis_angle_deg);
        [thickness.ok().flatten(), angle]
            .into_iter()
            .flatten()
            .collect::<Vec<_>>()
            .join("; ")
    }

    /// Material `index`.
    pub fn get(&self, index: u32) -> Result<&Material> {
        self.0.get(index as usize).map(|(m, _)| m).ok_or_else(|| {
            Error::new(
                "material",
                format!(
                    "index {index} is not in the table of {} materials",
                    self.0.len()
                ),
            )
        })
    }
}
