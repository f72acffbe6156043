//! The lobes of a thin element on a surface (a plate or a stack of layers between an exterior
//! above and an exit medium below, no geometric thickness in the scene): its specular reflection
//! and its transmission, from either side and in both transport modes, in fixed slots (0
//! reflection, 1 transmission), over a wavelength, bands or channel weights.
//!
//! The element is solved once, from `wi`'s side, for both lobes: in Importance mode that is each
//! lobe's own incidence; in Radiance mode (light from the mirror direction, or from the far
//! side) each lobe is the reversed path of the forward one ([`reversed`], the reciprocity of
//! media with symmetric dielectric tensors). Light from below sees the element flipped
//! ([`Thin::oriented`], [`Element::flipped`]: exterior and exit swapped, mirrored through `z = 0`), solved as if from
//! above, its matrices mirrored back (`D M D`, `D = diag(1, 1, −1, −1)`).

use crate::band::{is_exact_band, narrow_band};
use crate::colour::weights::WeightSet;
use crate::error::{Error, Result};
use crate::material::check_wavelength;
use crate::optics::frame::PlaneFrame;
use crate::optics::mueller::reversed;
use crate::params::Bandwidth;
use crate::plate::slab::{Output, SlabMueller, Want};
use crate::quadrature::Accuracy;
use crate::real::complex::{self as cx, Cx};
use crate::real::{Mask, Real};
use crate::render::{PathLobe, Transport};
use crate::spectral::model::ThinModel;
use nalgebra::{Matrix4, Vector3};
use num_complex::Complex64 as C64;

/// Over which spectrum a thin element (a plate, a stack) is evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Spectrum {
    /// One wavelength: exact if `fwhm_nm == 0`, else a Gaussian band of that FWHM (closed form).
    Band {
        /// Centre wavelength (nm).
        wavelength_nm: f64,
        /// Full width at half maximum (nm).
        fwhm_nm: f64,
    },
    /// Every channel of a weight set (closed form).
    Weights(WeightSet),
    /// The first `count` (at most [`MAX_BANDS`]) wavelengths of `wavelengths_nm`, each as
    /// [`Spectrum::Band`] with the same `fwhm_nm`: the wavelengths a spectral renderer traces
    /// along one path, answered in one query (a plate's wavelength-independent work is shared).
    Bands {
        /// Centre wavelengths (nm).
        wavelengths_nm: [f64; MAX_BANDS],
        /// How many of them are used.
        count: usize,
        /// Full width at half maximum (nm).
        fwhm_nm: f64,
    },
}

/// Most wavelengths of one [`Spectrum::Bands`] query (Mitsuba's spectral variants trace 4).
pub const MAX_BANDS: usize = 4;

impl Spectrum {
    /// True if a channel's weight can be negative (linear sRGB: out-of-gamut colours give a
    /// negative channel value, which is the colour, not an error).
    pub(crate) fn is_signed(&self) -> bool {
        matches!(self, Spectrum::Weights(set) if set.is_signed())
    }

    /// Channels of the answer.
    pub(crate) fn channels(&self) -> Result<usize> {
        match *self {
            Spectrum::Band { .. } => Ok(1),
            Spectrum::Weights(_) => Ok(3),
            Spectrum::Bands { count, .. } if (1..=MAX_BANDS).contains(&count) => Ok(count),
            Spectrum::Bands { count, .. } => Err(Error::new(
                "count",
                format!("must be 1 to {MAX_BANDS} wavelengths, got {count}"),
            )),
        }
    }

    /// Checks every band's wavelength and `filter_bandwidth` ([`Bandwidth`]), once per query.
    pub(crate) fn validate(&self) -> Result<()> {
        for (wavelength_nm, fwhm_nm) in self.bands() {
            check_wavelength(wavelength_nm)?;
            Bandwidth::new("filter_bandwidth", fwhm_nm, wavelength_nm)?;
        }
        Ok(())
    }

    /// The single bands `(wavelength_nm, fwhm_nm)` of a [`Spectrum::Band`] or
    /// [`Spectrum::Bands`] (empty for weights).
    pub(crate) fn bands(&self) -> Vec<(f64, f64)> {
        match *self {
            Spectrum::Band {
                wavelength_nm,
                fwhm_nm,
            } => vec![(wavelength_nm, fwhm_nm)],
            Spectrum::Bands {
                wavelengths_nm,
                count,
                fwhm_nm,
            } => wavelengths_nm[..count.min(MAX_BANDS)]
                .iter()
                .map(|&l| (l, fwhm_nm))
                .collect(),
            Spectrum::Weights(_) => Vec::new(),
        }
    }
}

