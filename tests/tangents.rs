//! Derivatives of sampled lobes (`render::tangents`, the bridge's `sample_*_tangents`): against
//! closed forms differentiated independently here (Fresnel reflection and Snell refraction of a
//! dielectric interface, the Airy reflectance of an isotropic plate, by complex-step
//! differentiation of formulas written in this file), across normal incidence (where the core's
//! own frames turn abruptly), and the error of the production step against Richardson
//! extrapolation over random plates and crystal surfaces (the bound stated in
//! docs/gradients.md).

use birefringent::ffi::bridge::{
    CrystalLanes, PlateCall, PlateLanes, Samples, Status, Tangent, Tangents, Transport as T,
};
use birefringent::ffi::{
    band_spectrum, colour_channel_spectrum, crystal_tangents_available, exact_spectrum,
    new_materials, plate_tangents_available, sample_crystal, sample_crystal_tangents, sample_plate,
    sample_plate_tangents, srgb_spectrum, Materials, PlateSpectrum,
};
use birefringent::material::Material;
use birefringent::optics::medium::Uniaxial;
use birefringent::optics::surface::Surface;
use birefringent::params::Thickness;
use birefringent::render::choice::{choose, Choice};
use birefringent::render::crystal::crystal_slots;
use birefringent::render::plate::{plate_lobes, PlateQuery};
use birefringent::render::slots::Slots;
use birefringent::render::tangents::{
    Columns, Input, Lane, Point, Stencil, RELATIVE_STEP, STENCIL,
};
use birefringent::render::thin::Spectrum;
use birefringent::render::Transport;
use birefringent::{Result, C64};
use nalgebra::Vector3;

mod common;
use common::Rng;

/// Step of complex-step differentiation: `f'(x) = Im f(x + ih) / h` to rounding for an
/// analytic `f`.
const CS: f64 = 1e-30;

/// The fixed part of a plate query.
#[derive(Clone)]
struct PlateSetup {
    ext: f64,
    exit: f64,
    waves: Vec<f64>,
    transport: Transport,
    intensity_only: bool,
}

impl PlateSetup {
    fn at(&self, p: &Point) -> Result<Vec<Slots<2>>> {
        let (s, c) = p.axis_angle_deg.to_radians().sin_cos();
        let axis = Vector3::new(
            c * p.axis.x - s * p.axis.y,
            s * p.axis.x + c * p.axis.y,
            p.axis.z,
        );
        let q = PlateQuery::new(
            p.material,
            p.birefringence,
            C64::new(self.ext, 0.0),
            C64::new(self.exit, 0.0),
            axis,
            Thickness::from_nm(p.thickness_nm)?,
            true,
            true,
            self.intensity_only,
        )?;
        let mut w = [0.0; 4];
        w[..self.waves.len()].copy_from_slice(&self.waves);
        let spectrum = Spectrum::Bands {
            wavelengths_nm: w,
            count: self.waves.len(),
            fwhm_nm: 0.0,
        };
        plate_lobes(&q, &spectrum, p.wi, self.transport)
    }
}

/// The fixed part of a crystal query.
#[derive(Clone)]
struct CrystalSetup {
    ext: f64,
    waves: Vec<f64>,
    transport: Transport,
}

impl CrystalSetup {
    fn at(&self, p: &Point) -> Result<Vec<Slots<9>>> {
        self.waves
            .iter()
            .map(|&l| {
                let (o, e) = p.material.indices(l, 0.0)?;
                let surface = Surface::new(C64::new(self.ext, 0.0), Uniaxial::new(o, e, p.axis)?)?;
                crystal_slots(&surface, p.wi, self.transport)
            })
            .collect()
    }
}

fn point(material: Material, wi: Vector3<f64>) -> Point {
    Point {
        material,
        birefringence: 0.0,
        thickness_nm: 0.0,
        axis_angle_deg: 0.0,
        axis: Vector3::x(),
        wi,
    }
}

fn constant(o: f64, e: f64) -> Material {
    Material::constant(C64::new(o, 0.0), C64::new(e, 0.0)).unwrap()
}

/// Unpolarised Fresnel reflectance from index `n1` into `n2` at angle `theta`, written with
/// complex arithmetic so that it can be differentiated by complex step.
fn fresnel_r(n1: C64, n2: C64, theta: C64) -> C64 {
    let ci = theta.cos();
    let st = n1 * theta.sin() / n2;
    let ct = (C64::new(1.0, 0.0) - st * st).sqrt();
    let rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    let rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    (rs * rs + rp * rp) * 0.5
}

