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

use crate::band::{is_exact_band, narrow_band};
use crate::colour::weights::WeightSet;
use crate::error::{Error, Result};
use crate::material::check_wavelength;
use crate::optics::frame::PlaneFrame;
use crate::optics::mueller::reversed;
use crate::params::Bandwidth;
use crate::plate::slab::{Output, SlabMueller, Want};
use crate::quadrature::Accuracy;
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

/// A thin element (a plate, a stack) as the lobes need it: its two media, the element seen
/// from below, and its model at one incidence ([`ThinModel`]).
pub trait Thin: Clone {
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

/// The element's lobes seen from `wi`, one `[reflection, transmission]` pair per spectral
/// channel (module docs). `share`: one solve for both lobes (else each lobe solved on its own,
/// the reference the shared solution is tested against).
pub fn lobes<E: Thin>(
    q: &ThinQuery<E>,
    spectrum: &Spectrum,
    wi: Vector3<f64>,
    transport: Transport,
    share: bool,
) -> Result<Vec<[Option<PathLobe>; 2]>> {
    if !(wi.iter().all(|x| x.is_finite()) && (wi.norm() - 1.0).abs() < 1e-4) {
        return Err(Error::new("wi", "must be a unit vector"));
    }
    let channels = spectrum.channels()?;
    spectrum.validate()?;
    let mut out = vec![[None, None]; channels];
    if wi.z == 0.0 || (q.absorbing_exit && wi.z < 0.0) {
        return Ok(out);
    }
    let e = &q.element;
    let mut want = q.want;
    want.transmission &= !q.absorbing_exit;
    let wi = wi.normalize();
    let reflected = Vector3::new(-wi.x, -wi.y, wi.z);
    let lobes = [
        Some(reflected).filter(|_| want.reflection),
        through(e, wi).filter(|_| want.transmission),
    ];
    let shared = if share {
        let want = Want {
            reflection: lobes[0].is_some(),
            transmission: lobes[1].is_some(),
        };
        Some(physical(e, spectrum, wi, want, q.output)?)
    } else {
        None
    };
    for (component, wo) in lobes.into_iter().enumerate() {
        let Some(wo) = wo else { continue };
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
        let (ms, reverse): (&[SlabMueller], bool) = match &shared {
            Some(ms) => (ms, transport == Transport::Radiance),
            None => {
                own = physical(e, spectrum, towards, want, q.output)?;
                (&own, false)
            }
        };
        let (n_in, n_out) = side_indices(e, towards, component);
        let scale = match transport {
            Transport::Radiance => (n_out / n_in).powi(2),
            Transport::Importance => 1.0,
        };
        let s = PlaneFrame::from_direction(towards).s;
        for (c, m) in ms.iter().enumerate() {
            let m = if component == 0 { m.r } else { m.t };
            let Some(m) = m else { continue };
            let mut mueller = if reverse { reversed(&m) } else { m };
            // A band-averaged coherency of an element that passes (almost) nothing can give M00
            // a rounding-level negative (seen: -2e-22); under a non-negative weight the
            // unpolarised throughput is >= 0. (A signed sRGB channel keeps its sign.)
            if !spectrum.is_signed() {
                mueller[(0, 0)] = mueller[(0, 0)].max(0.0);
            }
            let eta = match transport {
                Transport::Radiance => n_in / n_out,
                Transport::Importance => n_out / n_in,
            };
            out[c][component] = Some(
                PathLobe::new(component, wo, (s, s), mueller, eta).with_radiance_factor(scale),
            );
        }
    }
    Ok(out)
}

/// Real indices `(n where the light arrives from, n where it leaves into)`.
fn side_indices<E: Thin>(e: &E, towards: Vector3<f64>, component: usize) -> (f64, f64) {
    let (near, far) = if towards.z > 0.0 {
        (e.ext(), e.exit())
    } else {
        (e.exit(), e.ext())
    };
    (near, if component == 0 { near } else { far })
}

/// The direction on the far side of the element that is joined to `w` by transmission (Snell's
/// law between the two isotropic media; `None` under total internal reflection).
fn through<E: Thin>(e: &E, w: Vector3<f64>) -> Option<Vector3<f64>> {
    let (n_near, n_far) = side_indices(e, w, 1);
    let ratio = n_near / n_far;
    let sin2 = ratio * ratio * (w.x * w.x + w.y * w.y);
    if sin2 >= 1.0 {
        return None;
    }
    let cos = (1.0 - sin2).sqrt();
    Some(Vector3::new(
        -w.x * ratio,
        -w.y * ratio,
        -w.z.signum() * cos,
    ))
}

/// Mueller matrices (s/p frames) of light arriving from `towards` (either side), per channel:
/// the element (flipped when `towards` is below) solved from above, mirrored back.
fn physical<E: Thin>(
    e: &E,
    spectrum: &Spectrum,
    towards: Vector3<f64>,
    want: Want,
    output: Output,
) -> Result<Vec<SlabMueller>> {
    let flipped;
    let (e, w, mirrored) = if towards.z > 0.0 {
        (e, towards, false)
    } else {
        flipped = e.flipped();
        (
            &flipped,
            Vector3::new(towards.x, towards.y, -towards.z),
            true,
        )
    };
    let beta = C64::new(e.ext() * (w.x * w.x + w.y * w.y).sqrt(), 0.0);
    let ms = evaluate(
        &e.model(PlaneFrame::from_direction(w), beta),
        spectrum,
        want,
        output,
    )?;
    let d = Matrix4::from_diagonal(&nalgebra::Vector4::new(1.0, 1.0, -1.0, -1.0));
    let fix = |m: Option<Matrix4<f64>>| m.map(|m| if mirrored { d * m * d } else { m });
    Ok(ms
        .into_iter()
        .map(|m| SlabMueller {
            r: fix(m.r),
            t: fix(m.t),
        })
        .collect())
}
