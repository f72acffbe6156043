//! Speed of the core's shortcuts against the full computation they replace, per plate query
//! (the call the `thinbirefringent` plugin makes per path vertex and wavelength or RGB query).
//!
//! ```text
//! cargo run --release --example bench_shortcuts -- [--out FILE] [--reps R]
//! ```
//! One thread (the Makefile pins it with `taskset -c 0`). For each shortcut, the "shortcut" and
//! the "full" query are timed in interleaved repetitions (R of each, alternating, each a loop of
//! calls cycling through 64 precomputed random incidence directions (polar angle uniform in
//! [0, 70] degrees, random azimuth) and wavelengths (uniform in [400, 700] nm)), with
//! `std::hint::black_box` on inputs and results; the figure is the ratio of the medians
//! `full / shortcut` (how many times faster the shortcut is). The shortcuts and where the core
//! decides them:
//!
//! * `intensity_only` (`PlateCall::intensity_only`, set by the plugin in the unpolarised variants;
//!   `Output::Intensity` in `spectral::gaussian::band_sum`): only `M00` of each path-class pair
//!   instead of the full coherency matrix. Full = the same query with `Output::Mueller`. It acts
//!   only where the closed-form path sum runs (band-filtered or RGB queries of plates too thick
//!   for quadrature); timed on a 1000 um plate through a 4 nm band (`Spectrum::Band`).
//! * `incoherent_thick_plate` (`coherent_order` in `spectral::gaussian`: at most `THICK_ORDER`
//!   coherent round trips plus the closed-form incoherent tail when one round trip exceeds the
//!   coherence length). Full = the coherent path sum to the order where the round-trip
//!   amplitude falls below `ORDER_TOLERANCE` for that query (the order the core uses for plates
//!   that are not thick), forced with `Method::Paths(Some(n))`. The pair cutoff `PAIR_CUTOFF` (pairs beyond
//!   the coherence length skipped) has no switch in the API and stays on in both; so a second
//!   figure times the exhaustive alternative, quadrature of the exact plate resolving every
//!   fringe (`Method::Panels`, two panels per oscillation of the highest significant order),
//!   on a 100 um plate (a 1000 um one would need ~10^4 panels per query).
//! * `isotropic_fast_path` (`Uniaxial::is_isotropic`, exact equality of the indices: one mode
//!   pair instead of o/e, path classes merged in `paths::traverse`, one refracted lobe in
//!   `render::crystal::forward_events`). There is no switch to disable it; the full path is timed by
//!   an input that defeats it: `eta_e = eta_o + 1e-9` (optically the same plate, anisotropic to
//!   the core). Timed for the exact plate at one wavelength (filter 0), the 4 nm band of a
//!   1000 um plate, and the bulk crystal surface (`crystal_lobes`).
//! * `one_lobe` (`Want`: the plugin asks only for transmission in `eval_null_transmission`,
//!   volpath's shadow rays through the plate, and only for the lobes `BSDFContext` enables).
//!   Full = reflection and transmission. Timed on the exact plate (filter 0) and the 4 nm band of
//!   a 1000 um plate.

use birefringent::band::narrow_band;
use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::optics::medium::Uniaxial;
use birefringent::optics::surface::Surface;
use birefringent::params::Thickness;
use birefringent::plate::slab::Output;
use birefringent::plate::slab::Want;
use birefringent::plate::Plate;
use birefringent::quadrature::Accuracy;
use birefringent::render::crystal::crystal_lobes;
use birefringent::render::plate::{plate_lobes, PlateQuery};
use birefringent::render::thin::Spectrum;
use birefringent::render::Transport;
use birefringent::spectral::gaussian::{band_with, Method};
use birefringent::spectral::model::{PlateModel, ThinModel};
use birefringent::C64;
use nalgebra::Vector3;
use serde_json::{json, Value};
use std::hint::black_box;
use std::time::Instant;

