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
