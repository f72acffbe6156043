//! The surface event of a clear crystal (lossless and birefringent) under a clear exterior, in
//! closed form: the [`Event`] that [`crate::optics::lobes::scatter`] computes through the
//! general interface, here from the closed-form amplitudes of
//! [`crate::optics::uniaxial_fresnel`] and the fields ([`crate::optics::fields`]) of only the waves
//! the event involves (the crystal's two down-going waves, and the incident one from inside),
//! in real arithmetic unless one of them or the exterior wave is evanescent. `scatter` is the
//! reference it is tested against (`tests/crystal_fast_path.rs`).
//!
//! Every wave that carries power in a lossless medium has a real field, and its Stokes frame
//! ([`crate::optics::lobes`]) has `x` along that field made perpendicular to the ray, so its
//! unit Jones vector there is `(1, 0)`: a crystal wave's flux-normalised Jones matrix is its
//! row of amplitudes (outgoing) or column (incoming) in the first row or column, the rest 0.
//! Ray directions are the Poynting vectors' (eq. S12), ray indices `k·ŝ` (eq. S14).

use crate::cmath::singular;
use crate::cmath::Scalar;
use crate::error::{Error, Result};
use crate::optics::fields::{Fields, Wave};
use crate::optics::frame::PlaneFrame;
use crate::optics::lobes::{incidence, Event, Lobe};
use crate::optics::modes::{uniaxial_normals, ModeKind};
use crate::optics::mueller;
use crate::optics::surface::{Incident, Surface};
use crate::optics::uniaxial_fresnel::{Psi, UniaxialFresnel};
use nalgebra::{Matrix2, Vector3};
use num_complex::Complex64 as C64;

/// True if [`scatter_clear`] serves `surface`: a lossless birefringent crystal under a lossless
/// exterior (an isotropic one has the closed form of [`crate::render::isotropic`]).
pub fn applies(surface: &Surface) -> bool {
    let (x, c) = (&surface.exterior, &surface.crystal);
    x.is_lossless() && x.is_isotropic() && c.is_lossless() && !c.is_isotropic()
}

/// The incident wave of an event (the fields of [`Event`] that describe it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arrival {
    /// Unit propagation direction (ray direction), local frame.
    pub direction: Vector3<f64>,
    /// `x` axis of its Stokes frame.
    pub stokes_x: Vector3<f64>,
    /// Its ray index (eq. S14).
    pub ray_index: f64,
}

/// [`crate::optics::lobes::scatter`] for a surface where [`applies`] holds: the lobes of light
/// arriving from the local direction `towards_light` (unit).
pub fn scatter_clear(
    surface: &Surface,
    towards_light: Vector3<f64>,
    incident: Incident,
) -> Result<Event> {
    let (mut reflected, mut transmitted) = ([None, None], [None, None]);
    let arrival = each_clear_lobe(surface, towards_light, incident, |_, is_reflected, lobe| {
        let side = if is_reflected {
            &mut reflected
        } else {
            &mut transmitted
        };
        side[usize::from(lobe.kind == ModeKind::E)] = Some(*lobe);
    })?;
    Ok(Event {
        incident_direction: arrival.direction,
        incident_stokes_x: arrival.stokes_x,
        incident_ray_index: arrival.ray_index,
        reflected,
        transmitted,
    })
}

/// [`scatter_clear`] lobe by lobe, without the event: `sink(arrival, reflected, lobe)` for each
/// outgoing lobe that carries power (reflections first, then in the order of [`Event`]'s
/// arrays); returns the incident wave.
pub fn each_clear_lobe(
    surface: &Surface,
    towards_light: Vector3<f64>,
    incident: Incident,
    mut sink: impl FnMut(&Arrival, bool, &Lobe),
) -> Result<Arrival> {
    let (frame, beta) = incidence(surface, towards_light, incident)?;
    let beta = beta.re;
    let crystal = surface.crystal_in(&frame);
    let eta = surface.exterior.eta_o.re;
    let w_squared = (eta - beta) * (eta + beta);
    let (q, w_e) = uniaxial_normals(&crystal, C64::new(beta, 0.0));
    let at = At {
        frame: &frame,
        beta,
        eta,
        towards_light,
        incident,
    };
    let sink = &mut sink;
    // The e-wave's exact flux when it propagates (as `modes::uniaxial_modes` takes it).
    let ek = (w_e.im == 0.0).then_some(w_e.re);
    if w_squared >= 0.0 && q.iter().all(|z| z.im == 0.0) {
        let (eps_o, eps_e) = (crystal.eps_o().re, crystal.eps_e().re);
        let fields = Fields::new(eps_o, eps_e, crystal.axis, beta);
        at.event(w_squared.sqrt(), q.map(|z| z.re), &fields, ek, sink)
    } else {
        let fields = Fields::new(
            crystal.eps_o(),
            crystal.eps_e(),
            crystal.axis,
            C64::new(beta, 0.0),
        );
        // The up-going exterior wave: propagating, or decaying upwards beyond the critical angle.
        let w = if w_squared >= 0.0 {
            C64::new(w_squared.sqrt(), 0.0)
        } else {
            C64::new(0.0, (-w_squared).sqrt())
        };
        at.event(w, q, &fields, ek, sink)
    }
}

