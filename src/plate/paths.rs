//! The path-class expansion of the slab (eqs. S20-S26, docs/physics.md §4).
//!
//! Expanding `(I − D)⁻¹ = Σₙ Dⁿ` writes each Jones matrix as a sum over path classes
//! `J(k) = Σ_c A_c exp(i k d Q_c)`: a class collects every internal path with the same number of
//! o and e traversals in each direction (`counts = [o↓, e↓, o↑, e↑]`), which share the phase
//! `k d Q_c`, `Q_c = −n_o↓ q_o↓ − n_e↓ q_e↓ + n_o↑ q_o↑ + n_e↑ q_e↑` (the supplemental's `k d ΔP_c`
//! for a plane-parallel plate). Amplitudes `A_c` are products of interface coefficients and do not
//! depend on `k` at fixed indices. Orders beyond the chosen `N` are summed incoherently in
//! closed form ([`IncoherentTail`]).

use crate::cmath;
use crate::optics::mueller;
use crate::plate::slab::{SlabBlocks, SlabOptics, Want};
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;

/// Traversal counts `[o↓, e↓, o↑, e↑]` of a path class.
pub type Counts = [u16; 4];

/// One path class of the reflected or transmitted field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathClass {
    /// Traversals per mode and direction.
    pub counts: Counts,
    /// Number of internal round trips.
    pub order: usize,
    /// `Q_c`: the class's phase is `k0 d Q_c` (complex with absorption).
    pub q: C64,
    /// Flux-normalised Jones amplitude (s/p in and out).
    pub amplitude: Matrix2<C64>,
}

/// The closed-form incoherent sum of all orders `> N` (docs/physics.md §4): coherence between
/// o and e, and between different paths, is dropped; mode populations propagate with
/// `|P|²` and reflect with `|r|²`. Stored as Mueller matrices (Mitsuba's convention).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IncoherentTail {
    /// Reflection of orders `> N` (zero if not asked for).
    pub r: Matrix4<f64>,
    /// Transmission of orders `> N` (zero if not asked for).
    pub t: Matrix4<f64>,
}

/// Path classes of orders `0..=N` and the incoherent remainder, at one wavelength.
#[derive(Clone, Debug, PartialEq)]
pub struct PathExpansion {
    /// Reflected classes, the direct top reflection first (counts all zero, order 0).
    pub reflection: Vec<PathClass>,
    /// Transmitted classes.
    pub transmission: Vec<PathClass>,
    /// Highest coherent order `N`.
    pub order: usize,
    /// Slab thickness (nm).
    pub thickness_nm: f64,
    /// Orders `> N`, incoherent.
    pub tail: IncoherentTail,
}

/// The internal waves of one stage of the expansion, by class and by the mode of their last
/// traversal: cell `(i, j, m)` (`i` e traversals down, `j` up; `m` the mode, 0 = o, 1 = e)
/// holds the row vector of that mode's amplitude per input polarisation (s, p). A reflection
/// maps mode `m` to `m'` by the scalar `r[m'][m]`, so a stage needs only these row vectors.
struct Stage {
    cells: Vec<[C64; 2]>,
    present: Vec<bool>,
    cols: usize,
}

/// Squared amplitude below which an internal path class is dropped.
const NEGLIGIBLE: f64 = 1e-30;

impl Stage {
    fn new(rows: usize, cols: usize) -> Self {
        Stage {
            cells: vec![[C64::new(0.0, 0.0); 2]; rows * cols * 2],
            present: vec![false; rows * cols * 2],
            cols,
        }
    }

    fn index(&self, i: usize, j: usize, m: usize) -> usize {
        (i * self.cols + j) * 2 + m
    }

    fn add(&mut self, i: usize, j: usize, m: usize, v: [C64; 2]) {
        let k = self.index(i, j, m);
        self.cells[k][0] += v[0];
        self.cells[k][1] += v[1];
        self.present[k] = true;
    }

    /// Every present cell as `(i, j, m, v)`.
    fn iter(&self) -> impl Iterator<Item = (usize, usize, usize, &[C64; 2])> {
        let cols = self.cols;
        self.cells
            .iter()
            .zip(&self.present)
            .enumerate()
            .filter_map(move |(k, (v, p))| p.then_some(((k / 2) / cols, (k / 2) % cols, k % 2, v)))
    }

