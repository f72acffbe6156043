//! The Radiance lobes of a bulk crystal surface, which the renderer takes from the forward
//! solve by the reciprocity theorem (`Q Mᵀ Q`, ray-index scaling), against an independent
//! method: solving the time-reversed problem, light sent from each `wo` and followed to the
//! wave that leaves along `wi`.

use birefringent::optics::lobes::{scatter, Event, Lobe};
use birefringent::optics::medium::Uniaxial;
use birefringent::optics::modes::ModeKind;
use birefringent::optics::surface::{Incident, Surface};
use birefringent::render::crystal::crystal_lobes_full;
use birefringent::render::{PathLobe, Transport};
use birefringent::C64;
use nalgebra::Vector3;

mod common;
use common::Rng;

fn re(x: f64) -> C64 {
    C64::new(x, 0.0)
}

/// Every wave leaving `event`, with its crystal-side mode (`None` outside the crystal).
fn waves(event: &Event, inside: bool) -> impl Iterator<Item = (Option<ModeKind>, &Lobe)> {
    let r = event
        .reflected
        .iter()
        .flatten()
        .map(move |l| (inside.then_some(l.kind), l));
    let t = event
        .transmitted
        .iter()
        .flatten()
        .map(move |l| ((!inside).then_some(l.kind), l));
    r.chain(t)
}

/// The reference Radiance lobe towards `wo` (a wave of mode `wo_mode`) for the wave leaving
/// along `wi` in mode `wi_mode`: the source at `wo` is scattered forward and the wave
/// reaching `wi` kept, its Mueller matrix scaled by `(n_wi / n_wo)²` (radiance across an
/// index step). `None` when the source is grazing (no power).
fn time_reversed(
    surface: &Surface,
    (wi, wi_mode): (Vector3<f64>, Option<ModeKind>),
    (wo, wo_mode): (Vector3<f64>, Option<ModeKind>),
) -> Option<PathLobe> {
    let incident = wo_mode.map_or(Incident::Outside, Incident::Inside);
    let event = scatter(surface, wo, incident).ok()?;
    let (_, l) = waves(&event, wo_mode.is_some())
        .find(|(mode, l)| (l.direction - wi).norm() < 1e-6 && *mode == wi_mode)?;
    let scale = (l.ray_index / event.incident_ray_index).powi(2);
    Some(PathLobe::new(
        0,
        wo,
        (event.incident_stokes_x, l.stokes_x),
        l.mueller * scale,
        event.incident_ray_index / l.ray_index,
    ))
}

/// The modes a wave along `d` can have: none outside the crystal (`d.z > 0`), o or e inside.
fn modes(d: Vector3<f64>) -> Vec<Option<ModeKind>> {
    if d.z > 0.0 {
        vec![None]
    } else {
        vec![Some(ModeKind::O), Some(ModeKind::E)]
    }
}

/// Random uniaxial crystals (positive and negative, any optic axis) seen from both sides at
/// any angle, total internal reflection included: every Radiance lobe equals the time-reversed
/// solution, the Mueller matrix to 1e-9 of its norm (the project's bound for one interface in
/// f64; the methods round differently through two 4x4 solves, measured worst 1.3e-11 near
/// grazing), frames to sign (a frame turned by 180 degrees describes the same Stokes vectors),
/// `eta` likewise.
#[test]
fn radiance_lobes_by_reciprocity_equal_the_time_reversed_solution() {
    let mut rng = Rng::new(83);
    let (mut worst, mut lobes, mut inside) = (0.0f64, 0, 0);
    for _ in 0..3_000 {
        let (no, ne) = (rng.range(1.3, 2.6), rng.range(1.3, 2.6));
        let crystal = Uniaxial::new(re(no), re(ne), rng.unit_vector()).unwrap();
        let surface = Surface::new(re(rng.range(1.0, 1.6)), crystal).unwrap();
        let wi = rng.unit_vector();
        if wi.z.abs() < 1e-3 {
            continue;
        }
        let forward = crystal_lobes_full(&surface, wi, Transport::Importance).unwrap();
        let radiance = crystal_lobes_full(&surface, wi, Transport::Radiance).unwrap();
        assert_eq!(forward.len(), radiance.len());
        inside += usize::from(wi.z < 0.0);
        for lobe in &radiance {
            // Inside, the modes at either end are not named by the component (an o-to-e
            // reflection is component 0 too): every pair is solved and the closest kept.
            let candidates: Vec<PathLobe> = modes(wi)
                .iter()
                .flat_map(|&a| modes(lobe.wo).into_iter().map(move |b| (a, b)))
                .filter_map(|(a, b)| time_reversed(&surface, (wi, a), (lobe.wo, b)))
                .collect();
            let axis = |x: Vector3<f64>, y: Vector3<f64>| (x - y).norm().min((x + y).norm());
            let best = candidates
                .iter()
                .map(|r| {
                    (r.mueller - lobe.mueller).norm() / lobe.mueller.norm().max(1e-300)
                        + axis(r.in_stokes_x, lobe.in_stokes_x)
                        + axis(r.out_stokes_x, lobe.out_stokes_x)
                        + (r.eta - lobe.eta).abs()
                })
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(best);
            lobes += 1;
        }
    }
    assert!(
        inside > 1_000 && lobes > 8_000,
        "coverage: {inside} inside, {lobes} lobes"
    );
    assert!(worst < 1e-9, "worst relative deviation {worst:e}");
}
