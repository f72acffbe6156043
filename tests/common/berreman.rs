//! An independent numerical reference for planar interfaces and plates of (possibly absorbing,
//! dichroic) anisotropic media: the Berreman 4x4 formulation, solved with general-purpose
//! numerical linear algebra. Nothing here uses the crate's closed-form mode construction.
//!
//! # Conventions
//!
//! Working frame: `x` = direction of the tangential wave vector, `z` = surface normal (the upper
//! medium fills `z > 0`), `y = z × x`. Every wave has the wave vector `k0 (β, 0, q)` (`β` may be
//! complex), fields `E(r) = e · exp(i k0 (β x + q z))`, time dependence `exp(−iωt)`, `μ = 1` and
//! `H` in units where the vacuum impedance is 1, so that for a plane wave `H = k × E` (`k` in
//! units of `k0`).
//!
//! # Derivation of the Berreman matrix `Δ`
//!
//! Maxwell's curl equations for time-harmonic fields (`exp(−iωt)`, `μ = 1`, `H` scaled by the
//! vacuum impedance) read `∇ × E = i k0 H` and `∇ × H = −i k0 ε E`. In a stratified medium the
//! fields depend on `x` only through `exp(i k0 β x)` and not at all on `y`, so `∂x = i k0 β`,
//! `∂y = 0`. Write `D = (1 / (i k0)) d/dz`. Component by component:
//!
//! ```text
//! (∇×E)_x = −∂z E_y            = i k0 H_x   ⇒  D E_y = −H_x
//! (∇×E)_y =  ∂z E_x − ∂x E_z   = i k0 H_y   ⇒  D E_x =  H_y + β E_z
//! (∇×E)_z =  ∂x E_y            = i k0 H_z   ⇒  H_z   =  β E_y                    (algebraic)
//! (∇×H)_x = −∂z H_y            = −i k0 (εE)_x ⇒ D H_y =  (εE)_x
//! (∇×H)_y =  ∂z H_x − ∂x H_z   = −i k0 (εE)_y ⇒ D H_x =  β H_z − (εE)_y = β² E_y − (εE)_y
//! (∇×H)_z =  ∂x H_y            = −i k0 (εE)_z ⇒ (εE)_z = −β H_y                  (algebraic)
//! ```
//!
//! The two algebraic equations eliminate the normal components:
//! `H_z = β E_y` and `E_z = −(β H_y + ε_zx E_x + ε_zy E_y) / ε_zz`. Substituting `E_z` into the
//! four differential equations gives `D ψ = Δ ψ` for `ψ = (E_x, E_y, H_x, H_y)`, i.e.
//! `dψ/dz = i k0 Δ ψ`, with
//!
//! ```text
//!       ⎡ −β ε_zx/ε_zz                 −β ε_zy/ε_zz                   0    1 − β²/ε_zz  ⎤
//!  Δ =  ⎢  0                            0                            −1    0            ⎥
//!       ⎢ −ε_yx + ε_yz ε_zx/ε_zz        β² − ε_yy + ε_yz ε_zy/ε_zz     0    β ε_yz/ε_zz  ⎥
//!       ⎣  ε_xx − ε_xz ε_zx/ε_zz        ε_xy − ε_xz ε_zy/ε_zz          0   −β ε_xz/ε_zz  ⎦
//! ```
//!
//! A plane wave `ψ(z) = ψ0 exp(i k0 q z)` solves this iff `Δ ψ0 = q ψ0`: the four eigenvalues
//! of `Δ` are the normal wave-vector components `q` of the medium's four modes, the eigenvectors
//! their tangential fields. (Check: for `ε = ε I`, `D² E_y = (ε − β²) E_y`, so `q² = ε − β²`.)
//!
//! # Numerics
//!
//! Eigenvalues come from a small complex Hessenberg-QR iteration ([`eigenvalues`]). Each mode
//! is classified as going up (`+z`) if `Im q > tol` (it decays upwards), down if `Im q < −tol`,
//! and otherwise by the sign of its normal Poynting flux `½ Re(E × H*)_z`. Eigenvectors are
//! null vectors of `Δ − qI` from an SVD; a nearly degenerate pair of same-direction modes is
//! resolved inside the pair's invariant subspace (null space of `(Δ − q₁I)(Δ − q₂I)`), and an
//! exactly degenerate pair (isotropic media) is split into the `E_x = 0` (s-like) and
//! `E_y = 0` (p-like) members of its eigenspace. `E_z` and `H_z` follow from the algebraic
//! equations above. Interfaces impose continuity of `ψ`; plates combine interface scattering
//! matrices with propagation factors that never grow (Redheffer star product,
//! [`plate_reference`]).
//!
//! Accuracy limits inherent to the formulation: near grazing incidence in a medium (`q → 0`,
//! its critical angle) `Δ` contains `β² − ε`, which loses accuracy by cancellation, and the
//! up/down pair approaches a Jordan block, so mode fields there carry errors `~ ε_mach / |q|`.
//! For complex `β` (absorbing exterior) the decay criterion is a convention and may fail to
//! split an extraordinary pair 2/2; [`waves`] then reports an error.

