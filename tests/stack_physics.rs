//! Limits and identities of the exact stack: one layer is the plate, a layer split in two
//! equal halves is the layer, an index-matched isotropic layer changes nothing; zero-order and
//! achromatic quarter-wave plates and a Lyot filter against their design formulas; and energy:
//! `R + T = 1` for lossless stacks, `R + T <= 1` for absorbing ones (up to 10 layers and 10 mm,
//! incidence up to 89.9°).

use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::params::Thickness;
use birefringent::plate::slab::{Slab, Want};
use birefringent::stack::exact::StackBlocks;
use birefringent::stack::{Layer, Stack};
use birefringent::C64;
use nalgebra::{Matrix2, Vector3};
use std::f64::consts::PI;

mod common;
use common::Rng;

fn c(x: f64) -> C64 {
    C64::new(x, 0.0)
}

fn layer(material: Material, axis: Vector3<f64>, thickness_nm: f64) -> Layer {
    Layer::new(
        material,
        0.0,
        axis,
        Thickness::from_nm(thickness_nm).unwrap(),
    )
    .unwrap()
}

fn jones(stack: &Stack, lambda: f64, frame: &PlaneFrame, beta: C64) -> [Matrix2<C64>; 2] {
    let j = StackBlocks::new(stack, lambda, frame, beta)
        .unwrap()
        .jones(lambda, Want::BOTH)
        .unwrap();
    [j.r.unwrap(), j.t.unwrap()]
}

/// Largest entry difference of the Mueller matrices of two pairs of Jones matrices (global
/// phases do not matter to them).
fn mueller_difference(a: &[Matrix2<C64>; 2], b: &[Matrix2<C64>; 2]) -> f64 {
    use birefringent::optics::mueller::from_jones;
    (0..2)
        .map(|i| (from_jones(&a[i]) - from_jones(&b[i])).abs().max())
        .fold(0.0, f64::max)
}

/// The largest modulus of the entries of `m`.
fn largest(m: &Matrix2<C64>) -> f64 {
    m.iter().map(|z| z.norm()).fold(0.0, f64::max)
}

fn random_material(rng: &mut Rng, absorbing: bool) -> Material {
    let k = |rng: &mut Rng| if absorbing { rng.range(0.0, 0.3) } else { 0.0 };
    match rng.index(4) {
        0 => Material::named("quartz", 0.0, 0.0).unwrap(),
        1 => Material::named("calcite", 0.0, 0.0).unwrap(),
        _ => Material::constant(
            C64::new(rng.range(1.3, 2.5), k(rng)),
            C64::new(rng.range(1.3, 2.5), k(rng)),
        )
        .unwrap(),
    }
}

/// One layer: the stack is the slab of `plate::slab`, operation for operation (1e-12).
#[test]
fn one_layer_is_the_plate() {
    let mut rng = Rng::new(1);
    let mut worst = 0.0f64;
    for _ in 0..2000 {
        let absorbing = rng.chance(0.3);
        let material = random_material(&mut rng, absorbing);
        let l = layer(material, rng.unit_vector(), 10f64.powf(rng.range(1.0, 6.5)));
        let (n1, n3) = (rng.range(1.0, 1.8), rng.range(1.0, 1.8));
        let stack = Stack::new(vec![l], c(n1), c(n3)).unwrap();
        let lambda = rng.range(380.0, 780.0);
        let frame = PlaneFrame::from_azimuth(rng.range(0.0, 6.3));
        let beta = c(n1 * rng.range(0.0, 1.5).sin());
        let (eo, ee) = l.material.indices(lambda, 0.0).unwrap();
        let medium = birefringent::optics::medium::Uniaxial::new(eo, ee, l.axis).unwrap();
        let slab = Slab::new(
            c(n1),
            medium,
            c(n3),
            Thickness::from_nm(l.thickness_nm).unwrap(),
        )
        .unwrap()
        .optics(&frame, beta)
        .unwrap()
        .jones(lambda, Want::BOTH)
        .unwrap();
        let s = jones(&stack, lambda, &frame, beta);
        for (a, b) in [(s[0], slab.r.unwrap()), (s[1], slab.t.unwrap())] {
            worst = worst.max(largest(&(a - b)));
        }
    }
    println!("one layer vs the plate: worst Jones difference {worst:e}");
    assert!(worst < 1e-12, "{worst:e}");
}

