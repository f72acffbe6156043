//! The plane-parallel uniaxial plate (slab) of thickness `d` between two isotropic media, exact at
//! one wavelength: every internal path summed in closed form (docs/physics.md §3; the plane-wave
//! form of eqs. S20-S26).
//!
//! With the interface blocks of [`crate::optics::interface`] (top interface: exterior above, crystal
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

use crate::cmath;
use crate::error::{Error, Result};
use crate::material::check_clear_index;
use crate::optics::frame::PlaneFrame;
use crate::optics::interface::Interface;
use crate::optics::medium::Uniaxial;
use crate::optics::modes::{modes, normal_components, ModeSet};
use crate::optics::mueller;
use crate::params::Thickness;
use crate::real::complex::{self as cx, Cx};
use crate::real::{Mask, Real};
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;

/// A uniaxial plate between an isotropic top (light arrives from there) and bottom medium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slab<T: Real = f64> {
    /// Top (incident side) medium, isotropic.
    pub top: Uniaxial<T>,
    /// The plate; optic axis in the local frame.
    pub layer: Uniaxial<T>,
    /// Bottom (exit side) medium, isotropic.
    pub bottom: Uniaxial<T>,
    /// Thickness in nm (the unit of wavelengths).
    pub thickness_nm: T,
}

/// The wavelength-independent part of a slab for one incidence (at fixed indices): both
/// interfaces, solved in the plane-of-incidence frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlabOptics<T: Real = f64> {
    /// Top interface (top medium above, layer below).
    pub top: Interface<T>,
    /// Bottom interface (layer above, bottom medium below).
    pub bottom: Interface<T>,
    /// Slab thickness in nm.
    pub thickness_nm: T,
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
pub struct SlabJones<T: Real = f64> {
    /// Reflection (`None` if not asked for).
    pub r: Option<Matrix2<Cx<T>>>,
    /// Transmission (`None` if not asked for; zero if the exit wave is evanescent).
    pub t: Option<Matrix2<Cx<T>>>,
}

/// Mueller matrices (Mitsuba's convention) of a slab in the s/p frames of the top medium
/// (reflection) and of the bottom medium (transmission); power fractions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlabMueller<T: Real = f64> {
    /// Reflection.
    pub r: Option<Matrix4<T>>,
    /// Transmission.
    pub t: Option<Matrix4<T>>,
}

impl Slab {
    /// A slab between the real indices `top` and `bottom` (checked, as `ext_ior` and
    /// `exit_ior`), of a validated thickness.
    pub fn new(top: C64, layer: Uniaxial, bottom: C64, thickness: Thickness) -> Result<Self> {
        Ok(Slab {
            top: Uniaxial::isotropic(check_clear_index("ext_ior", top)?)?,
            layer,
            bottom: Uniaxial::isotropic(check_clear_index("exit_ior", bottom)?)?,
            thickness_nm: thickness.nm(),
        })
    }
}

impl<T: Real> Slab<T> {
    /// The layer's modes for incidence parameter `beta` in the plane of `frame`.
    pub fn layer_modes(&self, frame: &PlaneFrame<T>, beta: Cx<T>) -> ModeSet<T> {
        modes(
            &self.layer.with_axis(frame.to_working(self.layer.axis)),
            beta,
        )
    }

    /// The layer's normal components `[o↓, e↓, o↑, e↑]` ([`normal_components`]).
    pub fn layer_q(&self, frame: &PlaneFrame<T>, beta: Cx<T>) -> [Cx<T>; 4] {
        normal_components(
            &self.layer.with_axis(frame.to_working(self.layer.axis)),
            beta,
        )
    }

    /// Solves both interfaces for incidence parameter `beta` in the plane of `frame`.
    pub fn optics(&self, frame: &PlaneFrame<T>, beta: Cx<T>) -> Result<SlabOptics<T>> {
        let layer = self.layer.with_axis(frame.to_working(self.layer.axis));
        // Both interfaces solved where they lie ([`Interface::solve_in_place`]): they are
        // large, and moving them around costs about as much as solving them.
        let inner = modes(&layer, beta);
        let mut out = Ok(SlabOptics {
            top: Interface::unsolved(modes(&self.top, beta), inner),
            bottom: Interface::unsolved(inner, modes(&self.bottom, beta)),
            thickness_nm: self.thickness_nm,
        });
        if let Ok(optics) = &mut out {
            if let Err(e) = optics
                .top
                .solve_in_place()
                .and_then(|()| optics.bottom.solve_in_place())
            {
                out = Err(e);
            }
        }
        out
    }
}

