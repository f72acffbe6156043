//! Shared input decoding of the fuzz targets: turns libFuzzer's bytes into the arguments of the
//! entry points, biased towards hostile values (NaN, ±inf, ±0, subnormals, huge and tiny
//! magnitudes, negative numbers, values at the edges of the valid ranges) so that the mutator
//! reaches them in a few steps instead of guessing 64-bit patterns.

/// A cursor over the fuzzer's bytes; reads past the end give zeros (so every input decodes).
pub struct Bytes<'a> {
    data: &'a [u8],
    pos: usize,
}

/// Values a tag byte selects directly: every class of IEEE-754 double that has a chance of
/// breaking a numerical code, and the ordinary magnitudes of the physics (indices, angles,
/// wavelengths in nm, thicknesses in nm).
pub const SPECIAL: [f64; 40] = [
    f64::NAN,
    -f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -0.0,
    f64::MIN_POSITIVE,
    5e-324,
    -5e-324,
    f64::MAX,
    f64::MIN,
    f64::EPSILON,
    1e-300,
    1e300,
    -1e300,
    1e-12,
    1e-8,
    1e-4,
    0.5,
    1.0,
    -1.0,
    1.0 + 1e-12,
    1.0 - 1e-12,
    1.0001,
    1.4,
    1.5,
    1.55,
    2.4,
    4.0,
    10.0,
    20.0,
    90.0,
    89.999,
    180.0,
    360.0,
    550.0,
    300.0,
    1000.0,
    1e8,
    -550.0,
];

impl<'a> Bytes<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        Bytes { data, pos: 0 }
    }

    pub fn is_empty(&self) -> bool {
        self.pos >= self.data.len()
    }

    /// The bytes not read yet.
    pub fn rest(&self) -> &'a [u8] {
        &self.data[self.pos.min(self.data.len())..]
    }

    pub fn u8(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }

    pub fn bool(&mut self) -> bool {
        self.u8() & 1 == 1
    }

    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }

    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }

    pub fn i32(&mut self) -> i32 {
        self.u32() as i32
    }

    /// A double: a tag byte picks a special value, a raw bit pattern, a value on a physical
    /// scale, or a small perturbation of a special value.
    pub fn f64(&mut self) -> f64 {
        let tag = self.u8();
        match tag {
            0..=119 => SPECIAL[tag as usize % SPECIAL.len()],
            120..=159 => f64::from_bits(u64::from_le_bytes(std::array::from_fn(|_| self.u8()))),
            160..=219 => {
                // [lo, hi) on a linear scale picked by the tag: indices, angles, wavelengths.
                let (lo, hi) = match tag % 6 {
                    0 => (0.0, 5.0),
                    1 => (-1.0, 1.0),
                    2 => (250.0, 1100.0),
                    3 => (0.0, 90.0),
                    4 => (0.0, 25.0),
                    _ => (-10.0, 10.0),
                };
                lo + (hi - lo) * (self.u16() as f64 / 65536.0)
            }
            _ => {
                // A log-uniform magnitude over 1e-320..1e308 with a sign.
                let e = -320.0 + 628.0 * (self.u16() as f64 / 65536.0);
                let sign = if self.bool() { -1.0 } else { 1.0 };
                sign * 10f64.powf(e)
            }
        }
    }

    /// Up to `max` raw bytes (the length is a byte of the input).
    pub fn bytes(&mut self, max: usize) -> Vec<u8> {
        let n = (self.u8() as usize).min(max);
        (0..n).map(|_| self.u8()).collect()
    }

    /// A unit vector from two angles, a nearly unit one, or three hostile components.
    pub fn direction(&mut self) -> [f64; 3] {
        match self.u8() % 4 {
            0 => [self.f64(), self.f64(), self.f64()],
            k => {
                let ct = 2.0 * (self.u32() as f64 / u32::MAX as f64) - 1.0;
                let phi = std::f64::consts::TAU * (self.u16() as f64 / 65536.0);
                let st = (1.0 - ct * ct).max(0.0).sqrt();
                let v = [st * phi.cos(), st * phi.sin(), ct];
                if k == 1 {
                    // Off unit length by a hostile relative amount.
                    let s = 1.0 + self.f64() * 1e-5;
                    [v[0] * s, v[1] * s, v[2] * s]
                } else if k == 2 {
                    // Rounded to f32, as Mitsuba passes its directions.
                    v.map(|x| x as f32 as f64)
                } else {
                    v
                }
            }
        }
    }
}

use serde_json::{json, Map, Value};

