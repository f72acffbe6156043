//! The surface event of a clear crystal (lossless and birefringent) under a clear exterior, in
//! closed form: the [`Event`] that [`crate::optics::lobes::scatter`] computes through the
//! general interface, here from the closed-form amplitudes of
//! [`crate::optics::uniaxial_fresnel`] and the fields ([`crate::optics::fields`]) of only the waves
//! the event involves (the crystal's two down-going waves, and the incident one from inside),
//! in real arithmetic unless one of them or the exterior wave is evanescent. `scatter` is the
//! reference it is tested against (`tests/crystal_fast_path.rs`). Written over the reals of
//! [`crate::real`] ([`clear_event`]): a lobe that carries power in some lanes only comes with
//! the mask of those lanes.
//!
//! Every wave that carries power in a lossless medium has a real field, and its Stokes frame
//! ([`crate::optics::lobes`]) has `x` along that field made perpendicular to the ray, so its
//! unit Jones vector there is `(1, 0)`: a crystal wave's flux-normalised Jones matrix is its
//! row of amplitudes (outgoing) or column (incoming) in the first row or column, the rest 0.
//! Ray directions are the Poynting vectors' (eq. S12), ray indices `k·ŝ` (eq. S14).

use crate::cmath::{singular, Scalar};
use crate::error::{Error, Result};
use crate::optics::fields::{Fields, Wave};
use crate::optics::frame::PlaneFrame;
use crate::optics::lobes::{incidence, Event, Lobe};
use crate::optics::modes::{uniaxial_normals, ModeKind};
use crate::optics::mueller;
use crate::optics::surface::{Incident, Surface};
use crate::optics::uniaxial_fresnel::{Psi, UniaxialFresnel};
use crate::real::complex::{self as cx, Cx};
use crate::real::{Mask, Real};
use nalgebra::{Matrix2, Vector3};

/// True if [`scatter_clear`] serves `surface`: a lossless birefringent crystal under a lossless
/// exterior (an isotropic one has the closed form of [`crate::render::isotropic`]).
pub fn applies(surface: &Surface) -> bool {
    let (x, c) = (&surface.exterior, &surface.crystal);
    x.is_lossless() && x.is_isotropic() && c.is_lossless() && !c.is_isotropic()
}

/// The incident wave of an event (the fields of [`Event`] that describe it), over the reals `T`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arrival<T: Real = f64> {
    /// Unit propagation direction (ray direction), local frame.
    pub direction: Vector3<T>,
    /// `x` axis of its Stokes frame.
    pub stokes_x: Vector3<T>,
    /// Its ray index (eq. S14).
    pub ray_index: T,
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
    clear_event(surface, towards_light, incident, true, |a, r, l, _| {
        sink(a, r, l)
    })
}

/// [`each_clear_lobe`] over the reals `T`: `sink(arrival, reflected, lobe, carries)` for each
/// outgoing lobe that carries power in some lanes (`carries`: in which; on `f64` only those that
/// do, with `true`). The lanes of `live` fail where the event cannot be computed (a grazing
/// incident wave, a singular boundary system); the others, whose results a recorded program
/// discards, compute finite numbers.
pub fn clear_event<T: Real>(
    surface: &Surface<T>,
    towards_light: Vector3<T>,
    incident: Incident,
    live: T::Mask,
    mut sink: impl FnMut(&Arrival<T>, bool, &Lobe<T>, T::Mask),
) -> Result<Arrival<T>> {
    let (frame, beta) = incidence(surface, towards_light, incident, live)?;
    let beta = beta.re;
    let crystal = surface.crystal_in(&frame);
    let eta = surface.exterior.eta_o.re;
    let w_squared = (eta - beta) * (eta + beta);
    let (q, w_e) = uniaxial_normals(&crystal, cx::real(beta));
    let at = At {
        frame: &frame,
        beta,
        eta,
        towards_light,
        incident,
        live,
    };
    let sink = &mut sink;
    let zero = T::zero();
    // The e-wave's exact flux where it propagates (as `modes::uniaxial_modes` takes it).
    let propagates = w_e.im.equals(zero);
    let ek = (propagates.known() != Some(false)).then_some((propagates, w_e.re));
    let real = q
        .iter()
        .fold(w_squared.ge(zero), |m, z| m & z.im.equals(zero));
    if real.surely() {
        let (eps_o, eps_e) = (crystal.eps_o().re, crystal.eps_e().re);
        let fields = Fields::new(eps_o, eps_e, crystal.axis, beta);
        at.event(w_squared.sqrt(), q.map(|z| z.re), &fields, ek, sink)
    } else {
        let fields = Fields::new(
            crystal.eps_o(),
            crystal.eps_e(),
            crystal.axis,
            cx::real(beta),
        );
        // The up-going exterior wave: propagating, or decaying upwards beyond the critical angle.
        let w = w_squared.ge(zero).when(
            || Cx::new(w_squared.safe_sqrt(), zero),
            || Cx::new(zero, (-w_squared).safe_sqrt()),
        );
        at.event(w, q, &fields, ek, sink)
    }
}

