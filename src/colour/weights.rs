//! Spectral weight functions of camera channels, for analytic spectral integration of
//! interference (thin-film / birefringent) intensities.
//!
//! An interference intensity is a sum of terms `a cos(k D + phi)` in the wavenumber
//! `k = 2 pi / lambda` (rad/nm, lambda in nm), `D` an optical path difference in nm. A channel
//! records `integral w(k) I(k) dk`, with `w(k)` its spectral weight per unit wavenumber. Each
//! weight is fitted by a sum of Gaussians, `w(k) ~= sum_j a_j N(k; mu_j, sigma_j)` with `N` the
//! unit-mass normal pdf, so that every term integrates in closed form:
//! `integral N(k; mu, sigma) e^{i k D} dk = e^{i mu D - sigma^2 D^2 / 2}` ([`fourier`]).
//!
//! Weight sets (per unit wavelength, tables at 1 nm from 360 to 830 nm, see `data.rs`
//! for the sources: CIE 015:2018, ISO/CIE 11664-1 and -2, IEC 61966-2-1):
//! * `xyz-e`: CIE 1931 x̄, ȳ, z̄ under illuminant E;
//! * `xyz-d65`: x̄, ȳ, z̄ times the D65 relative SPD;
//! * `srgb-d65`: the IEC 61966-2-1 XYZ -> linear-sRGB matrix applied to the `xyz-d65` weights
//!   (signed weights).
//!
//! Every channel is normalised so that a spectrally flat response of 1 gives exactly 1
//! (`integral w dlambda = 1`). [`white_scale`] turns normalised channel values back into
//! colorimetric values (XYZ or linear sRGB with the flat spectrum at `Y = 1`).

use super::data;
use crate::band::Gaussian;

/// A named set of three channel weights.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WeightSet {
    /// CIE 1931 XYZ under the equal-energy illuminant E.
    XyzE,
    /// CIE 1931 XYZ under CIE standard illuminant D65.
    XyzD65,
    /// Linear sRGB (IEC 61966-2-1) under D65.
    SrgbD65,
}

impl WeightSet {
    /// All weight sets.
    pub const ALL: [WeightSet; 3] = [WeightSet::XyzE, WeightSet::XyzD65, WeightSet::SrgbD65];

    /// Parses `"xyz-e"`, `"xyz-d65"` or `"srgb-d65"`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "xyz-e" => Some(WeightSet::XyzE),
            "xyz-d65" => Some(WeightSet::XyzD65),
            "srgb-d65" => Some(WeightSet::SrgbD65),
            _ => None,
        }
    }

    /// The name accepted by [`WeightSet::parse`].
    pub fn name(self) -> &'static str {
        match self {
            WeightSet::XyzE => "xyz-e",
            WeightSet::XyzD65 => "xyz-d65",
            WeightSet::SrgbD65 => "srgb-d65",
        }
    }

    /// Channel names, `["X", "Y", "Z"]` or `["R", "G", "B"]`.
    pub fn channel_names(self) -> [&'static str; 3] {
        match self {
            WeightSet::XyzE | WeightSet::XyzD65 => ["X", "Y", "Z"],
            WeightSet::SrgbD65 => ["R", "G", "B"],
        }
    }

    /// True if some channel's weight is negative somewhere (linear sRGB's colour matching
    /// functions are; XYZ's are not).
    pub fn is_signed(self) -> bool {
        self == WeightSet::SrgbD65
    }

    pub(crate) fn index(self) -> usize {
        match self {
            WeightSet::XyzE => 0,
            WeightSet::XyzD65 => 1,
            WeightSet::SrgbD65 => 2,
        }
    }

    /// Integral over wavelength of the un-normalised channel weights.
    fn norm(self) -> &'static [f64; 3] {
        match self {
            WeightSet::XyzE => &data::NORM_XYZ_E,
            WeightSet::XyzD65 => &data::NORM_XYZ_D65,
            WeightSet::SrgbD65 => &data::NORM_SRGB_D65,
        }
    }
}

