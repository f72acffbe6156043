//! The one error type of the core: every invalid input is reported as a message that names the
//! offending parameter, never as a panic, a NaN or a silently clamped value.

use std::fmt;

/// What kind of failure an [`Error`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// The input is invalid or the query physically undefined: the user's to fix.
    Invalid,
    /// A defect of the core (a caught panic, a non-finite result): never the user's input alone.
    Internal,
}

/// An invalid input, a physically undefined query, or an internal defect.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    /// Invalid input or internal defect.
    pub kind: ErrorKind,
    /// The parameter at fault (e.g. `"eta_o"`, `"optic_axis"`), or the quantity that is undefined.
    pub parameter: String,
    /// What is wrong with it, in words a user can act on.
    pub message: String,
}

impl Error {
    /// An error about parameter `parameter` (an [`ErrorKind::Invalid`] input).
    pub fn new(parameter: impl Into<String>, message: impl Into<String>) -> Self {
        Error {
            kind: ErrorKind::Invalid,
            parameter: parameter.into(),
            message: message.into(),
        }
    }

    /// An [`ErrorKind::Internal`] defect; `what` names the quantity that went wrong.
    pub fn internal(what: impl Into<String>, message: impl Into<String>) -> Self {
        Error {
            kind: ErrorKind::Internal,
            parameter: what.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.parameter, self.message)
    }
}

impl std::error::Error for Error {}

/// Shorthand used across the crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Checks that `x` is finite, naming `parameter` otherwise.
pub fn finite(parameter: &str, x: f64) -> Result<f64> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(Error::new(
            parameter,
            format!("must be a finite number, got {x}"),
        ))
    }
}
