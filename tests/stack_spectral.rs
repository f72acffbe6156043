//! Colour accuracy of a stack integrated over colour channels: the renderer's path
//! ([`StackModel::channels`] at [`Accuracy::Perceptual`]: thick layers' round trips
//! incoherent, Chebyshev product integration) against dense quadrature of the exact stack (a
//! fresh solve at every wavelength) with the tabulated 1-nm weights, compared by CIEDE2000 as
//! `tests/spectral_rgb.rs` compares one plate, within the same budget: mean at most 0.1, worst at
//! most 0.5 per quantity (crossed and parallel polarisers in transmission, the unpolarised
//! reflectance; `xyz-d65`, Lab white `(1, 1, 1)`).
//!
//! The random stacks (four families, drawn in turn): cellophane (1-4 tapes of 20-60 µm, index
//! 1.46-1.56, `Δn` 0.002-0.012, axes in the plane at random angles, sometimes an isotropic
//! adhesive of 1-20 µm between tapes); waveplates (two plates of quartz, MgF₂, sapphire or
//! calcite, 0.1-1.5 mm, axes in the plane, crossed or at random angles); thin films (1-5 layers
//! of 30 nm - 3 µm, constant indices 1.3-2.4, tilted axes, some absorbing); mixed (1-5 layers of
//! 0.3 µm - 1 mm, named crystals and constant indices). Exterior air, exit air or glass,
//! incidence 0-60° at a random azimuth.
//!
//! The quadrature step is `min(0.5, min_λ λ² / (16 n_g D))` nm over 360-830 nm (`D` the total
//! thickness, `n_g` the largest group index): 8 samples per period of the stack's longest
//! round trip. The same code is the validation run of `examples/bench_stack.rs`.
#![allow(dead_code)]

use birefringent::colour::convert::{ciede2000, xyz_to_lab};
use birefringent::colour::weights::{weight_per_nm, WeightSet};
use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::params::Thickness;
use birefringent::plate::slab::{Output, SlabMueller, Want};
use birefringent::quadrature::Accuracy;
use birefringent::spectral::model::ThinModel;
use birefringent::stack::exact::StackBlocks;
use birefringent::stack::spectral::StackModel;
use birefringent::stack::{Layer, Stack};
use birefringent::C64;
use nalgebra::{Matrix4, Vector3};
use std::time::Instant;

/// The weights of every colour here.
pub const SET: WeightSet = WeightSet::XyzD65;
/// Range of the tabulated weights (nm).
pub const RANGE: (f64, f64) = (360.0, 830.0);
/// The budget's bounds (mean, worst) on CIEDE2000.
pub const BOUNDS: (f64, f64) = (0.1, 0.5);
/// Stacks in `cargo test`.
pub const TEST_STACKS: usize = 48;
/// Seed of the test's stacks.
pub const TEST_SEED: u64 = 24;
/// The families of random stacks.
pub const FAMILIES: [&str; 4] = ["cellophane", "waveplate", "thin film", "mixed"];

/// SplitMix64.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    /// Uniform in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// Uniform in `[a, b)`.
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.uniform()
    }
    /// Log-uniform in `[a, b)`.
    pub fn log_range(&mut self, a: f64, b: f64) -> f64 {
        self.range(a.ln(), b.ln()).exp()
    }
    /// Uniform index in `0..n`.
    pub fn index(&mut self, n: usize) -> usize {
        ((self.uniform() * n as f64) as usize).min(n - 1)
    }
    /// A unit vector uniformly on the sphere.
    pub fn unit_vector(&mut self) -> Vector3<f64> {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vector3::new(r * phi.cos(), r * phi.sin(), z)
    }
    /// A unit vector in the plane of the layers.
    pub fn in_plane(&mut self) -> Vector3<f64> {
        let a = self.range(0.0, std::f64::consts::PI);
        Vector3::new(a.cos(), a.sin(), 0.0)
    }
}

