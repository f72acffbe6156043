//! The C ABI of the static library, for the C++ shim. Declared in `cpp/include/birefringent.h`
//! (kept by hand; `tests/c_abi.rs` compiles and runs a C program against it).
//!
//! Rules: plain `#[repr(C)]` structs, every function returns a status code and never unwinds
//! (panics are caught), invalid input gives `BFR_INVALID` and a message naming the parameter.

use crate::lobes::{scatter, Lobe};
use crate::medium::Uniaxial;
use crate::modes::ModeKind;
use crate::surface::{Incident, Surface};
use crate::{Error, C64};
use nalgebra::Vector3;
use std::os::raw::c_char;

/// Success.
pub const BFR_OK: i32 = 0;
/// Invalid input; the message says which parameter.
pub const BFR_INVALID: i32 = 1;
/// A bug (a caught panic or a non-finite result); the message says so.
pub const BFR_INTERNAL: i32 = 2;

/// A complex number `re + i im` (core convention: absorbing indices have `im >= 0`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct BfrComplex {
    pub re: f64,
    pub im: f64,
}

/// A crystal surface under an isotropic exterior, at one wavelength.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct BfrSurface {
    pub ext_ior: BfrComplex,
    pub eta_o: BfrComplex,
    pub eta_e: BfrComplex,
    /// Optic axis in the local shading frame (any non-zero length).
    pub optic_axis: [f64; 3],
}

/// One outgoing wave (see `crate::lobes`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct BfrLobe {
    /// 1 if the wave exists and carries power away from the surface, else 0.
    pub exists: i32,
    /// 0: exterior (or isotropic-crystal) s/p wave, 2: o-wave, 3: e-wave.
    pub kind: i32,
    /// Unit ray direction, local frame, pointing away from the surface.
    pub direction: [f64; 3],
    /// `x` axis of its Stokes frame (`y = direction × x`).
    pub stokes_x: [f64; 3],
    /// Mueller matrix, row-major, Mitsuba's convention: incident Stokes (frame
    /// `BfrEvent::incident_stokes_x`) → this wave's Stokes, power fractions.
    pub mueller: [f64; 16],
}

/// All lobes of a surface event.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct BfrEvent {
    /// `x` axis of the incident wave's Stokes frame (its propagation is `−towards_light`).
    pub incident_stokes_x: [f64; 3],
    /// Outside incidence: `[exterior, none]`; inside: `[o, e]`.
    pub reflected: [BfrLobe; 2],
    /// Outside incidence: `[o, e]`; inside: `[exterior, none]`.
    pub transmitted: [BfrLobe; 2],
}

fn complex(c: BfrComplex) -> C64 {
    C64::new(c.re, c.im)
}

fn v3(v: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

fn a3(v: Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

fn lobe(l: &Option<Lobe>) -> BfrLobe {
    match l {
        None => BfrLobe::default(),
        Some(l) => BfrLobe {
            exists: 1,
            kind: match l.kind {
                ModeKind::O => 2,
                ModeKind::E => 3,
                _ => 0,
            },
            direction: a3(l.direction),
            stokes_x: a3(l.stokes_x),
            mueller: std::array::from_fn(|k| l.mueller[(k / 4, k % 4)]),
        },
    }
}

/// Writes `msg` into the caller's buffer (NUL-terminated, truncated to fit).
unsafe fn write_message(msg: &str, buf: *mut c_char, len: usize) {
    if buf.is_null() || len == 0 {
        return;
    }
    let bytes = msg.as_bytes();
    let n = bytes.len().min(len - 1);
    // SAFETY: the caller guarantees `buf` points to `len` writable bytes.
    unsafe {
        std::ptr::copy_nonoverlapping(bytes.as_ptr() as *const c_char, buf, n);
        *buf.add(n) = 0;
    }
}

fn event(surface: &BfrSurface, towards_light: &[f64; 3], incident: i32) -> Result<BfrEvent, Error> {
    let crystal = Uniaxial::new(
        complex(surface.eta_o),
        complex(surface.eta_e),
        v3(&surface.optic_axis),
    )?;
    let s = Surface::new(complex(surface.ext_ior), crystal)?;
    let incident = match incident {
        0 => Incident::Outside,
        1 => Incident::Inside(ModeKind::O),
        2 => Incident::Inside(ModeKind::E),
        _ => {
            return Err(Error::new(
                "incident",
                "must be 0 (outside), 1 (o inside) or 2 (e inside)",
            ))
        }
    };
    let e = scatter(&s, v3(towards_light), incident)?;
    let out = BfrEvent {
        incident_stokes_x: a3(e.incident_stokes_x),
        reflected: [lobe(&e.reflected[0]), lobe(&e.reflected[1])],
        transmitted: [lobe(&e.transmitted[0]), lobe(&e.transmitted[1])],
    };
    let finite = out.reflected.iter().chain(out.transmitted.iter()).all(|l| {
        l.mueller
            .iter()
            .chain(l.direction.iter())
            .all(|x| x.is_finite())
    });
    if finite {
        Ok(out)
    } else {
        Err(Error::new(
            "internal",
            "non-finite result (a bug: please report the input)",
        ))
    }
}

/// Scatters light arriving at a crystal surface from `towards_light` (unit, local frame).
/// `incident`: 0 = from the exterior (`z > 0`), 1 = an o-wave from inside, 2 = an e-wave from
/// inside (`z < 0`; for inside waves `towards_light` is minus the ray direction).
/// Returns `BFR_OK` and fills `out`, or an error code and a message in `message`.
///
/// # Safety
/// `surface`, `towards_light` (3 doubles) and `out` must be valid pointers; `message` must be
/// null or point to `message_len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn bfr_surface_scatter(
    surface: *const BfrSurface,
    towards_light: *const f64,
    incident: i32,
    out: *mut BfrEvent,
    message: *mut c_char,
    message_len: usize,
) -> i32 {
    if surface.is_null() || towards_light.is_null() || out.is_null() {
        // SAFETY: message validity is the caller's contract.
        unsafe { write_message("null pointer argument", message, message_len) };
        return BFR_INVALID;
    }
    // SAFETY: non-null pointers to valid memory by the caller's contract.
    let (s, w) = unsafe { (*surface, *(towards_light as *const [f64; 3])) };
    let result = std::panic::catch_unwind(|| event(&s, &w, incident));
    let (code, msg) = match result {
        Ok(Ok(e)) => {
            // SAFETY: `out` is valid by the caller's contract.
            unsafe { *out = e };
            return BFR_OK;
        }
        Ok(Err(e)) if e.parameter == "internal" => (BFR_INTERNAL, e.to_string()),
        Ok(Err(e)) => (BFR_INVALID, e.to_string()),
        Err(_) => (BFR_INTERNAL, "internal error (panic caught)".to_string()),
    };
    // SAFETY: as above.
    unsafe { write_message(&msg, message, message_len) };
    code
}

/// The library's version string (static, NUL-terminated).
#[no_mangle]
pub extern "C" fn bfr_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr() as *const c_char
}
