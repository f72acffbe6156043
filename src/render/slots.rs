//! Fixed lobe slots: each index names the same lobe in every query, so that the lobes of one
//! surface point at several wavelengths (or colour channels) are matched by index.
//!
//! A plate has two slots, [`PLATE_REFLECTION`] and [`PLATE_TRANSMISSION`]. A bulk crystal's
//! lobe joins the wave leaving along `wi` to the wave at `wo`; each end is the exterior wave or
//! an ordinary or extraordinary ray inside the crystal, so a lobe's slot is `3 · end(wi) +
//! end(wo)` with `end` = 0 (exterior), 1 (o), 2 (e): seen from outside, slot 0 is the
//! reflection and slots 1 and 2 the o and e refractions; seen along an o-ray inside, slot 3 is
//! its refraction out and slots 4 and 5 its reflections into o and e; along an e-ray, 6, 7, 8.
//! An isotropic crystal has only "o" rays (its s and p waves travel together).

use crate::optics::modes::ModeKind;
use crate::render::PathLobe;

/// Slot of a plate's reflection.
pub const PLATE_REFLECTION: usize = 0;
/// Slot of a plate's transmission.
pub const PLATE_TRANSMISSION: usize = 1;
/// Slots of a plate query.
pub const PLATE_SLOTS: usize = 2;
/// Slots of a crystal query.
pub const CRYSTAL_SLOTS: usize = 9;

/// The lobes of one query (one wavelength or channel) by slot, over the reals `T`.
pub type Slots<const S: usize, T = f64> = [Option<PathLobe<T>>; S];

/// One end of a crystal lobe: `None` for the exterior wave, else the crystal ray's mode
/// (s/p waves of an isotropic crystal count as o).
fn end(mode: Option<ModeKind>) -> usize {
    match mode {
        None => 0,
        Some(ModeKind::E) => 2,
        Some(_) => 1,
    }
}

/// The slot of the crystal lobe joining the wave along `wi` (mode `wi_mode`, `None` outside)
/// to the wave at `wo` (`wo_mode`).
pub fn crystal_slot(wi_mode: Option<ModeKind>, wo_mode: Option<ModeKind>) -> usize {
    3 * end(wi_mode) + end(wo_mode)
}

/// Mitsuba's component of a crystal slot: 0 for a reflection (both ends on one side), else 1
/// or 2 by the mode of the end inside the crystal (1 ordinary, 2 extraordinary).
pub fn crystal_component(slot: usize) -> usize {
    match (slot / 3, slot % 3) {
        (0, inside) | (inside, 0) => inside,
        _ => 0,
    }
}

/// Mitsuba's component of a plate slot (the slot itself: 0 reflection, 1 transmission).
pub fn plate_component(slot: usize) -> usize {
    slot
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pair of ends has its own slot, and components follow Mitsuba's numbering.
    #[test]
    fn slots_are_distinct_and_components_follow_the_crystal_side() {
        let ends = [None, Some(ModeKind::O), Some(ModeKind::E)];
        let mut seen = [false; CRYSTAL_SLOTS];
        for a in ends {
            for b in ends {
                let s = crystal_slot(a, b);
                assert!(!seen[s]);
                seen[s] = true;
            }
        }
        let components: Vec<usize> = (0..CRYSTAL_SLOTS).map(crystal_component).collect();
        assert_eq!(components, [0, 1, 2, 1, 0, 0, 2, 0, 0]);
        assert_eq!(crystal_slot(Some(ModeKind::S), None), 3);
    }
}