impl<T: Real> SlabOptics<T> {
    /// The layer's modes.
    pub fn layer_modes(&self) -> &ModeSet<T> {
        &self.top.lower
    }

    /// Propagation factors `(P↓, P↑)` through the layer at vacuum wavelength `lambda_nm`.
    pub fn propagation(&self, lambda_nm: T) -> (Matrix2<Cx<T>>, Matrix2<Cx<T>>) {
        propagation(self.thickness_nm, lambda_nm, &self.layer_q())
    }

    /// The layer's normal components `[o↓, e↓, o↑, e↑]`.
    pub fn layer_q(&self) -> [Cx<T>; 4] {
        let m = self.layer_modes();
        [m.down[0].q, m.down[1].q, m.up[0].q, m.up[1].q]
    }

    /// What [`SlabOptics::jones`] needs besides the wavelength.
    pub fn blocks(&self) -> SlabBlocks<T> {
        SlabBlocks {
            r1: self.top.r_above(),
            t1: self.top.t_above(),
            r3: self.top.r_below(),
            t3: self.top.t_below(),
            r2: self.bottom.r_above(),
            t2: self.bottom.t_above(),
            q: self.layer_q(),
            flux: self.transmission_flux_ratio(),
            thickness_nm: self.thickness_nm,
        }
    }

    /// Flux ratio per unit amplitude `P_bottom / P_top` (transmission power factor, eq. S19).
    pub fn transmission_flux_ratio(&self) -> T {
        let p_in = self.top.upper.down[0].flux.abs();
        let p_out = self.bottom.lower.down[0].flux.abs();
        let carries = p_in.gt(T::zero()) & !self.bottom.lower.down[0].is_evanescent();
        carries.when(|| p_out / p_in, T::zero)
    }

    /// The coherent, flux-normalised Jones matrices at `lambda_nm` (all internal paths).
    /// Fails only at an exact internal resonance (`I − D` singular: a guided mode, which light
    /// from outside cannot excite in a passive slab).
    pub fn jones(&self, lambda_nm: T, want: Want) -> Result<SlabJones<T>> {
        self.blocks().jones(lambda_nm, want)
    }

    /// [`SlabOptics::mueller`] with the interfaces of `self` and the layer phases of the normal
    /// components `q` (`[o↓, e↓, o↑, e↑]`, e.g. [`crate::optics::modes::normal_components`] at a nearby
    /// wavelength): a dispersive plate across a narrow band, where the amplitudes barely change
    /// but the phases do.
    pub fn mueller_with_phases(
        &self,
        lambda_nm: T,
        q: &[Cx<T>; 4],
        want: Want,
    ) -> Result<SlabMueller<T>> {
        SlabBlocks {
            q: *q,
            ..self.blocks()
        }
        .mueller(lambda_nm, want)
    }

    /// Mueller matrices (Mitsuba's convention, s/p frames) of reflection and transmission.
    pub fn mueller(&self, lambda_nm: T, want: Want) -> Result<SlabMueller<T>> {
        let j = self.jones(lambda_nm, want)?;
        Ok(SlabMueller {
            r: j.r.as_ref().map(mueller::from_jones),
            t: j.t.as_ref().map(mueller::from_jones),
        })
    }
}

/// Propagation factors `(P↓, P↑) = (diag exp(−i k0 q↓ d), diag exp(i k0 q↑ d))` of a layer of
/// thickness `thickness_nm` with normal components `q = [o↓, e↓, o↑, e↑]`.
fn propagation<T: Real>(
    thickness_nm: T,
    lambda_nm: T,
    q: &[Cx<T>; 4],
) -> (Matrix2<Cx<T>>, Matrix2<Cx<T>>) {
    let (pd, pu) = phase_factors(thickness_nm, lambda_nm, q);
    let zero = cx::real(T::zero());
    (
        Matrix2::new(pd[0], zero, zero, pd[1]),
        Matrix2::new(pu[0], zero, zero, pu[1]),
    )
}

