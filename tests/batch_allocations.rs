//! The batch layer allocates nothing per lane: a batch of N lanes makes exactly the heap
//! allocations of the N scalar core queries it runs (`plate_lobes`, `crystal_slots`), counted by a
//! global allocator; the core's own per-query allocations are printed (they belong to those
//! functions, not to the bridge). Each batch runs twice, counted the second time: the first use
//! of the core initialises tables once (172 allocations measured), which is no per-lane cost.

use birefringent::ffi::bridge::{CrystalLanes, PlateCall, PlateLanes, Samples, Status, Transport};
use birefringent::ffi::{band_spectrum, new_materials, sample_crystal, sample_plate};
use birefringent::material::Material;
use birefringent::optics::medium::Uniaxial;
use birefringent::optics::surface::Surface;
use birefringent::params::Thickness;
use birefringent::render::crystal::crystal_slots;
use birefringent::render::plate::{plate_lobes, PlateQuery};
use birefringent::render::thin::Spectrum;
use birefringent::render::Transport as CoreTransport;
use birefringent::C64;
use nalgebra::Vector3;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Counts every allocation of the process (the only test of this binary: no other test allocates
/// meanwhile).
struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: forwarded to the system allocator with the caller's layout.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `alloc` above.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn counted(mut f: impl FnMut()) -> usize {
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    f();
    ALLOCATIONS.load(Ordering::Relaxed) - before
}

const N: usize = 64;

/// Directions on both sides, away from grazing.
fn directions() -> Vec<Vector3<f64>> {
    (0..N)
        .map(|i| {
            let t = 0.1 + 1.3 * (i as f64 / N as f64);
            let side = if i % 2 == 0 { 1.0 } else { -1.0 };
            Vector3::new(t.sin() * 0.6, t.sin() * 0.8, side * t.cos())
        })
        .collect()
}

/// Output columns of `N` lanes, 4 channels, full matrices.
struct Out {
    status: Vec<Status>,
    component: Vec<u32>,
    cols: Vec<Vec<f64>>,
}

impl Out {
    fn new() -> Self {
        Out {
            status: vec![Status::Ok; N],
            component: vec![0; N],
            cols: (0..5)
                .map(|_| vec![0.0; N])
                .chain((0..22).map(|_| vec![0.0; 4 * N]))
                .collect(),
        }
    }

    fn samples(&mut self) -> Samples<'_> {
        let mut c = self.cols.iter_mut().map(|v| v.as_mut_slice());
        let mut next = || c.next().unwrap();
        Samples {
            status: &mut self.status,
            component: &mut self.component,
            pdf: next(),
            eta: next(),
            wo: [next(), next(), next()],
            in_stokes_x: [next(), next(), next()],
            out_stokes_x: [next(), next(), next()],
            value: std::array::from_fn(|_| next()),
            message: String::new(),
        }
    }
}

#[test]
fn batches_allocate_only_what_the_core_queries_do() {
    let dirs = directions();
    let (x, y, z): (Vec<f64>, Vec<f64>, Vec<f64>) = (
        dirs.iter().map(|d| d.x).collect(),
        dirs.iter().map(|d| d.y).collect(),
        dirs.iter().map(|d| d.z).collect(),
    );
    let waves: [[f64; 1]; 4] = [[450.0], [500.0], [550.0], [600.0]];
    let wave_cols: Vec<&[f64]> = waves.iter().map(|w| w.as_slice()).collect();
    let mut m = new_materials();
    m.add_named("calcite", 0.0, 0.0).unwrap();
    let calcite = Material::named("calcite", 0.0, 0.0).unwrap();
    let spectrum = band_spectrum(4.0);
    let axis = Vector3::new(0.3, 0.5, 0.8);

    // The plate: a batch, then the same queries by the core API.
    let lanes = PlateLanes {
        count: N,
        active: &[1],
        material: &[0],
        transport: &[Transport::Radiance],
        sample: &[0.5],
        wi: [&x, &y, &z],
        wavelengths_nm: &wave_cols,
        ext_ior: &[1.0],
        exit_ior: &[1.0],
        optic_axis: [&[axis.x], &[axis.y], &[axis.z]],
        axis_angle_deg: &[0.0],
        thickness_nm: &[5000.0],
        birefringence: &[0.0],
    };
    let call = PlateCall {
        components: 3,
        intensity_only: false,
        absorbing_exit: false,
    };
    let mut out = Out::new();
    let mut run = || {
        let mut s = out.samples();
        assert_eq!(
            sample_plate(&m, &spectrum, &call, &lanes, &mut s),
            Status::Ok
        );
    };
    run();
    let batch = counted(run);
    let core = counted(|| {
        for d in &dirs {
            let q = PlateQuery::new(
                calcite,
                0.0,
                C64::new(1.0, 0.0),
                C64::new(1.0, 0.0),
                axis,
                Thickness::from_nm(5000.0).unwrap(),
                true,
                true,
                false,
            )
            .unwrap();
            let s = Spectrum::Bands {
                wavelengths_nm: [450.0, 500.0, 550.0, 600.0],
                count: 4,
                fwhm_nm: 4.0,
            };
            std::hint::black_box(plate_lobes(&q, &s, *d, CoreTransport::Radiance).unwrap());
        }
    });
    println!("plate: {batch} allocations for {N} lanes; the core's queries alone {core} ({:.1} per lane)", core as f64 / N as f64);
    assert_eq!(batch, core, "the batch layer allocated per lane");

    // The crystal.
    let lanes = CrystalLanes {
        count: N,
        active: &[1],
        material: &[0],
        transport: &[Transport::Importance],
        sample: &[0.5],
        wi: [&x, &y, &z],
        wavelengths_nm: &wave_cols,
        ext_ior: &[1.0],
        optic_axis: [&[axis.x], &[axis.y], &[axis.z]],
    };
    let mut out = Out::new();
    let mut run = || {
        let mut s = out.samples();
        assert_eq!(sample_crystal(&m, 7, &lanes, &mut s), Status::Ok);
    };
    run();
    let batch = counted(run);
    let core = counted(|| {
        for d in &dirs {
            for w in [450.0, 500.0, 550.0, 600.0] {
                let (eo, ee) = calcite.indices(w, 0.0).unwrap();
                let s =
                    Surface::new(C64::new(1.0, 0.0), Uniaxial::new(eo, ee, axis).unwrap()).unwrap();
                std::hint::black_box(crystal_slots(&s, *d, CoreTransport::Importance).unwrap());
            }
        }
    });
    println!("crystal: {batch} allocations for {N} lanes; the core's queries alone {core} ({:.1} per lane)", core as f64 / N as f64);
    assert_eq!(batch, core, "the batch layer allocated per lane");
}