use nalgebra::{Matrix2, Matrix3, Matrix4, Vector3, Vector4, SVD};
use num_complex::Complex64 as C64;

/// A complex 3-vector.
pub type C3 = Vector3<C64>;
/// A tangential field vector `(E_x, E_y, H_x, H_y)`.
pub type Psi = Vector4<C64>;

const ZERO: C64 = C64::new(0.0, 0.0);
const ONE: C64 = C64::new(1.0, 0.0);

/// Relative tolerance on `Im q` below which a mode is classified by its flux instead.
pub const IM_TOL: f64 = 1e-10;
/// Relative distance below which two same-direction eigenvalues count as exactly degenerate.
pub const DEGENERATE_TOL: f64 = 1e-10;
/// Relative distance below which a same-direction pair is resolved inside its invariant
/// subspace rather than by independent null vectors.
pub const NEAR_DEGENERATE_TOL: f64 = 1e-3;

/// Relative normal flux `|P| / (|E| |H|)` below which a wave counts as carrying no power
/// (rounding noise of an evanescent wave in a lossless medium).
pub const FLUX_FLOOR: f64 = 1e-12;

/// Permittivity of a uniaxial medium, `ε = ε_o I + (ε_e − ε_o) A Aᵀ`, `ε = η²`, with the axis
/// `axis` (normalised here) given in the working frame.
pub fn uniaxial_eps(eta_o: C64, eta_e: C64, axis: Vector3<f64>) -> Matrix3<C64> {
    let a = axis / axis.norm();
    let (eo, ee) = (eta_o * eta_o, eta_e * eta_e);
    Matrix3::from_fn(|i, j| {
        let diag = if i == j { eo } else { ZERO };
        diag + (ee - eo) * (a[i] * a[j])
    })
}

/// Permittivity `ε I` of an isotropic medium.
pub fn isotropic_eps(eps: C64) -> Matrix3<C64> {
    Matrix3::identity() * eps
}

/// True when `eps` is exactly a multiple of the identity.
pub fn is_scalar(eps: &Matrix3<C64>) -> bool {
    (0..3).all(|i| {
        (0..3).all(|j| {
            if i == j {
                eps[(i, j)] == eps[(0, 0)]
            } else {
                eps[(i, j)] == ZERO
            }
        })
    })
}

/// The Berreman matrix `Δ(β, ε)`: `dψ/dz = i k0 Δ ψ`, `ψ = (E_x, E_y, H_x, H_y)` (see the
/// module documentation for the derivation).
pub fn delta_matrix(eps: &Matrix3<C64>, beta: C64) -> Matrix4<C64> {
    let e = |i: usize, j: usize| eps[(i, j)];
    let ezz = e(2, 2);
    let b2 = beta * beta;
    #[rustfmt::skip]
    let m = Matrix4::new(
        -beta * e(2, 0) / ezz,                -beta * e(2, 1) / ezz,                     ZERO, ONE - b2 / ezz,
        ZERO,                                 ZERO,                                     -ONE,  ZERO,
        -e(1, 0) + e(1, 2) * e(2, 0) / ezz,   b2 - e(1, 1) + e(1, 2) * e(2, 1) / ezz,    ZERO, beta * e(1, 2) / ezz,
        e(0, 0) - e(0, 2) * e(2, 0) / ezz,    e(0, 1) - e(0, 2) * e(2, 1) / ezz,         ZERO, -beta * e(0, 2) / ezz,
    );
    m
}

