//! One planar interface between two homogeneous (isotropic or uniaxial) media: the 4x4
//! boundary system (eqs. S17-S18) solved once for waves arriving from either side, and the
//! power ratios (eq. S19).
//!
//! The upper medium fills `z > 0`, the lower one `z < 0` (working frame of [`crate::optics::modes`]).
//! Tangential `E` and `H` are continuous across `z = 0`; writing every field as a sum of modes,
//! `Ψ₁↓ a + Ψ₁↑ b = Ψ₂↓ c + Ψ₂↑ d` with the known incoming amplitudes `a` (from above) and `d`
//! (from below). Solving `[Ψ₁↑ −Ψ₂↓] [b; c] = [−Ψ₁↓ Ψ₂↑] [a; d]` gives the full scattering
//! matrix `S` of the interface: `[b; c] = S [a; d]`. This one solve ([`Interface::from_modes`])
//! covers iso→aniso, aniso→iso and aniso→aniso interfaces alike; when one side is isotropic,
//! [`Interface::solve`] reduces it to a 2x2 solve ([`crate::optics::admittance`]) with the same `S`.

use crate::cmath::{self, singular};
use crate::error::Result;
use crate::optics::admittance;
use crate::optics::fresnel::Fresnel;
use crate::optics::medium::Uniaxial;
use crate::optics::modes::{modes, Mode, ModeKind, ModeSet};
use crate::real::complex::{self as cx, Cx};
use crate::real::{all_finite, Mask, Real};
use nalgebra::{Matrix2, Matrix4};

/// The solved interface for one incidence parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interface<T: Real = f64> {
    /// Modes of the upper medium.
    pub upper: ModeSet<T>,
    /// Modes of the lower medium.
    pub lower: ModeSet<T>,
    /// Scattering matrix: rows `[up₁ (2); down₂ (2)]`, columns `[down₁ (2); up₂ (2)]`.
    pub s: Matrix4<Cx<T>>,
}

/// Writes `sign ×` the tangential fields of two modes into columns `offset`, `offset + 1`.
fn put<T: Real>(m: &mut Matrix4<Cx<T>>, offset: usize, pair: &[Mode<T>; 2], sign: f64) {
    for (j, mode) in pair.iter().enumerate() {
        for (i, f) in mode.tangential().iter().enumerate() {
            m[(i, offset + j)] = *f * T::cst(sign);
        }
    }
}

impl<T: Real> Interface<T> {
    /// Solves the interface between `upper` and `lower` (axes in the working frame) for the
    /// incidence parameter `beta`.
    /// Two isotropic media take the closed-form Fresnel amplitudes ([`Fresnel`]; the same
    /// matrix as the 4x4 solve, which `tests/interface_physics.rs` checks).
    #[inline]
    pub fn new(upper: &Uniaxial<T>, lower: &Uniaxial<T>, beta: Cx<T>) -> Result<Self> {
        if (upper.is_isotropic() & lower.is_isotropic()).surely() {
            let (m1, m2) = (modes(upper, beta), modes(lower, beta));
            let f = Fresnel::amplitudes(upper.eta_o, lower.eta_o, beta)?;
            return Ok(Self::isotropic(m1, m2, &f));
        }
        // Solved in place: an `Interface` is large, moving it costs.
        let mut out = Self::unsolved(modes(upper, beta), modes(lower, beta));
        out.solve_in_place()?;
        Ok(out)
    }

    /// Solves the boundary system for mode sets as [`modes`] gives them: by the admittance
    /// reduction ([`crate::optics::admittance`], one 2x2 solve) when either side has s/p modes (an
    /// isotropic medium), else by the general 4x4 solve ([`Interface::from_modes`]). The same
    /// scattering matrix either way, to rounding (`tests/interface_fast_path.rs`).
    #[inline]
    pub fn solve(upper: ModeSet<T>, lower: ModeSet<T>) -> Result<Self> {
        let mut out = Self::unsolved(upper, lower);
        out.solve_in_place()?;
        Ok(out)
    }