/// The refracted direction from `n1` into `n2` (crystal below) for `wi` in the x-z plane at
/// angle `theta`.
fn snell_wo(n1: C64, n2: C64, theta: C64) -> [C64; 3] {
    let st = n1 * theta.sin() / n2;
    let ct = (C64::new(1.0, 0.0) - st * st).sqrt();
    [-st, C64::new(0.0, 0.0), -ct]
}

fn cs_derivative(f: impl Fn(C64) -> C64, x: f64) -> f64 {
    f(C64::new(x, CS)).im / CS
}

fn close(a: f64, b: f64, rel: f64, what: &str) {
    assert!(
        (a - b).abs() <= rel * b.abs().max(1e-12),
        "{what}: {a} vs {b} (relative {:.2e})",
        (a - b).abs() / b.abs()
    );
}

/// The stencils the closed forms are checked with, and the tolerance of each: the production
/// one (central differences, ~1e-9 here), and forward differences (measured 3e-6 to 1.5e-5
/// here), the cheaper alternative docs/gradients.md weighs.
const METHODS: [(Stencil, f64, f64); 2] = [
    (STENCIL, RELATIVE_STEP, 1e-7),
    (Stencil::Forward, 1e-5, 1e-4),
];

/// The lane's derivatives for `inputs`, with the choice fixed to `slot` (probability 1), by
/// the production stencil.
fn plate_derivatives(setup: &PlateSetup, p: Point, slot: usize, inputs: &[Input]) -> Columns {
    plate_derivatives_with(setup, p, slot, inputs, (STENCIL, RELATIVE_STEP))
}

fn plate_derivatives_with(
    setup: &PlateSetup,
    p: Point,
    slot: usize,
    inputs: &[Input],
    (stencil, step): (Stencil, f64),
) -> Columns {
    let lobes = setup.at(&p).unwrap();
    let at = |q: &Point| setup.at(q);
    Lane {
        point: p,
        transport: setup.transport,
        bulk: false,
        shortest_nm: setup.waves.iter().copied().fold(f64::INFINITY, f64::min),
        lobes: &lobes,
        choice: Choice {
            slot,
            pdf: 1.0,
            hero: 0,
        },
        intensity_only: setup.intensity_only,
        at: &at,
    }
    .derivatives_with(inputs, step, stencil)
}

/// A dielectric interface (an isotropic crystal, n = 1.5 under air): the derivatives of the
/// reflectance and of the transmittance (Importance mode: `M00 = R`, `1 - R`) and of the
/// refracted direction with respect to the index and the angle of incidence, against the
/// complex-step derivatives of Fresnel's and Snell's laws. The index's derivative is split
/// between `eta_o` and `eta_e` (an isotropic crystal stays isotropic), half each.
#[test]
fn dielectric_interface_matches_fresnel_and_snell() {
    let (n, theta) = (1.5, 35f64.to_radians());
    let wi = Vector3::new(theta.sin(), 0.0, theta.cos());
    let setup = CrystalSetup {
        ext: 1.0,
        waves: vec![550.0],
        transport: Transport::Importance,
    };
    let p = point(constant(n, n), wi);
    let lobes = setup.at(&p).unwrap();
    let at = |q: &Point| setup.at(q);
    let inputs = [Input::EtaO, Input::EtaE, Input::Wi];
    let one = C64::new(1.0, 0.0);
    let dr_dn = cs_derivative(|x| fresnel_r(one, x, C64::new(theta, 0.0)), n);
    let dr_dtheta = cs_derivative(|t| fresnel_r(one, C64::new(n, 0.0), t), theta);
    let dtheta = [theta.cos(), 0.0, -theta.sin()];
    for ((slot, sign), (stencil, step, tol)) in [(0, 1.0), (1, -1.0)]
        .into_iter()
        .flat_map(|s| METHODS.map(|m| (s, m)))
    {
        let d = Lane {
            point: p,
            transport: setup.transport,
            bulk: true,
            shortest_nm: 550.0,
            lobes: &lobes,
            choice: Choice {
                slot,
                pdf: 1.0,
                hero: 0,
            },
            intensity_only: true,
            at: &at,
        }
        .derivatives_with(&inputs, step, stencil);
        close(d.value[0][0][0], 0.5 * sign * dr_dn, tol, "d M00 / d eta_o");
        close(d.value[1][0][0], 0.5 * sign * dr_dn, tol, "d M00 / d eta_e");
        let along: f64 = (0..3).map(|j| d.value[2 + j][0][0] * dtheta[j]).sum();
        close(along, sign * dr_dtheta, tol, "d M00 / d theta");
        if slot == 1 {
            for j in [0, 2] {
                let dn = cs_derivative(|x| snell_wo(one, x, C64::new(theta, 0.0))[j], n);
                close(d.wo[0][j] + d.wo[1][j], dn, tol, "d wo / d eta");
                let dt = cs_derivative(|t| snell_wo(one, C64::new(n, 0.0), t)[j], theta);
                let along: f64 = (0..3).map(|k| d.wo[2 + k][j] * dtheta[k]).sum();
                close(along, dt, tol, "d wo / d theta");
            }
        }
    }
}

