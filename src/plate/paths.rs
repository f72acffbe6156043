//! The path-class expansion of the slab (eqs. S20-S26, docs/physics.md §4).
//!
//! Expanding `(I − D)⁻¹ = Σₙ Dⁿ` writes each Jones matrix as a sum over path classes
//! `J(k) = Σ_c A_c exp(i k d Q_c)`: a class collects every internal path with the same number of
//! o and e traversals in each direction (`counts = [o↓, e↓, o↑, e↑]`), which share the phase
//! `k d Q_c`, `Q_c = −n_o↓ q_o↓ − n_e↓ q_e↓ + n_o↑ q_o↑ + n_e↑ q_e↑` (the supplemental's `k d ΔP_c`
//! for a plane-parallel plate). Amplitudes `A_c` are products of interface coefficients and do not
//! depend on `k` at fixed indices. Orders beyond the chosen `N` are summed incoherently in
//! closed form ([`IncoherentTail`]).

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

/// The reflected or transmitted lobe of the slab.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lobe {
    /// Reflection: the direct top reflection (index 0), then the classes of each order.
    Reflection,
    /// Transmission.
    Transmission,
}

impl Lobe {
    /// Both lobes, in the order of [`crate::plate::slab::SlabMueller`]'s fields.
    pub const BOTH: [Lobe; 2] = [Lobe::Reflection, Lobe::Transmission];

    /// The classes of orders `0..=order` (the direct reflection included).
    pub fn classes(self, order: usize) -> usize {
        let n = order + 1;
        match self {
            Lobe::Transmission => n * (n + 1) * (n + 2) / 3,
            Lobe::Reflection => (n + 1) * (n + 2) * (2 * n + 3) / 6,
        }
    }

    /// The index of class `(n, i, j)`: order `n`, `i` e-traversals down, `j` up (a fixed
    /// layout: classes of lower orders first, then by `i` and `j`).
    pub fn index(self, n: usize, i: usize, j: usize) -> usize {
        match self {
            Lobe::Transmission => Lobe::Transmission.classes_below(n) + i * (n + 1) + j,
            Lobe::Reflection => Lobe::Reflection.classes_below(n) + i * (n + 2) + j,
        }
    }

    /// Classes of orders below `n` (the direct reflection included).
    fn classes_below(self, n: usize) -> usize {
        match n {
            0 => usize::from(self == Lobe::Reflection),
            n => self.classes(n - 1),
        }
    }

    /// The traversal counts `[o↓, e↓, o↑, e↑]` and the order of class `index`.
    pub fn class(self, index: usize) -> (Counts, usize) {
        if self == Lobe::Reflection && index == 0 {
            return ([0; 4], 0);
        }
        let n = (0..).find(|&n| self.classes(n) > index).expect("an order");
        let k = index - self.classes_below(n);
        let (cols, ups) = match self {
            Lobe::Transmission => (n + 1, n),
            Lobe::Reflection => (n + 2, n + 1),
        };
        let (i, j) = (k / cols, k % cols);
        let c = |x: usize| x as u16;
        ([c(n + 1 - i), c(i), c(ups - j), c(j)], n)
    }
}

/// The amplitudes of every path class of both lobes up to one order, in the layout of
/// [`Lobe::index`], and the internal waves that enter the next order (for the incoherent tail):
/// the expansion as a dynamic programme over the stages of the internal waves, by class and by
/// the mode of their last traversal (a reflection maps mode `m` to `m'` by the scalar
/// `r[m'][m]`, so a stage holds one row vector per cell: the amplitude per input polarisation).
#[derive(Clone, Debug)]
pub struct ClassAmplitudes {
    /// Highest order the storage holds.
    capacity: usize,
    /// Highest order expanded by the last [`ClassAmplitudes::expand`].
    pub order: usize,
    /// Reflected classes ([`Lobe::Reflection`]'s layout).
    pub reflection: Vec<Matrix2<C64>>,
    /// Transmitted classes, flux factor included.
    pub transmission: Vec<Matrix2<C64>>,
    /// Per mode `m` of the waves entering the traversal after the last order,
    /// `Σ_cells conj(v_c1) v_c2` as the vectorised-coherency row `2 c1 + c2`.
    pub populations: [[C64; 4]; 2],
    /// The same waves summed coherently (row `m`: mode `m`), for an isotropic layer.
    pub state: Matrix2<C64>,
    down: Vec<[C64; 2]>,
    up: Vec<[C64; 2]>,
}

