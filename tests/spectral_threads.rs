//! A channel query's answer does not depend on what its thread computed before. The closed-form
//! integration keeps working tables per thread between queries (the path classes' phase tables
//! of chirped groups among them, refilled per query: `tests/spectral_allocations.rs`); a table
//! left over from another plate would give the second of two queries on one thread another
//! plate's phases. Each plate here is queried after every other on one thread and alone on a
//! fresh thread, through the calculator (`calc::run`, the public entry of the integration), and
//! the answers must be equal to the bit: the query is deterministic.

use birefringent::calc;
use serde_json::{json, Value};

/// Thick plates near grazing incidence (path classes with chirped groups: their traversals'
/// phases vary across the band faster than linearly), over the sRGB channels, both lobes.
fn plates() -> Vec<Value> {
    let plate = |material: &str, um: f64, axis: [f64; 3], theta: f64, phi: f64| {
        json!({"wavelength_nm": 550, "material": material, "thickness_um": um,
               "optic_axis": axis, "theta_deg": theta, "phi_deg": phi,
               "spectrum": {"weights": "srgb-d65", "method": "analytic"}})
    };
    vec![
        plate("calcite", 150.0, [1.0, 0.3, 0.2], 80.0, 28.6),
        plate("calcite", 120.0, [0.2, 1.0, 0.4], 78.0, 60.0),
        plate("quartz", 150.0, [1.0, 1.0, 0.0], 82.0, 10.0),
        plate("rutile", 39.99, [-0.964, 0.178, 0.198], 55.9, 28.6),
    ]
}

fn slab(input: &Value) -> Value {
    calc::run("slab", input).expect("a valid plate")
}

/// Each plate alone on a fresh thread (fresh per-thread tables).
fn alone(input: &Value) -> Value {
    let input = input.clone();
    std::thread::spawn(move || slab(&input)).join().unwrap()
}

#[test]
fn a_query_after_another_plate_equals_the_query_alone() {
    let plates = plates();
    let fresh: Vec<Value> = plates.iter().map(alone).collect();
    // The plates differ, so a stale table would show.
    for i in 1..plates.len() {
        assert_ne!(fresh[0], fresh[i], "plates 0 and {i} give the same answer");
    }
    // On one thread: every ordered pair (a, b), b right after a.
    std::thread::spawn(move || {
        for (a, first) in plates.iter().enumerate() {
            for (b, second) in plates.iter().enumerate() {
                if a == b {
                    continue;
                }
                slab(first);
                assert!(
                    slab(second) == fresh[b],
                    "plate {b} after plate {a} differs from plate {b} alone"
                );
            }
        }
    })
    .join()
    .unwrap();
}
