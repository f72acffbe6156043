//! A lobe's Mueller matrix in Mitsuba's implicit Stokes frames.
//!
//! Mitsuba reads a BSDF's Mueller matrix as mapping Stokes vectors in the frame
//! `stokes_basis(−wo_hat)` of the arriving light to the frame `stokes_basis(wi_hat)` of the
//! leaving light (`(wo_hat, wi_hat)` = `(wo, wi)` in Radiance mode, `(wi, wo)` in Importance
//! mode), where `stokes_basis(w)` is the first vector of Mitsuba's `coordinate_system(w)`: the
//! orthonormal basis of T. Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 6(1),
//! 2017. The rotation between two frames of one ray is Mitsuba's `rotate_stokes_basis`: the
//! rotator `R(θ)` (Stokes `Q, U` rotated by `2θ`) of the signed angle `θ` from the current
//! frame's x axis to the target's, counter-clockwise about the propagation direction.
//!
//! The shim (cpp/src/lobes.h) rotates the core's lobes into these frames with Mitsuba's own
//! functions for the values it hands Mitsuba. Here the same rotation serves the derivatives of
//! [`crate::render::tangents`]: they are taken of the rotated matrix, which is a smooth
//! function of the directions (except across the seam `w.z = 0` of `stokes_basis`, at grazing
//! angles), while the core's own frames (the plane of incidence) turn abruptly near normal
//! incidence.

use crate::render::{PathLobe, Transport};
use nalgebra::{Matrix4, Vector3};

/// Mitsuba's `stokes_basis(w)`: the first vector of `coordinate_system(w)` (Duff et al. 2017)
/// for a unit `w`, with the sign of `w.z` as Mitsuba takes it (`-0.0` counts as negative).
pub fn stokes_basis(w: Vector3<f64>) -> Vector3<f64> {
    let sign = 1f64.copysign(w.z);
    let a = -1.0 / (sign + w.z);
    let b = w.x * w.y * a;
    Vector3::new(sign * (w.x * w.x * a) + 1.0, sign * b, -sign * w.x)
}

/// Mitsuba's `rotator(θ)`: the Mueller matrix of a rotation of the Stokes frame by `θ`.
pub fn rotator(theta: f64) -> Matrix4<f64> {
    let (s, c) = (2.0 * theta).sin_cos();
    Matrix4::new(
        1.0, 0.0, 0.0, 0.0, //
        0.0, c, s, 0.0, //
        0.0, -s, c, 0.0, //
        0.0, 0.0, 0.0, 1.0,
    )
}

/// Mitsuba's `rotate_stokes_basis(forward, current, target)`: the Mueller matrix that
/// re-expresses a Stokes vector of a ray along `forward` from the frame with x axis `current`
/// in the frame with x axis `target` (both perpendicular to `forward`). The signed angle is
/// taken as `atan2(forward · (current × target), current · target)`, which equals Mitsuba's
/// unsigned angle with its sign rule and does not need unit axes.
pub fn rotate_stokes_basis(
    forward: Vector3<f64>,
    current: Vector3<f64>,
    target: Vector3<f64>,
) -> Matrix4<f64> {
    let theta = forward
        .dot(&current.cross(&target))
        .atan2(current.dot(&target));
    rotator(theta)
}

/// `m`, a matrix in the explicit frames of `lobe` (its `in_stokes_x` and `out_stokes_x`),
/// re-expressed in Mitsuba's implicit frames for the query direction `wi` and the sampled
/// direction `wo` (see the module documentation).
pub fn in_implicit_frames(
    lobe: &PathLobe,
    m: &Matrix4<f64>,
    wi: Vector3<f64>,
    wo: Vector3<f64>,
    transport: Transport,
) -> Matrix4<f64> {
    let (wo_hat, wi_hat) = match transport {
        Transport::Radiance => (wo, wi),
        Transport::Importance => (wi, wo),
    };
    let k_in = -wo_hat;
    let r_in_t = rotate_stokes_basis(k_in, lobe.in_stokes_x, stokes_basis(k_in)).transpose();
    let r_out = rotate_stokes_basis(wi_hat, lobe.out_stokes_x, stokes_basis(wi_hat));
    r_out * m * r_in_t
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `stokes_basis(w)` is a unit vector perpendicular to `w` on both hemispheres, and is
    /// Duff et al.'s first basis vector: `(1 - x²/(1+z), -xy/(1+z), -x)` for `z > 0`.
    #[test]
    fn stokes_basis_is_an_orthonormal_companion() {
        for w in [
            Vector3::new(0.3, -0.4, 0.866),
            Vector3::new(-0.6, 0.1, -0.79),
            Vector3::new(0.0, 0.0, 1.0),
            Vector3::new(0.0, 0.0, -1.0),
        ] {
            let w = w.normalize();
            let s = stokes_basis(w);
            assert!((s.norm() - 1.0).abs() < 1e-14);
            assert!(s.dot(&w).abs() < 1e-14);
        }
        let w = Vector3::new(0.3, -0.4, 0.866).normalize();
        let z1 = 1.0 + w.z;
        let expected = Vector3::new(1.0 - w.x * w.x / z1, -w.x * w.y / z1, -w.x);
        assert!((stokes_basis(w) - expected).norm() < 1e-15);
    }

    /// Rotating the frame by +θ about the propagation direction gives `rotator(θ)`; a
    /// rotation by π is the identity (Stokes vectors are invariant under x → −x).
    #[test]
    fn rotation_angle_and_sign() {
        let k = Vector3::z();
        let (c, t) = (
            Vector3::x(),
            Vector3::new(0.6_f64.cos(), 0.6_f64.sin(), 0.0),
        );
        assert!((rotate_stokes_basis(k, c, t) - rotator(0.6)).norm() < 1e-15);
        assert!((rotate_stokes_basis(-k, c, t) - rotator(-0.6)).norm() < 1e-15);
        assert!((rotate_stokes_basis(k, c, -c) - Matrix4::identity()).norm() < 1e-15);
        // A Stokes vector polarised along `t` reads (1, 1, 0, 0) in the target frame.
        let s_current = nalgebra::Vector4::new(1.0, (1.2_f64).cos(), (1.2_f64).sin(), 0.0);
        let s_target = rotate_stokes_basis(k, c, t) * s_current;
        assert!((s_target - nalgebra::Vector4::new(1.0, 1.0, 0.0, 0.0)).norm() < 1e-15);
    }
}
