//! Fuzz target: every entry point of the C ABI (cpp/include/birefringent.h, src/ffi.rs), called
//! exactly as the C++ shim calls them, with arguments decoded from the fuzzer's bytes: hostile
//! doubles everywhere (NaN, ±inf, huge, tiny, negative), non-unit and non-finite directions,
//! arbitrary transport modes and flag bits, null pointers for every pointer argument, material
//! names of arbitrary bytes (non-UTF-8, unknown, empty, very long), and message buffers of every
//! length from 0 up (the buffer is a heap allocation of exactly `message_len` bytes, so a write
//! past it is caught under AddressSanitizer, `FUZZ_ASAN=1`).
//!
//! Contract asserted (a violation aborts, and libFuzzer keeps the input):
//! - no panic (libfuzzer-sys turns any panic, even one the ABI would catch, into an abort) and
//!   no status other than BFR_OK / BFR_INVALID / BFR_INTERNAL; BFR_INTERNAL (documented as a
//!   bug, but a clean error) goes to `birefringent_fuzz::soft_finding` (a crash with
//!   FUZZ_STRICT=1, else kept and counted);
//! - on BFR_INVALID: a non-empty, NUL-terminated message within the buffer, "parameter: what";
//! - on BFR_OK: every lobe finite, `exists` 0 or 1, unused lobes all zero, `weight` = M00 >= 0,
//!   (except sRGB channels, whose weights are negative in places), unit `wo`, components in
//!   range, intensity-only queries leave M[1..] zero;
//! - soft (a `soft_finding`: kept and listed, a crash only with FUZZ_STRICT=1): no BFR_INTERNAL,
//!   and in Importance mode (power fractions of the incident power) every crystal lobe <= 1
//!   and the plate's R + T <= 1 through a Gaussian band (inside a strongly absorbing crystal
//!   the incident and reflected waves exchange power through their interference term, so a
//!   per-wave ratio above 1 is not necessarily wrong there, which is why it is soft);
//! - the same call twice gives bitwise the same output (no hidden state).
#![no_main]

use birefringent::ffi::*;
use birefringent_fuzz::Bytes;
use libfuzzer_sys::fuzz_target;
use std::os::raw::c_char;
use std::ptr;

/// Names the core knows (with aliases and case/space variants) and near misses.
const NAMES: [&[u8]; 14] = [
    b"calcite",
    b"quartz",
    b"Crystalline Quartz",
    b"sapphire",
    b"rutile",
    b"mgf2",
    b"lithium niobate",
    b"bbo",
    b"kdp",
    b"",
    b" calcite ",
    b"calcite\xff",
    b"\xc3\xa9",
    b"unobtainium",
];

/// A message buffer of exactly `len` bytes (`None`: a null pointer with a hostile length).
struct Message {
    buf: Option<Vec<u8>>,
    len: usize,
}

impl Message {
    fn new(b: &mut Bytes) -> Self {
        match b.u8() % 8 {
            0 => Message {
                buf: None,
                len: b.u32() as usize,
            },
            1 => Message {
                buf: Some(Vec::new()),
                len: 0,
            },
            k => {
                let len = if k == 2 {
                    b.u16() as usize % 4096
                } else {
                    b.u8() as usize
                };
                // 0xAA: not NUL, so a missing terminator is seen.
                Message {
                    buf: Some(vec![0xAA; len]),
                    len,
                }
            }
        }
    }

    fn ptr(&mut self) -> *mut c_char {
        match &mut self.buf {
            None => ptr::null_mut(),
            Some(v) if v.is_empty() => ptr::NonNull::<c_char>::dangling().as_ptr(),
            Some(v) => v.as_mut_ptr() as *mut c_char,
        }
    }

    /// The contract on the message after a call that returned `rc`.
    fn check(&self, rc: i32) {
        let Some(v) = &self.buf else { return };
        if rc == BFR_OK {
            return;
        }
        if v.is_empty() {
            return;
        }
        let end = v
            .iter()
            .position(|&c| c == 0)
            .expect("message not NUL-terminated");
        if v.len() >= 2 {
            assert!(end > 0, "empty error message");
        }
        // "parameter: what" unless truncated before the colon.
        if end == v.len() - 1 && end < 40 {
            return;
        }
        let text = String::from_utf8_lossy(&v[..end]);
        assert!(
            text.contains(": "),
            "message does not name a parameter: {text:?}"
        );
    }
}

