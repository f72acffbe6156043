//! The `birefringence` calculator as a user runs it: JSON in, JSON out, batch mode, errors.

use serde_json::Value;
use std::io::Write;
use std::process::{Command, Stdio};

fn run(args: &[&str], input: &str) -> (i32, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_birefringence"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The calculator may exit before reading (usage errors): ignore a broken pipe.
    let _ = child.stdin.take().unwrap().write_all(input.as_bytes());
    let out = child.wait_with_output().unwrap();
    (
        out.status.code().unwrap(),
        String::from_utf8(out.stdout).unwrap(),
    )
}

const CASE: &str = r#"{"wavelength_nm": 589.3, "eta_o": 1.4, "eta_e": 1.55, "optic_axis": [0.42, 0.1, 0.9], "theta_deg": 30}"#;

#[test]
fn one_case_gives_power_fractions_that_sum_to_one() {
    let (code, out) = run(&["interface"], CASE);
    assert_eq!(code, 0);
    let v: Value = serde_json::from_str(&out).unwrap();
    for pol in ["s", "p"] {
        let r: f64 = ["s", "p"]
            .iter()
            .map(|o| v["R"][format!("{pol}{o}")].as_f64().unwrap())
            .sum();
        let t: f64 = ["o", "e"]
            .iter()
            .map(|m| v["T"][pol][m].as_f64().unwrap())
            .sum();
        assert!((r + t - 1.0).abs() < 1e-12);
    }
    assert!(v["waves"]["transmitted"]["e"]["ray_direction"].is_array());
}

#[test]
fn batch_mode_keeps_going_after_an_invalid_line() {
    let input = format!(
        "{CASE}\nnot json\n{{\"wavelength_nm\": 500, \"eta_o\": 1.5, \"eta_e\": 1.6, \"theta_deg\": 10}}\n\n{}\n{{\"wavelength_nm\": 500, \"material\": \"unobtainium\", \"optic_axis\": [0,0,1], \"theta_deg\": 10}}\n{{\"wavelength_nm\": 500, \"eta_o\": 1.5, \"eta_e\": 1.5, \"thta_deg\": 10}}\n",
        CASE.replace("30", "45")
    );
    let (code, out) = run(&["interface", "--batch"], &input);
    assert_eq!(code, 1, "some lines failed");
    let lines: Vec<Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 6, "one output line per non-empty input line");
    assert!(lines[0]["R"].is_object());
    assert!(lines[1]["error"].as_str().unwrap().contains("invalid JSON"));
    assert!(lines[2]["error"]
        .as_str()
        .unwrap()
        .starts_with("optic_axis"));
    assert!(lines[3]["R"].is_object());
    assert!(lines[4]["error"]
        .as_str()
        .unwrap()
        .contains("unknown crystal 'unobtainium'"));
    assert!(lines[5]["error"]
        .as_str()
        .unwrap()
        .starts_with("thta_deg: unknown field"));
}