    /// The two mode sets with `S = 0`, for [`Interface::solve_in_place`].
    #[inline]
    pub(crate) fn unsolved(upper: ModeSet<T>, lower: ModeSet<T>) -> Self {
        Interface {
            upper,
            lower,
            s: Matrix4::from_element(cx::real(T::zero())),
        }
    }

    /// Sets `S` from the mode sets ([`Interface::solve`] without moving `self`).
    #[inline]
    pub(crate) fn solve_in_place(&mut self) -> Result<()> {
        let (upper, lower) = (&self.upper, &self.lower);
        let iso_above = is_sp(upper);
        let solution = if iso_above {
            // Its incoming waves go down, the other medium's go up.
            let (iso_in, iso_out) = (tangential(&upper.down), tangential(&upper.up));
            let (other_in, other_out) = (tangential(&lower.up), tangential(&lower.down));
            admittance::solve(&iso_in, &iso_out, &other_in, &other_out)
        } else if is_sp(lower) {
            // Its incoming waves go up, the other medium's go down.
            let (iso_in, iso_out) = (tangential(&lower.up), tangential(&lower.down));
            let (other_in, other_out) = (tangential(&upper.down), tangential(&upper.up));
            admittance::solve(&iso_in, &iso_out, &other_in, &other_out)
        } else {
            self.s = from_modes_s(upper, lower)?;
            return Ok(());
        };
        place(&mut self.s, &solution?, iso_above)
    }

    /// The interface of two isotropic media from its Fresnel amplitudes: every block of `S`
    /// is diagonal in the s/p bases.
    fn isotropic(upper: ModeSet<T>, lower: ModeSet<T>, f: &Fresnel<T>) -> Self {
        let mut s = Matrix4::from_element(cx::real(T::zero()));
        for k in 0..2 {
            s[(k, k)] = f.r_above[k];
            s[(2 + k, k)] = f.t_above[k];
            s[(k, 2 + k)] = f.t_below[k];
            s[(2 + k, 2 + k)] = f.r_below[k];
        }
        Interface { upper, lower, s }
    }

    /// Solves the boundary system for given mode sets (eq. S18).
    pub fn from_modes(upper: ModeSet<T>, lower: ModeSet<T>) -> Result<Self> {
        let s = from_modes_s(&upper, &lower)?;
        Ok(Interface { upper, lower, s })
    }

    /// Reflection of waves arriving from above: `up₁ ← down₁` (rows/cols in mode order).
    pub fn r_above(&self) -> Matrix2<Cx<T>> {
        self.s.fixed_view::<2, 2>(0, 0).into_owned()
    }

    /// Transmission of waves arriving from above: `down₂ ← down₁`.
    pub fn t_above(&self) -> Matrix2<Cx<T>> {
        self.s.fixed_view::<2, 2>(2, 0).into_owned()
    }

    /// Transmission of waves arriving from below: `up₁ ← up₂`.
    pub fn t_below(&self) -> Matrix2<Cx<T>> {
        self.s.fixed_view::<2, 2>(0, 2).into_owned()
    }

    /// Reflection of waves arriving from below: `down₂ ← up₂`.
    pub fn r_below(&self) -> Matrix2<Cx<T>> {
        self.s.fixed_view::<2, 2>(2, 2).into_owned()
    }

    /// Power ratios (eq. S19) of the whole scattering matrix: entry `(i, j)` is the flux
    /// carried by outgoing wave `i` per unit flux of incoming wave `j`, each wave's own normal
    /// Poynting flux (`|S_ij|² |P_i| / |P_j|`). Evanescent waves in lossless media carry none.
    /// Columns of incoming waves that carry no flux are zero.
    pub fn power(&self) -> Matrix4<T> {
        let out = self.outgoing_flux();
        let inc = self.incoming_flux();
        let zero = T::zero();
        Matrix4::from_fn(|i, j| {
            let carries = inc[j].gt(zero);
            let safe = carries.when(|| inc[j], T::one);
            carries.when(|| cx::norm_sqr(self.s[(i, j)]) * out[i] / safe, || zero)
        })
    }

