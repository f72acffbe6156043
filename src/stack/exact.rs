//! The stack at one wavelength, exact: every internal path of every layer summed by a
//! scattering-matrix (Redheffer star product) recursion over the interfaces (docs/physics.md §8).
//!
//! The interfaces are numbered from the exterior down: interface `j` lies on top of layer `j`
//! (interface `N` between the last layer and the exit medium). Each is solved once for waves
//! from either side ([`Interface`]: the admittance reduction next to an isotropic medium, the
//! general 4x4 boundary system between two uniaxial layers), giving its blocks `r↓, t↓` (waves
//! arriving from above) and `r↑, t↑` (from below), in the modes of the media it joins. Light
//! from the exterior sees, below the top of layer `j`, a reflection `Γ_j` and a transmission
//! `τ_j` (to the exit medium) of the part of the stack beneath, which follow from the bottom up:
//!
//! ```text
//! Γ_N = r↓_N,  τ_N = t↓_N                                   (the exit interface)
//! Γ' = P↑ Γ P↓,  τ' = τ P↓                                  (referred to the top of layer j)
//! Γ_{j} = r↓_j + t↑_j Γ' (I − r↑_j Γ')⁻¹ t↓_j,   τ_{j} = τ' (I − r↑_j Γ')⁻¹ t↓_j
//! ```
//! with the propagation matrices `P↓ = diag(exp(−i k0 q↓ d))`, `P↑ = diag(exp(i k0 q↑ d))` of
//! layer `j` (their moduli are at most 1: only decaying exponentials occur, so thick,
//! absorbing and evanescent layers stay exact). `(I − r↑ Γ')⁻¹` sums every round trip between
//! the interface and everything below it. For one layer this is the slab of
//! [`crate::plate::slab`], operation for operation. The reflection is `Γ_0`, the transmission
//! `√(P_exit/P_ext) τ_0` (flux-normalised, eq. S19).

use crate::cmath;
use crate::error::{Error, Result};
use crate::optics::frame::PlaneFrame;
use crate::optics::interface::Interface;
use crate::optics::modes::{isotropic_modes, modes, normal_components, Mode, ModeSet};
use crate::optics::mueller;
use crate::plate::slab::{inverse, phase_factors, scale, SlabJones, SlabMueller, Want};
use crate::real::complex::{self as cx, Cx};
use crate::real::{Mask, Real};
use crate::stack::{in_layer, Stack};
use nalgebra::Matrix2;
use num_complex::Complex64 as C64;

/// The four blocks of one interface: `[r↓, t↓, r↑, t↑]` (reflection and transmission of waves
/// arriving from above, then from below), in the modes of the media it joins.
pub type InterfaceBlocks<T = f64> = [Matrix2<Cx<T>>; 4];

/// Index of each block in [`InterfaceBlocks`].
pub const R_DOWN: usize = 0;
/// See [`R_DOWN`].
pub const T_DOWN: usize = 1;
/// See [`R_DOWN`].
pub const R_UP: usize = 2;
/// See [`R_DOWN`].
pub const T_UP: usize = 3;

/// Complex values per interface in [`StackBlocks::values`].
pub const INTERFACE_VALUES: usize = 16;

/// Everything the stack's Jones matrices need besides the wavelength: the interface blocks,
/// the layers' normal components and thicknesses, and the transmission flux factor, over the
/// reals `T` (`f64` on the host). The blocks depend on the wavelength only through the indices.
#[derive(Clone, Debug, PartialEq)]
pub struct StackBlocks<T: Real = f64> {
    /// Interface `j` on top of layer `j` (`N + 1` of them).
    pub interfaces: Vec<InterfaceBlocks<T>>,
    /// Layer normal components `[o↓, e↓, o↑, e↑]` (`[s, p, s, p]` if isotropic).
    pub q: Vec<[Cx<T>; 4]>,
    /// Layer thicknesses (nm).
    pub thickness_nm: Vec<T>,
    /// Transmission flux factor `P_exit / P_ext` (0 if the exit wave is evanescent).
    pub flux: T,
}

