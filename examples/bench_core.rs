//! Core benchmark: timings of the exact optics and of the closed-form spectral integration,
//! the analytic method's colour accuracy on many random plates, and its error/time trade-off
//! against stochastic (hero-wavelength) spectral sampling.
//!
//! ```text
//! cargo run --release --example bench_core -- [--validate N] [--plates M] [--seeds S] [--out FILE]
//! ```
//! * `--validate N` (default 500): the validation run of `tests/spectral_rgb.rs` (the same code,
//!   included as a module) on `N` random plates: CIEDE2000 of the analytic XYZ colours against
//!   dense quadrature of the exact plate.
//! * `--plates M` (default 100, at most N): the first `M` of those plates are the test set of the
//!   error-vs-time comparison; their quadrature colours are its reference.
//! * `--seeds S` (default 6): independent seeds of the stochastic estimator per plate.
//! * `--out FILE` (default `bench/out/core.json`).
//!
//! Everything runs on one thread (pin it: the Makefile runs it under `taskset -c 0`). Timings are
//! medians over repetitions of a timed loop (counts in the output), with the inputs cycled through
//! a set of precomputed random ones and `std::hint::black_box` on inputs and results.
//!
//! Stochastic estimator (what an unbiased spectral renderer does per pixel sample): the
//! crossed-polariser transmission XYZ of a plate from `N` wavelengths, hero-wavelength style:
//! one uniform `u₀` per estimate, `u_i = frac(u₀ + i/N)` (rotations of the hero, i.e.
//! stratified), `λ_i = P⁻¹(u_i)` with `p(λ) = (|w_X| + |w_Y| + |w_Z|)/3` (the mean of the three
//! normalised tabulated `xyz-d65` weights, which are ≥ 0: one sample serves all three channels;
//! "sample from the sum and weight"), and
//! `XYZ_c ≈ (1/N) Σ f(λ_i) w_c(λ_i)/p(λ_i)`. `p` is the same piecewise-linear function as the
//! tables, sampled exactly (quadratic inverse per 1-nm bin), so the estimator is unbiased for
//! the quadrature reference. Each sample evaluates the exact plate (indices at `λ_i`, both
//! interfaces, the transmission Mueller matrix; for a non-dispersive plate the interfaces are
//! solved once per estimate, as the closed form also does). A second curve uses independent
//! (i.i.d.) `u_i` for comparison. The analytic method is timed for the same output (transmission
//! Mueller matrix, 3 channels) and for reflection + transmission.

#[path = "../tests/spectral_rgb.rs"]
mod spectral_rgb;

use birefringent::colour::weights::weight_per_nm;
use birefringent::colour::weights::WeightSet;
use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::optics::interface::Interface;
use birefringent::optics::medium::Uniaxial;
use birefringent::params::Thickness;
use birefringent::plate::slab::Output;
use birefringent::plate::slab::{Slab, SlabOptics, Want};
use birefringent::plate::Plate;
use birefringent::quadrature::Accuracy;
use birefringent::spectral::model::{PlateModel, ThinModel};
use birefringent::spectral::route::{self, Route};
use birefringent::spectral::survey::Survey;
use birefringent::C64;
use serde_json::{json, Value};
use spectral_rgb::{Case, Outcome, Rng, QUANTITIES, RANGE, SET};
use std::hint::black_box;
use std::time::Instant;

/// Sample counts of the stochastic estimator.
const SAMPLE_COUNTS: [usize; 8] = [1, 4, 16, 64, 256, 1024, 4096, 16384];
/// The issue's goals.
const GOAL_INTERFACE_NS: f64 = 100.0;
const GOAL_MUELLER_NS: f64 = 500.0;
/// At the analytic method's own mean error, against stratified hero sampling.
const GOAL_SPEEDUP: f64 = 200.0;
/// At mean CIEDE2000 [`HALF_DE`], against stratified hero sampling.
const GOAL_SPEEDUP_AT_HALF: f64 = 20.0;
const HALF_DE: f64 = 0.5;
const GOAL_ANALYTIC_DE: f64 = 0.5;
const TARGET_DE: f64 = 1.0;
/// Per-plate analytic time over the extended validation set (T Mueller, 3 channels of
/// `xyz-d65`): median, mean, p99, max (issue 20, goal 1).
const GOAL_MEDIAN_US: f64 = 8.0;
const GOAL_MEAN_US: f64 = 15.0;
const GOAL_P99_US: f64 = 60.0;
const GOAL_MAX_US: f64 = 500.0;
/// The sRGB reflection and transmission Mueller matrices of one render query: median, p99.
const GOAL_RENDER_MEDIAN_US: f64 = 15.0;
const GOAL_RENDER_P99_US: f64 = 100.0;
/// The calculator's analytic `xyz-d65` slab line against its exact (one wavelength) line, on
/// average over random plates 0.5-1000 um at 0-60 degrees (issue 20, goal 3), and its mean
/// time per line (issue 30).
const GOAL_CALCULATOR_RATIO: f64 = 2.0;
const GOAL_CALCULATOR_MEAN_US: f64 = 50.0;
/// The first analytic query of a process, any named crystal (issue 30, item 4).
const GOAL_FIRST_QUERY_MS: f64 = 10.0;
/// Plates of the near-grazing hard set (issue 30).
const HARD_PLATES: usize = 40;
const T_ONLY: Want = Want {
    reflection: false,
    transmission: true,
};

struct Args {
    validate: usize,
    plates: usize,
    seeds: usize,
    out: String,
}

