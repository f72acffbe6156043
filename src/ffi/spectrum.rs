//! The tagged spectrum of a plate query.

use super::bridge::ChannelSet;
use crate::error::{Error, Result};
use crate::render::plate::{Spectrum, MAX_BANDS};
use crate::spectral::weights::WeightSet;

/// What a plate query integrates over (see `bridge::PlateSpectrum`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlateSpectrum {
    /// Each lane's wavelengths, exact (`fwhm_nm` 0) or averaged over a Gaussian band.
    Bands {
        /// Full width at half maximum (nm).
        fwhm_nm: f64,
    },
    /// The sRGB channels.
    Srgb,
    /// The luminance: the Y channel of CIE XYZ under D65.
    Luminance,
}

/// Exact at each lane's wavelengths.
pub fn exact_spectrum() -> Box<PlateSpectrum> {
    Box::new(PlateSpectrum::Bands { fwhm_nm: 0.0 })
}

/// A Gaussian band of `fwhm_nm` around each wavelength (checked per lane by the plate query:
/// `params::Bandwidth`, which depends on the wavelength).
pub fn band_spectrum(fwhm_nm: f64) -> Box<PlateSpectrum> {
    Box::new(PlateSpectrum::Bands { fwhm_nm })
}

/// A channel set.
pub fn channel_spectrum(set: ChannelSet) -> Result<Box<PlateSpectrum>> {
    match set {
        ChannelSet::Srgb => Ok(Box::new(PlateSpectrum::Srgb)),
        ChannelSet::Luminance => Ok(Box::new(PlateSpectrum::Luminance)),
        _ => Err(Error::new(
            "set",
            format!("unknown channel set {}", set.repr),
        )),
    }
}

/// Index of the Y channel in the XYZ weight sets.
const Y: usize = 1;

impl PlateSpectrum {
    /// Channels of a query with `wavelengths` wavelength columns.
    pub fn channels(&self, wavelengths: usize) -> usize {
        match self {
            PlateSpectrum::Bands { .. } => wavelengths,
            PlateSpectrum::Srgb => 3,
            PlateSpectrum::Luminance => 1,
        }
    }

    /// Checks the number of wavelength columns a query gives.
    pub fn check_wavelength_columns(&self, wavelengths: usize) -> Result<()> {
        let ok = match self {
            PlateSpectrum::Bands { .. } => (1..=MAX_BANDS).contains(&wavelengths),
            _ => wavelengths == 0,
        };
        if ok {
            Ok(())
        } else {
            let want = match self {
                PlateSpectrum::Bands { .. } => format!("1 to {MAX_BANDS}"),
                _ => "none (a channel set)".into(),
            };
            Err(Error::new(
                "wavelengths_nm",
                format!("{wavelengths} wavelength columns given, the spectrum takes {want}"),
            ))
        }
    }

    /// The core's spectrum for one lane with wavelengths `lambda[..count]`, and which of its
    /// channels are the query's (`None`: all).
    pub fn lane(&self, lambda: [f64; MAX_BANDS], count: usize) -> (Spectrum, Option<usize>) {
        match *self {
            PlateSpectrum::Bands { fwhm_nm } => (
                Spectrum::Bands {
                    wavelengths_nm: lambda,
                    count,
                    fwhm_nm,
                },
                None,
            ),
            PlateSpectrum::Srgb => (Spectrum::Weights(WeightSet::SrgbD65), None),
            PlateSpectrum::Luminance => (Spectrum::Weights(WeightSet::XyzD65), Some(Y)),
        }
    }
}
