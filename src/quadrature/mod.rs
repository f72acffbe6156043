//! Quadrature that knows no plate: the nested Chebyshev–Lobatto nodes of the visible band,
//! Gauss–Hermite and Gauss–Legendre rules, the product-integration rules of a fringe against a
//! colour channel (`fringe`) and of a weight set on Chebyshev points (`chebyshev`), the checked
//! Chebyshev interpolant, and the error budget every spectral method is held to.

pub mod budget;
pub mod chebyshev;
pub mod fringe;
pub mod hermite;
pub mod interpolate;
pub mod nodes;

/// How exactly a channel set is integrated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Accuracy {
    /// The perceptual budget of [`budget`] (mean CIEDE2000 0.1, worst 0.5 against the tabulated
    /// weights, measured in `tests/spectral_rgb.rs`): what renders use.
    Perceptual,
    /// Every approximation below 1e-5 of the fitted weights (the rule the perceptual one is
    /// checked against, and the calculator's `"method": "exact"`).
    Exact,
}