/// Airy reflectance of a lossless isotropic layer of index `n` and thickness `d` (nm) in air at
/// normal incidence, at `lambda` (nm).
fn airy_r(n: C64, d: C64, lambda: f64) -> C64 {
    let rho = ((n - 1.0) / (n + 1.0)).powi(2);
    let f = rho * 4.0 / ((-rho + 1.0) * (-rho + 1.0));
    let s = (n * d * (2.0 * std::f64::consts::PI / lambda)).sin();
    f * s * s / (f * s * s + 1.0)
}

/// An isotropic plate at normal incidence: the reflectance's derivatives with respect to the
/// thickness and the indices against the Airy formula. With the axis in the plate, light
/// polarised along it sees `eta_e` and across it `eta_o`, so each index carries half of
/// `dR/dn` (partial derivatives at the isotropic point, where the core's closed-form etalon
/// gives way to the general slab on either side of the difference).
#[test]
fn isotropic_plate_matches_airy() {
    let (n, d, lambda) = (1.5, 2000.0, 550.0);
    let setup = PlateSetup {
        ext: 1.0,
        exit: 1.0,
        waves: vec![lambda],
        transport: Transport::Importance,
        intensity_only: true,
    };
    let mut p = point(constant(n, n), Vector3::z());
    p.thickness_nm = d;
    let dr_dd = cs_derivative(|x| airy_r(C64::new(n, 0.0), x, lambda), d);
    let dr_dn = cs_derivative(|x| airy_r(x, C64::new(d, 0.0), lambda), n);
    for (stencil, step, tol) in METHODS {
        let inputs = [Input::Thickness, Input::EtaO, Input::EtaE];
        let cols = plate_derivatives_with(&setup, p, 0, &inputs, (stencil, step));
        // The slab's own rounding at 2 um: 1e-6 of the derivative with central differences.
        let tol = tol.max(1e-6);
        close(cols.value[0][0][0], dr_dd, tol, "dR/dd");
        close(cols.value[1][0][0], 0.5 * dr_dn, tol, "dR/d eta_o");
        close(cols.value[2][0][0], 0.5 * dr_dn, tol, "dR/d eta_e");
    }
}

/// A birefringent plate's transmitted Mueller matrix (polarised, Radiance mode) differentiated
/// with respect to `wi`: continuous through normal incidence, where the plane of incidence
/// (the core's own frames) turns abruptly; taken in Mitsuba's implicit frames the derivative
/// at `wi = z` agrees with the ones 1e-6 rad away in two azimuths to 1e-4 of its size
/// (measured 1.6e-5; with the core's frames differentiated instead it was off by its own size).
#[test]
fn wi_derivatives_are_continuous_through_normal_incidence() {
    let setup = PlateSetup {
        ext: 1.0,
        exit: 1.0,
        waves: vec![450.0, 550.0, 650.0],
        transport: Transport::Radiance,
        intensity_only: false,
    };
    let mut p = point(constant(1.54, 1.55), Vector3::z());
    p.thickness_nm = 20_000.0;
    p.axis = Vector3::new(1.0, 0.3, 0.6);
    let at_normal = plate_derivatives(&setup, p, 1, &[Input::Wi]);
    let tilt = 1e-6f64;
    for (x, y) in [(0.6, 0.8), (-0.8, 0.6)] {
        p.wi = Vector3::new(tilt.sin() * x, tilt.sin() * y, tilt.cos());
        let off = plate_derivatives(&setup, p, 1, &[Input::Wi]);
        let mut size = 0.0f64;
        let mut diff = 0.0f64;
        for k in 0..3 {
            for c in 0..3 {
                for e in 0..16 {
                    size = size.max(at_normal.value[k][c][e].abs());
                    diff = diff.max((at_normal.value[k][c][e] - off.value[k][c][e]).abs());
                }
            }
        }
        println!("normal incidence: {diff:.1e} of {size:.2}");
        assert!(size > 0.1, "derivative {size}");
        assert!(diff < 1e-4 * size, "{diff} vs {size}");
    }
}