/// Inputs cycled through by every timed loop.
const INPUTS: usize = 64;
/// Round-trip amplitude below which the full coherent sum stops (the core's `ORDER_TOLERANCE`).
const ORDER_TOLERANCE: f64 = 1e-5;

/// A small deterministic generator (SplitMix64), so that every run times the same inputs.
struct Rng(u64);
impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `(wi, wavelength_nm)` inputs: `wi` on the exterior side, polar angle in [0, 70] degrees.
fn inputs() -> Vec<(Vector3<f64>, f64)> {
    let mut rng = Rng(20261122);
    (0..INPUTS)
        .map(|_| {
            let theta = rng.uniform() * 70f64.to_radians();
            let phi = rng.uniform() * std::f64::consts::TAU;
            let wi = Vector3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            (wi, 400.0 + 300.0 * rng.uniform())
        })
        .collect()
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

/// Nanoseconds per call of a loop of `inner` calls.
fn per_call(inner: usize, f: &mut dyn FnMut(usize)) -> f64 {
    let t = Instant::now();
    for i in 0..inner {
        f(i % INPUTS);
    }
    t.elapsed().as_secs_f64() * 1e9 / inner as f64
}

/// Times `shortcut` and `full` in `reps` interleaved repetitions (each sized to ~20 ms of the
/// slower one) and returns the JSON record with the medians and the speed ratio.
fn compare(
    name: &str,
    reps: usize,
    shortcut: &mut dyn FnMut(usize),
    full: &mut dyn FnMut(usize),
) -> Value {
    // Warm-up, and a size for the loops.
    let probe = per_call(INPUTS, shortcut).max(per_call(INPUTS, full));
    let inner = ((2e7 / probe) as usize).clamp(INPUTS, 1 << 20);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for _ in 0..reps {
        a.push(per_call(inner, shortcut));
        b.push(per_call(inner, full));
    }
    let (ms, mf) = (median(a), median(b));
    let ratio = mf / ms;
    println!("{name:<48} shortcut {ms:>11.0} ns  full {mf:>11.0} ns  ratio {ratio:>7.2}x");
    json!({"shortcut_ns": ms, "full_ns": mf, "ratio": ratio, "repetitions": reps,
           "calls_per_repetition": inner})
}

fn material(eta_o: f64, eta_e: f64) -> Material {
    Material::constant(C64::new(eta_o, 0.0), C64::new(eta_e, 0.0)).expect("valid indices")
}

fn query(
    m: Material,
    thickness_um: f64,
    axis: [f64; 3],
    want: Want,
    intensity: bool,
) -> PlateQuery {
    PlateQuery::new(
        m,
        0.0,
        C64::new(1.0, 0.0),
        C64::new(1.0, 0.0),
        Vector3::from(axis),
        Thickness::from_nm(thickness_um * 1e3).unwrap(),
        want.reflection,
        want.transmission,
        intensity,
    )
    .expect("valid plate")
}

/// A closure evaluating `plate_lobes` of `q` over a band of `fwhm` around each input wavelength.
fn plate_call(q: PlateQuery, fwhm: f64, inputs: &[(Vector3<f64>, f64)]) -> impl FnMut(usize) + '_ {
    move |i| {
        let (wi, lambda) = inputs[i];
        let s = Spectrum::Band {
            wavelength_nm: lambda,
            fwhm_nm: fwhm,
        };
        black_box(plate_lobes(&q, black_box(&s), black_box(wi), Transport::Radiance).unwrap());
    }
}

/// Per input, the order at which the round-trip amplitude of `plate` falls below
/// [`ORDER_TOLERANCE`], as the core computes it for plates that are not thick.
fn full_orders(plate: &Plate, inputs: &[(Vector3<f64>, f64)]) -> Vec<usize> {
    inputs
        .iter()
        .map(|&(wi, lambda)| {
            let frame = PlaneFrame::from_direction(wi);
            let beta = plate.ext * (wi.x * wi.x + wi.y * wi.y).sqrt();
            let o = plate.at(lambda).unwrap().optics(&frame, beta).unwrap();
            let (pd, pu) = o.propagation(lambda);
            let rho = (o.top.r_below() * pu * o.bottom.r_above() * pd).norm();
            ((ORDER_TOLERANCE.ln() / rho.ln()).ceil() as usize).saturating_sub(1)
        })
        .collect()
}

