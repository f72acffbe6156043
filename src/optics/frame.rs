//! The local shading frame (Mitsuba's: `z` = surface normal towards the exterior) and the
//! plane-of-incidence working frame of [`crate::optics::modes`].

use crate::real::{Mask, Real};
use nalgebra::Vector3;

/// The plane-of-incidence frame expressed in the local frame: working `x` = `u` (direction of the
/// tangential wave vector), working `y` = `s = ẑ × u` (the s direction), working `z` = `ẑ`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneFrame<T: Real = f64> {
    /// Unit tangential propagation direction (local frame, `u.z = 0`).
    pub u: Vector3<T>,
    /// Unit s direction `ẑ × u` (local frame).
    pub s: Vector3<T>,
}

impl PlaneFrame {
    /// The frame for light arriving from the azimuth `phi` (radians): the direction towards the
    /// light is `(sin θ cos φ, sin θ sin φ, ±cos θ)`, so the tangential propagation direction is
    /// `u = −(cos φ, sin φ, 0)`. Defined for every θ, normal incidence included.
    pub fn from_azimuth(phi: f64) -> Self {
        Self::from_u(Vector3::new(-phi.cos(), -phi.sin(), 0.0))
    }
}

impl<T: Real> PlaneFrame<T> {
    /// The frame for light arriving from the local direction `towards_light` (either
    /// hemisphere). At normal incidence the s direction falls back to `(1, 0, 0)`, as in
    /// Mitsuba's `dielectric`.
    pub fn from_direction(towards_light: Vector3<T>) -> Self {
        let (x, y) = (-towards_light.x, -towards_light.y);
        let n = (x * x + y * y).sqrt();
        let zero = T::zero();
        let tilted = n.gt(zero);
        // Divided by one at normal incidence, where the quotient is discarded: no lane of a
        // recorded program computes 0/0 (whose NaN would poison Dr.Jit's derivatives).
        let n = tilted.when(|| n, T::one);
        let (ux, uy) = tilted.when(|| (x / n, y / n), || (zero, T::cst(-1.0)));
        Self::from_u(Vector3::new(ux, uy, zero))
    }

    fn from_u(u: Vector3<T>) -> Self {
        // ẑ × u, written out.
        PlaneFrame {
            u,
            s: Vector3::new(-u.y, u.x, T::zero()),
        }
    }

    /// Local → working coordinates.
    pub fn to_working(&self, v: Vector3<T>) -> Vector3<T> {
        Vector3::new(v.dot(&self.u), v.dot(&self.s), v.z)
    }

    /// Working → local coordinates.
    pub fn to_local(&self, v: Vector3<T>) -> Vector3<T> {
        self.u * v.x + self.s * v.y + Vector3::new(T::zero(), T::zero(), v.z)
    }
}

/// `axis` rotated about the local normal (z) by `degrees`, counter-clockwise seen from +z (from
/// the tangent s towards t): the plugins' `axis_angle`.
pub fn rotated_about_normal<T: Real>(axis: Vector3<T>, degrees: T) -> Vector3<T> {
    // As `f64::to_radians`: `degrees · (π / 180)`.
    let (s, c) = (degrees * (std::f64::consts::PI / 180.0)).sin_cos();
    Vector3::new(c * axis.x - s * axis.y, s * axis.x + c * axis.y, axis.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_handedness() {
        for phi in [0.0, 0.3, 2.0, -1.2] {
            let f = PlaneFrame::from_azimuth(phi);
            assert!((f.u.cross(&f.s) - Vector3::z()).norm() < 1e-15);
            let v = Vector3::new(0.3, -0.5, 0.8);
            assert!((f.to_local(f.to_working(v)) - v).norm() < 1e-15);
        }
        let f = PlaneFrame::from_direction(Vector3::<f64>::z());
        assert_eq!(f.s, Vector3::x());
        let w = Vector3::new(0.5_f64.sin(), 0.0, 0.5_f64.cos());
        let f = PlaneFrame::from_direction(w);
        assert!((f.u - Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-15);
    }
}