/// A random lane: a plate (thickness up to 6 mm, constant or named indices, stress
/// birefringence, absorption) or a crystal surface, random direction, wavelengths, transport,
/// output kind and choice.
enum Setup {
    Plate(PlateSetup),
    Crystal(CrystalSetup),
}

fn random_lane(rng: &mut Rng) -> (Setup, Point, bool) {
    let waves: Vec<f64> = (0..1 + rng.index(4))
        .map(|_| rng.range(380.0, 720.0))
        .collect();
    let transport = if rng.chance(0.5) {
        Transport::Radiance
    } else {
        Transport::Importance
    };
    let intensity_only = rng.chance(0.3);
    let mut wi = rng.unit_vector();
    while wi.z.abs() < 0.1 {
        wi = rng.unit_vector();
    }
    let plate = rng.chance(0.6);
    let no = rng.range(1.3, 2.0);
    let material = if plate && rng.chance(0.2) {
        Material::named("quartz", 0.0, rng.range(0.0, 1e-4)).unwrap()
    } else if rng.chance(0.3) {
        constant(no, no)
    } else {
        let k = if plate && rng.chance(0.3) { 1e-4 } else { 0.0 };
        Material::constant(C64::new(no, k), C64::new(no + rng.range(-0.2, 0.2), 0.0)).unwrap()
    };
    let mut p = point(material, wi);
    p.axis = rng.unit_vector() * rng.range(0.5, 2.0);
    if plate {
        p.thickness_nm = 10f64.powf(rng.range(1.0, 6.8));
        p.birefringence = if rng.chance(0.5) {
            rng.range(0.0, 1e-3)
        } else {
            0.0
        };
        p.axis_angle_deg = rng.range(-90.0, 90.0);
        let (ext, exit) = (rng.range(1.0, 1.6), rng.range(1.0, 1.6));
        let setup = PlateSetup {
            ext,
            exit,
            waves,
            transport,
            intensity_only,
        };
        (Setup::Plate(setup), p, intensity_only)
    } else {
        let setup = CrystalSetup {
            ext: rng.range(1.0, 1.2),
            waves,
            transport,
        };
        (Setup::Crystal(setup), p, intensity_only)
    }
}

