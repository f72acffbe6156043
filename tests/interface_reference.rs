//! Compares the crate's closed-form interface solution (`birefringent::optics::interface`) with the
//! independent Berreman 4x4 reference in `common::berreman`, on many random configurations,
//! and tests the reference's plate solver on its own.
//!
//! Mode bases differ between the two methods (normalisation and phase are conventions), so
//! only basis-independent quantities are compared: the normal wave-vector components `q`, the
//! outgoing field vectors `(E, H)` (amplitude × mode field) produced by each of the crate's
//! incoming modes, and the power ratios. Run with `--nocapture` to see the statistics.

mod common;

use birefringent::optics::{interface::Interface, medium::Uniaxial, modes::Mode};
use birefringent::C64;
use common::berreman::{self, Waves};
use common::Rng;
use nalgebra::{Matrix3, Vector3, Vector4};

/// Tolerance on `q` (relative to `max(1, |q|)`).
const Q_TOL: f64 = 1e-10;
/// Tolerance on outgoing field vectors, relative to `max(|incident|, |all outgoing|)` (6-vector
/// Hermitian norms). Normally the incident field is the larger; for evanescent incidence near
/// a pole of the scattering matrix (a guided/surface resonance) the outgoing amplitudes can
/// exceed it many times, and the rounding errors of both calculations scale with them. The
/// worst error relative to the incident field alone is printed too.
const FIELD_TOL: f64 = 1e-9;
/// Tolerance on power ratios (relative to `max(1, P)`).
const POWER_TOL: f64 = 1e-9;
/// Relative `|q_0 − q_1|` below which a crate pair is compared by its summed field (the split
/// of a nearly degenerate pair into two modes is ill-conditioned / basis dependent).
const PAIR_SUM_TOL: f64 = 1e-4;
/// Relative incoming flux (`|P| / (|E| |H|)`) below which power ratios are not compared (the
/// crate's ratios are then quotients of rounding noise, e.g. evanescent incident waves).
const FLUX_FLOOR: f64 = 1e-6;

/// Relative incoming flux above which the plain [`POWER_TOL`] applies (`½ cos θ` for an
/// isotropic medium: `f_rel = 3e-3` is about 0.35° from grazing).
const GRAZING_F_REL: f64 = 3e-3;

/// Tolerance on a power ratio for an incoming wave of relative flux `f_rel`.
///
/// Near grazing incidence (`q → 0`: the incident medium's critical angle) the Berreman
/// formulation itself is ill-conditioned: `Δ` contains `β² − ε`, which loses accuracy by
/// cancellation, and the up and down modes approach a Jordan block, so the reference's mode
/// fields carry an error `~ ε_mach / q`; the tiny incident flux (`∝ q`) then turns it into a
/// power-ratio error `~ ε_mach / q²`. (The crate's closed form uses `(η − β)(η + β)` and does
/// not suffer from this.) The tolerance is widened accordingly, `1e-14 / f_rel²`, only where
/// that exceeds [`POWER_TOL`], i.e. within ~0.35° of grazing.
fn power_tol(f_rel: f64) -> f64 {
    POWER_TOL.max(1e-14 / (f_rel * f_rel))
}

fn c(re: f64, im: f64) -> C64 {
    C64::new(re, im)
}

fn norm6(v: &[C64; 6]) -> f64 {
    v.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt()
}

fn diff6(a: &[C64; 6], b: &[C64; 6]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm_sqr())
        .sum::<f64>()
        .sqrt()
}

fn add6(a: &[C64; 6], b: &[C64; 6]) -> [C64; 6] {
    [0, 1, 2, 3, 4, 5].map(|i| a[i] + b[i])
}

fn mode6(m: &Mode, amp: C64) -> [C64; 6] {
    berreman::field6(&(m.e * amp), &(m.h * amp))
}

fn medium_str(m: &Uniaxial) -> String {
    if m.is_isotropic() {
        format!("Uniaxial::isotropic(c({:?}, {:?}))", m.eta_o.re, m.eta_o.im)
    } else {
        format!(
            "Uniaxial::new(c({:?}, {:?}), c({:?}, {:?}), Vector3::new({:?}, {:?}, {:?}))",
            m.eta_o.re, m.eta_o.im, m.eta_e.re, m.eta_e.im, m.axis.x, m.axis.y, m.axis.z
        )
    }
}

fn case_str(upper: &Uniaxial, lower: &Uniaxial, beta: C64) -> String {
    format!(
        "upper = {}; lower = {}; beta = c({:?}, {:?})",
        medium_str(upper),
        medium_str(lower),
        beta.re,
        beta.im
    )
}

/// A maximum together with the case that produced it.
#[derive(Default)]
struct Worst {
    value: f64,
    case: String,
}

impl Worst {
    fn update(&mut self, v: f64, case: impl FnOnce() -> String) {
        if v > self.value || v.is_nan() {
            self.value = v;
            self.case = case();
        }
    }
}

#[derive(Default)]
struct Stats {
    cases: usize,
    incidences: usize,
    singular: Vec<String>,
    reference_failures: Vec<String>,
    failures: Vec<String>,
    field_individual: usize,
    field_summed: usize,
    power_compared: usize,
    power_skipped_no_flux: usize,
    power_grazing: usize,
    q: Worst,
    field: Worst,
    field_vs_incident: Worst,
    decay_ambiguous: Vec<String>,
    classification_differs: Vec<String>,
    energy_wrong_way: Vec<String>,
    power: Worst,
    power_not_grazing: Worst,
    power_vs_tol: Worst,
    crate_eigen_residual: Worst,
    crate_normal_fields: Worst,
    reference_maxwell: Worst,
}

