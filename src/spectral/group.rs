//! How the phases of the plate's four layer modes vary across a band: group paths and their
//! dispersion, from which the spectral integration linearises each path's phase (the group
//! delay and its curvature) and sizes its rules.

use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::plate::slab::SlabOptics;
use crate::plate::Plate;
use num_complex::Complex64 as C64;

/// First and second derivatives in `k` of the phase-per-traversal `Q` of the layer's four modes
/// `[o↓, e↓, o↑, e↑]` at wavenumber `mu` (zero without dispersion), by central differences of
/// the exact modes (step `10⁻³ μ`: truncation ~10⁻⁶, rounding ~10⁻¹⁰ relative).
pub fn dispersion(plate: &Plate, frame: &PlaneFrame, beta: C64, mu: f64) -> Result<Dispersion> {
    if !plate.is_dispersive() {
        return Ok(Dispersion::default());
    }
    let h = mu * 1e-3;
    let q = |k: f64| -> Result<[C64; 4]> {
        let q = plate.at(std::f64::consts::TAU / k)?.layer_q(frame, beta);
        Ok([-q[0], -q[1], q[2], q[3]])
    };
    let (a, b, c) = (q(mu + h)?, q(mu)?, q(mu - h)?);
    Ok(Dispersion {
        d1: std::array::from_fn(|i| ((a[i] - c[i]) / (2.0 * h)).re),
        d2: std::array::from_fn(|i| ((a[i] - b[i] * 2.0 + c[i]) / (h * h)).re),
    })
}

/// `dQ/dk` and `d²Q/dk²` per mode (see [`dispersion`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct Dispersion {
    /// `dQ/dk` per traversal.
    pub d1: [f64; 4],
    /// `d²Q/dk²` per traversal.
    pub d2: [f64; 4],
}

/// The smallest and largest group path per unit thickness of one internal round trip,
/// `d(k Re(q↑ − q↓))/dk` over the mode pairs (the phase index without dispersion).
pub fn group_round_trips(optics: &SlabOptics, disp: &Dispersion, mu: f64) -> (f64, f64) {
    let m = optics.layer_modes();
    let trips = (0..2).flat_map(|a| {
        (0..2).map(move |b| (m.up[a].q - m.down[b].q).re + mu * (disp.d1[2 + a] + disp.d1[b]))
    });
    trips.fold((f64::INFINITY, 0.0), |(lo, hi), t| (lo.min(t), hi.max(t)))
}

/// The largest difference of group path per unit thickness between the two modes travelling
/// the same way, `d(k Re(q_o − q_e))/dk` (the direct paths' birefringent oscillation).
pub fn group_splitting(optics: &SlabOptics, disp: &Dispersion, mu: f64) -> f64 {
    let q = optics.layer_q();
    let g = |j: usize| q[j].re + mu * disp.d1[j] * if j < 2 { -1.0 } else { 1.0 };
    (g(0) - g(1)).abs().max((g(2) - g(3)).abs())
}
