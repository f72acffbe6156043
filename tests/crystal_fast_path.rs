//! The closed-form surface event of a clear birefringent crystal (`optics::clear_lobes`, which
//! `render::crystal::crystal_lobes` and `crystal_slots` take) against the general computation it
//! replaces (`optics::lobes::scatter` through the interface's solve, which `crystal_lobes_full`
//! takes): the same lobes in the same order, every field of every lobe, both sides, both
//! transport modes, on random crystals and directions including the traps of the closed form:
//! grazing (1e-6 to 1e-2 from it) and total internal reflection inside, an exterior denser than
//! the crystal (refracted waves evanescent from outside), an optic axis along the normal, in the
//! plane of incidence, across it or in the surface, `η_o` within 1e-9 of `η_e`, and named crystals
//! at random wavelengths.
//!
//! Tolerance: `1e-12`, relative to the largest entry of the query's Mueller matrices, absolute
//! for unit vectors and ray-index ratios. Both evaluate the same closed-form
//! fields and the same 2x2 reduction of the same boundary equations (the general one by Gaussian
//! elimination with pivoting, this one by Cramer's rule), so they agree to rounding, amplified
//! by the conditioning of the system: observed worst 6e-14 (printed), the near-degenerate crystals
//! included (their two nearly parallel waves come from the same closed-form fields in both).
//! Mueller matrices and Jones matrices are compared relative to the largest of the query (a
//! lobe that carries 1e-12 of the light near grazing is known to 1e-12 of the light).

use birefringent::material::Material;
use birefringent::optics::clear_lobes::{applies, scatter_clear};
use birefringent::optics::lobes::{scatter, Event, Lobe};
use birefringent::optics::medium::Uniaxial;
use birefringent::optics::modes::ModeKind;
use birefringent::optics::surface::{Incident, Surface};
use birefringent::render::crystal::{crystal_lobes, crystal_lobes_full, crystal_slots};
use birefringent::render::{PathLobe, Transport};
use birefringent::C64;
use nalgebra::{Matrix4, Vector3};

mod common;
use common::Rng;

const TOL: f64 = 1e-12;

fn re(x: f64) -> C64 {
    C64::new(x, 0.0)
}

/// The kinds of random crystal.
const KINDS: [&str; 7] = [
    "random tilted axis",
    "axis along the normal",
    "axis in the plane of incidence",
    "axis across the plane of incidence",
    "axis in the surface",
    "named crystal",
    "eta_o == eta_e within 1e-9",
];

/// A random clear birefringent crystal of kind `k` under a clear exterior (denser than the
/// crystal in about a fifth of the cases), for light along `wi` (which sets the plane of
/// incidence of an exterior wave, and nearly that of a crystal wave).
fn surface(rng: &mut Rng, k: usize, wi: Vector3<f64>) -> Surface {
    let (mut eo, mut ee) = (re(rng.range(1.2, 3.0)), re(rng.range(1.2, 3.0)));
    let phi = wi.y.atan2(wi.x);
    let axis = match KINDS[k] {
        "axis along the normal" => Vector3::new(0.0, 0.0, 1.0),
        "axis in the plane of incidence" => {
            let t = rng.range(0.0, 6.3);
            Vector3::new(phi.cos() * t.sin(), phi.sin() * t.sin(), t.cos())
        }
        "axis across the plane of incidence" => Vector3::new(-phi.sin(), phi.cos(), 0.0),
        "axis in the surface" => {
            let phi = rng.range(0.0, 6.3);
            Vector3::new(phi.cos(), phi.sin(), 0.0)
        }
        "named crystal" => {
            let names = ["calcite", "quartz", "rutile", "sapphire"];
            let m = Material::named(names[rng.index(4)], 0.0, 0.0).unwrap();
            (eo, ee) = m.indices(rng.range(400.0, 800.0), 0.0).unwrap();
            rng.unit_vector()
        }
        "eta_o == eta_e within 1e-9" => {
            ee = eo + re(rng.range(-1e-9, 1e-9));
            rng.unit_vector()
        }
        _ => rng.unit_vector(),
    };
    let ext = if rng.chance(0.2) {
        rng.range(1.0, 3.2)
    } else {
        rng.range(1.0, 1.6)
    };
    Surface::new(re(ext), Uniaxial::new(eo, ee, axis).unwrap()).unwrap()
}

