//! The plane-parallel uniaxial plate (slab) of thickness `d` between two isotropic media, exact at
//! one wavelength: every internal path summed in closed form (physics notes §3; the plane-wave
//! form of seed eqs. S20-S26).
//!
//! With the interface blocks of [`crate::interface`] (top interface: exterior above, crystal
//! below; bottom interface: crystal above, exit medium below) and the propagation matrices
//! `P↓ = diag(exp(−i k0 q↓ d))`, `P↑ = diag(exp(i k0 q↑ d))` of the o/e modes,
//!
//! ```text
//! D   = r₃ P↑ r₂ P↓                       (one internal round trip, mixes o and e)
//! J_T = t₂ P↓ (I − D)⁻¹ t₁
//! J_R = r₁ + t₃ P↑ r₂ P↓ (I − D)⁻¹ t₁
//! ```
//! Only decaying exponentials appear (`|exp(−i k0 q↓ d)| ≤ 1`), so thick absorbing or
//! evanescent layers stay exact: this is a scattering-matrix formulation.

use crate::error::{Error, Result};
use crate::frame::PlaneFrame;
use crate::interface::Interface;
use crate::medium::{check_clear_index, Uniaxial};
use crate::modes::{modes, normal_components, ModeSet};
use crate::mueller;
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;

/// A uniaxial plate between an isotropic top (light arrives from there) and bottom medium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slab {
    /// Top (incident side) medium, isotropic.
    pub top: Uniaxial,
    /// The plate; optic axis in the local frame.
    pub layer: Uniaxial,
    /// Bottom (exit side) medium, isotropic.
    pub bottom: Uniaxial,
    /// Thickness in nm (the unit of wavelengths).
    pub thickness_nm: f64,
}

/// The wavelength-independent part of a slab for one incidence (at fixed indices): both
/// interfaces, solved in the plane-of-incidence frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlabOptics {
    /// Top interface (top medium above, layer below).
    pub top: Interface,
    /// Bottom interface (layer above, bottom medium below).
    pub bottom: Interface,
    /// Slab thickness in nm.
    pub thickness_nm: f64,
}

/// Which lobes a query needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Want {
    /// Compute reflection.
    pub reflection: bool,
    /// Compute transmission.
    pub transmission: bool,
}

impl Want {
    /// Both lobes.
    pub const BOTH: Want = Want {
        reflection: true,
        transmission: true,
    };
}

/// Coherent Jones matrices of a slab at one wavelength, in the s/p bases of the top
/// (incident and reflected waves) and bottom (transmitted wave) media; flux-normalised, so
/// `|J|²` entries are power fractions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlabJones {
    /// Reflection (`None` if not asked for).
    pub r: Option<Matrix2<C64>>,
    /// Transmission (`None` if not asked for; zero if the exit wave is evanescent).
    pub t: Option<Matrix2<C64>>,
}

/// Mueller matrices (Mitsuba's convention) of a slab in the s/p frames of the top medium
/// (reflection) and of the bottom medium (transmission); power fractions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlabMueller {
    /// Reflection.
    pub r: Option<Matrix4<f64>>,
    /// Transmission.
    pub t: Option<Matrix4<f64>>,
}

impl Slab {
    /// A validated slab.
    pub fn new(top: C64, layer: Uniaxial, bottom: C64, thickness_nm: f64) -> Result<Self> {
        if !(thickness_nm.is_finite() && thickness_nm >= 0.0) {
            return Err(Error::new(
                "thickness",
                format!("must be finite and >= 0, got {thickness_nm}"),
            ));
        }
        Ok(Slab {
            top: Uniaxial::isotropic(check_clear_index("ext_ior", top)?)?,
            layer,
            bottom: Uniaxial::isotropic(check_clear_index("exit_ior", bottom)?)?,
            thickness_nm,
        })
    }

    /// The layer's modes for incidence parameter `beta` in the plane of `frame`.
    pub fn layer_modes(&self, frame: &PlaneFrame, beta: C64) -> ModeSet {
        modes(
            &self.layer.with_axis(frame.to_working(self.layer.axis)),
            beta,
        )
    }

    /// The layer's normal components `[o↓, e↓, o↑, e↑]` ([`normal_components`]).
    pub fn layer_q(&self, frame: &PlaneFrame, beta: C64) -> [C64; 4] {
        normal_components(
            &self.layer.with_axis(frame.to_working(self.layer.axis)),
            beta,
        )
    }

