//! One colour channel of a weight set, the unit of a channel render: the plate integrated in
//! closed form over that channel's weight (docs/physics.md, section 7, "Channel renders").

use super::data;
use super::weights::{self, white_scale, WeightSet};

/// The name of [`Channel::LUMINANCE`]: the plugins' default `channel` in the mono variants.
pub const DEFAULT_CHANNEL: &str = "xyz-d65:Y";

/// Channel `index` (0, 1, 2) of a weight set, named `"<set>:<channel>"`, e.g. `"srgb-d65:R"`
/// or `"xyz-d65:Y"`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Channel {
    /// The weight set.
    pub set: WeightSet,
    /// The channel within the set (0, 1, 2).
    pub index: usize,
}

impl Channel {
    /// CIE 1931 Y under D65: the luminance of the sRGB channels (the default of the mono
    /// variants, named [`DEFAULT_CHANNEL`]).
    pub const LUMINANCE: Channel = Channel {
        set: WeightSet::XyzD65,
        index: 1,
    };

    /// Parses `"<set>:<channel>"` (a name of [`WeightSet::parse`] and one of its
    /// [`WeightSet::channel_names`]).
    pub fn parse(name: &str) -> Option<Channel> {
        let (set, letter) = name.split_once(':')?;
        let set = WeightSet::parse(set)?;
        let index = set.channel_names().iter().position(|&c| c == letter)?;
        Some(Channel { set, index })
    }

    /// The name accepted by [`Channel::parse`].
    pub fn name(self) -> String {
        format!(
            "{}:{}",
            self.set.name(),
            self.set.channel_names()[self.index]
        )
    }

    /// Every accepted name, for messages.
    pub fn all_names() -> Vec<String> {
        WeightSet::ALL
            .iter()
            .flat_map(|&set| (0..3).map(move |index| Channel { set, index }.name()))
            .collect()
    }

    /// The mean wavelength (nm) of the channel's weight where it is positive,
    /// `∫ λ w⁺(λ) dλ / ∫ w⁺(λ) dλ` on the 1-nm table: where a channel render evaluates what it
    /// cannot integrate over the channel (a bulk crystal's refraction, whose directions depend
    /// on the wavelength). The positive part, because the signed sRGB weights' negative lobes
    /// lie in another channel's band.
    pub fn mean_wavelength_nm(self) -> f64 {
        let (mut moment, mut mass) = (0.0, 0.0);
        for i in 0..data::N_TABLE {
            let lambda = data::LAMBDA_MIN_NM + i as f64;
            let w = weights::weight_per_nm(self.set, self.index, lambda).max(0.0);
            moment += lambda * w;
            mass += w;
        }
        moment / mass
    }
}

/// The matrix (row-major) that turns the three normalised channel values of `set` into linear
/// sRGB with the set's white at `Y = 1`: `XYZ_TO_SRGB · diag(white_scale)` for the `xyz-*` sets
/// (IEC 61966-2-1), `diag(white_scale)` (≈ identity) for `srgb-d65`.
pub fn to_linear_srgb(set: WeightSet) -> [[f64; 3]; 3] {
    let s = white_scale(set);
    let mut m = match set {
        WeightSet::SrgbD65 => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        WeightSet::XyzE | WeightSet::XyzD65 => data::XYZ_TO_SRGB,
    };
    for row in &mut m {
        for (x, scale) in row.iter_mut().zip(s) {
            *x *= scale;
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for name in Channel::all_names() {
            assert_eq!(Channel::parse(&name).unwrap().name(), name);
        }
        assert_eq!(Channel::parse(DEFAULT_CHANNEL), Some(Channel::LUMINANCE));
        for bad in [
            "xyz-d65",
            "xyz-d65:R",
            "srgb-d65:Y",
            "rgb:R",
            "srgb-d65:r",
            "",
        ] {
            assert_eq!(Channel::parse(bad), None, "{bad}");
        }
    }

    /// Each mean wavelength lies in its channel's band (ȳ·D65 peaks at 555-560 nm; the sRGB
    /// channels' positive lobes in the red, green and blue).
    #[test]
    fn mean_wavelengths_lie_in_their_bands() {
        let y = Channel::LUMINANCE.mean_wavelength_nm();
        assert!((554.0..560.0).contains(&y), "{y}");
        let rgb: Vec<f64> = (0..3)
            .map(|index| {
                Channel {
                    set: WeightSet::SrgbD65,
                    index,
                }
                .mean_wavelength_nm()
            })
            .collect();
        assert!((590.0..640.0).contains(&rgb[0]), "{rgb:?}");
        assert!((520.0..560.0).contains(&rgb[1]), "{rgb:?}");
        assert!((440.0..480.0).contains(&rgb[2]), "{rgb:?}");
    }

    /// The D65 white (every normalised channel 1) is sRGB (1, 1, 1) from both D65 sets, and the
    /// equal-energy white from `xyz-e` is the sRGB of CIE XYZ (1, 1, 1) (IEC 61966-2-1 matrix
    /// applied in the test): to the tables' rounding, 2e-3.
    #[test]
    fn whites_map_to_their_srgb() {
        let apply = |m: [[f64; 3]; 3]| -> Vec<f64> { m.iter().map(|r| r.iter().sum()).collect() };
        for set in [WeightSet::SrgbD65, WeightSet::XyzD65] {
            for v in apply(to_linear_srgb(set)) {
                assert!((v - 1.0).abs() < 2e-3, "{set:?} {v}");
            }
        }
        let e = apply(to_linear_srgb(WeightSet::XyzE));
        let want = [
            3.2406 - 1.5372 - 0.4986,
            -0.9689 + 1.8758 + 0.0415,
            0.0557 - 0.2040 + 1.0570,
        ];
        for (v, w) in e.iter().zip(want) {
            assert!((v - w).abs() < 2e-3, "{e:?}");
        }
    }
}