fn desc(b: &mut Bytes, name_buf: &mut Vec<u8>) -> BfrMaterialDesc {
    let material = match b.u8() % 4 {
        0 | 1 => ptr::null(),
        2 => {
            name_buf.clear();
            name_buf.extend_from_slice(NAMES[b.u8() as usize % NAMES.len()]);
            name_buf.push(0);
            name_buf.as_ptr() as *const c_char
        }
        _ => {
            // Arbitrary bytes (up to 255, or a long run), NUL-terminated.
            name_buf.clear();
            let raw = b.bytes(255);
            name_buf.extend(raw.into_iter().filter(|&c| c != 0));
            if b.u8() == 0xFF {
                name_buf.extend(std::iter::repeat_n(b'x', 100_000));
            }
            name_buf.push(0);
            name_buf.as_ptr() as *const c_char
        }
    };
    BfrMaterialDesc {
        material,
        eta_o: BfrComplex {
            re: b.f64(),
            im: b.f64(),
        },
        eta_e: BfrComplex {
            re: b.f64(),
            im: b.f64(),
        },
        kappa_o: b.f64(),
        kappa_e: b.f64(),
    }
}

fn geometry(b: &mut Bytes) -> BfrGeometry {
    BfrGeometry {
        ext_ior: b.f64(),
        exit_ior: b.f64(),
        optic_axis: b.direction(),
        thickness_nm: b.f64(),
        birefringence: b.f64(),
    }
}

fn is_zero(l: &BfrPathLobe) -> bool {
    l.exists == 0
        && l.component == 0
        && l.wo
            .iter()
            .chain(&l.in_stokes_x)
            .chain(&l.out_stokes_x)
            .chain(&l.mueller)
            .chain([&l.weight, &l.eta])
            .all(|x| x.to_bits() == 0)
}