/// Full `E` and `H` from the tangential vector `ψ`, using the two algebraic Maxwell equations:
/// `E_z = −(β H_y + ε_zx E_x + ε_zy E_y)/ε_zz`, `H_z = β E_y`.
pub fn full_fields(eps: &Matrix3<C64>, beta: C64, psi: &Psi) -> (C3, C3) {
    let ez = -(beta * psi[3] + eps[(2, 0)] * psi[0] + eps[(2, 1)] * psi[1]) / eps[(2, 2)];
    let hz = beta * psi[1];
    (
        Vector3::new(psi[0], psi[1], ez),
        Vector3::new(psi[2], psi[3], hz),
    )
}

/// One numerically computed mode.
#[derive(Clone, Copy, Debug)]
pub struct Wave {
    /// Normal wave-vector component (eigenvalue of `Δ`).
    pub q: C64,
    /// Tangential fields `(E_x, E_y, H_x, H_y)` (eigenvector of `Δ`).
    pub psi: Psi,
    /// Full electric field.
    pub e: C3,
    /// Full magnetic field.
    pub h: C3,
}

impl Wave {
    fn new(eps: &Matrix3<C64>, beta: C64, q: C64, psi: Psi) -> Self {
        let (e, h) = full_fields(eps, beta, &psi);
        Wave { q, psi, e, h }
    }

    /// Normal Poynting flux `½ Re(E × H*)_z` (positive upwards).
    pub fn flux(&self) -> f64 {
        flux(&self.e, &self.h)
    }

    /// The wave times a complex amplitude.
    pub fn scaled(&self, a: C64) -> Wave {
        Wave {
            q: self.q,
            psi: self.psi * a,
            e: self.e * a,
            h: self.h * a,
        }
    }

    /// `(E, H)` as one 6-vector.
    pub fn field6(&self) -> [C64; 6] {
        field6(&self.e, &self.h)
    }
}

/// `½ Re(E × H*)_z`.
pub fn flux(e: &C3, h: &C3) -> f64 {
    0.5 * (e.x * h.y.conj() - e.y * h.x.conj()).re
}

/// `(E, H)` as one 6-vector.
pub fn field6(e: &C3, h: &C3) -> [C64; 6] {
    [e.x, e.y, e.z, h.x, h.y, h.z]
}

/// The four modes of one medium, classified by direction.
#[derive(Clone, Copy, Debug)]
pub struct Waves {
    /// Modes going (or decaying) upwards, `+z`.
    pub up: [Wave; 2],
    /// Modes going (or decaying) downwards, `−z`.
    pub down: [Wave; 2],
    /// Whether the up / down pair was exactly degenerate and split into s-like (`E_x = 0`,
    /// index 0) and p-like (`E_y = 0`, index 1) members.
    pub degenerate: [bool; 2],
    /// The Berreman matrix the modes were computed from.
    pub delta: Matrix4<C64>,
}

