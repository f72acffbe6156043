//! Columns of a batch: one value per lane, or one value for every lane.

use crate::error::{Error, Result};

/// A validated input column of a batch of `count` lanes.
#[derive(Clone, Copy, Debug)]
pub struct Column<'a, T> {
    data: &'a [T],
}

impl<'a, T: Copy> Column<'a, T> {
    /// `data` as a column of `count` lanes: it must hold `count` values or one.
    #[inline]
    pub fn new(name: &str, data: &'a [T], count: usize) -> Result<Self> {
        if data.len() == count || data.len() == 1 {
            Ok(Column { data })
        } else {
            Err(column_error(name, data.len(), count))
        }
    }

    /// The value of lane `i`.
    #[inline]
    pub fn at(&self, i: usize) -> T {
        if self.data.len() == 1 {
            self.data[0]
        } else {
            self.data[i]
        }
    }
}

/// The error of an input column of `len` values for `count` lanes (out of line: the checks of
/// every call stay short).
#[cold]
#[inline(never)]
fn column_error(name: &str, len: usize, count: usize) -> Error {
    Error::new(
        name,
        format!("column of {len} values for {count} lanes (give {count} or 1)"),
    )
}

/// Three columns: a vector per lane.
#[derive(Clone, Copy, Debug)]
pub struct Columns3<'a>([Column<'a, f64>; 3]);

impl<'a> Columns3<'a> {
    /// The three columns `data` of `count` lanes.
    pub fn new(name: &str, data: &[&'a [f64]; 3], count: usize) -> Result<Self> {
        Ok(Columns3([
            Column::new(name, data[0], count)?,
            Column::new(name, data[1], count)?,
            Column::new(name, data[2], count)?,
        ]))
    }

    /// The vector of lane `i`.
    #[inline]
    pub fn at(&self, i: usize) -> nalgebra::Vector3<f64> {
        nalgebra::Vector3::new(self.0[0].at(i), self.0[1].at(i), self.0[2].at(i))
    }
}

/// An output column of `len` values, or none (an optional output not asked for).
#[inline]
pub fn check_output<T>(name: &str, data: &[T], len: usize, optional: bool) -> Result<()> {
    if data.len() == len || (optional && data.is_empty()) {
        Ok(())
    } else {
        Err(output_error(name, data.len(), len, optional))
    }
}

/// The error of [`check_output`] (out of line, as [`column_error`]).
#[cold]
#[inline(never)]
fn output_error(name: &str, found: usize, len: usize, optional: bool) -> Error {
    Error::new(
        name,
        format!(
            "output column of {found} values, {len} needed{}",
            if optional { " (or none)" } else { "" }
        ),
    )
}

/// Up to [`MAX_CHANNELS`] wavelength columns.
#[derive(Clone, Copy, Debug)]
pub struct Wavelengths<'a> {
    columns: [Option<Column<'a, f64>>; MAX_CHANNELS],
    count: usize,
}

/// Most channels of a query.
pub const MAX_CHANNELS: usize = 4;

impl<'a> Wavelengths<'a> {
    /// The wavelength columns `data` of `count` lanes.
    pub fn new(data: &[&'a [f64]], count: usize) -> Result<Self> {
        if data.len() > MAX_CHANNELS {
            return Err(Error::new(
                "wavelengths_nm",
                format!("{} columns given, at most {MAX_CHANNELS}", data.len()),
            ));
        }
        let mut columns = [None; MAX_CHANNELS];
        for (c, d) in columns.iter_mut().zip(data) {
            *c = Some(Column::new("wavelengths_nm", d, count)?);
        }
        Ok(Wavelengths {
            columns,
            count: data.len(),
        })
    }

    /// Number of columns.
    pub fn count(&self) -> usize {
        self.count
    }

    /// The wavelengths of lane `i` (0 beyond [`Wavelengths::count`]).
    #[inline]
    pub fn at(&self, i: usize) -> [f64; MAX_CHANNELS] {
        self.columns.map(|c| c.map_or(0.0, |c| c.at(i)))
    }
}