/// A layer split into two equal halves (an interface between identical media, which reflects
/// nothing) is the layer: Jones matrices to 1e-9.
#[test]
fn a_layer_split_in_halves_is_the_layer() {
    let mut rng = Rng::new(2);
    let mut worst = 0.0f64;
    for _ in 0..1000 {
        let n = 1 + rng.index(5);
        let layers: Vec<Layer> = (0..n)
            .map(|_| {
                let absorbing = rng.chance(0.3);
                let m = random_material(&mut rng, absorbing);
                layer(m, rng.unit_vector(), 10f64.powf(rng.range(1.0, 5.5)))
            })
            .collect();
        let (n1, n3) = (rng.range(1.0, 1.8), rng.range(1.0, 1.8));
        let whole = Stack::new(layers.clone(), c(n1), c(n3)).unwrap();
        let k = rng.index(n);
        let half = Layer {
            thickness_nm: 0.5 * layers[k].thickness_nm,
            ..layers[k]
        };
        let mut split = layers.clone();
        split[k] = half;
        split.insert(k, half);
        let split = Stack::new(split, c(n1), c(n3)).unwrap();
        let lambda = rng.range(380.0, 780.0);
        let frame = PlaneFrame::from_azimuth(rng.range(0.0, 6.3));
        let beta = c(n1 * rng.range(0.0, 1.45).sin());
        let (a, b) = (
            jones(&whole, lambda, &frame, beta),
            jones(&split, lambda, &frame, beta),
        );
        for i in 0..2 {
            worst = worst.max(largest(&(a[i] - b[i])));
        }
    }
    println!("split layer: worst Jones difference {worst:e}");
    assert!(worst < 1e-9, "{worst:e}");
}

/// An isotropic layer of the exterior's index on top, or of the exit's below, changes no
/// Mueller matrix (its phase changes only the global phase of the Jones matrices).
#[test]
fn an_index_matched_isotropic_layer_changes_nothing() {
    let mut rng = Rng::new(3);
    let mut worst = 0.0f64;
    for i in 0..1000 {
        let n = 1 + rng.index(4);
        let layers: Vec<Layer> = (0..n)
            .map(|_| {
                let absorbing = rng.chance(0.3);
                let m = random_material(&mut rng, absorbing);
                layer(m, rng.unit_vector(), 10f64.powf(rng.range(1.0, 5.5)))
            })
            .collect();
        let (n1, n3) = (rng.range(1.0, 1.8), rng.range(1.0, 1.8));
        let base = Stack::new(layers.clone(), c(n1), c(n3)).unwrap();
        let (index, at) = if i % 2 == 0 { (n1, 0) } else { (n3, n) };
        let matched = layer(
            Material::constant(c(index), c(index)).unwrap(),
            rng.unit_vector(),
            10f64.powf(rng.range(1.0, 5.5)),
        );
        let mut with = layers;
        with.insert(at, matched);
        let with = Stack::new(with, c(n1), c(n3)).unwrap();
        let lambda = rng.range(380.0, 780.0);
        let frame = PlaneFrame::from_azimuth(rng.range(0.0, 6.3));
        let beta = c(n1 * rng.range(0.0, 1.45).sin());
        let e = mueller_difference(
            &jones(&base, lambda, &frame, beta),
            &jones(&with, lambda, &frame, beta),
        );
        worst = worst.max(e);
    }
    println!("index-matched layer: worst Mueller difference {worst:e}");
    assert!(worst < 1e-10, "{worst:e}");
}

/// Flux reflectance and transmittance summed over both outputs for each input polarisation.
fn energy(j: &[Matrix2<C64>; 2]) -> [f64; 2] {
    std::array::from_fn(|a| {
        (0..2)
            .map(|b| j[0][(b, a)].norm_sqr() + j[1][(b, a)].norm_sqr())
            .sum()
    })
}

