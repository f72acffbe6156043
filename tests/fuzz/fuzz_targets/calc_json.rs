//! Fuzz target: arbitrary text through `birefringent::calc::run_text`, the function the
//! `birefringence` binary calls on every document (and every `--batch` line). The first byte
//! picks the subcommand (`interface`, `slab`, or an unknown one); the rest is the text (invalid
//! UTF-8 is replaced, as the binary cannot read it as a line anyway). A dictionary of the field
//! names (tests/fuzz/calc.dict) and the seed corpus of valid documents
//! (tests/fuzz/corpus/calc_json) let the mutator reach the physics.
//!
//! Contract asserted: see `birefringent_fuzz::check_calc_output`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    birefringent_fuzz::set_input(data);
    let (sub, text) = match data.split_first() {
        Some((b, rest)) => (
            match b % 3 {
                0 => "interface",
                1 => "slab",
                _ => "refract",
            },
            rest,
        ),
        None => ("interface", data),
    };
    let text = String::from_utf8_lossy(text);
    birefringent_fuzz::run_calc(sub, &text);
});
