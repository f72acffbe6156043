//! Closed-form Fresnel amplitudes of a planar interface between an isotropic medium above and a
//! uniaxial one below (the boundary system of eqs. S17-S18 solved by hand), in real or complex
//! arithmetic ([`Scalar`]).
//!
//! Working frame of [`crate::optics::modes`]; tangential fields `ψ = (E_x, E_y, H_x, H_y)`. The
//! isotropic medium (index `η`, normal component `w = sqrt(η² − β²)` of its up-going waves) has
//! the s/p modes of [`crate::optics::modes::isotropic_modes`]: `ψ_s(q) = (0, 1, −q, 0)` and
//! `ψ_p(q) = (−q/η, 0, 0, −η)`, up-going at `q = w`, down-going at `q = −w`. The two linear forms
//!
//! ```text
//! S(ψ) = w E_y + H_x,        P(ψ) = η² E_x − w H_y
//! ```
//! vanish on both up-going (outgoing) isotropic waves, and on the down-going (incoming) ones give
//! `S(ψ_s(−w)) = 2w`, `P(ψ_p(−w)) = 2ηw`, `S(ψ_p) = P(ψ_s) = 0`. Continuity of `ψ` across the
//! surface, with incoming amplitudes `a_s, a_p` above and `d` of one up-going crystal mode
//! `ψ_in` below, reflected isotropic amplitudes `b` and amplitudes `c` of the crystal's two
//! down-going modes `ψ_o`, `ψ_e`,
//!
//! ```text
//! a_s ψ_s(−w) + a_p ψ_p(−w) + b_s ψ_s(w) + b_p ψ_p(w) = c_o ψ_o + c_e ψ_e + d ψ_in,
//! ```
//! becomes under `S` and `P` a 2×2 system for `c` alone, solved by Cramer's rule:
//!
//! ```text
//! M c = (2w a_s − d S(ψ_in), 2ηw a_p − d P(ψ_in)),     M = [[S(ψ_o), S(ψ_e)], [P(ψ_o), P(ψ_e)]],
//! ```
//! and the `E_y` and `H_y` rows give the isotropic side: `b_s = Σ c_j E_y,j + d E_y,in − a_s`,
//! `b_p = −(Σ c_j H_y,j + d H_y,in)/η − a_p`. No coefficient is divided by a small number (`w` → 0
//! at grazing leaves `S = H_x`, `P = η² E_x`). These are the entries of the interface's
//! scattering matrix ([`crate::optics::interface`]) for an isotropic upper medium: columns `s, p`
//! (from above) and `o↑, e↑` (from below). Closed-form coefficients of this interface are also
//! given by J. Lekner, J. Phys.: Condens. Matter 3, 6121 (1991), which the supplemental cites (§2);
//! this derivation is independent and is checked against the general 4×4 solve
//! (`tests/interface_fast_path.rs`).

use crate::cmath::Scalar;
use crate::real::{Mask, Real};
use std::marker::PhantomData;

/// Tangential fields `(E_x, E_y, H_x, H_y)` of a mode.
pub type Psi<T> = [T; 4];

/// The interface for one incidence parameter: the isotropic side and the crystal's down-going
/// modes, with `M⁻¹` by Cramer's rule; in the arithmetic `T` over the reals `R`
/// ([`crate::real`]).
#[derive(Clone, Copy, Debug)]
pub struct UniaxialFresnel<T, R = f64> {
    /// `η` of the isotropic medium.
    eta: T,
    /// `w` of its up-going waves.
    w: T,
    /// `ψ` of the crystal's down-going modes `[o, e]`.
    down: [Psi<T>; 2],
    /// `M = [[S(ψ_o), S(ψ_e)], [P(ψ_o), P(ψ_e)]]`.
    m: [[T; 2]; 2],
    /// `1 / det M`.
    inv_det: T,
    reals: PhantomData<R>,
}

