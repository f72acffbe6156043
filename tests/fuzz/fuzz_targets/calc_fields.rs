//! Fuzz target: structured calculator inputs. The bytes choose which of the documented fields
//! are present (and a few unknown ones) and give each a hostile value: numbers from
//! `Bytes::f64` (huge, tiny, negative, subnormal, on physical scales; a non-finite one becomes
//! the largest JSON number or a literal serde_json refuses), complex `[n, kappa]` pairs, vectors
//! of any length, named crystals and IOR names, wrong JSON types, nested `spectrum` objects. The
//! document is serialised and goes through `birefringent::calc::run_text` as text, exactly as
//! the binary does. Without this target, raw-text mutation rarely builds a document that
//! passes validation deep enough to reach the plate and the spectral integration.
//!
//! Contract asserted: see `birefringent_fuzz::check_calc_output`.
#![no_main]

use birefringent_fuzz::{calc_document, Bytes};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    birefringent_fuzz::set_input(data);
    let mut b = Bytes::new(data);
    let sub = if b.bool() { "slab" } else { "interface" };
    let text = calc_document(&mut b, sub == "slab");
    birefringent_fuzz::run_calc(sub, &text);
});