/// Every interface of `stack` at `lambda_nm`, solved for incidence parameter `beta` in the plane
/// of `frame` (from the exterior down).
pub fn interfaces(
    stack: &Stack,
    lambda_nm: f64,
    frame: &PlaneFrame,
    beta: C64,
) -> Result<Vec<Interface>> {
    let media = stack.media(lambda_nm, frame)?;
    let mut above = modes(&media[0], beta);
    let mut out = Vec::with_capacity(media.len() - 1);
    for m in &media[1..] {
        let below = modes(m, beta);
        out.push(Interface::solve(above, below)?);
        above = below;
    }
    Ok(out)
}

/// The layers' normal components `[o↓, e↓, o↑, e↑]` at `lambda_nm` ([`normal_components`]: the
/// same roots and branches as the modes of [`interfaces`], without the fields).
pub fn layer_q(
    stack: &Stack,
    lambda_nm: f64,
    frame: &PlaneFrame,
    beta: C64,
) -> Result<Vec<[C64; 4]>> {
    let mut q = vec![[C64::new(0.0, 0.0); 4]; stack.layers.len()];
    layer_q_into(stack, lambda_nm, frame, beta, &mut q)?;
    Ok(q)
}

/// [`layer_q`] into `q` (one entry per layer).
pub fn layer_q_into(
    stack: &Stack,
    lambda_nm: f64,
    frame: &PlaneFrame,
    beta: C64,
    q: &mut [[C64; 4]],
) -> Result<()> {
    for (j, (l, qj)) in stack.layers.iter().zip(q.iter_mut()).enumerate() {
        *qj = normal_components(
            &l.medium(lambda_nm, frame).map_err(|e| in_layer(j, e))?,
            beta,
        );
    }
    Ok(())
}

impl<T: Real> StackBlocks<T> {
    /// The stack at `lambda_nm` for incidence parameter `beta` in the plane of `frame`
    /// ([`StackBlocks::solve`] with each layer's modes).
    pub fn new(stack: &Stack<T>, lambda_nm: T, frame: &PlaneFrame<T>, beta: Cx<T>) -> Result<Self> {
        let layers = &stack.layers;
        StackBlocks::solve(
            stack.ext,
            stack.exit,
            layers.iter().map(|l| l.thickness_nm).collect(),
            beta,
            |j| {
                let medium = layers[j].medium(lambda_nm, frame);
                Ok(modes(&medium.map_err(|e| in_layer(j, e))?, beta))
            },
        )
    }

    /// The stack between the isotropic exterior `ext` and exit medium `exit` whose layer `j`
    /// (from the exterior down) is `thickness_nm[j]` thick and has the modes `layer(j)` for
    /// incidence parameter `beta`: each interface solved where it lies (an [`Interface`] is
    /// large: moving it costs about as much as solving it) and reduced to its blocks.
    pub fn solve(
        ext: Cx<T>,
        exit: Cx<T>,
        thickness_nm: Vec<T>,
        beta: Cx<T>,
        mut layer: impl FnMut(usize) -> Result<ModeSet<T>>,
    ) -> Result<Self> {
        let n = thickness_nm.len();
        let mut out = StackBlocks {
            interfaces: Vec::with_capacity(n + 1),
            q: Vec::with_capacity(n),
            thickness_nm,
            flux: T::zero(),
        };
        let top = isotropic_modes(ext, beta);
        let mut iface = Interface::unsolved(top, top);
        for j in 0..=n {
            let below = if j < n {
                layer(j)?
            } else {
                isotropic_modes(exit, beta)
            };
            iface.upper = iface.lower;
            iface.lower = below;
            if j == 0 {
                iface.upper = top;
            }
            iface.solve_in_place()?;
            out.interfaces.push(blocks_of(&iface));
            if j < n {
                let m = &iface.lower;
                out.q.push([m.down[0].q, m.down[1].q, m.up[0].q, m.up[1].q]);
            }
        }
        out.flux = flux_ratio(&top.down[0], &iface.lower.down[0]);
        Ok(out)
    }

    /// Number of layers.
    pub fn layers(&self) -> usize {
        self.q.len()
    }