/// The geometry of one event.
struct At<'a> {
    frame: &'a PlaneFrame,
    beta: f64,
    /// The exterior's index.
    eta: f64,
    towards_light: Vector3<f64>,
    incident: Incident,
}

impl At<'_> {
    /// The event with the exterior's up-going normal component `w`, the crystal's normal
    /// components `q = [o↓, e↓, o↑, e↑]` and fields, and the up-going e-wave's `(εk)_z` if it
    /// propagates: its lobes to `sink` ([`each_clear_lobe`]).
    fn event<T: Scalar<f64>>(
        &self,
        w: T,
        q: [T; 4],
        fields: &Fields<T>,
        ek: Option<f64>,
        sink: &mut impl FnMut(&Arrival, bool, &Lobe),
    ) -> Result<Arrival> {
        let down = [
            fields.ordinary(q[0]),
            fields.extraordinary(q[1], ek.map(|w| (true, -w))),
        ];
        let fresnel = UniaxialFresnel::new(T::one() * self.eta, w, [psi(&down[0]), psi(&down[1])])
            .ok_or_else(singular)?;
        let zero = T::zero();
        match self.incident {
            Incident::Outside => {
                // The incident s and p waves carry the same flux, ½ w.
                let p_in = incoming_power(0.5 * w.re())?;
                let arrival = Arrival {
                    direction: -self.towards_light,
                    stokes_x: self.frame.s,
                    ray_index: self.eta,
                };
                let (r, t) = fresnel.from_above();
                let out = Out {
                    arrival: &arrival,
                    reflected: true,
                    p_in,
                };
                self.exterior(w, r, &out, sink);
                let out = Out {
                    reflected: false,
                    ..out
                };
                self.crystal(ModeKind::O, q[0], &down[0], t[0], &out, sink);
                self.crystal(ModeKind::E, q[1], &down[1], t[1], &out, sink);
                Ok(arrival)
            }
            Incident::Inside(kind) => {
                let (up, q_in) = match kind {
                    ModeKind::E => (fields.extraordinary(q[3], ek.map(|w| (true, w))), q[3]),
                    _ => (fields.ordinary(q[2]), q[2]),
                };
                let p_in = incoming_power(up.flux.abs())?;
                let ray = self.ray(q_in, &up);
                let arrival = Arrival {
                    direction: -self.towards_light,
                    stokes_x: ray.stokes_x,
                    ray_index: ray.index,
                };
                let (c, b) = fresnel.from_below(&psi(&up));
                let out = Out {
                    arrival: &arrival,
                    reflected: true,
                    p_in,
                };
                self.crystal(ModeKind::O, q[0], &down[0], [c[0], zero], &out, sink);
                self.crystal(ModeKind::E, q[1], &down[1], [c[1], zero], &out, sink);
                let out = Out {
                    reflected: false,
                    ..out
                };
                self.exterior(w, [[b[0], zero], [b[1], zero]], &out, sink);
                Ok(arrival)
            }
        }
    }

    /// The exterior's outgoing s/p lobe with amplitudes `a[out][in]` to `sink`, if it carries
    /// power (not beyond the critical angle). Its s wave `E = ŷ`, `H = (−w, 0, β)` has flux
    /// `½ w`.
    fn exterior<T: Scalar<f64>>(
        &self,
        w: T,
        a: [[T; 2]; 2],
        out: &Out,
        sink: &mut impl FnMut(&Arrival, bool, &Lobe),
    ) {
        let flux = 0.5 * w.re();
        let k = Vector3::new(self.beta, 0.0, w.re());
        if !carries(flux, 1.0, (w.norm_sqr() + self.beta * self.beta).sqrt()) {
            return;
        }
        let direction = self.frame.to_local(k / k.norm());
        let f = (flux / out.p_in).sqrt();
        let c = |z: T| (z * f).complex();
        let jones = Matrix2::new(c(a[0][0]), c(a[0][1]), c(a[1][0]), c(a[1][1]));
        // From inside, the incident crystal wave is the `x` state of its frame alone.
        let mueller = if out.reflected {
            mueller::from_jones(&jones)
        } else {
            mueller::from_jones_column(jones[(0, 0)], jones[(1, 0)])
        };
        let lobe = Lobe {
            kind: ModeKind::S,
            direction,
            wave_normal: direction,
            stokes_x: self.frame.s,
            jones,
            mueller,
            ray_index: k.norm(),
        };
        sink(out.arrival, out.reflected, &lobe);
    }

    /// The outgoing crystal wave `kind` of normal component `q` and fields `wave`, with
    /// amplitudes `a` for the incoming `[s, p]` (from outside) or `[wave, —]` (from inside), to
    /// `sink` if it carries power (not evanescent).
    fn crystal<T: Scalar<f64>>(
        &self,
        kind: ModeKind,
        q: T,
        wave: &Wave<T>,
        a: [T; 2],
        out: &Out,
        sink: &mut impl FnMut(&Arrival, bool, &Lobe),
    ) {
        if !carries(wave.flux, size(&wave.e), size(&wave.h)) {
            return;
        }
        let ray = self.ray(q, wave);
        let f = (wave.flux.abs() / out.p_in).sqrt();
        let (a0, a1) = ((a[0] * f).complex(), (a[1] * f).complex());
        let zero = C64::new(0.0, 0.0);
        let k = Vector3::new(self.beta, 0.0, q.re());
        let lobe = Lobe {
            kind,
            direction: ray.direction,
            wave_normal: self.frame.to_local(k / k.norm()),
            stokes_x: ray.stokes_x,
            jones: Matrix2::new(a0, a1, zero, zero),
            mueller: mueller::from_jones_row(a0, a1),
            ray_index: ray.index,
        };
        sink(out.arrival, out.reflected, &lobe);
    }

    /// The ray of a crystal wave that carries power (its field is real).
    fn ray<T: Scalar<f64>>(&self, q: T, wave: &Wave<T>) -> Ray {
        let re = |v: &[T; 3]| Vector3::new(v[0].re(), v[1].re(), v[2].re());
        let (e, h) = (re(&wave.e), re(&wave.h));
        let s = e.cross(&h);
        let s = s / s.norm();
        let index = self.beta * s.x + q.re() * s.z;
        let (d, e) = (self.frame.to_local(s), self.frame.to_local(e));
        let mut x = e - d * d.dot(&e);
        if x.norm() < 1e-12 {
            x = self.frame.s - d * d.dot(&self.frame.s);
        }
        Ray {
            direction: d,
            stokes_x: x.normalize(),
            index,
        }
    }
}

