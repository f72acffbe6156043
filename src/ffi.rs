//! The C ABI of the static library, for the C++ shim. Declared in `cpp/include/birefringent.h`
//! (kept by hand; `tests/c_abi.rs` compiles and runs a C program against it).
//!
//! Rules: plain `#[repr(C)]` structs and one opaque handle; every function returns a status
//! code and never unwinds (panics are caught); invalid input gives `BFR_INVALID` and a message
//! naming the parameter; a non-finite result is reported as `BFR_INTERNAL`, never returned.

use crate::error::{Error, Result};
use crate::material::{check_kappa, Material, RENDER_RANGE_NM};
use crate::optics::medium::Uniaxial;
use crate::optics::surface::Surface;
use crate::params::{Length, Thickness};
use crate::render::crystal::crystal_lobes;
use crate::render::plate::{plate_lobes, PlateQuery, Spectrum, MAX_BANDS};
use crate::render::{PathLobe, Transport};
use crate::spectral::weights::WeightSet;
use crate::C64;
use nalgebra::Vector3;
use std::ffi::CStr;
use std::os::raw::c_char;

/// Success.
pub const BFR_OK: i32 = 0;
/// Invalid input; the message names the parameter.
pub const BFR_INVALID: i32 = 1;
/// A bug (a caught panic or a non-finite result).
pub const BFR_INTERNAL: i32 = 2;
/// Plate flag: compute reflection.
pub const BFR_WANT_REFLECTION: i32 = 1;
/// Plate flag: compute transmission.
pub const BFR_WANT_TRANSMISSION: i32 = 2;
/// Plate flag: intensity only.
pub const BFR_INTENSITY_ONLY: i32 = 4;
/// Plate flag: the exit medium absorbs what enters it (no transmission, no light from below).
pub const BFR_ABSORBING_EXIT: i32 = 8;
/// Mitsuba's `TransportMode::Radiance`.
pub const BFR_RADIANCE: i32 = 0;
/// Mitsuba's `TransportMode::Importance`.
pub const BFR_IMPORTANCE: i32 = 1;
/// Lobes of a bulk crystal query.
pub const BFR_CRYSTAL_LOBES: usize = 6;

/// `re + i im`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct BfrComplex {
    pub re: f64,
    pub im: f64,
}

/// Principal indices of a material.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct BfrMaterialDesc {
    pub material: *const c_char,
    pub eta_o: BfrComplex,
    pub eta_e: BfrComplex,
    pub kappa_o: f64,
    pub kappa_e: f64,
}

/// Opaque material handle.
pub struct BfrMaterial(Material);

/// Per-query geometry.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct BfrGeometry {
    pub ext_ior: f64,
    pub exit_ior: f64,
    pub optic_axis: [f64; 3],
    pub thickness_nm: f64,
    pub birefringence: f64,
}

/// One lobe as a path tracer samples it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct BfrPathLobe {
    pub exists: i32,
    pub component: i32,
    pub wo: [f64; 3],
    pub in_stokes_x: [f64; 3],
    pub out_stokes_x: [f64; 3],
    pub mueller: [f64; 16],
    pub weight: f64,
    pub eta: f64,
}

fn c64(c: BfrComplex) -> C64 {
    C64::new(c.re, c.im)
}

