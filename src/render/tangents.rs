//! Derivatives of a sampled lobe with respect to the inputs of its query: what a
//! differentiable renderer (Mitsuba's llvm_ad variants) attaches to its graph.
//!
//! **What is differentiated.** The sample a path follows: its direction `wo` (the chosen
//! slot's direction in the hero channel) and its weight in every channel, the Mueller matrix
//! over the selection probability *expressed in Mitsuba's implicit Stokes frames*
//! ([`crate::render::mitsuba_frames`]; the core's own plane-of-incidence frames turn abruptly
//! near normal incidence, Mitsuba's do not). The choice (slot, hero channel) and its
//! probability are held at their values for the lane: *attached sampling* with a detached
//! selection probability, as Mitsuba's own `dielectric` samples (the derivative of the
//! expected value is then the expected derivative of the weight, since
//! `Σ_s P_s · (∂M_s / P_s) = ∂ Σ_s M_s`).
//!
//! **How.** Central differences of the core's exact query, in `f64`, along each input (vectors
//! along two tangents of the unit vector, then expressed as Cartesian columns): two more
//! queries per direction, with a step of [`RELATIVE_STEP`] times the input's natural scale at
//! the lane: the change that moves the plate's largest optical phase `2π n d / λ` by about one
//! radian (the optic axis's direction through the birefringence `|η_e − η_o|` alone; for a
//! crystal surface, which has no thickness: one unit of index, one radian). `tests/tangents.rs`
//! measures the error against closed-form derivatives and against Richardson extrapolation:
//! over random plates and crystals, a median of 1e-8 of the derivative, 6e-6 at the 99th
//! percentile, 5e-5 at the 99.9th (docs/gradients.md). Forward differences
//! ([`Stencil::Forward`]) need one query per direction instead of two, but are ~1000 times
//! less accurate (median 7e-6, 99th percentile 1.4e-4): beyond Mitsuba's own tolerance for
//! the attached sampling of `dielectric` (1e-5); docs/gradients.md weighs the two.
//!
//! **Where a side of the difference is missing** (the perturbed query fails, e.g. a thickness
//! or `κ` below 0 at the edge of its range, or the slot does not exist there, e.g. beyond a
//! critical angle), the difference is one-sided, of second order, from three points on the
//! side that exists (not from the lane itself: at the edge of a range, e.g. `κ = 0`, the lane
//! may take another branch of the code, equal to its neighbours only to rounding); a channel
//! whose slot does not exist at the lane itself has derivative 0 (a lobe appearing is a jump,
//! not a derivative).
//!
//! **An isotropic crystal surface stays isotropic.** Moving `η_o` alone would split its
//! refraction into o and e rays, a different set of lobes; so for a bulk crystal with equal
//! indices, the derivatives with respect to `η_o` and `η_e` (and `κ_o`, `κ_e`) are each half the
//! derivative along `η_o = η_e`: their sum is the derivative with respect to the common index.
//! A plate has the same lobes whatever its indices, and takes ordinary partial derivatives.

use crate::error::Result;
use crate::material::{Index, Material};
use crate::render::choice::Choice;
use crate::render::mitsuba_frames::{in_implicit_frames, stokes_basis};
use crate::render::slots::Slots;
use crate::render::{PathLobe, Transport};
use crate::C64;
use nalgebra::{Matrix4, Vector3};
use std::f64::consts::PI;
use std::ops::{Add, Mul, Sub};

/// An input of a lane that derivatives can be taken with respect to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Input {
    /// The plate's thickness (nm).
    Thickness,
    /// The plate's added birefringence (added to `Re η_e`).
    Birefringence,
    /// The plate's axis rotation about the normal (degrees).
    AxisAngle,
    /// `Re η_o` of a material with constant indices.
    EtaO,
    /// `Re η_e` of a material with constant indices.
    EtaE,
    /// `κ_o`, the ordinary extinction coefficient.
    KappaO,
    /// `κ_e`, the extraordinary extinction coefficient.
    KappaE,
    /// The optic axis (local, any non-zero length): three columns, x, y, z.
    OpticAxis,
    /// The query direction `wi` (unit, local): three columns, x, y, z.
    Wi,
}

impl Input {
    /// Derivative columns of the input: 3 for a vector (x, y, z), else 1.
    pub fn columns(self) -> usize {
        match self {
            Input::OpticAxis | Input::Wi => 3,
            _ => 1,
        }
    }
}

/// Most derivative columns of one query: every input once (the two vectors count three each).
pub const MAX_COLUMNS: usize = 13;

/// Most channels of one query.
pub const MAX_CHANNELS: usize = 4;

