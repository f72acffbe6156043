//! Named crystals over the wavelengths Mitsuba samples (360-830 nm), where some crystals' cited
//! data stop short (rutile: 430 nm, lithium niobate: 400 nm): the one rule of
//! `Material::coverage`, as the core, the calculator (`calc::run_text`) and the bridge the
//! plugins load materials through apply it.

use birefringent::calc::run_text;
use birefringent::ffi::new_materials;
use birefringent::material::crystals::{crystal, crystal_names};
use birefringent::material::{Material, RENDER_RANGE_NM};
use serde_json::json;

fn nm_grid() -> impl Iterator<Item = f64> {
    (RENDER_RANGE_NM.0 as u32..=RENDER_RANGE_NM.1 as u32).map(f64::from)
}

#[test]
fn every_crystal_gives_finite_indices_at_every_nm_from_360_to_830() {
    // Core: finite indices above 1, kappa >= 0; the rule accepts each wavelength, with a
    // warning stating the data's range exactly where the data do not reach.
    for name in crystal_names() {
        let c = crystal(name).unwrap();
        let m = Material::named(name, 0.0, 0.0).unwrap();
        let (mut warned, mut clean) = (0, 0);
        for nm in nm_grid() {
            let (o, e) = m.indices(nm, 0.0).unwrap();
            for eta in [o, e] {
                assert!(
                    eta.re.is_finite() && eta.re > 1.0 && eta.re < 4.0,
                    "{name} {nm}: {eta}"
                );
                assert!(eta.im >= 0.0 && eta.im.is_finite(), "{name} {nm}: {eta}");
            }
            let w = m.coverage(nm, nm).unwrap();
            assert_eq!(w.is_some(), !c.in_range(nm), "{name} at {nm} nm: {w:?}");
            if let Some(w) = w {
                let range = format!("cover {}-{} nm", c.range_nm.0, c.range_nm.1);
                assert!(w.contains(name) && w.contains(&range), "{w}");
                warned += 1;
            } else {
                clean += 1;
            }
        }
        println!("{name}: {clean} nm from its data, {warned} nm extrapolated with a warning");
    }
}

#[test]
fn the_calculator_warns_where_the_plugins_warn() {
    // The same grid through the JSON calculator: every case succeeds (finite output is
    // checked by run_text), with a `warnings` entry exactly where the core warns.
    for name in crystal_names() {
        let m = Material::named(name, 0.0, 0.0).unwrap();
        for nm in nm_grid() {
            let input = json!({"wavelength_nm": nm, "material": name,
                               "optic_axis": [0.3, 0.2, 0.9], "theta_deg": 30});
            let (out, ok) = run_text("interface", &input.to_string());
            assert!(ok, "{name} at {nm} nm: {out}");
            let expected = m.coverage(nm, nm).unwrap();
            let got = out
                .get("warnings")
                .map(|w| w[0].as_str().unwrap().to_string());
            assert_eq!(got, expected, "{name} at {nm} nm");
        }
    }
    // slab and spectral weights (360-830 nm) carry the same warning.
    let slab = json!({"wavelength_nm": 380, "material": "linbo3", "optic_axis": [1, 0, 0],
                      "theta_deg": 0, "thickness_um": 0.3});
    let (out, ok) = run_text("slab", &slab.to_string());
    assert!(
        ok && out["warnings"][0].as_str().unwrap().contains("400-5000 nm"),
        "{out}"
    );
    let mut rgb = slab.clone();
    rgb["wavelength_nm"] = json!(550);
    rgb["spectrum"] = json!({"weights": "srgb-d65"});
    let (out, ok) = run_text("slab", &rgb.to_string());
    let w = out["warnings"].as_array().unwrap();
    assert!(ok && w.len() == 1, "{out}");
    assert!(
        w[0].as_str()
            .unwrap()
            .contains("extrapolated at 360-400 nm"),
        "{out}"
    );
}

#[test]
fn wavelengths_beyond_the_data_and_the_render_range_are_refused() {
    for (name, nm, range) in [
        ("rutile", 359.0, "430-1530"),
        ("rutile", 1600.0, "430-1530"),
        ("linbo3", 300.0, "400-5000"),
        ("calcite", 2500.0, "204-2172"),
        ("bbo", 1100.0, "220-1060"),
    ] {
        let input = json!({"wavelength_nm": nm, "material": name, "optic_axis": [0, 0, 1],
                           "theta_deg": 10});
        let (out, ok) = run_text("interface", &input.to_string());
        let e = out["error"].as_str().unwrap_or_default();
        assert!(
            !ok && e.starts_with("wavelength_nm:") && e.contains(range),
            "{out}"
        );
    }
    // Inside the data, outside the render range: the data decide (no warning).
    let (out, ok) = run_text(
        "interface",
        &json!({"wavelength_nm": 250, "material": "calcite", "optic_axis": [0, 0, 1],
                "theta_deg": 10})
        .to_string(),
    );
    assert!(ok && out.get("warnings").is_none(), "{out}");
}

/// The bridge's warning for a loaded material: what the plugins log at load.
fn load_message(name: &str) -> String {
    let mut table = new_materials();
    let index = table.add_named(name, 0.0, 0.0).unwrap();
    table.warning(index)
}

#[test]
fn loading_a_crystal_whose_data_miss_part_of_360_830_nm_gives_its_warning() {
    let mut warned = Vec::new();
    for name in crystal_names() {
        let msg = load_message(name);
        let c = crystal(name).unwrap();
        let covered = c.range_nm.0 <= RENDER_RANGE_NM.0 && c.range_nm.1 >= RENDER_RANGE_NM.1;
        assert_eq!(msg.is_empty(), covered, "{name}: {msg:?}");
        if !covered {
            warned.push(name);
            println!("{msg}");
        }
    }
    assert_eq!(warned, ["rutile", "linbo3"]);
    assert!(load_message("rutile").contains("extrapolated at 360-430 nm"));
    assert!(load_message("rutile").contains("absorbs below about 410 nm"));
}
