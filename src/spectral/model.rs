//! A plate at one incidence and its Mueller matrices at one wavelength, over a Gaussian band and
//! over the channels of a weight set: the one way down the layers. Which model serves the plate
//! (two Airy etalons or the general plate) and which method serves each spectrum is decided in
//! [`crate::spectral::route`], from the plate's properties and its surveys
//! ([`crate::spectral::survey`]); each method then starts from the survey's solved blocks.
//!
//! * A lossless isotropic layer that does not disperse is two Airy etalons
//!   ([`crate::plate::etalon`]): exact in closed form at one wavelength and over every Gaussian
//!   whose series is not too long.
//! * Any other plate is the general slab ([`crate::plate::slab`]) at one wavelength; over a band,
//!   Gaussian by Gaussian, the methods of [`crate::spectral::gaussian`]; over a channel set, the
//!   route of its survey ([`crate::spectral::route::Route`]), held to the perceptual budget of
//!   [`crate::quadrature::budget`] or, at [`Accuracy::Exact`], every approximation below 1e-5 of
//!   the fitted weights.

use crate::band::Gaussian;
use crate::colour::weights::{gaussians, WeightSet};
use crate::error::{Error, Result};
use crate::optics::frame::PlaneFrame;
use crate::plate::etalon::Etalon;
use crate::plate::slab::{Output, SlabMueller, SlabOptics, Want};
use crate::plate::Plate;
use crate::quadrature::Accuracy;
use crate::spectral::classes;
use crate::spectral::dense;
use crate::spectral::envelope;
use crate::spectral::gaussian;
use crate::spectral::pointwise;
use crate::spectral::route::{self, Route};
use crate::spectral::survey::{BandSurvey, Survey};
use nalgebra::Matrix4;
use num_complex::Complex64 as C64;
use std::cell::{Cell, OnceCell};
use std::f64::consts::TAU;

/// A thin element (a plate, a stack of layers) at one incidence, over a spectrum (s/p frames,
/// power fractions): what the renderer ([`crate::render::thin`]) and the calculator ask of
/// either.
pub trait ThinModel {
    /// Exactly at `lambda_nm`.
    fn at(&self, lambda_nm: f64, want: Want, output: Output) -> Result<SlabMueller>;
    /// Over the band `Σ_j a_j G(k; μ_j, σ_j)`, to `accuracy`.
    fn band(
        &self,
        band: &[Gaussian],
        want: Want,
        output: Output,
        accuracy: Accuracy,
    ) -> Result<SlabMueller>;
    /// Over the three channels of `set`, to `accuracy`.
    fn channels(
        &self,
        set: WeightSet,
        want: Want,
        output: Output,
        accuracy: Accuracy,
    ) -> Result<[SlabMueller; 3]>;
}

/// A plate at one incidence, with the model that serves it.
pub struct PlateModel<'a> {
    plate: &'a Plate,
    frame: PlaneFrame,
    beta: C64,
    etalon: Option<Etalon>,
    /// Without dispersion the interfaces do not depend on the wavelength: solved once, for
    /// every wavelength and band asked of this model (the four a spectral renderer traces along
    /// a path).
    fixed: OnceCell<SlabOptics>,
    /// The etalon's incoherent band average, the same for every band thicker than its coherence
    /// length: evaluated once for all of them.
    incoherent: Cell<Option<SlabMueller>>,
}

impl<'a> PlateModel<'a> {
    /// The model of `plate` for incidence parameter `beta` in the plane of `frame`
    /// ([`route::model`]).
    pub fn new(plate: &'a Plate, frame: PlaneFrame, beta: C64) -> Self {
        PlateModel {
            plate,
            frame,
            beta,
            etalon: route::model(plate, beta),
            fixed: OnceCell::new(),
            incoherent: Cell::new(None),
        }
    }

    /// The isotropic closed form, where it serves the plate.
    pub fn etalon(&self) -> Option<&Etalon> {
        self.etalon.as_ref()
    }

    /// The plate solved at `lambda_nm` (once without dispersion).
    fn optics(&self, lambda_nm: f64) -> Result<SlabOptics> {
        let solve = || self.plate.at(lambda_nm)?.optics(&self.frame, self.beta);
        if self.plate.is_dispersive() {
            return solve();
        }
        if let Some(o) = self.fixed.get() {
            return Ok(*o);
        }
        let o = solve()?;
        Ok(*self.fixed.get_or_init(|| o))
    }

    /// Over one unit-mass Gaussian, on its route.
    fn gaussian(&self, g: &Gaussian, want: Want, output: Output) -> Result<SlabMueller> {
        if let Some(e) = self.etalon.as_ref().filter(|e| route::etalon_serves(e, g)) {
            let incoherent = e.is_incoherent(g);
            if let Some(m) = self.incoherent.get().filter(|_| incoherent) {
                return Ok(m);
            }
            let m = e
                .band(g, want, output)
                .expect("the route checked its series");
            if incoherent {
                self.incoherent.set(Some(m));
            }
            return Ok(m);
        }
        let survey = BandSurvey::new(
            self.plate,
            self.frame,
            self.beta,
            g,
            self.optics(TAU / g.mu)?,
        )?;
        let (r, t) = gaussian::gaussian(&survey, route::gaussian(&survey), want, output)?;
        Ok(SlabMueller {
            r: want.reflection.then_some(r),
            t: want.transmission.then_some(t),
        })
    }
}

impl ThinModel for PlateModel<'_> {
    fn at(&self, lambda_nm: f64, want: Want, output: Output) -> Result<SlabMueller> {
        if let Some(e) = &self.etalon {
            return Ok(e.mueller(lambda_nm, want, output));
        }
        Ok(output.keep(self.optics(lambda_nm)?.mueller(lambda_nm, want)?))
    }

    /// Each Gaussian on its route ([`route::etalon_serves`], [`route::gaussian`]); every
    /// method of a Gaussian holds its approximations below 1e-5 (both accuracies).
    fn band(
        &self,
        band: &[Gaussian],
        want: Want,
        output: Output,
        _accuracy: Accuracy,
    ) -> Result<SlabMueller> {
        if band.is_empty() {
            return Err(Error::new("spectrum", "empty spectral band"));
        }
        let (mut r, mut t) = (Matrix4::zeros(), Matrix4::zeros());
        for g in band {
            let m = self.gaussian(g, want, output)?;
            r += m.r.unwrap_or_default() * g.amplitude;
            t += m.t.unwrap_or_default() * g.amplitude;
        }
        Ok(output.keep(SlabMueller {
            r: want.reflection.then_some(r),
            t: want.transmission.then_some(t),
        }))
    }

    /// The etalon Gaussian by Gaussian; the general plate on the route of its survey
    /// ([`route::channels`]).
    fn channels(
        &self,
        set: WeightSet,
        want: Want,
        output: Output,
        accuracy: Accuracy,
    ) -> Result<[SlabMueller; 3]> {
        let by_gaussians = || -> Result<[SlabMueller; 3]> {
            let one = |c: usize| self.band(gaussians(set, c), want, output, accuracy);
            Ok([one(0)?, one(1)?, one(2)?])
        };
        if self.etalon.is_some() {
            return by_gaussians();
        }
        let survey = Survey::new(self.plate, self.frame, self.beta)?;
        match route::channels(&survey, set, accuracy) {
            Route::Pointwise(points) => pointwise::channels(
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
            Route::Gaussians => by_gaussians(),
        }
    }
}
