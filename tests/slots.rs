//! Fixed lobe slots of the crystal (`render::crystal::crystal_slots`): the same lobes as
//! `crystal_lobes`, each in the slot of the two waves it joins, checked against the textbook
//! property that tells an ordinary ray from an extraordinary one: the o-wave's field is
//! perpendicular to the optic axis.

use birefringent::material::Material;
use birefringent::optics::medium::Uniaxial;
use birefringent::optics::surface::Surface;
use birefringent::render::crystal::{crystal_lobes, crystal_slots};
use birefringent::render::slots::{crystal_component, CRYSTAL_SLOTS};
use birefringent::render::{PathLobe, Transport};
use birefringent::C64;
use nalgebra::Vector3;

mod common;
use common::Rng;

fn same(a: &PathLobe, b: &PathLobe) -> bool {
    let bits = |l: &PathLobe| -> Vec<u64> {
        l.wo.iter()
            .chain(l.in_stokes_x.iter())
            .chain(l.out_stokes_x.iter())
            .chain(l.mueller.iter())
            .chain([l.weight, l.eta].iter())
            .map(|x| x.to_bits())
            .chain([l.component as u64])
            .collect()
    };
    bits(a) == bits(b)
}

/// A random surface: a named crystal at a random wavelength, constant birefringent or
/// isotropic indices, or an absorbing isotropic medium.
fn surface(rng: &mut Rng) -> Surface {
    let axis = rng.unit_vector();
    let (eo, ee) = match rng.index(4) {
        0 => {
            let names = ["calcite", "quartz", "rutile", "sapphire"];
            let m = Material::named(names[rng.index(4)], 0.0, 0.0).unwrap();
            m.indices(rng.range(400.0, 800.0), 0.0).unwrap()
        }
        1 => (
            C64::new(rng.range(1.3, 2.5), 0.0),
            C64::new(rng.range(1.3, 2.5), 0.0),
        ),
        2 => {
            let n = C64::new(rng.range(1.3, 2.5), 0.0);
            (n, n)
        }
        _ => {
            let n = C64::new(rng.range(0.2, 3.0), rng.range(0.01, 4.0));
            (n, n)
        }
    };
    let ext = C64::new(rng.range(1.0, 1.6), 0.0);
    Surface::new(ext, Uniaxial::new(eo, ee, axis).unwrap()).unwrap()
}

/// Over 20,000 random queries (both sides, both modes): every lobe of `crystal_lobes` is in
/// exactly one slot, bit for bit, and no slot holds anything else; each slot's component is
/// `crystal_component(slot)`; the lobes whose crystal end is an o-ray have their Stokes frame
/// `x` axis (the field's major axis) perpendicular to the optic axis (to 1e-9: rounding of unit
/// vectors; an e-ray's field is not, and slots mixing o and e would fail). Lobes from inside an
/// anisotropic crystal exist in both modes' slots 3-8 only.
#[test]
fn crystal_slots_hold_the_lobes_of_crystal_lobes_by_their_waves() {
    let mut rng = Rng::new(2024);
    let (mut lobes_seen, mut o_checked) = (0usize, 0usize);
    for _ in 0..20_000 {
        let s = surface(&mut rng);
        let wi = rng.unit_vector();
        if wi.z.abs() < 1e-3 {
            continue;
        }
        let transport = if rng.chance(0.5) {
            Transport::Radiance
        } else {
            Transport::Importance
        };
        let lobes = crystal_lobes(&s, wi, transport).unwrap();
        let slots = crystal_slots(&s, wi, transport).unwrap();
        assert_eq!(lobes.len(), slots.iter().flatten().count());
        for l in &lobes {
            let found: Vec<usize> = (0..CRYSTAL_SLOTS)
                .filter(|&k| slots[k].as_ref().is_some_and(|x| same(x, l)))
                .collect();
            assert_eq!(found.len(), 1, "{l:?} in slots {found:?}");
            assert_eq!(crystal_component(found[0]), l.component);
            if wi.z < 0.0 {
                assert!(found[0] >= 3, "inside lobe in slot {}", found[0]);
            } else {
                assert!(found[0] < 3, "outside lobe in slot {}", found[0]);
            }
        }
        lobes_seen += lobes.len();
        if s.crystal.is_isotropic() {
            continue;
        }
        // The frame of the crystal end: the outgoing wave's in Importance mode (wo end), the
        // source's in Radiance mode; for the wi end the other one.
        let axis = s.crystal.axis;
        for (k, l) in slots.iter().enumerate() {
            let Some(l) = l else { continue };
            let (wi_frame, wo_frame) = match transport {
                Transport::Importance => (l.in_stokes_x, l.out_stokes_x),
                Transport::Radiance => (l.out_stokes_x, l.in_stokes_x),
            };
            let ends: [(usize, Vector3<f64>); 2] = [(k / 3, wi_frame), (k % 3, wo_frame)];
            for (end, x) in ends {
                if end == 1 {
                    assert!(
                        x.dot(&axis).abs() < 1e-9,
                        "slot {k}: o frame . A = {}",
                        x.dot(&axis)
                    );
                    o_checked += 1;
                }
            }
        }
    }
    println!(
        "{lobes_seen} lobes in their slots; {o_checked} o-ray frames perpendicular to the axis"
    );
    assert!(o_checked > 10_000);
}
