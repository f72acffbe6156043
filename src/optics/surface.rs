//! The surface of a uniaxial crystal under an isotropic exterior, seen from the local shading
//! frame (Mitsuba's: `z` = normal towards the exterior, the crystal fills `z < 0`).
//!
//! This ties [`crate::optics::frame`], [`crate::optics::modes`] and [`crate::optics::interface`] together: it turns a
//! direction of incidence into the incidence parameter `β` and solves the interface with the
//! exterior as the upper medium and the crystal as the lower one.

use crate::error::{Error, Result};
use crate::material::check_clear_index;
use crate::optics::frame::PlaneFrame;
use crate::optics::interface::Interface;
use crate::optics::medium::Uniaxial;
use crate::optics::modes::{index_along, k_max, Mode, ModeKind};
use crate::real::Real;
use nalgebra::Vector3;
use num_complex::Complex64 as C64;

/// Which wave arrives at the surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Incident {
    /// A plane wave in the exterior (s and p both solved).
    Outside,
    /// An o- or e-wave inside the crystal travelling towards the surface.
    Inside(ModeKind),
}

/// An isotropic exterior over a uniaxial crystal whose optic axis is given in the local frame,
/// over the reals `T` (`f64` on the host).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface<T: Real = f64> {
    /// The exterior medium (isotropic).
    pub exterior: Uniaxial<T>,
    /// The crystal, optic axis in the local frame.
    pub crystal: Uniaxial<T>,
}

/// A solved surface: the interface in the plane-of-incidence frame, and that frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solved {
    /// The plane-of-incidence frame in local coordinates.
    pub frame: PlaneFrame,
    /// The solved interface (upper = exterior, lower = crystal).
    pub interface: Interface,
}

impl Surface {
    /// A surface between an isotropic exterior of index `ext` and `crystal`.
    pub fn new(ext: C64, crystal: Uniaxial) -> Result<Self> {
        let exterior = Uniaxial::isotropic(check_clear_index("ext_ior", ext)?)?;
        Ok(Surface { exterior, crystal })
    }

    /// Incidence parameter `β = η sin θ` (eq. S1) of a wave whose wave normal makes the
    /// angle `theta` with the normal, in the plane of `frame`. For an e-wave inside, `η` is the
    /// direction-dependent extraordinary index.
    pub fn beta(&self, incident: Incident, frame: &PlaneFrame, theta: f64) -> C64 {
        let (st, ct) = theta.sin_cos();
        match incident {
            Incident::Outside => self.exterior.eta_o * st,
            Incident::Inside(kind) => {
                let normal = Vector3::new(st, 0.0, ct);
                index_along(&self.crystal_in(frame), kind, normal) * st
            }
        }
    }

    /// Solves the surface for incidence parameter `beta` in the plane of `frame`.
    pub fn solve(&self, frame: PlaneFrame, beta: C64) -> Result<Solved> {
        if !beta.re.is_finite() || !beta.im.is_finite() || beta.re < 0.0 {
            return Err(Error::new("beta", "must be finite and >= 0"));
        }
        let interface = Interface::new(&self.exterior, &self.crystal_in(&frame), beta)?;
        Ok(Solved { frame, interface })
    }

    /// `(K_o^max, K_e^max)/k0` of the crystal in the plane of `frame` (eq. S15).
    pub fn k_max(&self, frame: &PlaneFrame) -> (C64, C64) {
        k_max(&self.crystal_in(frame))
    }
}

impl<T: Real> Surface<T> {
    /// The crystal with its optic axis expressed in the working frame of `frame`.
    pub fn crystal_in(&self, frame: &PlaneFrame<T>) -> Uniaxial<T> {
        self.crystal.with_axis(frame.to_working(self.crystal.axis))
    }
}

impl Solved {
    /// Ray (Poynting) direction of a mode in the local frame (eq. S12).
    pub fn ray_local(&self, mode: &Mode) -> Option<Vector3<f64>> {
        mode.ray_direction().map(|d| self.frame.to_local(d))
    }

    /// Wave-normal direction of a mode in the local frame (eq. S11).
    pub fn wave_local(&self, mode: &Mode) -> Vector3<f64> {
        self.frame.to_local(mode.wave_direction())
    }
}