/// Eigenvalues of a complex 4x4 matrix: Givens reduction to upper Hessenberg form, then the
/// complex single-shift QR algorithm (Wilkinson shifts, deflation of negligible subdiagonal
/// entries, an exceptional shift when an eigenvalue does not converge). The result is the
/// diagonal of a (unitarily similar) Schur form; `None` if it fails to converge.
///
/// (nalgebra's `Schur` uses a real-oriented double-shift iteration that stalls on complex
/// matrices with repeated eigenvalues, e.g. the Berreman matrix of an absorbing isotropic
/// medium, hence this small dedicated implementation.)
#[allow(clippy::needless_range_loop)] // index arithmetic on a small dense matrix
pub fn eigenvalues(a: &Matrix4<C64>) -> Option<[C64; 4]> {
    const N: usize = 4;
    let mut h = [[ZERO; N]; N];
    for (i, row) in h.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = a[(i, j)];
        }
    }
    // A Givens rotation G = [[c̄, s̄], [−s, c]] with G (x, y)ᵀ = (r, 0)ᵀ.
    let givens = |x: C64, y: C64| -> Option<(C64, C64)> {
        let r = x.norm().hypot(y.norm());
        (r > 0.0).then(|| (x / r, y / r))
    };
    // Applies G to rows (p, i) for columns `cols`, and Gᴴ to columns (p, i) for rows `rows`.
    let rotate_rows = |h: &mut [[C64; N]; N],
                       p: usize,
                       i: usize,
                       c: C64,
                       s: C64,
                       cols: std::ops::RangeInclusive<usize>| {
        for k in cols {
            let (x, y) = (h[p][k], h[i][k]);
            h[p][k] = c.conj() * x + s.conj() * y;
            h[i][k] = -s * x + c * y;
        }
    };
    let rotate_cols = |h: &mut [[C64; N]; N],
                       p: usize,
                       i: usize,
                       c: C64,
                       s: C64,
                       rows: std::ops::RangeInclusive<usize>| {
        for row in h[rows].iter_mut() {
            let (x, y) = (row[p], row[i]);
            row[p] = x * c + y * s;
            row[i] = -x * s.conj() + y * c.conj();
        }
    };
    // Hessenberg reduction (a similarity transform).
    for k in 0..N - 2 {
        for i in k + 2..N {
            if let Some((c, s)) = givens(h[k + 1][k], h[i][k]) {
                rotate_rows(&mut h, k + 1, i, c, s, 0..=N - 1);
                rotate_cols(&mut h, k + 1, i, c, s, 0..=N - 1);
                h[i][k] = ZERO;
            }
        }
    }
    let norm = h.iter().flatten().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
    if !norm.is_finite() {
        return None;
    }
    let mut hi = N - 1;
    let mut iter = 0;
    let mut total = 0;
    while hi > 0 {
        // Deflation: the active window is lo..=hi.
        let mut lo = hi;
        while lo > 0 {
            let mut tst = h[lo][lo].norm() + h[lo - 1][lo - 1].norm();
            if tst == 0.0 {
                tst = norm;
            }
            if h[lo][lo - 1].norm() <= f64::EPSILON * tst {
                h[lo][lo - 1] = ZERO;
                break;
            }
            lo -= 1;
        }
        if lo == hi {
            hi -= 1;
            iter = 0;
            continue;
        }
        total += 1;
        iter += 1;
        if total > 500 {
            return None;
        }
        // Wilkinson shift: the eigenvalue of the trailing 2x2 block closer to its last entry.
        let (a, b, c, d) = (h[hi - 1][hi - 1], h[hi - 1][hi], h[hi][hi - 1], h[hi][hi]);
        let half = (a - d) * 0.5;
        let disc = (half * half + b * c).sqrt();
        let (m1, m2) = ((a + d) * 0.5 + disc, (a + d) * 0.5 - disc);
        let mut mu = if (m1 - d).norm() <= (m2 - d).norm() {
            m1
        } else {
            m2
        };
        if iter % 10 == 0 {
            // Exceptional shift.
            mu = d + C64::new(0.75, 0.31) * h[hi][hi - 1].norm();
        }
        // One explicit shifted QR step on the window: H − μI = QR, H ← RQ + μI.
        for k in lo..=hi {
            h[k][k] -= mu;
        }
        let mut rots = [(ONE, ZERO); N];
        for k in lo..hi {
            let (c, s) = givens(h[k][k], h[k + 1][k]).unwrap_or((ONE, ZERO));
            rotate_rows(&mut h, k, k + 1, c, s, lo..=hi);
            h[k + 1][k] = ZERO;
            rots[k] = (c, s);
        }
        for k in lo..hi {
            let (c, s) = rots[k];
            rotate_cols(&mut h, k, k + 1, c, s, lo..=hi);
        }
        for k in lo..=hi {
            h[k][k] += mu;
        }
    }
    Some([h[0][0], h[1][1], h[2][2], h[3][3]])
}

/// Right singular vectors of `m` for its `count` smallest singular values (a numerical null
/// space).
fn null_space(m: Matrix4<C64>, count: usize) -> Vec<Psi> {
    let svd = SVD::new(m, false, true);
    let vt = svd.v_t.expect("requested V");
    (4 - count..4).map(|r| vt.row(r).adjoint()).collect()
}

fn hermitian_normalize(v: Psi) -> Psi {
    let n = v.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
    v / C64::new(n, 0.0)
}

