//! `applesim calibrate-bruise` (issue 26 Build item 3, acceptance "Calibration round trip";
//! docs/damage.md section 8): drops simulated by ordinary runs with known coefficients and their
//! bruises computed by the run's own analysis are refitted by the command (through the binary)
//! to the coefficients; a scenario naming the written preset file uses them; bad drop files are
//! refused naming the row and column; the published data set of docs/damage/ fits as documented.

use crate::common;
use applesim::analysis;
use applesim::scenario::{self, Scenario};
use common::*;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("applesim-calbruise-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const D: f64 = 0.08;
const M: f64 = 0.2;

/// The materials of the lab file and of every drop's run: the paper's apple, steel, and a
/// 1 MPa foam half-space.
fn materials(damage: Value) -> Value {
    json!({
        "apple": { "preset": "apple-paper", "damage": damage },
        "steel": { "preset": "steel" },
        "foam": { "youngs_modulus_pa": 1e6, "poisson_ratio": 0.3 }
    })
}

fn contact() -> Value {
    json!({ "friction": 0.3, "ke": 0.25, "lambda_s_m": 1000 })
}

fn lab_file(dir: &Path) -> PathBuf {
    let mut m = materials(Value::Null);
    m["apple"].as_object_mut().unwrap().remove("damage");
    let p = dir.join("lab.json");
    std::fs::write(
        &p,
        serde_json::to_string_pretty(&json!({ "materials": m, "contact": contact() })).unwrap(),
    )
    .unwrap();
    p
}

/// A drop from `h` onto a plane of `surface`, released at rest: an ordinary run at the shipped
/// scenarios' step (1e-5 s), to just after the first impact (the rebound is in the air).
fn drop_scenario(surface: &str, h: f64, damage: Value) -> Scenario {
    let t_fall = (2.0 * h / 9.81f64).sqrt();
    let sc = json!({
        "duration_s": t_fall + 0.03,
        "time_step_s": 1e-5,
        "gravity_m_s2": [0, 0, -9.81],
        "output": { "sample_interval_s": 0.01, "force_history": false },
        "materials": materials(damage),
        "contact": contact(),
        "apples": [{ "name": "a", "material": "apple", "diameter_m": D, "mass_kg": M,
                     "position_m": [0, 0, D / 2.0 + h], "velocity_m_s": [0, 0, 0] }],
        "surfaces": [{ "name": "floor", "type": "plane", "material": surface,
                       "point_m": [0, 0, 0], "normal": [0, 0, 1] }]
    });
    scenario::from_json(&sc.to_string(), "drop").unwrap()
}

/// One drop's run through the run's own analysis: (bruise volume, bruised, absorbed energy).
fn run_drop(surface: &str, h: f64, damage: Value) -> (Option<f64>, bool, f64) {
    let sc = drop_scenario(surface, h, damage);
    let (r, _) = run(&sc);
    let a = analysis::analyse(&sc, &r);
    assert_eq!(a.bruise.contacts.len(), 1, "one impact per drop");
    let apple = &a.bruise.apples[0];
    (
        apple.bruise_volume_mm3,
        apple.bruises > 0,
        a.bruise.contacts[0].absorbed_energy_j,
    )
}

fn applesim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args(args)
        .output()
        .expect("runs applesim")
}

