//! JSON encodings of the calculator's outputs.

use crate::optics::modes::Mode;
use crate::optics::surface::Solved;
use nalgebra::Vector3;
use num_complex::Complex64 as C64;
use serde_json::{json, Map, Value};

/// A JSON number; a non-finite value becomes the marker string [`NON_FINITE`], which
/// [`super::run_text`] turns into an error (serde_json would silently write `null`).
pub fn num(x: f64) -> Value {
    serde_json::Number::from_f64(x)
        .map(Value::Number)
        .unwrap_or_else(|| Value::String(NON_FINITE.into()))
}

/// Marker of a non-finite number in an output under construction.
pub const NON_FINITE: &str = "<non-finite>";

/// `[re, im]`.
pub fn complex(z: C64) -> Value {
    json!([num(z.re), num(z.im)])
}

/// `[x, y, z]`.
pub fn vector(v: Vector3<f64>) -> Value {
    json!([num(v.x), num(v.y), num(v.z)])
}

/// Everything known about one outgoing (or incident) wave, directions in the local frame.
pub fn wave(solved: &Solved, mode: &Mode) -> Value {
    json!({
        "q": complex(mode.q),
        "evanescent": mode.is_evanescent(),
        "wave_direction": vector(solved.wave_local(mode)),
        "ray_direction": solved.ray_local(mode).map(vector),
        "effective_index": complex(mode.effective_index()),
        "ray_index": mode.ray_index().map(num),
        "flux": num(mode.flux()),
    })
}

/// Adds the `warnings` array to `out` unless there are none.
pub fn insert_warnings(out: &mut Map<String, Value>, warnings: &[String]) {
    if !warnings.is_empty() {
        out.insert("warnings".into(), json!(warnings));
    }
}
