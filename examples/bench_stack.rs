//! Stack benchmark: the cost of a stack against one plate (at one wavelength and over the XYZ
//! channels), and the channel integration's colour accuracy on random stacks.
//!
//! ```text
//! cargo run --release --example bench_stack -- [--validate N] [--out FILE]
//! ```
//! * Timings (one thread: the Makefile pins it with `taskset -c 0`): each pair of queries is
//!   timed in interleaved rounds (stack, plate, stack, plate, ...: a load that changes during the
//!   run affects both alike), each round the best of a few repetitions of an inner loop cycling
//!   through 16 incidences; the ratio is the median over rounds of stack / plate. Goals (issue
//!   24): a 4-layer stack at one wavelength at most 4x one plate, its XYZ integration at most 4x
//!   a plate's. The 4-layer stack is cellophane tape (n_o 1.47, n_e 1.478, 30-40 um, axes in the
//!   plane at 0, 30, 70 and 110 degrees) in air; the plate one such tape. Also reported without a
//!   goal: a zero-order quartz quarter-wave plate (two crossed 1 mm plates, dispersive) against
//!   one 1 mm quartz plate.
//! * `--validate N` (default 200): `tests/stack_spectral.rs` (included as a module) on N random
//!   stacks: CIEDE2000 of the analytic XYZ against dense quadrature of the exact stack with the
//!   tabulated weights, per quantity and per family of stacks.
//! * `--out FILE` (default `bench/out/stack.json`).

#[path = "../tests/stack_spectral.rs"]
mod stack_spectral;

use birefringent::colour::weights::WeightSet;
use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::params::Thickness;
use birefringent::plate::slab::{Output, Want};
use birefringent::plate::Plate;
use birefringent::quadrature::Accuracy;
use birefringent::spectral::model::{PlateModel, ThinModel};
use birefringent::stack::exact::StackBlocks;
use birefringent::stack::spectral::StackModel;
use birefringent::stack::{Layer, Stack};
use birefringent::C64;
use nalgebra::Vector3;
use serde_json::{json, Value};
use std::hint::black_box;
use std::time::Instant;

/// The issue's goals: stack / plate at one wavelength and over XYZ.
const GOAL_WAVELENGTH: f64 = 4.0;
const GOAL_XYZ: f64 = 4.0;
/// Interleaved rounds per comparison.
const ROUNDS: usize = 15;

fn axis(deg: f64) -> Vector3<f64> {
    let a = deg.to_radians();
    Vector3::new(a.cos(), a.sin(), 0.0)
}

fn layer(m: Material, deg: f64, nm: f64) -> Layer {
    Layer::new(m, 0.0, axis(deg), Thickness::from_nm(nm).unwrap()).unwrap()
}

fn plate(m: Material, nm: f64) -> Plate {
    Plate {
        material: m,
        birefringence: 0.0,
        ext: C64::new(1.0, 0.0),
        exit: C64::new(1.0, 0.0),
        axis: axis(0.0),
        thickness_nm: nm,
    }
}

/// 16 incidences up to 60 degrees at assorted azimuths: `(frame, beta)`.
fn incidences() -> Vec<(PlaneFrame, C64)> {
    (0..16)
        .map(|i| {
            let theta = (60.0 * i as f64 / 15.0).to_radians();
            (
                PlaneFrame::from_azimuth(0.7 + 1.9 * i as f64),
                C64::new(theta.sin(), 0.0),
            )
        })
        .collect()
}