/// A random direction: uniform, or within 1e-6..1e-2 of grazing.
fn direction(rng: &mut Rng) -> Vector3<f64> {
    let d = rng.unit_vector();
    if rng.chance(0.1) {
        let z = 10f64.powf(rng.range(-6.0, -2.0)) * d.z.signum();
        let t = (1.0 - z * z).sqrt() / (d.x * d.x + d.y * d.y).sqrt();
        return Vector3::new(d.x * t, d.y * t, z);
    }
    d
}

/// The largest difference between two lobes of a query: Mueller matrices relative to `scale`
/// (the largest entry of the query's matrices: a lobe that carries 1e-12 of the light is known
/// to 1e-12 of the light, not of itself); directions, Stokes axes (up to sign: the same Stokes
/// vectors) and `eta` absolute.
fn lobe_diff(a: &PathLobe, b: &PathLobe, scale: f64) -> f64 {
    let axis = |x: Vector3<f64>, y: Vector3<f64>| (x - y).norm().min((x + y).norm());
    ((a.mueller - b.mueller).abs().max() / scale)
        .max((a.wo - b.wo).norm())
        .max(axis(a.in_stokes_x, b.in_stokes_x))
        .max(axis(a.out_stokes_x, b.out_stokes_x))
        .max((a.eta - b.eta).abs())
}

/// The Mueller matrices of a query summed (over the lobes of each component).
fn sum(lobes: &[PathLobe], component: usize) -> Matrix4<f64> {
    lobes
        .iter()
        .filter(|l| l.component == component)
        .map(|l| l.mueller)
        .sum()
}

#[derive(Default)]
struct Tally {
    queries: usize,
    lobes: usize,
    worst: f64,
    worst_sum: f64,
    tir: usize,
    evanescent_outside: usize,
}

#[test]
fn clear_crystal_lobes_equal_the_general_computation() {
    let mut rng = Rng::new(20);
    let mut tallies: Vec<Tally> = (0..KINDS.len()).map(|_| Tally::default()).collect();
    for i in 0..40_000 {
        let k = i % KINDS.len();
        let wi = direction(&mut rng);
        let s = surface(&mut rng, k, wi);
        assert!(applies(&s));
        let t = if rng.chance(0.5) {
            Transport::Radiance
        } else {
            Transport::Importance
        };
        let (fast, full) = match (crystal_lobes(&s, wi, t), crystal_lobes_full(&s, wi, t)) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(a), Err(b)) => {
                assert_eq!(a, b);
                continue;
            }
            (a, b) => panic!("{s:?} {wi:?}: fast {a:?}, full {b:?}"),
        };
        let tally = &mut tallies[k];
        tally.queries += 1;
        assert_eq!(fast.len(), full.len(), "{s:?} {wi:?} {t:?}");
        let transmitted = fast.iter().filter(|l| l.component != 0).count();
        tally.tir += usize::from(wi.z < 0.0 && transmitted == 0);
        tally.evanescent_outside += usize::from(wi.z > 0.0 && transmitted < 2);
        let scale = full
            .iter()
            .map(|l| l.mueller.abs().max())
            .fold(0.0, f64::max);
        for (a, b) in fast.iter().zip(&full) {
            assert_eq!(a.component, b.component);
            tally.lobes += 1;
            let d = lobe_diff(a, b, scale);
            tally.worst = tally.worst.max(d);
        }
        for c in 0..3 {
            let (a, b) = (sum(&fast, c), sum(&full, c));
            tally.worst_sum = tally.worst_sum.max((a - b).abs().max() / scale);
        }
        // The slots hold the same lobes as the list (the bridge's entry point).
        let slots = crystal_slots(&s, wi, t).unwrap();
        assert_eq!(slots.iter().flatten().count(), fast.len());
    }
    for (kind, t) in KINDS.iter().zip(&tallies) {
        println!(
            "{kind:28}: {:5} queries, {:6} lobes ({:4} TIR inside, {:4} with an evanescent refraction from outside): worst {:.2e}, of the sums {:.2e}",
            t.queries, t.lobes, t.tir, t.evanescent_outside, t.worst, t.worst_sum
        );
        assert!(t.worst < TOL, "{kind}: {:e}", t.worst);
        assert!(t.worst_sum < TOL, "{kind}: sums {:e}", t.worst_sum);
        assert!(
            t.queries > 5000 && t.tir > 300 && t.evanescent_outside > 50,
            "{kind}"
        );
    }
}