/// The diagonals of [`propagation`]. The o-wave's `q↑ = −q↓` (bit for bit, as
/// [`crate::optics::modes`] builds them) shares one exponential.
#[inline]
pub(crate) fn phase_factors<T: Real>(
    thickness_nm: T,
    lambda_nm: T,
    q: &[Cx<T>; 4],
) -> ([Cx<T>; 2], [Cx<T>; 2]) {
    let kd = thickness_nm * std::f64::consts::TAU / lambda_nm;
    // exp(i q sign kd) = exp((−Im q, Re q) · sign kd).
    let p = |k: usize, sign: f64| {
        let f = kd * sign;
        cx::exp(Cx::new(-q[k].im * f, q[k].re * f))
    };
    let (down_o, down_e, up_e) = (p(0, -1.0), p(1, -1.0), p(3, 1.0));
    let up_o = if q[2] == -q[0] { down_o } else { p(2, 1.0) };
    ([down_o, down_e], [up_o, up_e])
}

/// `m⁻¹` by the adjugate with one division; the resonance error where the determinant is
/// exactly zero (the criterion of `nalgebra`'s `try_inverse`, which this replaces on the hot
/// path; while recording such lanes fail).
#[inline]
pub(crate) fn inverse<T: Real>(m: &Matrix2<Cx<T>>) -> Result<Matrix2<Cx<T>>> {
    let det = m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)];
    let zero = T::zero();
    let singular = det.re.equals(zero) & det.im.equals(zero);
    singular.fail(|| {
        Error::new(
            "slab",
            "internal resonance: the multiple-reflection sum diverges",
        )
    })?;
    let r = cx::inv(singular.when(|| cx::real(T::one()), || det));
    Ok(Matrix2::new(
        m[(1, 1)] * r,
        -m[(0, 1)] * r,
        -m[(1, 0)] * r,
        m[(0, 0)] * r,
    ))
}

/// `diag(a) m`.
#[inline]
fn scale_rows<T: Real>(a: &[Cx<T>; 2], m: &Matrix2<Cx<T>>) -> Matrix2<Cx<T>> {
    Matrix2::new(
        a[0] * m[(0, 0)],
        a[0] * m[(0, 1)],
        a[1] * m[(1, 0)],
        a[1] * m[(1, 1)],
    )
}

/// `diag(a) m diag(b)`.
#[inline]
pub(crate) fn scale<T: Real>(a: &[Cx<T>; 2], m: &Matrix2<Cx<T>>, b: &[Cx<T>; 2]) -> Matrix2<Cx<T>> {
    Matrix2::new(
        a[0] * m[(0, 0)] * b[0],
        a[0] * m[(0, 1)] * b[1],
        a[1] * m[(1, 0)] * b[0],
        a[1] * m[(1, 1)] * b[1],
    )
}

/// The slab's amplitudes that do not depend on the wavelength at fixed indices: the interface
/// blocks (1: top from above, 3: top from below, 2: bottom from above), the layer's normal
/// components and the transmission flux factor. With the wavelength they give the plate
/// (module docs); across a spectrum they can be interpolated (they vary only with the indices).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlabBlocks<T: Real = f64> {
    /// Top interface, reflection from above.
    pub r1: Matrix2<Cx<T>>,
    /// Top interface, transmission from above.
    pub t1: Matrix2<Cx<T>>,
    /// Top interface, reflection from below.
    pub r3: Matrix2<Cx<T>>,
    /// Top interface, transmission from below.
    pub t3: Matrix2<Cx<T>>,
    /// Bottom interface, reflection from above.
    pub r2: Matrix2<Cx<T>>,
    /// Bottom interface, transmission from above.
    pub t2: Matrix2<Cx<T>>,
    /// Layer normal components `[o↓, e↓, o↑, e↑]`.
    pub q: [Cx<T>; 4],
    /// Transmission flux factor `P_bottom / P_top`.
    pub flux: T,
    /// Thickness (nm).
    pub thickness_nm: T,
}

/// Number of complex values in [`SlabBlocks::values`].
pub const BLOCK_VALUES: usize = 29;

