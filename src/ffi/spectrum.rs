//! The tagged spectrum of a plate query.

use crate::colour::channel::{self, Channel};
use crate::colour::weights::WeightSet;
use crate::error::{Error, Result};
use crate::render::thin::{Spectrum, MAX_BANDS};

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
    /// One colour channel (a mono variant's render).
    Channel(Channel),
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

/// The three linear sRGB channels (the RGB variants).
pub fn srgb_spectrum() -> Box<PlateSpectrum> {
    Box::new(PlateSpectrum::Srgb)
}

/// The colour channel named `name` (the plugins' `channel` parameter, e.g. `"srgb-d65:R"`).
pub fn colour_channel_spectrum(name: &str) -> Result<Box<PlateSpectrum>> {
    Ok(Box::new(PlateSpectrum::Channel(parse_channel(name)?)))
}

/// The plugins' default `channel` in the mono variants (the luminance).
pub fn default_channel() -> &'static str {
    channel::DEFAULT_CHANNEL
}

/// The wavelength (nm) at which a channel render evaluates a bulk crystal, whose refraction
/// cannot be integrated over the channel: the channel's mean wavelength
/// ([`Channel::mean_wavelength_nm`]).
pub fn colour_channel_wavelength(name: &str) -> Result<f64> {
    Ok(parse_channel(name)?.mean_wavelength_nm())
}

/// The matrix (row-major) from the normalised channel values of the weight set `weights`
/// (`"srgb-d65"`, `"xyz-d65"`, `"xyz-e"`) to linear sRGB ([`channel::to_linear_srgb`]).
pub fn channels_to_linear_srgb(weights: &str) -> Result<[f64; 9]> {
    let set = WeightSet::parse(weights).ok_or_else(|| {
        Error::new(
            "weights",
            format!("must be \"srgb-d65\", \"xyz-d65\" or \"xyz-e\", got \"{weights}\""),
        )
    })?;
    let m = channel::to_linear_srgb(set);
    Ok(std::array::from_fn(|i| m[i / 3][i % 3]))
}

/// The plugins' `channel` parameter, validated.
fn parse_channel(name: &str) -> Result<Channel> {
    Channel::parse(name).ok_or_else(|| {
        Error::new(
            "channel",
            format!(
                "must be one of {}, got \"{name}\"",
                Channel::all_names().join(", ")
            ),
        )
    })
}

impl PlateSpectrum {
    /// Channels of a query with `wavelengths` wavelength columns.
    pub fn channels(&self, wavelengths: usize) -> usize {
        match self {
            PlateSpectrum::Bands { .. } => wavelengths,
            PlateSpectrum::Srgb => 3,
            PlateSpectrum::Channel(_) => 1,
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

    /// Why a query over this spectrum has no derivatives, or nothing for the exact plate at
    /// each wavelength (its recorded program carries Dr.Jit's derivatives). The closed-form
    /// integrals over a band or over colour channels run in the core on the host, outside
    /// Dr.Jit's graph: a gradient through them would silently be 0, so the shim refuses it
    /// with this reason.
    pub fn gradients_refused(&self) -> String {
        let instead = "render gradients in llvm_ad_spectral or llvm_ad_spectral_polarized with filter_bandwidth 0, where the plate is exact at each sampled wavelength";
        match *self {
            PlateSpectrum::Bands { fwhm_nm: 0.0 } => String::new(),
            PlateSpectrum::Bands { fwhm_nm } => format!("filter_bandwidth: gradients of a plate averaged over a band ({fwhm_nm} nm) are not available: set filter_bandwidth to 0 ({instead})"),
            PlateSpectrum::Srgb => format!("variant: gradients of a plate integrated over the sRGB channels (llvm_ad_rgb) are not available: {instead}"),
            PlateSpectrum::Channel(c) => format!("variant: gradients of a plate integrated over the colour channel \"{}\" (llvm_ad_mono, llvm_ad_mono_polarized) are not available: {instead}", c.name()),
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
            PlateSpectrum::Channel(c) => (Spectrum::Weights(c.set), Some(c.index)),
        }
    }
}