/// One random stack and its illumination.
#[derive(Clone, Debug)]
pub struct Case {
    /// Position in its run.
    pub index: usize,
    /// Its family (index into [`FAMILIES`]).
    pub family: usize,
    /// The stack.
    pub stack: Stack,
    /// Polar angle of incidence (degrees, from air).
    pub theta_deg: f64,
    /// Azimuth (degrees).
    pub phi_deg: f64,
}

impl Case {
    /// Plane of incidence.
    pub fn frame(&self) -> PlaneFrame {
        PlaneFrame::from_azimuth(self.phi_deg.to_radians())
    }
    /// Incidence parameter.
    pub fn beta(&self) -> C64 {
        C64::new(self.stack.ext.re * self.theta_deg.to_radians().sin(), 0.0)
    }
    /// A short description.
    pub fn describe(&self) -> String {
        let layers: Vec<String> = self
            .stack
            .layers
            .iter()
            .map(|l| {
                let (o, e) = l.material.indices(550.0, 0.0).unwrap();
                format!(
                    "{:.3} um ({:.4}{:+.1e}i, {:.4}{:+.1e}i; axis {:.2} {:.2} {:.2})",
                    l.thickness_nm * 1e-3,
                    o.re,
                    o.im,
                    e.re,
                    e.im,
                    l.axis.x,
                    l.axis.y,
                    l.axis.z
                )
            })
            .collect();
        format!(
            "#{} {}: [{}], exit {}, theta {:.1}, phi {:.1}",
            self.index,
            FAMILIES[self.family],
            layers.join(", "),
            self.stack.exit.re,
            self.theta_deg,
            self.phi_deg
        )
    }
}

fn layer(material: Material, axis: Vector3<f64>, nm: f64) -> Layer {
    Layer::new(material, 0.0, axis, Thickness::from_nm(nm).unwrap()).unwrap()
}

fn constant(o: C64, e: C64) -> Material {
    Material::constant(o, e).unwrap()
}

/// The `index`-th random case (its family `index % 4`).
pub fn random_case(rng: &mut Rng, index: usize) -> Case {
    let family = index % FAMILIES.len();
    let mut layers = Vec::new();
    match family {
        0 => {
            let n = 1 + rng.index(4);
            for i in 0..n {
                if i > 0 && rng.uniform() < 0.4 {
                    let a = rng.range(1.46, 1.52);
                    let glue = constant(C64::new(a, 0.0), C64::new(a, 0.0));
                    layers.push(layer(glue, Vector3::z(), rng.range(1e3, 2e4)));
                }
                let no = rng.range(1.46, 1.56);
                let m = constant(
                    C64::new(no, 0.0),
                    C64::new(no + rng.range(0.002, 0.012), 0.0),
                );
                let axis = rng.in_plane();
                layers.push(layer(m, axis, rng.range(2e4, 6e4)));
            }
        }
        1 => {
            let names = ["quartz", "mgf2", "sapphire", "calcite"];
            let first = rng.in_plane();
            let crossed = Vector3::new(-first.y, first.x, 0.0);
            for i in 0..2 {
                let m = Material::named(names[rng.index(names.len())], 0.0, 0.0).unwrap();
                let axis = if i == 0 || rng.uniform() < 0.5 {
                    if i == 0 {
                        first
                    } else {
                        crossed
                    }
                } else {
                    rng.in_plane()
                };
                layers.push(layer(m, axis, rng.range(1e5, 1.5e6)));
            }
        }
        2 => {
            let n = 1 + rng.index(5);
            for _ in 0..n {
                let k = |rng: &mut Rng| {
                    if rng.uniform() < 0.3 {
                        rng.log_range(1e-4, 0.05)
                    } else {
                        0.0
                    }
                };
                let o = C64::new(rng.range(1.3, 2.4), k(rng));
                let e = if rng.uniform() < 0.3 {
                    o
                } else {
                    C64::new(rng.range(1.3, 2.4), k(rng))
                };
                let axis = rng.unit_vector();
                layers.push(layer(constant(o, e), axis, rng.log_range(30.0, 3e3)));
            }
        }
        _ => {
            let n = 1 + rng.index(5);
            for _ in 0..n {
                let m = if rng.uniform() < 0.4 {
                    let names = ["quartz", "mgf2", "sapphire", "calcite"];
                    Material::named(names[rng.index(names.len())], 0.0, 0.0).unwrap()
                } else {
                    let o = rng.range(1.35, 1.8);
                    constant(
                        C64::new(o, 0.0),
                        C64::new(o + rng.log_range(1e-4, 0.1), 0.0),
                    )
                };
                let axis = rng.unit_vector();
                layers.push(layer(m, axis, rng.log_range(300.0, 1e6)));
            }
        }
    }
    let exit = if rng.uniform() < 0.5 { 1.0 } else { 1.5 };
    let theta_deg = rng.range(0.0, 60.0);
    let phi_deg = rng.range(0.0, 360.0);
    Case {
        index,
        family,
        stack: Stack::new(layers, C64::new(1.0, 0.0), C64::new(exit, 0.0)).unwrap(),
        theta_deg,
        phi_deg,
    }
}