fn bits(lobes: &[BfrPathLobe]) -> Vec<u64> {
    lobes
        .iter()
        .flat_map(|l| {
            [l.exists as u64, l.component as u64]
                .into_iter()
                .chain(l.wo.iter().map(|x| x.to_bits()))
                .chain(l.in_stokes_x.iter().map(|x| x.to_bits()))
                .chain(l.out_stokes_x.iter().map(|x| x.to_bits()))
                .chain(l.mueller.iter().map(|x| x.to_bits()))
                .chain([l.weight.to_bits(), l.eta.to_bits()])
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The contract on the lobes of a successful query.
fn check_lobes(
    lobes: &[BfrPathLobe],
    max_component: i32,
    intensity_only: bool,
    rgb: bool,
    args: &str,
) {
    for l in lobes {
        assert!(l.exists == 0 || l.exists == 1, "exists = {}", l.exists);
        if l.exists == 0 {
            assert!(is_zero(l), "unused lobe not zeroed: {l:?}");
            continue;
        }
        let all =
            l.wo.iter()
                .chain(&l.in_stokes_x)
                .chain(&l.out_stokes_x)
                .chain(&l.mueller)
                .chain([&l.weight, &l.eta]);
        for x in all {
            assert!(x.is_finite(), "non-finite number in {l:?} for {args}");
        }
        assert!((0..=max_component).contains(&l.component), "{l:?}");
        assert_eq!(l.weight.to_bits(), l.mueller[0].to_bits(), "weight != M00");
        // A linear sRGB channel weight is negative over part of the spectrum, so an RGB channel
        // of a non-flat spectrum may be < 0 (or > 1): no sign check there.
        assert!(rgb || l.weight >= 0.0, "negative weight {l:?} for {args}");
        let n = l.wo.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!(
            (n - 1.0).abs() < 1e-9,
            "wo not unit ({n}): {l:?} for {args}"
        );
        if intensity_only {
            assert!(l.mueller[1..].iter().all(|&x| x == 0.0), "{l:?}");
        }
    }
}

/// What a successful call must satisfy (see the contract at the top).
impl Expect {
    /// A plate entry point writing `n_out` lobes (components 0 and 1).
    fn plate(n_out: usize, intensity_only: bool, rgb: bool, importance_plate: bool) -> Self {
        Expect {
            n_out,
            max_component: 1,
            intensity_only,
            rgb,
            importance_plate,
            crystal_importance: false,
        }
    }
}

struct Expect {
    /// Lobes the call writes to `out`.
    n_out: usize,
    max_component: i32,
    intensity_only: bool,
    /// sRGB channels: a weight may be negative.
    rgb: bool,
    /// The plate through a Gaussian band in Importance mode: R + T <= 1 (soft).
    importance_plate: bool,
    /// The crystal in Importance mode: every lobe <= 1 (soft).
    crystal_importance: bool,
}

/// The message check, the status check and the repeat check around one call writing `out`.
fn call(
    b: &mut Bytes,
    args: &str,
    e: Expect,
    f: impl Fn(*mut BfrPathLobe, *mut c_char, usize) -> i32,
) {
    let n_out = e.n_out;
    if std::env::var_os("FUZZ_PRINT").is_some() {
        // Replaying one input (`FUZZ_PRINT=1 c_abi FILE`): say what is called.
        eprintln!("call with {args}");
    }
    let null_out = b.u8() == 0;
    let mut msg = Message::new(b);
    let mut out = vec![BfrPathLobe::default(); n_out];
    let out_ptr = |o: &mut Vec<BfrPathLobe>| {
        if null_out {
            ptr::null_mut()
        } else {
            o.as_mut_ptr()
        }
    };
    let p = out_ptr(&mut out);
    let rc = f(p, msg.ptr(), msg.len);
    assert!(
        rc == BFR_OK || rc == BFR_INVALID || rc == BFR_INTERNAL,
        "status {rc}"
    );
    if rc == BFR_INTERNAL {
        let mut full = vec![0u8; 1024];
        f(p, full.as_mut_ptr() as *mut c_char, full.len());
        let end = full.iter().position(|&c| c == 0).unwrap_or(0);
        birefringent_fuzz::soft_finding(&format!(
            "status {rc} ({}) for {args}",
            String::from_utf8_lossy(&full[..end])
        ));
        msg.check(rc);
        return;
    }
    msg.check(rc);
    if rc != BFR_OK {
        return;
    }
    assert!(!null_out, "a null output pointer was accepted");
    check_lobes(&out, e.max_component, e.intensity_only, e.rgb, args);
    if e.crystal_importance {
        // Each lobe is a power fraction of the incident power (of one incident mode inside).
        for l in &out {
            if l.weight > 1.0 + 1e-9 {
                birefringent_fuzz::soft_finding(&format!(
                    "lobe weight {} > 1: {l:?} for {args}",
                    l.weight
                ));
            }
        }
    }
    if e.importance_plate {
        // Power fractions of the incident power through a Gaussian band (a positive weight):
        // no gain.
        for pair in out.chunks(2) {
            let sum = pair[0].weight + pair[1].weight;
            if sum > 1.0 + 1e-9 {
                birefringent_fuzz::soft_finding(&format!("R + T = {sum} > 1: {pair:?} for {args}"));
            }
        }
    }
    let mut again = vec![BfrPathLobe::default(); n_out];
    let mut msg2 = Message { buf: None, len: 0 };
    let rc2 = f(again.as_mut_ptr(), msg2.ptr(), 0);
    assert_eq!(rc2, BFR_OK, "second call differs");
    assert!(bits(&out) == bits(&again), "second call differs for {args}");
}

fuzz_target!(|data: &[u8]| {
    birefringent_fuzz::set_input(data);
    let mut b = Bytes::new(data);
    let entry = b.u8() % 7;
    if entry == 5 {
        // SAFETY: no arguments; a static NUL-terminated string.
        let v = unsafe { std::ffi::CStr::from_ptr(bfr_version()) };
        assert!(!v.to_bytes().is_empty());
        return;
    }
    let mut name_buf = Vec::new();
    let d = desc(&mut b, &mut name_buf);
    let null_desc = b.u8() == 0;
    let mut msg = Message::new(&mut b);
    let dp: *const BfrMaterialDesc = if null_desc { ptr::null() } else { &d };
    // SAFETY: every pointer is null or valid for what the header says; the message buffer has
    // exactly msg.len bytes (or is null).
    let m = unsafe { bfr_material_new(dp, msg.ptr(), msg.len) };
    if m.is_null() {
        msg.check(BFR_INVALID);
        return;
    }
    assert!(!null_desc, "material from a null descriptor");
    let null_material = b.u8() == 0;
    let mp: *const BfrMaterial = if null_material { ptr::null() } else { m };
    let g = geometry(&mut b);
    let gp: *const BfrGeometry = if b.u8() == 0 { ptr::null() } else { &g };
    let wi = b.direction();
    let wp: *const f64 = if b.u8() == 0 {
        ptr::null()
    } else {
        wi.as_ptr()
    };
    let transport = match b.u8() % 4 {
        0 => BFR_RADIANCE,
        1 => BFR_IMPORTANCE,
        _ => b.i32(),
    };
    let flags = match b.u8() % 4 {
        0 => b.i32(),
        _ => (b.u8() % 16) as i32,
    };
    let importance = transport == BFR_IMPORTANCE;
    let name = if d.material.is_null() {
        None
    } else {
        Some(String::from_utf8_lossy(&name_buf[..name_buf.len() - 1]).into_owned())
    };
    let args = |extra: String| {
        format!(
            "material {name:?}, desc {d:?}, material null {null_material}, geometry {:?}, \
             wi {:?}, transport {transport}, flags {flags}, {extra}",
            (!gp.is_null()).then_some(g),
            (!wp.is_null()).then_some(wi),
        )
    };
    let intensity_only = flags & BFR_INTENSITY_ONLY != 0;
    match entry {
        0 => {}
        1 => {
            let lambda = b.f64();
            let (mut o, mut e) = (BfrComplex::default(), BfrComplex::default());
            let po: *mut BfrComplex = if b.u8() == 0 { ptr::null_mut() } else { &mut o };
            let pe: *mut BfrComplex = if b.u8() == 0 { ptr::null_mut() } else { &mut e };
            // SAFETY: null or valid pointers.
            let rc = unsafe { bfr_material_indices(mp, lambda, po, pe) };
            assert!(
                rc == BFR_OK || rc == BFR_INVALID || rc == BFR_INTERNAL,
                "status {rc}"
            );
            if rc == BFR_INTERNAL {
                birefringent_fuzz::soft_finding(&format!("indices at {lambda} nm: internal"));
            }
            if rc == BFR_OK {
                for x in [o.re, o.im, e.re, e.im] {
                    assert!(
                        x.is_finite(),
                        "non-finite index at {lambda} nm: {o:?} {e:?}"
                    );
                }
                assert!(o.im >= 0.0 && e.im >= 0.0, "gain medium: {o:?} {e:?}");
            }
        }
        2 => {
            let lambda = b.f64();
            call(
                &mut b,
                &args(format!("wavelength {lambda}")),
                Expect {
                    n_out: BFR_CRYSTAL_LOBES,
                    max_component: 2,
                    intensity_only: false,
                    rgb: false,
                    importance_plate: false,
                    crystal_importance: importance,
                },
                |out, mp_, ml| {
                    // SAFETY: out holds BFR_CRYSTAL_LOBES lobes or is null; other pointers as above.
                    unsafe { bfr_crystal_lobes(mp, gp, lambda, wp, transport, out, mp_, ml) }
                },
            );
        }
        3 => {
            let (lambda, fwhm) = (b.f64(), b.f64());
            let a = args(format!("wavelength {lambda}, fwhm {fwhm}"));
            call(
                &mut b,
                &a,
                Expect::plate(2, intensity_only, false, importance),
                |out, mp_, ml| {
                    // SAFETY: out holds 2 lobes or is null.
                    unsafe {
                        bfr_plate_lobes(mp, gp, lambda, fwhm, wp, transport, flags, out, mp_, ml)
                    }
                },
            );
        }
        6 => {
            // Several wavelengths at once: counts 0..=6 (0, 5 and 6 must be refused), a null
            // wavelength array now and then.
            let count = (b.u8() % 7) as usize;
            let fwhm = b.f64();
            let waves: Vec<f64> = (0..count.max(1)).map(|_| b.f64()).collect();
            let wv = if b.u8() == 0 {
                ptr::null()
            } else {
                waves.as_ptr()
            };
            let a = args(format!(
                "wavelengths {waves:?} (count {count}), fwhm {fwhm}"
            ));
            call(
                &mut b,
                &a,
                Expect::plate(2 * count.max(1), intensity_only, false, importance),
                |out, mp_, ml| {
                    // SAFETY: out holds 2 x max(count, 1) lobes or is null; wv holds
                    // max(count, 1) values or is null.
                    unsafe {
                        bfr_plate_lobes_n(
                            mp, gp, wv, count, fwhm, wp, transport, flags, out, mp_, ml,
                        )
                    }
                },
            );
        }
        _ => {
            call(
                &mut b,
                &args("sRGB channels".into()),
                Expect::plate(6, intensity_only, true, false),
                |out, mp_, ml| {
                    // SAFETY: out holds 3 x 2 lobes or is null.
                    unsafe { bfr_plate_lobes_rgb(mp, gp, wp, transport, flags, out, mp_, ml) }
                },
            );
        }
    }
    // SAFETY: m came from bfr_material_new and is not used afterwards.
    unsafe { bfr_material_free(m) };
    // Null is ignored.
    unsafe { bfr_material_free(ptr::null_mut()) };
});