impl<T: Real> SlabBlocks<T> {
    /// The Jones matrices at `lambda_nm` ([`SlabOptics::jones`]).
    pub fn jones(&self, lambda_nm: T, want: Want) -> Result<SlabJones<T>> {
        let (pd, pu) = phase_factors(self.thickness_nm, lambda_nm, &self.q);
        // P↑ r₂ P↓, shared by the round trip D and the reflected paths.
        let trip = scale(&pu, &self.r2, &pd);
        let d = cmath::mul2(&self.r3, &trip);
        let (one, zero) = (cx::real(T::one()), cx::real(T::zero()));
        let inverse = inverse(&(Matrix2::new(one, zero, zero, one) - d))?;
        let inner = cmath::mul2(&inverse, &self.t1);
        let r = want
            .reflection
            .then(|| self.r1 + cmath::mul2(&self.t3, &cmath::mul2(&trip, &inner)));
        let t = want.transmission.then(|| {
            let f = self.flux.sqrt();
            cmath::mul2(&self.t2, &scale_rows(&[pd[0] * f, pd[1] * f], &inner))
        });
        Ok(SlabJones { r, t })
    }

    /// The Mueller matrices at `lambda_nm` ([`SlabOptics::mueller`]).
    pub fn mueller(&self, lambda_nm: T, want: Want) -> Result<SlabMueller<T>> {
        let j = self.jones(lambda_nm, want)?;
        Ok(SlabMueller {
            r: j.r.as_ref().map(mueller::from_jones),
            t: j.t.as_ref().map(mueller::from_jones),
        })
    }

    /// The diagonals of the propagation matrices `(P↓, P↑)` at `lambda_nm` (attenuation
    /// included for complex `q`).
    pub fn propagation(&self, lambda_nm: T) -> ([Cx<T>; 2], [Cx<T>; 2]) {
        phase_factors(self.thickness_nm, lambda_nm, &self.q)
    }
}

impl SlabBlocks {
    /// All values as one array (blocks row by row, then `q`, then the flux).
    pub fn values(&self) -> [C64; BLOCK_VALUES] {
        let mut v = [C64::new(0.0, 0.0); BLOCK_VALUES];
        let blocks = [self.r1, self.t1, self.r3, self.t3, self.r2, self.t2];
        for (b, m) in blocks.iter().enumerate() {
            for k in 0..4 {
                v[4 * b + k] = m[(k / 2, k % 2)];
            }
        }
        v[24..28].copy_from_slice(&self.q);
        v[28] = C64::new(self.flux, 0.0);
        v
    }

    /// Value `e` of [`SlabBlocks::values`], without building the array.
    #[inline]
    pub fn value(&self, e: usize) -> C64 {
        let block = |m: &Matrix2<C64>, k: usize| m[(k / 2, k % 2)];
        match e {
            0..=3 => block(&self.r1, e),
            4..=7 => block(&self.t1, e - 4),
            8..=11 => block(&self.r3, e - 8),
            12..=15 => block(&self.t3, e - 12),
            16..=19 => block(&self.r2, e - 16),
            20..=23 => block(&self.t2, e - 20),
            24..=27 => self.q[e - 24],
            _ => C64::new(self.flux, 0.0),
        }
    }

    /// The inverse of [`SlabBlocks::values`].
    pub fn from_values(v: &[C64; BLOCK_VALUES], thickness_nm: f64) -> Self {
        let m = |b: usize| Matrix2::new(v[4 * b], v[4 * b + 1], v[4 * b + 2], v[4 * b + 3]);
        SlabBlocks {
            r1: m(0),
            t1: m(1),
            r3: m(2),
            t3: m(3),
            r2: m(4),
            t2: m(5),
            q: [v[24], v[25], v[26], v[27]],
            flux: v[28].re,
            thickness_nm,
        }
    }
}

/// What one band integration returns: Mueller matrices, or only their `M00` when no
/// polarisation is asked for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Output {
    /// Full Mueller matrices.
    Mueller,
    /// Intensity only (`M00`, stored in entry (0,0)).
    Intensity,
}

impl Output {
    /// `m` as this output asks: unchanged, or only `M00` (the other entries zero).
    pub fn keep<T: Real>(self, m: SlabMueller<T>) -> SlabMueller<T> {
        let cut = |m: Matrix4<T>| match self {
            Output::Mueller => m,
            Output::Intensity => {
                Matrix4::from_fn(|i, j| if i + j == 0 { m[(0, 0)] } else { T::zero() })
            }
        };
        SlabMueller {
            r: m.r.map(cut),
            t: m.t.map(cut),
        }
    }
}