/// The first `n` cases of `seed`.
pub fn cases(n: usize, seed: u64) -> Vec<Case> {
    let mut rng = Rng::new(seed);
    (0..n).map(|i| random_case(&mut rng, i)).collect()
}

/// `[crossed, parallel, reflection]` of a pair of Mueller matrices (as `tests/spectral_rgb.rs`).
pub fn quantities(m: &SlabMueller) -> [f64; 3] {
    let (t, r): (Matrix4<f64>, Matrix4<f64>) = (m.t.unwrap(), m.r.unwrap());
    let s0 = t[(0, 0)] + t[(0, 2)];
    let s2 = t[(2, 0)] + t[(2, 2)];
    [0.5 * (s0 - s2), 0.5 * (s0 + s2), r[(0, 0)]]
}

/// XYZ per quantity: `xyz[q][c]`.
pub type Colours = [[f64; 3]; 3];

/// The renderer's integration of all three channels.
pub fn analytic(case: &Case, accuracy: Accuracy) -> Colours {
    let ms = StackModel::new(&case.stack, case.frame(), case.beta())
        .channels(SET, Want::BOTH, Output::Mueller, accuracy)
        .unwrap_or_else(|e| panic!("analytic failed for {}: {e}", case.describe()));
    let mut out = [[0.0; 3]; 3];
    for (c, m) in ms.iter().enumerate() {
        for (q, v) in quantities(m).into_iter().enumerate() {
            out[q][c] = v;
        }
    }
    out
}

/// The quadrature step (nm): `min(0.5, min_λ λ² / (16 n_g D))`.
pub fn quadrature_step(stack: &Stack) -> f64 {
    let mut s = f64::INFINITY;
    let mut l = RANGE.0;
    while l <= RANGE.1 {
        let mut path = 0.0;
        for layer in &stack.layers {
            let h = 0.05;
            let n = |i: usize, l: f64| {
                let (o, e) = layer.material.indices(l, 0.0).unwrap();
                if i == 0 {
                    o.re
                } else {
                    e.re
                }
            };
            let ng = (0..2)
                .map(|i| n(i, l) - l * (n(i, l + h) - n(i, l - h)) / (2.0 * h))
                .fold(1.0, f64::max);
            path += ng * layer.thickness_nm;
        }
        s = s.min(l * l / path);
        l += 2.0;
    }
    (s / 16.0).min(0.5)
}

