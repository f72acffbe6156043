//! What a plate at one incidence looks like before any method is chosen, across the visible band
//! ([`Survey`]: its interface blocks at the amplitude nodes, [`Amplitudes`], and the invariants
//! read off them: the traversals' group paths and attenuation rates, the least attenuation, the
//! round trip's reflectance) or around the centre of one Gaussian of a band ([`BandSurvey`]).
//! [`crate::spectral::route`] decides from these alone; every method then starts from the same
//! solved blocks, and nothing is solved again to decide.

use crate::band::Gaussian;
use crate::cmath::spectral_norm;
use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::plate::slab::SlabOptics;
use crate::plate::Plate;
use crate::quadrature::budget::ATTENUATED;
use crate::quadrature::fringe;
use crate::quadrature::nodes::{self, SPAN};
use crate::spectral::amplitudes::{least_attenuation, Amplitudes};
use crate::spectral::group::{dispersion, group_round_trips, Dispersion};
use crate::spectral::narrow::{self, Narrow};
use nalgebra::Matrix2;
use num_complex::Complex64 as C64;
use std::f64::consts::TAU;

/// A plate at one incidence, surveyed across the band.
pub struct Survey<'a> {
    /// The plate.
    pub plate: &'a Plate,
    /// Its plane of incidence.
    pub frame: PlaneFrame,
    /// The incidence parameter.
    pub beta: C64,
    /// The interface blocks at the amplitude nodes.
    pub amplitudes: Amplitudes,
    /// Per traversal `[o↓, e↓, o↑, e↑]` at the band's centre: `d · d(k Q)/dk` (nm), the real
    /// part the group path of one traversal, the imaginary part the rate of its attenuation
    /// exponent.
    pub group_path: [C64; 4],
    /// The traversals' group paths (real parts) at [`SPAN`] of the band (dispersion moves them
    /// across it).
    pub group_paths: [[f64; 4]; SPAN.len()],
    /// The least attenuation exponent per traversal over the band; `None` where a clear
    /// layer's wave turns evanescent inside the band
    /// ([`crate::spectral::amplitudes::least_attenuation`]).
    pub loss: Option<[f64; 4]>,
    /// The decay per internal round trip `D = r₃ P↑ r₂ P↓` over the band: the largest
    /// `‖D⁸‖^{1/8}` at the amplitude nodes (spectral norms; with [`Survey::transient`], the norm
    /// of the `n`-th round trip is at most `C ρⁿ`). The flux-normalised blocks of a tilted
    /// crystal are not unitary in this basis: near grazing incidence `‖r₃‖ ‖r₂‖`, even `‖D‖`,
    /// can exceed 1 (calcite 90 µm at 89.5°: 1.049) while the round trips decay (`‖D⁸‖^{1/8}`
    /// 0.97), so one round trip's norm would not bound the orders.
    pub rho: f64,
    /// `C = max_{k ≤ 8} ‖Dᵏ‖/ρᵏ` over the nodes (at least 1): the transient growth of the first
    /// round trips over the decay `ρ`.
    pub transient: f64,
}

impl<'a> Survey<'a> {
    /// Solves `plate` at the amplitude nodes for incidence `beta` in the plane of `frame`.
    pub fn new(plate: &'a Plate, frame: PlaneFrame, beta: C64) -> Result<Self> {
        let amplitudes = Amplitudes::new(plate, &frame, beta)?;
        let d = plate.thickness_nm;
        let at = amplitudes.group_indices();
        let group_path = at[SPAN.len() / 2].map(|g| g * d);
        let group_paths = at.map(|g| g.map(|x| x.re * d));
        let loss = least_attenuation(plate, &amplitudes);
        let (rho, transient) = round_trip_decay(&amplitudes);
        Ok(Survey {
            plate,
            frame,
            beta,
            amplitudes,
            group_path,
            group_paths,
            loss,
            rho,
            transient,
        })
    }

    /// True for a traversal that carries light somewhere in the band (its least attenuation
    /// below [`ATTENUATED`]).
    pub fn live(&self, traversal: usize) -> bool {
        self.loss.is_none_or(|l| l[traversal] < ATTENUATED)
    }

    /// The smallest and largest of `f(group paths)` over [`SPAN`].
    pub fn group_path_range(&self, f: impl Fn(&[f64; 4]) -> f64) -> (f64, f64) {
        self.group_paths
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            })
    }

    /// The largest change of a live traversal's attenuation exponent across the half band
    /// (`a · d · |d(k Im Q)/dk|`).
    pub fn attenuation_tilt(&self) -> f64 {
        let (_, a) = fringe::band();
        (0..4)
            .filter(|&j| self.live(j))
            .map(|j| a * self.group_path[j].im.abs())
            .fold(0.0, f64::max)
    }
}