/// Random stacks of up to 10 layers and 10 mm in total (named crystals, constant indices,
/// isotropic layers; axes anywhere) under air, exit air or glass, incidence up to 89.9°:
/// lossless ones conserve energy to 1e-9, absorbing ones lose some and never gain.
#[test]
fn energy_is_conserved_or_lost() {
    let mut rng = Rng::new(4);
    let (mut lossless, mut gain, mut grazing, mut thick) = (0.0f64, f64::NEG_INFINITY, 0, 0);
    for i in 0..3000 {
        let absorbing = i % 3 == 0;
        let n = 1 + rng.index(10);
        let total = 10f64.powf(rng.range(2.0, 7.0)); // up to 10 mm
        let weights: Vec<f64> = (0..n).map(|_| rng.range(0.05, 1.0)).collect();
        let sum: f64 = weights.iter().sum();
        let layers: Vec<Layer> = weights
            .iter()
            .map(|w| {
                let m = random_material(&mut rng, absorbing);
                layer(m, rng.unit_vector(), total * w / sum)
            })
            .collect();
        let exit = if rng.chance(0.5) { 1.0 } else { 1.5 };
        let stack = Stack::new(layers, c(1.0), c(exit)).unwrap();
        let theta = if rng.chance(0.2) {
            89.9f64.to_radians()
        } else {
            rng.range(0.0, 89.9f64.to_radians())
        };
        let lambda = rng.range(380.0, 780.0);
        let frame = PlaneFrame::from_azimuth(rng.range(0.0, 6.3));
        let e = energy(&jones(&stack, lambda, &frame, c(theta.sin())));
        for x in e {
            if absorbing {
                gain = gain.max(x - 1.0);
            } else {
                lossless = lossless.max((x - 1.0).abs());
            }
        }
        grazing += usize::from(theta > 89.0f64.to_radians());
        thick += usize::from(total > 1e6);
    }
    println!(
        "energy: lossless |R + T - 1| <= {lossless:e}, absorbing R + T - 1 <= {gain:e} \
         ({grazing} near 89.9 deg, {thick} over 1 mm)"
    );
    assert!(grazing > 500 && thick > 300);
    assert!(lossless < 1e-9, "{lossless:e}");
    assert!(gain < 1e-12, "{gain:e}");
}

/// The frame of normal incidence whose s direction is x (`PlaneFrame::from_direction`'s
/// convention, Mitsuba's `dielectric`'s).
fn normal() -> PlaneFrame {
    PlaneFrame::from_direction(Vector3::z())
}

/// The retardance of a stack of in-plane retarders at normal incidence, with the first axis
/// along x and every other one along x or y: `arg(t_xx / t_yy)` of its transmission.
fn retardance(stack: &Stack, lambda: f64) -> f64 {
    let t = jones(stack, lambda, &normal(), c(0.0))[1];
    (t[(0, 0)] / t[(1, 1)]).arg()
}

/// `x` wrapped into `(−π, π]`.
fn wrap(x: f64) -> f64 {
    let y = x.rem_euclid(2.0 * PI);
    if y > PI {
        y - 2.0 * PI
    } else {
        y
    }
}

/// `n_e − n_o` of a named crystal at `lambda` nm.
fn birefringence(name: &str, lambda: f64) -> f64 {
    let (o, e) = Material::named(name, 0.0, 0.0)
        .unwrap()
        .indices(lambda, 0.0)
        .unwrap();
    e.re - o.re
}

/// The mean of a crystal's indices at 550 nm: an immersion that reflects almost nothing, so
/// that the stack's retardance is the plates' (no etalon ripple; `|r| < 4e-3` per face).
fn immersion(name: &str) -> f64 {
    let (o, e) = Material::named(name, 0.0, 0.0)
        .unwrap()
        .indices(550.0, 0.0)
        .unwrap();
    0.5 * (o.re + e.re)
}

/// A zero-order quarter-wave plate: two quartz plates of about 1 mm with crossed axes whose
/// thicknesses differ by `Δd = λ₀ / (4 Δn(λ₀))`: its retardance is `2π Δn(λ) Δd / λ` (the design
/// formula) to 2e-4 rad over 400-700 nm in an immersion, a quarter wave at 550 nm.
#[test]
fn zero_order_quarter_wave_plate_follows_its_design() {
    let quartz = Material::named("quartz", 0.0, 0.0).unwrap();
    let dd = 550.0 / (4.0 * birefringence("quartz", 550.0));
    let d1 = 1e6 + dd;
    let stack = Stack::new(
        vec![
            layer(quartz, Vector3::x(), d1),
            layer(quartz, Vector3::y(), 1e6),
        ],
        c(immersion("quartz")),
        c(immersion("quartz")),
    )
    .unwrap();
    let mut worst = 0.0f64;
    for i in 0..=60 {
        let lambda = 400.0 + 5.0 * i as f64;
        let design = 2.0 * PI * birefringence("quartz", lambda) * (d1 - 1e6) / lambda;
        worst = worst.max(wrap(retardance(&stack, lambda) - design).abs());
    }
    println!("zero-order QWP: worst retardance error {worst:e} rad");
    assert!(worst < 2e-4, "{worst:e}");
    assert!((retardance(&stack, 550.0) - 0.5 * PI).abs() < 2e-4);
}

