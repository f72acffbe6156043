//! Fuzz target: every entry point of the bridge (src/ffi/mod.rs, the C++ header generated from
//! it), called as the C++ shim calls them, with arguments decoded from the fuzzer's bytes:
//! material tables of hostile constants and arbitrary names (unknown, empty, very long, any
//! UTF-8: the generated C++ refuses other bytes before Rust sees them), hostile band widths
//! (checked per lane) and channel-set values, and batches of 0 to 8 lanes whose every column is hostile: NaN, ±inf,
//! huge, tiny and negative doubles, non-unit and non-finite directions, material indices outside
//! the table, transport values outside the enum, samples outside [0, 1], zero to six wavelength
//! columns, columns of every length around the lane count (a wrong one must be refused), output
//! columns of wrong lengths, optional outputs present or absent, any component bits.
//!
//! Contract asserted (a violation aborts, and libFuzzer keeps the input; the fuzz build has
//! `panic = "abort"`, so a panic the bridge would catch is a finding too):
//! - the call's status is Ok, Invalid or Internal, and Ok exactly when every lane is Ok;
//!   Internal (a defect, but a clean error) goes to `birefringent_fuzz::soft_finding`;
//! - a failed call or lane has a message "parameter: what"; a failed lane samples nothing;
//! - every lane that samples nothing has pdf 0 and all its outputs zero; a sampled lane has
//!   finite outputs, pdf in (0, 1], a unit `wo`, a component in range and enabled, a
//!   non-negative `value[0]` (but for sRGB channels, whose weights are signed);
//! - soft: in Importance mode with positive channel weights, every sampled lobe's power
//!   fraction `value[0] * pdf` is <= 1 + 1e-9 (inside a strongly absorbing crystal the incident
//!   and reflected waves exchange power through their interference term, so a ratio above 1 is
//!   not necessarily wrong there, which is why it is soft);
//! - the same call twice gives bitwise the same outputs, and lane 0 alone (every column cut to
//!   its value) gives lane 0's outputs: no hidden state, broadcasting is exact.
#![no_main]

use birefringent::ffi::bridge::{
    CrystalLanes, PlateCall, PlateLanes, Samples, Status, Transport,
};
use birefringent::ffi::{
    band_spectrum, colour_channel_spectrum, exact_spectrum, new_materials, sample_crystal, sample_plate, srgb_spectrum,
    Materials, PlateSpectrum,
};
use birefringent_fuzz::Bytes;
use libfuzzer_sys::fuzz_target;

/// Names the core knows (with aliases and case/space variants) and near misses.
const NAMES: [&str; 13] = [
    "calcite",
    "quartz",
    "Crystalline Quartz",
    "sapphire",
    "rutile",
    "mgf2",
    "lithium niobate",
    "bbo",
    "kdp",
    "",
    " calcite ",
    "\u{e9}",
    "unobtainium",
];

/// A table of up to 3 materials (indices 0..); refused entries are skipped.
fn materials(b: &mut Bytes) -> Box<Materials> {
    let mut m = new_materials();
    for _ in 0..(b.u8() % 4) {
        let (ko, ke) = (b.f64(), b.f64());
        let r = match b.u8() % 3 {
            0 => m.add_named(NAMES[b.u8() as usize % NAMES.len()], ko, ke),
            1 => {
                let raw = b.bytes(255);
                let mut name = String::from_utf8_lossy(&raw).into_owned();
                if b.u8() == 0xFF {
                    name.extend(std::iter::repeat_n('x', 100_000));
                }
                m.add_named(&name, ko, ke)
            }
            _ => m.add_constant(b.f64(), b.f64(), ko, ke),
        };
        if let Err(e) = r {
            check_message(&e.to_string());
        }
    }
    m
}

/// "parameter: what", non-empty.
fn check_message(text: &str) {
    assert!(!text.is_empty(), "empty error message");
    assert!(
        text.contains(": "),
        "message does not name a parameter: {text:?}"
    );
}