/// `(ρ, C)` of [`Survey::rho`] and [`Survey::transient`] from the round trips at the amplitude
/// nodes (`D`, `D²`, … `D⁸` by products) where the crude bound `max ‖r₃‖ ‖r₂‖ max|P↑| max|P↓|`
/// reaches 1; below 1, or where every `D⁸` vanishes, `ρ` is that crude bound and `C = 1`.
fn round_trip_decay(amplitudes: &Amplitudes) -> (f64, f64) {
    let (k0, a) = fringe::band();
    let lv = nodes::level(amplitudes.level);
    // `‖Dᵏ‖`, k = 1..8, at each node (a fixed array: a query allocates nothing).
    let mut powers = [[0.0f64; 8]; nodes::MAX_NODES];
    let mut crude = 0.0f64;
    for ((&j, t), norms) in lv.in_finest.iter().zip(&lv.nodes).zip(powers.iter_mut()) {
        let b = amplitudes.exact(j).expect("an amplitude node");
        let (pd, pu) = b.propagation(TAU / (k0 + a * t));
        let most = |p: [C64; 2]| p[0].norm().max(p[1].norm());
        crude = crude.max(spectral_norm(&b.r3) * spectral_norm(&b.r2) * most(pd) * most(pu));
        let diag = |p: [C64; 2]| Matrix2::new(p[0], C64::new(0.0, 0.0), C64::new(0.0, 0.0), p[1]);
        let d = b.r3 * diag(pu) * b.r2 * diag(pd);
        let mut dk = d;
        for (k, n) in norms.iter_mut().enumerate() {
            if k > 0 {
                dk *= d;
            }
            *n = spectral_norm(&dk);
        }
    }
    // Where the crude bound is below 1 it bounds every power (`‖Dⁿ‖ ≤ ρⁿ`, `C = 1`) and it is
    // what the path classes' order count is calibrated on: the decay alone, smaller for a
    // dichroic plate (0.12-0.21 against the clear mode's 0.33-0.42: indices 2.4 and 2.6 + 0.02i,
    // 5 µm at 60°), kept 2-3 orders and missed the dense quadrature by 1.3e-4
    // (tests/spectral_routes.rs, a_dichroic_plate_keeps_the_clear_modes_round_trips). The decay
    // serves where the crude bound reaches 1 while the round trips still die away (near grazing).
    if crude < 1.0 {
        return (crude, 1.0);
    }
    let powers = &powers[..lv.nodes.len()];
    let rho = powers
        .iter()
        .map(|n| n[7].powf(1.0 / 8.0))
        .fold(0.0, f64::max);
    if rho.is_nan() || rho <= 0.0 {
        return (crude, 1.0);
    }
    let transient = powers
        .iter()
        .flat_map(|n| {
            n.iter()
                .enumerate()
                .map(|(k, x)| x / rho.powi(k as i32 + 1))
        })
        .fold(1.0, f64::max);
    (rho, transient)
}

/// Orders are counted until the round trip's amplitude falls below this ([`BandSurvey::orders`]).
pub const ORDER_TOLERANCE: f64 = 1e-5;
/// Most round trips [`BandSurvey::orders`] counts.
pub const MAX_ORDERS: usize = 2000;

/// A plate at one incidence around the centre `μ` of one unit-mass Gaussian of a band: what
/// [`crate::spectral::route::gaussian`] decides from and the band's methods
/// ([`crate::spectral::gaussian`]) start from.
pub struct BandSurvey<'a> {
    /// The plate.
    pub plate: &'a Plate,
    /// Its plane of incidence.
    pub frame: PlaneFrame,
    /// The incidence parameter.
    pub beta: C64,
    /// The Gaussian.
    pub g: Gaussian,
    /// The plate solved at the centre (for every Gaussian, without dispersion).
    pub optics: SlabOptics,
    /// The traversals' phase derivatives at the centre.
    pub dispersion: Dispersion,
    /// The smallest and largest group path per unit thickness of one round trip.
    pub round_trips: (f64, f64),
    /// Round trips until the amplitude falls below [`ORDER_TOLERANCE`] (at most
    /// [`MAX_ORDERS`]).
    pub orders: usize,
    /// The narrow-band closed form, where it serves ([`narrow::plan`]).
    pub narrow: Option<Narrow>,
}

impl<'a> BandSurvey<'a> {
    /// The survey of `plate` over `g`, its interfaces at the centre `optics`.
    pub fn new(
        plate: &'a Plate,
        frame: PlaneFrame,
        beta: C64,
        g: &Gaussian,
        optics: SlabOptics,
    ) -> Result<Self> {
        let dispersion = dispersion(plate, &frame, beta, g.mu)?;
        let traversals = traversals(&optics, &dispersion, g.mu);
        Ok(BandSurvey {
            plate,
            frame,
            beta,
            g: *g,
            round_trips: group_round_trips(&optics, &dispersion, g.mu),
            orders: orders(&optics, TAU / g.mu),
            narrow: narrow::plan(&optics, g, &traversals),
            optics,
            dispersion,
        })
    }
}

/// How each traversal's phase varies around `mu` ([`narrow::Traversal`]), from the modes at
/// the centre and the dispersion derivatives.
fn traversals(optics: &SlabOptics, disp: &Dispersion, mu: f64) -> [narrow::Traversal; 4] {
    let m = optics.layer_modes();
    let q = [-m.down[0].q, -m.down[1].q, m.up[0].q, m.up[1].q];
    std::array::from_fn(|j| narrow::Traversal {
        group: q[j] + mu * disp.d1[j],
        curvature: 2.0 * disp.d1[j] + mu * disp.d2[j],
    })
}

/// Round trips until the internal amplitude `‖r₃ P↑ r₂ P↓‖` (Frobenius, at `lambda`) falls
/// below [`ORDER_TOLERANCE`], at most [`MAX_ORDERS`].
fn orders(optics: &SlabOptics, lambda: f64) -> usize {
    let (pd, pu) = optics.propagation(lambda);
    let rho = (optics.top.r_below() * pu * optics.bottom.r_above() * pd).norm();
    if rho <= 0.0 {
        0
    } else if rho >= 1.0 {
        MAX_ORDERS
    } else {
        ((ORDER_TOLERANCE.ln() / rho.ln()).ceil() as usize)
            .saturating_sub(1)
            .min(MAX_ORDERS)
    }
}