/// Over random plates and crystal surfaces, the production derivatives (every input) against
/// Richardson's extrapolation of central differences of relative steps 1e-3 and 2e-3 (error
/// O(h^4)), the error of an input's columns relative to their largest entry (below 1e-6 of
/// the input's natural scale counts as zero). Measured over 1200 lanes (8089 inputs), central
/// differences of relative step 1e-4 (the production choice): median 9.7e-9, 99th percentile
/// 6.1e-6, 99.9th 5.2e-5, largest 1.1e-2 (`kappa` of a millimetre absorbing plate near total
/// internal reflection, where the absorption's scale is the long internal path, not the
/// thickness); relative step 3e-5: 99th percentile 1.6e-5 (rounding); 3e-4: median 5.5e-8
/// (truncation). Forward differences (half the queries) of relative step 1e-5: median 7.2e-6,
/// 99th 1.4e-4, 99.9th 6.2e-4 (1e-6: median 9.6e-7 but 99th 8.9e-4 from rounding).
/// docs/gradients.md states the bound asserted here.
#[test]
fn production_step_error_is_bounded() {
    let mut rng = Rng::new(23);
    let mut errors = Vec::new();
    let mut lanes = 0;
    while lanes < 1200 {
        let (setup, p, intensity_only) = random_lane(&mut rng);
        let u = rng.uniform();
        let (inputs, shortest): (Vec<Input>, f64) = match &setup {
            Setup::Plate(s) => {
                let mut v = vec![
                    Input::Thickness,
                    Input::Birefringence,
                    Input::AxisAngle,
                    Input::KappaO,
                    Input::KappaE,
                    Input::OpticAxis,
                    Input::Wi,
                ];
                if !p.material.is_dispersive() {
                    v.extend([Input::EtaO, Input::EtaE]);
                }
                (v, s.waves.iter().copied().fold(f64::INFINITY, f64::min))
            }
            Setup::Crystal(s) => (
                vec![Input::EtaO, Input::EtaE, Input::OpticAxis, Input::Wi],
                s.waves.iter().copied().fold(f64::INFINITY, f64::min),
            ),
        };
        let errs = match &setup {
            Setup::Plate(s) => {
                let Ok(lobes) = s.at(&p) else { continue };
                let at = |q: &Point| s.at(q);
                lane_errors(
                    &lobes,
                    &at,
                    p,
                    s.transport,
                    false,
                    shortest,
                    intensity_only,
                    u,
                    &inputs,
                )
            }
            Setup::Crystal(s) => {
                let Ok(lobes) = s.at(&p) else { continue };
                let at = |q: &Point| s.at(q);
                lane_errors(
                    &lobes,
                    &at,
                    p,
                    s.transport,
                    true,
                    shortest,
                    intensity_only,
                    u,
                    &inputs,
                )
            }
        };
        let Some(errs) = errs else { continue };
        errors.extend(errs);
        lanes += 1;
    }
    errors.sort_by(f64::total_cmp);
    let q = |f: f64| errors[((errors.len() - 1) as f64 * f) as usize];
    println!(
        "{} columns: median {:.1e}, 99% {:.1e}, 99.9% {:.1e}, max {:.1e}",
        errors.len(),
        q(0.5),
        q(0.99),
        q(0.999),
        q(1.0)
    );
    assert!(q(0.5) < 1e-7, "median {}", q(0.5));
    assert!(q(0.99) < 3e-5, "99th percentile {}", q(0.99));
    assert!(q(0.999) < 3e-4, "99.9th percentile {}", q(0.999));
}

/// The relative error of each derivative column of one lane (`None` if it samples nothing).
#[allow(clippy::too_many_arguments)]
fn lane_errors<const S: usize>(
    lobes: &[Slots<S>],
    at: &dyn Fn(&Point) -> Result<Vec<Slots<S>>>,
    p: Point,
    transport: Transport,
    bulk: bool,
    shortest_nm: f64,
    intensity_only: bool,
    u: f64,
    inputs: &[Input],
) -> Option<Vec<f64>> {
    let choice = choose(lobes, |_| true, u)?;
    let lane = Lane {
        point: p,
        transport,
        bulk,
        shortest_nm,
        lobes,
        choice,
        intensity_only,
        at,
    };
    let d = lane.derivatives(inputs);
    let (d1, d2) = (
        lane.derivatives_with(inputs, 1e-3, Stencil::Central),
        lane.derivatives_with(inputs, 2e-3, Stencil::Central),
    );
    let entries = if intensity_only { 1 } else { 16 };
    let mut out = Vec::new();
    let mut k = 0;
    for &input in inputs {
        let tiny = 1e-6 / lane.natural_scale(input);
        let column = |x: &Columns, c: usize| -> Vec<f64> {
            let mut v: Vec<f64> = x.wo[c].to_vec();
            for ch in 0..lobes.len() {
                v.extend_from_slice(&x.value[c][ch][..entries]);
            }
            v
        };
        let columns = k..k + input.columns();
        let reference: Vec<Vec<f64>> = columns
            .clone()
            .map(|c| {
                let (r1, r2) = (column(&d1, c), column(&d2, c));
                r1.iter()
                    .zip(&r2)
                    .map(|(x, y)| (4.0 * x - y) / 3.0)
                    .collect()
            })
            .collect();
        let size = reference
            .iter()
            .flatten()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        let err = columns
            .zip(&reference)
            .flat_map(|(c, r)| column(&d, c).into_iter().zip(r.clone()))
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        out.push(err / size.max(tiny));
        k += input.columns();
    }
    Some(out)
}

// ---- the bridge (`sample_plate_tangents`, `sample_crystal_tangents`) -----------------------

/// Owned output columns (intensity only: `value[0]`) and derivative columns.
struct Owned {
    status: Vec<Status>,
    component: Vec<u32>,
    pdf: Vec<f64>,
    eta: Vec<f64>,
    wo: [Vec<f64>; 3],
    value: Vec<f64>,
    d_wo: [Vec<f64>; 3],
    d_value: Vec<f64>,
}

