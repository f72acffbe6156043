//! Uniaxial media at one wavelength: complex ordinary and extraordinary indices and an optic axis.
//!
//! Time convention of the whole core: fields vary as `exp(i (k·r − ω t))` (the supplemental's
//! convention), so an absorbing index is `n + iκ` with `κ ≥ 0` and a wave decays along the
//! imaginary part of its wave vector. The Mitsuba boundary converts once (see `mueller`).

use crate::error::{finite, Error, Result};
use crate::material::check_index;
use crate::real::complex::Cx;
use crate::real::Real;
use nalgebra::{Matrix3, Vector3};
use num_complex::Complex64 as C64;

/// A homogeneous, non-magnetic uniaxial medium: permittivity
/// `ε = ε_o I + (ε_e − ε_o) A Aᵀ` (eq. S6) with `ε_o = η_o²`, `ε_e = η_e²`; in the numbers `T`
/// of [`crate::real`] (`f64` on the host).
///
/// Dichroism (eq. S16) is carried by separate extinction coefficients in `η_o` and `η_e`:
/// light polarised perpendicular to `A` sees `κ_o`, light polarised along `A` sees `κ_e`.
/// `η_o == η_e` (bit for bit) makes the medium isotropic, and the core then uses s/p modes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uniaxial<T: Real = f64> {
    /// Ordinary complex index `n_o + iκ_o`.
    pub eta_o: Cx<T>,
    /// Extraordinary complex index `n_e + iκ_e`.
    pub eta_e: Cx<T>,
    /// Unit optic axis, in whatever frame the caller works in.
    pub axis: Vector3<T>,
}

impl Uniaxial {
    /// A validated uniaxial medium; `axis` is normalised. Fails (naming the parameter) for
    /// non-finite values, `n <= 0`, `κ < 0` or a zero axis.
    pub fn new(eta_o: C64, eta_e: C64, axis: Vector3<f64>) -> Result<Self> {
        check_index("eta_o", eta_o)?;
        check_index("eta_e", eta_e)?;
        for (i, c) in axis.iter().enumerate() {
            if !c.is_finite() {
                finite(&format!("optic_axis[{i}]"), *c)?;
            }
        }
        let norm = axis.norm();
        if norm <= 1e-300 || !norm.is_finite() {
            return Err(Error::new("optic_axis", "must be a non-zero vector"));
        }
        Ok(Uniaxial {
            eta_o,
            eta_e,
            axis: axis / norm,
        })
    }

    /// An isotropic medium of index `eta` (the axis is irrelevant and set to +z).
    pub fn isotropic(eta: C64) -> Result<Self> {
        check_index("eta", eta)?;
        Ok(Uniaxial {
            eta_o: eta,
            eta_e: eta,
            axis: Vector3::z(),
        })
    }

    /// The permittivity tensor `ε_o I + Δε A Aᵀ` (eq. S6).
    pub fn permittivity(&self) -> Matrix3<C64> {
        let a = self.axis.map(|x| C64::new(x, 0.0));
        Matrix3::identity() * self.eps_o() + a * a.transpose() * (self.eps_e() - self.eps_o())
    }

    /// The inverse permittivity `I/ε_o + (1/ε_e − 1/ε_o) A Aᵀ`.
    pub fn inverse_permittivity(&self) -> Matrix3<C64> {
        let a = self.axis.map(|x| C64::new(x, 0.0));
        let (io, ie) = (self.eps_o().inv(), self.eps_e().inv());
        Matrix3::identity() * io + a * a.transpose() * (ie - io)
    }
}

impl<T: Real> Uniaxial<T> {
    /// An isotropic medium of the (unchecked) index `eta`, axis +z: the exterior and exit
    /// media of a query.
    pub fn isotropic_unchecked(eta: Cx<T>) -> Self {
        let (zero, one) = (T::zero(), T::one());
        Uniaxial {
            eta_o: eta,
            eta_e: eta,
            axis: Vector3::new(zero, zero, one),
        }
    }

    /// True when the two indices are identical: the medium is then isotropic.
    pub fn is_isotropic(&self) -> T::Mask {
        self.eta_o.re.equals(self.eta_e.re) & self.eta_o.im.equals(self.eta_e.im)
    }

    /// True when both indices are real (no absorption).
    pub fn is_lossless(&self) -> T::Mask {
        let zero = T::zero();
        self.eta_o.im.equals(zero) & self.eta_e.im.equals(zero)
    }

    /// Ordinary permittivity `ε_o = η_o²`.
    pub fn eps_o(&self) -> Cx<T> {
        self.eta_o * self.eta_o
    }

    /// Extraordinary permittivity `ε_e = η_e²`.
    pub fn eps_e(&self) -> Cx<T> {
        self.eta_e * self.eta_e
    }

    /// The same medium with `axis` (a unit vector, e.g. the axis seen from another frame).
    pub fn with_axis(&self, axis: Vector3<T>) -> Self {
        Uniaxial { axis, ..*self }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permittivity_and_inverse_are_inverse() {
        let m = Uniaxial::new(
            C64::new(1.6, 0.01),
            C64::new(1.4, 0.2),
            Vector3::new(0.3, -0.2, 0.9),
        )
        .unwrap();
        let p = m.permittivity() * m.inverse_permittivity();
        assert!((p - Matrix3::identity()).norm() < 1e-14);
    }

    #[test]
    fn invalid_inputs_name_the_parameter() {
        let ok = C64::new(1.5, 0.0);
        let e = Uniaxial::new(C64::new(-1.0, 0.0), ok, Vector3::z()).unwrap_err();
        assert_eq!(e.parameter, "eta_o");
        let e = Uniaxial::new(ok, C64::new(1.5, -0.1), Vector3::z()).unwrap_err();
        assert_eq!(e.parameter, "eta_e");
        let e = Uniaxial::new(ok, ok, Vector3::zeros()).unwrap_err();
        assert_eq!(e.parameter, "optic_axis");
        let e = Uniaxial::new(ok, ok, Vector3::new(f64::NAN, 0.0, 1.0)).unwrap_err();
        assert_eq!(e.parameter, "optic_axis[0]");
    }
}