    /// Solves both interfaces for incidence parameter `beta` in the plane of `frame`.
    pub fn optics(&self, frame: &PlaneFrame, beta: C64) -> Result<SlabOptics> {
        let layer = self.layer.with_axis(frame.to_working(self.layer.axis));
        let inner = modes(&layer, beta);
        let top = Interface::from_modes(modes(&self.top, beta), inner)?;
        let bottom = Interface::from_modes(inner, modes(&self.bottom, beta))?;
        Ok(SlabOptics {
            top,
            bottom,
            thickness_nm: self.thickness_nm,
        })
    }
}

impl SlabOptics {
    /// The layer's modes.
    pub fn layer_modes(&self) -> &ModeSet {
        &self.top.lower
    }

    /// Propagation factors `(P↓, P↑)` through the layer at vacuum wavelength `lambda_nm`.
    pub fn propagation(&self, lambda_nm: f64) -> (Matrix2<C64>, Matrix2<C64>) {
        let m = self.layer_modes();
        let q = [m.down[0].q, m.down[1].q, m.up[0].q, m.up[1].q];
        self.propagation_with(lambda_nm, &q)
    }

    /// Propagation factors for given normal components `[o↓, e↓, o↑, e↑]` of the layer's modes.
    fn propagation_with(&self, lambda_nm: f64, q: &[C64; 4]) -> (Matrix2<C64>, Matrix2<C64>) {
        let kd = std::f64::consts::TAU * self.thickness_nm / lambda_nm;
        let i = C64::new(0.0, 1.0);
        let p = |k: usize, sign: f64| (i * q[k] * (sign * kd)).exp();
        (
            Matrix2::from_diagonal(&nalgebra::Vector2::new(p(0, -1.0), p(1, -1.0))),
            Matrix2::from_diagonal(&nalgebra::Vector2::new(p(2, 1.0), p(3, 1.0))),
        )
    }

    /// Flux ratio per unit amplitude `P_bottom / P_top` (transmission power factor, seed S19).
    pub fn transmission_flux_ratio(&self) -> f64 {
        let p_in = self.top.upper.down[0].flux.abs();
        let p_out = self.bottom.lower.down[0].flux.abs();
        if p_in > 0.0 && !self.bottom.lower.down[0].is_evanescent() {
            p_out / p_in
        } else {
            0.0
        }
    }

    /// The coherent, flux-normalised Jones matrices at `lambda_nm` (all internal paths).
    /// Fails only at an exact internal resonance (`I − D` singular: a guided mode, which light
    /// from outside cannot excite in a passive slab).
    pub fn jones(&self, lambda_nm: f64, want: Want) -> Result<SlabJones> {
        self.jones_with(self.propagation(lambda_nm), want)
    }

    /// [`SlabOptics::jones`] with the interfaces of `self` and the layer phases of the normal
    /// components `q` (`[o↓, e↓, o↑, e↑]`, e.g. [`crate::modes::normal_components`] at a nearby
    /// wavelength): a dispersive plate across a narrow band, where the amplitudes barely change
    /// but the phases do.
    pub fn mueller_with_phases(
        &self,
        lambda_nm: f64,
        q: &[C64; 4],
        want: Want,
    ) -> Result<SlabMueller> {
        let j = self.jones_with(self.propagation_with(lambda_nm, q), want)?;
        Ok(SlabMueller {
            r: j.r.as_ref().map(mueller::from_jones),
            t: j.t.as_ref().map(mueller::from_jones),
        })
    }

    fn jones_with(&self, (pd, pu): (Matrix2<C64>, Matrix2<C64>), want: Want) -> Result<SlabJones> {
        let (t1, r1) = (self.top.t_above(), self.top.r_above());
        let (t3, r3) = (self.top.t_below(), self.top.r_below());
        let (t2, r2) = (self.bottom.t_above(), self.bottom.r_above());
        let d = r3 * pu * r2 * pd;
        let inner = (Matrix2::identity() - d).try_inverse().ok_or_else(|| {
            Error::new(
                "slab",
                "internal resonance: the multiple-reflection sum diverges",
            )
        })? * t1;
        let r = want.reflection.then(|| r1 + t3 * pu * r2 * pd * inner);
        let t = want.transmission.then(|| {
            let f = self.transmission_flux_ratio().sqrt();
            t2 * pd * inner * C64::new(f, 0.0)
        });
        Ok(SlabJones { r, t })
    }

    /// Mueller matrices (Mitsuba's convention, s/p frames) of reflection and transmission.
    pub fn mueller(&self, lambda_nm: f64, want: Want) -> Result<SlabMueller> {
        let j = self.jones(lambda_nm, want)?;
        Ok(SlabMueller {
            r: j.r.as_ref().map(mueller::from_jones),
            t: j.t.as_ref().map(mueller::from_jones),
        })
    }
}
