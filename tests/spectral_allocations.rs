//! The per-query path of the channel integration allocates nothing once its tables exist (issue
//! 20, item 2): every route (the whole plate, families of orders, path classes with chirped
//! groups, the dense rule) is queried twice per plate, and the second query is counted by a
//! global allocator. The first query of a plate builds what is shared by all queries (rules,
//! layouts, per-thread working memory), which is no per-query cost.

use birefringent::colour::weights::WeightSet;
use birefringent::material::Material;
use birefringent::optics::frame::PlaneFrame;
use birefringent::plate::slab::{Output, Want};
use birefringent::plate::Plate;
use birefringent::quadrature::Accuracy;
use birefringent::spectral::model::{PlateModel, ThinModel};
use birefringent::spectral::route::{self, Route};
use birefringent::spectral::survey::Survey;
use birefringent::C64;
use nalgebra::Vector3;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Counts every allocation of the process (the only test of this binary).
struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.alloc(layout)
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn plate(name: &str, thickness_um: f64, axis: Vector3<f64>) -> Plate {
    Plate {
        material: Material::named(name, 0.0, 0.0).unwrap(),
        birefringence: 0.0,
        ext: C64::new(1.0, 0.0),
        exit: C64::new(1.0, 0.0),
        axis: axis.normalize(),
        thickness_nm: thickness_um * 1e3,
    }
}

fn route_name(r: Route) -> &'static str {
    match r {
        Route::Envelope(e) if e.families.is_none() => "whole",
        Route::Envelope(_) => "families",
        Route::Classes(_) => "classes",
        Route::Dense(_) => "dense",
        Route::Pointwise(_) => "pointwise",
        Route::Gaussians => "gaussians",
    }
}

#[test]
fn channel_queries_allocate_nothing_per_query() {
    let cases = [
        (plate("quartz", 0.0, Vector3::new(1.0, 1.0, 0.0)), 30.0f64),
        (plate("quartz", 5.0, Vector3::new(1.0, 1.0, 0.0)), 45.0),
        (plate("quartz", 20.0, Vector3::new(1.0, 1.0, 0.0)), 0.0),
        (plate("calcite", 150.0, Vector3::new(1.0, 0.3, 0.2)), 80.0),
        (
            plate("rutile", 39.99, Vector3::new(-0.964, 0.178, 0.198)),
            55.9,
        ),
        (plate("rutile", 1.3, Vector3::new(1.0, 0.2, 0.5)), 63.0),
    ];
    let mut seen = Vec::new();
    for (p, theta) in cases.iter() {
        let theta: f64 = *theta;
        let frame = PlaneFrame::from_azimuth(0.5);
        let beta = C64::new(theta.to_radians().sin(), 0.0);
        let name = route_name(route::channels(
            &Survey::new(p, frame, beta).unwrap(),
            WeightSet::SrgbD65,
            Accuracy::Perceptual,
        ));
        seen.push(name);
        let query = || {
            std::hint::black_box(
                PlateModel::new(p, frame, beta)
                    .channels(
                        WeightSet::SrgbD65,
                        Want::BOTH,
                        Output::Mueller,
                        Accuracy::Perceptual,
                    )
                    .unwrap(),
            );
        };
        query();
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        query();
        let count = ALLOCATIONS.load(Ordering::Relaxed) - before;
        println!("{name:>9}: {} allocations per query", count);
        assert_eq!(count, 0, "{name}: {count} allocations per query");
    }
    for r in ["whole", "families", "classes", "dense"] {
        assert!(seen.contains(&r), "no case takes the {r} route: {seen:?}");
    }
}
