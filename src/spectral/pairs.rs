//! Pairs of path classes grouped by what their interference depends on.
//!
//! A coherency of the plate is a double sum over pairs `(a, b)` of path classes
//! ([`crate::plate::paths`]), `cross(A_a, A_b) e^{ik d (Q_b − Q̄_a)}`. The phase depends on the
//! classes only through their count difference `Δ = counts_b − counts_a`, the attenuation (in
//! an absorbing layer) through their count sum: pairs that share both share their whole
//! spectral factor and are summed first. The pair `(b, a)` contributes the conjugate of
//! `(a, b)` (`Re(A K A⁻¹)` of the Mueller matrix is then twice that of one), so only the half
//! with `Δ ≥ 0` (lexicographically) is kept, with weight 2.

use crate::plate::paths::{Counts, PathClass};
use crate::spectral::fringe::FringeRule;
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64 as C64;

/// One group of pairs, in one lobe. Groups of one `Δ` are also split by their highest order,
/// so that weak high orders can take fewer nodes than the strong low ones.
pub struct Group {
    /// `Δ = counts_b − counts_a`, the larger half (first non-zero component > 0) or zero.
    pub delta: [i32; 4],
    /// The highest coherent order among its classes.
    pub order: usize,
    /// `counts_a + counts_b` of its pairs in an absorbing layer (their attenuation is
    /// `e^{−k d Σ_m sum_m Im Q_m}`), else zero.
    pub sum: [i32; 4],
    /// Its pairs: a range of [`Groups::pairs`].
    pub pairs: std::ops::Range<usize>,
    /// `Σ weight |A_a| |A_b|` at the centre, each times its least attenuation over the band.
    pub strength: f64,
    /// Its group path at the centre (nm).
    pub group_path: f64,
}

/// `Σ_m Δ_m x_m`.
pub fn dot(delta: &[i32; 4], x: &[f64; 4]) -> f64 {
    (0..4).map(|m| f64::from(delta[m]) * x[m]).sum()
}

/// The count difference `b − a`.
fn difference(a: &Counts, b: &Counts) -> [i32; 4] {
    std::array::from_fn(|m| i32::from(b[m]) - i32::from(a[m]))
}

/// True if `d` is zero or its first non-zero component is positive.
fn is_canonical(d: &[i32; 4]) -> bool {
    d.iter().find(|x| **x != 0).is_none_or(|x| *x > 0)
}

/// One pair: the classes' counts, and 1 for `a = b`, 2 otherwise.
pub type Pair = (Counts, Counts, f64);

/// The groups of one lobe and their pairs (each group's pairs are a range of them).
pub struct Groups {
    /// The groups.
    pub groups: Vec<Group>,
    /// Every pair, group by group.
    pub pairs: Vec<Pair>,
}

/// What decides which pairs are kept.
pub struct Selection<'a> {
    /// Plate thickness (nm).
    pub thickness_nm: f64,
    /// Group index per traversal at the band's centre.
    pub group: [f64; 4],
    /// An absorbing layer: pairs are also grouped by their attenuation.
    pub absorbing: bool,
    /// The least attenuation exponent per traversal over the band
    /// ([`crate::spectral::amplitudes::least_attenuation`]): a class's strength is its
    /// amplitude times `e^{−counts · loss}`.
    pub loss: [f64; 4],
    /// The rule whose visibility of a fringe of group path `G` decides ([`FringeRule::visibility`]).
    pub rule: &'a FringeRule,
    /// A group whose strength times its visibility is below this is dropped.
    pub drop: f64,
}

/// The pairs of `classes` grouped (by count difference, order and, in an absorbing layer,
/// attenuation), each with its group path and strength; invisible groups dropped (the `Δ = 0`
/// groups, the incoherent sums, are always kept). Pairs weaker than a thousandth of
/// [`Selection::drop`] are not formed at all.
pub fn groups(classes: &[PathClass], s: &Selection) -> Groups {
    let d = s.thickness_nm;
    // Classes by decreasing amplitude: the inner loop stops at the first pair too weak to
    // matter even at full visibility. Each class's group path, so that a pair's is a
    // difference.
    let mut by_norm: Vec<(f64, usize, f64)> = classes
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let counts = c.counts.map(i32::from);
            let attenuation = (-dot(&counts, &s.loss)).exp();
            (
                c.amplitude.norm() * attenuation,
                i,
                d * dot(&counts, &s.group),
            )
        })
        .collect();
    by_norm.sort_by(|x, y| y.0.total_cmp(&x.0));
    let weakest = s.drop * PAIR_SHARE;
    let mut pairs: Vec<(u64, usize, usize, f64)> = Vec::new();
    for (ia, &(na, a, ga)) in by_norm.iter().enumerate() {
        if na * na < weakest {
            break;
        }
        for &(nb, b, gb) in &by_norm[ia..] {
            let weight = if a == b { 1.0 } else { 2.0 };
            let amp = na * nb * weight;
            if amp < weakest {
                break;
            }
            if a != b && amp * s.rule.visibility(gb - ga) < weakest {
                continue;
            }
            let delta = difference(&classes[a].counts, &classes[b].counts);
            let (delta, a, b) = if is_canonical(&delta) {
                (delta, a, b)
            } else {
                (delta.map(|x| -x), b, a)
            };
            let order = classes[a].order.max(classes[b].order);
            let sum = if s.absorbing {
                std::array::from_fn(|m| {
                    i32::from(classes[a].counts[m]) + i32::from(classes[b].counts[m])
                })
            } else {
                [0; 4]
            };
            pairs.push((key(&delta, order, &sum), a, b, amp));
        }
    }
    pairs.sort_unstable_by_key(|p| (p.0, p.1, p.2));
    let mut out: Vec<Group> = Vec::new();
    let mut all: Vec<Pair> = Vec::with_capacity(pairs.len());
    let mut last_key = u64::MAX;
    for (k, a, b, amp) in pairs {
        all.push((
            classes[a].counts,
            classes[b].counts,
            if a == b { 1.0 } else { 2.0 },
        ));
        let end = all.len();
        match out.last_mut() {
            Some(g) if k == last_key => {
                g.pairs.end = end;
                g.strength += amp;
            }
            _ => {
                let delta = difference(&classes[a].counts, &classes[b].counts);
                let sum = if s.absorbing {
                    std::array::from_fn(|m| {
                        i32::from(classes[a].counts[m]) + i32::from(classes[b].counts[m])
                    })
                } else {
                    [0; 4]
                };
                out.push(Group {
                    delta,
                    order: classes[a].order.max(classes[b].order),
                    sum,
                    pairs: end - 1..end,
                    strength: amp,
                    group_path: d * dot(&delta, &s.group),
                });
                last_key = k;
            }
        }
    }
    out.retain(|g| g.delta == [0; 4] || g.strength * s.rule.visibility(g.group_path) >= s.drop);
    Groups {
        groups: out,
        pairs: all,
    }
}

