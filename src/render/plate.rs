//! The lobes of a birefringent plate (reflection and transmission) as a path tracer samples
//! them, over one wavelength, a band or a set of colour channels (see [`crate::render`] for the
//! transport modes, [`crate::render::thin`] for the lobes of a thin element).

use crate::band::{is_exact_band, narrow_band};
use crate::error::Result;
use crate::material::check_clear_index;
use crate::material::Material;
use crate::optics::frame::PlaneFrame;
use crate::optics::medium::Uniaxial;
use crate::params::Thickness;
use crate::plate::slab::{Output, SlabMueller, Want};
use crate::plate::Plate;
use crate::quadrature::Accuracy;
use crate::render::thin::{self, Spectrum, Thin};
use crate::render::{PathLobe, Transport};
use crate::spectral::model::PlateModel;
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

impl Thin for PlateQuery {
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

    fn flipped(&self) -> Self {
        let mut q = *self;
        q.plate.ext = self.plate.exit;
        q.plate.exit = self.plate.ext;
        q.plate.axis.z = -q.plate.axis.z;
        q
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
