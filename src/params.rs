//! Validated parameters. Each is checked once, where it enters the core (the bridge for the
//! plugins, the JSON reader for the calculator), with the name and the unit the caller's user
//! wrote, and becomes a value that the constructors inside the core take without checking
//! again. One rule per parameter, here; each boundary passes its own name: the plugin's
//! `thickness` (µm) and `filter_bandwidth`, the calculator's `thickness_um` and
//! `spectrum.bandwidth_nm`.

use crate::error::{Error, Result};

/// Largest plate thickness (nm): 1 m. Beyond, the phases `k d q` (~1e7 rad per metre at
/// 550 nm) lose the digits that interference needs.
pub const THICKNESS_MAX_NM: f64 = 1e9;

/// A unit of length a caller's user gives a thickness in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Length {
    /// Nanometres (the core's unit of lengths and wavelengths).
    Nanometres,
    /// Micrometres.
    Micrometres,
}

impl Length {
    /// Nanometres per unit.
    fn nm(self) -> f64 {
        match self {
            Length::Nanometres => 1.0,
            Length::Micrometres => 1e3,
        }
    }

    fn symbol(self) -> &'static str {
        match self {
            Length::Nanometres => "nm",
            Length::Micrometres => "µm",
        }
    }
}

/// A plate thickness: finite, within `[0, THICKNESS_MAX_NM]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thickness {
    nm: f64,
}

impl Thickness {
    /// The thickness `nm` (nanometres) of the caller's parameter `name`, whose user gives it in
    /// `shown_in`: the message of an invalid value names `name` and speaks `shown_in`.
    pub fn new(name: &str, nm: f64, shown_in: Length) -> Result<Self> {
        if nm.is_finite() && (0.0..=THICKNESS_MAX_NM).contains(&nm) {
            return Ok(Thickness { nm });
        }
        let (unit, per) = (shown_in.symbol(), shown_in.nm());
        Err(Error::new(
            name,
            format!(
                "must be within [0, {:e}] {unit} (1 m), got {} {unit}",
                THICKNESS_MAX_NM / per,
                nm / per
            ),
        ))
    }

    /// [`Thickness::new`] of a value given in nanometres under the name `thickness_nm`.
    pub fn from_nm(nm: f64) -> Result<Self> {
        Thickness::new("thickness_nm", nm, Length::Nanometres)
    }

    /// The thickness in nanometres.
    pub fn nm(self) -> f64 {
        self.nm
    }
}

/// The full width at half maximum of a Gaussian band around a wavelength: finite, `>= 0` and
/// at most a quarter of the wavelength (a Gaussian in wavenumber then keeps all its weight far
/// from `k = 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bandwidth {
    fwhm_nm: f64,
}

impl Bandwidth {
    /// The FWHM `fwhm_nm` (nm) of the caller's parameter `name` for a band centred on
    /// `wavelength_nm` (a valid wavelength).
    pub fn new(name: &str, fwhm_nm: f64, wavelength_nm: f64) -> Result<Self> {
        let max = 0.25 * wavelength_nm;
        if fwhm_nm.is_finite() && (0.0..=max).contains(&fwhm_nm) {
            return Ok(Bandwidth { fwhm_nm });
        }
        Err(Error::new(
            name,
            format!(
                "must be within [0, {max}] nm (a quarter of the wavelength {wavelength_nm} nm), got {fwhm_nm} nm"
            ),
        ))
    }

    /// The FWHM in nanometres.
    pub fn fwhm_nm(self) -> f64 {
        self.fwhm_nm
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The limits are inclusive, every message names the caller's parameter in its unit.
    #[test]
    fn limits_and_messages() {
        assert!(Thickness::new("t", 0.0, Length::Micrometres).is_ok());
        assert!(Thickness::new("t", THICKNESS_MAX_NM, Length::Micrometres).is_ok());
        let e = Thickness::new("thickness_um", 2e9, Length::Micrometres).unwrap_err();
        assert_eq!(
            e.to_string(),
            "thickness_um: must be within [0, 1e6] µm (1 m), got 2000000 µm"
        );
        let e = Thickness::from_nm(f64::NAN).unwrap_err();
        assert_eq!(
            e.to_string(),
            "thickness_nm: must be within [0, 1e9] nm (1 m), got NaN nm"
        );
        assert!(Bandwidth::new("b", 100.0, 400.0).is_ok());
        assert!(Bandwidth::new("b", 0.0, 400.0).is_ok());
        for bad in [-1e-300, 100.000_001, f64::NAN, f64::INFINITY] {
            let e = Bandwidth::new("filter_bandwidth", bad, 400.0).unwrap_err();
            assert_eq!(e.parameter, "filter_bandwidth");
            assert!(e.message.contains("[0, 100] nm"), "{e}");
        }
    }
}