/// An achromatic quarter-wave plate of quartz and MgF₂ with crossed axes, designed for a quarter
/// wave at 450 and 650 nm (`d_q Δn_q − d_m Δn_m = −λ/4` at both: quartz ~270 µm, MgF₂ ~221 µm; a
/// retardance of −π/2 is a quarter-wave plate with its fast and slow axes exchanged), between
/// immersions of each crystal's mean index: its retardance is `2π (d_q Δn_q − d_m Δn_m) / λ`
/// within the etalon ripple its faces allow (`4 Σ |r_i r_j|`, ~2e-3 rad), and within 0.15 rad of
/// a quarter wave from 420 to 700 nm, where a zero-order quartz quarter-wave plate drifts by
/// 0.56 rad.
#[test]
fn achromatic_quarter_wave_plate_follows_its_design() {
    let (l1, l2) = (450.0, 650.0);
    let (q1, q2) = (birefringence("quartz", l1), birefringence("quartz", l2));
    let (m1, m2) = (birefringence("mgf2", l1), birefringence("mgf2", l2));
    // d_q q − d_m m = −λ/4 at λ1 and λ2 (Cramer's rule).
    let det = -q1 * m2 + q2 * m1;
    let (r1, r2) = (-l1 / 4.0, -l2 / 4.0);
    let dq = (-r1 * m2 + r2 * m1) / det;
    let dm = (q1 * r2 - q2 * r1) / det;
    assert!(dq > 1e5 && dm > 1e5, "{dq} {dm}");
    let (n, nm) = (immersion("quartz"), immersion("mgf2"));
    let stack = Stack::new(
        vec![
            layer(
                Material::named("quartz", 0.0, 0.0).unwrap(),
                Vector3::x(),
                dq,
            ),
            layer(Material::named("mgf2", 0.0, 0.0).unwrap(), Vector3::y(), dm),
        ],
        c(n),
        c(nm),
    )
    .unwrap();
    // The etalon ripple of the retardance: each mode's phase moves by at most
    // Σ_{i<j} |r_i r_j| / (1 − ...) ≈ Σ |r_i r_j|, the retardance by twice that; normal-incidence
    // Fresnel amplitudes of the o and e indices at each face, the largest over 420-700 nm.
    let fresnel = |a: f64, b: f64| ((a - b) / (a + b)).abs();
    let mut ripple = 0.0f64;
    for i in 0..=56 {
        let lambda = 420.0 + 5.0 * i as f64;
        let q = Material::named("quartz", 0.0, 0.0)
            .unwrap()
            .indices(lambda, 0.0)
            .unwrap();
        let m = Material::named("mgf2", 0.0, 0.0)
            .unwrap()
            .indices(lambda, 0.0)
            .unwrap();
        // Quartz's e index meets MgF₂'s o index (crossed axes) and vice versa.
        for (a, b, x) in [(q.1.re, m.0.re, q.1.re), (q.0.re, m.1.re, q.0.re)] {
            let r = [fresnel(n, x), fresnel(a, b), fresnel(b, nm)];
            ripple = ripple.max(4.0 * (r[0] * r[1] + r[0] * r[2] + r[1] * r[2]));
        }
    }
    let zero_order = Stack::new(
        vec![layer(
            Material::named("quartz", 0.0, 0.0).unwrap(),
            Vector3::x(),
            550.0 / (4.0 * birefringence("quartz", 550.0)),
        )],
        c(n),
        c(n),
    )
    .unwrap();
    let (mut worst, mut flat, mut drift) = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..=56 {
        let lambda = 420.0 + 5.0 * i as f64;
        let design =
            2.0 * PI * (dq * birefringence("quartz", lambda) - dm * birefringence("mgf2", lambda))
                / lambda;
        let got = retardance(&stack, lambda);
        worst = worst.max(wrap(got - design).abs());
        flat = flat.max(wrap(got + 0.5 * PI).abs());
        drift = drift.max(wrap(retardance(&zero_order, lambda) - 0.5 * PI).abs());
    }
    println!(
        "achromatic QWP (quartz {dq:.0} nm, MgF2 {dm:.0} nm): design error {worst:e} rad \
         (etalon bound {ripple:e}), deviation from a quarter wave {flat:.4} rad (zero-order quartz: {drift:.3} rad)"
    );
    assert!(worst < ripple, "{worst:e} (bound {ripple:e})");
    assert!(flat < 0.15, "{flat}");
    assert!(drift > 0.5, "{drift}");
}

