//! The admittance fast path of an interface with one isotropic side
//! (`Interface::solve` → `birefringent::optics::admittance`) against the general 4x4 boundary solve
//! (`Interface::from_modes`) it replaces, on random interfaces in both orders.
//!
//! Tolerance: `max |S_fast − S_4x4| / max |S_4x4|` (entrywise, relative to the largest entry)
//! `< TOL = 1e-13`. Both are direct solves (Gaussian elimination with partial pivoting) of the
//! same four equations, identical algebra apart from rounding, so they agree to a few ulps
//! times the conditioning of the system (observed: ~1e-15 worst). The bound leaves two orders
//! of magnitude for the amplification near the conditioning traps, which are sampled on
//! purpose and reported separately: grazing incidence on the isotropic side (`β` within 1e-5
//! relative of its index: `q → 0`, its up and down waves merge) and a crystal with
//! `η_o = η_e` to 1e-9 (its o and e modes of one direction are nearly parallel). They need no
//! looser bound: the reduction eliminates the isotropic side exactly (its s/p rows are
//! decoupled), so it adds no conditioning of its own.
//!
//! The reduction runs in real arithmetic when every field is real (lossless media, propagating
//! waves) and in complex arithmetic otherwise; both occur in every family of cases below (the
//! unit tests of `admittance` and `fields` check that the two arithmetics agree bit for bit on
//! real inputs).

use birefringent::optics::admittance;
use birefringent::optics::frame::PlaneFrame;
use birefringent::optics::interface::Interface;
use birefringent::optics::medium::Uniaxial;
use birefringent::optics::modes::modes;
use birefringent::optics::uniaxial_fresnel::UniaxialFresnel;
use birefringent::params::Thickness;
use birefringent::plate::slab::Slab;
use birefringent::C64;
use nalgebra::{Matrix4, Vector3};

mod common;
use common::Rng;

const TOL: f64 = 1e-13;

/// The relative difference measure of this file.
fn rel_diff(a: &Matrix4<C64>, b: &Matrix4<C64>) -> f64 {
    let max = b.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let diff = (a - b).iter().map(|z| z.norm()).fold(0.0, f64::max);
    diff / max
}

/// One random interface configuration.
struct Case {
    iso: Uniaxial,
    crystal: Uniaxial,
    beta: C64,
    iso_above: bool,
    /// Grazing on the isotropic side or nearly degenerate crystal (see module docs).
    trap: bool,
    kind: &'static str,
}

fn complex_index(rng: &mut Rng, absorbing: bool) -> C64 {
    let n = rng.range(1.2, 3.0);
    C64::new(n, if absorbing { rng.range(0.0, 0.5) } else { 0.0 })
}

fn random_case(rng: &mut Rng, i: usize) -> Case {
    let iso_n = if rng.chance(0.15) {
        C64::new(rng.range(1.0, 3.0), rng.range(0.0, 0.3))
    } else {
        C64::new(rng.range(1.0, 3.0), 0.0)
    };
    let absorbing = rng.chance(0.3);
    let eta_o = complex_index(rng, absorbing);
    let mut eta_e = complex_index(rng, absorbing);
    if absorbing && rng.chance(0.4) {
        // Strongly dichroic: one polarisation clear, the other strongly absorbed.
        eta_e.im = if eta_o.im > 0.25 { 0.0 } else { 0.5 };
    }
    let (axis, kind) = match i % 10 {
        0 => (
            Vector3::new(0.0, 0.0, if rng.chance(0.5) { 1.0 } else { -1.0 }),
            "axis along the normal",
        ),
        1 => {
            let phi = rng.range(0.0, std::f64::consts::TAU);
            (
                Vector3::new(phi.cos(), 0.0, phi.sin()),
                "axis in the plane of incidence",
            )
        }
        2 => (Vector3::new(0.0, 1.0, 0.0), "axis normal to the plane"),
        3 => {
            eta_e = eta_o + C64::new(rng.range(-1e-9, 1e-9), 0.0);
            (rng.unit_vector(), "eta_o == eta_e within 1e-9")
        }
        _ => (rng.unit_vector(), "random tilted axis"),
    };
    let crystal = Uniaxial::new(eta_o, eta_e, axis).unwrap();
    let iso_above = rng.chance(0.5);
    // The incident medium's index sets the range of β: from 0 through its critical angles
    // into the other medium to beyond every index (all waves evanescent) in 10% of cases.
    let n_in = if iso_above {
        iso_n.re
    } else {
        eta_o.re.max(eta_e.re)
    };
    let beta = if rng.chance(0.1) {
        n_in * rng.range(1.0, 1.3)
    } else if rng.chance(0.1) {
        iso_n.re * (1.0 - 10f64.powf(rng.range(-9.0, -2.0)))
    } else {
        n_in * rng.range(0.0, 1.0)
    };
    let beta = C64::new(beta, 0.0);
    let grazing = ((beta - iso_n).norm() / iso_n.norm()) < 1e-5;
    Case {
        iso: Uniaxial::isotropic(iso_n).unwrap(),
        crystal,
        beta,
        iso_above,
        trap: grazing || i % 10 == 3,
        kind,
    }
}

