//! The lobes of a birefringent plate (reflection and transmission) as a path tracer samples
//! them, over one wavelength, a band or a set of colour channels (see [`crate::render`] for the
//! transport modes, [`crate::render::thin`] for the lobes of a thin element).

use crate::error::{Error, Result};
use crate::material::check_clear_index;
use crate::material::Material;
use crate::optics::frame::PlaneFrame;
use crate::optics::medium::Uniaxial;
use crate::params::Thickness;
use crate::plate::slab::{Output, SlabMueller, Want};
use crate::plate::Plate;
use crate::real::complex::Cx;
use crate::real::{Real, Select};
use crate::render::choice::{self, Sampled};
use crate::render::slots::{plate_component, Slots, PLATE_SLOTS};
use crate::render::thin::{self, Element, Spectrum, Thin, ThinQuery, MAX_BANDS};
use crate::render::{PathLobe, Transport};
use crate::spectral::model::PlateModel;
use nalgebra::Vector3;
use num_complex::Complex64 as C64;

/// A plate query: everything but the direction and the spectrum.
pub type PlateQuery = ThinQuery<Plate>;

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
        Ok(ThinQuery::of(
            plate,
            reflection,
            transmission,
            intensity_only,
        ))
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

impl Element for Plate {
    type Model<'a> = PlateModel<'a>;

    fn ext(&self) -> f64 {
        self.ext.re
    }

    fn exit(&self) -> f64 {
        self.exit.re
    }

    fn flipped(&self) -> Self {
        let mut p = *self;
        p.ext = self.exit;
        p.exit = self.ext;
        p.axis.z = -p.axis.z;
        p
    }

    /// The plate's model for this incidence (the one decision of [`crate::spectral::route::model`]).
    fn model(&self, frame: PlaneFrame, beta: C64) -> PlateModel<'_> {
        PlateModel::new(self, frame, beta)
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
    /// The exit medium absorbs whatever enters it ([`ThinQuery::absorbing_exit`]).
    pub absorbing_exit: bool,
}

impl ExactPlate {
    /// The exact plate of a validated query.
    pub fn of(q: &PlateQuery) -> Self {
        ExactPlate {
            plate: q.element,
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
