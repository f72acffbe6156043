//! The one lobe a path follows at a surface: chosen among the fixed slots
//! ([`crate::render::slots`]) of all channels of a query (the wavelengths a spectral renderer
//! traces along one path, or colour channels), so that every channel's expectation is the sum
//! of its lobes.
//!
//! A slot is chosen with probability proportional to the magnitude of its unpolarised power
//! fraction (`|M00|` of the physical transfer, without the radiance factor of Radiance mode:
//! [`PathLobe::power`]) summed over the channels (a signed sRGB channel is negative where the
//! plate's colour lies outside the gamut: a lobe negative in every channel of the query, as in
//! a one-channel render, must still be chosen for the expectation to hold). The probabilities
//! are thus the same in both transport modes and, for a dielectric interface, those of
//! Mitsuba's `dielectric` (its Fresnel `R` and `T`): with the probability detached, the
//! gradient of an attached sample's weight is then the built-in's (`render::tangents`). The
//! ray follows the slot's direction in the first channel that has it (the hero wavelength), and
//! every channel carries its own lobe of that slot divided by the probability. With dispersion the other wavelengths
//! are thus propagated along the hero's direction: their Fresnel, polarisation, o/e split and
//! radiance factor are exact, their angular dispersion (~0.5 degrees over the visible for
//! calcite) is neglected. A slot that is the only candidate is chosen with probability 1 whatever
//! its weight (the single-lobe convention of Mitsuba's own BSDFs: the sample's value is then
//! the lobe itself, the form `eval_null_transmission` needs).

use crate::render::slots::Slots;
#[cfg(doc)]
use crate::render::PathLobe;

/// The chosen slot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Choice {
    /// Its slot index.
    pub slot: usize,
    /// Its selection probability.
    pub pdf: f64,
    /// The first channel that has it (whose direction the ray follows).
    pub hero: usize,
}

/// Chooses a slot among those `enabled(slot)` allows that exist in at least one channel of
/// `channels`, with the uniform number `u` in [0, 1) walking the cumulative weights in slot
/// order. `None` if no slot can be chosen.
pub fn choose<const S: usize>(
    channels: &[Slots<S>],
    enabled: impl Fn(usize) -> bool,
    u: f64,
) -> Option<Choice> {
    // Each candidate's weight summed over the channels; `None` for the other slots.
    let weight: [Option<f64>; S] = std::array::from_fn(|slot| {
        let lobes = channels.iter().filter_map(|c| c[slot].as_ref());
        (enabled(slot) && lobes.clone().next().is_some())
            .then(|| lobes.map(|l| l.power.abs()).sum())
    });
    let chosen = |slot: usize, pdf: f64| Choice {
        slot,
        pdf,
        hero: channels.iter().position(|c| c[slot].is_some()).unwrap_or(0),
    };
    let mut candidates = weight
        .iter()
        .enumerate()
        .filter_map(|(s, w)| w.map(|w| (s, w)));
    let first = candidates.next()?;
    if candidates.next().is_none() {
        return Some(chosen(first.0, 1.0));
    }
    let total: f64 = weight.iter().flatten().sum();
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    // The last slot with weight catches u * total == total (rounding).
    let (target, mut acc, mut pick) = (u * total, 0.0, None);
    for (slot, w) in weight.iter().enumerate() {
        match *w {
            Some(w) if w > 0.0 => {
                pick = Some((slot, w));
                acc += w;
                if target < acc {
                    break;
                }
            }
            _ => {}
        }
    }
    pick.map(|(slot, w)| chosen(slot, w / total))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::PathLobe;
    use nalgebra::{Matrix4, Vector3};

    fn lobe(weight: f64) -> Option<PathLobe> {
        let z = Vector3::z();
        Some(PathLobe::new(
            0,
            z,
            (z, z),
            Matrix4::identity() * weight,
            1.0,
        ))
    }

    /// Probabilities are the channel-summed weights over their total; the walk picks slots in
    /// order; a slot present only in a later channel takes that channel as its hero.
    #[test]
    fn probabilities_follow_the_summed_weights() {
        let channels = [[lobe(0.1), lobe(0.3), None], [lobe(0.1), None, lobe(0.5)]];
        let c = choose(&channels, |_| true, 0.0).unwrap();
        assert_eq!((c.slot, c.hero), (0, 0));
        assert!((c.pdf - 0.2).abs() < 1e-15);
        let c = choose(&channels, |_| true, 0.3).unwrap();
        assert_eq!(c.slot, 1);
        let c = choose(&channels, |_| true, 0.99).unwrap();
        assert_eq!((c.slot, c.hero), (2, 1));
        assert!((c.pdf - 0.5).abs() < 1e-15);
        // u = 1 (rounding of a caller's u): the last slot with weight.
        assert_eq!(choose(&channels, |_| true, 1.0).unwrap().slot, 2);
    }

    /// A negative lobe (a signed channel) is chosen by its magnitude: one channel with lobes
    /// -0.2 and 0.6 picks them with probabilities 0.25 and 0.75, so that the expectation
    /// -0.2 + 0.6 holds (with negatives counted as 0 it came out 0.6).
    #[test]
    fn negative_lobes_are_chosen_by_magnitude() {
        let channels = [[lobe(-0.2), lobe(0.6)]];
        let c = choose(&channels, |_| true, 0.1).unwrap();
        assert_eq!(c.slot, 0);
        assert!((c.pdf - 0.25).abs() < 1e-15);
        let c = choose(&channels, |_| true, 0.5).unwrap();
        assert_eq!(c.slot, 1);
        assert!((c.pdf - 0.75).abs() < 1e-15);
    }

    /// A single candidate has probability 1 even at zero weight; several candidates without
    /// weight give nothing; disabled slots never appear.
    #[test]
    fn single_candidates_and_empty_choices() {
        let channels = [[lobe(-0.2), lobe(0.0), None]];
        let c = choose(&channels, |s| s == 0, 0.7).unwrap();
        assert_eq!((c.slot, c.pdf), (0, 1.0));
        let zero = [[lobe(0.0), lobe(0.0), None]];
        assert_eq!(choose(&zero, |_| true, 0.5), None);
        assert_eq!(choose(&channels, |s| s == 2, 0.5), None);
        let none: [Slots<3>; 1] = [[None, None, None]];
        assert_eq!(choose(&none, |_| true, 0.5), None);
    }
}
