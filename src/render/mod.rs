//! Lobes as a path tracer samples them: given the direction `wi` a renderer looks from and
//! its transport mode, every direction `wo` light can come from (Radiance) or go to
//! (Importance), with the physical Mueller matrix of that transfer in explicit Stokes frames.
//!
//! Physically the light always arrives along `−wo_hat` and leaves along `wi_hat`, with
//! `(wo_hat, wi_hat) = (wo, wi)` in Radiance mode and `(wi, wo)` in Importance mode (Mitsuba's
//! convention). Importance mode is the forward problem. Radiance mode needs the sources of the
//! light that leaves along `wi`: by time reversal (lossless reciprocity of the ray geometry),
//! they are the reversed outgoing rays of a wave sent along `−wi`; for each, the forward
//! problem is then solved from that source and the outgoing wave along `wi` is kept.

pub mod choice;
pub mod crystal;
pub mod isotropic;
pub mod plate;
pub mod slots;
pub mod stack;
pub mod thin;

use crate::real::{Mask, Real, Select};
use nalgebra::{Matrix4, Vector3};

/// Mitsuba's transport modes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    /// Paths traced from the camera.
    Radiance,
    /// Paths traced from the lights.
    Importance,
}

/// One sampled lobe, over the reals `T` (`f64` on the host).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathLobe<T: Real = f64> {
    /// Crystal: 0 reflection, 1 ordinary, 2 extraordinary transmission; plate: 0 R, 1 T.
    pub component: usize,
    /// Mitsuba's `wo` (unit, local).
    pub wo: Vector3<T>,
    /// `x` axis of the Stokes frame of the light arriving along `−wo_hat`.
    pub in_stokes_x: Vector3<T>,
    /// `x` axis of the Stokes frame of the light leaving along `wi_hat`.
    pub out_stokes_x: Vector3<T>,
    /// Physical Mueller matrix (Mitsuba's convention); in Radiance mode scaled by
    /// `(n_wi / n_wo)²` (radiance across an index step, ray indices of eq. S14).
    pub mueller: Matrix4<T>,
    /// `mueller[(0,0)]`, the unpolarised throughput.
    pub weight: T,
    /// The unpolarised power fraction of the physical transfer (`weight` without the radiance
    /// factor of Radiance mode; the same in both modes): what a lobe is chosen by
    /// ([`choice`]), as Mitsuba's own `dielectric` chooses by its Fresnel reflectance.
    pub power: T,
    /// Mitsuba's `bs.eta`: ray index on the `wo` side over the `wi` side.
    pub eta: T,
    /// Where the lobe exists: always on the host (a lobe that does not exist is `None` there);
    /// in a recorded program, the lanes that have it (total internal reflection removes a
    /// transmission in some lanes only).
    pub exists: T::Mask,
}

impl<T: Real> PathLobe<T> {
    /// A lobe whose weight and power are its Mueller matrix's `M00`; `stokes_x` = (in, out).
    pub fn new(
        component: usize,
        wo: Vector3<T>,
        (in_stokes_x, out_stokes_x): (Vector3<T>, Vector3<T>),
        mueller: Matrix4<T>,
        eta: T,
    ) -> Self {
        PathLobe {
            component,
            wo,
            in_stokes_x,
            out_stokes_x,
            mueller,
            weight: mueller[(0, 0)],
            power: mueller[(0, 0)],
            eta,
            exists: T::Mask::cst(true),
        }
    }

    /// The lobe with its Mueller matrix and weight multiplied by the radiance factor `factor`
    /// (Radiance mode, `(n_wi / n_wo)²`), its power fraction unchanged.
    pub fn with_radiance_factor(self, factor: T) -> Self {
        PathLobe {
            mueller: self.mueller * factor,
            weight: self.weight * factor,
            ..self
        }
    }

    /// The lobe where `exists` holds (and where it existed before).
    pub fn existing(self, exists: T::Mask) -> Self {
        PathLobe {
            exists: self.exists & exists,
            ..self
        }
    }
}

/// The lobe of `a` or of `b` per lane (both of one component: a slot's lobes in two outcomes
/// of a decision about the lanes).
impl<T: Real> Select<T::Mask> for PathLobe<T> {
    fn select(m: T::Mask, a: Self, b: Self) -> Self {
        debug_assert_eq!(a.component, b.component);
        PathLobe {
            component: a.component,
            wo: Select::select(m, a.wo, b.wo),
            in_stokes_x: Select::select(m, a.in_stokes_x, b.in_stokes_x),
            out_stokes_x: Select::select(m, a.out_stokes_x, b.out_stokes_x),
            mueller: Select::select(m, a.mueller, b.mueller),
            weight: T::select(m, a.weight, b.weight),
            power: T::select(m, a.power, b.power),
            eta: T::select(m, a.eta, b.eta),
            exists: Select::select(m, a.exists, b.exists),
        }
    }
}