/// A column of `count` values, or of a nearby wrong length now and then; mostly one value.
fn column<T: Copy>(b: &mut Bytes, count: usize, mut value: impl FnMut(&mut Bytes) -> T) -> Vec<T> {
    let len = match b.u8() % 16 {
        0 => count + 1,
        1 => count.saturating_sub(1),
        2 => 0,
        3..=8 => 1,
        _ => count,
    };
    (0..len).map(|_| value(b)).collect()
}

/// Owned input columns of a batch.
struct Lanes {
    count: usize,
    active: Vec<u8>,
    material: Vec<u32>,
    transport: Vec<Transport>,
    sample: Vec<f64>,
    wi: [Vec<f64>; 3],
    wavelengths: Vec<Vec<f64>>,
    ext_ior: Vec<f64>,
    exit_ior: Vec<f64>,
    optic_axis: [Vec<f64>; 3],
    axis_angle_deg: Vec<f64>,
    thickness_nm: Vec<f64>,
    birefringence: Vec<f64>,
}

fn lanes(b: &mut Bytes, materials: u32) -> Lanes {
    let count = (b.u8() % 9) as usize;
    let f = |b: &mut Bytes| b.f64();
    let dirs: Vec<[f64; 3]> = (0..count.max(1)).map(|_| b.direction()).collect();
    let axes: Vec<[f64; 3]> = (0..count.max(1)).map(|_| b.direction()).collect();
    let vec3 = |b: &mut Bytes, v: &[[f64; 3]], k: usize| {
        let mut i = 0;
        column(b, count, |_| {
            i += 1;
            v[(i - 1) % v.len()][k]
        })
    };
    Lanes {
        count,
        active: column(b, count, |b| b.u8() % 3),
        material: column(b, count, |b| match b.u8() % 8 {
            0 => b.u32(),
            k => (k as u32) % materials.max(1),
        }),
        transport: column(b, count, |b| Transport {
            repr: match b.u8() % 8 {
                0 => b.u8(),
                k => k % 2,
            },
        }),
        sample: column(b, count, |b| match b.u8() % 4 {
            0 => b.f64(),
            _ => b.u16() as f64 / 65536.0,
        }),
        wi: [vec3(b, &dirs, 0), vec3(b, &dirs, 1), vec3(b, &dirs, 2)],
        wavelengths: (0..(b.u8() % 7)).map(|_| column(b, count, f)).collect(),
        ext_ior: column(b, count, f),
        exit_ior: column(b, count, f),
        optic_axis: [vec3(b, &axes, 0), vec3(b, &axes, 1), vec3(b, &axes, 2)],
        axis_angle_deg: column(b, count, f),
        thickness_nm: column(b, count, f),
        birefringence: column(b, count, f),
    }
}

impl Lanes {
    /// Lane 0 alone (each column cut to its value for lane 0), if every column is valid.
    fn first(&self) -> Option<Lanes> {
        let one = |v: &Vec<f64>| (!v.is_empty()).then(|| vec![v[0]]);
        let cut = |v: &[Vec<f64>; 3]| Some([one(&v[0])?, one(&v[1])?, one(&v[2])?]);
        (self.count > 0).then_some(())?;
        Some(Lanes {
            count: 1,
            active: self.active.first().map(|&x| vec![x])?,
            material: self.material.first().map(|&x| vec![x])?,
            transport: self.transport.first().map(|&x| vec![x])?,
            sample: one(&self.sample)?,
            wi: cut(&self.wi)?,
            wavelengths: self.wavelengths.iter().map(one).collect::<Option<_>>()?,
            ext_ior: one(&self.ext_ior)?,
            exit_ior: one(&self.exit_ior)?,
            optic_axis: cut(&self.optic_axis)?,
            axis_angle_deg: one(&self.axis_angle_deg)?,
            thickness_nm: one(&self.thickness_nm)?,
            birefringence: one(&self.birefringence)?,
        })
    }
}

