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
//! Mitsuba's `dielectric` (its Fresnel `R` and `T`): with the probability detached (a recorded
//! program's `detach`), the gradient of an attached sample's weight is then the built-in's. The
//! ray follows the slot's direction in the first channel that has it (the hero wavelength), and
//! every channel carries its own lobe of that slot divided by the probability. With dispersion
//! the other wavelengths are thus propagated along the hero's direction: their Fresnel, polarisation, o/e split and
//! radiance factor are exact, their angular dispersion (~0.5 degrees over the visible for
//! calcite) is neglected. A slot that is the only candidate is chosen with probability 1 whatever
//! its weight (the single-lobe convention of Mitsuba's own BSDFs: the sample's value is then
//! the lobe itself, the form `eval_null_transmission` needs).

use crate::real::{Mask, Real, Select};
use crate::render::slots::Slots;
#[cfg(doc)]
use crate::render::PathLobe;
use nalgebra::{Matrix4, Vector3};

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
    let (chosen, pdf, valid) = walk(&candidates(channels, &enabled), u);
    let slot = chosen.iter().position(|&c| c)?;
    valid.then(|| Choice {
        slot,
        pdf,
        hero: channels
            .iter()
            .position(|c| c[slot].is_some_and(|l| l.exists))
            .unwrap_or(0),
    })
}

/// Each slot's candidacy (enabled, and existing in a channel) and weight (`|power|` summed
/// over the channels that have it).
fn candidates<T: Real, const S: usize>(
    channels: &[Slots<S, T>],
    enabled: &impl Fn(usize) -> bool,
) -> [(T::Mask, T); S] {
    std::array::from_fn(|slot| {
        let mut candidate = T::Mask::cst(false);
        let mut weight = T::zero();
        if enabled(slot) {
            for l in channels.iter().filter_map(|c| c[slot].as_ref()) {
                candidate = candidate | l.exists;
                weight += T::select(l.exists, l.power.abs(), T::zero());
            }
        }
        (candidate, weight)
    })
}

/// The walk of the module docs over slots `(candidate, weight)`: which slot is chosen (one
/// mask per slot, at most one holding), its probability, and whether one is chosen (a single
/// candidate always is, with probability 1; several need a positive total weight).
fn walk<T: Real, const S: usize>(slots: &[(T::Mask, T); S], u: T) -> ([T::Mask; S], T, T::Mask) {
    let (no, zero, one) = (T::Mask::cst(false), T::zero(), T::one());
    // The first candidate, and whether there is exactly one.
    let (mut seen, mut many) = (no, no);
    let mut first = [no; S];
    for (f, &(candidate, _)) in first.iter_mut().zip(slots) {
        many = many | (seen & candidate);
        *f = candidate & !seen;
        seen = seen | candidate;
    }
    let single = seen & !many;
    let total = slots
        .iter()
        .fold(zero, |acc, &(c, w)| acc + T::select(c, w, zero));
    // The last slot with weight catches u * total == total (rounding).
    let target = u * total;
    let (mut acc, mut done, mut weight) = (zero, no, zero);
    let mut pick = [no; S];
    for s in 0..S {
        let (candidate, w) = slots[s];
        let positive = candidate & w.gt(zero);
        acc += T::select(positive, w, zero);
        let take = !done & positive;
        for p in pick.iter_mut().take(s) {
            *p = *p & !take;
        }
        pick[s] = take;
        weight = T::select(take, w, weight);
        done = done | (positive & target.lt(acc));
    }
    let picked = pick.iter().fold(no, |m, &p| m | p);
    let chosen = std::array::from_fn(|s| (single & first[s]) | (!single & pick[s]));
    let pdf = T::select(single, one, weight / T::select(picked, total, one));
    let valid = single | (total.gt(zero) & picked);
    (chosen, pdf, valid)
}

/// A chosen lobe as Mitsuba's sample takes it, over the reals `T`: in `C` channels (at most).
#[derive(Clone, Copy, Debug)]
pub struct Sampled<T: Real, const C: usize> {
    /// Where a lobe was chosen.
    pub valid: T::Mask,
    /// The chosen slot (as a number).
    pub slot: T,
    /// Mitsuba's component of the chosen slot.
    pub component: T,
    /// Its selection probability (detached: no derivative flows through it).
    pub pdf: T,
    /// The hero channel's `bs.eta`.
    pub eta: T,
    /// The hero channel's `wo`.
    pub wo: Vector3<T>,
    /// Each channel's frame of the arriving light (the hero's where a channel lacks the lobe).
    pub in_x: [Vector3<T>; C],
    /// Each channel's frame of the leaving light.
    pub out_x: [Vector3<T>; C],
    /// Each channel's Mueller matrix over the probability (zero where it lacks the lobe).
    pub value: [Matrix4<T>; C],
}

/// The lobe a path follows among the slots of `channels` (the walk of [`choose`] with the
/// uniform number `u`, over the slots `enabled` allows), as Mitsuba's sample: the hero
/// channel's direction and index ratio, each channel's matrix over the probability.
pub fn sample<T: Real, const S: usize, const C: usize>(
    channels: &[Slots<S, T>; C],
    enabled: impl Fn(usize) -> bool,
    component: impl Fn(usize) -> usize,
    u: T,
) -> Sampled<T, C> {
    let (chosen, pdf, valid) = walk(&candidates(channels, &enabled), u);
    // The probability carries no derivative (as Mitsuba's `dielectric` detaches its Fresnel
    // choice): the gradient of an attached sample's weight is then that of its lobe.
    let pdf = pdf.detach();
    let zero = T::zero();
    let z3 = Vector3::from_element(zero);
    let mut out = Sampled {
        valid,
        slot: zero,
        component: zero,
        pdf,
        eta: zero,
        wo: z3,
        in_x: [z3; C],
        out_x: [z3; C],
        value: [Matrix4::from_element(zero); C],
    };
    // The hero: the first channel that has the slot; later channels choose in reverse order.
    for (s, &picked) in chosen.iter().enumerate() {
        if picked.known() == Some(false) {
            continue;
        }
        out.slot = T::select(picked, T::cst(s as f64), out.slot);
        out.component = T::select(picked, T::cst(component(s) as f64), out.component);
        for lobe in channels.iter().rev().filter_map(|c| c[s].as_ref()) {
            let hero = picked & lobe.exists;
            out.wo = Select::select(hero, lobe.wo, out.wo);
            out.eta = T::select(hero, lobe.eta, out.eta);
            for c in 0..C {
                out.in_x[c] = Select::select(hero, lobe.in_stokes_x, out.in_x[c]);
                out.out_x[c] = Select::select(hero, lobe.out_stokes_x, out.out_x[c]);
            }
        }
    }
    // Lanes without a lobe divide by one (their numbers are finite, and so their derivatives).
    let safe_pdf = T::select(valid, pdf, T::one());
    for (s, &picked) in chosen.iter().enumerate() {
        if picked.known() == Some(false) {
            continue;
        }
        for (c, slots) in channels.iter().enumerate() {
            let Some(lobe) = &slots[s] else { continue };
            let own = picked & lobe.exists;
            out.in_x[c] = Select::select(own, lobe.in_stokes_x, out.in_x[c]);
            out.out_x[c] = Select::select(own, lobe.out_stokes_x, out.out_x[c]);
            out.value[c] = Select::select(own, lobe.mueller / safe_pdf, out.value[c]);
        }
    }
    out
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
