//! The lobes of a thin element on a surface (a plate or a stack of layers between an exterior
//! above and an exit medium below, no geometric thickness in the scene): its specular reflection
//! and its transmission, from either side and in both transport modes, in fixed slots (0
//! reflection, 1 transmission), over a wavelength, bands or channel weights.
//!
//! The element is solved once, from `wi`'s side, for both lobes: in Importance mode that is each
//! lobe's own incidence; in Radiance mode (light from the mirror direction, or from the far
//! side) each lobe is the reversed path of the forward one ([`reversed`], the reciprocity of
//! media with symmetric dielectric tensors). Light from below sees the element flipped
//! ([`Thin::flipped`]: exterior and exit swapped, mirrored through `z = 0`), solved as if from
//! above, its matrices mirrored back (`D M D`, `D = diag(1, 1, −1, −1)`).

use crate::error::{Error, Result};
use crate::optics::frame::PlaneFrame;
use crate::optics::mueller::reversed;
use crate::plate::slab::{Output, SlabMueller, Want};
use crate::real::complex::{self as cx, Cx};
use crate::real::{Mask, Real};
use crate::render::{PathLobe, Transport};
use nalgebra::{Matrix4, Vector3};

/// A thin element as the lobes need it, over the reals `T` (`f64` on the host).
pub trait Thin<T: Real = f64>: Sized {
    /// What it is evaluated over: a spectrum (bands, channel weights), or wavelengths.
    type Spectrum: ?Sized;
    /// Which lobes are asked for.
    fn want(&self) -> Want;
    /// Only `M00`.
    fn output(&self) -> Output;
    /// The exit medium absorbs whatever enters it: no transmission lobe, no light from below.
    fn absorbing_exit(&self) -> bool;
    /// Real index of the exterior (above, `z > 0`).
    fn ext(&self) -> T;
    /// Real index of the exit medium (below).
    fn exit(&self) -> T;
    /// The element seen from below where `below` holds: exterior and exit swapped, mirrored
    /// through `z = 0`.
    fn oriented(&self, below: T::Mask) -> Self;
    /// The channels of `spectrum`, checked.
    fn channels(spectrum: &Self::Spectrum) -> Result<usize>;
    /// True if a channel's weight can be negative (signed sRGB channels).
    fn is_signed(spectrum: &Self::Spectrum) -> bool;
    /// Mueller matrices (s/p frames) per channel of `spectrum` for light from above with
    /// incidence parameter `beta` in the plane of `frame`.
    fn evaluate(
        &self,
        spectrum: &Self::Spectrum,
        frame: PlaneFrame<T>,
        beta: Cx<T>,
        want: Want,
    ) -> Result<Vec<SlabMueller<T>>>;
}