/// Owned output columns: `count` lanes of `channels` channels, optional columns present or
/// not, now and then a column of a wrong length.
#[derive(Clone, PartialEq)]
struct Out {
    status: Vec<Status>,
    component: Vec<u32>,
    cols: Vec<Vec<f64>>,
    message: String,
}

/// Columns of `Out::cols`: pdf, eta, wo (3), in/out frames (3 + 3), value (16).
const FRAMES: usize = 5;
const VALUE: usize = 11;

impl Out {
    fn new(b: &mut Bytes, count: usize, channels: usize, frames: bool, full: bool) -> Self {
        let per = count * channels;
        let mut cols: Vec<Vec<f64>> = (0..27)
            .map(|k| {
                let len = match k {
                    0..=4 => count,
                    5..=10 if frames => per,
                    11 => per,
                    12.. if full => per,
                    _ => 0,
                };
                vec![f64::NAN; len]
            })
            .collect();
        if b.u8() == 0 {
            let k = b.u8() as usize % cols.len();
            cols[k].push(0.0);
        }
        Out {
            status: vec![Status::Internal; count],
            component: vec![99; count],
            cols,
            message: String::new(),
        }
    }

    fn run(&mut self, f: &mut dyn FnMut(&mut Samples) -> Status) -> Status {
        let mut it = self.cols.iter_mut().map(|v| v.as_mut_slice());
        let mut next = || it.next().unwrap();
        let mut s = Samples {
            status: &mut self.status,
            component: &mut self.component,
            pdf: next(),
            eta: next(),
            wo: [next(), next(), next()],
            in_stokes_x: [next(), next(), next()],
            out_stokes_x: [next(), next(), next()],
            value: std::array::from_fn(|_| next()),
            message: String::new(),
        };
        let rc = f(&mut s);
        self.message = s.message;
        rc
    }

    fn bits(&self) -> Vec<u64> {
        let mut v: Vec<u64> = self.status.iter().map(|s| s.repr as u64).collect();
        v.extend(self.component.iter().map(|&c| c as u64));
        v.extend(self.cols.iter().flatten().map(|x| x.to_bits()));
        v
    }

    /// Lane `i`'s numbers.
    fn lane_bits(&self, i: usize, count: usize, channels: usize) -> Vec<u64> {
        let mut v = vec![self.status[i].repr as u64, self.component[i] as u64];
        for (k, c) in self.cols.iter().enumerate() {
            let per_channel = k >= FRAMES;
            for ch in 0..if per_channel { channels } else { 1 } {
                if let Some(x) = c.get(ch * count + i) {
                    v.push(x.to_bits());
                }
            }
        }
        v
    }
}

/// Three columns as slices.
fn v3(v: &[Vec<f64>; 3]) -> [&[f64]; 3] {
    [&v[0], &v[1], &v[2]]
}

/// What the kind of query lets through.
struct Expect {
    channels: usize,
    max_component: u32,
    components: u32,
    signed: bool,
    importance_bound: bool,
}