/// A JSON number from a hostile double: JSON has no NaN or infinity, so NaN becomes the string
/// "NaN" (a type error the calculator must name) and ±inf the largest finite double.
fn number(x: f64) -> Value {
    if x.is_nan() {
        Value::String("NaN".into())
    } else {
        json!(x.clamp(f64::MIN, f64::MAX))
    }
}

/// A value of a wrong JSON type (or an empty/odd one).
fn wrong_type(b: &mut Bytes) -> Value {
    match b.u8() % 6 {
        0 => Value::Null,
        1 => json!(b.bool()),
        2 => json!("1.5"),
        3 => json!([]),
        4 => json!({}),
        _ => json!([[1.5, 0.0], [1.5]]),
    }
}

const CRYSTALS: [&str; 11] = [
    "calcite",
    "quartz",
    "sapphire",
    "rutile",
    "mgf2",
    "linbo3",
    "bbo",
    "kdp",
    "Iceland Spar",
    "unobtainium",
    "",
];
const IORS: [&str; 5] = ["water", "bk7", "air", "diamond", "vacuum "];

/// A field value of the kind `kind` (mostly well-typed, sometimes not).
fn field(b: &mut Bytes, kind: u8) -> Value {
    if b.u8() < 16 {
        return wrong_type(b);
    }
    match kind {
        // a number
        0 => number(b.f64()),
        // an index: number, [n, kappa] or a name
        1 => match b.u8() % 4 {
            0 | 1 => number(b.f64()),
            2 => json!([number(b.f64()), number(b.f64())]),
            _ => json!(IORS[b.u8() as usize % IORS.len()]),
        },
        // a crystal index: number or [n, kappa]
        2 => match b.u8() % 2 {
            0 => number(b.f64()),
            _ => json!([number(b.f64()), number(b.f64())]),
        },
        // a vector of 0..=4 numbers, mostly 3
        3 => {
            let n = match b.u8() % 8 {
                0 => 0,
                1 => 2,
                2 => 4,
                _ => 3,
            };
            if n == 3 && b.bool() {
                Value::Array(b.direction().into_iter().map(number).collect())
            } else {
                Value::Array((0..n).map(|_| number(b.f64())).collect())
            }
        }
        // a crystal name
        4 => json!(CRYSTALS[b.u8() as usize % CRYSTALS.len()]),
        // side
        5 => json!(["outside", "inside", "below"][b.u8() as usize % 3]),
        // inside mode
        6 => json!(["o", "e", "x"][b.u8() as usize % 3]),
        // spectrum object
        _ => {
            let mut s = Map::new();
            if b.bool() {
                let w = ["srgb-d65", "xyz-d65", "xyz-e", "rgb"][b.u8() as usize % 4];
                s.insert("weights".into(), json!(w));
            }
            if b.bool() {
                s.insert("bandwidth_nm".into(), number(b.f64()));
            }
            if b.bool() {
                let m = ["analytic", "quadrature", "exact"][b.u8() as usize % 3];
                s.insert("method".into(), json!(m));
            }
            if b.bool() {
                s.insert("step_nm".into(), number(b.f64()));
            }
            if b.u8() == 0 {
                s.insert("colour".into(), json!(1));
            }
            Value::Object(s)
        }
    }
}

/// The fields of the calculator (README "Input fields") and the kind of value each takes.
const FIELDS: [(&str, u8); 16] = [
    ("wavelength_nm", 0),
    ("ext_ior", 1),
    ("eta_o", 2),
    ("eta_e", 2),
    ("material", 4),
    ("kappa_o", 0),
    ("kappa_e", 0),
    ("optic_axis", 3),
    ("theta_deg", 0),
    ("beta", 0),
    ("phi_deg", 0),
    ("side", 5),
    ("inside_mode", 6),
    ("thickness_um", 0),
    ("exit_ior", 1),
    ("spectrum", 7),
];

/// A calculator document: each field present or not (a presence byte per field, biased towards
/// the fields a valid query needs), plus now and then an unknown field; serialised as the text
/// the binary would read.
pub fn calc_document(b: &mut Bytes, slab: bool) -> String {
    let mut o = Map::new();
    for (name, kind) in FIELDS {
        let p = b.u8();
        let usual = match name {
            "wavelength_nm" | "theta_deg" => true,
            "eta_o" | "eta_e" | "optic_axis" => true,
            "thickness_um" => slab,
            _ => false,
        };
        let present = if usual { p >= 32 } else { p >= 192 };
        if present {
            o.insert(name.into(), field(b, kind));
        }
    }
    if b.u8() == 0xFF {
        o.insert("thickness".into(), json!(1.0));
    }
    Value::Object(o).to_string()
}

