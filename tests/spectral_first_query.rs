//! The first analytic query of a process pays only for what it reads (issue 30, item 4): the
//! tables every later query shares (the fringe rules' rows, the Chebyshev rules and their error
//! bounds, the layouts of path classes) are built where a query first needs them, each row or
//! rung at a time, and cheaply (the fringe rows from Chebyshev series, no division), or read from
//! tables computed ahead (the weights' moments, the Chebyshev rules' error bounds and the rules
//! from 256 points: `src/quadrature/chebyshev_tables.bin`). Measured by the bytes the first
//! query allocates, in a fresh process per named
//! crystal and case (a child process of this test: the tables are per process), which bounds what
//! it built (instruction counts, `valgrind --tool=callgrind`, are in the closing note of issue 30:
//! a first query then cost 13-350 ms).

use birefringent::colour::weights::WeightSet;
use birefringent::material::crystals::crystal_names;
use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::plate::slab::{Output, Want};
use birefringent::plate::Plate;
use birefringent::quadrature::Accuracy;
use birefringent::spectral::model::{PlateModel, ThinModel};
use birefringent::C64;
use nalgebra::Vector3;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Counts the bytes every allocation of the process asks for.
struct Counting;

static BYTES: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        BYTES.fetch_add(layout.size(), Ordering::Relaxed);
        System.alloc(layout)
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// The cases of the calculator's distribution (0-60 degrees, 0.5-1000 um) that build the most:
/// a thin plate on the dense rule, a thick one with chirped path classes, a millimetre plate.
const CASES: [(f64, f64); 4] = [(3.0, 60.0), (20.0, 30.0), (130.0, 60.0), (1000.0, 45.0)];

/// Most bytes a first query may allocate (temporaries included): the largest measured, 4.6 MB
/// (rutile 130 um at 60 degrees: the Chebyshev rules of its chirped groups and their node bases,
/// the layouts of its path classes, the fringe rows it reads; 5.9 MB while the rules' error
/// tables were built on first use), with a margin for other compilers' choices. The eager tables
/// before allocated up to 30.6 MB on the same cases (rutile 130 um at 60 degrees; 10-25 MB for
/// calcite and lithium niobate).
const BOUND: usize = 6_000_000;

/// The child: one first query, its bytes on stdout.
fn first_query(name: &str, case: usize) -> usize {
    let (d, theta) = CASES[case];
    let plate = Plate {
        material: Material::named(name, 0.0, 0.0).unwrap(),
        birefringence: 0.0,
        ext: C64::new(1.0, 0.0),
        exit: C64::new(1.0, 0.0),
        axis: Vector3::new(0.3, 0.5, 0.8).normalize(),
        thickness_nm: d * 1e3,
    };
    let frame = PlaneFrame::from_azimuth(0.7);
    let beta = C64::new(theta.to_radians().sin(), 0.0);
    let before = BYTES.load(Ordering::Relaxed);
    let m = PlateModel::new(&plate, frame, beta)
        .channels(
            WeightSet::XyzD65,
            Want::BOTH,
            Output::Mueller,
            Accuracy::Perceptual,
        )
        .unwrap();
    assert!(m.iter().all(|m| m.t.unwrap()[(0, 0)].is_finite()));
    BYTES.load(Ordering::Relaxed) - before
}

#[test]
fn first_query_builds_only_what_it_reads() {
    if let Ok(job) = std::env::var("FIRST_QUERY_CHILD") {
        let (name, case) = job.split_once(':').unwrap();
        println!("BYTES {}", first_query(name, case.parse().unwrap()));
        return;
    }
    let exe = std::env::current_exe().unwrap();
    let mut worst = (0, String::new());
    for name in crystal_names() {
        for (case, geometry) in CASES.iter().enumerate() {
            let job = format!("{name}:{case}");
            let out = std::process::Command::new(&exe)
                .args([
                    "first_query_builds_only_what_it_reads",
                    "--exact",
                    "--nocapture",
                ])
                .env("FIRST_QUERY_CHILD", &job)
                .output()
                .unwrap();
            let text = String::from_utf8_lossy(&out.stdout);
            let bytes: usize = text
                .lines()
                .find_map(|l| l.strip_prefix("BYTES "))
                .unwrap_or_else(|| panic!("{job}: {text}"))
                .trim()
                .parse()
                .unwrap();
            println!("{job} ({geometry:?}): {bytes} bytes");
            if bytes > worst.0 {
                worst = (bytes, job);
            }
        }
    }
    println!("largest first query: {} bytes ({})", worst.0, worst.1);
    assert!(worst.0 <= BOUND, "{worst:?} > {BOUND}");
}