/// The contract on a finished call's outputs.
fn check(out: &Out, rc: Status, lanes: &Lanes, e: &Expect, args: &str) {
    assert!(
        matches!(rc, Status::Ok | Status::Invalid | Status::Internal),
        "status {rc:?}"
    );
    if rc != Status::Ok {
        check_message(&out.message);
    }
    if rc == Status::Internal {
        birefringent_fuzz::soft_finding(&format!("internal: {} for {args}", out.message));
    }
    // A call refused as a whole leaves its outputs untouched; a call that ran wrote every lane,
    // and its status is Ok or that of its first failed lane.
    let untouched = out.component.iter().all(|&c| c == 99);
    if rc != Status::Ok && untouched {
        return;
    }
    assert!(
        out.component.iter().all(|&c| c != 99),
        "a lane left unwritten"
    );
    let first_failure = out.status.iter().find(|s| **s != Status::Ok);
    assert_eq!(
        first_failure.copied().unwrap_or(Status::Ok),
        rc,
        "call status {rc:?} vs lanes {:?}",
        out.status
    );
    let n = lanes.count;
    for i in 0..n {
        let per = |k: usize, ch: usize| out.cols[k].get(ch * n + i).copied();
        let lane: Vec<f64> = (0..out.cols.len())
            .flat_map(|k| {
                let chans = if k >= FRAMES { e.channels } else { 1 };
                (0..chans).filter_map(move |ch| per(k, ch))
            })
            .collect();
        let pdf = out.cols[0][i];
        if out.status[i] != Status::Ok || pdf == 0.0 {
            assert_eq!(pdf, 0.0);
            assert!(
                lane.iter().all(|x| *x == 0.0),
                "lane {i} samples nothing but {lane:?}"
            );
            assert_eq!(out.component[i], 0);
            continue;
        }
        assert!(
            lane.iter().all(|x| x.is_finite()),
            "non-finite lane {i} {lane:?} for {args}"
        );
        assert!(pdf > 0.0 && pdf <= 1.0, "pdf {pdf}");
        let c = out.component[i];
        assert!(
            c <= e.max_component && e.components & (1 << c) != 0,
            "component {c}"
        );
        let wo: f64 = (2..5).map(|k| out.cols[k][i].powi(2)).sum::<f64>().sqrt();
        assert!((wo - 1.0).abs() < 1e-9, "wo not unit ({wo}) for {args}");
        for ch in 0..e.channels {
            let m00 = per(VALUE, ch).unwrap();
            assert!(e.signed || m00 >= 0.0, "negative weight {m00} for {args}");
            let t = lanes.transport[if lanes.transport.len() == 1 { 0 } else { i }];
            if e.importance_bound && t == Transport::Importance && m00 * pdf > 1.0 + 1e-9 {
                birefringent_fuzz::soft_finding(&format!(
                    "power fraction {} > 1 in lane {i} channel {ch} for {args}",
                    m00 * pdf
                ));
            }
        }
    }
}

