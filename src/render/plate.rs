//! The lobes of a birefringent plate (reflection and transmission) as a path tracer samples
//! them, over one wavelength, a band or a set of colour channels (see [`crate::render`] for the
//! transport modes, [`crate::render::thin`] for the lobes of a thin element).

use crate::band::{is_exact_band, narrow_band};
use crate::error::{Error, Result};
use crate::material::check_clear_index;
use crate::material::{check_wavelength, Material};
use crate::optics::frame::PlaneFrame;
use crate::optics::medium::Uniaxial;
use crate::params::{Bandwidth, Thickness};
use crate::plate::slab::{Output, SlabMueller, Want};
use crate::plate::Plate;
use crate::real::complex::Cx;
use crate::real::{Real, Select};
use crate::render::choice::{self, Sampled};
use crate::render::slots::{plate_component, Slots, PLATE_SLOTS};
use crate::render::thin::{self, Thin};
use crate::render::{PathLobe, Transport};
use crate::spectral::model::{Accuracy, PlateModel};
use crate::spectral::weights::WeightSet;
use nalgebra::Vector3;
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
}

/// The plate's lobes seen from `wi`, one `[reflection, transmission]` pair per spectral
/// channel (one for [`Spectrum::Band`]): [`thin::lobes`], the plate solved once, from `wi`'s
/// side, for both lobes.
pub fn plate_lobes(
    q: &PlateQuery,
    spectrum: &Spectrum,
    wi: Vector3<f64>,
    transport: Transport,
) -> Result<Vec<[Option<PathLobe>; 2]>> {
    thin::lobes(q, spectrum, wi, transport, true)
}

/// [`plate_lobes`] with each lobe solved on its own (the light's own side and direction, by
/// time reversal in Radiance mode): the reference the shared solution is tested against.
pub fn plate_lobes_full(
    q: &PlateQuery,
    spectrum: &Spectrum,
    wi: Vector3<f64>,
    transport: Transport,
) -> Result<Vec<[Option<PathLobe>; 2]>> {
    thin::lobes(q, spectrum, wi, transport, false)
}

impl PlateQuery {
    /// The plate seen from below: exterior and exit swapped, mirrored through `z = 0`.
    fn flipped(&self) -> Self {
        let mut q = *self;
        q.plate.ext = self.plate.exit;
        q.plate.exit = self.plate.ext;
        q.plate.axis.z = -q.plate.axis.z;
        q
    }
}

impl Thin for PlateQuery {
    type Spectrum = Spectrum;

    fn channels(spectrum: &Spectrum) -> Result<usize> {
        let channels = spectrum.channels()?;
        spectrum.validate()?;
        Ok(channels)
    }

    fn is_signed(spectrum: &Spectrum) -> bool {
        spectrum.is_signed()
    }

    fn oriented(&self, below: bool) -> Self {
        if below {
            self.flipped()
        } else {
            *self
        }
    }

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
        self.plate.ext.re
    }

    fn exit(&self) -> f64 {
        self.plate.exit.re
    }

    /// Through the plate's model for this incidence (the one decision of [`PlateModel::new`]).
    fn evaluate(
        &self,
        spectrum: &Spectrum,
        frame: PlaneFrame,
        beta: C64,
        want: Want,
    ) -> Result<Vec<SlabMueller>> {
        evaluate(
            &PlateModel::new(&self.plate, frame, beta),
            spectrum,
            want,
            self.output,
        )
    }
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

/// A plate query at exact wavelengths, over the reals `T`: what a spectral renderer asks at the
/// wavelengths it traces along a path, on the host (`f64`) or recorded as a program
/// ([`crate::record`]) whose inputs are the path's and the plate's per-lane values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExactPlate<T: Real = f64> {
    /// The plate (top = the exterior side, `z > 0`).
    pub plate: Plate<T>,
    /// Which lobes to compute.
    pub want: Want,
    /// Only `M00`.
    pub output: Output,
    /// The exit medium absorbs whatever enters it ([`PlateQuery::absorbing_exit`]).
    pub absorbing_exit: bool,
}

impl ExactPlate {
    /// The exact plate of a validated query.
    pub fn of(q: &PlateQuery) -> Self {
        ExactPlate {
            plate: q.plate,
            want: q.want,
            output: q.output,
            absorbing_exit: q.absorbing_exit,
        }
    }
}

impl<T: Real> Thin<T> for ExactPlate<T> {
    type Spectrum = [T];

    fn channels(wavelengths: &[T]) -> Result<usize> {
        if (1..=MAX_BANDS).contains(&wavelengths.len()) {
            Ok(wavelengths.len())
        } else {
            Err(Error::new(
                "count",
                format!(
                    "must be 1 to {MAX_BANDS} wavelengths, got {}",
                    wavelengths.len()
                ),
            ))
        }
    }

    fn is_signed(_: &[T]) -> bool {
        false
    }

    fn want(&self) -> Want {
        self.want
    }

    fn output(&self) -> Output {
        self.output
    }

    fn absorbing_exit(&self) -> bool {
        self.absorbing_exit
    }

    fn ext(&self) -> T {
        self.plate.ext.re
    }

    fn exit(&self) -> T {
        self.plate.exit.re
    }

    fn oriented(&self, below: T::Mask) -> Self {
        let p = &self.plate;
        let mut q = *self;
        q.plate.ext = Select::select(below, p.exit, p.ext);
        q.plate.exit = Select::select(below, p.ext, p.exit);
        q.plate.axis.z = T::select(below, -p.axis.z, p.axis.z);
        q
    }

    /// The slab at each wavelength; a plate whose indices do not depend on the wavelength
    /// solves its interfaces once.
    fn evaluate(
        &self,
        wavelengths: &[T],
        frame: PlaneFrame<T>,
        beta: Cx<T>,
        want: Want,
    ) -> Result<Vec<SlabMueller<T>>> {
        let mut fixed = None;
        let mut out = Vec::with_capacity(wavelengths.len());
        for &lambda_nm in wavelengths {
            let slab = self.plate.at(lambda_nm)?;
            let optics = match fixed {
                Some(o) if !self.plate.material.is_dispersive() => o,
                _ => slab.optics(&frame, beta)?,
            };
            fixed = Some(optics);
            out.push(self.output.keep(optics.mueller(lambda_nm, want)?));
        }
        Ok(out)
    }
}

/// The lobe a path samples from an exact plate (one wavelength per channel) seen from `wi`,
/// chosen with the uniform number `u` among the components whose bits `components` sets
/// (0 reflection, 1 transmission), as Mitsuba's sample ([`choice::sample`]); the same for any
/// thin element at exact wavelengths (a stack: [`crate::render::stack::sample_exact_stack`]).
pub fn sample_exact<T: Real, E: Thin<T, Spectrum = [T]>, const C: usize>(
    q: &E,
    wavelengths: &[T; C],
    wi: Vector3<T>,
    u: T,
    transport: Transport,
    components: u32,
) -> Result<Sampled<T, C>> {
    let per_channel = thin::lobes(q, &wavelengths[..], wi, transport, true)?;
    let slots: [Slots<PLATE_SLOTS, T>; C] = std::array::from_fn(|c| per_channel[c]);
    Ok(choice::sample(
        &slots,
        |slot| components & (1 << plate_component(slot)) != 0,
        plate_component,
        u,
    ))
}
