//! Shared helpers of the integration tests: a seeded RNG, the independent Berreman 4x4
//! reference ([`berreman`]) and the documented meaning of a band's width ([`band`]).
#![allow(dead_code)]

pub mod band;
pub mod berreman;
pub mod samples;

use nalgebra::Vector3;

/// SplitMix64: a tiny, seeded, reproducible generator (no external crates).
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `[a, b)`.
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.uniform()
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.uniform() < p
    }

    /// Uniform index in `0..n`.
    pub fn index(&mut self, n: usize) -> usize {
        ((self.uniform() * n as f64) as usize).min(n - 1)
    }

    /// A unit vector uniformly distributed on the sphere.
    pub fn unit_vector(&mut self) -> Vector3<f64> {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, 2.0 * std::f64::consts::PI);
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vector3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// A plate of `material` below air: exit index uniform in `exit`, a random optic axis and a
/// thickness of `10^u` nm with `u` uniform in `log10_nm` (drawn in that order).
pub fn random_plate(
    rng: &mut Rng,
    material: birefringent::material::Material,
    exit: (f64, f64),
    log10_nm: (f64, f64),
) -> birefringent::plate::Plate {
    use birefringent::C64;
    birefringent::plate::Plate {
        material,
        birefringence: 0.0,
        ext: C64::new(1.0, 0.0),
        exit: C64::new(rng.range(exit.0, exit.1), 0.0),
        axis: rng.unit_vector(),
        thickness_nm: 10f64.powf(rng.range(log10_nm.0, log10_nm.1)),
    }
}

/// A sample of the generic code run on `f64` in the layout of a recorded program's outputs
/// (`bridge::SampleOutput`, without the failure mask): a query of fewer than four channels
/// repeats its last.
pub fn sample_outputs<const C: usize>(
    s: &birefringent::render::choice::Sampled<f64, C>,
) -> Vec<f64> {
    let mut out = vec![
        f64::from(u8::from(s.valid)),
        s.slot,
        s.component,
        s.pdf,
        s.eta,
    ];
    out.extend(s.wo.iter());
    for ch in 0..4 {
        let ch = ch.min(C - 1);
        out.extend(s.in_x[ch].iter().chain(s.out_x[ch].iter()));
        out.extend(s.value[ch].transpose().iter());
    }
    out
}

/// The largest difference between a recorded program's outputs `got` and the host's `want`
/// ([`sample_outputs`]) relative to `1 +` their size, over the outputs of the first `channels`
/// channels (the others repeat the last); panics with `context` beyond `tol`.
pub fn compare_outputs(
    got: &[f64],
    want: &[f64],
    channels: usize,
    tol: f64,
    context: &dyn std::fmt::Debug,
) -> f64 {
    use birefringent::ffi::bridge::SampleOutput;
    let per = SampleOutput::PerChannel.repr as usize;
    let first = SampleOutput::Channel0.repr as usize;
    let mut worst = 0.0f64;
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        if k.checked_sub(first).is_some_and(|j| j / per >= channels) {
            continue;
        }
        let e = (g - w).abs() / (1.0 + g.abs().max(w.abs()));
        assert!(e <= tol, "output {k}: {g} vs {w}\n{context:?}");
        worst = worst.max(e);
    }
    worst
}

/// Panics with `context` unless every value `program` computes on `inputs` is finite, those of
/// the outcomes its `select`s discard included (a NaN there would poison Dr.Jit's derivatives:
/// `0 · NaN`).
pub fn assert_every_value_finite(
    program: &birefringent::record::Program,
    inputs: &[f64],
    context: &dyn std::fmt::Debug,
) {
    let every = birefringent::record::Program {
        outputs: (0..program.instrs.len() as u32).collect(),
        ..program.clone()
    };
    if let Some(k) = every.run(inputs).iter().position(|x| !x.is_finite()) {
        let i = program.instrs[k];
        panic!("value {k} ({i:?}) is not finite\n{context:?}");
    }
}
