//! The reference every spectral method is checked against: the exact plate integrated over a
//! weight per nm by the trapezoid rule on a dense grid of wavelengths (slow; for validation and
//! the calculator's `"method": "quadrature"`).

use crate::error::{Error, Result};
use crate::optics::frame::PlaneFrame;
use crate::plate::slab::{SlabMueller, Want};
use crate::plate::Plate;
use nalgebra::Matrix4;
use num_complex::Complex64 as C64;

/// Most plate evaluations [`quadrature`] accepts.
pub const QUADRATURE_MAX: usize = 10_000_000;

/// Reference: `∫ w(λ) M(λ) dλ` of the exact slab by the trapezoid rule on `[lo, hi]` with
/// `step_nm`, `weight` per nm (normalise it yourself). Slow; for validation.
pub fn quadrature(
    plate: &Plate,
    frame: &PlaneFrame,
    beta: C64,
    weight: impl Fn(f64) -> f64,
    (lo, hi): (f64, f64),
    step_nm: f64,
    want: Want,
) -> Result<SlabMueller> {
    if !(step_nm > 0.0 && step_nm.is_finite()) {
        return Err(Error::new("step_nm", "must be > 0"));
    }
    let count = ((hi - lo) / step_nm).ceil().max(1.0);
    if count.is_nan() || count > QUADRATURE_MAX as f64 {
        return Err(Error::new(
            "step_nm",
            format!(
                "too small: {count:.3e} plate evaluations over [{lo}, {hi}] nm (at most {QUADRATURE_MAX:.0e}; minutes of run time)"
            ),
        ));
    }
    let n = count as usize;
    let h = (hi - lo) / n as f64;
    let fixed = if plate.is_dispersive() {
        None
    } else {
        Some(plate.at(0.5 * (lo + hi))?.optics(frame, beta)?)
    };
    let mut r = Matrix4::zeros();
    let mut t = Matrix4::zeros();
    for j in 0..=n {
        let lambda = lo + h * j as f64;
        let w = weight(lambda) * if j == 0 || j == n { 0.5 * h } else { h };
        if w == 0.0 {
            continue;
        }
        let optics = match fixed {
            Some(o) => o,
            None => plate.at(lambda)?.optics(frame, beta)?,
        };
        let m = optics.mueller(lambda, want)?;
        r += m.r.unwrap_or_default() * w;
        t += m.t.unwrap_or_default() * w;
    }
    Ok(SlabMueller {
        r: want.reflection.then_some(r),
        t: want.transmission.then_some(t),
    })
}