fn main() {
    let mut out = String::from("bench/out/shortcuts.json");
    let mut reps = 15usize;
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--out" => out = it.next().expect("--out FILE").clone(),
            "--reps" => reps = it.next().expect("--reps R").parse().expect("integer"),
            _ => panic!("unknown argument {a} (use --out FILE, --reps R)"),
        }
    }
    let inp = inputs();
    let axis = [1.0, 0.3, 0.4];
    let (mut results, mut headline) = (serde_json::Map::new(), serde_json::Map::new());
    let both = Want::BOTH;
    let t_only = Want {
        reflection: false,
        transmission: true,
    };
    let aniso = material(1.5, 1.6);

    // Intensity only: 1000 um plate, 4 nm band (closed-form path sum).
    let r = compare(
        "intensity_only (1000 um, 4 nm band)",
        reps,
        &mut plate_call(query(aniso, 1000.0, axis, both, true), 4.0, &inp),
        &mut plate_call(query(aniso, 1000.0, axis, both, false), 4.0, &inp),
    );
    headline.insert("intensity_only".into(), r["ratio"].clone());
    results.insert("intensity_only/1000um_band4nm".into(), r);
    let r = compare(
        "intensity_only (1 um, 4 nm band)",
        reps,
        &mut plate_call(query(aniso, 1.0, axis, both, true), 4.0, &inp),
        &mut plate_call(query(aniso, 1.0, axis, both, false), 4.0, &inp),
    );
    results.insert("intensity_only/1um_band4nm".into(), r);

    // Incoherent thick plate: the route (THICK_ORDER + tail) vs the coherent sum to ORDER_TOLERANCE.
    for (thick, panels_too) in [(1000.0, false), (100.0, true)] {
        let q = query(aniso, thick, axis, both, false);
        let plate = q.element;
        let orders = full_orders(&plate, &inp);
        let n = *orders.iter().max().unwrap_or(&0);
        let mean_order = orders.iter().sum::<usize>() as f64 / orders.len() as f64;
        // Per input: two quadrature panels per oscillation of its highest significant order
        // over the band's +-6.5 sigma (round trip ~2 x 1.6 d: the largest group index).
        let sigma = narrow_band(550.0, 4.0).sigma;
        let panels: Vec<usize> = orders
            .iter()
            .map(|&n| {
                let osc = 13.0 * sigma * thick * 1e3 * 2.0 * 1.6 * (n as f64 + 1.0)
                    / std::f64::consts::TAU;
                (2.0 * osc).ceil() as usize
            })
            .collect();
        // 0: the route; 1: the coherent path sum; 2: quadrature panels.
        let run = |which: u8| {
            let inp = &inp;
            let (orders, panels) = (&orders, &panels);
            move |i: usize| {
                let (wi, lambda) = inp[i];
                let frame = PlaneFrame::from_direction(wi);
                let beta = plate.ext * (wi.x * wi.x + wi.y * wi.y).sqrt();
                let band = [narrow_band(lambda, 4.0)];
                let method = match which {
                    // The route's own choice.
                    0 => {
                        let model = PlateModel::new(&plate, frame, beta);
                        black_box(
                            model
                                .band(&band, both, Output::Mueller, Accuracy::Perceptual)
                                .unwrap(),
                        );
                        return;
                    }
                    1 => Method::Paths(Some(orders[i])),
                    _ => Method::Panels(panels[i]),
                };
                black_box(
                    band_with(&plate, &frame, beta, &band, both, Output::Mueller, method).unwrap(),
                );
            }
        };
        let name = format!("incoherent_thick_plate ({thick} um, vs coherent sum)");
        let mut r = compare(&name, reps, &mut run(0), &mut run(1));
        r["full_coherent_order_mean"] = json!(mean_order);
        r["full_coherent_order_max"] = json!(n);
        if thick == 1000.0 {
            headline.insert("incoherent_thick_plate".into(), r["ratio"].clone());
        }
        results.insert(format!("incoherent_thick_plate/{thick}um_vs_paths"), r);
        if panels_too {
            let mean_panels = panels.iter().sum::<usize>() as f64 / panels.len() as f64;
            let name = format!("incoherent_thick_plate ({thick} um, vs quadrature)");
            let mut r = compare(&name, reps.min(5), &mut run(0), &mut run(2));
            r["full_panels_mean"] = json!(mean_panels);
            results.insert(format!("incoherent_thick_plate/{thick}um_vs_quadrature"), r);
        }
    }

    // Isotropic fast path: eta_e = eta_o vs eta_o + 1e-9.
    let (iso, near) = (material(1.5, 1.5), material(1.5, 1.5 + 1e-9));
    let r = compare(
        "isotropic_fast_path (plate, exact)",
        reps,
        &mut plate_call(query(iso, 1000.0, axis, both, false), 0.0, &inp),
        &mut plate_call(query(near, 1000.0, axis, both, false), 0.0, &inp),
    );
    headline.insert("isotropic_fast_path".into(), r["ratio"].clone());
    results.insert("isotropic_fast_path/plate_exact".into(), r);
    let r = compare(
        "isotropic_fast_path (plate 1000 um, 4 nm band)",
        reps,
        &mut plate_call(query(iso, 1000.0, axis, both, false), 4.0, &inp),
        &mut plate_call(query(near, 1000.0, axis, both, false), 4.0, &inp),
    );
    results.insert("isotropic_fast_path/plate_1000um_band4nm".into(), r);
    let surface = |eta_e: f64| {
        Surface::new(
            C64::new(1.0, 0.0),
            Uniaxial::new(
                C64::new(1.5, 0.0),
                C64::new(eta_e, 0.0),
                Vector3::from(axis),
            )
            .unwrap(),
        )
        .unwrap()
    };
    let (s_iso, s_near) = (surface(1.5), surface(1.5 + 1e-9));
    let crystal = |s: Surface| {
        let inp = &inp;
        move |i: usize| {
            let (wi, _) = inp[i];
            black_box(crystal_lobes(&s, black_box(wi), Transport::Radiance).unwrap());
        }
    };
    let r = compare(
        "isotropic_fast_path (crystal surface)",
        reps,
        &mut crystal(s_iso),
        &mut crystal(s_near),
    );
    results.insert("isotropic_fast_path/crystal_surface".into(), r);

    // One lobe: transmission only vs both.
    let r = compare(
        "one_lobe (T only, plate 1000 um, 4 nm band)",
        reps,
        &mut plate_call(query(aniso, 1000.0, axis, t_only, false), 4.0, &inp),
        &mut plate_call(query(aniso, 1000.0, axis, both, false), 4.0, &inp),
    );
    headline.insert("one_lobe".into(), r["ratio"].clone());
    results.insert("one_lobe/plate_1000um_band4nm".into(), r);
    let r = compare(
        "one_lobe (T only, plate exact)",
        reps,
        &mut plate_call(query(aniso, 1000.0, axis, t_only, false), 0.0, &inp),
        &mut plate_call(query(aniso, 1000.0, axis, both, false), 0.0, &inp),
    );
    results.insert("one_lobe/plate_exact".into(), r);

    let doc = json!({"headline": headline, "cases": results});
    if let Some(dir) = std::path::Path::new(&out).parent() {
        std::fs::create_dir_all(dir).expect("output directory");
    }
    std::fs::write(&out, serde_json::to_string_pretty(&doc).unwrap()).expect("write output");
    println!("wrote {out}");
}
