//! The lobes of a birefringent plate (reflection and transmission) as a path tracer samples
//! them, over one wavelength, a band or a set of colour channels (see [`crate::render`] for the
//! transport modes).

use crate::band::{is_exact_band, narrow_band};
use crate::error::{Error, Result};
use crate::material::check_clear_index;
use crate::material::{check_wavelength, Material};
use crate::optics::frame::PlaneFrame;
use crate::optics::medium::Uniaxial;
use crate::optics::mueller::reversed;
use crate::params::{Bandwidth, Thickness};
use crate::plate::slab::{Output, SlabMueller, Want};
use crate::plate::Plate;
use crate::render::{PathLobe, Transport};
use crate::spectral::model::{Accuracy, PlateModel};
use crate::spectral::weights::WeightSet;
use nalgebra::{Matrix4, Vector3};
use num_complex::Complex64 as C64;

/// A plate query: everything but the direction and the spectrum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlateQuery {
    /// The plate (top = the exterior side, `z > 0`).
    pub plate: Plate,
    /// Which lobes to compute.
    pub want: Want,
    /// Only `M00`.
    pub output: Output,
    /// The exit medium absorbs whatever enters it (a film on a black substrate): no
    /// transmission lobe, and no light from below (it cannot reach the plate).
    pub absorbing_exit: bool,
}

