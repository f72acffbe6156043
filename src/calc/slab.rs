//! `birefringence slab`: a plane-parallel uniaxial plate.

use super::input::Fields;
use super::interface::read_incidence;
use super::media;
use super::output::{complex, num};
use crate::error::{Error, Result};
use crate::optics::surface::Surface;
use crate::params::{Length, Thickness};
use crate::plate::slab::{Slab, SlabJones, Want};
use crate::plate::Plate;
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;
use serde_json::{json, Map, Value};

/// A parsed slab query.
pub struct SlabQuery {
    /// The slab at `wavelength_nm`.
    pub slab: Slab,
    /// The same plate with its (possibly dispersive) material.
    pub plate: Plate,
    /// Vacuum wavelength (nm).
    pub wavelength_nm: f64,
    /// Plane of incidence.
    pub frame: crate::optics::frame::PlaneFrame,
    /// Incidence parameter.
    pub beta: C64,
    /// Warnings for the output (see [`media::Media::warnings`]).
    pub warnings: Vec<String>,
}

/// Reads the slab fields (everything but `spectrum`).
pub fn read(f: &mut Fields) -> Result<SlabQuery> {
    let m = media::read(f)?;
    let thickness = Thickness::new(
        "thickness_um",
        f.required_number("thickness_um")? * 1e3,
        Length::Micrometres,
    )?;
    let exit = media::read_ior(f, "exit_ior")?.unwrap_or(m.ext);
    let surface = Surface::new(m.ext, m.crystal)?;
    let inc = read_incidence(f, &surface, false)?;
    let slab = Slab::new(m.ext, m.crystal, exit, thickness)?;
    Ok(SlabQuery {
        plate: Plate {
            material: m.material,
            birefringence: 0.0,
            ext: m.ext,
            exit,
            axis: m.crystal.axis,
            thickness_nm: slab.thickness_nm,
        },
        slab,
        wavelength_nm: m.wavelength_nm,
        frame: inc.frame,
        beta: inc.beta,
        warnings: m.warnings,
    })
}

/// The accepted fields of `slab`.
pub fn slab_fields() -> Vec<&'static str> {
    super::interface::FIELDS
        .iter()
        .filter(|f| **f != "inside_mode")
        .chain(&["thickness_um", "exit_ior", "spectrum"])
        .copied()
        .collect()
}

/// The `slab` subcommand without a `spectrum`: the slab at exactly `wavelength_nm`.
pub fn run_monochromatic(input: &Value, fields: &[&str]) -> Result<Value> {
    let mut f = Fields::new(input, fields)?;
    let q = read(&mut f)?;
    let optics = q.slab.optics(&q.frame, q.beta)?;
    let j = optics.jones(q.wavelength_nm, Want::BOTH)?;
    monochromatic_output("slab", "plate", &j, q.beta, &q.warnings)
}

/// The output of `slab` (or `stack`, `subcommand`) at one wavelength from the element's Jones
/// matrices `j`: powers, Jones and Mueller matrices of both lobes, the incidence parameter and
/// the warnings; refused if the element (`what`) would create energy.
pub(super) fn monochromatic_output(
    subcommand: &str,
    what: &str,
    j: &SlabJones,
    beta: C64,
    warnings: &[String],
) -> Result<Value> {
    let (r, t) = (j.r.unwrap_or_default(), j.t.unwrap_or_default());
    check_passive(subcommand, what, &r, &t)?;
    let mut out = Map::new();
    out.insert("R".into(), powers(&r));
    out.insert("T".into(), powers(&t));
    out.insert("jones".into(), json!({"R": jones(&r), "T": jones(&t)}));
    let (mr, mt) = (
        crate::optics::mueller::from_jones(&r),
        crate::optics::mueller::from_jones(&t),
    );
    out.insert(
        "mueller".into(),
        json!({"R": matrix(&mr), "T": matrix(&mt)}),
    );
    out.insert("beta".into(), complex(beta));
    super::output::insert_warnings(&mut out, warnings);
    Ok(Value::Object(out))
}

const SP: [&str; 2] = ["s", "p"];

/// Largest excess over 1 of the reflected plus transmitted power fractions of one input
/// polarisation accepted as rounding: at 89.999 degrees with index contrasts of several hundred
/// the boundary systems are conditioned ~1e9-1e10 (worst seen 7.3e-7, a zero-thickness
/// absorbing layer under an exterior of index 595).
const PASSIVE_SLACK: f64 = 1e-6;

/// A plate or stack (`what`, errors under `parameter`) is passive (`κ ≥ 0`): for each input
/// polarisation it reflects and transmits at most the incident power. Where the computation gains energy beyond rounding, the result is
/// refused rather than returned: the known case is a weakly birefringent plate in which the o
/// and e waves are both near grazing (an exterior denser than the plate, β close to both
/// indices), where the modes' basis is ill-conditioned (docs/physics.md, §4, Known
/// limitations).
pub(super) fn check_passive(
    parameter: &str,
    what: &str,
    r: &Matrix2<C64>,
    t: &Matrix2<C64>,
) -> Result<()> {
    for (a, input) in SP.iter().enumerate() {
        let total: f64 = (0..2)
            .map(|b| r[(b, a)].norm_sqr() + t[(b, a)].norm_sqr())
            .sum();
        if total > 1.0 + PASSIVE_SLACK {
            return Err(Error::new(
                parameter,
                format!(
                    "the computed {what} reflects and transmits {total:.7} of the incident {input} \
                     power (more than it receives): its o and e waves are near grazing and nearly \
                     degenerate at this incidence, where the method is ill-conditioned; change \
                     the incidence or the indices slightly"
                ),
            ));
        }
    }
    Ok(())
}

/// `{"ss", "sp", "ps", "pp"}`: input polarisation first, output second.
pub fn powers(j: &Matrix2<C64>) -> Value {
    let mut m = Map::new();
    for (a, ia) in SP.iter().enumerate() {
        for (b, ob) in SP.iter().enumerate() {
            m.insert(format!("{ia}{ob}"), num(j[(b, a)].norm_sqr()));
        }
    }
    Value::Object(m)
}

/// Rows = output (s, p), columns = input (s, p), entries `[re, im]`.
pub(super) fn jones(j: &Matrix2<C64>) -> Value {
    json!((0..2)
        .map(|r| (0..2).map(|c| complex(j[(r, c)])).collect::<Vec<_>>())
        .collect::<Vec<_>>())
}

/// Row-major 4x4.
pub fn matrix(m: &Matrix4<f64>) -> Value {
    json!((0..4)
        .map(|r| (0..4).map(|c| num(m[(r, c)])).collect::<Vec<_>>())
        .collect::<Vec<_>>())
}