/// A finite-difference stencil.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stencil {
    /// `(f(h) - f(0)) / h`: one evaluation per direction.
    Forward,
    /// `(f(h) - f(-h)) / 2h`: two evaluations per direction.
    Central,
}

/// The stencil the renderer's derivatives use (see the module documentation).
pub const STENCIL: Stencil = Stencil::Central;

/// Step of the differences, relative to each input's natural scale at the lane (see the module
/// documentation and `tests/tangents.rs`, which measures the error of the choice).
pub const RELATIVE_STEP: f64 = 1e-4;

/// The inputs of one lane that derivatives are taken with respect to; the rest of the query
/// (media, wavelengths, transport, enabled lobes) is fixed.
#[derive(Clone, Copy, Debug)]
pub struct Point {
    /// The material.
    pub material: Material,
    /// Added to `Re η_e` (a plate's stress birefringence; 0 for a crystal).
    pub birefringence: f64,
    /// A plate's thickness (nm; 0 for a crystal surface).
    pub thickness_nm: f64,
    /// A plate's axis rotation about the normal (degrees).
    pub axis_angle_deg: f64,
    /// The optic axis (local, any non-zero length).
    pub axis: Vector3<f64>,
    /// The query direction (unit, local).
    pub wi: Vector3<f64>,
}

/// One lane: its point, its sampled lobe, and how to recompute its lobes elsewhere.
pub struct Lane<'a, const S: usize> {
    /// Where the derivatives are taken.
    pub point: Point,
    /// The lane's transport mode.
    pub transport: Transport,
    /// A bulk crystal's surface (an isotropic one stays isotropic, see the module docs).
    pub bulk: bool,
    /// The shortest wavelength of the query (nm), for the steps.
    pub shortest_nm: f64,
    /// The lane's lobes, per channel.
    pub lobes: &'a [Slots<S>],
    /// The lobe the lane samples.
    pub choice: Choice,
    /// Only the unpolarised weight (`M00`) is wanted.
    pub intensity_only: bool,
    /// The lane's lobes at another point (per channel, as `lobes`).
    pub at: &'a dyn Fn(&Point) -> Result<Vec<Slots<S>>>,
}

/// The derivative columns of one lane: column `k` of `d wo` and of each channel's weight
/// (16 entries, row-major, in Mitsuba's implicit frames; entry 0 alone when intensity only).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Columns {
    /// `d wo / d column`.
    pub wo: [[f64; 3]; MAX_COLUMNS],
    /// `d weight / d column`, per channel.
    pub value: [[[f64; 16]; MAX_CHANNELS]; MAX_COLUMNS],
}

impl Columns {
    /// Every derivative zero.
    pub fn zeros() -> Self {
        Columns {
            wo: [[0.0; 3]; MAX_COLUMNS],
            value: [[[0.0; 16]; MAX_CHANNELS]; MAX_COLUMNS],
        }
    }
}

/// The sampled lobe at one point: the hero's direction and each channel's weight (`None` where
/// the channel lacks the slot).
struct Sampled {
    wo: Vector3<f64>,
    value: [Option<Matrix4<f64>>; MAX_CHANNELS],
}