/// A pair weaker than this share of [`Selection::drop`] (times its visibility) is not formed:
/// a group of them stays below the drop threshold unless it has a hundred such pairs.
const PAIR_SHARE: f64 = 0.01;

/// The sort key of a group: its count difference, order and count sum packed in 64 bits
/// (counts are below 2 (`MAX_ORDER` + 2) + 1 = 21, so 6 bits each, offset by 32 for the
/// signed differences).
fn key(delta: &[i32; 4], order: usize, sum: &[i32; 4]) -> u64 {
    let mut k = 0u64;
    for x in delta {
        k = (k << 6) | ((x + 32) as u64 & 63);
    }
    k = (k << 4) | (order as u64 & 15);
    for x in sum {
        k = (k << 6) | (*x as u64 & 63);
    }
    k
}

/// The entries of a coherency that `M00` needs: `M00 = ½ Re(K₀₀ + K₀₃ + K₃₀ + K₃₃)`.
pub const INTENSITY_ENTRIES: [(usize, usize); 4] = [(0, 0), (0, 3), (3, 0), (3, 3)];

/// `acc += s conj(x) ⊗ y` (all 16 entries, or with `intensity` only [`INTENSITY_ENTRIES`]).
#[inline]
pub fn cross_add(
    acc: &mut Matrix4<C64>,
    x: &Matrix2<C64>,
    y: &Matrix2<C64>,
    s: f64,
    intensity: bool,
) {
    let xc = [
        x[(0, 0)].conj() * s,
        x[(0, 1)].conj() * s,
        x[(1, 0)].conj() * s,
        x[(1, 1)].conj() * s,
    ];
    if intensity {
        acc[(0, 0)] += xc[0] * y[(0, 0)];
        acc[(0, 3)] += xc[1] * y[(0, 1)];
        acc[(3, 0)] += xc[2] * y[(1, 0)];
        acc[(3, 3)] += xc[3] * y[(1, 1)];
        return;
    }
    // Kronecker product: entry (2 r1 + r2, 2 c1 + c2) = conj(x[r1][c1]) y[r2][c2].
    for r1 in 0..2 {
        for c1 in 0..2 {
            let xv = xc[2 * r1 + c1];
            for r2 in 0..2 {
                for c2 in 0..2 {
                    acc[(2 * r1 + r2, 2 * c1 + c2)] += xv * y[(r2, c2)];
                }
            }
        }
    }
}

/// `acc += m w` over the entries the output needs.
#[inline]
pub fn add_scaled(acc: &mut Matrix4<C64>, m: &Matrix4<C64>, w: C64, intensity: bool) {
    if intensity {
        for e in INTENSITY_ENTRIES {
            acc[e] += m[e] * w;
        }
    } else {
        *acc += m * w;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::mueller;

    #[test]
    fn cross_add_is_the_kronecker_product() {
        let x = Matrix2::new(
            C64::new(0.3, -0.2),
            C64::new(-0.1, 0.5),
            C64::new(0.7, 0.05),
            C64::new(-0.4, -0.6),
        );
        let y = Matrix2::new(
            C64::new(-0.25, 0.1),
            C64::new(0.6, -0.3),
            C64::new(0.02, 0.9),
            C64::new(0.5, 0.45),
        );
        let mut acc = Matrix4::zeros();
        cross_add(&mut acc, &x, &y, 2.0, false);
        assert!((acc - mueller::cross(&x, &y) * C64::new(2.0, 0.0)).norm() < 1e-15);
        let mut m00 = Matrix4::zeros();
        cross_add(&mut m00, &x, &y, 2.0, true);
        for e in INTENSITY_ENTRIES {
            assert!((m00[e] - acc[e]).norm() < 1e-15);
        }
    }
}