impl<T: Scalar<f64>> UniaxialFresnel<T> {
    /// The interface between an isotropic medium of index `eta` above (its up-going normal
    /// component `w`) and a crystal whose down-going modes have the tangential fields `down`.
    /// `None` if `M` is singular to working precision ([`UniaxialFresnel::solved`]).
    #[inline]
    pub fn new(eta: T, w: T, down: [Psi<T>; 2]) -> Option<Self> {
        let (fresnel, singular) = Self::solved(eta, w, down);
        (!singular).then_some(fresnel)
    }
}

impl<R: Real, T: Scalar<R>> UniaxialFresnel<T, R> {
    /// [`UniaxialFresnel::new`] over the reals `R`: the interface, and where `M` is singular to
    /// working precision (a guided or surface wave; the criterion of
    /// [`crate::cmath::solve4`]: `|det M|` below `1e-150` of the largest product of entries), in
    /// which lanes its amplitudes are those of `det M = 1` (finite, and meaningless).
    #[inline]
    pub fn solved(eta: T, w: T, down: [Psi<T>; 2]) -> (Self, R::Mask) {
        let eps = eta * eta;
        let form = |p: &Psi<T>| (w * p[1] + p[2], eps * p[0] - w * p[3]);
        let ((s_o, p_o), (s_e, p_e)) = (form(&down[0]), form(&down[1]));
        let m = [[s_o, s_e], [p_o, p_e]];
        let det = s_o * p_e - s_e * p_o;
        let scale = m
            .iter()
            .flatten()
            .map(|z| z.norm_sqr())
            .fold(R::zero(), |a, x| a.max(x));
        let n = det.norm_sqr();
        let singular = !n.finite() | n.le(scale * 1e-300 * scale);
        let fresnel = UniaxialFresnel {
            eta,
            w,
            down,
            m,
            inv_det: singular.when(T::one, || det).inverse(),
            reals: PhantomData,
        };
        (fresnel, singular)
    }

    /// Waves arriving from above with unit amplitudes: `(r, t)`, `r[out][in]` with outgoing
    /// `[s, p]` above, `t[out][in]` with outgoing `[o, e]` below, incoming `[s, p]`.
    #[inline]
    pub fn from_above(&self) -> ([[T; 2]; 2], [[T; 2]; 2]) {
        let (m, k) = (&self.m, self.inv_det);
        let two_w = self.w * R::cst(2.0);
        let (s_in, p_in) = (two_w * k, two_w * self.eta * k);
        let t = [
            [m[1][1] * s_in, -(m[0][1] * p_in)],
            [-(m[1][0] * s_in), m[0][0] * p_in],
        ];
        let (o, e) = (&self.down[0], &self.down[1]);
        let minus_inv_eta = -self.eta.inverse();
        let ey = |col: usize| t[0][col] * o[1] + t[1][col] * e[1];
        let hy = |col: usize| (t[0][col] * o[3] + t[1][col] * e[3]) * minus_inv_eta;
        let r = [[ey(0) - T::one(), ey(1)], [hy(0), hy(1) - T::one()]];
        (r, t)
    }

    /// One crystal mode arriving from below with tangential fields `up` (unit amplitude):
    /// `(reflected [o, e], transmitted [s, p])`.
    #[inline]
    pub fn from_below(&self, up: &Psi<T>) -> ([T; 2], [T; 2]) {
        let (m, k) = (&self.m, self.inv_det);
        let eps = self.eta * self.eta;
        let (s_in, p_in) = (self.w * up[1] + up[2], eps * up[0] - self.w * up[3]);
        let c = [
            (m[0][1] * p_in - m[1][1] * s_in) * k,
            (m[1][0] * s_in - m[0][0] * p_in) * k,
        ];
        let (o, e) = (&self.down[0], &self.down[1]);
        let b_s = up[1] + c[0] * o[1] + c[1] * e[1];
        let b_p = -((up[3] + c[0] * o[3] + c[1] * e[3]) * self.eta.inverse());
        (c, [b_s, b_p])
    }
}
