#[path = "../tests/spectral_rgb.rs"]
mod spectral_rgb;
fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(40);
    let cases = spectral_rgb::hard_cases(n, spectral_rgb::TEST_SEED ^ 0x6A2D);
    let outcomes: Vec<spectral_rgb::Outcome> = cases
        .iter()
        .map(|c| spectral_rgb::compare_with_step(c, spectral_rgb::hard_quadrature_step(c), false))
        .collect();
    for o in &outcomes {
        println!("{:.3?} {}", o.de, o.case.describe());
    }
    spectral_rgb::report(&outcomes);
}