#[derive(Default)]
struct Tally {
    cases: usize,
    worst: f64,
    worst_trap: f64,
    traps: usize,
    evanescent: usize,
    /// Every field real: the reduction runs in real arithmetic.
    real: usize,
    singular_both: usize,
}

#[test]
fn admittance_path_equals_the_4x4_solve_on_random_interfaces() {
    let mut rng = Rng::new(2024);
    let mut tallies: Vec<(&'static str, bool, Tally)> = Vec::new();
    let mut worst_case = String::new();
    for i in 0..40_000 {
        let c = random_case(&mut rng, i);
        let (upper, lower) = if c.iso_above {
            (&c.iso, &c.crystal)
        } else {
            (&c.crystal, &c.iso)
        };
        let (m1, m2) = (modes(upper, c.beta), modes(lower, c.beta));
        let fast = Interface::solve(m1, m2);
        let full = Interface::from_modes(m1, m2);
        let t = match tallies
            .iter_mut()
            .position(|(k, a, _)| *k == c.kind && *a == c.iso_above)
        {
            Some(p) => &mut tallies[p].2,
            None => {
                tallies.push((c.kind, c.iso_above, Tally::default()));
                &mut tallies.last_mut().unwrap().2
            }
        };
        t.cases += 1;
        let (fast, full) = match (fast, full) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(a), Err(b)) => {
                assert_eq!(a, b);
                t.singular_both += 1;
                continue;
            }
            (a, b) => panic!(
                "one path singular, the other not: {:?} {:?} beta {} iso above {}: fast {:?} full {:?}",
                c.iso, c.crystal, c.beta, c.iso_above, a.err(), b.err()
            ),
        };
        assert_eq!((fast.upper, fast.lower), (full.upper, full.lower));
        let err = rel_diff(&fast.s, &full.s);
        let all_modes = m1.up.iter().chain(&m1.down).chain(&m2.up).chain(&m2.down);
        t.evanescent += usize::from(all_modes.clone().any(|m| m.is_evanescent()));
        t.real += usize::from(
            all_modes
                .clone()
                .all(|m| m.tangential().iter().all(|z| z.im == 0.0)),
        );
        let case = || {
            format!(
                "{:?} {:?} beta {} iso above {}",
                c.iso, c.crystal, c.beta, c.iso_above
            )
        };
        assert!(err < TOL, "{err:e}: {}", case());
        if c.trap {
            t.traps += 1;
            t.worst_trap = t.worst_trap.max(err);
        } else if err > t.worst {
            t.worst = err;
            worst_case = case();
        }
    }
    let mut total = 0;
    for (kind, above, t) in &tallies {
        total += t.cases;
        println!(
            "{kind:30} iso {:5}: {:5} cases ({:4} with an evanescent mode, {:4} all real, {:4} grazing/degenerate, {} singular in both), worst {:.2e} (grazing/degenerate {:.2e})",
            if *above { "above" } else { "below" },
            t.cases,
            t.evanescent,
            t.real,
            t.traps,
            t.singular_both,
            t.worst,
            t.worst_trap
        );
    }
    println!("worst case (outside the traps): {worst_case}");
    assert!(total >= 20_000);
    for (_, _, t) in &tallies {
        assert!(
            t.cases > 1000 && t.evanescent > 50,
            "every family must include evanescent modes"
        );
        // Both arithmetics of the reduction (real fields, complex fields) are exercised.
        assert!(
            t.real > 100 && t.cases - t.real > 100,
            "{} real of {}",
            t.real,
            t.cases
        );
    }
}