fuzz_target!(|data: &[u8]| {
    birefringent_fuzz::set_input(data);
    let mut b = Bytes::new(data);
    let entry = b.u8() % 4;
    if entry == 3 {
        assert!(!birefringent::ffi::version().is_empty());
        return;
    }
    let m = materials(&mut b);
    let n_materials = b.u8() as u32 % 4;
    let l = lanes(&mut b, n_materials);
    let components = match b.u8() % 4 {
        0 => b.u32(),
        k => k as u32 * (1 + b.u8() as u32 % 3),
    };
    let frames = b.bool();
    let full = frames || b.bool();
    let args =
        format!(
        "entry {entry}, {} lanes, components {components}, wavelengths {:?}, wi {:?}, axis {:?}, \
         ext {:?}, exit {:?}, thickness {:?}, birefringence {:?}, transport {:?}, sample {:?}, \
         material {:?} of {}",
        l.count, l.wavelengths, l.wi, l.optic_axis, l.ext_ior, l.exit_ior, l.thickness_nm,
        l.birefringence, l.transport, l.sample, l.material, n_materials
    );
    if std::env::var_os("FUZZ_PRINT").is_some() {
        eprintln!("call with {args}");
    }
    // One call of the entry point on `lanes`, its spectrum and outputs decoded from `b`.
    let run_once = |b: &mut Bytes, lanes: &Lanes| -> (Out, Status, Expect) {
        let waves: Vec<&[f64]> = lanes.wavelengths.iter().map(|w| w.as_slice()).collect();
        let mut expect = Expect {
            channels: waves.len(),
            max_component: 2,
            components,
            signed: false,
            importance_bound: true,
        };
        if entry != 0 {
            let mut out = Out::new(b, lanes.count, expect.channels, frames, full);
            let cl = CrystalLanes {
                count: lanes.count,
                active: &lanes.active,
                material: &lanes.material,
                transport: &lanes.transport,
                sample: &lanes.sample,
                wi: v3(&lanes.wi),
                wavelengths_nm: &waves,
                ext_ior: &lanes.ext_ior,
                optic_axis: v3(&lanes.optic_axis),
            };
            let rc = out.run(&mut |s| sample_crystal(&m, components, &cl, s));
            return (out, rc, expect);
        }
        let (spectrum, signed, positive) = spectrum(b);
        expect.max_component = 1;
        expect.signed = signed;
        expect.importance_bound = positive;
        expect.channels = spectrum.channels(waves.len());
        let mut out = Out::new(b, lanes.count, expect.channels, frames, full);
        let call = PlateCall {
            components,
            intensity_only: !full,
            absorbing_exit: b.bool(),
        };
        let pl = PlateLanes {
            count: lanes.count,
            active: &lanes.active,
            material: &lanes.material,
            transport: &lanes.transport,
            sample: &lanes.sample,
            wi: v3(&lanes.wi),
            wavelengths_nm: &waves,
            ext_ior: &lanes.ext_ior,
            exit_ior: &lanes.exit_ior,
            optic_axis: v3(&lanes.optic_axis),
            axis_angle_deg: &lanes.axis_angle_deg,
            thickness_nm: &lanes.thickness_nm,
            birefringence: &lanes.birefringence,
        };
        let rc = out.run(&mut |s| sample_plate(&m, &spectrum, &call, &pl, s));
        (out, rc, expect)
    };
    let rest = b.rest();
    let (out, rc, expect) = run_once(&mut b, &l);
    if std::env::var_os("FUZZ_PRINT").is_some() {
        eprintln!(
            "status {rc:?} [{}], lanes {:?}, pdf {:?}",
            out.message, out.status, out.cols[0]
        );
    }
    check(&out, rc, &l, &expect, &args);
    // Determinism: the same call again (the same bytes decode the same spectrum and outputs).
    let (again, rc2, _) = run_once(&mut Bytes::new(rest), &l);
    assert!(
        rc == rc2 && out.bits() == again.bits(),
        "second call differs for {args}"
    );
    // Lane 0 alone: its outputs equal lane 0's of the batch.
    if rc != Status::Ok {
        return;
    }
    if let Some(first) = l.first() {
        let (alone, rc1, e1) = run_once(&mut Bytes::new(rest), &first);
        if rc1 == Status::Ok {
            assert_eq!(
                alone.lane_bits(0, 1, e1.channels),
                out.lane_bits(0, l.count, expect.channels),
                "lane 0 alone differs for {args}"
            );
        }
    }
});

/// A plate spectrum: (spectrum, signed channel weights, positive weights).
fn spectrum(b: &mut Bytes) -> (Box<PlateSpectrum>, bool, bool) {
    match b.u8() % 5 {
        0 => (exact_spectrum(), false, true),
        1 | 2 => (band_spectrum(b.f64()), false, true),
        3 => (srgb_spectrum(), true, false),
        _ => {
            // Mostly valid channel names, sometimes a mangled one.
            const NAMES: [&str; 10] = [
                "srgb-d65:R", "srgb-d65:G", "srgb-d65:B", "xyz-d65:X", "xyz-d65:Y",
                "xyz-d65:Z", "xyz-e:X", "xyz-e:Y", "xyz-e:Z", "srgb-d65:Y",
            ];
            let name = NAMES[b.u8() as usize % NAMES.len()];
            match colour_channel_spectrum(name) {
                Ok(s) => (s, name.starts_with("srgb"), false),
                Err(e) => {
                    check_message(&e.to_string());
                    (exact_spectrum(), false, true)
                }
            }
        }
    }
}