    /// The stage after a reflection `r` (mode `m` → `m'`) and the next traversal, down (the
    /// first index counts e) or up (the second does).
    fn reflect(&self, r: &Matrix2<C64>, down: bool) -> Stage {
        let rows = self.cells.len() / (2 * self.cols);
        let (rows, cols) = if down {
            (rows + 1, self.cols)
        } else {
            (rows, self.cols + 1)
        };
        let mut out = Stage::new(rows, cols);
        for (i, j, m, v) in self.iter() {
            for to in 0..2 {
                let w = [r[(to, m)] * v[0], r[(to, m)] * v[1]];
                // Paths this weak cannot matter (amplitude < 1e-15 of the incident wave).
                if w[0].norm_sqr() + w[1].norm_sqr() < NEGLIGIBLE {
                    continue;
                }
                let (di, dj) = if down { (to, 0) } else { (0, to) };
                out.add(i + di, j + dj, to, w);
            }
        }
        out
    }

    /// The class amplitudes `Σ_m t[:, m] ⊗ v_m` (leaving through `t`, times `scale`) by class.
    fn leave(&self, t: &Matrix2<C64>, scale: C64) -> Vec<(usize, usize, Matrix2<C64>)> {
        let mut out: Vec<(usize, usize, Matrix2<C64>)> = Vec::new();
        for (i, j, m, v) in self.iter() {
            let a = Matrix2::new(
                t[(0, m)] * v[0],
                t[(0, m)] * v[1],
                t[(1, m)] * v[0],
                t[(1, m)] * v[1],
            ) * scale;
            match out.last_mut() {
                Some(last) if last.0 == i && last.1 == j => last.2 += a,
                _ => out.push((i, j, a)),
            }
        }
        out
    }

    /// Per mode `m`, `Σ_cells conj(v_c1) v_c2` as the vectorised-coherency row `2 c1 + c2`:
    /// the populations of the next traversal's modes, per input coherency.
    fn populations(&self) -> [[C64; 4]; 2] {
        let mut x = [[C64::new(0.0, 0.0); 4]; 2];
        for (_, _, m, v) in self.iter() {
            for c1 in 0..2 {
                for c2 in 0..2 {
                    x[m][2 * c1 + c2] += v[c1].conj() * v[c2];
                }
            }
        }
        x
    }
}

impl PathExpansion {
    /// Expands `optics` to order `n_max` (round trips), evaluating the incoherent tail's
    /// attenuation at `lambda_nm`.
    pub fn new(optics: &SlabOptics, n_max: usize, lambda_nm: f64, want: Want) -> Self {
        let merged = optics.layer_modes().down[0].kind == crate::optics::modes::ModeKind::S;
        Self::from_blocks(&optics.blocks(), merged, n_max, want, Some(lambda_nm))
    }