fn calibrate(dir: &Path, csv: &Path, extra: &[&str], out: &str) -> (Value, String) {
    let lab = lab_file(dir);
    let out = dir.join(out);
    let mut args = vec![
        "calibrate-bruise",
        csv.to_str().unwrap(),
        "--materials",
        lab.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = applesim(&args);
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    println!("{stdout}");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let preset: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    (preset, stdout)
}

/// The drops of the round trips: several heights onto steel and onto the foam.
const DROPS: &[(&str, f64)] = &[
    ("steel", 0.02),
    ("steel", 0.04),
    ("steel", 0.07),
    ("steel", 0.1),
    ("steel", 0.15),
    ("steel", 0.2),
    ("foam", 0.1),
    ("foam", 0.2),
    ("foam", 0.3),
    ("foam", 0.4),
];

/// Writes the drops with the volumes (or yes/no) their runs gave.
fn write_csv(dir: &Path, name: &str, rows: &[(&str, f64, String)], column: &str) -> PathBuf {
    let mut s = format!("id,height_m,surface,diameter_m,mass_kg,{column}\n");
    for (k, (surface, h, m)) in rows.iter().enumerate() {
        s.push_str(&format!("d{k},{h},{surface},{D},{M},{m}\n"));
    }
    let p = dir.join(name);
    std::fs::write(&p, s).unwrap();
    p
}

fn number(v: &Value, field: &str) -> f64 {
    v[field]
        .as_f64()
        .unwrap_or_else(|| panic!("{field} missing in {v}"))
}

/// The round trip's measured errors, as docs/damage.md section 8 prints them (%): BS and E_th of
/// the energy model; p_c and the depth ratio of the pressure-area model. Checked at twice these.
const ROUND_TRIP_ENERGY_PCT: [f64; 2] = [0.0022, 0.0091];
const ROUND_TRIP_PRESSURE_PCT: [f64; 2] = [0.0007, 0.0029];

#[test]
fn round_trip_recovers_the_energy_model_and_a_scenario_naming_the_preset_uses_it() {
    let dir = scratch("energy");
    let truth = json!({ "model": "energy", "bruise_susceptibility_mm3_j": 5000.0, "threshold_energy_j": 0.05 });
    let rows: Vec<(&str, f64, String)> = DROPS
        .iter()
        .map(|&(s, h)| {
            let (v, _, e) = run_drop(s, h, truth.clone());
            let v = v.expect("the energy model gives volumes");
            println!("{s} {h} m: E = {e:.6} J, V = {v:.3} mm^3");
            (s, h, format!("{v:.9}"))
        })
        .collect();
    // Some drops below the threshold, on both surfaces.
    assert!(
        rows.iter()
            .filter(|r| r.2.parse::<f64>().unwrap() == 0.0)
            .count()
            >= 2
    );
    let csv = write_csv(&dir, "drops.csv", &rows, "volume_mm3");
    let (preset, stdout) = calibrate(&dir, &csv, &["--model", "energy"], "energy.json");
    let bs = number(&preset, "bruise_susceptibility_mm3_j");
    let e_th = number(&preset, "threshold_energy_j");
    let err = [100.0 * rel(bs, 5000.0), 100.0 * rel(e_th, 0.05)];
    println!(
        "round trip: BS {bs} ({:.4} %), E_th {e_th} ({:.4} %)",
        err[0], err[1]
    );
    for (e, doc) in err.iter().zip(ROUND_TRIP_ENERGY_PCT) {
        // The issue's acceptance is 1 %; the docs print the measured figure, checked at 2x.
        assert!(*e <= 2.0 * doc && *e <= 1.0, "{err:?}");
    }
    assert_eq!(preset["model"], "energy");
    let source = preset["source"].as_str().unwrap();
    assert!(
        source.starts_with(&format!(
            "applesim calibrate-bruise: {} (10 drops, volumes)",
            csv.display()
        )),
        "{source}"
    );
    assert!(
        source.contains("residual RMS") && source.contains("+-"),
        "{source}"
    );
    assert!(stdout.contains("energy model: BS = "), "{stdout}");
    // The report beside it.
    assert!(dir.join("energy.report.md").is_file());

    // (b) A scenario naming the written file: its runs use those coefficients.
    let mut sc = drop_scenario("steel", 0.15, json!({ "file": "energy.json" }));
    let path = dir.join("uses_preset.json");
    std::fs::write(&path, serde_json::to_string(&sc).unwrap()).unwrap();
    sc = scenario::load(&path).unwrap();
    let d = sc.materials["apple"].damage.as_ref().unwrap();
    assert_eq!(d.bruise_susceptibility_mm3_j, Some(bs));
    assert_eq!(d.threshold_energy_j, Some(e_th));
    assert!(d
        .source
        .as_deref()
        .unwrap()
        .starts_with("file energy.json: applesim calibrate-bruise"));
    let (r, _) = run(&sc);
    let a = analysis::analyse(&sc, &r);
    let e = a.bruise.contacts[0].absorbed_energy_j;
    let v = a.bruise.apples[0].bruise_volume_mm3.unwrap();
    println!("scenario naming the preset: E = {e} J, V = {v} mm^3");
    assert!(e > e_th);
    assert!(
        rel(v, bs * (e - e_th)) < 1e-12,
        "{v} against {}",
        bs * (e - e_th)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn round_trip_recovers_the_pressure_area_model_with_its_depth_ratio() {
    let dir = scratch("pressure");
    let truth =
        json!({ "model": "pressure-area", "critical_pressure_pa": 2.2e5, "depth_ratio": 3.0 });
    let rows: Vec<(&str, f64, String)> = DROPS
        .iter()
        .map(|&(s, h)| {
            let (v, _, _) = run_drop(s, h, truth.clone());
            let v = v.expect("the pressure-area model gives volumes");
            println!("{s} {h} m: V = {v:.3} mm^3");
            (s, h, format!("{v:.9}"))
        })
        .collect();
    assert!(rows.iter().any(|r| r.2.parse::<f64>().unwrap() == 0.0));
    let csv = write_csv(&dir, "drops.csv", &rows, "volume_mm3");
    let (preset, _) = calibrate(
        &dir,
        &csv,
        &["--model", "pressure-area", "--fit-depth-ratio"],
        "pa.json",
    );
    let pc = number(&preset, "critical_pressure_pa");
    let k = number(&preset, "depth_ratio");
    let err = [100.0 * rel(pc, 2.2e5), 100.0 * rel(k, 3.0)];
    println!(
        "round trip: p_c {pc} ({:.4} %), depth ratio {k} ({:.4} %)",
        err[0], err[1]
    );
    for (e, doc) in err.iter().zip(ROUND_TRIP_PRESSURE_PCT) {
        assert!(*e <= 2.0 * doc && *e <= 1.0, "{err:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn yes_no_drops_fit_the_peak_force_onset_between_the_bracketing_drops() {
    let dir = scratch("force");
    let truth = json!({ "model": "peak-force", "peak_force_n": 100.0 });
    // Two steel drops about 1 % below and above 100 N (F ~ h^0.6 from 97.5 N at 5 cm), and
    // others well away on both surfaces.
    let drops: Vec<(&str, f64)> = vec![
        ("steel", 0.02),
        ("steel", 0.0512),
        ("steel", 0.0530),
        ("steel", 0.1),
        ("foam", 0.1),
        ("foam", 0.3),
    ];
    let rows: Vec<(&str, f64, String)> = drops
        .iter()
        .map(|&(s, h)| {
            let (_, b, _) = run_drop(s, h, truth.clone());
            (s, h, if b { "yes" } else { "no" }.to_string())
        })
        .collect();
    assert_eq!(rows[1].2, "no");
    assert_eq!(rows[2].2, "yes");
    let csv = write_csv(&dir, "drops.csv", &rows, "bruised");
    let (preset, stdout) = calibrate(&dir, &csv, &["--model", "peak-force"], "force.json");
    let f = number(&preset, "peak_force_n");
    println!("peak-force onset {f} N ({:.3} %)", 100.0 * rel(f, 100.0));
    // docs/damage.md section 8 prints 0.13 %; checked at twice that.
    assert!(rel(f, 100.0) <= 0.0026, "{f}");
    assert!(stdout.contains("the data separate"), "{stdout}");
    assert!(stdout.contains("0 of 6 drops misclassified"), "{stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_drop_files_are_refused_naming_the_row_and_column() {
    let dir = scratch("bad");
    let lab = lab_file(&dir);
    let head = "height_m,surface,diameter_m,mass_kg,volume_mm3\n";
    let cases: &[(&str, String, &str)] = &[
        (
            "unknown column",
            "height_m,surface,diameter_m,mass_kg,volume\n0.1,steel,0.08,0.2,1\n".into(),
            "drops.csv, row 1, column volume: unknown column 'volume': the columns are id, height_m",
        ),
        (
            "missing value",
            format!("{head}0.1,steel,0.08,0.2,10\n0.2,steel,,0.2,40\n"),
            "drops.csv, row 3, column diameter_m: empty: give the apple's diameter (m)",
        ),
        (
            "unknown surface",
            format!("{head}0.1,steel,0.08,0.2,10\n0.2,wood,0.08,0.2,40\n"),
            "drops.csv, row 3, column surface: unknown surface 'wood': name a surface or material of the lab file (apple, foam, steel)",
        ),
        (
            "not a number",
            format!("{head}0.1,steel,0.08,0.2kg,10\n"),
            "drops.csv, row 2, column mass_kg: '0.2kg' is not a number",
        ),
        (
            "no bruise given",
            format!("{head}0.1,steel,0.08,0.2,\n"),
            "drops.csv, row 2, column volume_mm3: empty: give the drop's bruise",
        ),
        (
            "a bad yes/no",
            "height_m,surface,diameter_m,mass_kg,bruised\n0.1,steel,0.08,0.2,perhaps\n".into(),
            "drops.csv, row 2, column bruised: 'perhaps' is not yes/no",
        ),
    ];
    for (what, text, want) in cases {
        let csv = dir.join("drops.csv");
        std::fs::write(&csv, text).unwrap();
        let out = dir.join("never.json");
        let o = applesim(&[
            "calibrate-bruise",
            csv.to_str().unwrap(),
            "--materials",
            lab.to_str().unwrap(),
            "--model",
            "energy",
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        println!("{what}: {err}");
        assert!(!o.status.success(), "{what}");
        assert_eq!(o.status.code(), Some(1), "{what}: no panic");
        let want = format!(
            "error: {}{want}",
            csv.display().to_string().trim_end_matches("drops.csv")
        );
        assert!(err.starts_with(&want), "{what}: {err}\nwanted: {want}");
        assert_eq!(err.lines().count(), 1, "{what}: one line");
        assert!(
            !out.exists() && !dir.join("never.report.md").exists(),
            "{what}: nothing written"
        );
    }
    // The lab file's mistakes name it and the field.
    std::fs::write(
        dir.join("bad_lab.json"),
        r#"{"materials": {"apple": {"preset": "apple-paper"}}, "contact": {"friction": 0.3, "ke": 0.25, "lambda_s_m": 1000}, "surface": {}}"#,
    )
    .unwrap();
    std::fs::write(
        dir.join("drops.csv"),
        format!("{head}0.1,apple,0.08,0.2,1\n"),
    )
    .unwrap();
    let o = applesim(&[
        "calibrate-bruise",
        dir.join("drops.csv").to_str().unwrap(),
        "--materials",
        dir.join("bad_lab.json").to_str().unwrap(),
        "--model",
        "energy",
        "--out",
        dir.join("never.json").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    println!("{err}");
    assert!(
        err.contains("bad_lab.json: surface: unknown field `surface`, expected one of `materials`, `contact`, `pairs`, `surfaces`"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// docs/damage.md section 8 and docs/damage/README.md: the fits of the published data set, as
/// printed. Regression pins (GV), not closed forms: they change with any assumption of
/// docs/damage/README.md. Each: (data file, model, the coefficients line, the residuals line).
const PUBLISHED: &[(&str, &str, &str, &str)] = &[
    (
        "komarnicki_stopa_2013.csv",
        "energy",
        "energy model: BS = 163341 +- 9513 mm^3/J, E_th = 0.0508826 J",
        "residual RMS 209.6 mm^3 over 3 drops (1 degree of freedom), 1 misclassified (bruised or not)",
    ),
    (
        "fu_2017.csv",
        "pressure-area",
        "pressure-area model: p_c = 251140 +- 46509 Pa",
        "2 of 8 drops misclassified (bruised or not)",
    ),
    (
        "fu_2017.csv",
        "peak-force",
        "peak-force model: F_th = 119.46 +- 109 N",
        "4 of 8 drops misclassified (bruised or not)",
    ),
];

#[test]
fn the_published_data_set_fits_as_documented() {
    let dir = scratch("published");
    let data = repo("docs/damage");
    let doc = std::fs::read_to_string(repo("docs/damage.md")).unwrap();
    let readme = std::fs::read_to_string(data.join("README.md")).unwrap();
    for (file, model, coefficients, residuals) in PUBLISHED {
        let out = dir.join(format!("{model}.json"));
        let o = applesim(&[
            "calibrate-bruise",
            data.join(file).to_str().unwrap(),
            "--materials",
            data.join("lab.json").to_str().unwrap(),
            "--model",
            model,
            "--out",
            out.to_str().unwrap(),
        ]);
        let stdout = String::from_utf8_lossy(&o.stdout);
        println!("{stdout}");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(
            stdout.lines().any(|l| l == *coefficients),
            "{file} {model}: {coefficients}"
        );
        assert!(
            stdout.lines().any(|l| l == *residuals),
            "{file} {model}: {residuals}"
        );
        // The docs print the same lines.
        for (name, text) in [("docs/damage.md", &doc), ("docs/damage/README.md", &readme)] {
            assert!(text.contains(coefficients), "{name} lacks '{coefficients}'");
            assert!(text.contains(residuals), "{name} lacks '{residuals}'");
        }
        // Every drop's residual as printed is in the README's table of that fit.
        let table = stdout
            .lines()
            .skip_while(|l| !l.starts_with("row "))
            .skip(1)
            .take_while(|l| !l.is_empty());
        for line in table {
            let cells: Vec<&str> = line.split_whitespace().collect();
            let id = cells[1];
            let residual = cells.last().unwrap();
            assert!(
                readme.lines().any(|l| l.contains(&format!("| {id} |"))
                    && l.contains(model)
                    && l.contains(&format!("| {residual} |"))),
                "docs/damage/README.md: no row of {id} ({model}) with residual {residual}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