impl Owned {
    fn new(n: usize, channels: usize, columns: usize) -> Self {
        Owned {
            status: vec![Status::Internal; n],
            component: vec![0; n],
            pdf: vec![f64::NAN; n],
            eta: vec![f64::NAN; n],
            wo: std::array::from_fn(|_| vec![f64::NAN; n]),
            value: vec![f64::NAN; n * channels],
            d_wo: std::array::from_fn(|_| vec![f64::NAN; n * columns]),
            d_value: vec![f64::NAN; n * channels * columns],
        }
    }

    fn views<'a>(&'a mut self, inputs: &'a [Tangent]) -> (Samples<'a>, Tangents<'a>) {
        let [a, b, c] = &mut self.wo;
        let [d, e, f] = &mut self.d_wo;
        let mut value = [&mut self.value[..]].into_iter();
        let mut d_value = [&mut self.d_value[..]].into_iter();
        let samples = Samples {
            status: &mut self.status,
            component: &mut self.component,
            pdf: &mut self.pdf,
            eta: &mut self.eta,
            wo: [a, b, c],
            in_stokes_x: [&mut [], &mut [], &mut []],
            out_stokes_x: [&mut [], &mut [], &mut []],
            value: std::array::from_fn(|_| value.next().unwrap_or_default()),
            message: String::new(),
        };
        let tangents = Tangents {
            inputs,
            wo: [d, e, f],
            value: std::array::from_fn(|_| d_value.next().unwrap_or_default()),
        };
        (samples, tangents)
    }
}

/// A plate batch of 6 lanes (one inactive) at thickness `t` nm: (status, owned outputs).
fn plate_batch(
    m: &Materials,
    spectrum: &PlateSpectrum,
    t: f64,
    inputs: &[Tangent],
) -> (Status, Owned) {
    let n = 6;
    let wis: Vec<Vector3<f64>> = (0..n)
        .map(|i| {
            Vector3::new(
                0.1 * i as f64,
                -0.05 * i as f64,
                if i % 2 == 0 { 1.0 } else { -1.0 },
            )
            .normalize()
        })
        .collect();
    let col = |k: usize| -> Vec<f64> { wis.iter().map(|w| w[k]).collect() };
    let (wx, wy, wz) = (col(0), col(1), col(2));
    let waves = [vec![450.0; 1], vec![560.0; 1], vec![630.0; 1]];
    let wave_refs: Vec<&[f64]> = waves.iter().map(|w| w.as_slice()).collect();
    let active: Vec<u8> = (0..n).map(|i| u8::from(i != 3)).collect();
    let sample: Vec<f64> = (0..n).map(|i| (i as f64 + 0.5) / n as f64).collect();
    let lanes = PlateLanes {
        count: n,
        active: &active,
        material: &[0],
        transport: &[T::Radiance],
        sample: &sample,
        wi: [&wx, &wy, &wz],
        wavelengths_nm: &wave_refs,
        ext_ior: &[1.0],
        exit_ior: &[1.3],
        optic_axis: [&[1.0], &[0.3], &[0.2]],
        axis_angle_deg: &[15.0],
        thickness_nm: &[t],
        birefringence: &[0.001],
    };
    let call = PlateCall {
        components: 3,
        intensity_only: true,
        absorbing_exit: false,
    };
    let columns: usize = inputs
        .iter()
        .map(|t| {
            if matches!(*t, Tangent::Wi | Tangent::OpticAxis) {
                3
            } else {
                1
            }
        })
        .sum();
    let mut o = Owned::new(n, 3, columns);
    let rc = {
        let (mut s, mut d) = o.views(inputs);
        if inputs.is_empty() {
            sample_plate(m, spectrum, &call, &lanes, &mut s)
        } else {
            sample_plate_tangents(m, spectrum, &call, &lanes, &mut d, &mut s)
        }
    };
    (rc, o)
}

