//! Reading the calculator's JSON input: typed fields with errors that name the field.

use crate::error::{Error, Result};
use nalgebra::Vector3;
use num_complex::Complex64 as C64;
use serde_json::{Map, Value};

/// A JSON object read field by field. Unknown (e.g. misspelt) fields are rejected up front,
/// before anything else is reported, since they are usually the root cause. Errors name the
/// field as the user wrote it: `spectrum.bandwidth_nm` for a field of the nested `spectrum`.
pub struct Fields<'a> {
    map: &'a Map<String, Value>,
    /// The object's own name (`"spectrum"`), or empty for the input itself.
    prefix: &'static str,
}

impl<'a> Fields<'a> {
    /// Wraps a JSON value that must be an object with only `accepted` fields.
    pub fn new(value: &'a Value, accepted: &[&str]) -> Result<Self> {
        Fields::nested(value, accepted, "")
    }

    /// [`Fields::new`] for the object in field `prefix` of the input (empty: the input).
    pub fn nested(value: &'a Value, accepted: &[&str], prefix: &'static str) -> Result<Self> {
        let Value::Object(map) = value else {
            let what = if prefix.is_empty() { "input" } else { prefix };
            return Err(Error::new(what, "must be a JSON object"));
        };
        let fields = Fields { map, prefix };
        let mut unknown: Vec<&String> = map
            .keys()
            .filter(|k| !accepted.contains(&k.as_str()))
            .collect();
        unknown.sort();
        if let Some(k) = unknown.first() {
            // A length, wavelength or angle without its unit (`thickness` for `thickness_um`).
            let hint = accepted
                .iter()
                .find(|a| {
                    a.strip_prefix(k.as_str())
                        .is_some_and(|u| u.starts_with('_'))
                })
                .map(|a| format!("did you mean {a} (the unit is part of the name)? "))
                .unwrap_or_default();
            return Err(Error::new(
                fields.qualified(k),
                format!("unknown field ({hint}accepted: {})", accepted.join(", ")),
            ));
        }
        Ok(fields)
    }

    /// The name of field `name` as the user wrote it.
    pub fn qualified(&self, name: &str) -> String {
        if self.prefix.is_empty() {
            name.to_string()
        } else {
            format!("{}.{name}", self.prefix)
        }
    }

    /// The raw value of `name`, if present (and not null).
    pub fn get(&mut self, name: &'static str) -> Option<&'a Value> {
        self.map.get(name).filter(|v| !v.is_null())
    }

    /// True if `name` is present.
    pub fn has(&self, name: &str) -> bool {
        self.map.get(name).is_some_and(|v| !v.is_null())
    }

    /// An optional finite number.
    pub fn number(&mut self, name: &'static str) -> Result<Option<f64>> {
        let full = self.qualified(name);
        self.get(name).map(|v| number(&full, v)).transpose()
    }

    /// A required finite number.
    pub fn required_number(&mut self, name: &'static str) -> Result<f64> {
        self.number(name)?
            .ok_or_else(|| Error::new(self.qualified(name), "is required"))
    }

    /// An optional complex number: a number or `[re, im]`.
    pub fn complex(&mut self, name: &'static str) -> Result<Option<C64>> {
        let full = self.qualified(name);
        self.get(name).map(|v| complex(&full, v)).transpose()
    }

    /// An optional string.
    pub fn string(&mut self, name: &'static str) -> Result<Option<&'a str>> {
        let full = self.qualified(name);
        self.get(name)
            .map(|v| {
                v.as_str()
                    .ok_or_else(|| Error::new(full, "must be a string"))
            })
            .transpose()
    }

    /// An optional 3-vector `[x, y, z]`.
    pub fn vector3(&mut self, name: &'static str) -> Result<Option<Vector3<f64>>> {
        let full = self.qualified(name);
        self.get(name).map(|v| vector3(&full, v)).transpose()
    }
}

/// A finite JSON number.
pub fn number(name: &str, v: &Value) -> Result<f64> {
    let x = v
        .as_f64()
        .ok_or_else(|| Error::new(name, format!("must be a number, got {v}")))?;
    crate::error::finite(name, x)
}

/// A number or `[re, im]`.
pub fn complex(name: &str, v: &Value) -> Result<C64> {
    match v {
        Value::Array(a) if a.len() == 2 => Ok(C64::new(number(name, &a[0])?, number(name, &a[1])?)),
        Value::Number(_) => Ok(C64::new(number(name, v)?, 0.0)),
        _ => Err(Error::new(
            name,
            format!("must be a number or [re, im], got {v}"),
        )),
    }
}

/// `[x, y, z]` of finite numbers.
pub fn vector3(name: &str, v: &Value) -> Result<Vector3<f64>> {
    match v {
        Value::Array(a) if a.len() == 3 => Ok(Vector3::new(
            number(name, &a[0])?,
            number(name, &a[1])?,
            number(name, &a[2])?,
        )),
        _ => Err(Error::new(name, format!("must be [x, y, z], got {v}"))),
    }
}
