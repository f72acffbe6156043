//! Closed-form Fresnel amplitudes of a planar interface between two isotropic media, in the
//! core's s/p conventions: the isotropic fast path of [`crate::optics::interface`] and the building
//! block of [`crate::plate::etalon`].
//!
//! Conventions of [`crate::optics::modes::isotropic_modes`]: `E_s = ŷ`, `E_p = k̂ × ŷ`, normal
//! components `q = ±w` with `w = sqrt(η² − β²)` the principal root (`Re w ≥ 0`, `Im w ≥ 0`
//! for the wave that travels or decays upwards). Matching tangential `E` and `H = k × E`
//! (eq. S18 for two isotropic media) gives the textbook amplitudes
//!
//! ```text
//! r_s = (w₁ − w₂)/(w₁ + w₂)               t_s = 2 w₁/(w₁ + w₂)
//! r_p = (w₁ η₂² − w₂ η₁²)/(w₁ η₂² + w₂ η₁²)   t_p = 2 η₁ η₂ w₁/(w₁ η₂² + w₂ η₁²)
//! ```
//! for a wave arriving from the upper medium 1 (Born & Wolf §1.5.2, here for complex indices);
//! from below, swap 1 and 2 (a mirror through the surface maps the basis onto itself up to a
//! sign common to incident and outgoing p waves).

use crate::cmath::singular;
use crate::error::Result;
use crate::real::complex::{self as cx, Cx};
use crate::real::{all_finite, Mask, Real};
use num_complex::Complex64 as C64;

/// Amplitudes `[s, p]` of one isotropic/isotropic interface, both directions of incidence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fresnel<T: Real = f64> {
    /// Reflection of a wave arriving from above.
    pub r_above: [Cx<T>; 2],
    /// Transmission of a wave arriving from above.
    pub t_above: [Cx<T>; 2],
    /// Reflection of a wave arriving from below.
    pub r_below: [Cx<T>; 2],
    /// Transmission of a wave arriving from below.
    pub t_below: [Cx<T>; 2],
}

/// `w = sqrt(η² − β²)` on the branch of the up-going wave, evaluated as `(η − β)(η + β)` so
/// that it stays exact near grazing and critical incidence.
pub fn normal_component<T: Real>(eta: Cx<T>, beta: Cx<T>) -> Cx<T> {
    let w = cx::sqrt((eta - beta) * (eta + beta));
    // Principal root: Re w ≥ 0; the up-going wave also needs Im w ≥ 0 when Re w = 0.
    let zero = T::zero();
    (w.re.equals(zero) & w.im.lt(zero)).when(|| -w, || w)
}

impl Fresnel {
    /// The interface between an upper medium of index `eta1` and a lower one of index `eta2`
    /// for incidence parameter `beta`. `None` where a denominator vanishes (a surface wave:
    /// `w₁ + w₂ = 0` or the p pole), which a passive pair of media reaches only at grazing
    /// incidence from both sides at once.
    pub fn new(eta1: C64, eta2: C64, beta: C64) -> Option<Self> {
        Self::amplitudes(eta1, eta2, beta).ok()
    }
}

impl<T: Real> Fresnel<T> {
    /// [`Fresnel::new`] over the reals `T`: the singular error where a denominator vanishes or
    /// an amplitude is not finite (while recording, those lanes fail).
    pub fn amplitudes(eta1: Cx<T>, eta2: Cx<T>, beta: Cx<T>) -> Result<Self> {
        let (w1, w2) = (normal_component(eta1, beta), normal_component(eta2, beta));
        let (e1, e2) = (eta1 * eta1, eta2 * eta2);
        let ds = w1 + w2;
        let dp = w1 * e2 + w2 * e1;
        let zero = T::zero();
        let vanishes = |d: Cx<T>| d.re.equals(zero) & d.im.equals(zero);
        let pole = vanishes(ds) | vanishes(dp);
        pole.fail(singular)?;
        let one = Cx::new(T::one(), zero);
        let (is, ip) = (
            cx::inv(pole.when(|| one, || ds)),
            cx::inv(pole.when(|| one, || dp)),
        );
        let two = T::cst(2.0);
        let two_eta = eta1 * eta2 * two;
        let f = Fresnel {
            r_above: [(w1 - w2) * is, (w1 * e2 - w2 * e1) * ip],
            t_above: [w1 * is * two, two_eta * w1 * ip],
            r_below: [(w2 - w1) * is, (w2 * e1 - w1 * e2) * ip],
            t_below: [w2 * is * two, two_eta * w2 * ip],
        };
        let finite = all_finite(
            [f.r_above, f.t_above, f.r_below, f.t_below]
                .iter()
                .flatten(),
        );
        (!finite).fail(singular)?;
        Ok(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Stokes relations `t t' − r r' = 1`, `r' = −r` (lossless or not: they follow from
    /// reciprocity of the boundary conditions alone), to rounding.
    #[test]
    fn stokes_relations_hold() {
        for (n1, n2, b) in [
            (C64::new(1.0, 0.0), C64::new(1.5, 0.0), 0.3),
            (C64::new(1.5, 0.0), C64::new(1.0, 0.0), 0.9),
            (C64::new(1.2, 0.0), C64::new(0.2, 3.1), 0.7),
        ] {
            let f = Fresnel::new(n1, n2, C64::new(b, 0.0)).unwrap();
            for k in 0..2 {
                assert!((f.r_above[k] + f.r_below[k]).norm() < 1e-15);
                let one = f.t_above[k] * f.t_below[k] - f.r_above[k] * f.r_below[k];
                assert!((one - 1.0).norm() < 1e-14, "{one}");
            }
        }
    }
}