    /// `|P|` of the outgoing waves `[up₁, down₂]` (0 for an evanescent wave).
    pub fn outgoing_flux(&self) -> [T; 4] {
        let (u, d) = (&self.upper.up, &self.lower.down);
        [&u[0], &u[1], &d[0], &d[1]].map(carried)
    }

    /// `|P|` of the incoming waves `[down₁, up₂]` (0 for an evanescent wave: its flux is
    /// rounding noise, and dividing by it would give meaningless power ratios).
    pub fn incoming_flux(&self) -> [T; 4] {
        let (d, u) = (&self.upper.down, &self.lower.up);
        [&d[0], &d[1], &u[0], &u[1]].map(carried)
    }
}

/// `S` by the general 4x4 solve of [`Interface::from_modes`].
fn from_modes_s<T: Real>(upper: &ModeSet<T>, lower: &ModeSet<T>) -> Result<Matrix4<Cx<T>>> {
    let zero = Matrix4::from_element(cx::real(T::zero()));
    let (mut lhs, mut rhs) = (zero, zero);
    put(&mut lhs, 0, &upper.up, 1.0);
    put(&mut lhs, 2, &lower.down, -1.0);
    put(&mut rhs, 0, &upper.down, -1.0);
    put(&mut rhs, 2, &lower.up, 1.0);
    let real_system = lhs
        .iter()
        .chain(rhs.iter())
        .fold(T::Mask::cst(true), |m, z| m & z.im.equals(T::zero()));
    let s = if real_system.surely() {
        let x = cmath::eliminate4(&lhs.map(|z| z.re), &[rhs.map(|z| z.re)])?;
        x[0].map(cx::real)
    } else {
        cmath::eliminate4(&lhs, &[rhs])?[0]
    };
    let finite = all_finite(s.iter());
    (!finite).fail(singular)?;
    Ok(s)
}

/// True for the s/p pair of an isotropic medium ([`crate::optics::modes::isotropic_modes`]): the s
/// mode has only `(E_y, H_x)`, the p mode only `(E_x, H_y)`, which the admittance reduction needs.
fn is_sp<T: Real>(m: &ModeSet<T>) -> bool {
    let sp = |p: &[Mode<T>; 2]| p[0].kind == ModeKind::S && p[1].kind == ModeKind::P;
    sp(&m.down) && sp(&m.up)
}

/// The tangential fields `ψ` of a pair of modes.
#[inline]
fn tangential<T: Real>(pair: &[Mode<T>; 2]) -> [[Cx<T>; 4]; 2] {
    [pair[0].tangential(), pair[1].tangential()]
}

/// Writes the admittance solution into `S` (rows `[up₁; down₂]`, columns `[down₁; up₂]`): as
/// it comes for an isotropic upper medium (its outgoing/incoming waves first), with the
/// isotropic and the other medium's blocks swapped in rows and columns for an isotropic lower
/// one. The singular error if any entry is not finite (as [`Interface::from_modes`]).
#[inline]
fn place<T: Real>(
    s: &mut Matrix4<Cx<T>>,
    r: &admittance::Solution<Cx<T>>,
    iso_above: bool,
) -> Result<()> {
    let finite = all_finite(r.x.iter().chain(&r.y).flatten());
    (!finite).fail(singular)?;
    let (first, second, shift) = if iso_above {
        (&r.x, &r.y, 0)
    } else {
        (&r.y, &r.x, 2)
    };
    for i in 0..2 {
        for j in 0..4 {
            s[(i, (j + shift) & 3)] = first[i][j];
            s[(i + 2, (j + shift) & 3)] = second[i][j];
        }
    }
    Ok(())
}

/// The power a mode carries through the surface: `|P|`, or 0 if it is evanescent.
fn carried<T: Real>(m: &Mode<T>) -> T {
    m.is_evanescent().when(T::zero, || m.flux().abs())
}