/// Where an event's outgoing lobes go: the incident wave, the side and its flux.
struct Out<'a> {
    arrival: &'a Arrival,
    reflected: bool,
    p_in: f64,
}

/// A crystal wave's ray: its direction and Stokes `x` axis (local frame) and its ray index.
struct Ray {
    direction: Vector3<f64>,
    stokes_x: Vector3<f64>,
    index: f64,
}

/// The tangential fields of a wave.
#[inline(always)]
fn psi<T: Scalar<f64>>(wave: &Wave<T>) -> Psi<T> {
    [wave.e[0], wave.e[1], wave.h[0], wave.h[1]]
}

/// The Hermitian norm of a 3-vector.
fn size<T: Scalar<f64>>(v: &[T; 3]) -> f64 {
    (v[0].norm_sqr() + v[1].norm_sqr() + v[2].norm_sqr()).sqrt()
}

/// True if a wave of normal flux `flux` and field norms `e`, `h` carries power through the
/// surface: the criterion of [`crate::optics::modes::Mode::is_evanescent`].
fn carries(flux: f64, e: f64, h: f64) -> bool {
    flux.abs() > 1e-12 * e * h
}

/// The incident flux, or the error of a wave that carries none (exactly grazing).
fn incoming_power(p: f64) -> Result<f64> {
    if p.is_nan() || p <= 0.0 {
        return Err(Error::new(
            "direction",
            "the incident wave carries no power through the surface (grazing)",
        ));
    }
    Ok(p)
}
