//! `birefringence interface`: one isotropic/uniaxial interface.

use super::input::Fields;
use super::media;
use super::output::{complex, num, wave};
use crate::error::{Error, Result};
use crate::optics::frame::PlaneFrame;
use crate::optics::modes::ModeKind;
use crate::optics::surface::{Incident, Solved, Surface};
use num_complex::Complex64 as C64;
use serde_json::{json, Map, Value};

/// Incidence read from `theta_deg` or `beta`, with `phi_deg` and `side`.
pub struct Incidence {
    /// Which wave arrives.
    pub incident: Incident,
    /// The plane of incidence.
    pub frame: PlaneFrame,
    /// Incidence parameter.
    pub beta: C64,
}

/// Reads `side`, `inside_mode`, `theta_deg`/`beta`, `phi_deg` for `surface`.
pub fn read_incidence(f: &mut Fields, surface: &Surface, allow_inside: bool) -> Result<Incidence> {
    let side = f.string("side")?.unwrap_or("outside");
    let incident = match side {
        "outside" => Incident::Outside,
        "inside" if allow_inside => Incident::Inside(read_mode(f)?),
        _ => {
            let allowed = if allow_inside {
                "\"outside\" or \"inside\""
            } else {
                "\"outside\""
            };
            return Err(Error::new(
                "side",
                format!("must be {allowed}, got \"{side}\""),
            ));
        }
    };
    if !matches!(incident, Incident::Inside(_)) && f.has("inside_mode") {
        return Err(Error::new(
            "inside_mode",
            "only applies with side = \"inside\"",
        ));
    }
    let phi = f.number("phi_deg")?.unwrap_or(0.0).to_radians();
    let frame = PlaneFrame::from_azimuth(phi);
    let beta = match (f.number("theta_deg")?, f.number("beta")?) {
        (Some(t), None) => {
            if !(0.0..90.0).contains(&t) {
                return Err(Error::new(
                    "theta_deg",
                    format!("must be in [0, 90), got {t}"),
                ));
            }
            surface.beta(incident, &frame, t.to_radians())
        }
        // From outside the incident wave must propagate: beta < ext_ior (beyond, it is
        // evanescent and carries no power to take fractions of).
        (None, Some(b))
            if matches!(incident, Incident::Outside) && b >= surface.exterior.eta_o.re =>
        {
            return Err(Error::new(
                "beta",
                format!(
                    "must be < ext_ior ({}) for light from outside, got {b}",
                    surface.exterior.eta_o.re
                ),
            ))
        }
        (None, Some(b)) if b >= 0.0 => C64::new(b, 0.0),
        (None, Some(b)) => return Err(Error::new("beta", format!("must be >= 0, got {b}"))),
        (Some(_), Some(_)) => return Err(Error::new("beta", "give theta_deg or beta, not both")),
        (None, None) => return Err(Error::new("theta_deg", "give theta_deg or beta")),
    };
    Ok(Incidence {
        incident,
        frame,
        beta,
    })
}

fn read_mode(f: &mut Fields) -> Result<ModeKind> {
    match f.string("inside_mode")? {
        Some("o") => Ok(ModeKind::O),
        Some("e") => Ok(ModeKind::E),
        Some(m) => Err(Error::new(
            "inside_mode",
            format!("must be \"o\" or \"e\", got \"{m}\""),
        )),
        None => Err(Error::new(
            "inside_mode",
            "is required with side = \"inside\"",
        )),
    }
}

/// Fields of the `interface` subcommand.
pub const FIELDS: [&str; 13] = [
    "wavelength_nm",
    "ext_ior",
    "eta_o",
    "eta_e",
    "material",
    "kappa_o",
    "kappa_e",
    "optic_axis",
    "theta_deg",
    "phi_deg",
    "beta",
    "side",
    "inside_mode",
];