impl Stats {
    fn fail(&mut self, msg: String) {
        if self.failures.len() < 20 {
            self.failures.push(msg);
        } else if self.failures.len() == 20 {
            self.failures.push("(further failures omitted)".into());
        }
    }

    fn report(&self, name: &str) {
        println!(
            "[{name}] cases {} (incidences {}), singular/skipped {}, reference failures {}",
            self.cases,
            self.incidences,
            self.singular.len(),
            self.reference_failures.len()
        );
        println!(
            "  compared: {} individual outgoing fields, {} summed (near-degenerate) pairs, {} power ratios ({} of them near grazing, widened tolerance; {} incidences without flux not power-compared)",
            self.field_individual,
            self.field_summed,
            self.power_compared,
            self.power_grazing,
            self.power_skipped_no_flux
        );
        for (label, w) in [
            ("q", &self.q),
            (
                "outgoing field (rel. max(|incident|, |outgoing|))",
                &self.field,
            ),
            ("outgoing field (rel. |incident|)", &self.field_vs_incident),
            ("power ratio", &self.power),
            (
                "power ratio (f_rel >= GRAZING_F_REL)",
                &self.power_not_grazing,
            ),
            ("power ratio / its tolerance", &self.power_vs_tol),
            (
                "crate mode as Berreman eigenvector (residual)",
                &self.crate_eigen_residual,
            ),
            ("crate E_z/H_z vs Maxwell", &self.crate_normal_fields),
            ("reference k×E=H, k×H=−εE", &self.reference_maxwell),
        ] {
            println!("  worst {label}: {:.3e}   at {}", w.value, w.case);
        }
        if !self.decay_ambiguous.is_empty() || !self.classification_differs.is_empty() {
            println!(
                "  complex beta: decay criterion ambiguous in {} cases, crate classification differs in {} cases",
                self.decay_ambiguous.len(),
                self.classification_differs.len()
            );
        }
        if !self.energy_wrong_way.is_empty() {
            println!(
                "  complex beta: in {} compared cases a crate mode carries flux against its up/down label",
                self.energy_wrong_way.len()
            );
        }
        for s in self.energy_wrong_way.iter().take(2) {
            println!("  flux against label: {s}");
        }
        for s in self.decay_ambiguous.iter().take(2) {
            println!("  decay ambiguous: {s}");
        }
        for s in self.classification_differs.iter().take(2) {
            println!("  classification differs: {s}");
        }
        for s in self.singular.iter().take(3) {
            println!("  singular: {s}");
        }
        for s in self.reference_failures.iter().take(3) {
            println!("  reference failure: {s}");
        }
        for f in &self.failures {
            println!("  FAILURE: {f}");
        }
    }

    fn assert_ok(&self, name: &str, min_cases: usize) {
        self.report(name);
        assert!(
            self.cases >= min_cases,
            "[{name}] only {} cases",
            self.cases
        );
        assert!(
            self.failures.is_empty(),
            "[{name}] {} failures",
            self.failures.len()
        );
        assert!(
            self.reference_failures.is_empty(),
            "[{name}] reference failed"
        );
        assert!(self.q.value <= Q_TOL, "[{name}] q");
        assert!(self.field.value <= FIELD_TOL, "[{name}] fields");
        assert!(self.power_vs_tol.value <= 1.0, "[{name}] power");
        assert!(self.power_not_grazing.value <= POWER_TOL, "[{name}] power");
    }
}

/// Best assignment of the crate pair to the reference pair by `q`: `(perm, relative error)`,
/// with `perm[k]` the reference index of crate mode `k`.
fn match_q(cq: [C64; 2], rq: [C64; 2]) -> ([usize; 2], f64) {
    let rel = |a: C64, b: C64| (a - b).norm() / a.norm().max(1.0);
    let e0 = rel(cq[0], rq[0]).max(rel(cq[1], rq[1]));
    let e1 = rel(cq[0], rq[1]).max(rel(cq[1], rq[0]));
    if e0 <= e1 {
        ([0, 1], e0)
    } else {
        ([1, 0], e1)
    }
}

/// Residual of the reference mode in the full Maxwell equations `k × E = H`, `k × H = −ε E`.
fn maxwell_residual(w: &berreman::Wave, eps: &Matrix3<C64>, beta: C64) -> f64 {
    let k = Vector3::new(beta, c(0.0, 0.0), w.q);
    let r1 = (k.cross(&w.e) - w.h).norm();
    let r2 = (k.cross(&w.h) + eps * w.e).norm();
    (r1 + r2) / (w.e.norm() + w.h.norm()) / (1.0 + k.norm())
}

/// A pair of crate modes with the reference pair of the same direction and medium.
type ModeGroup<'a> = (
    &'a [Mode; 2],
    &'a [berreman::Wave; 2],
    &'a Waves,
    &'a Matrix3<C64>,
    &'static str,
);

