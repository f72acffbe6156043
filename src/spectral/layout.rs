//! Pairs of path classes grouped by what their interference depends on, laid out once per lobe
//! and order (they do not depend on the plate).
//!
//! A coherency of the plate is a double sum over pairs `(a, b)` of path classes
//! ([`crate::plate::paths`]), `cross(A_a, A_b) e^{ik d (Q_b − Q̄_a)}`. The phase depends on the
//! classes only through their count difference `Δ = counts_b − counts_a`, the attenuation (in
//! an absorbing layer) through their count sum: pairs that share both share their whole
//! spectral factor and are summed first. The pair `(b, a)` contributes the conjugate of
//! `(a, b)`, so only the half with `Δ ≥ 0` (lexicographically) is kept, with weight 2. The
//! groups of the pairs of orders `(m, n)` form one block, so that a query can skip every block
//! its classes are too weak for, or every pair of different orders when its round trips are
//! invisible.

use crate::plate::paths::{Counts, Lobe};
use std::ops::Range;
use std::sync::OnceLock;

/// Highest coherent order laid out.
pub const MAX_ORDER: usize = 8;

/// The pairs of one lobe's classes up to one order.
pub struct Layout {
    /// The blocks of pairs of orders `(m, n)`, `m ≤ n`.
    pub blocks: Vec<Block>,
    /// The groups, block by block.
    pub groups: Vec<Group>,
    /// The pairs `(a, b)` of class indices ([`Lobe::index`]), group by group.
    pub pairs: Vec<(u16, u16)>,
    /// Each class's counts.
    pub counts: Vec<Counts>,
    /// Each class's order.
    pub orders: Vec<u8>,
}

/// The pairs of two orders.
pub struct Block {
    /// The orders `(m, n)`, `m ≤ n`.
    pub orders: (usize, usize),
    /// Its groups: a range of [`Layout::groups`].
    pub groups: Range<usize>,
    /// Its pairs: a range of [`Layout::pairs`].
    pub pairs: Range<usize>,
}

/// Pairs with one count difference (and, in an absorbing layer's layout, one count sum).
pub struct Group {
    /// `Δ = counts_b − counts_a`, zero or with its first non-zero component positive.
    pub delta: [i32; 4],
    /// `counts_a + counts_b` in an absorbing layer's layout (the attenuation
    /// `e^{−k d Σ_m sum_m Im Q_m}`), else zero.
    pub sum: [i32; 4],
    /// Its pairs: a range of [`Layout::pairs`].
    pub pairs: Range<usize>,
}

impl Group {
    /// True for the incoherent sum of each class with itself.
    pub fn is_diagonal(&self) -> bool {
        self.delta == [0; 4]
    }
}

/// The layout of `lobe` up to `order` (at most [`MAX_ORDER`]); `absorbing` splits groups by
/// their count sum; without `cross_orders` only the pairs of classes of one order (a plate whose
/// round trips are invisible needs no other). Built on first use.
pub fn layout(lobe: Lobe, order: usize, absorbing: bool, cross_orders: bool) -> &'static Layout {
    const N: usize = MAX_ORDER + 1;
    type Layouts = [[OnceLock<Layout>; 2]; 2];
    static ALL: [[Layouts; N]; 2] =
        [const { [const { [const { [const { OnceLock::new() }; 2] }; 2] }; N] }; 2];
    let order = order.min(MAX_ORDER);
    let l = usize::from(lobe == Lobe::Transmission);
    ALL[l][order][usize::from(absorbing)][usize::from(cross_orders)]
        .get_or_init(|| Layout::build(lobe, order, absorbing, cross_orders))
}

/// A pair of classes keyed for grouping: its orders, `Δ` counts and summed counts packed into
/// 6-bit fields of one `u64` in that order of significance (counts are at most
/// `MAX_ORDER + 2`: `Δ + 32` and the sums fit), and the classes `(a, b)`: sorting the keys
/// sorts by (orders, Δ, sum, a, b).
type Keyed = (u64, u32);

/// The packed key of [`Keyed`].
fn key(orders: (usize, usize), delta: &[i32; 4], sum: &[i32; 4]) -> u64 {
    let field = |k: u64, x: i64| (k << 6) | (x as u64 & 63);
    let mut k = field(field(0, orders.0 as i64), orders.1 as i64);
    for d in delta {
        k = field(k, i64::from(*d) + 32);
    }
    for x in sum {
        k = field(k, i64::from(*x));
    }
    k
}

/// The fields of a packed key: (orders, Δ, sum).
fn unkey(k: u64) -> ((usize, usize), [i32; 4], [i32; 4]) {
    let field = |i: u32| ((k >> (6 * i)) & 63) as i32;
    let sum = [field(3), field(2), field(1), field(0)];
    let delta = [field(7) - 32, field(6) - 32, field(5) - 32, field(4) - 32];
    ((field(9) as usize, field(8) as usize), delta, sum)
}