    /// Expands the plate of `blocks` to order `n_max`; `merged` for an isotropic layer (one
    /// phase for s and p); the incoherent tail of the higher orders at `tail_at` (nm), or zero.
    pub fn from_blocks(
        b: &SlabBlocks,
        merged: bool,
        n_max: usize,
        want: Want,
        tail_at: Option<f64>,
    ) -> Self {
        let qs = [-b.q[0], -b.q[1], b.q[2], b.q[3]];
        let ft = C64::new(b.flux.sqrt(), 0.0);
        let class = |counts: Counts, order: usize, amplitude: Matrix2<C64>| PathClass {
            counts,
            order,
            q: counts.iter().zip(qs).map(|(n, q)| q * f64::from(*n)).sum(),
            amplitude,
        };
        // (n + 2)(n + 1) transmitted and (n + 2)² reflected classes at most per order n.
        let most = (n_max + 3) * (n_max + 2) * (n_max + 1) / 3 + n_max + 2;
        let mut reflection = Vec::with_capacity(if want.reflection { most } else { 0 });
        let mut transmission = Vec::with_capacity(if want.transmission { most } else { 0 });
        if want.reflection {
            reflection.push(class([0; 4], 0, b.r1));
        }
        if merged {
            let tail = Self::merged_classes(
                b,
                n_max,
                want,
                tail_at,
                &mut reflection,
                &mut transmission,
                &class,
            );
            return PathExpansion {
                reflection,
                transmission,
                order: n_max,
                thickness_nm: b.thickness_nm,
                tail,
            };
        }
        // The first traversal down: mode m carries row m of t₁.
        let mut down = Stage::new(2, 1);
        down.add(0, 0, 0, [b.t1[(0, 0)], b.t1[(0, 1)]]);
        down.add(1, 0, 1, [b.t1[(1, 0)], b.t1[(1, 1)]]);
        for order in 0..=n_max {
            let n = order as u16;
            // `down`: n + 1 traversals down (i of them e), n up (j of them e).
            if want.transmission {
                for (i, j, a) in down.leave(&b.t2, ft) {
                    let (i, j) = (i as u16, j as u16);
                    transmission.push(class([n + 1 - i, i, n - j, j], order, a));
                }
            }
            let up = down.reflect(&b.r2, false);
            if want.reflection {
                for (i, j, a) in up.leave(&b.t3, C64::new(1.0, 0.0)) {
                    let (i, j) = (i as u16, j as u16);
                    reflection.push(class([n + 1 - i, i, n + 1 - j, j], order, a));
                }
            }
            down = up.reflect(&b.r3, true);
        }
        let tail = match tail_at {
            Some(lambda_nm) => IncoherentTail::new(b, &down.populations(), lambda_nm, want),
            None => IncoherentTail {
                r: Matrix4::zeros(),
                t: Matrix4::zeros(),
            },
        };
        PathExpansion {
            reflection,
            transmission,
            order: n_max,
            thickness_nm: b.thickness_nm,
            tail,
        }
    }

    /// The classes of an isotropic (merged) layer: s and p share one phase, so each order is
    /// one class, `t₂ (r₃ r₂)ⁿ t₁` (and `t₃ r₂ (r₃ r₂)ⁿ t₁` reflected); returns the tail.
    #[allow(clippy::too_many_arguments)]
    fn merged_classes(
        b: &SlabBlocks,
        n_max: usize,
        want: Want,
        tail_at: Option<f64>,
        reflection: &mut Vec<PathClass>,
        transmission: &mut Vec<PathClass>,
        class: &dyn Fn(Counts, usize, Matrix2<C64>) -> PathClass,
    ) -> IncoherentTail {
        let ft = C64::new(b.flux.sqrt(), 0.0);
        let mut state = b.t1; // just below the top, going down
        for order in 0..=n_max {
            let n = order as u16;
            if want.transmission {
                transmission.push(class(
                    [n + 1, 0, n, 0],
                    order,
                    cmath::mul2(&b.t2, &state) * ft,
                ));
            }
            let up = cmath::mul2(&b.r2, &state);
            if want.reflection {
                reflection.push(class([n + 1, 0, n + 1, 0], order, cmath::mul2(&b.t3, &up)));
            }
            state = cmath::mul2(&b.r3, &up);
        }
        match tail_at {
            Some(lambda_nm) => IncoherentTail::merged(b, &state, lambda_nm, want),
            None => IncoherentTail {
                r: Matrix4::zeros(),
                t: Matrix4::zeros(),
            },
        }
    }

    /// The coherent Jones matrices `(J_R, J_T)` of orders `0..=N` at `lambda_nm` (no tail).
    pub fn jones(&self, lambda_nm: f64) -> (Matrix2<C64>, Matrix2<C64>) {
        let kd = std::f64::consts::TAU * self.thickness_nm / lambda_nm;
        let sum = |cs: &[PathClass]| {
            cs.iter()
                .map(|c| c.amplitude * (C64::new(0.0, kd) * c.q).exp())
                .sum::<Matrix2<C64>>()
        };
        (sum(&self.reflection), sum(&self.transmission))
    }
}

