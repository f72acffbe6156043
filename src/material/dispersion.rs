//! Real refractive-index dispersion models `n(λ)`.
//!
//! Callers pass vacuum wavelengths in **nanometres** (the renderer's unit). All
//! fitted formulas are evaluated with `λ` in **micrometres**, the unit in which
//! the published coefficients are given, so coefficients can be copied from the
//! cited papers unchanged.
//!
//! The models are deliberately small:
//!
//! * [`Dispersion::Constant`]: `n(λ) = n₀`.
//! * [`Dispersion::Cauchy`]: `n(λ) = A₀ + A₁/λ² + A₂/λ⁴ + …`.
//! * [`Dispersion::Sellmeier`]: `n²(λ) = A + Σᵢ termᵢ(λ)`, where each [`Term`] is
//!   one of `B λ²/(λ² − C)`, `B/(λ² − C)` or `D λᵖ`. This single form covers
//!   every fit in the crystal catalogue exactly (classical Sellmeier sums, the
//!   two-pole fits of Ghosh 1999, the `A + B/(λ² − C) − Dλ²` fits of DeVore 1951
//!   and Eimerl et al. 1987, and Zernike's 1964 mixed form).
//!
//! Validity ranges are properties of a fit, not of the formula, so they are
//! kept with the data (see `crystals::Crystal::range_nm`). Evaluating outside a
//! fit's range is allowed and returns the formula's value; see
//! [`Dispersion::index`] for what happens where the formula breaks down.

use crate::real::{Mask, Real};
use std::borrow::Cow;

/// One additive term of a Sellmeier-type expression for `n²(λ)`, `λ` in µm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Term {
    /// Classical Sellmeier oscillator `b λ² / (λ² − c)`.
    ///
    /// `c` is the *square* of the resonance wavelength, in µm². Fits that
    /// publish the resonance wavelength `λᵢ` itself (e.g. Dodge 1984) are
    /// written with `c = λᵢ²`.
    Oscillator { b: f64, c: f64 },
    /// Pole term `b / (λ² − c)`, `c` in µm², as used by DeVore (1951),
    /// Eimerl et al. (1987) and Zernike (1964).
    Pole { b: f64, c: f64 },
    /// Power term `d λᵖ`, e.g. the infrared correction `−D λ²` of many fits.
    Power { d: f64, p: i32 },
}

impl Term {
    /// Value of the term at `l2 = λ²` (µm²).
    fn eval<T: Real>(&self, l2: T) -> T {
        match *self {
            Term::Oscillator { b, c } => l2 * b / (l2 - c),
            Term::Pole { b, c } => T::cst(b) / (l2 - c),
            Term::Power { d, p } => powi(l2.sqrt(), p) * d,
        }
    }

    /// Wavelength (nm) of the term's pole, if it has one at a real, positive
    /// wavelength.
    fn pole_nm(&self) -> Option<f64> {
        match *self {
            Term::Oscillator { c, .. } | Term::Pole { c, .. } if c > 0.0 => Some(c.sqrt() * 1e3),
            _ => None,
        }
    }
}

/// A real refractive index as a function of vacuum wavelength.
///
/// Coefficient lists are `Cow<'static, [_]>` so that catalogue entries can be
/// `static` (borrowed slices) while user-supplied models can own their data
/// (`vec![...].into()`).
#[derive(Clone, Debug, PartialEq)]
pub enum Dispersion {
    /// Wavelength-independent index `n(λ) = n₀`.
    Constant(f64),
    /// Cauchy series `n(λ) = Σₖ Aₖ λ^(−2k) = A₀ + A₁/λ² + A₂/λ⁴ + …`,
    /// `λ` in µm, coefficients `[A₀, A₁, A₂, …]`.
    Cauchy(Cow<'static, [f64]>),
    /// Sellmeier-type form `n²(λ) = a + Σᵢ termsᵢ(λ)`, `λ` in µm.
    ///
    /// The common form `n² − 1 = Σ Bᵢ λ²/(λ² − Cᵢ)` is `a = 1` with
    /// [`Term::Oscillator`] terms.
    Sellmeier {
        /// Constant part of `n²`.
        a: f64,
        /// Wavelength-dependent terms, summed.
        terms: Cow<'static, [Term]>,
    },
}

impl Dispersion {
    /// Refractive index at `wavelength_nm` (vacuum wavelength, nanometres).
    ///
    /// Returns the formula's value whenever it is finite and positive, also
    /// outside the fit's validity range (the caller decides what to accept).
    /// Never returns NaN: where the formula has no meaningful value (a
    /// wavelength that is not finite and positive, `n² ≤ 0`, or a pole) this
    /// returns `1.0`. Use [`Dispersion::try_index`] to detect those cases.
    pub fn index(&self, wavelength_nm: f64) -> f64 {
        self.try_index(wavelength_nm).unwrap_or(1.0)
    }

    /// Refractive index at `wavelength_nm`, or `None` if the wavelength is not
    /// finite and positive or the formula's value there is not a finite,
    /// positive real number.
    pub fn try_index(&self, wavelength_nm: f64) -> Option<f64> {
        let (n, valid) = self.evaluate(wavelength_nm);
        valid.then_some(n)
    }

