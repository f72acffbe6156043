//! Reading the calculator's JSON input: typed fields with errors that name the field.

use crate::error::{Error, Result};
use nalgebra::Vector3;
use num_complex::Complex64 as C64;
use serde_json::{Map, Value};

/// A JSON object read field by field. Unknown (e.g. misspelt) fields are rejected up front,
/// before anything else is reported, since they are usually the root cause.
pub struct Fields<'a> {
    map: &'a Map<String, Value>,
}

impl<'a> Fields<'a> {
    /// Wraps a JSON value that must be an object with only `accepted` fields.
    pub fn new(value: &'a Value, accepted: &[&str]) -> Result<Self> {
        let Value::Object(map) = value else {
            return Err(Error::new("input", "must be a JSON object"));
        };
        let mut unknown: Vec<&String> = map
            .keys()
            .filter(|k| !accepted.contains(&k.as_str()))
            .collect();
        unknown.sort();
        if let Some(k) = unknown.first() {
            return Err(Error::new(
                k.as_str(),
                format!("unknown field (accepted: {})", accepted.join(", ")),
            ));
        }
        Ok(Fields { map })
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
        self.get(name).map(|v| number(name, v)).transpose()
    }

    /// A required finite number.
    pub fn required_number(&mut self, name: &'static str) -> Result<f64> {
        self.number(name)?
            .ok_or_else(|| Error::new(name, "is required"))
    }

    /// An optional complex number: a number or `[re, im]`.
    pub fn complex(&mut self, name: &'static str) -> Result<Option<C64>> {
        self.get(name).map(|v| complex(name, v)).transpose()
    }

    /// An optional string.
    pub fn string(&mut self, name: &'static str) -> Result<Option<&'a str>> {
        self.get(name)
            .map(|v| {
                v.as_str()
                    .ok_or_else(|| Error::new(name, "must be a string"))
            })
            .transpose()
    }

    /// An optional 3-vector `[x, y, z]`.
    pub fn vector3(&mut self, name: &'static str) -> Result<Option<Vector3<f64>>> {
        self.get(name).map(|v| vector3(name, v)).transpose()
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