/// The derivative columns through the bridge: the samples are the plain call's, bit for bit;
/// column k of lane i sits at `k * count + i` (channel c of the weight at
/// `(k * channels + c) * count + i`); an inactive lane has zero derivatives; the thickness
/// column equals central differences of the bridge's own lobes (`value * pdf`, intensity only)
/// over thickness (1e-6).
#[test]
fn bridge_columns_are_the_lanes_derivatives() {
    let mut m = new_materials();
    m.add_constant(1.54, 1.55, 0.0, 0.0).unwrap();
    let spectrum = exact_spectrum();
    let inputs = [Tangent::Wi, Tangent::Thickness];
    let (rc, plain) = plate_batch(&m, &spectrum, 2000.0, &[]);
    let (rc_t, with) = plate_batch(&m, &spectrum, 2000.0, &inputs);
    assert_eq!((rc, rc_t), (Status::Ok, Status::Ok));
    assert_eq!(plain.pdf, with.pdf);
    assert_eq!(plain.value, with.value);
    assert_eq!(plain.wo, with.wo);
    let (n, channels, h) = (6, 3, 1e-3);
    let (_, plus) = plate_batch(&m, &spectrum, 2000.0 + h, &[]);
    let (_, minus) = plate_batch(&m, &spectrum, 2000.0 - h, &[]);
    for i in 0..n {
        for c in 0..channels {
            let d = with.d_value[(3 * channels + c) * n + i]; // column 3: the thickness
            if i == 3 {
                assert_eq!(d, 0.0, "inactive lane");
                continue;
            }
            assert_eq!(plus.component[i], with.component[i]);
            let lobe = |o: &Owned| o.value[c * n + i] * o.pdf[i];
            let fd = (lobe(&plus) - lobe(&minus)) / (2.0 * h);
            let exact = d * with.pdf[i];
            assert!(
                (exact - fd).abs() <= 1e-6 * fd.abs().max(1e-6),
                "lane {i} channel {c}: {exact} vs {fd}"
            );
        }
    }
}

/// A query that cannot give derivatives says why, naming what to change, and writes nothing
/// else: the plate over a band, the sRGB channels or a colour channel; `eta_o` of a named
/// crystal; a plate's input of a crystal; `kappa` of a birefringent crystal; an input asked
/// twice; derivative columns of the wrong length.
#[test]
fn requests_without_derivatives_are_refused_with_the_reason() {
    let mut m = new_materials();
    m.add_constant(1.54, 1.55, 0.0, 0.0).unwrap();
    let mut named = new_materials();
    named.add_named("calcite", 0.0, 0.0).unwrap();
    let none: &[Tangent] = &[Tangent::Thickness];
    let err = |r: birefringent::Result<()>| r.unwrap_err().to_string();
    assert!(plate_tangents_available(&m, &exact_spectrum(), none).is_ok());
    let e = err(plate_tangents_available(&m, &band_spectrum(4.0), none));
    assert!(
        e.contains("filter_bandwidth") && e.contains("llvm_ad_spectral"),
        "{e}"
    );
    let e = err(plate_tangents_available(&m, &srgb_spectrum(), none));
    assert!(
        e.contains("llvm_ad_rgb") && e.contains("llvm_ad_spectral_polarized"),
        "{e}"
    );
    let channel = colour_channel_spectrum("srgb-d65:G").unwrap();
    let e = err(plate_tangents_available(&m, &channel, none));
    assert!(
        e.contains("llvm_ad_mono") && e.contains("srgb-d65:G"),
        "{e}"
    );
    let e = err(plate_tangents_available(
        &named,
        &exact_spectrum(),
        &[Tangent::EtaO],
    ));
    assert!(e.starts_with("eta_o"), "{e}");
    assert!(plate_tangents_available(&named, &exact_spectrum(), &[Tangent::KappaE]).is_ok());
    let e = err(crystal_tangents_available(&m, &[Tangent::AxisAngle]));
    assert!(e.starts_with("axis_angle") && e.contains("plate"), "{e}");
    let e = err(crystal_tangents_available(&m, &[Tangent::KappaO]));
    assert!(
        e.starts_with("kappa_o") && e.contains("birefringent"),
        "{e}"
    );
    let mut glass = new_materials();
    glass.add_constant(1.5, 1.5, 0.1, 0.1).unwrap();
    assert!(crystal_tangents_available(&glass, &[Tangent::KappaO, Tangent::EtaE]).is_ok());
    let e = err(crystal_tangents_available(&m, &[Tangent::Wi, Tangent::Wi]));
    assert!(e.contains("twice"), "{e}");
    // Columns of the wrong length: the call fails as a whole, with the column's name.
    let (rc, _) = plate_batch(&m, &band_spectrum(4.0), 2000.0, none);
    assert_eq!(rc, Status::Invalid);
    let mut o = Owned::new(1, 1, 1);
    o.d_value.push(0.0);
    let inputs = [Tangent::EtaO];
    let (mut s, mut d) = o.views(&inputs);
    let lanes = CrystalLanes {
        count: 1,
        active: &[1],
        material: &[0],
        transport: &[T::Radiance],
        sample: &[0.5],
        wi: [&[0.0], &[0.0], &[1.0]],
        wavelengths_nm: &[&[550.0]],
        ext_ior: &[1.0],
        optic_axis: [&[1.0], &[0.0], &[0.0]],
    };
    assert_eq!(
        sample_crystal_tangents(&m, 7, &lanes, &mut d, &mut s),
        Status::Invalid
    );
    assert!(s.message.contains("tangents.value"), "{}", s.message);
    let mut o = Owned::new(1, 1, 0);
    let (mut s, _) = o.views(&[]);
    assert_eq!(sample_crystal(&m, 7, &lanes, &mut s), Status::Ok);
}