/// Runs the `interface` subcommand on one input object.
pub fn run(input: &Value) -> Result<Value> {
    let mut f = Fields::new(input, &FIELDS)?;
    let m = media::read(&mut f)?;
    let surface = Surface::new(m.ext, m.crystal)?;
    let inc = read_incidence(&mut f, &surface, true)?;
    let solved = surface.solve(inc.frame, inc.beta)?;
    let mut out = match inc.incident {
        Incident::Outside => outside(&solved)?,
        Incident::Inside(kind) => inside(&solved, kind)?,
    };
    let (ko, ke) = surface.k_max(&inc.frame);
    out.insert("beta".into(), complex(inc.beta));
    out.insert("k_max".into(), json!({"o": complex(ko), "e": complex(ke)}));
    out.insert("isotropic".into(), json!(m.crystal.is_isotropic()));
    super::output::insert_warnings(&mut out, &m.warnings);
    Ok(Value::Object(out))
}

const SP: [&str; 2] = ["s", "p"];
const OE: [&str; 2] = ["o", "e"];

/// Outputs for light arriving from the exterior.
fn outside(sv: &Solved) -> Result<Map<String, Value>> {
    let i = &sv.interface;
    require_flux(i.incoming_flux()[0])?;
    let (p, r, t) = (i.power(), i.r_above(), i.t_above());
    let mut out = Map::new();
    let pair = |a: usize, b: usize| format!("{}{}", SP[a], SP[b]);
    out.insert(
        "R".into(),
        obj((0..2)
            .flat_map(|a| (0..2).map(move |b| (a, b)))
            .map(|(a, b)| (pair(a, b), num(p[(b, a)])))),
    );
    out.insert(
        "r".into(),
        obj((0..2)
            .flat_map(|a| (0..2).map(move |b| (a, b)))
            .map(|(a, b)| (pair(a, b), complex(r[(b, a)])))),
    );
    out.insert(
        "T".into(),
        obj((0..2).map(|a| {
            (
                SP[a].to_string(),
                obj((0..2).map(|b| (OE[b].to_string(), num(p[(2 + b, a)])))),
            )
        })),
    );
    out.insert(
        "t".into(),
        obj((0..2).map(|a| {
            (
                SP[a].to_string(),
                obj((0..2).map(|b| (OE[b].to_string(), complex(t[(b, a)])))),
            )
        })),
    );
    out.insert(
        "waves".into(),
        json!({
            "incident": obj((0..2).map(|a| (SP[a].to_string(), wave(sv, &i.upper.down[a])))),
            "reflected": obj((0..2).map(|a| (SP[a].to_string(), wave(sv, &i.upper.up[a])))),
            "transmitted": obj((0..2).map(|b| (OE[b].to_string(), wave(sv, &i.lower.down[b])))),
        }),
    );
    Ok(out)
}

/// Outputs for an o- or e-wave arriving from inside the crystal.
fn inside(sv: &Solved, kind: ModeKind) -> Result<Map<String, Value>> {
    let i = &sv.interface;
    let col = 2 + usize::from(kind == ModeKind::E);
    require_flux(i.incoming_flux()[col])?;
    let p = i.power();
    let mut out = Map::new();
    out.insert(
        "R".into(),
        obj((0..2).map(|b| (OE[b].to_string(), num(p[(2 + b, col)])))),
    );
    out.insert(
        "r".into(),
        obj((0..2).map(|b| (OE[b].to_string(), complex(i.s[(2 + b, col)])))),
    );
    out.insert(
        "T".into(),
        obj((0..2).map(|b| (SP[b].to_string(), num(p[(b, col)])))),
    );
    out.insert(
        "t".into(),
        obj((0..2).map(|b| (SP[b].to_string(), complex(i.s[(b, col)])))),
    );
    out.insert(
        "waves".into(),
        json!({
            "incident": wave(sv, &i.lower.up[col - 2]),
            "reflected": obj((0..2).map(|b| (OE[b].to_string(), wave(sv, &i.lower.down[b])))),
            "transmitted": obj((0..2).map(|b| (SP[b].to_string(), wave(sv, &i.upper.up[b])))),
        }),
    );
    Ok(out)
}

fn obj(it: impl Iterator<Item = (String, Value)>) -> Value {
    Value::Object(it.collect())
}

fn require_flux(flux: f64) -> Result<()> {
    if flux > 0.0 {
        Ok(())
    } else {
        Err(Error::new(
            "incidence",
            "the incident wave carries no power through the surface (grazing, or evanescent past K_max)",
        ))
    }
}