fn a3(v: Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

fn lobe(l: &PathLobe) -> BfrPathLobe {
    BfrPathLobe {
        exists: 1,
        component: l.component as i32,
        wo: a3(l.wo),
        in_stokes_x: a3(l.in_stokes_x),
        out_stokes_x: a3(l.out_stokes_x),
        mueller: std::array::from_fn(|k| l.mueller[(k / 4, k % 4)]),
        weight: l.weight,
        eta: l.eta,
    }
}

/// True if every number of a lobe is finite: `Σ 0·x` is 0 exactly when every `x` is finite
/// (NaN otherwise); a branch-free sum the compiler vectorises, on every query's hot path.
fn finite(l: &BfrPathLobe) -> bool {
    let zero_sum = |xs: &[f64]| xs.iter().fold(0.0, |acc, x| acc + 0.0 * x);
    let total = zero_sum(&l.wo)
        + zero_sum(&l.in_stokes_x)
        + zero_sum(&l.out_stokes_x)
        + zero_sum(&l.mueller)
        + zero_sum(&[l.weight, l.eta]);
    total == 0.0
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

/// Runs `f` with panics caught, mapping the outcome to a status code and a message.
unsafe fn guarded(message: *mut c_char, len: usize, f: impl FnOnce() -> Result<()>) -> i32 {
    let (code, msg) = match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(Ok(())) => return BFR_OK,
        Ok(Err(e)) if e.parameter == "internal" => (BFR_INTERNAL, e.to_string()),
        Ok(Err(e)) => (BFR_INVALID, e.to_string()),
        Err(_) => (BFR_INTERNAL, "internal error (panic caught)".to_string()),
    };
    // SAFETY: message validity is the caller's contract.
    unsafe { write_message(&msg, message, len) };
    code
}

fn null(name: &str) -> Error {
    Error::new(name, "null pointer")
}

fn material_from(desc: &BfrMaterialDesc) -> Result<Material> {
    if desc.material.is_null() {
        check_kappa("kappa_o", desc.kappa_o)?;
        check_kappa("kappa_e", desc.kappa_e)?;
        let eo = c64(desc.eta_o) + C64::new(0.0, desc.kappa_o);
        let ee = c64(desc.eta_e) + C64::new(0.0, desc.kappa_e);
        return Material::constant(eo, ee);
    }
    // SAFETY: a non-null `material` is a NUL-terminated string by the caller's contract.
    let name = unsafe { CStr::from_ptr(desc.material) }
        .to_str()
        .map_err(|_| Error::new("material", "is not valid UTF-8"))?;
    Material::named(name, desc.kappa_o, desc.kappa_e)
}

/// Creates a material handle, or returns null and writes a message. On success the message
/// is the warning of [`Material::coverage`] over [`RENDER_RANGE_NM`] (the wavelengths the
/// plugins evaluate: a named crystal whose data do not reach them), empty if none.
///
/// # Safety
/// `desc` must be null or valid; `message` null or `message_len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn bfr_material_new(
    desc: *const BfrMaterialDesc,
    message: *mut c_char,
    message_len: usize,
) -> *mut BfrMaterial {
    let mut out = std::ptr::null_mut();
    let mut warning = String::new();
    // SAFETY: pointer contracts above.
    let rc = unsafe {
        guarded(message, message_len, || {
            let d = desc.as_ref().ok_or_else(|| null("desc"))?;
            let m = material_from(d)?;
            warning = m
                .coverage(RENDER_RANGE_NM.0, RENDER_RANGE_NM.1)?
                .unwrap_or_default();
            out = Box::into_raw(Box::new(BfrMaterial(m)));
            Ok(())
        })
    };
    if rc == BFR_OK {
        // SAFETY: message validity is the caller's contract.
        unsafe { write_message(&warning, message, message_len) };
    }
    out
}

/// Frees a material handle (null is ignored).
///
/// # Safety
/// `m` must come from `bfr_material_new` and not be used afterwards.
#[no_mangle]
pub unsafe extern "C" fn bfr_material_free(m: *mut BfrMaterial) {
    if !m.is_null() {
        // SAFETY: created by Box::into_raw in bfr_material_new.
        drop(unsafe { Box::from_raw(m) });
    }
}

/// Indices at a wavelength.
///
/// # Safety
/// Valid pointers (outputs writable).
#[no_mangle]
pub unsafe extern "C" fn bfr_material_indices(
    m: *const BfrMaterial,
    wavelength_nm: f64,
    eta_o: *mut BfrComplex,
    eta_e: *mut BfrComplex,
) -> i32 {
    // SAFETY: pointer contracts above.
    unsafe {
        guarded(std::ptr::null_mut(), 0, || {
            let m = m.as_ref().ok_or_else(|| null("material"))?;
            let (o, e) = m.0.indices(wavelength_nm, 0.0)?;
            let (po, pe) = (
                eta_o.as_mut().ok_or_else(|| null("eta_o"))?,
                eta_e.as_mut().ok_or_else(|| null("eta_e"))?,
            );
            *po = BfrComplex { re: o.re, im: o.im };
            *pe = BfrComplex { re: e.re, im: e.im };
            Ok(())
        })
    }
}

fn vec3(p: *const f64, name: &str) -> Result<Vector3<f64>> {
    if p.is_null() {
        return Err(null(name));
    }
    // SAFETY: non-null pointer to 3 doubles by the caller's contract.
    let a = unsafe { std::slice::from_raw_parts(p, 3) };
    Ok(Vector3::new(a[0], a[1], a[2]))
}

fn transport(t: i32) -> Result<Transport> {
    match t {
        BFR_RADIANCE => Ok(Transport::Radiance),
        BFR_IMPORTANCE => Ok(Transport::Importance),
        _ => Err(Error::new(
            "transport",
            "must be BFR_RADIANCE (0) or BFR_IMPORTANCE (1)",
        )),
    }
}

/// Copies lobes into `out[..n]` (unused entries zeroed), refusing non-finite numbers.
fn emit(lobes: &[PathLobe], out: &mut [BfrPathLobe]) -> Result<()> {
    out.iter_mut().for_each(|o| *o = BfrPathLobe::default());
    if lobes.len() > out.len() {
        return Err(Error::new("internal", "more lobes than the output holds"));
    }
    for (o, l) in out.iter_mut().zip(lobes) {
        *o = checked(l)?;
    }
    Ok(())
}