/// The element's lobes seen from `wi`, one `[reflection, transmission]` pair per spectral
/// channel (module docs). `share`: one solve for both lobes (else each lobe solved on its own,
/// the reference the shared solution is tested against).
pub fn lobes<T: Real, E: Thin<T>>(
    e: &E,
    spectrum: &E::Spectrum,
    wi: Vector3<T>,
    transport: Transport,
    share: bool,
) -> Result<Vec<[Option<PathLobe<T>>; 2]>> {
    let norm = wi.dot(&wi).sqrt();
    let finite = wi.iter().fold(T::Mask::cst(true), |m, x| m & x.finite());
    let unit = finite & (norm - T::one()).abs().lt(T::cst(1e-4));
    (!unit).fail(|| Error::new("wi", "must be a unit vector"))?;
    let channels = E::channels(spectrum)?;
    let mut out = vec![[None, None]; channels];
    let zero = T::zero();
    let grazing = wi.z.equals(zero);
    let dark = if e.absorbing_exit() {
        grazing | wi.z.lt(zero)
    } else {
        grazing
    };
    if dark.surely() {
        return Ok(out);
    }
    let mut want = e.want();
    want.transmission &= !e.absorbing_exit();
    let wi = wi / norm;
    let reflected = Vector3::new(-wi.x, -wi.y, wi.z);
    let (through, transmits) = through(e, wi);
    let lobes = [
        want.reflection.then_some((reflected, !dark)),
        (want.transmission && transmits.known() != Some(false))
            .then_some((through, !dark & transmits)),
    ];
    let shared = if share {
        let want = Want {
            reflection: lobes[0].is_some(),
            transmission: lobes[1].is_some(),
        };
        Some(physical(e, spectrum, wi, want)?)
    } else {
        None
    };
    let signed = E::is_signed(spectrum);
    for (component, lobe) in lobes.into_iter().enumerate() {
        let Some((wo, exists)) = lobe else { continue };
        let towards = match transport {
            Transport::Importance => wi,
            Transport::Radiance => wo,
        };
        let want = Want {
            reflection: component == 0,
            transmission: component == 1,
        };
        // Shared: solved from wi's side; a Radiance lobe is its reversed path.
        let own;
        let (ms, reverse): (&[SlabMueller<T>], bool) = match &shared {
            Some(ms) => (ms, transport == Transport::Radiance),
            None => {
                own = physical(e, spectrum, towards, want)?;
                (&own, false)
            }
        };
        let (n_in, n_out) = side_indices(e, towards, component);
        let ratio = n_out / n_in;
        let scale = match transport {
            Transport::Radiance => ratio * ratio,
            Transport::Importance => T::one(),
        };
        let s = PlaneFrame::from_direction(towards).s;
        for (c, m) in ms.iter().enumerate() {
            let m = if component == 0 { m.r } else { m.t };
            let Some(m) = m else { continue };
            let mut mueller = if reverse { reversed(&m) } else { m };
            // A band-averaged coherency of an element that passes (almost) nothing can give M00
            // a rounding-level negative (seen: -2e-22); under a non-negative weight the
            // unpolarised throughput is >= 0. (A signed sRGB channel keeps its sign.)
            if !signed {
                mueller[(0, 0)] = mueller[(0, 0)].max(zero);
            }
            let eta = match transport {
                Transport::Radiance => n_in / n_out,
                Transport::Importance => n_out / n_in,
            };
            out[c][component] = Some(
                PathLobe::new(component, wo, (s, s), mueller, eta)
                    .with_radiance_factor(scale)
                    .existing(exists),
            );
        }
    }
    Ok(out)
}

/// Real indices `(n where the light arrives from, n where it leaves into)`.
fn side_indices<T: Real, E: Thin<T>>(e: &E, towards: Vector3<T>, component: usize) -> (T, T) {
    let above = towards.z.gt(T::zero());
    let (near, far) = (
        T::select(above, e.ext(), e.exit()),
        T::select(above, e.exit(), e.ext()),
    );
    (near, if component == 0 { near } else { far })
}

/// The direction on the far side of the element that is joined to `w` by transmission (Snell's
/// law between the two isotropic media), and where it exists (not under total internal
/// reflection; where it does not, the direction is the grazing one).
fn through<T: Real, E: Thin<T>>(e: &E, w: Vector3<T>) -> (Vector3<T>, T::Mask) {
    let (n_near, n_far) = side_indices(e, w, 1);
    let ratio = n_near / n_far;
    let sin2 = ratio * ratio * (w.x * w.x + w.y * w.y);
    let exists = sin2.lt(T::one());
    let cos = (T::one() - sin2).safe_sqrt();
    let direction = Vector3::new(-w.x * ratio, -w.y * ratio, cos.copysign(-w.z));
    (direction, exists)
}

/// Mueller matrices (s/p frames) of light arriving from `towards` (either side), per channel:
/// the element (flipped when `towards` is below) solved from above, mirrored back.
fn physical<T: Real, E: Thin<T>>(
    e: &E,
    spectrum: &E::Spectrum,
    towards: Vector3<T>,
    want: Want,
) -> Result<Vec<SlabMueller<T>>> {
    let below = towards.z.lt(T::zero());
    let seen = e.oriented(below);
    let w = Vector3::new(towards.x, towards.y, towards.z.abs());
    let beta = cx::real(seen.ext() * (w.x * w.x + w.y * w.y).sqrt());
    let ms = seen.evaluate(spectrum, PlaneFrame::from_direction(w), beta, want)?;
    // D M D with D = diag(1, 1, −1, −1): the entries with one index in {2, 3} change sign.
    let mirror = |m: Option<Matrix4<T>>| {
        m.map(|m| {
            if below.known() == Some(false) {
                return m;
            }
            Matrix4::from_fn(|i, j| {
                let x = m[(i, j)];
                if (i >= 2) != (j >= 2) {
                    T::select(below, -x, x)
                } else {
                    x
                }
            })
        })
    };
    Ok(ms
        .into_iter()
        .map(|m| SlabMueller {
            r: mirror(m.r),
            t: mirror(m.t),
        })
        .collect())
}
