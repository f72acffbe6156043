//! The meaning of a band's width, written out independently of `birefringent::band`: what the
//! plugin's `filter_bandwidth` and the calculator's `bandwidth_nm` promise (plugin/README.md,
//! "`filter_bandwidth`"): a Gaussian of full width at half maximum `fwhm` (nm, in wavelength)
//! around `center`, taken as a unit-mass Gaussian in wavenumber k = 2 pi / lambda.

use std::f64::consts::{LN_2, PI, TAU};

/// `(mu, sigma)` in wavenumber (rad/nm) of the band of FWHM `fwhm` around `center` (nm).
///
/// Derivation: exp(-x^2 / (2 s^2)) falls to one half at x = s sqrt(2 ln 2), so a Gaussian of
/// full width at half maximum w has s = w / (2 sqrt(2 ln 2)) = w / 2.3548. In wavelength that is
/// sigma_lambda; carried to k = 2 pi / lambda through |dk/dlambda| = 2 pi / lambda^2 at the
/// centre, sigma_k = 2 pi sigma_lambda / center^2, and mu = 2 pi / center.
pub fn documented_band(center: f64, fwhm: f64) -> (f64, f64) {
    let sigma_lambda = fwhm / (2.0 * (2.0 * LN_2).sqrt());
    (TAU / center, TAU * sigma_lambda / (center * center))
}

/// The band as a weight per nm of wavelength: N(k(lambda); mu, sigma) |dk/dlambda|.
pub fn band_weight(center: f64, fwhm: f64) -> impl Fn(f64) -> f64 {
    let (mu, sigma) = documented_band(center, fwhm);
    move |lambda: f64| {
        let k = TAU / lambda;
        let z = (k - mu) / sigma;
        (-0.5 * z * z).exp() / (sigma * (2.0 * PI).sqrt()) * TAU / (lambda * lambda)
    }
}

/// The fringe contrast a band leaves to a term with optical path difference `d_nm`:
/// |integral of N(k; mu, sigma) exp(i k D) dk| = exp(-sigma^2 D^2 / 2) (the characteristic
/// function of a normal distribution).
pub fn contrast(center: f64, fwhm: f64, d_nm: f64) -> f64 {
    let (_, sigma) = documented_band(center, fwhm);
    (-0.5 * (sigma * d_nm).powi(2)).exp()
}
