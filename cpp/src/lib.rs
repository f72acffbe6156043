//! The plugin library's C entry points, called by the Python package (`ctypes`): registration
//! of the Mitsuba plugins (the C++ shim of this crate), the version, the supported variants and
//! the colour matrix of a channel render.
//! Everything else the shim needs from the core goes through the core's bridge.

use std::ffi::{c_char, CStr};
use std::sync::OnceLock;

// The shim calls the core's bridge: link it.
use birefringent as _;

#[cxx::bridge(namespace = "bfr")]
mod shim {
    unsafe extern "C++" {
        include!("register.h");

        /// Registers the three plugins with Mitsuba's PluginManager.
        fn register_plugins() -> Result<()>;

        /// The variants the plugins work in, comma-separated.
        fn supported_variants() -> &'static str;
    }
}

/// Writes `msg` into the caller's buffer (NUL-terminated, truncated to fit).
///
/// # Safety
/// `buf` is null or points to `len` writable bytes.
unsafe fn write_message(msg: &str, buf: *mut c_char, len: usize) {
    if buf.is_null() || len == 0 {
        return;
    }
    let n = msg.len().min(len - 1);
    // SAFETY: the caller guarantees `buf` points to `len` writable bytes.
    unsafe {
        std::ptr::copy_nonoverlapping(msg.as_ptr() as *const c_char, buf, n);
        *buf.add(n) = 0;
    }
}

/// Registers `thinbirefringent` and `birefringent` (again: a new registration replaces the
/// old). Returns 0, or 1 with a message in `message` (`message_len` bytes).
///
/// # Safety
/// `message` is null or points to `message_len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn bfr_mitsuba_register(message: *mut c_char, message_len: usize) -> i32 {
    let outcome = std::panic::catch_unwind(shim::register_plugins);
    let text = match outcome {
        Ok(Ok(())) => return 0,
        Ok(Err(e)) => e.what().to_string(),
        Err(_) => "internal error (panic caught) while registering the plugins".to_string(),
    };
    // SAFETY: the caller's contract.
    unsafe { write_message(&text, message, message_len) };
    1
}

/// A static NUL-terminated copy of `text`.
fn c_string(cell: &'static OnceLock<Vec<u8>>, text: impl FnOnce() -> String) -> *const c_char {
    let bytes = cell.get_or_init(|| {
        let mut v = text().into_bytes();
        v.retain(|&b| b != 0);
        v.push(0);
        v
    });
    CStr::from_bytes_with_nul(bytes).map_or(std::ptr::null(), CStr::as_ptr)
}

/// The core's version (static, NUL-terminated).
#[no_mangle]
pub extern "C" fn bfr_mitsuba_version() -> *const c_char {
    static CELL: OnceLock<Vec<u8>> = OnceLock::new();
    c_string(&CELL, || birefringent::ffi::version().to_string())
}

/// The variants the plugins work in, comma-separated (static, NUL-terminated).
#[no_mangle]
pub extern "C" fn bfr_mitsuba_variants() -> *const c_char {
    static CELL: OnceLock<Vec<u8>> = OnceLock::new();
    c_string(&CELL, || shim::supported_variants().to_string())
}

/// Writes into `out` (9 doubles, row-major) the matrix from the normalised channel values of
/// the weight set named `weights` (NUL-terminated: `srgb-d65`, `xyz-d65`, `xyz-e`) to linear
/// sRGB (the core's `channels_to_linear_srgb`). Returns 0, or 1 with a message in `message`.
///
/// # Safety
/// `weights` is a NUL-terminated string, `out` points to 9 writable doubles, `message` is null
/// or points to `message_len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn bfr_mitsuba_channel_matrix(
    weights: *const c_char,
    out: *mut f64,
    message: *mut c_char,
    message_len: usize,
) -> i32 {
    let outcome = std::panic::catch_unwind(|| {
        // SAFETY: the caller's contract.
        let name = unsafe { CStr::from_ptr(weights) }
            .to_str()
            .map_err(|_| "weights: not UTF-8".to_string())?;
        birefringent::ffi::channels_to_linear_srgb(name).map_err(|e| e.to_string())
    });
    let text = match outcome {
        Ok(Ok(m)) => {
            // SAFETY: the caller's contract.
            unsafe { std::ptr::copy_nonoverlapping(m.as_ptr(), out, 9) };
            return 0;
        }
        Ok(Err(e)) => e,
        Err(_) => "internal error (panic caught) in the colour matrix".to_string(),
    };
    // SAFETY: the caller's contract.
    unsafe { write_message(&text, message, message_len) };
    1
}