fn parse_args() -> Args {
    let mut a = Args {
        validate: 500,
        plates: 100,
        seeds: 6,
        out: "bench/out/core.json".into(),
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    while i < args.len() {
        let value = |i: usize| -> &str {
            args.get(i + 1).map(String::as_str).unwrap_or_else(|| {
                eprintln!("{} needs a value", args[i]);
                std::process::exit(2)
            })
        };
        let number = |i: usize| -> usize {
            value(i).parse().unwrap_or_else(|_| {
                eprintln!("{} needs a positive integer", args[i]);
                std::process::exit(2)
            })
        };
        match args[i].as_str() {
            "--validate" => a.validate = number(i),
            "--plates" => a.plates = number(i),
            "--seeds" => a.seeds = number(i),
            "--out" => a.out = value(i).to_string(),
            "-h" | "--help" => {
                println!("usage: bench_core [--validate N] [--plates M] [--seeds S] [--out FILE]");
                std::process::exit(0)
            }
            other => {
                eprintln!("unknown argument {other}");
                std::process::exit(2)
            }
        }
        i += 2;
    }
    a.plates = a.plates.min(a.validate).max(1);
    a.validate = a.validate.max(1);
    a.seeds = a.seeds.max(1);
    a
}

// ---- machine -----------------------------------------------------------------------------

fn read(path: &str) -> String {
    std::fs::read_to_string(path).unwrap_or_default()
}

fn loadavg() -> String {
    read("/proc/loadavg")
        .split_whitespace()
        .take(3)
        .collect::<Vec<_>>()
        .join(" ")
}

fn machine() -> Value {
    let cpuinfo = read("/proc/cpuinfo");
    let field = |name: &str| {
        cpuinfo
            .lines()
            .find(|l| l.starts_with(name))
            .and_then(|l| l.split_once(':'))
            .map(|(_, v)| v.trim().to_string())
            .unwrap_or_default()
    };
    let nproc = |args: &[&str]| {
        std::process::Command::new("nproc")
            .args(args)
            .output()
            .ok()
            .and_then(|o| String::from_utf8(o.stdout).ok())
            .and_then(|s| s.trim().parse::<usize>().ok())
    };
    let affinity = read("/proc/self/status")
        .lines()
        .find(|l| l.starts_with("Cpus_allowed_list"))
        .and_then(|l| l.split_once(':'))
        .map(|(_, v)| v.trim().to_string())
        .unwrap_or_default();
    json!({
        "nproc": nproc(&[]),
        "nproc_all": nproc(&["--all"]),
        "cpu_model": field("model name"),
        "cpu_mhz": field("cpu MHz"),
        "logical_cpus_in_cpuinfo": cpuinfo.lines().filter(|l| l.starts_with("processor")).count(),
        "cpus_allowed": affinity,
        "loadavg_at_start": loadavg(),
        "os": read("/proc/sys/kernel/osrelease").trim(),
        "note": "shared machine: other builds may run concurrently; see loadavg",
    })
}

// ---- timing ------------------------------------------------------------------------------

/// Median (and spread) of `reps` timings of `inner` calls of `f(i)`, ns per call.
struct Timing {
    median_ns: f64,
    min_ns: f64,
    max_ns: f64,
    reps: usize,
    inner: usize,
}

impl Timing {
    fn json(&self) -> Value {
        json!({"median_ns": self.median_ns, "min_ns": self.min_ns, "max_ns": self.max_ns,
               "repetitions": self.reps, "calls_per_repetition": self.inner})
    }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn time_calls(reps: usize, inner: usize, mut f: impl FnMut(usize)) -> Timing {
    for i in 0..inner.min(1000) {
        f(i); // warm-up
    }
    let mut per_call: Vec<f64> = (0..reps)
        .map(|_| {
            let t = Instant::now();
            for i in 0..inner {
                f(i);
            }
            t.elapsed().as_secs_f64() * 1e9 / inner as f64
        })
        .collect();
    let (min, max) = (
        per_call.iter().copied().fold(f64::INFINITY, f64::min),
        per_call.iter().copied().fold(0.0, f64::max),
    );
    Timing {
        median_ns: median(&mut per_call),
        min_ns: min,
        max_ns: max,
        reps,
        inner,
    }
}

// ---- micro-benchmarks ------------------------------------------------------------------------

const SET_SIZE: usize = 64;

fn micro() -> Value {
    let mut rng = Rng::new(99);
    // (i) air above a uniaxial crystal (calcite-like, random axis in the working frame).
    let air = Uniaxial::isotropic(C64::new(1.0, 0.0)).unwrap();
    let iface: Vec<(Uniaxial, C64)> = (0..SET_SIZE)
        .map(|_| {
            let crystal = Uniaxial::new(
                C64::new(1.658, 0.0),
                C64::new(1.486, 0.0),
                rng.unit_vector(),
            )
            .unwrap();
            (crystal, C64::new(rng.range(0.0, 0.94), 0.0))
        })
        .collect();
    let interface = time_calls(25, 20_000, |i| {
        let (crystal, beta) = black_box(&iface[i % SET_SIZE]);
        black_box(Interface::new(black_box(&air), crystal, *beta).unwrap());
    });
    // (ii) exact plate per wavelength: constant-index slabs (quartz-like), random incidence.
    let slabs: Vec<(Slab, PlaneFrame, C64, f64)> = (0..SET_SIZE)
        .map(|_| {
            let layer = Uniaxial::new(
                C64::new(1.544, 0.0),
                C64::new(1.553, 0.0),
                rng.unit_vector(),
            )
            .unwrap();
            let slab = Slab::new(
                C64::new(1.0, 0.0),
                layer,
                C64::new(1.5, 0.0),
                Thickness::from_nm(rng.log_range(500.0, 5e6)).unwrap(),
            )
            .unwrap();
            let frame = PlaneFrame::from_azimuth(rng.range(0.0, std::f64::consts::TAU));
            (
                slab,
                frame,
                C64::new(rng.range(0.0, 0.94), 0.0),
                rng.range(360.0, 830.0),
            )
        })
        .collect();
    let optics_mueller = time_calls(25, 10_000, |i| {
        let (slab, frame, beta, lambda) = black_box(&slabs[i % SET_SIZE]);
        let o = slab.optics(frame, *beta).unwrap();
        black_box(o.mueller(*lambda, Want::BOTH).unwrap());
    });
    let optics_mueller_t = time_calls(25, 10_000, |i| {
        let (slab, frame, beta, lambda) = black_box(&slabs[i % SET_SIZE]);
        let o = slab.optics(frame, *beta).unwrap();
        black_box(o.mueller(*lambda, T_ONLY).unwrap());
    });
    let optics_only = time_calls(25, 10_000, |i| {
        let (slab, frame, beta, _) = black_box(&slabs[i % SET_SIZE]);
        black_box(slab.optics(frame, *beta).unwrap());
    });
    let fixed: Vec<(SlabOptics, f64)> = slabs
        .iter()
        .map(|(s, f, b, l)| (s.optics(f, *b).unwrap(), *l))
        .collect();
    let mueller_fixed = time_calls(25, 20_000, |i| {
        let (o, lambda) = black_box(&fixed[i % SET_SIZE]);
        black_box(o.mueller(*lambda, Want::BOTH).unwrap());
    });
    // Dispersive plate (quartz): indices at λ, interfaces, Mueller matrices.
    let quartz = Material::named("quartz", 0.0, 0.0).unwrap();
    let plates: Vec<(Plate, PlaneFrame, C64, f64)> = slabs
        .iter()
        .map(|(s, f, b, l)| {
            let p = Plate {
                material: quartz,
                birefringence: 0.0,
                ext: s.top.eta_o,
                exit: s.bottom.eta_o,
                axis: s.layer.axis,
                thickness_nm: s.thickness_nm,
            };
            (p, *f, *b, *l)
        })
        .collect();
    let plate_at = time_calls(25, 10_000, |i| {
        let (p, frame, beta, lambda) = black_box(&plates[i % SET_SIZE]);
        let o = p.at(*lambda).unwrap().optics(frame, *beta).unwrap();
        black_box(o.mueller(*lambda, Want::BOTH).unwrap());
    });
    let plate_at_t = time_calls(25, 10_000, |i| {
        let (p, frame, beta, lambda) = black_box(&plates[i % SET_SIZE]);
        let o = p.at(*lambda).unwrap().optics(frame, *beta).unwrap();
        black_box(o.mueller(*lambda, T_ONLY).unwrap());
    });
    let v = json!({
        "interface_iso_to_aniso": interface.json(),
        "plate_optics_plus_mueller_RT": optics_mueller.json(),
        "plate_optics_plus_mueller_T": optics_mueller_t.json(),
        "plate_optics_only": optics_only.json(),
        "plate_mueller_fixed_optics_RT": mueller_fixed.json(),
        "dispersive_plate_at_optics_mueller_RT": plate_at.json(),
        "dispersive_plate_at_optics_mueller_T": plate_at_t.json(),
        "goals": {
            "interface_ns": GOAL_INTERFACE_NS,
            "interface_met": interface.median_ns <= GOAL_INTERFACE_NS,
            "mueller_per_wavelength_ns": GOAL_MUELLER_NS,
            "optics_plus_mueller_met": optics_mueller.median_ns <= GOAL_MUELLER_NS,
            "fixed_optics_mueller_met": mueller_fixed.median_ns <= GOAL_MUELLER_NS,
            "dispersive_met": plate_at.median_ns <= GOAL_MUELLER_NS,
        },
        "loadavg": loadavg(),
    });
    let line = |name: &str, t: &Timing, goal: Option<f64>| {
        let g = goal.map_or(String::new(), |g| {
            format!(
                "  (goal <= {g} ns: {})",
                if t.median_ns <= g { "met" } else { "NOT met" }
            )
        });
        println!(
            "  {name:<58} median {:>8.1} ns  [min {:.1}, max {:.1}; {} x {} calls]{g}",
            t.median_ns, t.min_ns, t.max_ns, t.reps, t.inner
        );
    };
    line(
        "(i) Interface::new air -> uniaxial",
        &interface,
        Some(GOAL_INTERFACE_NS),
    );
    line(
        "(ii) slab.optics + mueller (R+T), constant indices",
        &optics_mueller,
        Some(GOAL_MUELLER_NS),
    );
    line(
        "     slab.optics + mueller (T only)",
        &optics_mueller_t,
        None,
    );
    line(
        "     slab.optics only (both interfaces)",
        &optics_only,
        None,
    );
    line(
        "     mueller (R+T) with fixed optics",
        &mueller_fixed,
        Some(GOAL_MUELLER_NS),
    );
    line(
        "     quartz: plate.at(l) + optics + mueller (R+T)",
        &plate_at,
        Some(GOAL_MUELLER_NS),
    );
    line(
        "     quartz: plate.at(l) + optics + mueller (T only)",
        &plate_at_t,
        None,
    );
    v
}

// ---- stochastic sampling -----------------------------------------------------------------------

/// `p(λ) = (|w_X| + |w_Y| + |w_Z|)/3` on the 1-nm grid (piecewise linear) and its CDF.
struct Sampler {
    pdf: Vec<f64>,
    cdf: Vec<f64>,
}

impl Sampler {
    fn new() -> Self {
        let n = (RANGE.1 - RANGE.0) as usize + 1;
        let pdf: Vec<f64> = (0..n)
            .map(|i| {
                (0..3)
                    .map(|c| weight_per_nm(SET, c, RANGE.0 + i as f64).abs())
                    .sum::<f64>()
                    / 3.0
            })
            .collect();
        let mut cdf = vec![0.0; n];
        for i in 1..n {
            cdf[i] = cdf[i - 1] + 0.5 * (pdf[i - 1] + pdf[i]);
        }
        let total = cdf[n - 1];
        let pdf = pdf.iter().map(|p| p / total).collect();
        let cdf = cdf.iter().map(|c| c / total).collect();
        Sampler { pdf, cdf }
    }

    /// `λ = P⁻¹(u)` and `p(λ)`.
    fn sample(&self, u: f64) -> (f64, f64) {
        let n = self.cdf.len();
        let i = self.cdf.partition_point(|c| *c <= u).clamp(1, n - 1) - 1;
        let (p0, p1) = (self.pdf[i], self.pdf[i + 1]);
        let r = u - self.cdf[i]; // mass to cover inside the bin: p0 t + (p1 - p0) t²/2 = r
        let a = 0.5 * (p1 - p0);
        let t = if a.abs() < 1e-14 * p0.max(1e-300) {
            r / p0
        } else {
            let disc = (p0 * p0 + 4.0 * a * r).max(0.0);
            2.0 * r / (p0 + disc.sqrt())
        };
        let t = t.clamp(0.0, 1.0);
        (RANGE.0 + i as f64 + t, p0 + (p1 - p0) * t)
    }
}

/// N-sample estimate of the crossed-polariser XYZ of `case`.
fn stochastic(case: &Case, sampler: &Sampler, n: usize, rng: &mut Rng, hero: bool) -> [f64; 3] {
    let (frame, beta, plate) = (case.frame(), case.beta(), &case.plate);
    let fixed = if plate.is_dispersive() {
        None
    } else {
        Some(plate.at(550.0).unwrap().optics(&frame, beta).unwrap())
    };
    let u0 = rng.uniform();
    let mut xyz = [0.0; 3];
    for i in 0..n {
        let u = if hero {
            (u0 + i as f64 / n as f64).fract()
        } else if i == 0 {
            u0
        } else {
            rng.uniform()
        };
        let (lambda, pdf) = sampler.sample(u);
        let optics = match fixed {
            Some(o) => o,
            None => plate.at(lambda).unwrap().optics(&frame, beta).unwrap(),
        };
        let t = optics.mueller(lambda, T_ONLY).unwrap().t.unwrap();
        let f = spectral_rgb::crossed(&t) / pdf;
        for (c, x) in xyz.iter_mut().enumerate() {
            *x += f * weight_per_nm(SET, c, lambda);
        }
    }
    xyz.map(|x| x / n as f64)
}

/// Closed form for the crossed-polariser colour (transmission only, or both lobes): all three
/// channels through the renderer's path (`PlateModel::channels`, perceptual accuracy).
fn analytic_crossed(case: &Case, want: Want) -> [f64; 3] {
    let ms = PlateModel::new(&case.plate, case.frame(), case.beta())
        .channels(SET, want, Output::Mueller, Accuracy::Perceptual)
        .unwrap();
    std::array::from_fn(|c| spectral_rgb::crossed(&ms[c].t.unwrap()))
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// log-log interpolation of the time at which the error curve reaches `target` (first crossing);
/// extrapolates along the last segment if never reached (flagged).
fn time_to_reach(points: &[(f64, f64)], target: f64) -> (Option<f64>, bool) {
    for w in points.windows(2) {
        let ((t0, e0), (t1, e1)) = (w[0], w[1]);
        if e0 > target && e1 <= target {
            let s = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
            return (Some((t0.ln() + s * (t1.ln() - t0.ln())).exp()), false);
        }
    }
    if points.first().is_some_and(|p| p.1 <= target) {
        return (Some(points[0].0), false);
    }
    let n = points.len();
    if n >= 2 {
        let ((t0, e0), (t1, e1)) = (points[n - 2], points[n - 1]);
        if e1 < e0 {
            let s = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
            return (Some((t0.ln() + s * (t1.ln() - t0.ln())).exp()), true);
        }
    }
    (None, true)
}

fn stochastic_study(outcomes: &[Outcome], seeds: usize) -> Value {
    let cases: Vec<&Case> = outcomes.iter().map(|o| &o.case).collect();
    let refs: Vec<[f64; 3]> = outcomes.iter().map(|o| o.reference.tabulated[0]).collect();
    let np = cases.len() as f64;
    // Analytic: same output (T Mueller, 3 channels) and both lobes; whole-set timings.
    let reps = 7;
    let mut analytic_xyz = vec![[0.0; 3]; cases.len()];
    let time_set = |want: Want, store: bool, out: &mut Vec<[f64; 3]>| -> (f64, Vec<f64>) {
        let mut totals = Vec::new();
        let mut per_plate = vec![Vec::new(); cases.len()];
        for _ in 0..reps {
            let t = Instant::now();
            for (i, c) in cases.iter().enumerate() {
                let ti = Instant::now();
                let xyz = black_box(analytic_crossed(black_box(c), want));
                per_plate[i].push(ti.elapsed().as_secs_f64());
                if store {
                    out[i] = xyz;
                }
            }
            totals.push(t.elapsed().as_secs_f64());
        }
        let pp: Vec<f64> = per_plate.iter_mut().map(|v| median(v)).collect();
        (median(&mut totals) / np, pp)
    };
    let (analytic_t, analytic_pp) = time_set(T_ONLY, true, &mut analytic_xyz);
    let (analytic_rt, analytic_rt_pp) = time_set(Want::BOTH, false, &mut analytic_xyz);
    let analytic_de: Vec<f64> = analytic_xyz
        .iter()
        .zip(&refs)
        .map(|(a, r)| spectral_rgb::delta_e(*a, *r))
        .collect();
    let a_stats = spectral_rgb::stats(&analytic_de);
    let mut pp_sorted = analytic_pp.clone();
    let mut pp_rt_sorted = analytic_rt_pp.clone();
    println!(
        "  analytic (T Mueller, 3 channels): {:.2} us per plate (mean over {} plates, median of {reps} set timings; \
         per-plate median {:.2} us); R+T: {:.2} us; mean CIEDE2000 {:.4} (median {:.4}, worst {:.4})",
        analytic_t * 1e6,
        cases.len(),
        median(&mut pp_sorted) * 1e6,
        analytic_rt * 1e6,
        a_stats.mean,
        a_stats.median,
        a_stats.worst
    );

    let sampler = Sampler::new();
    let mut curves = serde_json::Map::new();
    let (mut hero_points, mut iid_points) = (Vec::new(), Vec::new());
    for hero in [true, false] {
        let name = if hero { "hero" } else { "iid" };
        let mut rows = Vec::new();
        for &n in &SAMPLE_COUNTS {
            let mut set_times = Vec::new();
            let mut errors = Vec::new();
            let mut seed_means = Vec::new();
            for s in 0..seeds {
                let mut rng = Rng::new(
                    0x5eed_0000 + 1000 * s as u64 + n as u64 + if hero { 0 } else { 1 << 40 },
                );
                let t = Instant::now();
                let est: Vec<[f64; 3]> = cases
                    .iter()
                    .map(|c| black_box(stochastic(black_box(c), &sampler, n, &mut rng, hero)))
                    .collect();
                set_times.push(t.elapsed().as_secs_f64());
                let e: Vec<f64> = est
                    .iter()
                    .zip(&refs)
                    .map(|(a, r)| spectral_rgb::delta_e(*a, *r))
                    .collect();
                seed_means.push(mean(&e));
                errors.extend(e);
            }
            let t = median(&mut set_times) / np;
            let m = mean(&errors);
            let st = spectral_rgb::stats(&errors);
            let sd = (seed_means.iter().map(|x| (x - m).powi(2)).sum::<f64>()
                / (seeds.max(2) - 1) as f64)
                .sqrt();
            println!(
                "  {name:>4} N = {n:>5}: {:>10.2} us per plate, mean CIEDE2000 {:>8.4} (median {:.4}, worst {:.3}; \
                 std of seed means {:.4})",
                t * 1e6,
                m,
                st.median,
                st.worst,
                sd
            );
            if hero {
                hero_points.push((t, m));
            } else {
                iid_points.push((t, m));
            }
            rows.push(
                json!({"n": n, "seconds_per_plate": t, "mean_de": m, "median_de": st.median,
                             "worst_de": st.worst, "std_of_seed_means": sd, "seeds": seeds,
                             "timing_repetitions": seeds}),
            );
        }
        curves.insert(name.into(), Value::Array(rows));
    }
    let (t_half, extrap_half) = time_to_reach(&hero_points, HALF_DE);
    let ratio_half = t_half.map(|t| t / analytic_t);
    let (t1, extrap1) = time_to_reach(&hero_points, TARGET_DE);
    let (t_eq, extrap_eq) = time_to_reach(&hero_points, a_stats.mean);
    let ratio1 = t1.map(|t| t / analytic_t);
    let ratio_eq = t_eq.map(|t| t / analytic_t);
    let analytic_median = median(&mut analytic_pp.clone());
    let ratio1_median = t1.map(|t| t / analytic_median);
    // The issue's premise ("2-5 at N = 1024") is independent wavelengths: the same comparison.
    let (t1_iid, extrap1_iid) = time_to_reach(&iid_points, TARGET_DE);
    let ratio_eq_median = t_eq.map(|t| t / analytic_median);
    let quantile = |v: &[f64], q: f64| {
        let mut s = v.to_vec();
        s.sort_by(f64::total_cmp);
        // Nearest rank: the smallest value with at least a fraction q of the values <= it.
        s[((q * s.len() as f64).ceil() as usize).clamp(1, s.len()) - 1]
    };
    let slowest = (0..cases.len())
        .max_by(|a, b| analytic_rt_pp[*a].total_cmp(&analytic_rt_pp[*b]))
        .unwrap_or(0);
    println!(
        "  analytic per-plate time (T only): p10 {:.3} ms, median {:.3} ms, p90 {:.3} ms, p99 {:.3} ms, max {:.3} ms; \
         slowest (R+T, {:.1} ms): {}",
        quantile(&analytic_pp, 0.1) * 1e3,
        analytic_median * 1e3,
        quantile(&analytic_pp, 0.9) * 1e3,
        quantile(&analytic_pp, 0.99) * 1e3,
        quantile(&analytic_pp, 1.0) * 1e3,
        analytic_rt_pp[slowest] * 1e3,
        cases[slowest].describe()
    );
    println!(
        "  against the analytic's median per-plate time: {} x at CIEDE2000 {TARGET_DE}, {} x at the analytic's error",
        ratio1_median.map_or("-".into(), |r| format!("{r:.3}")),
        ratio_eq_median.map_or("-".into(), |r| format!("{r:.3}"))
    );
    println!(
        "  stochastic (hero) reaches mean CIEDE2000 {HALF_DE}: {} -> {} x the analytic time{} (goal >= {GOAL_SPEEDUP_AT_HALF}: {})",
        t_half.map_or("never".into(), |t| format!("{:.1} us", t * 1e6)),
        ratio_half.map_or("-".into(), |r| format!("{r:.3}")),
        if extrap_half { " (extrapolated)" } else { "" },
        if ratio_half.is_some_and(|r| r >= GOAL_SPEEDUP_AT_HALF) { "met" } else { "NOT met" }
    );
    println!(
        "  stochastic (hero) reaches mean CIEDE2000 {TARGET_DE}: {} -> {} x the analytic time{}",
        t1.map_or("never".into(), |t| format!("{:.1} us", t * 1e6)),
        ratio1.map_or("-".into(), |r| format!("{r:.3}")),
        if extrap1 { " (extrapolated)" } else { "" }
    );
    println!(
        "  stochastic (iid) reaches mean CIEDE2000 {TARGET_DE}: {} -> {} x the analytic time, {} x its median{}",
        t1_iid.map_or("never".into(), |t| format!("{:.1} us", t * 1e6)),
        t1_iid.map_or("-".into(), |t| format!("{:.3}", t / analytic_t)),
        t1_iid.map_or("-".into(), |t| format!("{:.3}", t / analytic_median)),
        if extrap1_iid { " (extrapolated)" } else { "" }
    );
    println!(
        "  stochastic (hero) reaches the analytic's mean CIEDE2000 {:.4}: {} -> {} x{} (goal >= {GOAL_SPEEDUP}: {})",
        a_stats.mean,
        t_eq.map_or("never".into(), |t| format!("{:.1} us", t * 1e6)),
        ratio_eq.map_or("-".into(), |r| format!("{r:.3}")),
        if extrap_eq {
            " (extrapolated along the last segment)"
        } else {
            ""
        },
        if ratio_eq.is_some_and(|r| r >= GOAL_SPEEDUP) { "met" } else { "NOT met" }
    );
    json!({
        "plates": cases.len(),
        "quantity": "crossed-polariser transmission XYZ (xyz-d65), CIEDE2000 against the quadrature reference",
        "sampling": "hero: u_i = frac(u0 + i/N), lambda_i = P^-1(u_i), p = (|w_X| + |w_Y| + |w_Z|)/3 (tabulated, \
                     normalised), XYZ_c = mean(f w_c / p); iid: independent u_i, same pdf",
        "analytic": {
            "seconds_per_plate_T": analytic_t,
            "seconds_per_plate_RT": analytic_rt,
            "median_seconds_per_plate_T": median(&mut pp_sorted),
            "median_seconds_per_plate_RT": median(&mut pp_rt_sorted),
            "per_plate_seconds_T_quantiles": {
                "p10": quantile(&analytic_pp, 0.1), "p50": analytic_median, "p90": quantile(&analytic_pp, 0.9),
                "p99": quantile(&analytic_pp, 0.99), "max": quantile(&analytic_pp, 1.0),
            },
            "slowest_plate_RT": {"seconds": analytic_rt_pp[slowest], "description": cases[slowest].describe(),
                                 "reproducer": cases[slowest].reproducer()},
            "timing_repetitions": reps,
            "mean_de": a_stats.mean, "median_de": a_stats.median, "worst_de": a_stats.worst,
        },
        "stochastic": Value::Object(curves),
        "target_de": TARGET_DE,
        "half_de": HALF_DE,
        "stochastic_seconds_to_half": t_half,
        "stochastic_seconds_to_half_extrapolated": extrap_half,
        "speedup_at_half": ratio_half,
        "stochastic_seconds_to_target": t1,
        "stochastic_seconds_to_target_extrapolated": extrap1,
        "speedup_at_target": ratio1,
        "stochastic_seconds_to_analytic_error": t_eq,
        "stochastic_seconds_to_analytic_error_extrapolated": extrap_eq,
        "speedup_at_analytic_error": ratio_eq,
        "speedup_at_target_vs_median_analytic_time": ratio1_median,
        "iid_seconds_to_target": t1_iid,
        "iid_seconds_to_target_extrapolated": extrap1_iid,
        "speedup_at_target_vs_iid": t1_iid.map(|t| t / analytic_t),
        "speedup_at_target_vs_iid_median_analytic_time": t1_iid.map(|t| t / analytic_median),
        "speedup_at_analytic_error_vs_median_analytic_time": ratio_eq_median,
        "goals": {
            "speedup": GOAL_SPEEDUP,
            "speedup_met_at_analytic_error": ratio_eq.map(|r| r >= GOAL_SPEEDUP),
            "speedup_at_half": GOAL_SPEEDUP_AT_HALF,
            "speedup_met_at_half": ratio_half.map(|r| r >= GOAL_SPEEDUP_AT_HALF),
            "analytic_mean_de": GOAL_ANALYTIC_DE,
            "analytic_mean_de_met": a_stats.mean < GOAL_ANALYTIC_DE,
            "analytic_worst_de_below_goal": a_stats.worst < GOAL_ANALYTIC_DE,
        },
    })
}

// ---- analytic time over the validation set -------------------------------------------------------

/// Quantiles of per-plate times (seconds): median, mean, p90, p99 and max, in microseconds.
fn quantiles(per_plate: &mut [f64]) -> (f64, f64, f64, f64, f64) {
    let mean_t = mean(per_plate);
    per_plate.sort_by(f64::total_cmp);
    let n = per_plate.len();
    let q = |p: f64| per_plate[((p * n as f64).ceil() as usize).clamp(1, n) - 1] * 1e6;
    (
        q(0.5),
        mean_t * 1e6,
        q(0.9),
        q(0.99),
        per_plate[n - 1] * 1e6,
    )
}

/// The median of `reps` timed calls of `f` (after one untimed call, which builds the rules a
/// first query of a process builds once), in seconds.
fn median_time(reps: usize, mut f: impl FnMut()) -> f64 {
    f();
    let mut t: Vec<f64> = (0..reps)
        .map(|_| {
            let t0 = Instant::now();
            f();
            t0.elapsed().as_secs_f64()
        })
        .collect();
    median(&mut t)
}

fn verdict(x: f64, goal: f64) -> &'static str {
    if x <= goal {
        "met"
    } else {
        "NOT met"
    }
}

/// The analytic method's time per plate over every plate of the extended set (`cases`): the
/// transmission Mueller matrix over the three channels of `xyz-d65` (goal 1), and the sRGB
/// reflection and transmission Mueller matrices a render query asks for (`srgb-d65`, both
/// lobes), each the median of 9 timed calls per plate; and per route, its share of the plates
/// and its median.
fn analytic_timing(cases: &[Case]) -> Value {
    let reps = 9;
    let time = |c: &Case, set: WeightSet, want: Want| {
        median_time(reps, || {
            black_box(
                PlateModel::new(black_box(&c.plate), c.frame(), c.beta())
                    .channels(set, want, Output::Mueller, Accuracy::Perceptual)
                    .unwrap(),
            );
        })
    };
    let mut xyz: Vec<f64> = cases.iter().map(|c| time(c, SET, T_ONLY)).collect();
    let mut render: Vec<f64> = cases
        .iter()
        .map(|c| time(c, WeightSet::SrgbD65, Want::BOTH))
        .collect();
    let mut routes: std::collections::BTreeMap<&'static str, Vec<f64>> = Default::default();
    for (c, t) in cases.iter().zip(&xyz) {
        let survey = Survey::new(&c.plate, c.frame(), c.beta()).unwrap();
        let name = match route::channels(&survey, SET, Accuracy::Perceptual) {
            Route::Envelope(e) if e.families.is_none() => "envelope (whole plate)",
            Route::Envelope(_) => "envelope (families of orders)",
            Route::Classes(_) => "path classes",
            Route::Dense(_) => "dense rule",
            Route::Pointwise(_) => "pointwise (exact blocks)",
            Route::Gaussians => "Gaussian by Gaussian",
        };
        routes.entry(name).or_default().push(*t);
    }
    let n = cases.len();
    let (med, mean_t, p90, p99, max) = quantiles(&mut xyz);
    let (rmed, rmean, rp90, rp99, rmax) = quantiles(&mut render);
    println!(
        "  xyz-d65 T Mueller over {n} plates: median {med:.2} us (goal <= {GOAL_MEDIAN_US}: {}), mean {mean_t:.2} us \
         (goal <= {GOAL_MEAN_US}: {}), p90 {p90:.1} us, p99 {p99:.1} us (goal <= {GOAL_P99_US}: {}), max {max:.1} us \
         (goal <= {GOAL_MAX_US}: {})",
        verdict(med, GOAL_MEDIAN_US),
        verdict(mean_t, GOAL_MEAN_US),
        verdict(p99, GOAL_P99_US),
        verdict(max, GOAL_MAX_US),
    );
    println!(
        "  srgb-d65 R and T Mueller (a render query) over {n} plates: median {rmed:.2} us (goal <= {GOAL_RENDER_MEDIAN_US}: {}), \
         mean {rmean:.2} us, p90 {rp90:.1} us, p99 {rp99:.1} us (goal <= {GOAL_RENDER_P99_US}: {}), max {rmax:.1} us",
        verdict(rmed, GOAL_RENDER_MEDIAN_US),
        verdict(rp99, GOAL_RENDER_P99_US),
    );
    let per_route: serde_json::Map<String, Value> = routes
        .iter_mut()
        .map(|(name, t)| {
            let count = t.len();
            let (m, avg, _, _, worst) = quantiles(t);
            println!(
                "    {name}: {count} plates ({:.0} %), median {m:.2} us, mean {avg:.2} us, max {worst:.1} us",
                100.0 * count as f64 / n as f64
            );
            (
                name.to_string(),
                json!({"plates": count, "median_us": m, "mean_us": avg, "max_us": worst}),
            )
        })
        .collect();
    json!({
        "plates": n,
        "repetitions_per_plate": reps,
        "xyz_transmission": {
            "median_us": med, "mean_us": mean_t, "p90_us": p90, "p99_us": p99, "max_us": max,
            "goals": {
                "median_us": GOAL_MEDIAN_US, "median_met": med <= GOAL_MEDIAN_US,
                "mean_us": GOAL_MEAN_US, "mean_met": mean_t <= GOAL_MEAN_US,
                "p99_us": GOAL_P99_US, "p99_met": p99 <= GOAL_P99_US,
                "max_us": GOAL_MAX_US, "max_met": max <= GOAL_MAX_US,
            },
        },
        "srgb_render_query": {
            "median_us": rmed, "mean_us": rmean, "p90_us": rp90, "p99_us": rp99, "max_us": rmax,
            "goals": {
                "median_us": GOAL_RENDER_MEDIAN_US, "median_met": rmed <= GOAL_RENDER_MEDIAN_US,
                "p99_us": GOAL_RENDER_P99_US, "p99_met": rp99 <= GOAL_RENDER_P99_US,
            },
        },
        "routes": per_route,
    })
}

/// The calculator's analytic `xyz-d65` slab line against its exact line (one wavelength, 550
/// nm), each as `birefringence slab` runs a line (JSON in, JSON out), over random plates
/// 0.5-1000 um at 0-60 degrees (the crystals and constant indices of the validation set):
/// the mean time per line of each, and their ratio (goal 3).
fn calculator(plates: usize) -> Value {
    let mut rng = Rng::new(0xCA1C);
    let mut exact = Vec::with_capacity(plates);
    let mut analytic = Vec::with_capacity(plates);
    for i in 0..plates {
        let mut case = spectral_rgb::random_case(&mut rng, i);
        case.plate.thickness_nm = rng.log_range(500.0, 1e6);
        case.theta_deg = rng.range(0.0, 60.0);
        let line = case.reproducer();
        let mut mono = line.clone();
        mono.as_object_mut().expect("an object").remove("spectrum");
        let (mono, line) = (mono.to_string(), line.to_string());
        let run = |text: &str| {
            let (out, ok) = birefringent::calc::run_text("slab", text);
            assert!(ok, "{text}: {out}");
            black_box(out.to_string());
        };
        exact.push(median_time(9, || run(&mono)));
        analytic.push(median_time(9, || run(&line)));
    }
    let (e, a) = (mean(&exact) * 1e6, mean(&analytic) * 1e6);
    let ratio = a / e;
    println!(
        "  calculator, {plates} random plates 0.5-1000 um at 0-60 deg: exact line {e:.1} us, analytic xyz-d65 line {a:.1} us on average \
         (goal <= {GOAL_CALCULATOR_MEAN_US} us: {}): ratio {ratio:.2} (goal <= {GOAL_CALCULATOR_RATIO}: {})",
        verdict(a, GOAL_CALCULATOR_MEAN_US),
        verdict(ratio, GOAL_CALCULATOR_RATIO)
    );
    json!({"plates": plates, "exact_line_mean_us": e, "analytic_line_mean_us": a, "ratio": ratio,
           "goal_ratio": GOAL_CALCULATOR_RATIO, "met": ratio <= GOAL_CALCULATOR_RATIO,
           "goal_analytic_mean_us": GOAL_CALCULATOR_MEAN_US, "mean_met": a <= GOAL_CALCULATOR_MEAN_US})
}

/// The calculator's analytic line over the thicknesses and angles of `tests/spectral_first_query.rs`
/// (3, 20, 130, 1000 um at 60, 30, 60, 45 degrees), optic axis (0.3, 0.5, 0.8).
fn first_query_line(crystal: &str, case: usize) -> String {
    let (d, theta) = [(3.0, 60.0), (20.0, 30.0), (130.0, 60.0), (1000.0, 45.0)][case];
    json!({"material": crystal, "wavelength_nm": 550.0, "theta_deg": theta, "thickness_um": d,
           "optic_axis": [0.3, 0.5, 0.8], "spectrum": {"weights": "xyz-d65"}})
    .to_string()
}

/// In a child process (`BENCH_FIRST_QUERY=<crystal>:<case>`): one exact line (the process and
/// the calculator warmed up), then the first analytic line, timed; prints its microseconds.
fn first_query_child(job: &str) {
    let (crystal, case) = job.split_once(':').expect("crystal:case");
    let line = first_query_line(crystal, case.parse().expect("a case"));
    let mut mono: Value = serde_json::from_str(&line).expect("json");
    mono.as_object_mut().expect("an object").remove("spectrum");
    let (out, ok) = birefringent::calc::run_text("slab", &mono.to_string());
    assert!(ok, "{out}");
    let t = Instant::now();
    let (out, ok) = birefringent::calc::run_text("slab", &line);
    let us = t.elapsed().as_secs_f64() * 1e6;
    assert!(ok, "{out}");
    println!("FIRST_QUERY_US {us}");
}

/// The first analytic query of a process (item 4 of issue 30): each named crystal's lines of
/// [`first_query_line`], each in a fresh process (the median of 3), the largest and the mean.
fn first_query() -> Value {
    let exe = std::env::current_exe().expect("the benchmark's path");
    let mut rows = Vec::new();
    for crystal in birefringent::material::crystals::crystal_names() {
        for case in 0..4 {
            let job = format!("{crystal}:{case}");
            let mut t: Vec<f64> = (0..3)
                .map(|_| {
                    let out = std::process::Command::new(&exe)
                        .env("BENCH_FIRST_QUERY", &job)
                        .output()
                        .expect("the benchmark runs");
                    String::from_utf8_lossy(&out.stdout)
                        .lines()
                        .find_map(|l| l.strip_prefix("FIRST_QUERY_US "))
                        .and_then(|v| v.trim().parse().ok())
                        .unwrap_or(f64::NAN)
                })
                .collect();
            rows.push((job, median(&mut t)));
        }
    }
    let worst = rows.iter().cloned().fold(
        (String::new(), 0.0f64),
        |w, r| if r.1 > w.1 { r } else { w },
    );
    let mean_ms = rows.iter().map(|r| r.1).sum::<f64>() / rows.len() as f64 * 1e-3;
    println!(
        "  first analytic query of a process, {} lines (8 crystals x 4 plates): mean {mean_ms:.2} ms, largest {:.2} ms ({}) (goal <= {GOAL_FIRST_QUERY_MS} ms: {})",
        rows.len(),
        worst.1 * 1e-3,
        worst.0,
        verdict(worst.1 * 1e-3, GOAL_FIRST_QUERY_MS)
    );
    json!({"lines": rows.iter().map(|(j, t)| json!({"line": j, "us": t})).collect::<Vec<_>>(),
           "mean_ms": mean_ms, "largest_ms": worst.1 * 1e-3, "largest": worst.0,
           "goal_ms": GOAL_FIRST_QUERY_MS, "met": worst.1 * 1e-3 <= GOAL_FIRST_QUERY_MS})
}

/// The near-grazing hard set (issue 30: rutile, sapphire, lithium niobate and calcite of 3-17 um
/// at 79-86 degrees; named crystals 50-500 um thick at 88.5-89.5 degrees) against dense
/// quadrature whose step resolves the internal-reflection fringes
/// ([`spectral_rgb::hard_quadrature_step`]), and the two plates the issue gives with converged
/// references (transmission between s polarisers, `T_ss`).
fn hard_validation(n: usize) -> Value {
    let t = Instant::now();
    let cases = spectral_rgb::hard_cases(n, spectral_rgb::TEST_SEED ^ 0x6A2D);
    let outcomes: Vec<Outcome> = cases
        .iter()
        .map(|c| spectral_rgb::compare_with_step(c, spectral_rgb::hard_quadrature_step(c), false))
        .collect();
    let stats = spectral_rgb::summarize(&outcomes, false);
    for (q, s) in stats.iter().enumerate() {
        println!(
            "  {:>10}: mean CIEDE2000 {:.3}, worst {:.3} ({}), {} of {n} at or above {}",
            QUANTITIES[q],
            s.mean,
            s.worst,
            outcomes[s.worst_case].case.describe(),
            s.above_bound,
            spectral_rgb::WORST_BOUND
        );
    }
    let steps: Vec<f64> = outcomes.iter().map(|o| o.reference.step_nm).collect();
    println!(
        "  references: steps {:.1e} - {:.1e} nm, {} wavelengths, {:.0} s",
        steps.iter().cloned().fold(f64::INFINITY, f64::min),
        steps.iter().cloned().fold(0.0, f64::max),
        outcomes.iter().map(|o| o.reference.samples).sum::<usize>(),
        t.elapsed().as_secs_f64()
    );
    let worked = worked_cases();
    json!({
        "plates": n,
        "quantities": (0..3).map(|q| json!({"quantity": QUANTITIES[q], "mean": stats[q].mean,
            "worst": stats[q].worst, "above_bound": stats[q].above_bound,
            "worst_case": outcomes[stats[q].worst_case].case.describe()})).collect::<Vec<_>>(),
        "cases": outcomes.iter().map(|o| json!({"description": o.case.describe(), "de": o.de,
            "reproducer": o.case.reproducer(), "step_nm": o.reference.step_nm})).collect::<Vec<_>>(),
        "worked_cases": worked,
    })
}

/// The issue's two plates (xyz-d65, axis (0.3, -0.5, 0.8), air on both sides): the analytic
/// `T_ss` (`(M00 + M01 + M10 + M11)/2`) against the trapezoid rule of the exact plate at two
/// steps, the finer a tenth of the internal fringes' spacing or less.
fn worked_cases() -> Value {
    let cases: [(&str, f64, f64, f64, f64); 2] = [
        ("calcite", 90.4, 89.489, 182.26, 4e-4),
        ("rutile", 9.80, 85.026, 208.79, 5e-3),
    ];
    cases
        .iter()
        .map(|&(name, um, theta, phi, step)| {
            let plate = Plate {
                material: Material::named(name, 0.0, 0.0).unwrap(),
                birefringence: 0.0,
                ext: C64::new(1.0, 0.0),
                exit: C64::new(1.0, 0.0),
                axis: nalgebra::Vector3::new(0.3, -0.5, 0.8).normalize(),
                thickness_nm: um * 1e3,
            };
            let frame = PlaneFrame::from_azimuth(phi.to_radians());
            let beta = C64::new(theta.to_radians().sin(), 0.0);
            let tss = |m: &nalgebra::Matrix4<f64>| 0.5 * (m[(0, 0)] + m[(0, 1)] + m[(1, 0)] + m[(1, 1)]);
            let analytic: Vec<f64> = PlateModel::new(&plate, frame, beta)
                .channels(SET, Want::BOTH, Output::Mueller, Accuracy::Perceptual)
                .unwrap()
                .iter()
                .map(|m| tss(&m.t.unwrap()))
                .collect();
            let reference = |step: f64| -> Vec<f64> {
                (0..3)
                    .map(|c| {
                        let m = birefringent::spectral::reference::quadrature(
                            &plate, &frame, beta, |l| weight_per_nm(SET, c, l), RANGE, step,
                            Want::BOTH,
                        )
                        .unwrap();
                        tss(&m.t.unwrap())
                    })
                    .collect()
            };
            let (fine, half) = (reference(step), reference(0.5 * step));
            let de = spectral_rgb::delta_e(
                [analytic[0], analytic[1], analytic[2]],
                [half[0], half[1], half[2]],
            );
            println!(
                "  {name} {um} um at {theta} deg: analytic T_ss {analytic:.4?}, reference (step {step:e} nm) {fine:.4?}, (step {:e}) {half:.4?}: CIEDE2000 {de:.2}",
                0.5 * step
            );
            json!({"plate": format!("{name} {um} um at {theta} deg, azimuth {phi}"),
                   "analytic": analytic, "reference": half, "reference_coarser": fine,
                   "step_nm": 0.5 * step, "de": de})
        })
        .collect()
}

// ---- validation ------------------------------------------------------------------------------

fn validation(n: usize) -> (Vec<Outcome>, Value) {
    let t = Instant::now();
    let cases = spectral_rgb::extended_cases(n, spectral_rgb::TEST_SEED ^ 0xBE7C);
    let mut outcomes = Vec::with_capacity(n);
    for c in &cases {
        outcomes.push(spectral_rgb::compare(c, true));
        if outcomes.len() % 100 == 0 {
            eprintln!(
                "  validation: {} / {n} plates ({:.0} s)",
                outcomes.len(),
                t.elapsed().as_secs_f64()
            );
        }
    }
    let failures = spectral_rgb::report(&outcomes);
    let fitted = spectral_rgb::summarize(&outcomes, true);
    for (q, s) in fitted.iter().enumerate() {
        println!(
            "  {:>10} vs quadrature with the fitted Gaussians as weights: worst {:.4}, median {:.4} (closed-form error alone)",
            QUANTITIES[q], s.worst, s.median
        );
    }
    let stats = spectral_rgb::summarize(&outcomes, false);
    let per_q: Vec<Value> = (0..3)
        .map(|q| {
            let s = stats[q];
            let w = &outcomes[s.worst_case];
            json!({
                "quantity": QUANTITIES[q],
                "worst": s.worst, "median": s.median, "mean": s.mean, "cases_at_or_above_1": s.above_bound,
                "worst_met": s.worst < spectral_rgb::WORST_BOUND, "mean_met": s.mean < spectral_rgb::MEAN_BOUND,
                "fitted_weights_worst": fitted[q].worst, "fitted_weights_median": fitted[q].median,
                "worst_case": {
                    "description": w.case.describe(),
                    "reproducer": w.case.reproducer(),
                    "analytic_xyz": w.analytic[q],
                    "quadrature_xyz": w.reference.tabulated[q],
                    "quadrature_step_nm": w.reference.step_nm,
                    "all_de": w.de,
                },
            })
        })
        .collect();
    let failing: Vec<Value> = outcomes
        .iter()
        .filter(|o| {
            !o.de
                .iter()
                .all(|e| spectral_rgb::below(*e, spectral_rgb::WORST_BOUND))
        })
        .map(|o| {
            json!({"description": o.case.describe(), "de": o.de, "de_fitted_weights": o.de_fitted,
                        "reproducer": o.case.reproducer(), "analytic_xyz": o.analytic,
                        "quadrature_xyz": o.reference.tabulated})
        })
        .collect();
    // Per material class: worst error of any quantity.
    let mut classes = serde_json::Map::new();
    for name in spectral_rgb::CRYSTALS.iter().copied().chain(["constant"]) {
        let sel: Vec<&Outcome> = outcomes
            .iter()
            .filter(|o| match &o.case.kind {
                spectral_rgb::Kind::Crystal(c) => *c == name,
                spectral_rgb::Kind::Constant { .. } => name == "constant",
            })
            .collect();
        if sel.is_empty() {
            continue;
        }
        let worst: Vec<f64> = (0..3)
            .map(|q| sel.iter().map(|o| o.de[q]).fold(0.0, f64::max))
            .collect();
        classes.insert(name.into(), json!({"plates": sel.len(), "worst_de": worst}));
    }
    // Convergence of the reference: the worst case of each quantity and every case above the
    // bound, again with half the step.
    let mut check: Vec<usize> = stats.iter().map(|s| s.worst_case).collect();
    check.extend((0..outcomes.len()).filter(|i| {
        !outcomes[*i]
            .de
            .iter()
            .all(|e| spectral_rgb::below(*e, spectral_rgb::WORST_BOUND))
    }));
    check.sort_unstable();
    check.dedup();
    let convergence: Vec<Value> = check
        .iter()
        .map(|i| {
            let o = &outcomes[*i];
            let half = spectral_rgb::reference(&o.case, 0.5 * o.reference.step_nm, false);
            let de: Vec<f64> =
                (0..3).map(|q| spectral_rgb::delta_e(o.reference.tabulated[q], half.tabulated[q])).collect();
            let txt: Vec<String> = de.iter().map(|e| format!("{e:.1e}")).collect();
            println!("  reference convergence, {}: CIEDE2000(step, step/2) [{}]", o.case.describe(), txt.join(", "));
            json!({"case": o.case.index, "step_nm": o.reference.step_nm, "de_step_vs_half_step": de})
        })
        .collect();
    let samples: usize = outcomes.iter().map(|o| o.reference.samples).sum();
    let quad_s: f64 = outcomes.iter().map(|o| o.seconds.1).sum();
    let ana_s: f64 = outcomes.iter().map(|o| o.seconds.0).sum();
    println!(
        "  {n} plates in {:.1} s: quadrature {samples} wavelengths ({:.1} s), analytic {:.3} s",
        t.elapsed().as_secs_f64(),
        quad_s,
        ana_s
    );
    let v = json!({
        "plates": n,
        "seed": spectral_rgb::TEST_SEED ^ 0xBE7C,
        "weights": "xyz-d65",
        "lab_white": spectral_rgb::WHITE,
        "bounds": {"worst": spectral_rgb::WORST_BOUND, "mean": spectral_rgb::MEAN_BOUND},
        "passed": failures.is_empty(),
        "failures": failures,
        "quantities": per_q,
        "per_material_worst": Value::Object(classes),
        "cases_at_or_above_bound": failing,
        "reference_convergence": convergence,
        "quadrature_wavelengths": samples,
        "quadrature_seconds": quad_s,
        "analytic_seconds": ana_s,
        "note": "rutile's dispersion fit (DeVore 1951) covers 430-1530 nm and is extrapolated below 430 nm",
    });
    (outcomes, v)
}

fn main() {
    if let Ok(job) = std::env::var("BENCH_FIRST_QUERY") {
        first_query_child(&job);
        return;
    }
    let args = parse_args();
    let started = Instant::now();
    let mut report = serde_json::Map::new();
    let m = machine();
    println!(
        "machine: {} | nproc {} (--all {}) | allowed CPUs {} | loadavg {}",
        m["cpu_model"].as_str().unwrap_or("?"),
        m["nproc"],
        m["nproc_all"],
        m["cpus_allowed"].as_str().unwrap_or("?"),
        m["loadavg_at_start"].as_str().unwrap_or("?")
    );
    report.insert("machine".into(), m);
    report.insert(
        "build".into(),
        json!({"profile": if cfg!(debug_assertions) { "debug" } else { "release" }}),
    );
    if cfg!(debug_assertions) {
        eprintln!("warning: debug build; timings are meaningless (use --release)");
    }
    println!("micro-benchmarks (start):");
    report.insert("micro_start".into(), micro());

    println!(
        "validation: analytic vs quadrature, {} random plates:",
        args.validate
    );
    let (outcomes, v) = validation(args.validate);
    report.insert("validation".into(), v);

    println!("analytic time per plate over the validation set:");
    let cases: Vec<Case> = outcomes.iter().map(|o| o.case.clone()).collect();
    report.insert("analytic_time".into(), analytic_timing(&cases));
    println!("the calculator's lines:");
    report.insert("calculator".into(), calculator(200));
    report.insert("first_query".into(), first_query());
    println!("the near-grazing hard set, {HARD_PLATES} plates:");
    report.insert("hard_set".into(), hard_validation(HARD_PLATES));

    println!(
        "error vs time, crossed polarisers, {} plates x {} seeds:",
        args.plates, args.seeds
    );
    report.insert(
        "error_vs_time".into(),
        stochastic_study(&outcomes[..args.plates], args.seeds),
    );

    println!("micro-benchmarks (end):");
    report.insert("micro_end".into(), micro());
    report.insert("loadavg_at_end".into(), json!(loadavg()));
    report.insert(
        "seconds_total".into(),
        json!(started.elapsed().as_secs_f64()),
    );

    let out = std::path::Path::new(&args.out);
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir).expect("create output directory");
    }
    std::fs::write(
        out,
        serde_json::to_string_pretty(&Value::Object(report)).unwrap(),
    )
    .expect("write JSON");
    println!(
        "wrote {} ({:.0} s)",
        out.display(),
        started.elapsed().as_secs_f64()
    );
}
