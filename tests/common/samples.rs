//! The recorded programs' outputs (`SampleOutput`) on the host: a thin element's generic
//! sample run on `f64` in a program's layout, and the two comparisons of the recorded-program
//! tests (program against generic sample, generic sample against the bridge's scalar route).

use birefringent::ffi::bridge::SampleOutput;
use birefringent::render::choice::{choose, Sampled};
use birefringent::render::plate::sample_exact;
use birefringent::render::thin::Thin;
use birefringent::render::thin::{Spectrum, MAX_BANDS};
use birefringent::render::{PathLobe, Transport};
use nalgebra::Vector3;
use std::fmt::Debug;

/// What a path asks of a thin element at exact wavelengths.
#[derive(Clone, Copy, Debug)]
pub struct Path<'a> {
    /// Mitsuba's `si.wi`.
    pub wi: Vector3<f64>,
    /// The lobe-choosing uniform number.
    pub u: f64,
    /// One to four wavelengths (nm).
    pub wavelengths: &'a [f64],
    /// The transport mode.
    pub transport: Transport,
    /// The enabled components' bits.
    pub components: u32,
}

/// The generic sample of `q` (`render::plate::sample_exact`) run on `f64`, as a program's
/// outputs (without the failure mask).
pub fn direct<E: Thin<f64, Spectrum = [f64]>>(q: &E, path: &Path) -> Vec<f64> {
    match path.wavelengths.len() {
        1 => direct_in::<E, 1>(q, path),
        2 => direct_in::<E, 2>(q, path),
        3 => direct_in::<E, 3>(q, path),
        _ => direct_in::<E, 4>(q, path),
    }
}

fn direct_in<E: Thin<f64, Spectrum = [f64]>, const C: usize>(q: &E, p: &Path) -> Vec<f64> {
    let w: [f64; C] = std::array::from_fn(|k| p.wavelengths[k]);
    let s = sample_exact(q, &w, p.wi, p.u, p.transport, p.components).unwrap();
    outputs(&s)
}

/// A sample's outputs in `SampleOutput` order; a query of fewer than four wavelengths repeats
/// its last.
fn outputs<const C: usize>(s: &Sampled<f64, C>) -> Vec<f64> {
    let mut out = vec![
        f64::from(u8::from(s.valid)),
        s.slot,
        s.component,
        s.pdf,
        s.eta,
    ];
    out.extend(s.wo.iter());
    for ch in 0..MAX_BANDS {
        let ch = ch.min(C - 1);
        out.extend(s.in_x[ch].iter().chain(s.out_x[ch].iter()));
        out.extend(s.value[ch].transpose().iter());
    }
    out
}

/// Relative closeness for numbers of order one or smaller.
pub fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

/// A program's outputs `got` equal `want` within `tol` in the outputs of the first `channels`
/// (the others repeat the last), and the lane did not fail.
pub fn assert_program_outputs(
    got: &[f64],
    want: &[f64],
    channels: usize,
    tol: f64,
    lane: &impl Debug,
) {
    let count = SampleOutput::Count.repr as usize;
    assert_eq!(got.len(), count + 1);
    assert_eq!(got[count], 0.0, "{lane:?} failed");
    let per = SampleOutput::PerChannel.repr as usize;
    let first = SampleOutput::Channel0.repr as usize;
    for (k, (g, w)) in got.iter().zip(&want[..count]).enumerate() {
        let channel = k.checked_sub(first).map(|j| j / per);
        if channel.is_some_and(|c| c >= channels) {
            continue;
        }
        assert!(close(*g, *w, tol), "output {k}: {g} vs {w}\n{lane:?}");
    }
}

/// The bridge's exact spectrum at `wavelengths` (one to four).
pub fn exact_bands(wavelengths: &[f64]) -> Spectrum {
    let mut wavelengths_nm = [0.0; MAX_BANDS];
    wavelengths_nm[..wavelengths.len()].copy_from_slice(wavelengths);
    Spectrum::Bands {
        wavelengths_nm,
        count: wavelengths.len(),
        fwhm_nm: 0.0,
    }
}

/// The generic sample's outputs `got` equal the scalar route's: the choice among `lobes` (one
/// `[reflection, transmission]` pair per channel) with the path's `u` and components, gathered
/// as the bridge writes a lane, to 1e-9. Returns whether a lobe was chosen.
pub fn assert_scalar_route(
    got: &[f64],
    lobes: &[[Option<PathLobe>; 2]],
    path: &Path,
    lane: &impl Debug,
) -> bool {
    let enabled = |slot: usize| path.components & (1 << slot) != 0;
    let choice = choose(lobes, enabled, path.u);
    assert_eq!(got[0] != 0.0, choice.is_some(), "{lane:?}");
    let Some(choice) = choice else {
        return false;
    };
    let hero = lobes[choice.hero][choice.slot].unwrap();
    let tol = 1e-9;
    assert_eq!(got[1], choice.slot as f64);
    assert!(
        close(got[3], choice.pdf, tol),
        "pdf {} vs {}\n{lane:?}",
        got[3],
        choice.pdf
    );
    assert!(close(got[4], hero.eta, tol));
    for k in 0..3 {
        assert!(close(got[5 + k], hero.wo[k], tol));
    }
    let per = SampleOutput::PerChannel.repr as usize;
    let first = SampleOutput::Channel0.repr as usize;
    for (c, slots) in lobes.iter().enumerate() {
        let base = first + per * c;
        let m = slots[choice.slot].map(|l| l.mueller / choice.pdf);
        for e in 0..16 {
            let want = m.map_or(0.0, |m| m[(e / 4, e % 4)]);
            let g = got[base + 6 + e];
            assert!(
                close(g, want, tol),
                "channel {c} entry {e}: {g} vs {want}\n{lane:?}"
            );
        }
    }
    true
}