/// The modes of a medium of permittivity `eps` for incidence parameter `beta`.
///
/// Fails (with a message) only for configurations where the mode problem is degenerate in a
/// way the classification cannot resolve (e.g. `q = 0` exactly: grazing/critical incidence, or
/// `ε_zz = 0`).
pub fn waves(eps: &Matrix3<C64>, beta: C64) -> Result<Waves, String> {
    if eps[(2, 2)] == ZERO {
        return Err("eps_zz = 0".into());
    }
    let delta = delta_matrix(eps, beta);
    let qs = eigenvalues(&delta).ok_or("QR iteration did not converge")?;
    let scale = 1.0 + qs.iter().map(|q| q.norm()).fold(0.0, f64::max);

    // Classification.
    let mut up = Vec::new();
    let mut down = Vec::new();
    for &q in &qs {
        let goes_up = if q.im > IM_TOL * scale {
            true
        } else if q.im < -IM_TOL * scale {
            false
        } else {
            let v = null_space(delta - Matrix4::identity() * q, 1)[0];
            let f = Wave::new(eps, beta, q, v).flux();
            if f == 0.0 || !f.is_finite() {
                return Err(format!("cannot classify mode q = {q}: no decay, no flux"));
            }
            f > 0.0
        };
        if goes_up {
            up.push(q)
        } else {
            down.push(q)
        }
    }
    if up.len() != 2 {
        return Err(format!(
            "classification gave {} up and {} down modes: up {:?} down {:?}",
            up.len(),
            down.len(),
            up,
            down
        ));
    }
    let (up, deg_up) = pair_modes(eps, beta, &delta, [up[0], up[1]], scale)?;
    let (down, deg_down) = pair_modes(eps, beta, &delta, [down[0], down[1]], scale)?;
    Ok(Waves {
        up,
        down,
        degenerate: [deg_up, deg_down],
        delta,
    })
}

/// Eigenvectors of the same-direction pair `q`.
fn pair_modes(
    eps: &Matrix3<C64>,
    beta: C64,
    delta: &Matrix4<C64>,
    q: [C64; 2],
    scale: f64,
) -> Result<([Wave; 2], bool), String> {
    let id = Matrix4::<C64>::identity();
    let gap = (q[0] - q[1]).norm();
    if gap <= DEGENERATE_TOL * scale || is_scalar(eps) {
        // Exactly degenerate: any vector of the 2D eigenspace is a mode. Split into the member
        // with E_x = 0 (s-like) and the one with E_y = 0 (p-like).
        let qm = (q[0] + q[1]) * 0.5;
        let v = null_space(delta - id * qm, 2);
        let s = v[0] * v[1][0] - v[1] * v[0][0];
        let p = v[0] * v[1][1] - v[1] * v[0][1];
        let s = hermitian_normalize(s);
        let p = hermitian_normalize(p);
        return Ok((
            [Wave::new(eps, beta, qm, s), Wave::new(eps, beta, qm, p)],
            true,
        ));
    }
    if gap > NEAR_DEGENERATE_TOL * scale {
        let w = q.map(|qi| {
            let v = hermitian_normalize(null_space(delta - id * qi, 1)[0]);
            Wave::new(eps, beta, qi, v)
        });
        return Ok((w, false));
    }
    // Nearly degenerate: invariant subspace of the pair, then the 2x2 restriction of Δ.
    let p = (delta - id * q[0]) * (delta - id * q[1]);
    let v = null_space(p, 2);
    let basis = nalgebra::Matrix4x2::from_columns(&[v[0], v[1]]);
    let m: Matrix2<C64> = basis.adjoint() * delta * basis;
    let w = q.map(|qi| {
        let c1 = nalgebra::Vector2::new(m[(0, 1)], qi - m[(0, 0)]);
        let c2 = nalgebra::Vector2::new(qi - m[(1, 1)], m[(1, 0)]);
        let c = if c1.norm() >= c2.norm() { c1 } else { c2 };
        let v = hermitian_normalize(basis * c);
        Wave::new(eps, beta, qi, v)
    });
    Ok((w, false))
}

/// Solves the boundary conditions at `z = 0` for an incident tangential field `psi_inc`
/// arriving from above (`from_above`, a down-going field of the upper medium) or from below.
/// Returns the outgoing amplitudes `[upper.up[0], upper.up[1], lower.down[0], lower.down[1]]`.
///
/// Continuity of `ψ`: from above `ψ_inc + Ψ₁↑ b = Ψ₂↓ c`; from below `Ψ₁↑ b = Ψ₂↓ c + ψ_inc`.
pub fn outgoing(upper: &Waves, lower: &Waves, psi_inc: &Psi, from_above: bool) -> Option<[C64; 4]> {
    let lhs = Matrix4::from_columns(&[
        upper.up[0].psi,
        upper.up[1].psi,
        -lower.down[0].psi,
        -lower.down[1].psi,
    ]);
    let rhs = if from_above { -psi_inc } else { *psi_inc };
    let x = lhs.full_piv_lu().solve(&rhs)?;
    if x.iter().any(|z| !z.re.is_finite() || !z.im.is_finite()) {
        return None;
    }
    Some([x[0], x[1], x[2], x[3]])
}

