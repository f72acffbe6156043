//! The lobes of a birefringent plate (reflection and transmission) as a path tracer samples
//! them, over one wavelength, a band or a set of colour channels (see [`crate::render`] for the
//! transport modes, [`crate::render::thin`] for the lobes of a thin element).

use crate::error::Result;
use crate::material::check_clear_index;
use crate::material::Material;
use crate::optics::frame::PlaneFrame;
use crate::optics::medium::Uniaxial;
use crate::params::Thickness;
use crate::plate::Plate;
use crate::render::thin::{self, Spectrum, Thin, ThinQuery};
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

impl Thin for Plate {
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
