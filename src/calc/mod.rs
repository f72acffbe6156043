//! The JSON calculator behind the `birefringence` command: one JSON object in, one out.

pub mod input;
pub mod interface;
pub mod media;
pub mod output;
pub mod slab;
pub mod spectrum;
pub mod stack;

use crate::error::{Error, Result};
use serde_json::{json, Value};

/// The subcommands.
pub const SUBCOMMANDS: [&str; 3] = ["interface", "slab", "stack"];

/// Runs `subcommand` on one input object; errors become `{"error": "..."}` at the caller.
pub fn run(subcommand: &str, input: &Value) -> Result<Value> {
    match subcommand {
        "interface" => interface::run(input),
        "slab" => run_slab(input),
        "stack" => stack::run(input),
        _ => Err(Error::new(
            "subcommand",
            format!(
                "unknown subcommand '{subcommand}' (known: {})",
                SUBCOMMANDS.join(", ")
            ),
        )),
    }
}

/// The `slab` subcommand: the slab at one wavelength, or over the `spectrum` the input asks for.
fn run_slab(input: &Value) -> Result<Value> {
    let fields = slab::slab_fields();
    match input::Fields::new(input, &fields)?.get("spectrum") {
        None => slab::run_monochromatic(input, &fields),
        Some(spec) => spectrum::run(input, &fields, spec),
    }
}

/// Runs one line/document of text: parse errors, physics errors and panics all become an error
/// object; the boolean says whether it succeeded.
pub fn run_text(subcommand: &str, text: &str) -> (Value, bool) {
    let result = std::panic::catch_unwind(|| {
        let input: Value = serde_json::from_str(text)
            .map_err(|e| Error::new("input", format!("invalid JSON: {e}")))?;
        let out = run(subcommand, &input)?;
        check_finite(&out)?;
        Ok::<Value, Error>(out)
    });
    match result {
        Ok(Ok(v)) => (v, true),
        Ok(Err(e)) => (json!({ "error": e.to_string() }), false),
        Err(_) => (
            json!({ "error": "internal error (a bug: please report the input)" }),
            false,
        ),
    }
}

/// Guards the promise of finite output: any NaN/inf in a result is reported as an error.
fn check_finite(v: &Value) -> Result<()> {
    match v {
        Value::String(s) if s == output::NON_FINITE => Err(Error::new(
            "output",
            "non-finite value (a bug: please report the input)",
        )),
        Value::Array(a) => a.iter().try_for_each(check_finite),
        Value::Object(o) => o.values().try_for_each(check_finite),
        _ => Ok(()),
    }
}
