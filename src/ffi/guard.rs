//! Panics never cross the bridge, and every failure becomes a [`Status`] with a message.

use super::bridge::Status;
use crate::error::{Error, ErrorKind, Result};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The status of an error's kind.
pub fn status(e: &Error) -> Status {
    match e.kind {
        ErrorKind::Invalid => Status::Invalid,
        ErrorKind::Internal => Status::Internal,
    }
}

/// Runs `f`, turning a panic into an internal error.
pub fn guarded<T>(f: impl FnOnce() -> Result<T>) -> Result<T> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|_| Err(panicked()))
}

/// The error of a caught panic.
pub fn panicked() -> Error {
    Error::internal(
        "internal",
        "internal error (panic caught; a bug: please report the input)",
    )
}

/// The error of a non-finite result, never handed to the renderer.
pub fn non_finite() -> Error {
    Error::internal(
        "internal",
        "non-finite result (a bug: please report the input)",
    )
}
