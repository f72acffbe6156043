//! Which model serves a plate at one incidence — decided once, in [`PlateModel::new`] — and the
//! plate's Mueller matrices through it at one wavelength, over a Gaussian band, and over the
//! channels of a weight set.
//!
//! * A lossless isotropic layer that does not disperse ([`Plate::etalon`]) is two Airy etalons
//!   ([`crate::plate::etalon`]): exact in closed form at one wavelength and over every
//!   Gaussian.
//! * Any other plate is the general slab ([`crate::plate::slab`]) at one wavelength; over a
//!   band, the closed forms and quadratures of [`crate::spectral::gaussian`]; over a channel
//!   set, the path-class fringe integration of [`crate::colour::channels`] (held to the
//!   perceptual budget stated there), or, on request or where that method declines (more
//!   coherent orders than it sums: thin plates of high index near grazing incidence), the exact
//!   rule of [`integrate_set_exact`] (every approximation below 1e-5 of the fitted weights).

use crate::band::Gaussian;
use crate::colour::weights::{gaussians, WeightSet};
use crate::error::Result;
use crate::optics::frame::PlaneFrame;
use crate::plate::etalon::Etalon;
use crate::plate::slab::{Output, SlabMueller, SlabOptics, Want};
use crate::plate::Plate;
use crate::quadrature::Accuracy;
use crate::spectral::classes;
use crate::spectral::dense;
use crate::spectral::envelope;
use crate::spectral::gaussian::{self, channels_exact, etalon_sum};
use crate::spectral::pointwise;
use crate::spectral::route::{self, Route};
use crate::spectral::survey::Survey;
use num_complex::Complex64 as C64;
use std::cell::OnceCell;

/// A plate at one incidence, with the model that serves it.
pub struct PlateModel<'a> {
    plate: &'a Plate,
    frame: PlaneFrame,
    beta: C64,
    etalon: Option<Etalon>,
    /// Without dispersion the interfaces do not depend on the wavelength: solved once, for
    /// every wavelength asked of this model (the four a spectral renderer traces along a path).
    fixed: OnceCell<SlabOptics>,
}

impl<'a> PlateModel<'a> {
    /// The model of `plate` for incidence parameter `beta` in the plane of `frame`: an
    /// [`Etalon`] where [`Plate::etalon`] applies, else the general plate.
    pub fn new(plate: &'a Plate, frame: PlaneFrame, beta: C64) -> Self {
        PlateModel {
            plate,
            frame,
            beta,
            // The etalon's indices do not depend on the wavelength (no dispersion): any one
            // selects where they are evaluated.
            etalon: plate.etalon(550.0, beta),
            fixed: OnceCell::new(),
        }
    }

    /// The isotropic closed form, where it serves the plate.
    pub fn etalon(&self) -> Option<&Etalon> {
        self.etalon.as_ref()
    }

    /// Exactly at `lambda_nm` (s/p frames, power fractions).
    pub fn at(&self, lambda_nm: f64, want: Want, output: Output) -> Result<SlabMueller> {
        if let Some(e) = &self.etalon {
            return Ok(e.mueller(lambda_nm, want, output));
        }
        let solve = || self.plate.at(lambda_nm)?.optics(&self.frame, self.beta);
        let m = if self.plate.is_dispersive() {
            solve()?.mueller(lambda_nm, want)?
        } else {
            let optics = match self.fixed.get() {
                Some(o) => o,
                None => {
                    let o = solve()?;
                    self.fixed.get_or_init(|| o)
                }
            };
            optics.mueller(lambda_nm, want)?
        };
        Ok(output.keep(m))
    }

    /// Over the band `Σ_j a_j G(k; μ_j, σ_j)`. `incoherent` keeps the etalon's incoherent sum
    /// for further bands (every band thicker than the coherence length gives the same).
    pub fn band(
        &self,
        band: &[Gaussian],
        want: Want,
        output: Output,
        incoherent: &mut Option<SlabMueller>,
    ) -> Result<SlabMueller> {
        if let Some(m) = self
            .etalon
            .as_ref()
            .and_then(|e| etalon_sum(e, band, want, output, incoherent))
        {
            return Ok(m);
        }
        gaussian::band(self.plate, &self.frame, self.beta, band, want, output)
    }

    /// Over the three channels of `set`, to `accuracy`.
    pub fn channels(
        &self,
        set: WeightSet,
        want: Want,
        output: Output,
        accuracy: Accuracy,
    ) -> Result<[SlabMueller; 3]> {
        if self.etalon.is_some() {
            let mut incoherent = None;
            let mut one = |c: usize| self.band(gaussians(set, c), want, output, &mut incoherent);
            return Ok([one(0)?, one(1)?, one(2)?]);
        }
        if accuracy == Accuracy::Exact {
            return channels_exact(self.plate, &self.frame, self.beta, set, want, output);
        }
        let survey = Survey::new(self.plate, self.frame, self.beta)?;
        match route::choose(&survey, set)? {
            Route::Evanescent(points) => pointwise::channels(
                self.plate,
                &self.frame,
                self.beta,
                set,
                points,
                want,
                output,
            ),
            Route::Dense(points) => dense::channels(&survey, points, set, want, output),
            Route::Envelope(plan) => envelope::channels(&survey, &plan, set, want, output),
            Route::Classes(plan) => classes::channels(&survey, &plan, set, want, output),
        }
    }
}