impl IncoherentTail {
    /// The incoherent sum of every order after the expanded ones, as coherency
    /// superoperators: `X₀ = P̄↓ Σ_c K(A_c)` of the internal waves entering the next
    /// traversal (`x0[m]`: the population row of mode `m`, see `Stage::populations`), one round
    /// trip `P̄↓ K(r₃) P̄↑ K(r₂)`, summed as `(I − RT)⁻¹`. `P̄` keeps only the populations of
    /// the o and e modes, which have different phases: the sum runs on the two populations
    /// (a 2x2 real round trip).
    fn new(b: &SlabBlocks, x0: &[[C64; 4]; 2], lambda_nm: f64, want: Want) -> Self {
        let (pd, pu) = Self::attenuations(b, lambda_nm);
        let pop = |m: &Matrix2<C64>, i: usize, j: usize| m[(i, j)].norm_sqr();
        // One round trip on populations: r₂, ↑ attenuation, r₃, ↓ attenuation.
        let trip = |m: usize| -> [f64; 2] {
            let up: [f64; 2] = std::array::from_fn(|u| pu[u] * pop(&b.r2, u, m));
            std::array::from_fn(|d| pd[d] * (0..2).map(|u| pop(&b.r3, d, u) * up[u]).sum::<f64>())
        };
        let (c0, c1) = (trip(0), trip(1));
        let (a, bb, c, d) = (1.0 - c0[0], -c1[0], -c0[1], 1.0 - c1[1]);
        let det = a * d - bb * c;
        let mut total = Matrix4::zeros();
        let mut after_bottom = Matrix4::zeros();
        if det != 0.0 && det.is_finite() {
            let inv = [[d / det, -bb / det], [-c / det, a / det]];
            let rows = [0usize, 3];
            for col in 0..4 {
                let x = [x0[0][col] * pd[0], x0[1][col] * pd[1]];
                let t = [
                    x[0] * inv[0][0] + x[1] * inv[0][1],
                    x[0] * inv[1][0] + x[1] * inv[1][1],
                ];
                for (m, &r) in rows.iter().enumerate() {
                    total[(r, col)] = t[m];
                    after_bottom[(r, col)] = (0..2)
                        .map(|k| t[k] * (pu[m] * pop(&b.r2, m, k)))
                        .sum::<C64>();
                }
            }
        }
        Self::leave(b, &total, &after_bottom, want)
    }

    /// An isotropic (absorbing) layer: s and p share one phase, so their coherency survives
    /// the band average; the full superoperator sum `(I − RT)⁻¹ P̄↓ K(state)`.
    fn merged(b: &SlabBlocks, state: &Matrix2<C64>, lambda_nm: f64, want: Want) -> Self {
        let (pd, pu) = Self::attenuations(b, lambda_nm);
        let k = mueller::coherency;
        let (pd, pu) = (C64::new(pd[0], 0.0), C64::new(pu[0], 0.0));
        let after = k(&b.r2) * pu;
        let rt = k(&b.r3) * after * pd;
        let total = (Matrix4::identity() - rt)
            .try_inverse()
            .map(|inv| inv * (k(state) * pd))
            .unwrap_or_else(Matrix4::zeros);
        Self::leave(b, &total, &(after * total), want)
    }

    /// Intensity attenuations `(↓, ↑)` per mode of one traversal at `lambda_nm`.
    fn attenuations(b: &SlabBlocks, lambda_nm: f64) -> ([f64; 2], [f64; 2]) {
        let kd = std::f64::consts::TAU * b.thickness_nm / lambda_nm;
        let att = |q: C64, sign: f64| (-2.0 * sign * kd * q.im).exp();
        (
            [att(b.q[0], -1.0), att(b.q[1], -1.0)],
            [att(b.q[2], 1.0), att(b.q[3], 1.0)],
        )
    }

    /// The Mueller matrices of the internal sums leaving through the bottom (`total`, going
    /// down) and the top (`after_bottom`, going up).
    fn leave(
        b: &SlabBlocks,
        total: &Matrix4<C64>,
        after_bottom: &Matrix4<C64>,
        want: Want,
    ) -> Self {
        let k = mueller::coherency;
        let ft = C64::new(b.flux.sqrt(), 0.0);
        IncoherentTail {
            t: if want.transmission {
                mueller::from_coherency(&(k(&(b.t2 * ft)) * total))
            } else {
                Matrix4::zeros()
            },
            r: if want.reflection {
                mueller::from_coherency(&(k(&b.t3) * after_bottom))
            } else {
                Matrix4::zeros()
            },
        }
    }
}