/// The C form of a lobe, refusing non-finite numbers (never handed to the renderer).
fn checked(l: &PathLobe) -> Result<BfrPathLobe> {
    let o = lobe(l);
    if finite(&o) {
        Ok(o)
    } else {
        Err(Error::new(
            "internal",
            "non-finite result (a bug: please report the input)",
        ))
    }
}

/// Bulk crystal lobes seen from `wi`.
///
/// # Safety
/// Valid pointers; `out` holds `BFR_CRYSTAL_LOBES` entries; `message` null or writable.
#[no_mangle]
pub unsafe extern "C" fn bfr_crystal_lobes(
    m: *const BfrMaterial,
    g: *const BfrGeometry,
    wavelength_nm: f64,
    wi: *const f64,
    transport_mode: i32,
    out: *mut BfrPathLobe,
    message: *mut c_char,
    message_len: usize,
) -> i32 {
    // SAFETY: pointer contracts above.
    unsafe {
        guarded(message, message_len, || {
            let (m, g) = (
                m.as_ref().ok_or_else(|| null("material"))?,
                g.as_ref().ok_or_else(|| null("geometry"))?,
            );
            if out.is_null() {
                return Err(null("out"));
            }
            let out = std::slice::from_raw_parts_mut(out, BFR_CRYSTAL_LOBES);
            let (eo, ee) = m.0.indices(wavelength_nm, g.birefringence)?;
            let axis = Vector3::from(g.optic_axis);
            let s = Surface::new(C64::new(g.ext_ior, 0.0), Uniaxial::new(eo, ee, axis)?)?;
            let lobes = crystal_lobes(&s, vec3(wi, "wi")?, transport(transport_mode)?)?;
            emit(&lobes, out)
        })
    }
}

fn plate_query(m: &Material, g: &BfrGeometry, flags: i32) -> Result<PlateQuery> {
    let known =
        BFR_WANT_REFLECTION | BFR_WANT_TRANSMISSION | BFR_INTENSITY_ONLY | BFR_ABSORBING_EXIT;
    if flags & !known != 0 {
        return Err(Error::new("flags", format!("unknown bits in {flags}")));
    }
    Ok(PlateQuery::new(
        *m,
        g.birefringence,
        C64::new(g.ext_ior, 0.0),
        C64::new(g.exit_ior, 0.0),
        Vector3::from(g.optic_axis),
        Thickness::new("thickness", g.thickness_nm, Length::Micrometres)?,
        flags & BFR_WANT_REFLECTION != 0,
        flags & BFR_WANT_TRANSMISSION != 0,
        flags & BFR_INTENSITY_ONLY != 0,
    )?
    .with_absorbing_exit(flags & BFR_ABSORBING_EXIT != 0))
}

/// The shared body of the plate entry points: validates the pointers, evaluates the plate over
/// `spectrum` and writes one `[reflection, transmission]` pair per channel into `out`.
///
/// # Safety
/// As for the entry points; `out` holds `2 × channels` entries.
#[allow(clippy::too_many_arguments)]
unsafe fn plate_entry(
    m: *const BfrMaterial,
    g: *const BfrGeometry,
    spectrum: Spectrum,
    channels: usize,
    wi: *const f64,
    transport_mode: i32,
    flags: i32,
    out: *mut BfrPathLobe,
    message: *mut c_char,
    message_len: usize,
) -> i32 {
    // SAFETY: pointer contracts of the entry points.
    unsafe {
        guarded(message, message_len, || {
            let (m, g) = (
                m.as_ref().ok_or_else(|| null("material"))?,
                g.as_ref().ok_or_else(|| null("geometry"))?,
            );
            if out.is_null() {
                return Err(null("out"));
            }
            let out = std::slice::from_raw_parts_mut(out, 2 * channels);
            let q = plate_query(&m.0, g, flags)?;
            let lobes = plate_lobes(&q, &spectrum, vec3(wi, "wi")?, transport(transport_mode)?)?;
            for (c, l) in lobes.iter().enumerate().take(channels) {
                emit_plate(l, &mut out[2 * c..2 * c + 2])?;
            }
            Ok(())
        })
    }
}