impl<const S: usize> Lane<'_, S> {
    /// The derivative columns for `inputs`, in order (vectors give three columns each).
    pub fn derivatives(&self, inputs: &[Input]) -> Columns {
        self.derivatives_with(inputs, RELATIVE_STEP, STENCIL)
    }

    /// [`Lane::derivatives`] with steps of `relative_step` times each input's
    /// [`Lane::natural_scale`] and the `stencil` given (the tests' reference).
    pub fn derivatives_with(
        &self,
        inputs: &[Input],
        relative_step: f64,
        stencil: Stencil,
    ) -> Columns {
        let mut out = Columns::zeros();
        self.fill(inputs, (relative_step, stencil), &mut out);
        out
    }

    /// [`Lane::derivatives`] into the first columns of `out` (the others are left as they
    /// are): what a batch writes lane after lane without moving a whole [`Columns`].
    pub fn derivatives_into(&self, inputs: &[Input], out: &mut Columns) {
        self.fill(inputs, (RELATIVE_STEP, STENCIL), out);
    }

    fn fill(&self, inputs: &[Input], method: (f64, Stencil), out: &mut Columns) {
        let columns: usize = inputs.iter().map(|i| i.columns()).sum();
        for k in 0..columns.min(MAX_COLUMNS) {
            out.wo[k] = [0.0; 3];
            out.value[k] = [[0.0; 16]; MAX_CHANNELS];
        }
        let base = self.sampled(&self.point, self.lobes);
        let mut k = 0;
        for &input in inputs {
            match input {
                Input::OpticAxis | Input::Wi => {
                    let (v, scale) = match input {
                        Input::Wi => (self.point.wi, 1.0),
                        _ => (self.point.axis, self.point.axis.norm()),
                    };
                    let unit = v / scale;
                    let t1 = stokes_basis(unit);
                    for t in [t1, unit.cross(&t1)] {
                        let d = self.along(input, t, base.as_ref(), method);
                        for j in 0..3 {
                            accumulate(out, k + j, &d, t[j] / scale);
                        }
                    }
                }
                _ => {
                    let d = self.along(input, Vector3::zeros(), base.as_ref(), method);
                    accumulate(out, k, &d, 1.0);
                }
            }
            k += input.columns();
        }
    }

    /// The derivative along one direction of `input` (`t`: the tangent of a vector input).
    fn along(
        &self,
        input: Input,
        t: Vector3<f64>,
        base: Option<&Sampled>,
        (relative_step, stencil): (f64, Stencil),
    ) -> Derivative {
        let Some(base) = base else {
            return Derivative::default();
        };
        let h = relative_step * self.natural_scale(input);
        // An isotropic bulk crystal's pair of indices moves together, half each.
        let paired = self.bulk && self.point.material.is_isotropic();
        let factor = if paired && is_index(input) { 0.5 } else { 1.0 };
        let side = |sign: f64| {
            let p = moved(&self.point, input, t, sign * h, paired)?;
            let lobes = (self.at)(&p).ok()?;
            self.sampled(&p, &lobes)
        };
        let sides = match stencil {
            Stencil::Forward => {
                // Backward where the forward side does not exist (the edge of a range).
                let near = side(1.0)
                    .map(|s| (s, 1.0))
                    .or_else(|| side(-1.0).map(|s| (s, -1.0)));
                let (plus, minus) = match near {
                    Some((s, sign)) if sign > 0.0 => (Some(s), None),
                    Some((s, _)) => (None, Some(s)),
                    None => (None, None),
                };
                [plus, minus, None, None]
            }
            Stencil::Central => {
                let (plus, minus) = (side(1.0), side(-1.0));
                // One-sided (at the edge of a range): two more points on the side that exists.
                let sign = match (&plus, &minus) {
                    (Some(_), None) => 1.0,
                    (None, Some(_)) => -1.0,
                    _ => 0.0,
                };
                let far = [2.0, 3.0].map(|k| (sign != 0.0).then(|| side(k * sign)).flatten());
                let [f2, f3] = far;
                [plus, minus, f2, f3]
            }
        };
        let sides = [&sides[0], &sides[1], &sides[2], &sides[3]].map(|s| s.as_ref());
        let wo = sides.map(|s| s.map(|s| s.wo));
        let mut d = Derivative {
            wo: difference(wo, base.wo, h).map_or_else(Vector3::zeros, |x| x * factor),
            value: [None; MAX_CHANNELS],
        };
        for (c, v) in d.value.iter_mut().enumerate() {
            // A channel without the slot at the lane has no derivative.
            *v = base.value[c].and_then(|at| {
                difference(sides.map(|s| s.and_then(|s| s.value[c])), at, h).map(|x| x * factor)
            });
        }
        d
    }

    /// The sampled lobe (the lane's choice) among `lobes` at `p`; `None` if the hero channel
    /// lacks its slot there.
    fn sampled(&self, p: &Point, lobes: &[Slots<S>]) -> Option<Sampled> {
        let hero: &PathLobe = lobes.get(self.choice.hero)?[self.choice.slot].as_ref()?;
        let wi = p.wi.normalize();
        let mut value = [None; MAX_CHANNELS];
        for (v, slots) in value.iter_mut().zip(lobes) {
            *v = slots[self.choice.slot].as_ref().map(|l| {
                let m = l.mueller / self.choice.pdf;
                if self.intensity_only {
                    m
                } else {
                    in_implicit_frames(l, &m, wi, hero.wo, self.transport)
                }
            });
        }
        Some(Sampled { wo: hero.wo, value })
    }

    /// The natural scale of `input` at the lane, in its units (an angle: radians for `wi` and
    /// the optic axis's direction, degrees for `axis_angle`): the change that moves the plate's
    /// largest optical phase by about one radian, or one unit (index, radian) for a surface
    /// (see the module documentation).
    pub fn natural_scale(&self, input: Input) -> f64 {
        let p = &self.point;
        let (n, dn) = p
            .material
            .indices(self.shortest_nm, p.birefringence)
            .map_or((1.0, 1.0), |(o, e)| {
                (o.norm().max(e.norm()), (e - o).norm())
            });
        // Radians of phase per unit index across the plate.
        let per_index = 2.0 * PI * p.thickness_nm / self.shortest_nm;
        match input {
            Input::Thickness => self.shortest_nm / (2.0 * PI * n),
            Input::Birefringence | Input::EtaO | Input::EtaE | Input::KappaO | Input::KappaE => {
                1.0 / (1.0 + per_index)
            }
            // The axis turns the phase through the birefringence only.
            Input::AxisAngle => 180.0 / PI / (1.0 + dn * per_index),
            Input::OpticAxis => 1.0 / (1.0 + dn * per_index),
            Input::Wi => 1.0 / (1.0 + n * per_index),
        }
    }
}