impl Layout {
    fn build(lobe: Lobe, order: usize, absorbing: bool, cross_orders: bool) -> Self {
        let n = lobe.classes(order);
        let classes: Vec<(Counts, usize)> = (0..n).map(|k| lobe.class(k)).collect();
        let mut keyed: Vec<Keyed> = Vec::with_capacity(n * (n + 1) / 2);
        for a in 0..n {
            for b in a..n {
                if !cross_orders && classes[a].1 != classes[b].1 {
                    continue;
                }
                let (ca, cb) = (classes[a].0, classes[b].0);
                let delta: [i32; 4] = std::array::from_fn(|m| i32::from(cb[m]) - i32::from(ca[m]));
                let (delta, a, b) = if is_canonical(&delta) {
                    (delta, a, b)
                } else {
                    (delta.map(|x| -x), b, a)
                };
                let sum = if absorbing {
                    std::array::from_fn(|m| i32::from(ca[m]) + i32::from(cb[m]))
                } else {
                    [0; 4]
                };
                let (oa, ob) = (classes[a].1, classes[b].1);
                keyed.push((
                    key((oa.min(ob), oa.max(ob)), &delta, &sum),
                    ((a as u32) << 16) | b as u32,
                ));
            }
        }
        keyed.sort_unstable();
        let mut out = Layout {
            blocks: Vec::new(),
            groups: Vec::new(),
            pairs: Vec::with_capacity(keyed.len()),
            counts: classes.iter().map(|c| c.0).collect(),
            orders: classes.iter().map(|c| c.1 as u8).collect(),
        };
        for (k, ab) in keyed {
            let (orders, delta, sum) = unkey(k);
            let p = out.pairs.len();
            out.pairs.push(((ab >> 16) as u16, (ab & 0xffff) as u16));
            let new_block = out.blocks.last().is_none_or(|bl| bl.orders != orders);
            if new_block {
                let g = out.groups.len();
                out.blocks.push(Block {
                    orders,
                    groups: g..g,
                    pairs: p..p,
                });
            }
            let new_group = new_block
                || out
                    .groups
                    .last()
                    .is_none_or(|g| g.delta != delta || g.sum != sum);
            if new_group {
                out.groups.push(Group {
                    delta,
                    sum,
                    pairs: p..p,
                });
            }
            let g = out.groups.len();
            let block = out.blocks.last_mut().expect("a block");
            block.groups.end = g;
            block.pairs.end = p + 1;
            out.groups.last_mut().expect("a group").pairs.end = p + 1;
        }
        out
    }
}

/// True if `d` is zero or its first non-zero component is positive.
fn is_canonical(d: &[i32; 4]) -> bool {
    d.iter().find(|x| **x != 0).is_none_or(|x| *x > 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every unordered pair of classes (of one order, without `cross_orders`) is laid out once,
    /// in the block of its orders and a group whose count difference (and sum) it has.
    #[test]
    fn every_pair_once_in_its_group() {
        for lobe in Lobe::BOTH {
            for (order, absorbing, cross) in
                (0..16).map(|i| ([0, 1, 3, 8][i / 4], i & 2 != 0, i & 1 != 0))
            {
                {
                    let l = layout(lobe, order, absorbing, cross);
                    let n = lobe.classes(order);
                    let same: usize = (0..n)
                        .flat_map(|a| (a..n).map(move |b| (a, b)))
                        .filter(|&(a, b)| cross || l.orders[a] == l.orders[b])
                        .count();
                    assert_eq!(l.pairs.len(), same);
                    let mut seen = vec![false; n * n];
                    for block in &l.blocks {
                        for g in &l.groups[block.groups.clone()] {
                            assert!(
                                g.pairs.start >= block.pairs.start
                                    && g.pairs.end <= block.pairs.end
                            );
                            for &(a, b) in &l.pairs[g.pairs.clone()] {
                                let (a, b) = (a as usize, b as usize);
                                let (lo, hi) = (a.min(b), a.max(b));
                                assert!(!seen[lo * n + hi]);
                                seen[lo * n + hi] = true;
                                let d: [i32; 4] = std::array::from_fn(|m| {
                                    i32::from(l.counts[b][m]) - i32::from(l.counts[a][m])
                                });
                                assert_eq!(d, g.delta);
                                if absorbing {
                                    let s: [i32; 4] = std::array::from_fn(|m| {
                                        i32::from(l.counts[b][m]) + i32::from(l.counts[a][m])
                                    });
                                    assert_eq!(s, g.sum);
                                }
                                let (oa, ob) = (l.orders[a] as usize, l.orders[b] as usize);
                                assert_eq!((oa.min(ob), oa.max(ob)), block.orders);
                            }
                        }
                    }
                }
            }
        }
    }
}