/// The interface scattering matrix in the reference bases: rows `[upper.up (2); lower.down (2)]`,
/// columns `[upper.down (2); lower.up (2)]` (same layout as the crate's `Interface::s`).
pub fn interface_s(upper: &Waves, lower: &Waves) -> Option<Matrix4<C64>> {
    let mut s = Matrix4::zeros();
    for j in 0..4 {
        let (psi, above) = if j < 2 {
            (upper.down[j].psi, true)
        } else {
            (lower.up[j - 2].psi, false)
        };
        let x = outgoing(upper, lower, &psi, above)?;
        for (i, xi) in x.iter().enumerate() {
            s[(i, j)] = *xi;
        }
    }
    Some(s)
}

/// Modes of an isotropic medium in the textbook bilinear s/p basis: `E_s = ŷ`,
/// `E_p = k̂ × ŷ` with `k̂ = k/η` (so `H_p = k × E_p = −η ŷ`), `η = sqrt(ε)` with `Re η > 0`.
/// Computed numerically (degenerate Berreman eigenspace split into `E_x = 0` / `E_y = 0`) and
/// then scaled to that basis; index 0 is s, index 1 is p.
pub fn isotropic_sp_waves(eps: C64, beta: C64) -> Result<Waves, String> {
    let m = isotropic_eps(eps);
    let mut w = waves(&m, beta)?;
    let eta = eps.sqrt();
    for pair in [&mut w.up, &mut w.down] {
        let s = pair[0];
        let p = pair[1];
        pair[0] = s.scaled(ONE / s.e.y);
        pair[1] = p.scaled(-eta / p.h.y);
    }
    Ok(w)
}

/// Reference solution for a plate: a layer of permittivity `eps_layer` (working frame) and
/// thickness `d` (in wavelengths) between isotropic half-spaces `eps_top` (above, `z > 0`) and
/// `eps_bottom` (below, `z < −d`).
///
/// All 2x2 matrices are indexed `[outgoing (s, p)][incoming (s, p)]` in the textbook s/p bases
/// of the half-spaces (see [`isotropic_sp_waves`]); power ratios are `|amp|² |P_out| / |P_in|`
/// with each s/p mode's own normal Poynting flux (zero columns for incoming waves carrying
/// no flux, i.e. `|P| <= FLUX_FLOOR |E| |H|`: evanescent incidence).
#[derive(Clone, Copy, Debug)]
pub struct PlateRef {
    /// Reflection of waves incident from the top.
    pub r: Matrix2<C64>,
    /// Transmission top → bottom.
    pub t: Matrix2<C64>,
    /// Reflection of waves incident from the bottom.
    pub r_below: Matrix2<C64>,
    /// Transmission bottom → top.
    pub t_below: Matrix2<C64>,
    /// Power ratios of `r`.
    pub power_r: Matrix2<f64>,
    /// Power ratios of `t`.
    pub power_t: Matrix2<f64>,
    /// Power ratios of `r_below`.
    pub power_r_below: Matrix2<f64>,
    /// Power ratios of `t_below`.
    pub power_t_below: Matrix2<f64>,
    /// Normal wave-vector components of the layer modes `[up0, up1, down0, down1]`.
    pub q_layer: [C64; 4],
}

/// Blocks `[[A11, A12], [A21, A22]]` of a 4x4 scattering matrix.
fn blocks(s: &Matrix4<C64>) -> [[Matrix2<C64>; 2]; 2] {
    let b = |r: usize, c: usize| s.fixed_view::<2, 2>(r, c).into_owned();
    [[b(0, 0), b(0, 2)], [b(2, 0), b(2, 2)]]
}