/// Over which spectrum a plate query is evaluated.
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
    fn is_signed(&self) -> bool {
        matches!(self, Spectrum::Weights(set) if set.is_signed())
    }

    /// Channels of the answer.
    fn channels(&self) -> Result<usize> {
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
    fn validate(&self) -> Result<()> {
        for (wavelength_nm, fwhm_nm) in self.bands() {
            check_wavelength(wavelength_nm)?;
            Bandwidth::new("filter_bandwidth", fwhm_nm, wavelength_nm)?;
        }
        Ok(())
    }

    /// The single bands `(wavelength_nm, fwhm_nm)` of a [`Spectrum::Band`] or
    /// [`Spectrum::Bands`] (empty for weights).
    fn bands(&self) -> Vec<(f64, f64)> {
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

impl PlateQuery {
    /// A validated query.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        material: Material,
        birefringence: f64,
        ext: C64,
        exit: C64,
        axis: Vector3<f64>,
        thickness: Thickness,
        reflection: bool,
        transmission: bool,
        intensity_only: bool,
    ) -> Result<Self> {
        let plate = Plate {
            material,
            birefringence,
            ext: check_clear_index("ext_ior", ext)?,
            exit: check_clear_index("exit_ior", exit)?,
            axis: Uniaxial::new(C64::new(1.0, 0.0), C64::new(1.5, 0.0), axis)?.axis,
            thickness_nm: thickness.nm(),
        };
        Ok(PlateQuery {
            plate,
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
        })
    }

    /// The same query with an absorbing exit medium or not ([`PlateQuery::absorbing_exit`]).
    pub fn with_absorbing_exit(self, absorbing_exit: bool) -> Self {
        PlateQuery {
            absorbing_exit,
            ..self
        }
    }

    /// The same plate seen from below: exterior and exit swapped, mirrored through `z = 0`.
    fn flipped(&self) -> Self {
        let mut q = *self;
        q.plate.ext = self.plate.exit;
        q.plate.exit = self.plate.ext;
        q.plate.axis.z = -q.plate.axis.z;
        q
    }
}

/// The plate's lobes seen from `wi`, one `[reflection, transmission]` pair per spectral
/// channel (one for [`Spectrum::Band`]). The plate is solved once, from `wi`'s side, for both
/// lobes: in Importance mode that is each lobe's own incidence; in Radiance mode (light from
/// the mirror direction, or from the far side) each lobe is the reversed path of the forward
/// one ([`reversed`], the reciprocity of media with symmetric dielectric tensors).
pub fn plate_lobes(
    q: &PlateQuery,
    spectrum: &Spectrum,
    wi: Vector3<f64>,
    transport: Transport,
) -> Result<Vec<[Option<PathLobe>; 2]>> {
    lobes_of_plate(q, spectrum, wi, transport, true)
}

/// [`plate_lobes`] with each lobe solved on its own (the light's own side and direction, by
/// time reversal in Radiance mode): the reference the shared solution is tested against.
pub fn plate_lobes_full(
    q: &PlateQuery,
    spectrum: &Spectrum,
    wi: Vector3<f64>,
    transport: Transport,
) -> Result<Vec<[Option<PathLobe>; 2]>> {
    lobes_of_plate(q, spectrum, wi, transport, false)
}

fn lobes_of_plate(
    q: &PlateQuery,
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
    let mut q = *q;
    q.want.transmission &= !q.absorbing_exit;
    let q = &q;
    let wi = wi.normalize();
    let reflected = Vector3::new(-wi.x, -wi.y, wi.z);
    let lobes = [
        Some(reflected).filter(|_| q.want.reflection),
        through_plate(q, wi).filter(|_| q.want.transmission),
    ];
    let shared = if share {
        let want = Want {
            reflection: lobes[0].is_some(),
            transmission: lobes[1].is_some(),
        };
        Some(physical_plate(q, spectrum, wi, want)?)
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
                own = physical_plate(q, spectrum, towards, want)?;
                (&own, false)
            }
        };
        let (n_in, n_out) = side_indices(q, towards, component);
        let scale = match transport {
            Transport::Radiance => (n_out / n_in).powi(2),
            Transport::Importance => 1.0,
        };
        let s = PlaneFrame::from_direction(towards).s;
        for (c, m) in ms.iter().enumerate() {
            let m = if component == 0 { m.r } else { m.t };
            let Some(m) = m else { continue };
            let mut mueller = if reverse { reversed(&m) } else { m };
            // A band-averaged coherency of a plate that passes (almost) nothing can give M00 a
            // rounding-level negative (seen: -2e-22); under a non-negative weight the
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
fn side_indices(q: &PlateQuery, towards: Vector3<f64>, component: usize) -> (f64, f64) {
    let (near, far) = if towards.z > 0.0 {
        (q.plate.ext.re, q.plate.exit.re)
    } else {
        (q.plate.exit.re, q.plate.ext.re)
    };
    (near, if component == 0 { near } else { far })
}

/// The direction on the far side of the plate that is joined to `w` by transmission (Snell's
/// law between the two isotropic media; `None` under total internal reflection).
fn through_plate(q: &PlateQuery, w: Vector3<f64>) -> Option<Vector3<f64>> {
    let (n_near, n_far) = side_indices(q, w, 1);
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

/// The plate seen from `towards` (either side), mirrored through `z = 0` when it is below, and
/// its model for that incidence (the one decision of [`PlateModel::new`]).
fn model_from(q: &PlateQuery, towards: Vector3<f64>) -> (PlateQuery, PlaneFrame, C64, bool) {
    let (q, w, mirrored) = if towards.z > 0.0 {
        (*q, towards, false)
    } else {
        (
            q.flipped(),
            Vector3::new(towards.x, towards.y, -towards.z),
            true,
        )
    };
    let beta = q.plate.ext * (w.x * w.x + w.y * w.y).sqrt();
    (q, PlaneFrame::from_direction(w), beta, mirrored)
}

/// The plate's Mueller matrices (s/p frames) over `spectrum`, per channel, through `model`.
fn evaluate(
    model: &PlateModel,
    spectrum: &Spectrum,
    want: Want,
    output: Output,
) -> Result<Vec<SlabMueller>> {
    match *spectrum {
        Spectrum::Weights(set) => Ok(model
            .channels(set, want, output, Accuracy::Perceptual)?
            .to_vec()),
        _ => {
            // Bands thicker than the coherence length of an isotropic plate share one
            // incoherent sum.
            let mut incoherent = None;
            spectrum
                .bands()
                .into_iter()
                .map(|(wavelength_nm, fwhm_nm)| {
                    if is_exact_band(fwhm_nm, wavelength_nm) {
                        model.at(wavelength_nm, want, output)
                    } else {
                        let band = [narrow_band(wavelength_nm, fwhm_nm)];
                        model.band(&band, want, output, &mut incoherent)
                    }
                })
                .collect()
        }
    }
}

/// Mueller matrices (s/p frames) of light arriving from `towards` (either side), per channel.
fn physical_plate(
    q: &PlateQuery,
    spectrum: &Spectrum,
    towards: Vector3<f64>,
    want: Want,
) -> Result<Vec<SlabMueller>> {
    let (q, frame, beta, mirrored) = model_from(q, towards);
    let ms = evaluate(
        &PlateModel::new(&q.plate, frame, beta),
        spectrum,
        want,
        q.output,
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
