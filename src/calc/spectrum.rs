//! `birefringence slab` with a `spectrum`: Mueller matrices integrated over camera channel
//! weights or over a Gaussian band, in closed form ("analytic": what the renderer uses, to the
//! perceptual budget of `quadrature::budget` over channels; "exact": every approximation below
//! 1e-5 of the fitted weights) or by dense quadrature of the exact slab ("quadrature", the
//! reference).

use super::input::Fields;
use super::output::num;
use super::slab::{matrix, read, SlabQuery};
use crate::band::{is_exact_band, narrow_band, Gaussian};
use crate::colour::weights::{weight_per_nm, WeightSet};
use crate::error::{Error, Result};
use crate::params::Bandwidth;
use crate::plate::slab::Output;
use crate::plate::slab::{SlabMueller, Want};
use crate::quadrature::Accuracy;
use crate::spectral::model::{PlateModel, ThinModel};
use crate::spectral::reference::quadrature;
use nalgebra::{Matrix4, Vector4};
use serde_json::{json, Map, Value};

/// Visible range of the tabulated weights (nm).
pub const RANGE: (f64, f64) = crate::material::RENDER_RANGE_NM;

/// What a `spectrum` object asks for.
pub enum Over {
    /// The three channels of a weight set.
    Weights(WeightSet),
    /// A Gaussian band of this FWHM (nm) around the query's wavelength.
    Band(f64),
}

/// A parsed `spectrum` object.
pub struct Request<'a> {
    /// Channels or a band.
    pub over: Over,
    /// `"analytic"`, `"exact"` or `"quadrature"`.
    pub method: &'a str,
    /// The accuracy of the closed form (`"analytic"`: perceptual).
    pub accuracy: Accuracy,
    /// The quadrature's step (nm), if given.
    pub step: Option<f64>,
}

impl Request<'_> {
    /// True for the dense quadrature of the exact result (the reference).
    pub fn quadrature(&self) -> bool {
        self.method == "quadrature"
    }
}

/// Reads the `spectrum` object `spec` of a query at `wavelength_nm`.
pub fn read_request(spec: &Value, wavelength_nm: f64) -> Result<Request<'_>> {
    let mut s = Fields::nested(
        spec,
        &["weights", "method", "step_nm", "bandwidth_nm"],
        "spectrum",
    )?;
    let method = s.string("method")?.unwrap_or("analytic");
    let accuracy = match method {
        "analytic" => Accuracy::Perceptual,
        "exact" | "quadrature" => Accuracy::Exact,
        _ => {
            return Err(Error::new(
                "spectrum.method",
                format!("must be \"analytic\", \"exact\" or \"quadrature\", got \"{method}\""),
            ))
        }
    };
    let step = s.number("step_nm")?;
    if let Some(st) = step {
        if st <= 0.0 {
            return Err(Error::new(
                "spectrum.step_nm",
                format!("must be > 0, got {st}"),
            ));
        }
    }
    let over = match (s.string("weights")?, s.number("bandwidth_nm")?) {
        (Some(w), None) => Over::Weights(WeightSet::parse(w).ok_or_else(|| {
            Error::new(
                "spectrum.weights",
                format!("must be \"srgb-d65\", \"xyz-d65\" or \"xyz-e\", got \"{w}\""),
            )
        })?),
        (None, Some(b)) => {
            Over::Band(Bandwidth::new("spectrum.bandwidth_nm", b, wavelength_nm)?.fwhm_nm())
        }
        (Some(_), Some(_)) => {
            return Err(Error::new(
                "spectrum",
                "give weights or bandwidth_nm, not both",
            ))
        }
        (None, None) => return Err(Error::new("spectrum", "give weights or bandwidth_nm")),
    };
    Ok(Request {
        over,
        method,
        accuracy,
        step,
    })
}

/// The channel names of a request at `wavelength_nm`.
pub fn channel_names(over: &Over, wavelength_nm: f64) -> Vec<String> {
    match over {
        Over::Weights(set) => set.channel_names().iter().map(|s| s.to_string()).collect(),
        Over::Band(b) => vec![format!("{wavelength_nm} nm ± {b} nm FWHM")],
    }
}

/// Runs `slab` with the `spectrum` object `spec`.
pub fn run(input: &Value, fields: &[&str], spec: &Value) -> Result<Value> {
    let mut f = Fields::new(input, fields)?;
    let q = read(&mut f)?;
    let request = read_request(spec, q.wavelength_nm)?;
    let mut warnings = q.warnings.clone();
    let results: Vec<SlabMueller> = match request.over {
        Over::Weights(set) => {
            warnings.extend(q.plate.material.coverage(RANGE.0, RANGE.1)?);
            if request.quadrature() {
                let step = request.step.unwrap_or_else(|| auto_step(&q, RANGE.0));
                (0..3)
                    .map(|c| {
                        quadrature(
                            &q.plate,
                            &q.frame,
                            q.beta,
                            |l| weight_per_nm(set, c, l),
                            RANGE,
                            step,
                            Want::BOTH,
                        )
                        .map_err(step_field)
                    })
                    .collect::<Result<Vec<_>>>()?
            } else {
                PlateModel::new(&q.plate, q.frame, q.beta)
                    .channels(set, Want::BOTH, Output::Mueller, request.accuracy)?
                    .to_vec()
            }
        }
        Over::Band(b) => vec![band(&q, b, request.quadrature(), request.step)?],
    };
    Ok(encode(
        channel_names(&request.over, q.wavelength_nm),
        &results,
        request.method,
        &warnings,
    ))
}

