//! A uniaxial material: its two principal complex indices as functions of wavelength.

pub mod crystals;
pub mod dispersion;

use crate::error::{Error, Result};
use crate::material::crystals::Crystal;
use crate::real::complex::Cx;
use crate::real::{Mask, Real};
use num_complex::Complex64 as C64;

/// Vacuum wavelengths accepted (nm): X-rays to millimetre waves; the optics is continuum
/// electrodynamics, so anything beyond is outside the model (and outside f64's comfort).
pub const WAVELENGTH_RANGE: (f64, f64) = (1.0, 1e6);

/// Wavelengths (nm) a renderer evaluates materials over: Mitsuba's spectral variants sample
/// 360-830 nm, the range of the CIE tables (which the RGB integration covers too).
pub const RENDER_RANGE_NM: (f64, f64) = (360.0, 830.0);

/// Fails (naming `wavelength_nm`) outside [`WAVELENGTH_RANGE`] or for NaN.
pub fn check_wavelength(lambda_nm: f64) -> Result<()> {
    if (WAVELENGTH_RANGE.0..=WAVELENGTH_RANGE.1).contains(&lambda_nm) {
        Ok(())
    } else {
        Err(Error::new(
            "wavelength_nm",
            format!(
                "must be within [{}, {}] nm, got {lambda_nm}",
                WAVELENGTH_RANGE.0, WAVELENGTH_RANGE.1
            ),
        ))
    }
}

/// One principal index: `n(λ) + iκ`, over the reals `T` (`f64`, or the recorded numbers of a
/// program whose indices are inputs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Index<T: Real = f64> {
    /// Wavelength-independent.
    Constant(Cx<T>),
    /// A named crystal's ordinary or extraordinary dispersion, plus a constant extinction.
    Crystal {
        /// The crystal's dispersion data.
        crystal: &'static Crystal,
        /// `true` for the extraordinary index.
        extraordinary: bool,
        /// Extinction coefficient κ.
        kappa: T,
    },
}

impl<T: Real> Index<T> {
    /// The complex index at `lambda_nm`. Crystal fits are evaluated outside their range too
    /// (what callers accept there is [`Material::coverage`]).
    pub fn at(&self, lambda_nm: T) -> Cx<T> {
        match *self {
            Index::Constant(n) => n,
            Index::Crystal {
                crystal,
                extraordinary,
                kappa,
            } => {
                let d = if extraordinary {
                    &crystal.extraordinary
                } else {
                    &crystal.ordinary
                };
                Cx::new(d.index_of(lambda_nm), kappa)
            }
        }
    }

    /// True if the index varies with wavelength.
    pub fn is_dispersive(&self) -> bool {
        matches!(self, Index::Crystal { .. })
    }
}

/// Ordinary and extraordinary indices of a uniaxial material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material<T: Real = f64> {
    /// Ordinary index.
    pub eta_o: Index<T>,
    /// Extraordinary index.
    pub eta_e: Index<T>,
}

impl<T: Real> Material<T> {
    /// True if any index varies with wavelength.
    pub fn is_dispersive(&self) -> bool {
        self.eta_o.is_dispersive() || self.eta_e.is_dispersive()
    }

    /// `(η_o, η_e)` at `lambda_nm`, with `birefringence` added to `Re η_e` (photoelastic
    /// stress: `n_e − n_o = C (σ₁ − σ₂)` on an isotropic material). Fails (naming the
    /// parameter) if the result is not a valid index; while recording, such lanes fail.
    pub fn indices(&self, lambda_nm: T, birefringence: T) -> Result<(Cx<T>, Cx<T>)> {
        if let (Some(lambda_nm), Some(b)) = (lambda_nm.value(), birefringence.value()) {
            check_wavelength(lambda_nm)?;
            if !b.is_finite() {
                return Err(Error::new("birefringence", "must be finite"));
            }
        }
        let eo = checked_index("eta_o", self.eta_o.at(lambda_nm))?;
        let ee = self.eta_e.at(lambda_nm) + birefringence;
        let added = birefringence.value() != Some(0.0);
        checked_index(if added { "birefringence" } else { "eta_e" }, ee)?;
        Ok((eo, ee))
    }
}

