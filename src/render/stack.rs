//! The lobes of a stack of layers (reflection and transmission) as a path tracer samples them,
//! over one wavelength, a band or a set of colour channels: [`crate::render::thin`] with the
//! stack's model of [`crate::stack::spectral`].

use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::render::thin::{self, Spectrum, Thin, ThinQuery};
use crate::render::{PathLobe, Transport};
use crate::stack::spectral::StackModel;
use crate::stack::Stack;
use nalgebra::Vector3;
use num_complex::Complex64 as C64;

/// A stack query: everything but the direction and the spectrum.
pub type StackQuery = ThinQuery<Stack>;

impl StackQuery {
    /// A query of `stack` (validated by [`Stack::new`]).
    pub fn new(stack: Stack, reflection: bool, transmission: bool, intensity_only: bool) -> Self {
        ThinQuery::of(stack, reflection, transmission, intensity_only)
    }
}

/// The stack's lobes seen from `wi`, one `[reflection, transmission]` pair per spectral channel:
/// [`thin::lobes`], the stack solved once, from `wi`'s side, for both lobes.
pub fn stack_lobes(
    q: &StackQuery,
    spectrum: &Spectrum,
    wi: Vector3<f64>,
    transport: Transport,
) -> Result<Vec<[Option<PathLobe>; 2]>> {
    thin::lobes(q, spectrum, wi, transport, true)
}

/// [`stack_lobes`] with each lobe solved on its own (the reference of the shared solution).
pub fn stack_lobes_full(
    q: &StackQuery,
    spectrum: &Spectrum,
    wi: Vector3<f64>,
    transport: Transport,
) -> Result<Vec<[Option<PathLobe>; 2]>> {
    thin::lobes(q, spectrum, wi, transport, false)
}

impl Thin for Stack {
    type Model<'a> = StackModel<'a>;

    fn ext(&self) -> f64 {
        self.ext.re
    }

    fn exit(&self) -> f64 {
        self.exit.re
    }

    fn flipped(&self) -> Self {
        Stack::flipped(self)
    }

    fn model(&self, frame: PlaneFrame, beta: C64) -> StackModel<'_> {
        StackModel::new(self, frame, beta)
    }
}