/// Squared amplitude below which an internal wave is dropped (amplitude < 1e-15 of the
/// incident wave: it cannot matter).
const NEGLIGIBLE: f64 = 1e-30;

impl ClassAmplitudes {
    /// Storage for orders up to `capacity`.
    pub fn with_capacity(capacity: usize) -> Self {
        let stage = 2 * (capacity + 3) * (capacity + 3);
        let zero = Matrix2::zeros();
        ClassAmplitudes {
            capacity,
            order: 0,
            reflection: vec![zero; Lobe::Reflection.classes(capacity)],
            transmission: vec![zero; Lobe::Transmission.classes(capacity)],
            populations: [[C64::new(0.0, 0.0); 4]; 2],
            state: zero,
            down: vec![[C64::new(0.0, 0.0); 2]; stage],
            up: vec![[C64::new(0.0, 0.0); 2]; stage],
        }
    }

    /// The highest order the storage holds.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Expands the plate of `blocks` to `order` (at most the capacity) for the lobes of `want`.
    pub fn expand(&mut self, b: &SlabBlocks, order: usize, want: Want) {
        assert!(order <= self.capacity, "order {order} beyond the capacity");
        self.order = order;
        let zero = Matrix2::zeros();
        if want.reflection {
            self.reflection[..Lobe::Reflection.classes(order)].fill(zero);
            self.reflection[0] = b.r1;
        }
        if want.transmission {
            self.transmission[..Lobe::Transmission.classes(order)].fill(zero);
        }
        let ft = C64::new(b.flux.sqrt(), 0.0);
        let one = C64::new(1.0, 0.0);
        let z = [C64::new(0.0, 0.0); 2];
        // Stage Dₙ (n + 1 traversals down, i of them e; n up, j of them e): cell
        // (i (n + 1) + j) 2 + m.
        self.down[..4].fill(z);
        self.down[0] = [b.t1[(0, 0)], b.t1[(0, 1)]];
        self.down[2 + 1] = [b.t1[(1, 0)], b.t1[(1, 1)]];
        for n in 0..=order {
            let (rows, cols, up_cols) = (n + 2, n + 1, n + 2);
            let (t_base, r_base) = (
                Lobe::Transmission.index(n, 0, 0),
                Lobe::Reflection.index(n, 0, 0),
            );
            self.up[..2 * rows * up_cols].fill(z);
            for i in 0..rows {
                for j in 0..cols {
                    for m in 0..2 {
                        let v = self.down[2 * (i * cols + j) + m];
                        if v[0].norm_sqr() + v[1].norm_sqr() < NEGLIGIBLE {
                            continue;
                        }
                        if want.transmission {
                            let a = &mut self.transmission[t_base + i * cols + j];
                            add_outer(a, &b.t2, m, &v, ft);
                        }
                        // Uₙ: after the bottom reflection (n + 1 up, j of them e).
                        for to in 0..2 {
                            let r = b.r2[(to, m)];
                            let u = &mut self.up[2 * (i * up_cols + j + to) + to];
                            u[0] += r * v[0];
                            u[1] += r * v[1];
                        }
                    }
                }
            }
            // Dₙ₊₁: after the top reflection.
            let next_cols = n + 2;
            self.down[..2 * (n + 3) * next_cols].fill(z);
            for i in 0..rows {
                for j in 0..up_cols {
                    for m in 0..2 {
                        let v = self.up[2 * (i * up_cols + j) + m];
                        if v[0].norm_sqr() + v[1].norm_sqr() < NEGLIGIBLE {
                            continue;
                        }
                        if want.reflection {
                            let a = &mut self.reflection[r_base + i * up_cols + j];
                            add_outer(a, &b.t3, m, &v, one);
                        }
                        for to in 0..2 {
                            let r = b.r3[(to, m)];
                            let d = &mut self.down[2 * ((i + to) * next_cols + j) + to];
                            d[0] += r * v[0];
                            d[1] += r * v[1];
                        }
                    }
                }
            }
        }
        let cells = 2 * (order + 3) * (order + 2);
        self.populations = [[C64::new(0.0, 0.0); 4]; 2];
        self.state = zero;
        for (cell, v) in self.down[..cells].iter().enumerate() {
            let m = cell % 2;
            for c1 in 0..2 {
                self.state[(m, c1)] += v[c1];
                for c2 in 0..2 {
                    self.populations[m][2 * c1 + c2] += v[c1].conj() * v[c2];
                }
            }
        }
    }

