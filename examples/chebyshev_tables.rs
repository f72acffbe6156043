//! Writes `src/quadrature/chebyshev_tables.bin`, the Chebyshev rules' moments and error tables
//! that the first analytic query of a process reads instead of building them (issue 30, item 4):
//!
//! ```text
//! cargo run --release --example chebyshev_tables
//! ```
//!
//! Run it after changing the weights' fits or the rules' ladder; the unit test
//! `quadrature::chebyshev::tests::stored_tables_are_current` fails until then.

fn main() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/src/quadrature/chebyshev_tables.bin"
    );
    let bytes = birefringent::quadrature::chebyshev::tabulate();
    std::fs::write(path, &bytes).expect("the table file is written");
    println!("{path}: {} bytes", bytes.len());
}