#[test]
fn invalid_inputs_name_the_parameter_and_exit_non_zero() {
    let cases = [
        (
            r#"{"wavelength_nm": 500, "eta_o": -1.5, "eta_e": 1.6, "optic_axis": [0,0,1], "theta_deg": 10}"#,
            "eta_o",
        ),
        (
            r#"{"wavelength_nm": 500, "eta_o": 1.5, "eta_e": [1.6, -0.1], "optic_axis": [0,0,1], "theta_deg": 10}"#,
            "eta_e",
        ),
        (
            r#"{"wavelength_nm": 500, "eta_o": 1.5, "eta_e": 1.6, "optic_axis": [0,0,0], "theta_deg": 10}"#,
            "optic_axis",
        ),
        (
            r#"{"wavelength_nm": 500, "eta_o": 1.5, "eta_e": 1.6, "optic_axis": [0,0,1], "theta_deg": 90}"#,
            "theta_deg",
        ),
        (
            r#"{"wavelength_nm": 500, "eta_o": 1.5, "eta_e": 1.6, "optic_axis": [0,0,1], "theta_deg": 10, "beta": 0.2}"#,
            "beta",
        ),
        (
            r#"{"wavelength_nm": 500, "eta_o": 1.5, "eta_e": 1.6, "optic_axis": [0,0,1], "theta_deg": 10, "side": "inside"}"#,
            "inside_mode",
        ),
        (
            r#"{"wavelength_nm": 500, "eta_o": 1.5, "eta_e": 1.6, "optic_axis": [0,0,1], "theta_deg": 10, "ext_ior": [1.0, 0.1]}"#,
            "ext_ior",
        ),
        (
            r#"{"wavelength_nm": 100, "material": "calcite", "optic_axis": [0,0,1], "theta_deg": 10}"#,
            "wavelength_nm",
        ),
        (
            r#"{"wavelength_nm": "green", "eta_o": 1.5, "eta_e": 1.6, "optic_axis": [0,0,1], "theta_deg": 10}"#,
            "wavelength_nm",
        ),
        (r#"[1, 2]"#, "input"),
    ];
    for (input, param) in cases {
        let (code, out) = run(&["interface"], input);
        assert_eq!(code, 1, "{input}");
        let v: Value = serde_json::from_str(&out).unwrap();
        let msg = v["error"].as_str().unwrap();
        assert!(msg.starts_with(&format!("{param}:")), "{input} -> {msg}");
    }
    let (code, _) = run(&["nonsense"], CASE);
    assert_eq!(code, 2, "usage error");
}

/// A length, wavelength or angle written without the unit its field's name carries gets the
/// field to use: `thickness` -> `thickness_um`, `wavelength` -> `wavelength_nm`, `theta` ->
/// `theta_deg`; a field with no such counterpart gets the list alone.
#[test]
fn a_field_without_its_unit_names_the_field_with_it() {
    let cases = [
        (
            "slab",
            r#"{"wavelength_nm": 550, "eta_o": 1.5, "eta_e": 1.6, "optic_axis": [1,0,0], "theta_deg": 0, "thickness": 3}"#,
            Some("thickness: unknown field (did you mean thickness_um (the unit is part of the name)? accepted: "),
        ),
        (
            "interface",
            r#"{"wavelength": 550, "eta_o": 1.5, "eta_e": 1.6, "optic_axis": [1,0,0], "theta_deg": 0}"#,
            Some("wavelength: unknown field (did you mean wavelength_nm"),
        ),
        (
            "interface",
            r#"{"wavelength_nm": 550, "eta_o": 1.5, "eta_e": 1.6, "optic_axis": [1,0,0], "theta": 0}"#,
            Some("theta: unknown field (did you mean theta_deg"),
        ),
        (
            "interface",
            r#"{"wavelength_nm": 550, "eta_o": 1.5, "eta_e": 1.6, "optic_axis": [1,0,0], "theta_deg": 0, "thick": 1}"#,
            None,
        ),
    ];
    for (command, input, want) in cases {
        let (code, out) = run(&[command], input);
        assert_eq!(code, 1, "{input}");
        let v: Value = serde_json::from_str(&out).unwrap();
        let msg = v["error"].as_str().unwrap();
        match want {
            Some(w) => assert!(msg.starts_with(w), "{input} -> {msg}"),
            None => assert!(msg.starts_with("thick: unknown field (accepted: "), "{msg}"),
        }
    }
}

#[test]
fn inside_incidence_and_named_materials() {
    let input = r#"{"wavelength_nm": 589.3, "material": "calcite", "ext_ior": "water", "optic_axis": [0.5, 0.2, 0.8], "theta_deg": 20, "side": "inside", "inside_mode": "e"}"#;
    let (code, out) = run(&["interface"], input);
    assert_eq!(code, 0, "{out}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let total: f64 = ["o", "e"]
        .iter()
        .map(|m| v["R"][m].as_f64().unwrap())
        .sum::<f64>()
        + ["s", "p"]
            .iter()
            .map(|m| v["T"][m].as_f64().unwrap())
            .sum::<f64>();
    assert!((total - 1.0).abs() < 1e-12);
}

const PLATE: &str = r#""wavelength_nm": 550, "material": "quartz", "optic_axis": [0.7, 0.7, 0.1], "theta_deg": 20, "phi_deg": 30, "thickness_um": 12"#;

fn slab(extra: &str) -> (i32, Value) {
    let (code, out) = run(&["slab"], &format!("{{{PLATE}{extra}}}"));
    (code, serde_json::from_str(&out).unwrap())
}

#[test]
fn slab_monochromatic_conserves_energy_and_prints_jones_and_mueller() {
    let (code, v) = slab("");
    assert_eq!(code, 0, "{v}");
    for input in ["s", "p"] {
        let total: f64 = ["s", "p"]
            .iter()
            .map(|o| {
                v["R"][format!("{input}{o}")].as_f64().unwrap()
                    + v["T"][format!("{input}{o}")].as_f64().unwrap()
            })
            .sum();
        assert!((total - 1.0).abs() < 1e-12);
    }
    assert_eq!(v["mueller"]["T"].as_array().unwrap().len(), 4);
    assert_eq!(v["jones"]["R"].as_array().unwrap().len(), 2);
    // A zero band is the monochromatic plate.
    let (_, b) = slab(r#", "spectrum": {"bandwidth_nm": 0}"#);
    assert_eq!(b["mueller_T"], v["mueller"]["T"]);
}

/// A slab that the method cannot compute accurately (o and e waves of a weakly birefringent
/// plate both near grazing under a denser exterior: the computed reflection and transmission of
/// p light summed to 1.00068, found by the fuzzer) is refused, naming the slab, not returned.
#[test]
fn a_slab_that_would_gain_energy_is_refused() {
    let input = r#"{"beta": 1.0001, "eta_e": 1.0, "eta_o": [1.0001, 1e-300], "ext_ior": 550.0, "optic_axis": [0, 1, 1], "thickness_um": 1.0001, "wavelength_nm": 1.0001}"#;
    let (code, out) = run(&["slab"], input);
    assert_ne!(code, 0, "{out}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let e = v["error"].as_str().unwrap();
    assert!(
        e.starts_with("slab: the computed plate reflects and transmits 1.000"),
        "{e}"
    );
}

#[test]
fn slab_spectrum_analytic_agrees_with_quadrature() {
    for spectrum in [r#"{"weights": "xyz-d65"}"#, r#"{"bandwidth_nm": 12}"#] {
        let (_, a) = slab(&format!(r#", "spectrum": {spectrum}"#));
        let q_spec = spectrum.replace('}', r#", "method": "quadrature", "step_nm": 0.05}"#);
        let (code, q) = slab(&format!(r#", "spectrum": {q_spec}"#));
        assert_eq!(code, 0, "{q}");
        let flat = |v: &Value| -> Vec<f64> {
            let mut out = Vec::new();
            fn walk(v: &Value, out: &mut Vec<f64>) {
                match v {
                    Value::Number(n) => out.push(n.as_f64().unwrap()),
                    Value::Array(a) => a.iter().for_each(|x| walk(x, out)),
                    _ => {}
                }
            }
            walk(&v["mueller_T"], &mut out);
            walk(&v["mueller_R"], &mut out);
            out
        };
        let (fa, fq) = (flat(&a), flat(&q));
        assert_eq!(fa.len(), fq.len());
        let worst = fa
            .iter()
            .zip(&fq)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        // Gaussian fits of the CIE weights (~1e-3 in the Fourier domain) vs the 1-nm tables.
        assert!(worst < 3e-3, "{spectrum}: {worst}");
        if spectrum.contains("weights") {
            assert_eq!(a["channels"], serde_json::json!(["X", "Y", "Z"]));
            assert_eq!(a["T"]["ss"].as_array().unwrap().len(), 3);
        }
    }
}

#[test]
fn slab_errors_name_the_field() {
    let cases = [
        (
            r#", "spectrum": {"weights": "srgb", "bandwidth_nm": 3}"#,
            "spectrum",
        ),
        (r#", "spectrum": {"weights": "rgb"}"#, "spectrum.weights"),
        (
            r#", "spectrum": {"bandwidth_nm": 3, "step": 1}"#,
            "spectrum.step",
        ),
        (
            r#", "spectrum": {"bandwidth_nm": -3}"#,
            "spectrum.bandwidth_nm",
        ),
        (
            r#", "spectrum": {"weights": "xyz-e", "method": "monte-carlo"}"#,
            "spectrum.method",
        ),
        (r#", "exit_ior": -1"#, "exit_ior"),
        (r#", "side": "inside""#, "side"),
        // fields of the nested spectrum object keep its name (they were `bandwidth_nm`,
        // `spectrum.input`)
        (
            r#", "spectrum": {"bandwidth_nm": "x"}"#,
            "spectrum.bandwidth_nm",
        ),
        (r#", "spectrum": {"weights": 3}"#, "spectrum.weights"),
        (r#", "spectrum": 3"#, "spectrum"),
        // the quadrature's own step limit (it was the bare `step_nm`)
        (
            r#", "spectrum": {"bandwidth_nm": 100, "method": "quadrature", "step_nm": 1e-6}"#,
            "spectrum.step_nm",
        ),
    ];
    for (extra, field) in cases {
        let (code, v) = slab(extra);
        assert_eq!(code, 1, "{extra}");
        let msg = v["error"].as_str().unwrap();
        assert!(msg.starts_with(&format!("{field}:")), "{extra} -> {msg}");
    }
    let (code, out) = run(
        &["slab"],
        r#"{"wavelength_nm": 550, "eta_o": 1.5, "eta_e": 1.6, "optic_axis": [1,0,0], "theta_deg": 0, "thickness_um": -2}"#,
    );
    assert_eq!(code, 1);
    assert!(out.contains("thickness_um"), "{out}");
}

/// An e-wave from inside past its K_max is evanescent: it carries no power, so the calculator
/// refuses the case instead of dividing by a rounding-level flux (which once printed R = 5.6e15).
#[test]
fn an_evanescent_incident_wave_is_refused() {
    let case = r#"{"wavelength_nm":550,"ext_ior":1.0,"eta_o":1.5,"eta_e":1.0001,"optic_axis":[0.3,0.2,0.5],"beta":1.2,"side":"inside","inside_mode":"e"}"#;
    let (code, out) = run(&["interface"], case);
    assert_ne!(code, 0);
    let v: Value = serde_json::from_str(&out).unwrap();
    let e = v["error"].as_str().unwrap();
    assert!(e.starts_with("incidence:") && e.contains("no power"), "{e}");
}

/// Every message names the field the user wrote, in the field's unit: a plate thicker than 1 m
/// is `thickness_um` in µm (it was the core's `thickness` in nm), a band wider than a quarter
/// of the wavelength is `spectrum.bandwidth_nm` with the limit at this wavelength.
#[test]
fn slab_range_errors_name_the_field_in_its_unit() {
    let cases = [
        (
            r#""thickness_um": 2e6"#,
            "thickness_um: must be within [0, 1e6] µm (1 m), got 2000000 µm",
        ),
        (
            r#""thickness_um": -2"#,
            "thickness_um: must be within [0, 1e6] µm (1 m), got -2 µm",
        ),
        (
            r#""thickness_um": 12, "spectrum": {"bandwidth_nm": 150}"#,
            "spectrum.bandwidth_nm: must be within [0, 137.5] nm (a quarter of the wavelength 550 nm), got 150 nm",
        ),
    ];
    for (fields, want) in cases {
        let input = format!(
            r#"{{"wavelength_nm": 550, "eta_o": 1.5, "eta_e": 1.6, "optic_axis": [1,0,0], "theta_deg": 0, {fields}}}"#
        );
        let (code, out) = run(&["slab"], &input);
        assert_eq!(code, 1, "{fields}");
        let v: Value = serde_json::from_str(&out).unwrap();
        assert_eq!(v["error"].as_str().unwrap(), want, "{fields}");
    }
}

/// An extinction coefficient beyond the accepted range is named as written (`kappa_o`,
/// `kappa_e`), for a named crystal and for constant indices (it was the core's `eta_e` /
/// `eta_o`, the index it is added to).
#[test]
fn kappa_errors_name_the_kappa() {
    for (fields, want) in [
        (
            r#""material": "quartz", "kappa_e": 2e3"#,
            "kappa_e: must be within [0, 1000], got 2000",
        ),
        (
            r#""eta_o": 1.5, "eta_e": 1.6, "kappa_o": 1e4"#,
            "kappa_o: must be within [0, 1000], got 10000",
        ),
    ] {
        let input =
            format!(r#"{{"wavelength_nm": 550, "optic_axis": [1,0,0], "theta_deg": 0, {fields}}}"#);
        let (code, out) = run(&["interface"], &input);
        assert_eq!(code, 1, "{fields}");
        let v: Value = serde_json::from_str(&out).unwrap();
        assert_eq!(v["error"].as_str().unwrap(), want, "{fields}");
    }
}