    /// The incoherent tail of the orders after the expanded ones at `lambda_nm`
    /// ([`IncoherentTail`]; `merged` for an isotropic layer, whose s and p share one phase).
    pub fn tail(&self, b: &SlabBlocks, merged: bool, lambda_nm: f64, want: Want) -> IncoherentTail {
        if merged {
            IncoherentTail::merged(b, &self.state, lambda_nm, want)
        } else {
            IncoherentTail::new(b, &self.populations, lambda_nm, want)
        }
    }
}

/// `a += s · t[:, m] ⊗ v` (the class amplitude of waves in mode `m` leaving through `t`).
#[inline]
fn add_outer(a: &mut Matrix2<C64>, t: &Matrix2<C64>, m: usize, v: &[C64; 2], s: C64) {
    if v[0] == C64::new(0.0, 0.0) && v[1] == C64::new(0.0, 0.0) {
        return;
    }
    let (t0, t1) = (t[(0, m)] * s, t[(1, m)] * s);
    a[(0, 0)] += t0 * v[0];
    a[(0, 1)] += t0 * v[1];
    a[(1, 0)] += t1 * v[0];
    a[(1, 1)] += t1 * v[1];
}

impl PathExpansion {
    /// Expands `optics` to order `n_max` (round trips), evaluating the incoherent tail's
    /// attenuation at `lambda_nm`.
    pub fn new(optics: &SlabOptics, n_max: usize, lambda_nm: f64, want: Want) -> Self {
        let merged = optics.layer_modes().down[0].kind == crate::optics::modes::ModeKind::S;
        Self::from_blocks(&optics.blocks(), merged, n_max, want, Some(lambda_nm))
    }

    /// Expands the plate of `blocks` to order `n_max`; `merged` for an isotropic layer (one
    /// phase for s and p: the classes of an order are summed into one); the incoherent tail of
    /// the higher orders at `tail_at` (nm), or zero.
    pub fn from_blocks(
        b: &SlabBlocks,
        merged: bool,
        n_max: usize,
        want: Want,
        tail_at: Option<f64>,
    ) -> Self {
        let mut c = ClassAmplitudes::with_capacity(n_max);
        c.expand(b, n_max, want);
        let qs = [-b.q[0], -b.q[1], b.q[2], b.q[3]];
        let class = |counts: Counts, order: usize, amplitude: Matrix2<C64>| PathClass {
            counts,
            order,
            q: counts.iter().zip(qs).map(|(n, q)| q * f64::from(*n)).sum(),
            amplitude,
        };
        let list = |lobe: Lobe, amps: &[Matrix2<C64>]| -> Vec<PathClass> {
            let all = amps[..lobe.classes(n_max)]
                .iter()
                .enumerate()
                .map(|(k, a)| {
                    let (counts, order) = lobe.class(k);
                    class(counts, order, *a)
                });
            if !merged {
                return all.filter(|p| p.amplitude != Matrix2::zeros()).collect();
            }
            // One class per order (and the direct reflection), all traversals counted as o.
            let mut out: Vec<PathClass> = Vec::new();
            for p in all {
                let counts = [p.counts[0] + p.counts[1], 0, p.counts[2] + p.counts[3], 0];
                match out.last_mut() {
                    Some(last) if last.counts == counts => last.amplitude += p.amplitude,
                    _ => out.push(class(counts, p.order, p.amplitude)),
                }
            }
            out
        };
        let reflection = if want.reflection {
            list(Lobe::Reflection, &c.reflection)
        } else {
            Vec::new()
        };
        let transmission = if want.transmission {
            list(Lobe::Transmission, &c.transmission)
        } else {
            Vec::new()
        };
        let tail = match tail_at {
            Some(lambda_nm) => c.tail(b, merged, lambda_nm, want),
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
    /// traversal (`x0[m]`: the population row of mode `m`, [`ClassAmplitudes::populations`]), one round
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