/// The closed form of an isotropic upper medium over a uniaxial one
/// (`birefringent::optics::uniaxial_fresnel`, which the crystal surface takes) against the 4x4
/// solve: every entry of `S` (from above: `r`, `t`; from below, each crystal wave: its
/// reflections and transmission), on the random interfaces above with the isotropic medium
/// above (absorbing, dichroic, evanescent, grazing, degenerate and beyond every index), to
/// `1e-12` relative to the largest entry: both are direct solves of the same equations (Cramer's
/// rule of the reduced 2x2 system against elimination with pivoting), which agree to rounding
/// times the conditioning (observed worst printed). The grazing and nearly degenerate traps
/// are included in the bound.
#[test]
fn uniaxial_closed_form_equals_the_4x4_solve_on_random_interfaces() {
    let mut rng = Rng::new(2025);
    let (mut worst, mut worst_trap, mut cases, mut singular) = (0.0f64, 0.0f64, 0, 0);
    let (mut absorbing, mut evanescent) = (0, 0);
    while cases < 30_000 {
        let c = random_case(&mut rng, cases + singular);
        if !c.iso_above {
            continue;
        }
        let (upper, lower) = (modes(&c.iso, c.beta), modes(&c.crystal, c.beta));
        let psi = |m: &birefringent::optics::modes::Mode| m.tangential();
        let closed = UniaxialFresnel::new(
            c.iso.eta_o,
            upper.up[0].q,
            [psi(&lower.down[0]), psi(&lower.down[1])],
        );
        let (closed, full) = match (closed, Interface::from_modes(upper, lower)) {
            (Some(a), Ok(b)) => (a, b),
            (None, Err(_)) => {
                singular += 1;
                continue;
            }
            (a, b) => panic!(
                "one singular: {:?} {:?} {:?}",
                c.crystal,
                a.is_some(),
                b.err()
            ),
        };
        let mut s = Matrix4::zeros();
        let (r, t) = closed.from_above();
        for i in 0..2 {
            for j in 0..2 {
                s[(i, j)] = r[i][j];
                s[(2 + i, j)] = t[i][j];
            }
        }
        for j in 0..2 {
            let (refl, trans) = closed.from_below(&psi(&lower.up[j]));
            for i in 0..2 {
                s[(i, 2 + j)] = trans[i];
                s[(2 + i, 2 + j)] = refl[i];
            }
        }
        let err = rel_diff(&s, &full.s);
        assert!(
            err < 1e-12,
            "{err:e}: {:?} {:?} beta {}",
            c.iso,
            c.crystal,
            c.beta
        );
        cases += 1;
        absorbing += usize::from(!c.crystal.is_lossless() || !c.iso.is_lossless());
        let all = upper.up.iter().chain(&lower.up).chain(&lower.down);
        evanescent += usize::from(all.clone().any(|m| m.is_evanescent()));
        if c.trap {
            worst_trap = worst_trap.max(err);
        } else {
            worst = worst.max(err);
        }
    }
    println!(
        "closed form vs 4x4: {cases} interfaces ({absorbing} absorbing, {evanescent} with an evanescent wave, {singular} singular in both): worst {worst:.2e}, grazing/degenerate {worst_trap:.2e}"
    );
    assert!(absorbing > 5000 && evanescent > 2000);
}

/// The measure above would see a coefficient of `S` perturbed by a fraction of the tolerance.
#[test]
fn the_comparison_detects_a_perturbed_coefficient() {
    let air = Uniaxial::isotropic(C64::new(1.0, 0.0)).unwrap();
    let crystal = Uniaxial::new(
        C64::new(1.658, 0.0),
        C64::new(1.486, 0.0),
        Vector3::new(0.3, 0.5, 0.8),
    )
    .unwrap();
    let beta = C64::new(0.7, 0.0);
    let (m1, m2) = (modes(&air, beta), modes(&crystal, beta));
    let full = Interface::from_modes(m1, m2).unwrap();
    for k in 0..16 {
        let mut fast = Interface::solve(m1, m2).unwrap();
        fast.s[(k / 4, k % 4)] += C64::new(0.0, 10.0 * TOL);
        assert!(rel_diff(&fast.s, &full.s) > TOL, "entry {k}");
    }
}

/// The reduction itself reports a singular system as `None` (a wave that cannot be matched).
#[test]
fn singular_reduced_system_is_none() {
    let z = C64::new(0.0, 0.0);
    let one = C64::new(1.0, 0.0);
    let s = [z, one, -one, z];
    let p = [one, z, z, -one];
    // The other medium's outgoing modes equal the isotropic outgoing ones: L = C(O) = 0.
    assert!(admittance::solve(&[s, p], &[s, p], &[s, p], &[s, p]).is_err());
}

/// The plate's interfaces (`Slab::optics`, which takes the fast path) equal the 4x4 solve.
#[test]
fn slab_interfaces_equal_the_4x4_solve() {
    let mut rng = Rng::new(7);
    let mut worst = 0.0f64;
    for _ in 0..2000 {
        let layer = Uniaxial::new(
            C64::new(rng.range(1.3, 2.5), 0.0),
            C64::new(rng.range(1.3, 2.5), 0.0),
            rng.unit_vector(),
        )
        .unwrap();
        let slab = Slab::new(
            C64::new(rng.range(1.0, 1.8), 0.0),
            layer,
            C64::new(rng.range(1.0, 1.8), 0.0),
            Thickness::from_nm(1e4).unwrap(),
        )
        .unwrap();
        let frame = PlaneFrame::from_azimuth(rng.range(0.0, std::f64::consts::TAU));
        let beta = C64::new(slab.top.eta_o.re * rng.range(0.0, 0.999), 0.0);
        let o = slab.optics(&frame, beta).unwrap();
        let top = Interface::from_modes(o.top.upper, o.top.lower).unwrap();
        let bottom = Interface::from_modes(o.bottom.upper, o.bottom.lower).unwrap();
        worst = worst
            .max(rel_diff(&o.top.s, &top.s))
            .max(rel_diff(&o.bottom.s, &bottom.s));
    }
    println!("slab interfaces: worst {worst:e}");
    assert!(worst < TOL, "{worst:e}");
}