/// A three-stage Lyot filter as one stack (immersed): polarisers made of a dichroic layer
/// (`κ_e = 0.01`, 1 mm: the e-wave loses `e^{-250}`) with axes along y (passing x), between them quartz
/// plates of `d, 2d, 4d` at 45° (`d` = 0.6 mm). Its transmission for x-polarised light is
/// `Π cos²(π Δn d_i / λ)` (to 2e-4: the immersion and the plates still reflect `|r| ≤ 3e-3` at
/// each of their 8 faces, whose ripples of order `|r|²` add up to ~1e-4) and its passbands lie where every stage is a whole number of waves,
/// `Δn(λ) d / λ = m`.
#[test]
fn lyot_filter_passbands_follow_the_closed_form() {
    let n = immersion("quartz");
    let polariser = layer(
        Material::constant(c(n), C64::new(n, 0.01)).unwrap(),
        Vector3::y(),
        1e6,
    );
    let quartz = Material::named("quartz", 0.0, 0.0).unwrap();
    let d = 600_000.0;
    let diagonal = Vector3::new(1.0, 1.0, 0.0);
    let mut layers = vec![polariser];
    for k in 0..3 {
        layers.push(layer(quartz, diagonal, d * (1 << k) as f64));
        layers.push(polariser);
    }
    let stack = Stack::new(layers, c(n), c(n)).unwrap();
    let transmission = |lambda: f64| {
        // x-polarised input (s at normal incidence), power into both outputs.
        let t = jones(&stack, lambda, &normal(), c(0.0))[1];
        t[(0, 0)].norm_sqr() + t[(1, 0)].norm_sqr()
    };
    let closed = |lambda: f64| {
        (0..3)
            .map(|k| {
                (PI * birefringence("quartz", lambda) * d * (1 << k) as f64 / lambda)
                    .cos()
                    .powi(2)
            })
            .product::<f64>()
    };
    let (mut worst, mut peaks) = (0.0f64, Vec::new());
    let step = 0.05;
    let grid: Vec<f64> = (0..=((700.0 - 450.0) / step) as usize)
        .map(|i| 450.0 + step * i as f64)
        .collect();
    let values: Vec<f64> = grid.iter().map(|&l| transmission(l)).collect();
    for (i, (&l, &t)) in grid.iter().zip(&values).enumerate() {
        worst = worst.max((t - closed(l)).abs());
        if i > 0 && i + 1 < grid.len() && t > values[i - 1] && t >= values[i + 1] && t > 0.5 {
            peaks.push(l);
        }
    }
    // The closed form's passbands: Δn(λ) d / λ = m, solved by fixed-point iteration.
    let mut expected = Vec::new();
    for m in 1..40 {
        let mut l = birefringence("quartz", 550.0) * d / m as f64;
        for _ in 0..50 {
            if !(300.0..=900.0).contains(&l) {
                break;
            }
            l = birefringence("quartz", l) * d / m as f64;
        }
        if (450.0..=700.0).contains(&l) {
            expected.push(l);
        }
    }
    expected.sort_by(f64::total_cmp);
    println!("Lyot: transmission vs closed form {worst:e}; passbands {peaks:?} vs {expected:?}");
    assert!(worst < 2e-4, "{worst:e}");
    assert_eq!(peaks.len(), expected.len());
    for (p, e) in peaks.iter().zip(&expected) {
        assert!(
            (p - e).abs() <= step,
            "passband at {p} nm, closed form {e} nm"
        );
    }
}