/// The geometry of one event.
struct At<'a, T: Real> {
    frame: &'a PlaneFrame<T>,
    beta: T,
    /// The exterior's index.
    eta: T,
    towards_light: Vector3<T>,
    incident: Incident,
    /// The lanes whose failures count ([`clear_event`]).
    live: T::Mask,
}

impl<T: Real> At<'_, T> {
    /// The event with the exterior's up-going normal component `w`, the crystal's normal
    /// components `q = [o↓, e↓, o↑, e↑]` and fields, and the up-going e-wave's `(εk)_z` where it
    /// propagates: its lobes to `sink` ([`clear_event`]).
    fn event<S: Scalar<T>>(
        &self,
        w: S,
        q: [S; 4],
        fields: &Fields<S, T>,
        ek: Option<(T::Mask, T)>,
        sink: &mut impl FnMut(&Arrival<T>, bool, &Lobe<T>, T::Mask),
    ) -> Result<Arrival<T>> {
        let down = [
            fields.ordinary(q[0]),
            fields.extraordinary(q[1], ek.map(|(m, w)| (m, -w))),
        ];
        let (fresnel, degenerate) =
            UniaxialFresnel::solved(S::one() * self.eta, w, [psi(&down[0]), psi(&down[1])]);
        (self.live & degenerate).fail(singular)?;
        let zero = S::zero();
        match self.incident {
            Incident::Outside => {
                // The incident s and p waves carry the same flux, ½ w.
                let (p_in, _) = self.incoming_power(w.re() * 0.5)?;
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
                    ModeKind::E => (fields.extraordinary(q[3], ek), q[3]),
                    _ => (fields.ordinary(q[2]), q[2]),
                };
                let (p_in, carried) = self.incoming_power(up.flux.abs())?;
                let ray = self.ray(q_in, &up, carried);
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

    /// The exterior's outgoing s/p lobe with amplitudes `a[out][in]` to `sink`, where it carries
    /// power (not beyond the critical angle). Its s wave `E = ŷ`, `H = (−w, 0, β)` has flux
    /// `½ w`.
    fn exterior<S: Scalar<T>>(
        &self,
        w: S,
        a: [[S; 2]; 2],
        out: &Out<T>,
        sink: &mut impl FnMut(&Arrival<T>, bool, &Lobe<T>, T::Mask),
    ) {
        let flux = w.re() * 0.5;
        let k = Vector3::new(self.beta, T::zero(), w.re());
        let carries = carries(
            flux,
            T::one(),
            (w.norm_sqr() + self.beta * self.beta).sqrt(),
        );
        if carries.known() == Some(false) {
            return;
        }
        let k_norm = k.dot(&k).sqrt();
        let direction = self.frame.to_local(k / k_norm);
        let f = (flux / out.p_in).sqrt();
        let c = |z: S| (z * f).complex();
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
            ray_index: k_norm,
        };
        sink(out.arrival, out.reflected, &lobe, carries);
    }

    /// The outgoing crystal wave `kind` of normal component `q` and fields `wave`, with
    /// amplitudes `a` for the incoming `[s, p]` (from outside) or `[wave, —]` (from inside), to
    /// `sink` where it carries power (not evanescent).
    fn crystal<S: Scalar<T>>(
        &self,
        kind: ModeKind,
        q: S,
        wave: &Wave<S, T>,
        a: [S; 2],
        out: &Out<T>,
        sink: &mut impl FnMut(&Arrival<T>, bool, &Lobe<T>, T::Mask),
    ) {
        let carries = carries(wave.flux, size(&wave.e), size(&wave.h));
        if carries.known() == Some(false) {
            return;
        }
        let ray = self.ray(q, wave, carries);
        let f = (wave.flux.abs() / out.p_in).sqrt();
        let (a0, a1) = ((a[0] * f).complex(), (a[1] * f).complex());
        let zero = cx::real(T::zero());
        let k = Vector3::new(self.beta, T::zero(), q.re());
        let lobe = Lobe {
            kind,
            direction: ray.direction,
            wave_normal: self.frame.to_local(k / k.dot(&k).sqrt()),
            stokes_x: ray.stokes_x,
            jones: Matrix2::new(a0, a1, zero, zero),
            mueller: mueller::from_jones_row(a0, a1),
            ray_index: ray.index,
        };
        sink(out.arrival, out.reflected, &lobe, carries);
    }

    /// The ray of a crystal wave where it carries power (`carries`; its field is real there; in
    /// the other lanes finite numbers).
    fn ray<S: Scalar<T>>(&self, q: S, wave: &Wave<S, T>, carries: T::Mask) -> Ray<T> {
        let re = |v: &[S; 3]| Vector3::new(v[0].re(), v[1].re(), v[2].re());
        let (e, h) = (re(&wave.e), re(&wave.h));
        let s = e.cross(&h);
        let s_norm = s.dot(&s).sqrt();
        let s = s / carries.when(|| s_norm, T::one);
        let index = self.beta * s.x + q.re() * s.z;
        let (d, e) = (self.frame.to_local(s), self.frame.to_local(e));
        let x = e - d * d.dot(&e);
        let along = x.dot(&x).sqrt().lt(T::cst(1e-12));
        let x = along.when(|| self.frame.s - d * d.dot(&self.frame.s), || x);
        let x_norm = x.dot(&x).sqrt();
        Ray {
            direction: d,
            stokes_x: x / carries.when(|| x_norm, T::one),
            index,
        }
    }

    /// The incident flux `p` (one where it is none) and where it carries power; the error of a
    /// wave that carries none (exactly grazing) in the lanes of `live`.
    fn incoming_power(&self, p: T) -> Result<(T, T::Mask)> {
        let carried = p.gt(T::zero());
        (self.live & !carried).fail(|| {
            Error::new(
                "direction",
                "the incident wave carries no power through the surface (grazing)",
            )
        })?;
        Ok((carried.when(|| p, T::one), carried))
    }
}

/// Where an event's outgoing lobes go: the incident wave, the side and its flux.
struct Out<'a, T: Real> {
    arrival: &'a Arrival<T>,
    reflected: bool,
    p_in: T,
}

/// A crystal wave's ray: its direction and Stokes `x` axis (local frame) and its ray index.
struct Ray<T: Real> {
    direction: Vector3<T>,
    stokes_x: Vector3<T>,
    index: T,
}

/// The tangential fields of a wave.
#[inline(always)]
fn psi<T: Real, S: Scalar<T>>(wave: &Wave<S, T>) -> Psi<S> {
    [wave.e[0], wave.e[1], wave.h[0], wave.h[1]]
}

/// The Hermitian norm of a 3-vector.
fn size<T: Real, S: Scalar<T>>(v: &[S; 3]) -> T {
    (v[0].norm_sqr() + v[1].norm_sqr() + v[2].norm_sqr()).sqrt()
}

/// Where a wave of normal flux `flux` and field norms `e`, `h` carries power through the
/// surface: the criterion of [`crate::optics::modes::Mode::is_evanescent`].
fn carries<T: Real>(flux: T, e: T, h: T) -> T::Mask {
    flux.abs().gt(e * 1e-12 * h)
}
