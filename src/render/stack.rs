//! The lobes of a stack of layers (reflection and transmission) as a path tracer samples them,
//! over one wavelength, a band or a set of colour channels: [`crate::render::thin`] with the
//! stack's model of [`crate::stack::spectral`]; at exact wavelengths over any [`Real`]
//! ([`ExactStack`]), the form a program records ([`crate::record`]).

use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::optics::medium::Uniaxial;
use crate::optics::modes::modes;
use crate::plate::slab::{Output, SlabMueller, Want};
use crate::real::complex::Cx;
use crate::real::{Real, Select};
use crate::render::choice::Sampled;
use crate::render::plate::{sample_exact, ExactPlate};
use crate::render::thin::{self, Element, Spectrum, Thin, ThinQuery};
use crate::render::{PathLobe, Transport};
use crate::stack::exact::StackBlocks;
use crate::stack::spectral::StackModel;
use crate::stack::{in_layer, Stack};
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

impl Element for Stack {
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

/// A stack query at exact wavelengths, over the reals `T`: what a spectral renderer asks at the
/// wavelengths it traces along a path, on the host (`f64`) or recorded as a program whose
/// inputs are the path's and the layers' per-lane values (the plate's [`ExactPlate`]).
///
/// Seen from below ([`Thin::oriented`]) a stack is [`Stack::flipped`]: exterior and exit
/// swapped, the layers in reverse order, each mirrored through `z = 0`. Layers of different
/// materials cannot be chosen between per lane before their indices are known, so the side is
/// kept as a mask, `below`, and the flip happens at each wavelength on the layers' media
/// ([`ExactStack::blocks`]): the stack's indices evaluated once, chosen per lane.
#[derive(Clone, Debug)]
pub struct ExactStack<T: Real = f64> {
    /// The stack as given (its exterior above, `z > 0`).
    pub stack: Stack<T>,
    /// Where it is seen from below: flipped.
    pub below: T::Mask,
    /// Which lobes to compute.
    pub want: Want,
    /// Only `M00`.
    pub output: Output,
    /// The exit medium absorbs whatever enters it ([`ThinQuery::absorbing_exit`]).
    pub absorbing_exit: bool,
}

impl ExactStack {
    /// The exact stack of a query (validated by [`Stack::new`]).
    pub fn of(q: &StackQuery) -> Self {
        ExactStack {
            stack: q.element.clone(),
            below: false,
            want: q.want,
            output: q.output,
            absorbing_exit: q.absorbing_exit,
        }
    }
}

impl<T: Real> ExactStack<T> {
    /// The blocks of the stack as seen (flipped where `below` holds) at `lambda_nm`, for
    /// incidence parameter `beta` in the plane of `frame`: every layer's medium evaluated once,
    /// layer `j` of the flipped stack being layer `N − 1 − j` mirrored.
    fn blocks(&self, lambda_nm: T, frame: &PlaneFrame<T>, beta: Cx<T>) -> Result<StackBlocks<T>> {
        let (layers, below) = (&self.stack.layers, self.below);
        let n = layers.len();
        let local = layers
            .iter()
            .enumerate()
            .map(|(j, l)| l.local_medium(lambda_nm).map_err(|e| in_layer(j, e)))
            .collect::<Result<Vec<_>>>()?;
        let thickness_nm = (0..n)
            .map(|j| {
                let (own, flipped) = (&layers[j], &layers[n - 1 - j]);
                T::select(below, flipped.thickness_nm, own.thickness_nm)
            })
            .collect();
        let (ext, exit) = (self.stack.ext, self.stack.exit);
        StackBlocks::solve(
            Select::select(below, exit, ext),
            Select::select(below, ext, exit),
            thickness_nm,
            beta,
            |j| {
                let (own, flipped) = (&local[j], &local[n - 1 - j]);
                let a = flipped.axis;
                let axis = Select::select(below, Vector3::new(a.x, a.y, -a.z), own.axis);
                let medium = Uniaxial {
                    eta_o: Select::select(below, flipped.eta_o, own.eta_o),
                    eta_e: Select::select(below, flipped.eta_e, own.eta_e),
                    axis: frame.to_working(axis),
                };
                Ok(modes(&medium, beta))
            },
        )
    }
}

impl<T: Real> Thin<T> for ExactStack<T> {
    type Spectrum = [T];

    fn channels(wavelengths: &[T]) -> Result<usize> {
        ExactPlate::<T>::channels(wavelengths)
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
        T::select(self.below, self.stack.exit.re, self.stack.ext.re)
    }

    fn exit(&self) -> T {
        T::select(self.below, self.stack.ext.re, self.stack.exit.re)
    }

    /// Flipped where `below` holds (and where it did not already).
    fn oriented(&self, below: T::Mask) -> Self {
        ExactStack {
            below: (self.below & !below) | (!self.below & below),
            ..self.clone()
        }
    }

    /// The blocks at each wavelength; a stack whose indices do not depend on the wavelength
    /// solves its interfaces once.
    fn evaluate(
        &self,
        wavelengths: &[T],
        frame: PlaneFrame<T>,
        beta: Cx<T>,
        want: Want,
    ) -> Result<Vec<SlabMueller<T>>> {
        let mut fixed: Option<StackBlocks<T>> = None;
        let mut out = Vec::with_capacity(wavelengths.len());
        for &lambda_nm in wavelengths {
            let blocks = match fixed.take() {
                Some(b) if !self.stack.is_dispersive() => b,
                _ => self.blocks(lambda_nm, &frame, beta)?,
            };
            out.push(self.output.keep(blocks.mueller(lambda_nm, want)?));
            fixed = Some(blocks);
        }
        Ok(out)
    }
}

/// The lobe a path samples from an exact stack (one wavelength per channel) seen from `wi`,
/// chosen with the uniform number `u` among the components whose bits `components` sets
/// (0 reflection, 1 transmission), as Mitsuba's sample ([`sample_exact`]).
pub fn sample_exact_stack<T: Real, const C: usize>(
    q: &ExactStack<T>,
    wavelengths: &[T; C],
    wi: Vector3<T>,
    u: T,
    transport: Transport,
    components: u32,
) -> Result<Sampled<T, C>> {
    sample_exact(q, wavelengths, wi, u, transport, components)
}