/// Seen from below, a stack is its layers in reverse order, each mirrored through its plane:
/// a tilted axis `(x, y, z)` becomes `(x, y, −z)`. Through the render entry points (the lobes a
/// path tracer samples, `render::stack::stack_lobes` against `render::plate::plate_lobes`), a
/// one-layer stack lit from below is the plate lit from below (the plate mirrors its own axis),
/// both lobes, both transport modes, Mueller matrices to 1e-12; and a two-layer stack lit from
/// below is the stack written upside down (layers reversed, axes mirrored, media swapped) lit
/// from above along the mirrored direction, its matrices mirrored back (`D M D`,
/// `D = diag(1, 1, −1, −1)`). Axes with `z` of either sign, so a layer left unmirrored shows.
#[test]
fn a_stack_seen_from_below_mirrors_its_layers() {
    use birefringent::render::plate::{plate_lobes, PlateQuery};
    use birefringent::render::stack::{stack_lobes, StackQuery};
    use birefringent::render::thin::Spectrum;
    use birefringent::render::Transport;
    use nalgebra::{Matrix4, Vector4};

    let spectrum = Spectrum::Band {
        wavelength_nm: 550.0,
        fwhm_nm: 0.0,
    };
    let quartz = || Material::named("quartz", 0.0, 0.0).unwrap();
    let (n_ext, n_exit) = (1.0, 1.33);
    let d = Matrix4::from_diagonal(&Vector4::new(1.0, 1.0, -1.0, -1.0));
    let mut worst = 0.0f64;
    let mut compare = |a: &[[Option<birefringent::render::PathLobe>; 2]],
                       b: &[[Option<birefringent::render::PathLobe>; 2]],
                       mirror: bool| {
        for (x, y) in a.iter().zip(b) {
            for (x, y) in x.iter().zip(y) {
                // (No transmission beyond the critical angle, in both.)
                assert_eq!(x.is_some(), y.is_some());
                let (Some(x), Some(y)) = (x, y) else { continue };
                let y = if mirror { d * y.mueller * d } else { y.mueller };
                worst = worst.max((x.mueller - y).abs().max());
            }
        }
    };
    for axis in [Vector3::new(0.3, 0.5, 0.81), Vector3::new(-0.6, 0.2, -0.5)] {
        for (theta, phi) in [(25.0f64, 10.0f64), (50.0, 200.0)] {
            let (t, p) = (theta.to_radians(), phi.to_radians());
            let below = Vector3::new(t.sin() * p.cos(), t.sin() * p.sin(), -t.cos());
            for transport in [Transport::Radiance, Transport::Importance] {
                let plate = PlateQuery::new(
                    quartz(),
                    0.0,
                    c(n_ext),
                    c(n_exit),
                    axis,
                    Thickness::from_nm(7500.0).unwrap(),
                    true,
                    true,
                    false,
                )
                .unwrap();
                let one = Stack::new(vec![layer(quartz(), axis, 7500.0)], c(n_ext), c(n_exit));
                let one = StackQuery::new(one.unwrap(), true, true, false);
                compare(
                    &stack_lobes(&one, &spectrum, below, transport).unwrap(),
                    &plate_lobes(&plate, &spectrum, below, transport).unwrap(),
                    false,
                );
                // Two layers: the second crossed with the first about the normal.
                let second = Vector3::new(-axis.y, axis.x, 0.4);
                let layers = vec![
                    layer(quartz(), axis, 7500.0),
                    layer(quartz(), second, 3000.0),
                ];
                let mirrored = |a: Vector3<f64>| Vector3::new(a.x, a.y, -a.z);
                let upside_down = vec![
                    layer(quartz(), mirrored(second), 3000.0),
                    layer(quartz(), mirrored(axis), 7500.0),
                ];
                let two = StackQuery::new(
                    Stack::new(layers, c(n_ext), c(n_exit)).unwrap(),
                    true,
                    true,
                    false,
                );
                let flipped = StackQuery::new(
                    Stack::new(upside_down, c(n_exit), c(n_ext)).unwrap(),
                    true,
                    true,
                    false,
                );
                compare(
                    &stack_lobes(&two, &spectrum, below, transport).unwrap(),
                    &stack_lobes(&flipped, &spectrum, mirrored(below), transport).unwrap(),
                    true,
                );
            }
        }
    }
    println!("stacks from below: worst Mueller difference {worst:e}");
    assert!(worst < 1e-12, "{worst:e}");
}