/// A thin element on the host (a plate, a stack): its two media, the element seen from below,
/// and its model at one incidence ([`ThinModel`]). Its query ([`ThinQuery`]) is a [`Thin`].
pub trait Element: Clone {
    /// The element at one incidence.
    type Model<'a>: ThinModel
    where
        Self: 'a;
    /// Real index of the exterior (above, `z > 0`).
    fn ext(&self) -> f64;
    /// Real index of the exit medium (below).
    fn exit(&self) -> f64;
    /// The element seen from below: exterior and exit swapped, mirrored through `z = 0`.
    fn flipped(&self) -> Self;
    /// The element for light from above with incidence parameter `beta` in the plane of
    /// `frame`.
    fn model(&self, frame: PlaneFrame, beta: C64) -> Self::Model<'_>;
}

/// A query of a thin element: everything but the direction and the spectrum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinQuery<E> {
    /// The element (its exterior above, `z > 0`).
    pub element: E,
    /// Which lobes to compute.
    pub want: Want,
    /// Only `M00`.
    pub output: Output,
    /// The exit medium absorbs whatever enters it (a film on a black substrate): no
    /// transmission lobe, and no light from below (it cannot reach the element).
    pub absorbing_exit: bool,
}

impl<E> ThinQuery<E> {
    /// A query of `element` for the lobes asked for, full Mueller matrices or only `M00`.
    pub fn of(element: E, reflection: bool, transmission: bool, intensity_only: bool) -> Self {
        ThinQuery {
            element,
            want: Want {
                reflection,
                transmission,
            },
            output: if intensity_only {
                Output::Intensity
            } else {
                Output::Mueller
            },
            absorbing_exit: false,
        }
    }

    /// The same query with an absorbing exit medium or not ([`ThinQuery::absorbing_exit`]).
    pub fn with_absorbing_exit(self, absorbing_exit: bool) -> Self {
        ThinQuery {
            absorbing_exit,
            ..self
        }
    }
}

/// The element's Mueller matrices (s/p frames) over `spectrum`, per channel, through `model`:
/// the channels of a weight set at the perceptual budget, each band exact (zero width) or over
/// its Gaussian.
pub fn evaluate<M: ThinModel>(
    model: &M,
    spectrum: &Spectrum,
    want: Want,
    output: Output,
) -> Result<Vec<SlabMueller>> {
    match *spectrum {
        Spectrum::Weights(set) => Ok(model
            .channels(set, want, output, Accuracy::Perceptual)?
            .to_vec()),
        _ => spectrum
            .bands()
            .into_iter()
            .map(|(wavelength_nm, fwhm_nm)| {
                if is_exact_band(fwhm_nm, wavelength_nm) {
                    model.at(wavelength_nm, want, output)
                } else {
                    let band = [narrow_band(wavelength_nm, fwhm_nm)];
                    model.band(&band, want, output, Accuracy::Perceptual)
                }
            })
            .collect(),
    }
}

/// A host query is the thin element over `f64`: its spectrum a [`Spectrum`], evaluated through
/// the element's model ([`evaluate`]).
impl<E: Element> Thin for ThinQuery<E> {
    type Spectrum = Spectrum;

    fn want(&self) -> Want {
        self.want
    }

    fn output(&self) -> Output {
        self.output
    }

    fn absorbing_exit(&self) -> bool {
        self.absorbing_exit
    }

    fn ext(&self) -> f64 {
        self.element.ext()
    }

    fn exit(&self) -> f64 {
        self.element.exit()
    }

    fn oriented(&self, below: bool) -> Self {
        if below {
            ThinQuery {
                element: self.element.flipped(),
                ..self.clone()
            }
        } else {
            self.clone()
        }
    }

    fn channels(spectrum: &Spectrum) -> Result<usize> {
        let channels = spectrum.channels()?;
        spectrum.validate()?;
        Ok(channels)
    }

    fn is_signed(spectrum: &Spectrum) -> bool {
        spectrum.is_signed()
    }

    fn evaluate(
        &self,
        spectrum: &Spectrum,
        frame: PlaneFrame,
        beta: C64,
        want: Want,
    ) -> Result<Vec<SlabMueller>> {
        evaluate(
            &self.element.model(frame, beta),
            spectrum,
            want,
            self.output,
        )
    }
}

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