    /// [`Dispersion::index`] over the reals `T` (a wavelength per lane while recording).
    pub fn index_of<T: Real>(&self, wavelength_nm: T) -> T {
        let (n, valid) = self.evaluate(wavelength_nm);
        valid.when(|| n, T::one)
    }

    /// `(n(λ), valid)`: the fit at `wavelength_nm` (nm; the fits take µm) and whether it is a
    /// valid index.
    fn evaluate<T: Real>(&self, wavelength_nm: T) -> (T, T::Mask) {
        let zero = T::zero();
        let positive = |x: T| x.finite() & x.gt(zero);
        let given = positive(wavelength_nm);
        let micrometres = wavelength_nm / 1000.0;
        let l2 = micrometres * micrometres;
        let (n, valid) = match self {
            Dispersion::Constant(n) => (T::cst(*n), given),
            Dispersion::Cauchy(coeffs) => {
                let x = l2.recip();
                let n = coeffs.iter().rev().fold(zero, |acc, &c| acc * x + c);
                (n, given & T::Mask::cst(!coeffs.is_empty()))
            }
            Dispersion::Sellmeier { a, terms } => {
                let n2 = terms.iter().fold(T::cst(*a), |acc, t| acc + t.eval(l2));
                let ok = positive(n2);
                (ok.when(|| n2.sqrt(), T::one), given & ok)
            }
        };
        (n, valid & positive(n))
    }

    pub fn poles_nm(&self) -> Vec<f64> {
        let mut poles: Vec<f64> = match self {
            Dispersion::Sellmeier { terms, .. } => terms.iter().filter_map(Term::pole_nm).collect(),
            _ => Vec::new(),
        };
        poles.sort_by(f64::total_cmp);
        poles
    }
}

/// `x^p` for a small integer `p`, by repeated multiplication (what `powi` does).
fn powi<T: Real>(x: T, p: i32) -> T {
    let base = if p < 0 { x.recip() } else { x };
    (0..p.unsigned_abs()).fold(T::one(), |acc, _| acc * base)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn constant_is_flat() {
        let d = Dispersion::Constant(1.5);
        for nm in [200.0, 589.3, 10_000.0] {
            assert_eq!(d.index(nm), 1.5);
        }
    }

    #[test]
    fn cauchy_matches_hand_evaluation() {
        // n = 1.5 + 0.004/λ² + 0.0001/λ⁴ at λ = 0.5 µm:
        // 1.5 + 0.004·4 + 0.0001·16 = 1.5176.
        let d = Dispersion::Cauchy(vec![1.5, 0.004, 1e-4].into());
        assert!(close(d.index(500.0), 1.5176, 1e-12));
        // Empty series is n = 0, which is not a valid index.
        assert_eq!(
            Dispersion::Cauchy(Cow::Borrowed(&[])).try_index(500.0),
            None
        );
    }

    #[test]
    fn sellmeier_terms_match_hand_evaluation() {
        // λ = 1 µm: n² = 2 + 1·1/(1 − 0.5) + 0.5/(1 − 0.5) − 0.25·1² = 4.75.
        let d = Dispersion::Sellmeier {
            a: 2.0,
            terms: vec![
                Term::Oscillator { b: 1.0, c: 0.5 },
                Term::Pole { b: 0.5, c: 0.5 },
                Term::Power { d: -0.25, p: 2 },
            ]
            .into(),
        };
        assert!(close(d.index(1000.0), 4.75f64.sqrt(), 1e-12));
        // λ = 2 µm: n² = 2 + 4/3.5 + 0.5/3.5 − 1 = 2.2857142857…
        assert!(close(
            d.index(2000.0),
            (2.0 + 4.5 / 3.5 - 1.0f64).sqrt(),
            1e-12
        ));
        let poles = d.poles_nm();
        assert_eq!(poles.len(), 2);
        assert!(close(poles[0], 0.5f64.sqrt() * 1e3, 1e-9));
    }

    #[test]
    fn never_nan() {
        let d = Dispersion::Sellmeier {
            a: 1.0,
            terms: Cow::Borrowed(&[Term::Oscillator { b: 1.0, c: 0.25 }]),
        };
        // Exactly on the pole (500 nm), where n² < 0 (at 450 nm,
        // n² = 1 + 0.2025/(0.2025 − 0.25)), and for invalid wavelengths:
        // `index` falls back to 1 and `try_index` says None.
        for nm in [500.0, 450.0, 0.0, -3.0, f64::NAN, f64::INFINITY] {
            assert_eq!(d.try_index(nm), None, "try_index({nm})");
            assert_eq!(d.index(nm), 1.0, "index({nm})");
        }
        // Just beyond the pole the formula is valid again (and large).
        assert!(d.index(510.0) > 3.0);
        assert_eq!(Dispersion::Constant(f64::NAN).index(500.0), 1.0);
        assert_eq!(Dispersion::Constant(-1.0).try_index(500.0), None);
    }
}