impl Material {
    /// The material over the reals `T`: each of its real numbers given by `re(extraordinary,
    /// n)` (the real part of a constant index) or `im(extraordinary, κ)` (an extinction
    /// coefficient), e.g. a recorded program's inputs or constants.
    pub fn lifted<T: Real>(
        &self,
        re: impl Fn(bool, f64) -> T,
        im: impl Fn(bool, f64) -> T,
    ) -> Material<T> {
        let lift = |index: &Index, extraordinary: bool| match *index {
            Index::Constant(n) => {
                Index::Constant(Cx::new(re(extraordinary, n.re), im(extraordinary, n.im)))
            }
            Index::Crystal {
                crystal,
                extraordinary,
                kappa,
            } => Index::Crystal {
                crystal,
                extraordinary,
                kappa: im(extraordinary, kappa),
            },
        };
        Material {
            eta_o: lift(&self.eta_o, false),
            eta_e: lift(&self.eta_e, true),
        }
    }

    /// Constant indices (validated).
    pub fn constant(eta_o: C64, eta_e: C64) -> Result<Self> {
        Ok(Material {
            eta_o: Index::Constant(check_index("eta_o", eta_o)?),
            eta_e: Index::Constant(check_index("eta_e", eta_e)?),
        })
    }

    /// A named crystal with extinction coefficients `kappa_o`, `kappa_e`.
    pub fn named(name: &str, kappa_o: f64, kappa_e: f64) -> Result<Self> {
        let crystal = crystals::crystal(name).ok_or_else(|| {
            Error::new(
                "material",
                format!(
                    "unknown crystal '{name}'; the catalogue's names: {} (case and the \
                     full names in brackets are accepted too), or give constant indices eta_o \
                     and eta_e instead",
                    crystals::crystal_list()
                ),
            )
        })?;
        check_kappa("kappa_o", kappa_o)?;
        check_kappa("kappa_e", kappa_e)?;
        let index = |extraordinary, kappa| Index::Crystal {
            crystal,
            extraordinary,
            kappa,
        };
        Ok(Material {
            eta_o: index(false, kappa_o),
            eta_e: index(true, kappa_e),
        })
    }

    /// True if the material is isotropic at every wavelength: equal constant indices (named
    /// crystals are birefringent).
    pub fn is_isotropic(&self) -> bool {
        matches!((self.eta_o, self.eta_e), (Index::Constant(o), Index::Constant(e)) if o == e)
    }

    /// The named crystals of this material (each once).
    fn crystals(&self) -> Vec<&'static Crystal> {
        let mut v: Vec<&'static Crystal> = Vec::new();
        for i in [self.eta_o, self.eta_e] {
            if let Index::Crystal { crystal, .. } = i {
                if !v.iter().any(|c| std::ptr::eq(*c, crystal)) {
                    v.push(crystal);
                }
            }
        }
        v
    }

    /// The rule for wavelengths a named crystal's cited data do not cover, for a caller that
    /// evaluates the material over `[lo, hi]` nm (the calculator: its one wavelength; the
    /// plugins, at load: [`RENDER_RANGE_NM`]). This is the only place it is decided:
    ///
    /// - inside the data's range ([`Crystal::range_nm`]): `Ok(None)`;
    /// - partly outside it but within [`RENDER_RANGE_NM`], where every catalogued fit is
    ///   finite, pole-free and of normal dispersion (tested in `crystals`): the fit is
    ///   extrapolated, `Ok(Some(warning))` with the data's range and what is known there;
    /// - beyond both: an error naming `wavelength_nm` and the data's range.
    pub fn coverage(&self, lo: f64, hi: f64) -> Result<Option<String>> {
        let mut warnings = Vec::new();
        for c in self.crystals() {
            let (a, b) = c.range_nm;
            let (r0, r1) = RENDER_RANGE_NM;
            for (u0, u1) in c.uncovered(lo, hi).into_iter().flatten() {
                if u0 < r0 || u1 > r1 {
                    let at = if lo == hi {
                        format!("{lo} nm is")
                    } else {
                        format!("{lo}-{hi} nm are")
                    };
                    return Err(Error::new(
                        "wavelength_nm",
                        format!(
                            "{at} outside the {a}-{b} nm range of the dispersion data for {} (extrapolated only within {r0}-{r1} nm, where Mitsuba samples)",
                            c.label()
                        ),
                    ));
                }
                let span = if u0 == u1 {
                    format!("{u0} nm")
                } else {
                    format!("{u0}-{u1} nm")
                };
                let note = if c.beyond_range.is_empty() {
                    String::new()
                } else {
                    format!("; {}", c.beyond_range)
                };
                warnings.push(format!(
                    "the dispersion data for {} cover {a}-{b} nm: its fit is extrapolated at {span}{note}",
                    c.label()
                ));
            }
        }
        Ok((!warnings.is_empty()).then(|| warnings.join("; ")))
    }
}

