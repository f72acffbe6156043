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

use nalgebra::{Matrix4, Vector3};

/// Mitsuba's transport modes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    /// Paths traced from the camera.
    Radiance,
    /// Paths traced from the lights.
    Importance,
}

/// One sampled lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathLobe {
    /// Crystal: 0 reflection, 1 ordinary, 2 extraordinary transmission; plate: 0 R, 1 T.
    pub component: usize,
    /// Mitsuba's `wo` (unit, local).
    pub wo: Vector3<f64>,
    /// `x` axis of the Stokes frame of the light arriving along `−wo_hat`.
    pub in_stokes_x: Vector3<f64>,
    /// `x` axis of the Stokes frame of the light leaving along `wi_hat`.
    pub out_stokes_x: Vector3<f64>,
    /// Physical Mueller matrix (Mitsuba's convention); in Radiance mode scaled by
    /// `(n_wi / n_wo)²` (radiance across an index step, ray indices of eq. S14).
    pub mueller: Matrix4<f64>,
    /// `mueller[(0,0)]`, the unpolarised throughput used to pick a lobe.
    pub weight: f64,
    /// Mitsuba's `bs.eta`: ray index on the `wo` side over the `wi` side.
    pub eta: f64,
}

impl PathLobe {
    /// A lobe whose weight is its Mueller matrix's `M00`; `stokes_x` = (in, out).
    pub fn new(
        component: usize,
        wo: Vector3<f64>,
        (in_stokes_x, out_stokes_x): (Vector3<f64>, Vector3<f64>),
        mueller: Matrix4<f64>,
        eta: f64,
    ) -> Self {
        PathLobe {
            component,
            wo,
            in_stokes_x,
            out_stokes_x,
            mueller,
            weight: mueller[(0, 0)],
            eta,
        }
    }
}