/// Dense trapezoid quadrature of the exact stack with the tabulated weights; the step used.
pub fn reference(case: &Case) -> (Colours, f64) {
    let (lo, hi) = RANGE;
    let step = quadrature_step(&case.stack);
    let n = ((hi - lo) / step).ceil().max(1.0) as usize;
    let h = (hi - lo) / n as f64;
    let (frame, beta) = (case.frame(), case.beta());
    let fixed = (!case.stack.is_dispersive())
        .then(|| StackBlocks::new(&case.stack, 550.0, &frame, beta).unwrap());
    let mut out = [[0.0; 3]; 3];
    for j in 0..=n {
        let lambda = lo + h * j as f64;
        let f = if j == 0 || j == n { 0.5 * h } else { h };
        let blocks = match &fixed {
            Some(b) => b.clone(),
            None => StackBlocks::new(&case.stack, lambda, &frame, beta).unwrap(),
        };
        let q = quantities(&blocks.mueller(lambda, Want::BOTH).unwrap());
        for (k, row) in out.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v += q[k] * weight_per_nm(SET, c, lambda) * f;
            }
        }
    }
    (out, h)
}

/// CIEDE2000 between two XYZ colours (white `(1, 1, 1)`).
pub fn delta_e(a: [f64; 3], b: [f64; 3]) -> f64 {
    ciede2000(xyz_to_lab(a, [1.0; 3]), xyz_to_lab(b, [1.0; 3]))
}

/// One case's comparison: per quantity CIEDE2000, and the seconds of the analytic integration
/// and of the reference.
pub struct Outcome {
    /// The case.
    pub case: Case,
    /// CIEDE2000 per quantity.
    pub de: [f64; 3],
    /// Seconds (analytic, reference).
    pub seconds: (f64, f64),
}

/// Runs one case.
pub fn compare(case: &Case) -> Outcome {
    let t0 = Instant::now();
    let a = analytic(case, Accuracy::Perceptual);
    let t1 = Instant::now();
    let (r, _) = reference(case);
    let t2 = Instant::now();
    Outcome {
        case: case.clone(),
        de: std::array::from_fn(|q| delta_e(a[q], r[q])),
        seconds: ((t1 - t0).as_secs_f64(), (t2 - t1).as_secs_f64()),
    }
}

/// Prints the statistics per quantity; returns `(mean, worst)` over the quantities' means and
/// worsts.
pub fn report(outcomes: &[Outcome]) -> (f64, f64) {
    let (mut mean_max, mut worst_max) = (0.0f64, 0.0f64);
    for (q, name) in ["crossed", "parallel", "reflection"].iter().enumerate() {
        let e: Vec<f64> = outcomes.iter().map(|o| o.de[q]).collect();
        let mean = e.iter().sum::<f64>() / e.len() as f64;
        let (i, worst) = e
            .iter()
            .copied()
            .enumerate()
            .fold((0, f64::NEG_INFINITY), |a, (i, x)| {
                if x > a.1 || x.is_nan() {
                    (i, x)
                } else {
                    a
                }
            });
        println!(
            "{name:>10}: CIEDE2000 mean {mean:.4}, worst {worst:.4} ({})",
            outcomes[i].case.describe()
        );
        mean_max = mean_max.max(mean);
        worst_max = if worst.is_nan() {
            f64::NAN
        } else {
            worst_max.max(worst)
        };
    }
    (mean_max, worst_max)
}

#[test]
fn stacks_over_channels_stay_within_the_perceptual_budget() {
    let outcomes: Vec<Outcome> = cases(TEST_STACKS, TEST_SEED).iter().map(compare).collect();
    let (mean, worst) = report(&outcomes);
    let time: f64 = outcomes.iter().map(|o| o.seconds.0).sum();
    println!(
        "{} stacks: analytic {:.1} ms per stack on average",
        outcomes.len(),
        1e3 * time / outcomes.len() as f64
    );
    assert!(mean <= BOUNDS.0, "mean {mean}");
    assert!(worst <= BOUNDS.1, "worst {worst}");
}