/// The Gaussian fit of channel `channel` (0, 1, 2) of `set`, per unit wavenumber.
///
/// # Panics
/// If `channel > 2`.
pub fn gaussians(set: WeightSet, channel: usize) -> &'static [Gaussian] {
    match set {
        WeightSet::XyzE => data::FIT_XYZ_E[channel],
        WeightSet::XyzD65 => data::FIT_XYZ_D65[channel],
        WeightSet::SrgbD65 => data::FIT_SRGB_D65[channel],
    }
}

/// Upper bound on `|fourier(set, channel, D) - exact transform of the tabulated weight|`, valid
/// for every `D`: the integral over `k` of the absolute fit residual (computed by the generator).
pub fn fourier_error_bound(set: WeightSet, channel: usize) -> f64 {
    data::FIT_L1_ERROR[set.index()][channel]
}

/// Un-normalised weight of `set`/`channel` at table node `i` (wavelength 360 + i nm).
fn node_weight(set: WeightSet, channel: usize, i: usize) -> f64 {
    let cmf = [data::CMF_X[i], data::CMF_Y[i], data::CMF_Z[i]];
    match set {
        WeightSet::XyzE => cmf[channel],
        WeightSet::XyzD65 => cmf[channel] * data::D65[i],
        WeightSet::SrgbD65 => {
            let m = &data::XYZ_TO_SRGB[channel];
            (m[0] * cmf[0] + m[1] * cmf[1] + m[2] * cmf[2]) * data::D65[i]
        }
    }
}

/// The tabulated weight of one channel at wavelength λ (nm) per unit wavelength, normalised
/// (∫ w dλ = 1), linear interpolation of the 1-nm table, 0 outside 360..830.
///
/// # Panics
/// If `channel > 2`.
pub fn weight_per_nm(set: WeightSet, channel: usize, lambda_nm: f64) -> f64 {
    assert!(channel < 3, "channel {channel} out of range");
    // NaN is not contained in the range either, so it maps to 0 as well.
    if !(data::LAMBDA_MIN_NM..=data::LAMBDA_MAX_NM).contains(&lambda_nm) {
        return 0.0;
    }
    let x = lambda_nm - data::LAMBDA_MIN_NM;
    let i = (x.floor() as usize).min(data::N_TABLE - 2);
    let t = x - i as f64;
    let w0 = node_weight(set, channel, i);
    let w1 = node_weight(set, channel, i + 1);
    (w0 + t * (w1 - w0)) / set.norm()[channel]
}

/// The tabulated weight per unit wavenumber at `k` (rad/nm): `w(λ) λ² / (2π)`, `λ = 2π / k`.
pub fn weight_per_wavenumber(set: WeightSet, channel: usize, k: f64) -> f64 {
    if k <= 0.0 {
        return 0.0;
    }
    let lambda = std::f64::consts::TAU / k;
    weight_per_nm(set, channel, lambda) * lambda * lambda / std::f64::consts::TAU
}

/// The Gaussian fit per unit wavenumber at `k` (rad/nm).
pub fn fit_per_wavenumber(set: WeightSet, channel: usize, k: f64) -> f64 {
    let inv_sqrt_tau = 1.0 / std::f64::consts::TAU.sqrt();
    gaussians(set, channel)
        .iter()
        .map(|g| {
            let z = (k - g.mu) / g.sigma;
            g.amplitude * inv_sqrt_tau / g.sigma * (-0.5 * z * z).exp()
        })
        .sum()
}