/// The derivative of the sampled lobe along one direction.
#[derive(Default)]
struct Derivative {
    wo: Vector3<f64>,
    value: [Option<Matrix4<f64>>; MAX_CHANNELS],
}

/// The derivative from the values `[f(h), f(-h), f(±2h), f(±3h)]` that were evaluated and
/// `at = f(0)`: the central difference where both sides exist; the one-sided second-order
/// difference `±(-5 f(±h) + 8 f(±2h) - 3 f(±3h)) / 2h` where one side and its two further
/// points do (it does not use `f(0)`: at the edge of a range, e.g. `κ = 0`, the lane may take
/// another branch of the code than the points beside it, equal only to rounding); else the
/// first-order difference with `f(0)` (the forward stencil); `None` where neither side exists.
fn difference<X>([plus, minus, f2, f3]: [Option<X>; 4], at: X, h: f64) -> Option<X>
where
    X: Copy + Add<Output = X> + Sub<Output = X> + Mul<f64, Output = X>,
{
    let one_sided = |f1: X, sign: f64| match (f2, f3) {
        (Some(f2), Some(f3)) => (f2 * 8.0 - f1 * 5.0 - f3 * 3.0) * (sign * 0.5 / h),
        _ => (f1 - at) * (sign / h),
    };
    match (plus, minus) {
        (Some(p), Some(m)) => Some((p - m) * (0.5 / h)),
        (Some(p), None) => Some(one_sided(p, 1.0)),
        (None, Some(m)) => Some(one_sided(m, -1.0)),
        (None, None) => None,
    }
}

/// Adds `weight` times `d` to column `k`.
fn accumulate(out: &mut Columns, k: usize, d: &Derivative, weight: f64) {
    for j in 0..3 {
        out.wo[k][j] += weight * d.wo[j];
    }
    for (c, v) in d.value.iter().enumerate() {
        if let Some(m) = v {
            for e in 0..16 {
                out.value[k][c][e] += weight * m[(e / 4, e % 4)];
            }
        }
    }
}

/// True for the inputs that are one of a material's indices.
fn is_index(input: Input) -> bool {
    matches!(
        input,
        Input::EtaO | Input::EtaE | Input::KappaO | Input::KappaE
    )
}

/// `p` moved by `h` along `input` (`t`: the tangent of a vector input; `paired`: both indices
/// of an isotropic pair move). `None` if the input cannot move (a named crystal's real index).
fn moved(p: &Point, input: Input, t: Vector3<f64>, h: f64, paired: bool) -> Option<Point> {
    let mut q = *p;
    match input {
        Input::Thickness => q.thickness_nm += h,
        Input::Birefringence => q.birefringence += h,
        Input::AxisAngle => q.axis_angle_deg += h,
        Input::EtaO | Input::EtaE | Input::KappaO | Input::KappaE => {
            let (re, im) = match input {
                Input::EtaO | Input::EtaE => (h, 0.0),
                _ => (0.0, h),
            };
            let ordinary = matches!(input, Input::EtaO | Input::KappaO);
            if ordinary || paired {
                q.material.eta_o = shifted(p.material.eta_o, re, im)?;
            }
            if !ordinary || paired {
                q.material.eta_e = shifted(p.material.eta_e, re, im)?;
            }
        }
        Input::OpticAxis => q.axis += t * (h * p.axis.norm()),
        Input::Wi => q.wi = (p.wi.normalize() + t * h).normalize(),
    }
    Some(q)
}

/// `index` with `re` added to its real part and `im` to its extinction; `None` for the real
/// part of a named crystal's index (its dispersion fit is not an input).
fn shifted(index: Index, re: f64, im: f64) -> Option<Index> {
    match index {
        Index::Constant(n) => Some(Index::Constant(n + C64::new(re, im))),
        Index::Crystal {
            crystal,
            extraordinary,
            kappa,
        } if re == 0.0 => Some(Index::Crystal {
            crystal,
            extraordinary,
            kappa: kappa + im,
        }),
        Index::Crystal { .. } => None,
    }
}