/// Every field of the closed-form event against the general one, including the Jones matrices
/// and wave normals that the lobes do not carry, for both incident crystal waves from inside.
#[test]
fn clear_events_equal_the_general_events() {
    let mut rng = Rng::new(21);
    let mut worst = 0.0f64;
    let lobes = |e: &Event| -> Vec<Lobe> {
        e.reflected
            .iter()
            .chain(&e.transmitted)
            .flatten()
            .copied()
            .collect()
    };
    for i in 0..10_000 {
        let d = rng.unit_vector();
        let s = surface(&mut rng, i % KINDS.len(), d);
        let incident = match (d.z > 0.0, rng.chance(0.5)) {
            (true, _) => Incident::Outside,
            (false, true) => Incident::Inside(ModeKind::O),
            (false, false) => Incident::Inside(ModeKind::E),
        };
        let (Ok(a), Ok(b)) = (scatter_clear(&s, d, incident), scatter(&s, d, incident)) else {
            continue;
        };
        worst = worst
            .max((a.incident_direction - b.incident_direction).norm())
            .max((a.incident_ray_index - b.incident_ray_index).abs())
            .max(
                (a.incident_stokes_x - b.incident_stokes_x)
                    .norm()
                    .min((a.incident_stokes_x + b.incident_stokes_x).norm()),
            );
        let (la, lb) = (lobes(&a), lobes(&b));
        assert_eq!(la.len(), lb.len());
        // Jones matrices relative to the event's largest amplitude (as the lobes above).
        let norm = |m: nalgebra::Matrix2<C64>| m.map(|z| z.norm()).max();
        let scale = lb.iter().map(|l| norm(l.jones)).fold(0.0, f64::max);
        for (x, y) in la.iter().zip(&lb) {
            assert_eq!(x.kind, y.kind);
            // Jones matrices up to a sign (a frame's x axis turned by 180 degrees; a crystal
            // wave's matrix has one non-zero row or column).
            let diff = norm(x.jones - y.jones).min(norm(x.jones + y.jones));
            worst = worst
                .max(diff / scale)
                .max((x.direction - y.direction).norm())
                .max((x.wave_normal - y.wave_normal).norm())
                .max((x.ray_index - y.ray_index).abs());
        }
    }
    println!("clear events vs general: worst {worst:e}");
    assert!(worst < TOL, "{worst:e}");
}

/// The comparison above would see a lobe perturbed by a fraction of the tolerance.
#[test]
fn the_comparison_detects_a_perturbed_lobe() {
    let s = Surface::new(
        re(1.0),
        Uniaxial::new(re(1.658), re(1.486), Vector3::new(0.3, 0.5, 0.8)).unwrap(),
    )
    .unwrap();
    let wi = Vector3::new(0.3, 0.2, -0.9).normalize();
    let a = crystal_lobes(&s, wi, Transport::Radiance).unwrap();
    let scale = a.iter().map(|l| l.mueller.abs().max()).fold(0.0, f64::max);
    for l in &a {
        for k in 0..16 {
            let mut b = *l;
            b.mueller[(k / 4, k % 4)] += 10.0 * TOL * scale;
            assert!(lobe_diff(l, &b, scale) > TOL);
        }
        let mut b = *l;
        b.wo.x += 10.0 * TOL;
        assert!(lobe_diff(l, &b, scale) > TOL);
    }
}