/// Closed-form ∫ w(k) e^{i k D} dk of the Gaussian fit, returned as (re, im):
/// sum_j a_j exp(-sigma_j^2 D^2/2) (cos mu_j D, sin mu_j D). D in nm (optical path difference).
pub fn fourier(set: WeightSet, channel: usize, opd_nm: f64) -> (f64, f64) {
    let mut re = 0.0;
    let mut im = 0.0;
    for g in gaussians(set, channel) {
        let sd = g.sigma * opd_nm;
        let env = g.amplitude * (-0.5 * sd * sd).exp();
        let (s, c) = (g.mu * opd_nm).sin_cos();
        re += env * c;
        im += env * s;
    }
    (re, im)
}

/// Per-channel factors that turn normalised channel values of `set` into colorimetric values
/// scaled so that the spectrally flat response (perfect white under the set's illuminant) has
/// luminance `Y = 1`: XYZ for the `xyz-*` sets (the white point, e.g. ≈ (0.9505, 1, 1.089)
/// for D65), linear sRGB for `srgb-d65` (≈ (1, 1, 1)).
pub fn white_scale(set: WeightSet) -> [f64; 3] {
    let n = set.norm();
    let y = match set {
        WeightSet::XyzE | WeightSet::XyzD65 => n[1],
        // Y of the un-normalised weights is the Y row of SRGB_TO_XYZ applied to the R, G, B norms
        WeightSet::SrgbD65 => {
            let m = &data::SRGB_TO_XYZ[1];
            m[0] * n[0] + m[1] * n[1] + m[2] * n[2]
        }
    };
    [n[0] / y, n[1] / y, n[2] / y]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::convert::{ciede2000, linear_srgb_to_xyz, xyz_to_lab};
    use std::f64::consts::TAU;

    /// Reference transform of the tabulated weight, `∫ w(λ) e^{i 2π D / λ} dλ` (equal to
    /// `∫ w(k) e^{i k D} dk`), by composite Simpson in λ with step `H` nm. The weight is linear
    /// between integer nm, which are nodes, so the error is that of Simpson on the smooth
    /// factor: about `H^4/180 * max|φ'|^4` with `φ' = 2π D / λ² <= 0.97 rad/nm` at D = 20 µm,
    /// i.e. below 1e-7 for `H = 0.1` (the weight integrates to 1).
    fn quadrature_fourier(set: WeightSet, channel: usize, opd: f64) -> (f64, f64) {
        const H: f64 = 0.1;
        let n = ((data::LAMBDA_MAX_NM - data::LAMBDA_MIN_NM) / H).round() as usize;
        let (mut re, mut im) = (0.0, 0.0);
        for i in 0..=n {
            let lambda = data::LAMBDA_MIN_NM + i as f64 * H;
            let c = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let w = c * weight_per_nm(set, channel, lambda);
            let (s, co) = (TAU * opd / lambda).sin_cos();
            re += w * co;
            im += w * s;
        }
        (re * H / 3.0, im * H / 3.0)
    }

    #[test]
    fn parse_and_names() {
        for set in WeightSet::ALL {
            assert_eq!(WeightSet::parse(set.name()), Some(set));
        }
        assert_eq!(WeightSet::parse("xyz"), None);
        assert_eq!(WeightSet::SrgbD65.channel_names(), ["R", "G", "B"]);
        assert_eq!(WeightSet::XyzD65.channel_names(), ["X", "Y", "Z"]);
    }

    #[test]
    fn tables_are_the_cie_ones() {
        // spot values of CIE 015:2018 (1931 CMFs at 1 nm, D65 at 5 nm)
        let at = |nm: usize| nm - 360;
        assert_eq!(data::CMF_Y[at(555)], 1.0);
        assert_eq!(data::CMF_X[at(600)], 1.0622);
        assert_eq!(data::CMF_Z[at(450)], 1.77211);
        assert_eq!(data::D65[at(560)], 100.0);
        assert_eq!(data::D65[at(460)], 117.812);
        assert_eq!(data::D65[at(830)], 60.3125);
        assert_eq!(data::D65.len(), 471);
        // D65 white point (Y = 1) from the 1-nm tables: CIE 015:2018 gives x, y = 0.31272, 0.32903
        let w = white_scale(WeightSet::XyzD65);
        let s = w[0] + w[1] + w[2];
        assert!((w[0] / s - 0.31272).abs() < 1e-5, "x = {}", w[0] / s);
        assert!((w[1] / s - 0.32903).abs() < 1e-5, "y = {}", w[1] / s);
    }

    /// Why the masses must sum to 1: `fourier(set, c, 0)` = Σ a_j is the closed form's response
    /// to a spectrally flat input, and the normalisation makes the true one ∫ w dk = ∫ w dλ = 1
    /// (the normal pdfs have unit mass over all k, and the part at k < 0, which no physical
    /// wavenumber reaches, is below Φ(-6) ≈ 1e-9 since μ/σ > 6). A white object must come out
    /// white, so 1e-3 (invisible, ΔE00 ≲ 0.1) is the requirement; the generator enforces
    /// Σ a_j = 1 as a constraint of the least-squares fit, so it in fact holds to rounding.
    #[test]
    fn fits_integrate_to_one() {
        for set in WeightSet::ALL {
            for c in 0..3 {
                let g = gaussians(set, c);
                assert!(g.len() >= 4 && g.len() <= 8);
                let sum: f64 = g.iter().map(|g| g.amplitude).sum();
                assert!((sum - 1.0).abs() < 1e-3, "{} {c}: {sum}", set.name());
                assert!((sum - 1.0).abs() < 1e-12, "{} {c}: {sum}", set.name());
                for g in g {
                    assert!(g.mu / g.sigma > 6.0, "negligible mass at k < 0");
                }
                assert!((fourier(set, c, 0.0).0 - 1.0).abs() < 1e-12);
                // the table itself integrates to 1 (trapezoid = exact for piecewise linear)
                let tab: f64 = (0..data::N_TABLE)
                    .map(|i| {
                        let lam = data::LAMBDA_MIN_NM + i as f64;
                        let f = if i == 0 || i == data::N_TABLE - 1 {
                            0.5
                        } else {
                            1.0
                        };
                        f * weight_per_nm(set, c, lam)
                    })
                    .sum();
                assert!((tab - 1.0).abs() < 1e-12, "{} {c}: table {tab}", set.name());
            }
        }
    }

    #[test]
    fn weight_per_nm_interpolates_and_vanishes_outside() {
        for set in WeightSet::ALL {
            for c in 0..3 {
                assert_eq!(weight_per_nm(set, c, 359.999), 0.0);
                assert_eq!(weight_per_nm(set, c, 830.001), 0.0);
                assert_eq!(weight_per_nm(set, c, f64::NAN), 0.0);
                let (a, b) = (weight_per_nm(set, c, 500.0), weight_per_nm(set, c, 501.0));
                let m = weight_per_nm(set, c, 500.25);
                assert!((m - (0.75 * a + 0.25 * b)).abs() <= 1e-12 * a.abs().max(b.abs()));
                assert!(weight_per_nm(set, c, 830.0).is_finite());
            }
        }
        // xyz-e Y at 555 nm is ȳ = 1 over ∫ȳ dλ (≈ 106.857 nm for the 1-nm table)
        let y555 = weight_per_nm(WeightSet::XyzE, 1, 555.0);
        assert!((1.0 / y555 - 106.857).abs() < 1e-2, "{}", 1.0 / y555);
    }

    /// The closed form against quadrature of the tabulated weight, D in [0, 20 µm].
    ///
    /// Justification of the tolerance: for every D,
    /// `|∫ (fit - w) e^{ikD} dk| <= ∫ |fit - w| dk = L1`, so the error can never exceed the fit's
    /// L1 residual (1.7e-3 to 7.9e-3 for these fits); it is recomputed here by quadrature in k
    /// (step 1e-6 rad/nm) and must agree with the generator's `FIT_L1_ERROR`, and the measured
    /// error must be below it (plus the 1e-6 quadrature error). The error actually reached is
    /// smaller, 6e-4 to 2.9e-3 depending on the channel: it must stay below the generator's own
    /// measurement `FOURIER_MAX_ERROR_20UM` (max over a 10-nm grid of D, independent Simpson
    /// quadrature) plus 5% (this test samples other D) and 1e-6 (quadrature).
    #[test]
    fn fourier_matches_quadrature() {
        for set in WeightSet::ALL {
            for c in 0..3 {
                // L1 residual by midpoint quadrature in k over the support of fit and table
                let (k0, k1, dk) = (TAU / 2000.0, TAU / 250.0, 1e-6);
                let n = ((k1 - k0) / dk) as usize;
                let l1: f64 = (0..n)
                    .map(|i| {
                        let k = k0 + (i as f64 + 0.5) * dk;
                        (fit_per_wavenumber(set, c, k) - weight_per_wavenumber(set, c, k)).abs()
                    })
                    .sum::<f64>()
                    * dk;
                let bound = fourier_error_bound(set, c);
                assert!(
                    (l1 - bound).abs() < 0.02 * bound,
                    "{} {c}: L1 {l1} vs {bound}",
                    set.name()
                );
                let mut max_err: f64 = 0.0;
                let mut d = 0.0;
                while d <= 20_000.0 {
                    let (re, im) = fourier(set, c, d);
                    let (qr, qi) = quadrature_fourier(set, c, d);
                    let err = (re - qr).hypot(im - qi);
                    assert!(
                        err <= l1 + 1e-6,
                        "{} {c} D={d}: {err} > L1 {l1}",
                        set.name()
                    );
                    max_err = max_err.max(err);
                    d += 37.0;
                }
                let tol = 1.05 * data::FOURIER_MAX_ERROR_20UM[set.index()][c] + 1e-6;
                assert!(
                    max_err <= tol,
                    "{} {c}: max err {max_err} > {tol}",
                    set.name()
                );
            }
        }
    }

    /// End to end: the colour of the two-beam fringe `I(k) = (1 + cos kD) / 2` (what a thin film
    /// or a birefringent plate between polarisers shows) from the closed form vs from quadrature,
    /// as CIEDE2000 (CIELAB relative to the set's white at Y = 1), D in [0, 20 µm]. It must
    /// stay below the generator's measurement `FRINGE_MAX_DELTA_E00_20UM` + 5% (other D samples)
    /// and, as a requirement, below 1 (about one just-noticeable difference).
    #[test]
    fn fringe_colour_delta_e() {
        for set in WeightSet::ALL {
            let scale = white_scale(set);
            let to_xyz = |v: [f64; 3]| {
                let s = [v[0] * scale[0], v[1] * scale[1], v[2] * scale[2]];
                match set {
                    WeightSet::SrgbD65 => linear_srgb_to_xyz(s),
                    _ => s,
                }
            };
            let white = to_xyz([1.0; 3]);
            assert!((white[1] - 1.0).abs() < 1e-12);
            let mut max_de: f64 = 0.0;
            let mut d = 0.0;
            while d <= 20_000.0 {
                let fit: [f64; 3] = std::array::from_fn(|c| 0.5 * (1.0 + fourier(set, c, d).0));
                let quad: [f64; 3] =
                    std::array::from_fn(|c| 0.5 * (1.0 + quadrature_fourier(set, c, d).0));
                let de = ciede2000(
                    xyz_to_lab(to_xyz(fit), white),
                    xyz_to_lab(to_xyz(quad), white),
                );
                max_de = max_de.max(de);
                d += 37.0;
            }
            let measured = data::FRINGE_MAX_DELTA_E00_20UM[set.index()];
            assert!(
                max_de <= 1.05 * measured + 1e-3,
                "{}: ΔE00 {max_de} > {measured}",
                set.name()
            );
            assert!(max_de < 1.0, "{}: ΔE00 {max_de}", set.name());
        }
    }
}