/// [`plate_reference`], reporting failures instead of panicking.
pub fn try_plate_reference(
    eps_top: C64,
    eps_layer: [[C64; 3]; 3],
    eps_bottom: C64,
    beta: C64,
    thickness_over_lambda: f64,
) -> Result<PlateRef, String> {
    let layer_eps = Matrix3::from_fn(|i, j| eps_layer[i][j]);
    let top = isotropic_sp_waves(eps_top, beta)?;
    let bottom = isotropic_sp_waves(eps_bottom, beta)?;
    let layer = waves(&layer_eps, beta)?;
    let sa = interface_s(&top, &layer).ok_or("top interface singular")?;
    let sb = interface_s(&layer, &bottom).ok_or("bottom interface singular")?;
    // Propagation through the layer, only with factors of modulus <= 1 (up to rounding):
    // a down mode's amplitude at z = −d is exp(−i k0 q d) times its amplitude at z = 0
    // (Im q <= 0), an up mode's amplitude at z = 0 is exp(+i k0 q d) times that at z = −d
    // (Im q >= 0).
    let k0d = 2.0 * std::f64::consts::PI * thickness_over_lambda;
    let i = C64::new(0.0, 1.0);
    let pd = Matrix2::from_diagonal(&nalgebra::Vector2::new(
        (-i * layer.down[0].q * k0d).exp(),
        (-i * layer.down[1].q * k0d).exp(),
    ));
    let pu = Matrix2::from_diagonal(&nalgebra::Vector2::new(
        (i * layer.up[0].q * k0d).exp(),
        (i * layer.up[1].q * k0d).exp(),
    ));
    let [[a11, a12], [a21, a22]] = blocks(&sa);
    // Refer the layer-side amplitudes of the top interface to the plane z = −d.
    let (a12, a21, a22) = (a12 * pu, pd * a21, pd * a22 * pu);
    let [[b11, b12], [b21, b22]] = blocks(&sb);
    // Redheffer star product of [[A11, A12], [A21, A22]] and [[B11, B12], [B21, B22]].
    let id = Matrix2::<C64>::identity();
    let inv1 = (id - a22 * b11)
        .try_inverse()
        .ok_or("multiple-reflection matrix singular")?;
    let inv2 = (id - b11 * a22)
        .try_inverse()
        .ok_or("multiple-reflection matrix singular")?;
    let r = a11 + a12 * b11 * inv1 * a21;
    let t = b21 * inv1 * a21;
    let t_below = a12 * inv2 * b12;
    let r_below = b22 + b21 * inv1 * a22 * b12;
    let pw = |m: &Matrix2<C64>, out: &[Wave; 2], inc: &[Wave; 2]| {
        Matrix2::from_fn(|a, b| {
            let fi = inc[b].flux().abs();
            if fi > FLUX_FLOOR * inc[b].e.norm() * inc[b].h.norm() {
                m[(a, b)].norm_sqr() * out[a].flux().abs() / fi
            } else {
                0.0
            }
        })
    };
    let all = [r, t, r_below, t_below];
    if all
        .iter()
        .any(|m| m.iter().any(|z| !z.re.is_finite() || !z.im.is_finite()))
    {
        return Err("non-finite plate amplitudes".into());
    }
    Ok(PlateRef {
        r,
        t,
        r_below,
        t_below,
        power_r: pw(&r, &top.up, &top.down),
        power_t: pw(&t, &bottom.down, &top.down),
        power_r_below: pw(&r_below, &bottom.down, &bottom.up),
        power_t_below: pw(&t_below, &top.up, &bottom.up),
        q_layer: [
            layer.up[0].q,
            layer.up[1].q,
            layer.down[0].q,
            layer.down[1].q,
        ],
    })
}

/// Reference solution for a plate (see [`PlateRef`]); panics if the configuration is singular.
pub fn plate_reference(
    eps_top: C64,
    eps_layer: [[C64; 3]; 3],
    eps_bottom: C64,
    beta: C64,
    thickness_over_lambda: f64,
) -> PlateRef {
    try_plate_reference(eps_top, eps_layer, eps_bottom, beta, thickness_over_lambda)
        .unwrap_or_else(|e| panic!("plate reference failed: {e}"))
}

/// A 3x3 complex matrix as nested arrays (the plate API's layer permittivity).
pub fn to_array(m: &Matrix3<C64>) -> [[C64; 3]; 3] {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| m[(i, j)]))
}