/// An optic axis of any length (the plugins take one; the core uses its direction): the
/// derivatives with respect to the components of `s · a` are those with respect to the unit
/// axis `a` divided by `s` (`d/dv f(v/|v|) = (I − â âᵀ) ∇f / |v|`), and the derivative along
/// the axis itself is zero (its length changes nothing). A plate (transmission, polarised,
/// three wavelengths, tilted incidence) and a crystal surface (its e-refraction, whose
/// direction moves with the axis), for `s` = 0.4 and 2.5: each column within 1e-6 of the
/// largest (the central differences' own error is ~1e-9 here, measured).
#[test]
fn a_non_unit_axis_has_the_unit_axis_derivatives_over_its_length() {
    let plate = PlateSetup {
        ext: 1.0,
        exit: 1.2,
        waves: vec![450.0, 550.0, 650.0],
        transport: Transport::Radiance,
        intensity_only: false,
    };
    let crystal = CrystalSetup {
        ext: 1.0,
        waves: vec![450.0, 550.0, 650.0],
        transport: Transport::Importance,
    };
    let unit = Vector3::new(0.6, 0.3, 0.742).normalize();
    let wi = Vector3::new(0.4, -0.2, 0.8).normalize();
    let mut p = point(constant(1.54, 1.59), wi);
    p.thickness_nm = 12_000.0;
    let derivatives = |axis: Vector3<f64>, crystal_lane: bool| -> Columns {
        let mut q = p;
        q.axis = axis;
        if !crystal_lane {
            return plate_derivatives(&plate, q, 1, &[Input::OpticAxis]);
        }
        let lobes = crystal.at(&q).unwrap();
        let at = |r: &Point| crystal.at(r);
        Lane {
            point: q,
            transport: crystal.transport,
            bulk: true,
            shortest_nm: 450.0,
            lobes: &lobes,
            // The e-refraction's slot, chosen with probability 1.
            choice: Choice {
                slot: 2,
                pdf: 1.0,
                hero: 0,
            },
            intensity_only: false,
            at: &at,
        }
        .derivatives(&[Input::OpticAxis])
    };
    for crystal_lane in [false, true] {
        let reference = derivatives(unit, crystal_lane);
        let size = (0..3)
            .flat_map(|j| reference.value[j].iter().flatten().chain(&reference.wo[j]))
            .fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(size > 1e-3, "the axis changes nothing: {size}");
        // Along the axis: nothing.
        let radial = (0..16)
            .map(|e| {
                (0..3)
                    .map(|j| reference.value[j][0][e] * unit[j])
                    .sum::<f64>()
            })
            .fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(radial < 1e-9 * size, "along the axis: {radial:e}");
        for s in [0.4, 2.5] {
            let scaled = derivatives(unit * s, crystal_lane);
            let mut worst = 0.0f64;
            for j in 0..3 {
                for (a, b) in scaled.value[j]
                    .iter()
                    .flatten()
                    .zip(reference.value[j].iter().flatten())
                {
                    worst = worst.max((a * s - b).abs());
                }
                for (a, b) in scaled.wo[j].iter().zip(&reference.wo[j]) {
                    worst = worst.max((a * s - b).abs());
                }
            }
            println!("crystal {crystal_lane}, |axis| {s}: worst {worst:.1e} of {size:.2}");
            assert!(worst < 1e-6 * size, "|axis| {s}: {worst:e} of {size}");
        }
    }
}