/// Seconds per call of `f` over the incidences: the best of 3 repetitions of `inner` calls.
fn per_call(inner: usize, f: &mut dyn FnMut(usize)) -> f64 {
    (0..3)
        .map(|_| {
            let t = Instant::now();
            for i in 0..inner {
                f(i % 16);
            }
            t.elapsed().as_secs_f64() / inner as f64
        })
        .fold(f64::INFINITY, f64::min)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// `(stack µs, plate µs, median ratio)` of interleaved rounds.
fn compare(inner: usize, stack: &mut dyn FnMut(usize), plate: &mut dyn FnMut(usize)) -> Value {
    stack(0);
    plate(0);
    let (mut s, mut p, mut r) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..ROUNDS {
        let a = per_call(inner, stack);
        let b = per_call(inner, plate);
        s.push(a * 1e6);
        p.push(b * 1e6);
        r.push(a / b);
    }
    json!({"stack_us": median(s), "plate_us": median(p), "ratio": median(r),
           "rounds": ROUNDS, "calls_per_round": inner})
}

fn timings() -> Value {
    let tape = Material::constant(C64::new(1.47, 0.0), C64::new(1.478, 0.0)).unwrap();
    let air = C64::new(1.0, 0.0);
    let four = Stack::new(
        vec![
            layer(tape, 0.0, 30e3),
            layer(tape, 30.0, 35e3),
            layer(tape, 70.0, 40e3),
            layer(tape, 110.0, 35e3),
        ],
        air,
        air,
    )
    .unwrap();
    let one = plate(tape, 35e3);
    let quartz = Material::named("quartz", 0.0, 0.0).unwrap();
    let zero_order = Stack::new(
        vec![layer(quartz, 0.0, 1.0146e6), layer(quartz, 90.0, 1e6)],
        air,
        air,
    )
    .unwrap();
    let quartz_plate = plate(quartz, 1e6);
    let inc = incidences();
    let lambda = 550.0;
    let set = WeightSet::XyzD65;
    let both = Want::BOTH;
    let xyz_stack = |s: &Stack, i: usize| {
        let (f, b) = inc[i];
        black_box(
            StackModel::new(black_box(s), f, b)
                .channels(set, both, Output::Mueller, Accuracy::Perceptual)
                .unwrap(),
        );
    };
    let xyz_plate = |p: &Plate, i: usize| {
        let (f, b) = inc[i];
        black_box(
            PlateModel::new(black_box(p), f, b)
                .channels(set, both, Output::Mueller, Accuracy::Perceptual)
                .unwrap(),
        );
    };
    let wavelength = compare(
        4000,
        &mut |i| {
            let (f, b) = inc[i];
            black_box(
                StackBlocks::new(black_box(&four), lambda, &f, b)
                    .unwrap()
                    .mueller(lambda, both)
                    .unwrap(),
            );
        },
        &mut |i| {
            let (f, b) = inc[i];
            black_box(
                PlateModel::new(black_box(&one), f, b)
                    .at(lambda, both, Output::Mueller)
                    .unwrap(),
            );
        },
    );
    let xyz = compare(60, &mut |i| xyz_stack(&four, i), &mut |i| {
        xyz_plate(&one, i)
    });
    let quartz_xyz = compare(6, &mut |i| xyz_stack(&zero_order, i), &mut |i| {
        xyz_plate(&quartz_plate, i)
    });
    let verdict = |v: &Value, goal: f64| {
        let r = v["ratio"].as_f64().unwrap_or(f64::NAN);
        format!(
            "{:.2} (<= {goal}: {})",
            r,
            if r <= goal { "met" } else { "not met" }
        )
    };
    let f = |v: &Value, key: &str| v[key].as_f64().unwrap_or(f64::NAN);
    println!(
        "one wavelength: 4-layer stack {:.2} us, plate {:.2} us, ratio {}",
        f(&wavelength, "stack_us"),
        f(&wavelength, "plate_us"),
        verdict(&wavelength, GOAL_WAVELENGTH)
    );
    println!(
        "XYZ (both lobes, Mueller): 4-layer stack {:.1} us, plate {:.1} us, ratio {}",
        f(&xyz, "stack_us"),
        f(&xyz, "plate_us"),
        verdict(&xyz, GOAL_XYZ)
    );
    println!(
        "XYZ, zero-order quartz QWP (2 x 1 mm, dispersive) {:.0} us vs one 1 mm quartz plate {:.0} us: ratio {:.1} (no goal)",
        f(&quartz_xyz, "stack_us"),
        f(&quartz_xyz, "plate_us"),
        f(&quartz_xyz, "ratio")
    );
    json!({
        "one_wavelength": wavelength, "goal_one_wavelength": GOAL_WAVELENGTH,
        "xyz": xyz, "goal_xyz": GOAL_XYZ,
        "zero_order_quartz_xyz": quartz_xyz,
    })
}

fn validation(n: usize) -> Value {
    let t = Instant::now();
    let outcomes: Vec<stack_spectral::Outcome> = stack_spectral::cases(n, 7919)
        .iter()
        .map(stack_spectral::compare)
        .collect();
    let (mean, worst) = stack_spectral::report(&outcomes);
    let mut families = Vec::new();
    for (f, name) in stack_spectral::FAMILIES.iter().enumerate() {
        let e: Vec<f64> = outcomes
            .iter()
            .filter(|o| o.case.family == f)
            .flat_map(|o| o.de)
            .collect();
        let times: Vec<f64> = outcomes
            .iter()
            .filter(|o| o.case.family == f)
            .map(|o| o.seconds.0 * 1e3)
            .collect();
        let m = e.iter().sum::<f64>() / e.len().max(1) as f64;
        let w = e.iter().copied().fold(0.0, f64::max);
        println!(
            "  {name:>10}: {} stacks, CIEDE2000 mean {m:.4}, worst {w:.4}; analytic median {:.2} ms",
            times.len(),
            median(times.clone())
        );
        families.push(
            json!({"family": name, "stacks": times.len(), "mean": m, "worst": w,
                             "median_ms": median(times)}),
        );
    }
    println!(
        "validation: {n} stacks in {:.0} s: worst mean over quantities {mean:.4} (<= {}), worst {worst:.4} (<= {})",
        t.elapsed().as_secs_f64(),
        stack_spectral::BOUNDS.0,
        stack_spectral::BOUNDS.1
    );
    json!({"stacks": n, "mean": mean, "worst": worst, "bounds": stack_spectral::BOUNDS,
           "families": families})
}

fn loadavg() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .unwrap_or_default()
        .split_whitespace()
        .next()
        .unwrap_or("?")
        .to_string()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let n: usize = arg("--validate")
        .and_then(|s| s.parse().ok())
        .unwrap_or(200);
    let out = arg("--out").unwrap_or_else(|| "bench/out/stack.json".into());
    let load_start = loadavg();
    let timing = timings();
    let valid = validation(n);
    let result = json!({"load_average_1min": [load_start, loadavg()], "timings": timing,
                        "validation": valid});
    if let Some(dir) = std::path::Path::new(&out).parent() {
        let _ = std::fs::create_dir_all(dir);
    }
    std::fs::write(&out, serde_json::to_string_pretty(&result).unwrap())
        .unwrap_or_else(|e| panic!("cannot write {out}: {e}"));
    println!("wrote {out}");
}
