//! A spectral band: a unit-mass Gaussian in wavenumber `k = 2π/λ`, the shape every spectral
//! weight is made of (a narrow band around one sampled wavelength, or one term of a camera
//! channel's fit, [`crate::colour::weights`]).

/// One Gaussian term of a fit, in wavenumber `k = 2 pi / lambda` (rad/nm, lambda in nm):
/// `amplitude * N(k; mu, sigma)` with `N` the unit-mass normal pdf.
#[derive(Clone, Copy, Debug)]
pub struct Gaussian {
    /// Mass of the term (dimensionless; the masses of a channel sum to 1).
    pub amplitude: f64,
    /// Mean wavenumber (rad/nm).
    pub mu: f64,
    /// Standard deviation in wavenumber (rad/nm).
    pub sigma: f64,
}

/// Bands narrower than this fraction of their wavelength are the exact single-wavelength result:
/// across such a band the phase of the thickest accepted plate (1 m, index up to ~3) changes by
/// less than 1e-4 rad, and its Gaussian's width in wavenumber would underflow for the
/// subnormal widths a caller could pass.
pub const EXACT_BAND: f64 = 1e-12;

/// True if a band of FWHM `fwhm_nm` around `center_nm` is treated as exact ([`EXACT_BAND`]).
pub fn is_exact_band(fwhm_nm: f64, center_nm: f64) -> bool {
    fwhm_nm <= EXACT_BAND * center_nm
}

/// A unit-mass Gaussian band of full width at half maximum `fwhm_nm` (in wavelength) around
/// `center_nm`, expressed in wavenumber.
pub fn narrow_band(center_nm: f64, fwhm_nm: f64) -> Gaussian {
    let mu = std::f64::consts::TAU / center_nm;
    let sigma_nm = fwhm_nm / (8.0 * std::f64::consts::LN_2).sqrt();
    Gaussian {
        amplitude: 1.0,
        mu,
        sigma: mu * sigma_nm / center_nm,
    }
}