    /// The coherent, flux-normalised Jones matrices at `lambda_nm` (module docs), in the s/p
    /// bases of the exterior (reflection) and of the exit medium (transmission). Fails only at
    /// an exact internal resonance (a guided mode, which light from outside cannot excite in
    /// a passive stack; while recording, such lanes fail).
    pub fn jones(&self, lambda_nm: T, want: Want) -> Result<SlabJones<T>> {
        let n = self.layers();
        let last = &self.interfaces[n];
        let (mut gamma, mut tau) = (last[R_DOWN], last[T_DOWN]);
        let (one, zero) = (cx::real(T::one()), cx::real(T::zero()));
        let identity = Matrix2::new(one, zero, zero, one);
        for j in (0..n).rev() {
            let (pd, pu) = phase_factors(self.thickness_nm[j], lambda_nm, &self.q[j]);
            let g = scale(&pu, &gamma, &pd);
            let iface = &self.interfaces[j];
            let x =
                inverse(&(identity - cmath::mul2(&iface[R_UP], &g))).map_err(|_| resonance())?;
            let y = cmath::mul2(&x, &iface[T_DOWN]);
            // τ P↓ (I − r↑ Γ')⁻¹ t↓, associated as the slab does (τ (P↓ y)).
            tau = cmath::mul2(&tau, &scale(&pd, &y, &[one; 2]));
            // Γ of the layers below is needed further up even when only T is wanted.
            if j > 0 || want.reflection {
                gamma = iface[R_DOWN] + cmath::mul2(&iface[T_UP], &cmath::mul2(&g, &y));
            }
        }
        let f = Cx::new(self.flux.sqrt(), T::zero());
        Ok(SlabJones {
            r: want.reflection.then_some(gamma),
            t: want.transmission.then(|| tau.map(|z| z * f)),
        })
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

impl StackBlocks {
    /// The blocks of solved `interfaces` (as [`interfaces`] gives them) of `stack`.
    pub fn from_interfaces(stack: &Stack, interfaces: &[Interface]) -> Self {
        let layers = stack.layers.len();
        let q = (0..layers)
            .map(|j| {
                let m = &interfaces[j].lower;
                [m.down[0].q, m.down[1].q, m.up[0].q, m.up[1].q]
            })
            .collect();
        StackBlocks {
            interfaces: interfaces.iter().map(blocks_of).collect(),
            q,
            thickness_nm: stack.layers.iter().map(|l| l.thickness_nm).collect(),
            flux: flux_ratio(
                &interfaces[0].upper.down[0],
                &interfaces[layers].lower.down[0],
            ),
        }
    }

    /// The interface blocks and the flux factor as one array ([`INTERFACE_VALUES`] per
    /// interface, row by row, then the flux): what varies slowly across a spectrum.
    pub fn values(&self) -> Vec<C64> {
        let mut v = Vec::with_capacity(self.interfaces.len() * INTERFACE_VALUES + 1);
        for blocks in &self.interfaces {
            for m in blocks {
                v.extend([m[(0, 0)], m[(0, 1)], m[(1, 0)], m[(1, 1)]]);
            }
        }
        v.push(C64::new(self.flux, 0.0));
        v
    }

    /// Sets the interface blocks and the flux from `v` ([`StackBlocks::values`]' layout).
    pub fn set_values(&mut self, v: &[C64]) {
        for (j, blocks) in self.interfaces.iter_mut().enumerate() {
            let o = j * INTERFACE_VALUES;
            for (b, m) in blocks.iter_mut().enumerate() {
                let i = o + 4 * b;
                *m = Matrix2::new(v[i], v[i + 1], v[i + 2], v[i + 3]);
            }
        }
        self.flux = v[v.len() - 1].re;
    }
}

/// `[r↓, t↓, r↑, t↑]` of a solved interface.
fn blocks_of<T: Real>(i: &Interface<T>) -> InterfaceBlocks<T> {
    [i.r_above(), i.t_above(), i.r_below(), i.t_below()]
}

/// Flux factor `P_out / P_in` of the transmitted wave (eq. S19; 0 if it is evanescent). The
/// division is by 1 in the lanes that discard it (their derivatives stay finite).
fn flux_ratio<T: Real>(incident: &Mode<T>, transmitted: &Mode<T>) -> T {
    let p_in = incident.flux.abs();
    let carries = p_in.gt(T::zero()) & !transmitted.is_evanescent();
    carries.when(
        || transmitted.flux.abs() / carries.when(|| p_in, T::one),
        T::zero,
    )
}

/// The error of a diverging multiple-reflection sum.
pub(crate) fn resonance() -> Error {
    Error::new(
        "stack",
        "internal resonance: the multiple-reflection sum diverges",
    )
}