/// What a calculator error `e` may name (the text before its ": "): a field of the document
/// (e.g. an unknown one), a field of the calculator (e.g. a missing one; an element `[i]` of a
/// vector field), `spectrum.<field>` for a field of the spectrum object, the subject of an
/// error about the whole input (`input`, `incidence`, `spectrum`, `subcommand`), or the object
/// of a physically undefined query (`slab`: a diverging multiple-reflection sum, `interface`: a
/// singular boundary system) — never a name of the core the user did not write (as
/// `thickness` in nm for `thickness_um` once was).
fn names_what_the_user_wrote(e: &str, text: &str) -> bool {
    let doc: Value = serde_json::from_str(text).unwrap_or(Value::Null);
    let keys = |v: &Value| -> Vec<String> {
        v.as_object()
            .map(|o| o.keys().cloned().collect())
            .unwrap_or_default()
    };
    let spectrum = doc.get("spectrum").map(keys).unwrap_or_default();
    let mut names: Vec<String> = keys(&doc);
    names.extend(FIELDS.iter().map(|(f, _)| f.to_string()));
    names.extend(
        ["weights", "method", "step_nm", "bandwidth_nm"]
            .iter()
            .map(|s| s.to_string())
            .chain(spectrum)
            .map(|k| format!("spectrum.{k}")),
    );
    names.extend(
        [
            "input",
            "incidence",
            "spectrum",
            "subcommand",
            "slab",
            "interface",
        ]
        .map(String::from),
    );
    names
        .iter()
        .any(|n| e.starts_with(&format!("{n}: ")) || e.starts_with(&format!("{n}[")))
}

/// The calculator's two internal errors (src/calc/mod.rs): a caught panic and a non-finite result.
const INTERNAL_PANIC: &str = "internal error (a bug: please report the input)";
const INTERNAL_NON_FINITE: &str = "output: non-finite value (a bug: please report the input)";

fn all_numbers_finite(v: &Value) -> bool {
    match v {
        Value::Number(n) => n.as_f64().is_some_and(f64::is_finite),
        Value::Array(a) => a.iter().all(all_numbers_finite),
        Value::Object(o) => o.values().all(all_numbers_finite),
        _ => true,
    }
}

/// The calculator's contract on one result of `run_text`:
/// - an error is `{"error": "parameter: what"}`, non-empty; the internal one (a caught panic or
///   a non-finite result, which the calculator labels "a bug") goes to [`soft_finding`];
/// - a success has no `error` key and only finite numbers; for `slab` without `spectrum`
///   every power fraction (`R.*`, `T.*`: fractions of the incident power of a lossless or
///   absorbing plate between real media) lies in [0, 1] to 1e-9 (f64 rounding of sums of
///   O(1) terms), else a [`soft_finding`];
/// - the binary can print it (`to_string_pretty`).
///
/// Panics (a fuzzer finding) when it does not hold.
pub fn check_calc_output(sub: &str, text: &str, v: &Value, ok: bool) {
    let document = text;
    let text: String = text.chars().take(2000).collect();
    serde_json::to_string_pretty(v).expect("output not serialisable");
    let o = v.as_object().expect("output not an object");
    if !ok {
        assert_eq!(o.len(), 1, "error output with other keys: {v}");
        let e = o
            .get("error")
            .and_then(Value::as_str)
            .expect("no error string");
        if e == INTERNAL_PANIC || e == INTERNAL_NON_FINITE {
            soft_finding(&format!("internal error: {e} for {sub} {text}"));
            return;
        }
        assert!(
            e.contains(": "),
            "error does not name a parameter: {e} for {sub} {text}"
        );
        assert!(
            names_what_the_user_wrote(e, document),
            "error names neither a field of the input nor of the calculator: {e} for {sub} {text}"
        );
        return;
    }
    assert!(!o.contains_key("error"), "success with an error key: {v}");
    assert!(
        all_numbers_finite(v),
        "non-finite number in {v} for {sub} {text}"
    );
    if sub == "slab" && o.contains_key("mueller") {
        for key in ["R", "T"] {
            let mut stack = vec![&o[key]];
            while let Some(x) = stack.pop() {
                match x {
                    Value::Object(m) => stack.extend(m.values()),
                    Value::Array(a) => stack.extend(a.iter()),
                    Value::Number(n) => {
                        let p = n.as_f64().unwrap_or(f64::NAN);
                        // Rounding bound: at 89.999 deg (cos 1.7e-5) with index contrasts
                        // of several hundred the boundary systems are conditioned ~1e9-1e10;
                        // the worst seen, T = 1 + 7.3e-7 (a zero-thickness absorbing layer
                        // under ext_ior 595), is rounding, not a defect of the method.
                        if !(-1e-6..=1.0 + 1e-6).contains(&p) {
                            soft_finding(&format!(
                                "{key} power fraction {p} outside [0, 1] for {sub} {text}"
                            ));
                        }
                    }
                    _ => {}
                }
            }
        }
    }
}