/// Reference solution for a stack: layers of permittivity `layers[i].0` (working frame) and
/// thickness `layers[i].1` (in wavelengths), from the top down, between isotropic half-spaces
/// `eps_top` (above) and `eps_bottom` (below). Reflection and transmission of waves incident
/// from the top, in the textbook s/p bases of the half-spaces (as [`PlateRef`]; the
/// transmitted wave referred to the bottom face), with their power ratios.
#[derive(Clone, Copy, Debug)]
pub struct StackRef {
    /// Reflection of waves incident from the top.
    pub r: Matrix2<C64>,
    /// Transmission top → bottom.
    pub t: Matrix2<C64>,
    /// Power ratios of `r`.
    pub power_r: Matrix2<f64>,
    /// Power ratios of `t`.
    pub power_t: Matrix2<f64>,
    /// `|P_out| / |P_in|` of the s waves of the two half-spaces (0 if either carries none).
    pub flux_ratio: f64,
}

/// [`StackRef`] by Redheffer star products of the interfaces' scattering matrices, top down,
/// each layer's amplitudes referred to its bottom face by factors of modulus <= 1 (the scheme of
/// [`try_plate_reference`], repeated per layer).
pub fn try_stack_reference(
    eps_top: C64,
    layers: &[(Matrix3<C64>, f64)],
    eps_bottom: C64,
    beta: C64,
) -> Result<StackRef, String> {
    let top = isotropic_sp_waves(eps_top, beta)?;
    let bottom = isotropic_sp_waves(eps_bottom, beta)?;
    let media: Vec<Waves> = layers
        .iter()
        .map(|(eps, _)| waves(eps, beta))
        .collect::<Result<_, _>>()?;
    let id = Matrix2::<C64>::identity();
    let i = C64::new(0.0, 1.0);
    let mut above = top;
    let mut s: Option<[[Matrix2<C64>; 2]; 2]> = None;
    for (k, below) in media.iter().chain(std::iter::once(&bottom)).enumerate() {
        let b = blocks(&interface_s(&above, below).ok_or("interface singular")?);
        s = Some(match s {
            None => b,
            Some([[a11, a12], [a21, a22]]) => {
                // Refer the layer-side amplitudes to the bottom face of layer k − 1.
                let layer = &media[k - 1];
                let k0d = 2.0 * std::f64::consts::PI * layers[k - 1].1;
                let pd = Matrix2::from_diagonal(&nalgebra::Vector2::new(
                    (-i * layer.down[0].q * k0d).exp(),
                    (-i * layer.down[1].q * k0d).exp(),
                ));
                let pu = Matrix2::from_diagonal(&nalgebra::Vector2::new(
                    (i * layer.up[0].q * k0d).exp(),
                    (i * layer.up[1].q * k0d).exp(),
                ));
                let (a12, a21, a22) = (a12 * pu, pd * a21, pd * a22 * pu);
                let [[b11, b12], [b21, b22]] = b;
                let inv1 = (id - a22 * b11)
                    .try_inverse()
                    .ok_or("multiple-reflection matrix singular")?;
                let inv2 = (id - b11 * a22)
                    .try_inverse()
                    .ok_or("multiple-reflection matrix singular")?;
                [
                    [a11 + a12 * b11 * inv1 * a21, a12 * inv2 * b12],
                    [b21 * inv1 * a21, b22 + b21 * inv1 * a22 * b12],
                ]
            }
        });
        above = *below;
    }
    let [[r, _], [t, _]] = s.ok_or("no interface")?;
    if [r, t]
        .iter()
        .any(|m| m.iter().any(|z| !z.re.is_finite() || !z.im.is_finite()))
    {
        return Err("non-finite stack amplitudes".into());
    }
    let pw = |m: &Matrix2<C64>, out: &[Wave; 2], inc: &[Wave; 2]| {
        Matrix2::from_fn(|a, b| {
            let fi = inc[b].flux().abs();
            if fi > FLUX_FLOOR * inc[b].e.norm() * inc[b].h.norm() {
                m[(a, b)].norm_sqr() * out[a].flux().abs() / fi
            } else {
                0.0
            }
        })
    };
    let (fi, fo) = (top.down[0].flux().abs(), bottom.down[0].flux().abs());
    let carried = |w: &Wave| w.flux().abs() > FLUX_FLOOR * w.e.norm() * w.h.norm();
    let flux_ratio = if carried(&top.down[0]) && carried(&bottom.down[0]) {
        fo / fi
    } else {
        0.0
    };
    Ok(StackRef {
        r,
        t,
        power_r: pw(&r, &top.up, &top.down),
        power_t: pw(&t, &bottom.down, &top.down),
        flux_ratio,
    })
}