/// Plate lobes at one wavelength (exact or band-filtered).
///
/// # Safety
/// Valid pointers; `out` holds 2 entries; `message` null or writable.
#[no_mangle]
pub unsafe extern "C" fn bfr_plate_lobes(
    m: *const BfrMaterial,
    g: *const BfrGeometry,
    wavelength_nm: f64,
    fwhm_nm: f64,
    wi: *const f64,
    transport_mode: i32,
    flags: i32,
    out: *mut BfrPathLobe,
    message: *mut c_char,
    message_len: usize,
) -> i32 {
    let spectrum = Spectrum::Band {
        wavelength_nm,
        fwhm_nm,
    };
    // SAFETY: the caller's contract is plate_entry's with one channel.
    unsafe {
        plate_entry(
            m,
            g,
            spectrum,
            1,
            wi,
            transport_mode,
            flags,
            out,
            message,
            message_len,
        )
    }
}

/// Plate lobes at up to [`MAX_BANDS`] wavelengths at once (each exact or band-filtered, as
/// [`bfr_plate_lobes`]): `out[2 i..2 i + 2]` for `wavelengths_nm[i]`.
///
/// # Safety
/// Valid pointers; `wavelengths_nm` holds `count` values and `out` `2 × count` entries;
/// `message` null or writable.
#[no_mangle]
pub unsafe extern "C" fn bfr_plate_lobes_n(
    m: *const BfrMaterial,
    g: *const BfrGeometry,
    wavelengths_nm: *const f64,
    count: usize,
    fwhm_nm: f64,
    wi: *const f64,
    transport_mode: i32,
    flags: i32,
    out: *mut BfrPathLobe,
    message: *mut c_char,
    message_len: usize,
) -> i32 {
    // SAFETY: the caller's contract; the count is checked before anything is read.
    unsafe {
        let mut spectrum = None;
        let rc = guarded(message, message_len, || {
            if wavelengths_nm.is_null() {
                return Err(null("wavelengths_nm"));
            }
            if !(1..=MAX_BANDS).contains(&count) {
                return Err(Error::new(
                    "count",
                    format!("must be 1 to {MAX_BANDS} wavelengths, got {count}"),
                ));
            }
            let mut w = [0.0; MAX_BANDS];
            w[..count].copy_from_slice(std::slice::from_raw_parts(wavelengths_nm, count));
            spectrum = Some(Spectrum::Bands {
                wavelengths_nm: w,
                count,
                fwhm_nm,
            });
            Ok(())
        });
        match spectrum {
            Some(spectrum) => plate_entry(
                m,
                g,
                spectrum,
                count,
                wi,
                transport_mode,
                flags,
                out,
                message,
                message_len,
            ),
            None => rc,
        }
    }
}

/// Writes `[reflection, transmission]` into `out[0..2]`.
fn emit_plate(lobes: &[Option<PathLobe>; 2], out: &mut [BfrPathLobe]) -> Result<()> {
    for (o, l) in out.iter_mut().zip(lobes) {
        *o = match l {
            Some(l) => checked(l)?,
            None => BfrPathLobe::default(),
        };
    }
    Ok(())
}

/// Plate lobes integrated over the linear sRGB (D65) channels.
///
/// # Safety
/// Valid pointers; `out` holds 3 × 2 entries; `message` null or writable.
#[no_mangle]
pub unsafe extern "C" fn bfr_plate_lobes_rgb(
    m: *const BfrMaterial,
    g: *const BfrGeometry,
    wi: *const f64,
    transport_mode: i32,
    flags: i32,
    out: *mut BfrPathLobe,
    message: *mut c_char,
    message_len: usize,
) -> i32 {
    let spectrum = Spectrum::Weights(WeightSet::SrgbD65);
    // SAFETY: the caller's contract is plate_entry's with three channels.
    unsafe {
        plate_entry(
            m,
            g,
            spectrum,
            3,
            wi,
            transport_mode,
            flags,
            out,
            message,
            message_len,
        )
    }
}

/// The library's version string (static, NUL-terminated).
#[no_mangle]
pub extern "C" fn bfr_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr() as *const c_char
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `finite` rejects a NaN or an infinity in any field (each position tried) and accepts
    /// large, tiny and negative finite values.
    #[test]
    fn finite_checks_every_number() {
        let good = BfrPathLobe {
            exists: 1,
            component: 0,
            wo: [0.0, -1e300, 1e-300],
            in_stokes_x: [1.0, 0.0, -0.0],
            out_stokes_x: [f64::MAX, f64::MIN, 0.5],
            mueller: [2.0; 16],
            weight: f64::MIN_POSITIVE,
            eta: 1.5,
        };
        assert!(finite(&good));
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for k in 0..27 {
                let mut l = good;
                match k {
                    0..=2 => l.wo[k] = bad,
                    3..=5 => l.in_stokes_x[k - 3] = bad,
                    6..=8 => l.out_stokes_x[k - 6] = bad,
                    9..=24 => l.mueller[k - 9] = bad,
                    25 => l.weight = bad,
                    _ => l.eta = bad,
                }
                assert!(!finite(&l), "{bad} at {k} accepted");
            }
        }
    }
}