/// Compares one interface configuration; all four incoming modes of the crate are used.
///
/// With `complex_beta_mode`, configurations where the decay criterion cannot split the modes
/// 2/2 or splits them differently from the crate are counted (see [`Stats`]) instead of
/// failing: for complex `β` the up/down classification is a convention (see `complex_exterior`).
fn compare_case(
    upper: &Uniaxial,
    lower: &Uniaxial,
    beta: C64,
    st: &mut Stats,
    complex_beta_mode: bool,
) {
    let desc = || case_str(upper, lower, beta);
    let iface = match Interface::new(upper, lower, beta) {
        Ok(i) => i,
        Err(e) => {
            st.singular.push(format!("{} ({e})", desc()));
            return;
        }
    };
    let eps_u = berreman::uniaxial_eps(upper.eta_o, upper.eta_e, upper.axis);
    let eps_l = berreman::uniaxial_eps(lower.eta_o, lower.eta_e, lower.axis);
    let (wu, wl) = match (berreman::waves(&eps_u, beta), berreman::waves(&eps_l, beta)) {
        (Ok(a), Ok(b)) => (a, b),
        (a, b) => {
            let msg = [a.err(), b.err()].into_iter().flatten().collect::<Vec<_>>();
            let msg = format!("{}: {}", desc(), msg.join("; "));
            if complex_beta_mode {
                st.decay_ambiguous.push(msg);
            } else {
                st.reference_failures.push(msg);
            }
            return;
        }
    };

    // Reference self-check.
    for (w, eps) in [(&wu, &eps_u), (&wl, &eps_l)] {
        for m in w.up.iter().chain(w.down.iter()) {
            st.reference_maxwell
                .update(maxwell_residual(m, eps, beta), desc);
        }
    }

    // q values and the crate's modes as Berreman eigenvectors.
    let groups: [ModeGroup; 4] = [
        (&iface.upper.up, &wu.up, &wu, &eps_u, "upper.up"),
        (&iface.upper.down, &wu.down, &wu, &eps_u, "upper.down"),
        (&iface.lower.up, &wl.up, &wl, &eps_l, "lower.up"),
        (&iface.lower.down, &wl.down, &wl, &eps_l, "lower.down"),
    ];
    let matches = groups.map(|(cm, rw, ..)| match_q([cm[0].q, cm[1].q], [rw[0].q, rw[1].q]));
    if complex_beta_mode && matches.iter().any(|m| m.1 > Q_TOL) {
        st.classification_differs.push(desc());
        return;
    }
    st.cases += 1;
    let perms = matches.map(|m| m.0);

    // Direction of energy flow of the crate's modes: for real β and passive media a mode that
    // decays upwards carries its flux upwards (d/dz of the flux is minus the absorption), so
    // "up" modes must have flux >= 0 and "down" modes flux <= 0.
    let wrong_way = [
        (&iface.upper.up, 1.0),
        (&iface.upper.down, -1.0),
        (&iface.lower.up, 1.0),
        (&iface.lower.down, -1.0),
    ]
    .iter()
    .flat_map(|(pair, sign)| pair.iter().map(move |m| (m, *sign)))
    .filter(|(m, sign)| m.flux() * sign < -1e-12 * m.e.norm() * m.h.norm())
    .count();
    if wrong_way > 0 {
        if complex_beta_mode {
            st.energy_wrong_way.push(desc());
        } else {
            st.fail(format!(
                "{}: {wrong_way} crate modes carry flux against their direction",
                desc()
            ));
        }
    }
    for (g, (cm, rw, waves, eps, label)) in groups.iter().enumerate() {
        let err = matches[g].1;
        st.q.update(err, desc);
        if err > Q_TOL {
            st.fail(format!(
                "{}: {label} q mismatch {err:.3e}: crate {:?} reference {:?}",
                desc(),
                [cm[0].q, cm[1].q],
                [rw[0].q, rw[1].q]
            ));
        }
        for m in cm.iter() {
            let psi = Vector4::from(m.tangential());
            let r = (waves.delta * psi - psi * m.q).norm() / (psi.norm() * (1.0 + m.q.norm()));
            st.crate_eigen_residual.update(r, desc);
            let (e, h) = berreman::full_fields(eps, beta, &psi);
            let n = ((m.e - e).norm() + (m.h - h).norm()) / (m.e.norm() + m.h.norm());
            st.crate_normal_fields.update(n, desc);
        }
    }

    // Outgoing fields and power ratios for each incoming mode of the crate.
    let power = iface.power();
    for j in 0..4 {
        st.incidences += 1;
        let (inc, above) = if j < 2 {
            (iface.upper.down[j], true)
        } else {
            (iface.lower.up[j - 2], false)
        };
        let psi_inc = Vector4::from(inc.tangential());
        let inc6 = mode6(&inc, c(1.0, 0.0));
        let inc_norm = norm6(&inc6);
        let out_norm = (0..4)
            .map(|i| {
                let m = if i < 2 {
                    &iface.upper.up[i]
                } else {
                    &iface.lower.down[i - 2]
                };
                norm6(&mode6(m, iface.s[(i, j)])).powi(2)
            })
            .sum::<f64>()
            .sqrt();
        let field_scale = inc_norm.max(out_norm);
        let inc_flux = berreman::flux(&inc.e, &inc.h);
        let f_rel = inc_flux.abs() / (inc.e.norm() * inc.h.norm());
        let flux_ok = f_rel > FLUX_FLOOR;
        if !flux_ok {
            st.power_skipped_no_flux += 1;
        }
        let Some(x) = berreman::outgoing(&wu, &wl, &psi_inc, above) else {
            st.fail(format!("{}: reference boundary system singular", desc()));
            continue;
        };
        // (crate modes, reference waves, crate row offset, medium isotropic, ref degenerate, perm)
        let out = [
            (
                &iface.upper.up,
                &wu.up,
                0usize,
                upper.is_isotropic(),
                wu.degenerate[0],
                perms[0],
            ),
            (
                &iface.lower.down,
                &wl.down,
                2usize,
                lower.is_isotropic(),
                wl.degenerate[1],
                perms[3],
            ),
        ];
        for (cm, rw, off, iso, ref_deg, perm) in out {
            let cf = [0, 1].map(|k| mode6(&cm[k], iface.s[(off + k, j)]));
            let rf = [0, 1].map(|k| rw[k].scaled(x[off + k]));
            let scale = cm[0].q.norm().max(cm[1].q.norm()).max(1.0);
            let pair_degenerate = (cm[0].q - cm[1].q).norm() <= PAIR_SUM_TOL * scale;
            let individual = if pair_degenerate {
                if iso && ref_deg {
                    // s/p split on both sides: crate [s, p], reference [E_x = 0, E_y = 0].
                    Some([0, 1])
                } else {
                    None
                }
            } else {
                Some(perm)
            };
            match individual {
                Some(perm) => {
                    for k in 0..2 {
                        let r = &rf[perm[k]];
                        let d = diff6(&cf[k], &r.field6());
                        let err = d / field_scale;
                        st.field_individual += 1;
                        st.field.update(err, desc);
                        st.field_vs_incident.update(d / inc_norm, desc);
                        if err > FIELD_TOL {
                            st.fail(format!(
                                "{}: incoming {j}, outgoing row {}: field mismatch {err:.3e}",
                                desc(),
                                off + k
                            ));
                        }
                        if flux_ok {
                            let p_ref = r.flux().abs() / inc_flux.abs();
                            let p_crate = power[(off + k, j)];
                            let err = (p_ref - p_crate).abs() / p_ref.max(1.0);
                            let tol = power_tol(f_rel);
                            st.power_compared += 1;
                            st.power.update(err, desc);
                            st.power_vs_tol.update(err / tol, desc);
                            if f_rel >= GRAZING_F_REL {
                                st.power_not_grazing.update(err, desc);
                            } else {
                                st.power_grazing += 1;
                            }
                            if err > tol {
                                st.fail(format!(
                                    "{}: incoming {j}, outgoing row {}: power crate {p_crate} reference {p_ref}",
                                    desc(),
                                    off + k
                                ));
                            }
                        }
                    }
                }
                None => {
                    let sum_c = add6(&cf[0], &cf[1]);
                    let sum_r = add6(&rf[0].field6(), &rf[1].field6());
                    let d = diff6(&sum_c, &sum_r);
                    let err = d / field_scale;
                    st.field_summed += 1;
                    st.field.update(err, desc);
                    st.field_vs_incident.update(d / inc_norm, desc);
                    if err > FIELD_TOL {
                        st.fail(format!(
                            "{}: incoming {j}, outgoing rows {off},{}: summed field mismatch {err:.3e}",
                            desc(),
                            off + 1
                        ));
                    }
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Random configurations.

#[derive(Clone, Copy, PartialEq)]
enum Loss {
    /// κ = 0.
    Lossless,
    /// κ_o, κ_e independently in [0, 0.5] (sometimes one of them 0).
    Absorbing,
    /// Metal-like and strongly dichroic: κ up to 10.
    Metal,
    /// A random mixture of the above.
    Mixed,
}

fn kappa(rng: &mut Rng, loss: Loss) -> f64 {
    match loss {
        Loss::Lossless => 0.0,
        Loss::Absorbing => {
            if rng.chance(0.15) {
                0.0
            } else {
                rng.range(0.0, 0.5)
            }
        }
        Loss::Metal => {
            if rng.chance(0.5) {
                rng.range(0.0, 10.0)
            } else {
                rng.range(0.0, 0.5)
            }
        }
        Loss::Mixed => {
            let l = [Loss::Lossless, Loss::Absorbing, Loss::Metal][rng.index(3)];
            kappa(rng, l)
        }
    }
}

fn random_uniaxial(rng: &mut Rng, loss: Loss) -> Uniaxial {
    let n_o = rng.range(1.2, 2.8);
    let mut n_e = rng.range(1.2, 2.8);
    let k_o = kappa(rng, loss);
    let mut k_e = kappa(rng, loss);
    if loss == Loss::Metal && rng.chance(0.5) {
        // Strongly dichroic: one polarisation nearly transparent, the other metallic.
        k_e = if k_o > 1.0 {
            rng.range(0.0, 0.1)
        } else {
            rng.range(2.0, 10.0)
        };
    }
    if loss != Loss::Lossless && rng.chance(0.1) {
        // Purely dichroic: same n, different κ.
        n_e = n_o;
        if k_e == k_o {
            k_e += 0.1;
        }
    }
    if n_o == n_e && k_o == k_e {
        n_e += 0.05;
    }
    Uniaxial::new(c(n_o, k_o), c(n_e, k_e), rng.unit_vector()).unwrap()
}

fn random_isotropic(rng: &mut Rng, lo: f64, hi: f64, loss: Loss) -> Uniaxial {
    let k = kappa(rng, loss);
    Uniaxial::isotropic(c(rng.range(lo, hi), k)).unwrap()
}

/// `β² = ε_e (ε_o + Δε A_z²) / (ε_e − Δε A_y²)`: where the two extraordinary roots meet (the
/// discriminant of `kᵀεk = ε_o ε_e` in `q` vanishes); for sampling near-critical incidences.
fn e_critical(m: &Uniaxial) -> f64 {
    let (eo, ee) = (m.eta_o.re.powi(2), m.eta_e.re.powi(2));
    let d = ee - eo;
    let a = m.axis;
    (ee * (eo + d * a.z * a.z) / (ee - d * a.y * a.y)).sqrt()
}

/// A real incidence parameter from 0 to beyond every critical value, with some exact zeros and
/// some samples within 1e-3..1e-9 (relative) of a critical value of a lossless medium.
fn random_beta(rng: &mut Rng, media: &[&Uniaxial]) -> C64 {
    let u = rng.uniform();
    if u < 0.05 {
        return c(0.0, 0.0);
    }
    if u < 0.15 {
        let mut crit = Vec::new();
        for m in media {
            if m.eta_o.im == 0.0 {
                crit.push(m.eta_o.re);
            }
            if !m.is_isotropic() && m.is_lossless() {
                crit.push(e_critical(m));
            }
        }
        if !crit.is_empty() {
            let b = crit[rng.index(crit.len())];
            let rel = 10f64.powf(-rng.range(3.0, 9.0));
            let sign = if rng.chance(0.5) { 1.0 } else { -1.0 };
            return c(b * (1.0 + sign * rel), 0.0);
        }
    }
    let top = media
        .iter()
        .map(|m| m.eta_o.re.max(m.eta_e.re))
        .fold(0.0, f64::max);
    c(rng.range(0.0, 1.25 * top), 0.0)
}

fn run(
    name: &str,
    seed: u64,
    count: usize,
    complex_beta: bool,
    mut gen: impl FnMut(&mut Rng) -> (Uniaxial, Uniaxial, C64),
) -> Stats {
    let mut rng = Rng::new(seed);
    let mut st = Stats::default();
    let t0 = std::time::Instant::now();
    for _ in 0..count {
        let (u, l, b) = gen(&mut rng);
        compare_case(&u, &l, b, &mut st, complex_beta);
    }
    println!("[{name}] {:.2} s", t0.elapsed().as_secs_f64());
    st
}

#[test]
fn iso_over_lossless_uniaxial() {
    let st = run("iso/lossless", 1, 10000, false, |r| {
        let u = random_isotropic(r, 1.0, 2.0, Loss::Lossless);
        let l = random_uniaxial(r, Loss::Lossless);
        let b = random_beta(r, &[&u, &l]);
        (u, l, b)
    });
    st.assert_ok("iso over lossless uniaxial", 9900);
}

#[test]
fn iso_over_absorbing_uniaxial() {
    let st = run("iso/absorbing", 2, 10000, false, |r| {
        let u = random_isotropic(r, 1.0, 2.0, Loss::Lossless);
        let l = random_uniaxial(r, Loss::Absorbing);
        let b = random_beta(r, &[&u, &l]);
        (u, l, b)
    });
    st.assert_ok("iso over absorbing/dichroic uniaxial", 9900);
}

#[test]
fn iso_over_metal_like_uniaxial() {
    let st = run("iso/metal", 3, 6000, false, |r| {
        let u = random_isotropic(r, 1.0, 2.0, Loss::Lossless);
        let l = random_uniaxial(r, Loss::Metal);
        let b = random_beta(r, &[&u, &l]);
        (u, l, b)
    });
    st.assert_ok("iso over metal-like dichroic uniaxial", 5900);
}

#[test]
fn aniso_to_aniso() {
    let st = run("aniso/aniso", 4, 6000, false, |r| {
        let u = random_uniaxial(r, Loss::Mixed);
        let l = random_uniaxial(r, Loss::Mixed);
        let b = random_beta(r, &[&u, &l]);
        (u, l, b)
    });
    st.assert_ok("aniso to aniso", 5900);
}

#[test]
fn aniso_to_iso() {
    let st = run("aniso/iso", 5, 6000, false, |r| {
        let u = random_uniaxial(r, Loss::Mixed);
        let l = random_isotropic(r, 1.0, 2.8, Loss::Mixed);
        let b = random_beta(r, &[&u, &l]);
        (u, l, b)
    });
    st.assert_ok("aniso to iso", 5900);
}

/// An absorbing exterior: `β = η sin θ` is complex. For complex `β` which of two modes is
/// "up" is a convention; the reference uses the decay criterion (`Im q`), which for an
/// extraordinary pair can leave both roots on the same side (then the case is counted as
/// ambiguous, not compared). Every case where the decay criterion is unambiguous must agree
/// with the crate. Cases where a crate mode's energy flows against its label are counted and
/// printed (see `known_issue_complex_beta_energy_direction`).
#[test]
fn complex_exterior() {
    let count = 4000;
    let st = run("complex exterior", 6, count, true, |r| {
        let k = r.range(0.0, 0.3);
        let u = Uniaxial::isotropic(c(r.range(1.0, 2.0), k)).unwrap();
        let l = random_uniaxial(r, Loss::Mixed);
        let theta = r.range(0.0, 1.5);
        (u, l, u.eta_o * theta.sin())
    });
    assert_eq!(st.cases + st.decay_ambiguous.len(), count);
    assert!(st.classification_differs.is_empty());
    st.assert_ok("complex exterior", count * 3 / 4);
}

/// Hand-picked configurations: optic axis along the normal, along the tangential direction,
/// along s and at 45° in each coordinate plane; normal incidence (`β = 0`, where o and e are
/// exactly degenerate for an axis along the normal); nearly isotropic crystals
/// (`|n_e − n_o|` down to 1e-12); purely dichroic media (`n_o = n_e`, `κ_o ≠ κ_e`);
/// isotropic/isotropic interfaces; all in both orders and crystal/crystal.
#[test]
fn special_configurations() {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let axes = [
        Vector3::new(0.0, 0.0, 1.0),
        Vector3::new(0.0, 0.0, -1.0),
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
        Vector3::new(s, 0.0, s),
        Vector3::new(0.0, s, s),
        Vector3::new(s, s, 0.0),
        Vector3::new(-s, 0.0, s),
    ];
    let pairs = [
        (c(1.6584, 0.0), c(1.4864, 0.0)),
        (c(1.6, 0.01), c(1.4, 0.2)),
        (c(1.3, 5.0), c(2.0, 0.1)),
        (c(1.5, 0.1), c(1.5, 0.3)),
        (c(1.5, 0.0), c(1.5 + 1e-7, 0.0)),
        (c(1.5, 0.0), c(1.5 + 1e-12, 0.0)),
        (c(2.2, 0.0), c(2.2 + 1e-4, 0.0)),
    ];
    let betas = [0.0, 0.3, 0.999, 1.2, 1.45, 1.7, 2.5];
    let isos = [c(1.0, 0.0), c(1.5, 0.0), c(1.33, 0.05), c(1.8, 3.0)];
    let mut st = Stats::default();
    let mut crystals = Vec::new();
    for a in axes {
        for (o, e) in pairs {
            crystals.push(Uniaxial::new(o, e, a).unwrap());
        }
    }
    let isos: Vec<Uniaxial> = isos
        .iter()
        .map(|&n| Uniaxial::isotropic(n).unwrap())
        .collect();
    for &b in &betas {
        let b = c(b, 0.0);
        for x in &crystals {
            for i in &isos {
                compare_case(i, x, b, &mut st, false);
                compare_case(x, i, b, &mut st, false);
            }
        }
        for (k, x) in crystals.iter().enumerate() {
            let y = &crystals[(k * 7 + 3) % crystals.len()];
            compare_case(x, y, b, &mut st, false);
        }
        for i in &isos {
            for j in &isos {
                compare_case(i, j, b, &mut st, false);
            }
        }
    }
    let n = betas.len() * (crystals.len() * (2 * isos.len() + 1) + isos.len() * isos.len());
    assert_eq!(st.cases + st.singular.len(), n);
    st.assert_ok("special configurations", n - st.singular.len());
    assert!(st.singular.is_empty(), "singular: {:?}", st.singular);
}

/// The product (calculator, bridge, plugins) refuses absorbing exterior media: with complex `β`
/// the incident plane wave is inhomogeneous, power fractions are not defined, and whether the
/// decaying or the energy-carrying root is "transmitted" is a convention (the library's
/// `Interface` uses decay; `complex_exterior` above compares exactly that).
#[test]
fn absorbing_exteriors_are_refused_with_a_clear_error() {
    let crystal = Uniaxial::isotropic(c(2.0, 0.0)).unwrap();
    let e = birefringent::optics::surface::Surface::new(c(1.5, 0.1), crystal).unwrap_err();
    assert_eq!(e.parameter, "ext_ior");
    assert!(e.message.contains("absorbing"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// The plate reference on its own.

/// Textbook Fresnel amplitudes `(r_s, r_p, t_s, t_p)` from medium `i` into medium `j` in the
/// bilinear basis `E_s = ŷ`, `E_p = k̂ × ŷ`: `r_s = (q_i − q_j)/(q_i + q_j)`,
/// `r_p = (q_i ε_j − q_j ε_i)/(q_i ε_j + q_j ε_i)`, `t_s = 2 q_i/(q_i + q_j)`,
/// `t_p = 2 η_i η_j q_i/(q_i ε_j + q_j ε_i)`, with `q = sqrt(ε − β²)` (principal root).
fn fresnel(eta_i: C64, eta_j: C64, beta: C64) -> [C64; 4] {
    let (ei, ej) = (eta_i * eta_i, eta_j * eta_j);
    let (qi, qj) = ((ei - beta * beta).sqrt(), (ej - beta * beta).sqrt());
    [
        (qi - qj) / (qi + qj),
        (qi * ej - qj * ei) / (qi * ej + qj * ei),
        qi * 2.0 / (qi + qj),
        eta_i * eta_j * qi * 2.0 / (qi * ej + qj * ei),
    ]
}

/// Airy summation for an isotropic layer: `r = (r12 + r23 e^{2iδ})/(1 + r12 r23 e^{2iδ})`,
/// `t = t12 t23 e^{iδ}/(1 + r12 r23 e^{2iδ})`, `δ = 2π q2 d/λ`; returns `[(r_s, t_s), (r_p, t_p)]`.
fn airy(n1: C64, n2: C64, n3: C64, beta: C64, d: f64) -> [(C64, C64); 2] {
    let f12 = fresnel(n1, n2, beta);
    let f23 = fresnel(n2, n3, beta);
    let q2 = (n2 * n2 - beta * beta).sqrt();
    let ph = (C64::i() * q2 * (2.0 * std::f64::consts::PI * d)).exp();
    [0, 1].map(|k| {
        let (r12, r23, t12, t23) = (f12[k], f23[k], f12[k + 2], f23[k + 2]);
        let den = C64::new(1.0, 0.0) + r12 * r23 * ph * ph;
        ((r12 + r23 * ph * ph) / den, t12 * t23 * ph / den)
    })
}

fn iso_eps(n: C64) -> [[C64; 3]; 3] {
    berreman::to_array(&berreman::isotropic_eps(n * n))
}

#[test]
fn plate_isotropic_layer_matches_airy() {
    let mut rng = Rng::new(11);
    let mut worst = Worst::default();
    let mut cases = 0;
    for k in 0..3000 {
        let n1 = c(rng.range(1.0, 2.0), 0.0);
        let n3 = c(
            rng.range(1.0, 2.8),
            if rng.chance(0.3) {
                rng.range(0.0, 0.5)
            } else {
                0.0
            },
        );
        let tir_inside = k % 4 == 0;
        let n2 = if tir_inside {
            // Frustrated total internal reflection: the layer is evanescent.
            c(rng.range(1.0, 0.95 * n1.re), 0.0)
        } else {
            c(
                rng.range(1.0, 2.8),
                if rng.chance(0.4) {
                    rng.range(0.0, 0.5)
                } else {
                    0.0
                },
            )
        };
        let beta = if tir_inside {
            c(rng.range(n2.re * 1.01, n1.re), 0.0)
        } else {
            c(rng.range(0.0, 0.99 * n1.re), 0.0)
        };
        let d = rng.range(0.0, 3.0);
        let p = berreman::plate_reference(n1 * n1, iso_eps(n2), n3 * n3, beta, d);
        let a = airy(n1, n2, n3, beta, d);
        let ab = airy(n3, n2, n1, beta, d);
        let mut err: f64 = 0.0;
        for i in 0..2 {
            err = err
                .max((p.r[(i, i)] - a[i].0).norm())
                .max((p.t[(i, i)] - a[i].1).norm())
                .max((p.r_below[(i, i)] - ab[i].0).norm())
                .max((p.t_below[(i, i)] - ab[i].1).norm())
                .max(p.r[(i, 1 - i)].norm())
                .max(p.t[(i, 1 - i)].norm())
                .max(p.r_below[(i, 1 - i)].norm())
                .max(p.t_below[(i, 1 - i)].norm());
        }
        worst.update(err, || format!("n1 {n1} n2 {n2} n3 {n3} beta {beta} d {d}"));
        cases += 1;
    }
    println!(
        "[plate Airy] {cases} cases, worst |plate − Airy| {:.3e} at {}",
        worst.value, worst.case
    );
    assert!(worst.value <= 1e-12);
}

/// A uniaxial permittivity with random indices (and optionally κ) and a random axis.
fn random_layer(rng: &mut Rng, kappa_max: f64, n_range: (f64, f64)) -> Matrix3<C64> {
    let ko = rng.range(0.0, kappa_max);
    let ke = rng.range(0.0, kappa_max);
    let no = rng.range(n_range.0, n_range.1);
    let ne = rng.range(n_range.0, n_range.1);
    berreman::uniaxial_eps(c(no, ko), c(ne, ke), rng.unit_vector())
}

#[test]
fn plate_lossless_conserves_energy() {
    let mut rng = Rng::new(12);
    let mut worst = Worst::default();
    let mut worst_tir: f64 = 0.0;
    let (mut cases, mut tir_cases) = (0, 0);
    for k in 0..3000 {
        let inside_tir = k % 3 == 0;
        let (n1, n3, layer, beta) = if inside_tir {
            // Layer indices below β < both half-space indices: evanescent inside.
            let n = rng.range(2.3, 2.8);
            let layer = random_layer(&mut rng, 0.0, (1.2, 1.8));
            (n, rng.range(2.3, 2.8), layer, rng.range(1.9, 2.25))
        } else {
            let (n1, n3) = (rng.range(1.0, 2.0), rng.range(1.0, 2.8));
            let layer = random_layer(&mut rng, 0.0, (1.2, 2.8));
            (n1, n3, layer, rng.range(0.0, 1.1 * n1))
        };
        let d = if rng.chance(0.2) {
            rng.range(0.0, 1000.0)
        } else {
            rng.range(0.0, 5.0)
        };
        let (e1, e3) = (c(n1 * n1, 0.0), c(n3 * n3, 0.0));
        let p = berreman::plate_reference(e1, berreman::to_array(&layer), e3, c(beta, 0.0), d);
        let desc = || format!("n1 {n1} n3 {n3} beta {beta} d {d} layer {layer:?}");
        // Columns of propagating incident waves must sum to 1 (each side independently).
        if beta < n1 {
            for j in 0..2 {
                let sum: f64 = (0..2).map(|i| p.power_r[(i, j)] + p.power_t[(i, j)]).sum();
                worst.update((sum - 1.0).abs(), desc);
            }
        }
        if beta < n3 {
            for j in 0..2 {
                let sum: f64 = (0..2)
                    .map(|i| p.power_r_below[(i, j)] + p.power_t_below[(i, j)])
                    .sum();
                worst.update((sum - 1.0).abs(), desc);
            }
        }
        if beta > n3 && beta < n1 {
            // Total internal reflection at the bottom: nothing transmitted.
            assert!(p.power_t.iter().all(|x| *x == 0.0), "{}", desc());
        }
        if inside_tir {
            tir_cases += 1;
            for j in 0..2 {
                worst_tir = worst_tir.max(p.power_t[(0, j)] + p.power_t[(1, j)]);
            }
        }
        cases += 1;
    }
    println!(
        "[plate energy] {cases} lossless cases ({tir_cases} with an evanescent layer, max T there {worst_tir:.3e}), worst |R + T − 1| {:.3e} at {}",
        worst.value, worst.case
    );
    assert!(worst.value <= 1e-11);
}

/// Thick absorbing (and thick evanescent) layers: everything stays finite, and once the layer
/// is opaque the plate reflects exactly like the top interface alone and transmits nothing.
#[test]
fn plate_thick_layers_stay_finite() {
    let mut rng = Rng::new(13);
    let mut worst = Worst::default();
    let mut cases = 0;
    for k in 0..1000 {
        let n1 = rng.range(1.0, 2.0);
        let n3 = c(rng.range(1.0, 2.8), rng.range(0.0, 0.3));
        let evanescent = k % 4 == 0;
        let layer = if evanescent {
            random_layer(&mut rng, 0.0, (1.0, 0.9 * n1))
        } else {
            random_layer(&mut rng, 1.0, (1.2, 2.8))
        };
        let beta = if evanescent {
            rng.range(0.95 * n1, n1)
        } else {
            rng.range(0.0, n1)
        };
        let beta = c(beta, 0.0);
        let d = 10f64.powf(rng.range(3.0, 5.0));
        let e1 = c(n1 * n1, 0.0);
        let p = berreman::plate_reference(e1, berreman::to_array(&layer), n3 * n3, beta, d);
        let all = [p.r, p.t, p.r_below, p.t_below];
        assert!(all
            .iter()
            .all(|m| m.iter().all(|z| z.re.is_finite() && z.im.is_finite())));
        let powers = [p.power_r, p.power_t, p.power_r_below, p.power_t_below];
        assert!(powers.iter().all(|m| m.iter().all(|x| x.is_finite())));
        // Opaque layer (every layer mode attenuated by far more than e^-700 across it):
        // reflection of the top interface alone, no transmission.
        let k0d = 2.0 * std::f64::consts::PI * d;
        if p.q_layer.iter().all(|q| q.im.abs() * k0d > 800.0) {
            let top = berreman::isotropic_sp_waves(e1, beta).unwrap();
            let lay = berreman::waves(&layer, beta).unwrap();
            let s = berreman::interface_s(&top, &lay).unwrap();
            let r_top = s.fixed_view::<2, 2>(0, 0).into_owned();
            let err = (p.r - r_top).norm();
            worst.update(err, || format!("n1 {n1} beta {beta} d {d} layer {layer:?}"));
            assert!(p.t.iter().all(|z| z.norm() == 0.0));
            assert!(p.t_below.iter().all(|z| z.norm() == 0.0));
            cases += 1;
        }
    }
    println!(
        "[plate thick] {cases} opaque thick layers, worst |r_plate − r_top interface| {:.3e}",
        worst.value
    );
    assert!(cases >= 500);
    assert!(worst.value <= 1e-13);
}

/// The star-product assembly against a direct solve of the plate's 8x8 boundary-value system
/// (amplitudes of the layer's down modes referred to `z = 0`, of its up modes to `z = −d`, so
/// no growing exponential appears either), for anisotropic, absorbing layers; and a plate of
/// zero thickness against the single top/bottom interface.
#[test]
fn plate_star_product_matches_direct_solve() {
    use nalgebra::{SMatrix, SVector};
    let mut rng = Rng::new(14);
    let mut worst = Worst::default();
    let mut worst_zero: f64 = 0.0;
    for _ in 0..2000 {
        let n1 = rng.range(1.0, 2.0);
        let e1 = c(n1 * n1, 0.0);
        let n3 = c(
            rng.range(1.0, 2.8),
            if rng.chance(0.3) {
                rng.range(0.0, 0.5)
            } else {
                0.0
            },
        );
        let e3 = n3 * n3;
        let kappa_max = if rng.chance(0.5) { 0.5 } else { 0.0 };
        let layer = random_layer(&mut rng, kappa_max, (1.2, 2.8));
        let beta = c(rng.range(0.0, 1.2 * n1), 0.0);
        let d = rng.range(0.0, 4.0);
        let p = berreman::plate_reference(e1, berreman::to_array(&layer), e3, beta, d);
        let top = berreman::isotropic_sp_waves(e1, beta).unwrap();
        let bot = berreman::isotropic_sp_waves(e3, beta).unwrap();
        let lay = berreman::waves(&layer, beta).unwrap();
        let k0d = 2.0 * std::f64::consts::PI * d;
        let i = C64::i();
        let pd = lay.down.map(|w| (-i * w.q * k0d).exp());
        let pu = lay.up.map(|w| (i * w.q * k0d).exp());
        // Unknowns: [r (top up 2), a (layer down at 0), b (layer up at −d), t (bottom down 2)].
        let mut m = SMatrix::<C64, 8, 8>::zeros();
        for row in 0..4 {
            for k in 0..2 {
                m[(row, k)] = top.up[k].psi[row];
                m[(row, 2 + k)] = -lay.down[k].psi[row];
                m[(row, 4 + k)] = -lay.up[k].psi[row] * pu[k];
                m[(4 + row, 2 + k)] = lay.down[k].psi[row] * pd[k];
                m[(4 + row, 4 + k)] = lay.up[k].psi[row];
                m[(4 + row, 6 + k)] = -bot.down[k].psi[row];
            }
        }
        let lu = m.full_piv_lu();
        for j in 0..2 {
            let mut rhs = SVector::<C64, 8>::zeros();
            for row in 0..4 {
                rhs[row] = -top.down[j].psi[row];
            }
            let x = lu.solve(&rhs).unwrap();
            for k in 0..2 {
                let e = (x[k] - p.r[(k, j)])
                    .norm()
                    .max((x[6 + k] - p.t[(k, j)]).norm());
                worst.update(e, || {
                    format!("n1 {n1} n3 {n3} beta {beta} d {d} layer {layer:?}")
                });
            }
        }
        // Zero thickness: the plate is the top/bottom interface.
        let p0 = berreman::plate_reference(e1, berreman::to_array(&layer), e3, beta, 0.0);
        let s = berreman::interface_s(&top, &bot).unwrap();
        let z = (p0.r - s.fixed_view::<2, 2>(0, 0)).norm()
            + (p0.t - s.fixed_view::<2, 2>(2, 0)).norm()
            + (p0.t_below - s.fixed_view::<2, 2>(0, 2)).norm()
            + (p0.r_below - s.fixed_view::<2, 2>(2, 2)).norm();
        worst_zero = worst_zero.max(z);
    }
    println!(
        "[plate direct] worst |star − direct| {:.3e} at {}; zero thickness vs interface {:.3e}",
        worst.value, worst.case, worst_zero
    );
    assert!(worst.value <= 1e-11);
    assert!(worst_zero <= 1e-12);
}
