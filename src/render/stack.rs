//! The lobes of a stack of layers (reflection and transmission) as a path tracer samples them,
//! over one wavelength, a band or a set of colour channels: [`crate::render::thin`] with the
//! stack's models of [`crate::stack::spectral`].

use crate::band::{is_exact_band, narrow_band};
use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::plate::slab::{Output, SlabMueller, Want};
use crate::quadrature::Accuracy;
use crate::render::thin::{self, Spectrum, Thin};
use crate::render::{PathLobe, Transport};
use crate::stack::spectral::StackModel;
use crate::stack::Stack;
use nalgebra::Vector3;
use num_complex::Complex64 as C64;

/// A stack query: everything but the direction and the spectrum.
#[derive(Clone, Debug, PartialEq)]
pub struct StackQuery {
    /// The stack (its exterior above, `z > 0`).
    pub stack: Stack,
    /// Which lobes to compute.
    pub want: Want,
    /// Only `M00`.
    pub output: Output,
    /// The exit medium absorbs whatever enters it: no transmission lobe, no light from below.
    pub absorbing_exit: bool,
}

impl StackQuery {
    /// A query of `stack` (validated by [`Stack::new`]).
    pub fn new(stack: Stack, reflection: bool, transmission: bool, intensity_only: bool) -> Self {
        StackQuery {
            stack,
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

    /// The same query with an absorbing exit medium or not.
    pub fn with_absorbing_exit(self, absorbing_exit: bool) -> Self {
        StackQuery {
            absorbing_exit,
            ..self
        }
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

impl Thin for StackQuery {
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
        self.stack.ext.re
    }

    fn exit(&self) -> f64 {
        self.stack.exit.re
    }

    fn flipped(&self) -> Self {
        StackQuery {
            stack: self.stack.flipped(),
            ..self.clone()
        }
    }

    fn evaluate(
        &self,
        spectrum: &Spectrum,
        frame: PlaneFrame,
        beta: C64,
        want: Want,
    ) -> Result<Vec<SlabMueller>> {
        let model = StackModel::new(&self.stack, frame, beta);
        match *spectrum {
            Spectrum::Weights(set) => Ok(model
                .channels(set, want, self.output, Accuracy::Perceptual)?
                .to_vec()),
            _ => spectrum
                .bands()
                .into_iter()
                .map(|(wavelength_nm, fwhm_nm)| {
                    if is_exact_band(fwhm_nm, wavelength_nm) {
                        model.at(wavelength_nm, want, self.output)
                    } else {
                        model.band(
                            &narrow_band(wavelength_nm, fwhm_nm),
                            want,
                            self.output,
                            Accuracy::Perceptual,
                        )
                    }
                })
                .collect(),
        }
    }
}
