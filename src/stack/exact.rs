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
use crate::optics::medium::Uniaxial;
use crate::optics::modes::{modes, normal_components, Mode};
use crate::optics::mueller;
use crate::plate::slab::{inverse, phase_factors, scale, SlabJones, SlabMueller, Want};
use crate::stack::{in_layer, Stack};
use nalgebra::Matrix2;
use num_complex::Complex64 as C64;

/// The four blocks of one interface: `[r↓, t↓, r↑, t↑]` (reflection and transmission of waves
/// arriving from above, then from below), in the modes of the media it joins.
pub type InterfaceBlocks = [Matrix2<C64>; 4];

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
/// the layers' normal components and thicknesses, and the transmission flux factor. The blocks
/// depend on the wavelength only through the indices.
#[derive(Clone, Debug, PartialEq)]
pub struct StackBlocks {
    /// Interface `j` on top of layer `j` (`N + 1` of them).
    pub interfaces: Vec<InterfaceBlocks>,
    /// Layer normal components `[o↓, e↓, o↑, e↑]` (`[s, p, s, p]` if isotropic).
    pub q: Vec<[C64; 4]>,
    /// Layer thicknesses (nm).
    pub thickness_nm: Vec<f64>,
    /// Transmission flux factor `P_exit / P_ext` (0 if the exit wave is evanescent).
    pub flux: f64,
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

impl StackBlocks {
    /// The stack at `lambda_nm` for incidence parameter `beta` in the plane of `frame`: each
    /// interface solved where it lies (an [`Interface`] is large: moving it costs about as much
    /// as solving it) and reduced to its blocks.
    pub fn new(stack: &Stack, lambda_nm: f64, frame: &PlaneFrame, beta: C64) -> Result<Self> {
        let n = stack.layers.len();
        let mut out = StackBlocks {
            interfaces: Vec::with_capacity(n + 1),
            q: Vec::with_capacity(n),
            thickness_nm: stack.layers.iter().map(|l| l.thickness_nm).collect(),
            flux: 0.0,
        };
        let top = modes(&Uniaxial::isotropic(stack.ext)?, beta);
        let mut iface = Interface::unsolved(top, top);
        for j in 0..=n {
            let below = match stack.layers.get(j) {
                Some(l) => modes(
                    &l.medium(lambda_nm, frame).map_err(|e| in_layer(j, e))?,
                    beta,
                ),
                None => modes(&Uniaxial::isotropic(stack.exit)?, beta),
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

    /// Number of layers.
    pub fn layers(&self) -> usize {
        self.q.len()
    }

    /// The coherent, flux-normalised Jones matrices at `lambda_nm` (module docs), in the s/p
    /// bases of the exterior (reflection) and of the exit medium (transmission). Fails only at
    /// an exact internal resonance (a guided mode, which light from outside cannot excite in
    /// a passive stack).
    pub fn jones(&self, lambda_nm: f64, want: Want) -> Result<SlabJones> {
        let n = self.layers();
        let last = &self.interfaces[n];
        let (mut gamma, mut tau) = (last[R_DOWN], last[T_DOWN]);
        for j in (0..n).rev() {
            let (pd, pu) = phase_factors(self.thickness_nm[j], lambda_nm, &self.q[j]);
            let g = scale(&pu, &gamma, &pd);
            let iface = &self.interfaces[j];
            let x = inverse(&(Matrix2::identity() - cmath::mul2(&iface[R_UP], &g)))
                .map_err(|_| resonance())?;
            let y = cmath::mul2(&x, &iface[T_DOWN]);
            // τ P↓ (I − r↑ Γ')⁻¹ t↓, associated as the slab does (τ (P↓ y)).
            tau = cmath::mul2(&tau, &scale(&pd, &y, &[C64::new(1.0, 0.0); 2]));
            // Γ of the layers below is needed further up even when only T is wanted.
            if j > 0 || want.reflection {
                gamma = iface[R_DOWN] + cmath::mul2(&iface[T_UP], &cmath::mul2(&g, &y));
            }
        }
        let f = self.flux.sqrt();
        Ok(SlabJones {
            r: want.reflection.then_some(gamma),
            t: want.transmission.then(|| tau * C64::new(f, 0.0)),
        })
    }

    /// Mueller matrices (Mitsuba's convention, s/p frames) of reflection and transmission.
    pub fn mueller(&self, lambda_nm: f64, want: Want) -> Result<SlabMueller> {
        let j = self.jones(lambda_nm, want)?;
        Ok(SlabMueller {
            r: j.r.as_ref().map(mueller::from_jones),
            t: j.t.as_ref().map(mueller::from_jones),
        })
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
fn blocks_of(i: &Interface) -> InterfaceBlocks {
    [i.r_above(), i.t_above(), i.r_below(), i.t_below()]
}

/// Flux factor `P_out / P_in` of the transmitted wave (eq. S19; 0 if it is evanescent).
fn flux_ratio(incident: &Mode, transmitted: &Mode) -> f64 {
    let p_in = incident.flux.abs();
    if p_in > 0.0 && !transmitted.is_evanescent() {
        transmitted.flux.abs() / p_in
    } else {
        0.0
    }
}

/// The error of a diverging multiple-reflection sum.
pub(crate) fn resonance() -> Error {
    Error::new(
        "stack",
        "internal resonance: the multiple-reflection sum diverges",
    )
}
