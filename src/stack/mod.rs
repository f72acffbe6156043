//! Layered stacks: `N` plane-parallel uniaxial or isotropic layers between two isotropic media
//! (zero-order and achromatic waveplates, Lyot and Šolc filters, cellophane in layers), each
//! layer with its own material, thickness and optic axis (docs/physics.md §8).
//!
//! * [`exact`]: the stack at one wavelength, every internal path of every layer summed by a
//!   scattering-matrix recursion over its interfaces (only decaying exponentials: stable for
//!   thick, absorbing and evanescent layers);
//! * [`coherence`]: the same recursion with the internal round trips of thick layers summed
//!   incoherently (in Mueller space), the model the spectral integration evaluates;
//! * [`plan`]: group paths, which layers are thick for a given spectrum, and how fast the
//!   stack's spectrum oscillates;
//! * [`spectral`]: the stack over colour channels and narrow bands (a dispersive stack's
//!   interface blocks interpolated across a spectrum by the plate's Chebyshev series,
//!   [`crate::quadrature::interpolate::Interpolant`]).

pub mod coherence;
pub mod exact;
pub mod plan;
pub mod spectral;
pub mod survey;

use crate::error::{Error, Result};
use crate::material::{check_clear_index, Material};
use crate::optics::frame::PlaneFrame;
use crate::optics::medium::Uniaxial;
use crate::params::Thickness;
use crate::real::complex::Cx;
use crate::real::Real;
use nalgebra::Vector3;
use num_complex::Complex64 as C64;

/// One layer of a stack: a plane-parallel uniaxial (or isotropic) plate, over the reals `T`
/// (`f64` on the host, recorded numbers in a program whose layers' values are inputs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layer<T: Real = f64> {
    /// Its principal indices (possibly dispersive).
    pub material: Material<T>,
    /// Added to `Re η_e` (photoelastic stress), 0 for none.
    pub birefringence: T,
    /// Optic axis in the local frame (`z` the normal towards the exterior): a unit vector as
    /// [`Layer::new`] makes it, any non-zero length for [`Layer::local_medium`].
    pub axis: Vector3<T>,
    /// Thickness (nm).
    pub thickness_nm: T,
}

impl Layer {
    /// A layer with a validated thickness; the axis is normalised (and refused if zero or not
    /// finite, naming `optic_axis`).
    pub fn new(
        material: Material,
        birefringence: f64,
        axis: Vector3<f64>,
        thickness: Thickness,
    ) -> Result<Self> {
        let one = C64::new(1.0, 0.0);
        Ok(Layer {
            material,
            birefringence,
            axis: Uniaxial::new(one, one, axis)?.axis,
            thickness_nm: thickness.nm(),
        })
    }
}

impl<T: Real> Layer<T> {
    /// The layer's medium at `lambda_nm`, its unit axis in the local frame. The indices are
    /// checked ([`Material::indices`]); the axis is not again (validated by [`Layer::new`], or a
    /// program's input).
    pub fn local_medium(&self, lambda_nm: T) -> Result<Uniaxial<T>> {
        let (eta_o, eta_e) = self.material.indices(lambda_nm, self.birefringence)?;
        // As the plate builds its layer (`Plate::at`, `Slab::optics`), bit for bit.
        Ok(Uniaxial {
            eta_o,
            eta_e,
            axis: self.axis / self.axis.dot(&self.axis).sqrt(),
        })
    }

    /// The layer's medium at `lambda_nm`, its axis in the working frame of `frame`.
    pub fn medium(&self, lambda_nm: T, frame: &PlaneFrame<T>) -> Result<Uniaxial<T>> {
        let local = self.local_medium(lambda_nm)?;
        Ok(local.with_axis(frame.to_working(local.axis)))
    }

    /// True if its indices vary with wavelength.
    pub fn is_dispersive(&self) -> bool {
        self.material.is_dispersive()
    }

    /// The same layer mirrored through its plane (`z → −z`): the layer seen from below.
    pub fn mirrored(&self) -> Self {
        Layer {
            axis: Vector3::new(self.axis.x, self.axis.y, -self.axis.z),
            ..*self
        }
    }
}

/// A stack of layers between an isotropic exterior (above, where light arrives from) and an
/// isotropic exit medium (below). `layers[0]` touches the exterior.
#[derive(Clone, Debug, PartialEq)]
pub struct Stack<T: Real = f64> {
    /// The layers, from the exterior down.
    pub layers: Vec<Layer<T>>,
    /// Exterior index (real).
    pub ext: Cx<T>,
    /// Exit index (real).
    pub exit: Cx<T>,
}

impl Stack {
    /// A stack with checked exterior and exit indices (`ext_ior`, `exit_ior`: real and
    /// positive) and at least one layer.
    pub fn new(layers: Vec<Layer>, ext: C64, exit: C64) -> Result<Self> {
        if layers.is_empty() {
            return Err(Error::new("layers", "must hold at least one layer"));
        }
        Ok(Stack {
            layers,
            ext: check_clear_index("ext_ior", ext)?,
            exit: check_clear_index("exit_ior", exit)?,
        })
    }

    /// Total thickness (nm).
    pub fn thickness_nm(&self) -> f64 {
        self.layers.iter().map(|l| l.thickness_nm).sum()
    }
}

impl<T: Real> Stack<T> {
    /// True if any layer's indices vary with wavelength.
    pub fn is_dispersive(&self) -> bool {
        self.layers.iter().any(Layer::is_dispersive)
    }

    /// The same stack seen from below: exterior and exit swapped, the layers in reverse order,
    /// every one mirrored through `z = 0`.
    pub fn flipped(&self) -> Self {
        Stack {
            layers: self.layers.iter().rev().map(Layer::mirrored).collect(),
            ext: self.exit,
            exit: self.ext,
        }
    }

    /// The media from the exterior down at `lambda_nm` (exterior, layers, exit), axes in the
    /// working frame of `frame`; a layer's error under its name ([`in_layer`]).
    pub fn media(&self, lambda_nm: T, frame: &PlaneFrame<T>) -> Result<Vec<Uniaxial<T>>> {
        let mut media = Vec::with_capacity(self.layers.len() + 2);
        media.push(Uniaxial::isotropic_unchecked(self.ext));
        for (j, layer) in self.layers.iter().enumerate() {
            media.push(layer.medium(lambda_nm, frame).map_err(|e| in_layer(j, e))?);
        }
        media.push(Uniaxial::isotropic_unchecked(self.exit));
        Ok(media)
    }
}

/// An error of layer `index` (0-based) under that layer's name: `layers[2].thickness_um`.
/// (An error about the layer as a whole, with an empty parameter, becomes `layers[2]`.)
pub fn in_layer(index: usize, e: Error) -> Error {
    let parameter = if e.parameter.is_empty() {
        format!("layers[{index}]")
    } else {
        format!("layers[{index}].{}", e.parameter)
    };
    Error { parameter, ..e }
}