/// The output of a spectrum query: power terms and Mueller matrices per channel (a list when
/// there are several channels), the channel names, the method and the warnings.
pub fn encode(
    names: Vec<String>,
    results: &[SlabMueller],
    method: &str,
    warnings: &[String],
) -> Value {
    let list = names.len() > 1;
    let pick = |v: Vec<Value>| {
        if list {
            Value::Array(v)
        } else {
            v.into_iter().next().unwrap_or(Value::Null)
        }
    };
    let mut out = Map::new();
    for (key, get) in [("R", 0usize), ("T", 1)] {
        let ms: Vec<Matrix4<f64>> = results
            .iter()
            .map(|m| if get == 0 { m.r } else { m.t }.unwrap_or_default())
            .collect();
        let mut terms = Map::new();
        for (name, input, output) in [
            ("ss", 1.0, 1.0),
            ("sp", 1.0, -1.0),
            ("ps", -1.0, 1.0),
            ("pp", -1.0, -1.0),
        ] {
            terms.insert(
                name.into(),
                pick(ms.iter().map(|m| num(power(m, input, output))).collect()),
            );
        }
        out.insert(key.into(), Value::Object(terms));
        out.insert(
            format!("mueller_{key}"),
            pick(ms.iter().map(matrix).collect()),
        );
    }
    out.insert("channels".into(), json!(names));
    out.insert("method".into(), json!(method));
    super::output::insert_warnings(&mut out, warnings);
    Value::Object(out)
}

/// Power from linear input `s` (`input = 1`) or `p` (`−1`) into output `s` (`1`) or `p` (`−1`)
/// of a Mueller matrix in s/p frames (Stokes x = s).
fn power(m: &Matrix4<f64>, input: f64, output: f64) -> f64 {
    let out = m * Vector4::new(1.0, input, 0.0, 0.0);
    0.5 * (out[0] + output * out[1])
}

/// A Gaussian band of FWHM `b` (validated) around the query's wavelength.
fn band(q: &SlabQuery, b: f64, quad: bool, step: Option<f64>) -> Result<SlabMueller> {
    if is_exact_band(b, q.wavelength_nm) {
        return q
            .slab
            .optics(&q.frame, q.beta)?
            .mueller(q.wavelength_nm, Want::BOTH);
    }
    let g = narrow_band(q.wavelength_nm, b);
    if !quad {
        return PlateModel::new(&q.plate, q.frame, q.beta).band(
            &[g],
            Want::BOTH,
            Output::Mueller,
            Accuracy::Exact,
        );
    }
    let range = band_range(q.wavelength_nm, b);
    quadrature(
        &q.plate,
        &q.frame,
        q.beta,
        band_weight(g),
        range,
        step.unwrap_or_else(|| auto_step(q, range.0)),
        Want::BOTH,
    )
    .map_err(step_field)
}

/// The weight per nm of the Gaussian band `g` (unit mass in wavenumber).
pub fn band_weight(g: Gaussian) -> impl Fn(f64) -> f64 {
    move |lambda: f64| {
        let k = std::f64::consts::TAU / lambda;
        let z = (k - g.mu) / g.sigma;
        (-0.5 * z * z).exp() / (g.sigma * std::f64::consts::TAU.sqrt()) * std::f64::consts::TAU
            / (lambda * lambda)
    }
}

/// The wavelengths a band's quadrature covers: ±4 FWHM around its centre.
pub fn band_range(wavelength_nm: f64, fwhm_nm: f64) -> (f64, f64) {
    (wavelength_nm - 4.0 * fwhm_nm, wavelength_nm + 4.0 * fwhm_nm)
}

/// The quadrature's error about its step under the name of the field that sets it.
pub fn step_field(e: Error) -> Error {
    if e.parameter == "step_nm" {
        Error::new("spectrum.step_nm", e.message)
    } else {
        e
    }
}

/// A quadrature step resolving the fringes of up to ~10 internal round trips at the shortest
/// wavelength: `λ² / (20 · 2 n d · 10)`, at most 1 nm.
fn auto_step(q: &SlabQuery, lambda_min: f64) -> f64 {
    let n = q.slab.layer.eta_o.re.max(q.slab.layer.eta_e.re);
    let opd = 2.0 * n * q.plate.thickness_nm * 10.0;
    (lambda_min * lambda_min / (20.0 * opd)).clamp(1e-5, 1.0)
}