thread_local! {
    static INPUT: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Remembers the current input, for [`soft_finding`].
pub fn set_input(data: &[u8]) {
    INPUT.with(|i| {
        let mut i = i.borrow_mut();
        i.clear();
        i.extend_from_slice(data);
    });
}

/// A breach of the *soft* contract: an entry point answered with its internal error
/// (`Status::Internal` of the bridge, or the calculator's "a bug: please report the input": a clean error status
/// with no non-finite number handed out, so the brief's contract of no crash and finite output
/// or a clean error holds, but it is a core defect), or a finite result outside its physical
/// bounds (a power fraction above 1). With `FUZZ_STRICT=1` it is a crash (libFuzzer keeps the
/// input); otherwise the input is written to `$FUZZ_FINDINGS/soft-<hash>` with the description
/// in `soft-<hash>.txt` and the run goes on; tests/fuzz/run.sh counts and lists them. Crashes,
/// panics, non-finite numbers, memory errors and malformed messages always fail.
pub fn soft_finding(what: &str) {
    if std::env::var("FUZZ_STRICT").is_ok_and(|v| v == "1") {
        panic!("{what}");
    }
    let Ok(dir) = std::env::var("FUZZ_FINDINGS") else {
        return;
    };
    INPUT.with(|i| {
        use std::hash::{Hash, Hasher};
        let data = i.borrow();
        let mut h = std::collections::hash_map::DefaultHasher::new();
        data.hash(&mut h);
        let base = std::path::Path::new(&dir).join(format!("soft-{:016x}", h.finish()));
        let _ = std::fs::create_dir_all(&dir);
        let _ = std::fs::write(&base, &*data);
        let _ = std::fs::write(base.with_extension("txt"), what);
    });
}

/// True when `FUZZ_EXHAUSTIVE=1`: nothing is skipped (tests/fuzz/run.sh then also runs one
/// process in which a timeout fails). Soft findings fail with `FUZZ_STRICT=1`, independently.
pub fn exhaustive() -> bool {
    std::env::var("FUZZ_EXHAUSTIVE").is_ok_and(|v| v == "1")
}

/// Calculator documents the bounded runs skip (unless [`exhaustive`]): the dense-quadrature
/// reference (`"method": "quadrature"`) costs one exact plate per node; the core accepts up to
/// 1e7 nodes (a minute), so more than 1e6 nodes is skipped to keep the runs exploring. (The
/// earlier skips of extreme magnitudes and of bands wider than half their wavelength are gone:
/// the core now refuses such inputs with a clear error.)
pub fn known_calc(text: &str) -> bool {
    if exhaustive() {
        return false;
    }
    let Ok(v) = serde_json::from_str::<Value>(text) else {
        return false;
    };
    let Some(spec) = v.get("spectrum").and_then(Value::as_object) else {
        return false;
    };
    let band = spec.get("bandwidth_nm").and_then(Value::as_f64);
    if spec.get("method").and_then(Value::as_str) == Some("quadrature") {
        let range = band.map_or(470.0, |b| 8.0 * b.abs());
        let step = spec.get("step_nm").and_then(Value::as_f64).unwrap_or(1e-5);
        // NaN (a zero or non-numeric step) counts as too many nodes.
        let nodes = range / step;
        return nodes.is_nan() || nodes > 1e6;
    }
    false
}

/// Runs calculator subcommand `sub` on document `text` and checks its output (the calculator
/// targets' common step): `FUZZ_PRINT=1 TARGET FILE` says what is run; [`known_calc`] inputs
/// are skipped.
pub fn run_calc(sub: &str, text: &str) {
    if std::env::var_os("FUZZ_PRINT").is_some() {
        eprintln!("{sub} {text}");
    }
    if known_calc(text) {
        return;
    }
    let (v, ok) = birefringent::calc::run_text(sub, text);
    check_calc_output(sub, text, &v, ok);
}