/// Validates the index of an isotropic medium that light arrives from or leaves into: real and
/// `> 0`. (With absorption there the incident plane wave is inhomogeneous and power fractions
/// are undefined.)
pub fn check_clear_index(parameter: &str, eta: C64) -> Result<C64> {
    check_index(parameter, eta)?;
    if eta.im != 0.0 {
        return Err(Error::new(
            parameter,
            "must be real: absorbing exterior or exit media are not supported (the incident wave would be inhomogeneous and power fractions undefined)",
        ));
    }
    Ok(eta)
}

/// Range of the real part of an index (every optical material lies well inside; beyond, the
/// results leave the range of the renderer's single-precision numbers).
pub const INDEX_RANGE: (f64, f64) = (1e-3, 1e3);
/// Largest extinction coefficient `κ` (metals reach ~100 in the infrared).
pub const KAPPA_MAX: f64 = 1e3;

/// Validates an extinction coefficient given on its own (`kappa_o`, `kappa_e`): finite,
/// `0 <= κ <=` [`KAPPA_MAX`], the range [`check_index`] allows for an index's imaginary part.
pub fn check_kappa(parameter: &str, kappa: f64) -> Result<f64> {
    if kappa.is_finite() && (0.0..=KAPPA_MAX).contains(&kappa) {
        Ok(kappa)
    } else {
        Err(Error::new(
            parameter,
            format!("must be within [0, {KAPPA_MAX}], got {kappa}"),
        ))
    }
}

/// [`check_index`] over the reals `T`: the full check with its message where the index is
/// known; while recording, the lanes where it is not a valid index fail.
pub fn checked_index<T: Real>(parameter: &str, eta: Cx<T>) -> Result<Cx<T>> {
    if let (Some(re), Some(im)) = (eta.re.value(), eta.im.value()) {
        check_index(parameter, C64::new(re, im))?;
        return Ok(eta);
    }
    let (lo, hi) = (T::cst(INDEX_RANGE.0), T::cst(INDEX_RANGE.1));
    let valid = eta.re.ge(lo) & eta.re.le(hi) & eta.im.ge(T::zero()) & eta.im.le(T::cst(KAPPA_MAX));
    (!valid).fail(|| Error::new(parameter, "not a valid index"))?;
    Ok(eta)
}

/// Validates one complex index `n + iκ`: finite, `n` within [`INDEX_RANGE`], `0 <= κ <=`
/// [`KAPPA_MAX`].
pub fn check_index(parameter: &str, eta: C64) -> Result<C64> {
    if !eta.re.is_finite() || !eta.im.is_finite() {
        return Err(Error::new(parameter, "must be finite"));
    }
    if eta.re <= 0.0 {
        return Err(Error::new(
            parameter,
            format!("real part of the index must be > 0, got {}", eta.re),
        ));
    }
    if !(INDEX_RANGE.0..=INDEX_RANGE.1).contains(&eta.re) {
        return Err(Error::new(
            parameter,
            format!(
                "real part of the index must be within [{}, {}], got {}",
                INDEX_RANGE.0, INDEX_RANGE.1, eta.re
            ),
        ));
    }
    if eta.im > KAPPA_MAX {
        return Err(Error::new(
            parameter,
            format!(
                "extinction coefficient (imaginary part) must be <= {KAPPA_MAX}, got {}",
                eta.im
            ),
        ));
    }
    if eta.im < 0.0 {
        return Err(Error::new(
            parameter,
            format!(
                "extinction coefficient (imaginary part) must be >= 0 in the n + i kappa convention, got {}",
                eta.im
            ),
        ));
    }
    Ok(eta)
}
