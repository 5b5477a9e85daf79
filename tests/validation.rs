//! Issue 7 acceptance: the paper's Figs. 1-7 run by `applesim validate` (scenarios/paper/),
//! checked here against the paper's numbers, our own reference integration and the trends the
//! paper states, each with its tolerance; the report renders and the command reproduces it
//! byte for byte.
//!
//! The validation runs once (library call, shared by the tests) and once more through the
//! binary, from the repository root with the default specs folder, as documented.

use crate::common;
use applesim::contact::Material;
use applesim::validate::{self, reference, Options, Validation};
use common::*;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("applesim-{name}-{}", std::process::id()))
}

/// The validation, run once into a temporary folder (cwd is the repository root under cargo
/// test, so the default relative specs folder is used, as by the command).
fn validation() -> &'static (PathBuf, Validation) {
    static RUN: OnceLock<(PathBuf, Validation)> = OnceLock::new();
    RUN.get_or_init(|| {
        let out = tmp("validation-lib");
        let _ = std::fs::remove_dir_all(&out);
        let opts = Options {
            specs_dir: PathBuf::from("scenarios/paper"),
            out_dir: out.clone(),
            runs_dir: out.join("runs"),
            jobs: 2,
        };
        let v = validate::run(&opts, &mut |l| println!("{l}")).expect("validation runs");
        // The tests need the report, the charts and each figure's merged.csv, not the run
        // folders (their numbers are in `v`): drop those, some 20 MB.
        for e in std::fs::read_dir(out.join("runs")).unwrap() {
            let _ = std::fs::remove_dir_all(e.unwrap().path().join("runs"));
        }
        (out, v)
    })
}

fn figure(id: &str) -> &'static validate::Figure {
    validation().1.figure(id).expect("figure present")
}

/// k of an 80 mm apple of shear modulus `g1` (nu 0.18) on steel (8.1e10 Pa, nu 0.28).
fn k_on_steel(g1: f64) -> f64 {
    let apple = Material::from_shear(g1, 0.18, None).unwrap();
    let steel = Material::from_shear(8.1e10, 0.28, None).unwrap();
    reference::flat_stiffness(&apple, &steel, 0.04)
}

#[test]
fn fig1_reproduces_the_quoted_points_within_4_percent() {
    let f = figure("fig1");
    assert_eq!(f.impacts.len(), 7, "seven speeds 0.2..1.4 m/s");
    for (v0, p, t) in [(0.2, 11.5, 8.8e-3), (1.4, 97.0, 5.5e-3)] {
        let i = f
            .impacts
            .iter()
            .find(|i| (i.v0_m_s - v0).abs() < 1e-12)
            .expect("run at the quoted speed");
        assert_eq!(i.mass_kg, 0.107, "the mass physics.md section 8 explains");
        assert_rel(
            &format!("peak force at {v0} m/s vs paper"),
            i.peak_force_n,
            p,
            0.04,
        );
        assert_rel(
            &format!("contact time at {v0} m/s vs paper"),
            i.contact_time_s,
            t,
            0.04,
        );
    }
}

#[test]
fn fig1_every_speed_within_half_a_percent_of_the_gravity_integration() {
    let k = k_on_steel(1.1e6);
    // The integrator itself against physics.md section 8 (with gravity).
    let a = reference::elastic_impact_with_gravity(0.107, 0.2, k, 9.81);
    assert_rel(
        "integrator P at 0.2 m/s vs physics.md",
        a.peak_force_n,
        11.18,
        5e-4,
    );
    assert_rel(
        "integrator t at 0.2 m/s vs physics.md",
        a.contact_time_s,
        8.66e-3,
        6e-4,
    );
    let f = figure("fig1");
    for (n, i) in f.impacts.iter().enumerate() {
        let v0 = 0.2 * (n + 1) as f64;
        assert!((i.v0_m_s - v0).abs() < 1e-9, "run {n} at {} m/s", i.v0_m_s);
        let r = reference::elastic_impact_with_gravity(0.107, v0, k, 9.81);
        assert_rel(
            &format!("P at {v0:.1} m/s"),
            i.peak_force_n,
            r.peak_force_n,
            0.005,
        );
        assert_rel(
            &format!("t at {v0:.1} m/s"),
            i.contact_time_s,
            r.contact_time_s,
            0.005,
        );
    }
}

/// Values of `xs` rise strictly at every step.
fn strictly_rising(xs: &[f64]) -> bool {
    xs.windows(2).all(|w| w[1] > w[0])
}

#[test]
fn fig1_force_up_and_contact_time_slightly_down_with_speed() {
    let f = figure("fig1");
    let p: Vec<f64> = f.impacts.iter().map(|i| i.peak_force_n).collect();
    let t: Vec<f64> = f.impacts.iter().map(|i| -i.contact_time_s).collect();
    println!("P {p:?}\n-t {t:?}");
    assert!(strictly_rising(&p), "force rises with speed");
    assert!(strictly_rising(&t), "contact time falls with speed");
    // "Slightly": the contact time falls less than half as fast as the speed rises (log-log
    // slope; elastic Hertz 0.2), while the force rises faster than the speed (Hertz 1.2).
    let (a, b) = (&f.impacts[0], &f.impacts[6]);
    let lv = (b.v0_m_s / a.v0_m_s).ln();
    let st = (b.contact_time_s / a.contact_time_s).ln() / lv;
    let sp = (b.peak_force_n / a.peak_force_n).ln() / lv;
    println!("d ln t / d ln v0 = {st:.4}, d ln P / d ln v0 = {sp:.4}");
    assert!(st < 0.0 && st.abs() < 0.5, "slope of t: {st}");
    assert!(sp > 1.0, "slope of P: {sp}");
}

#[test]
fn fig2_force_and_time_rise_with_size_and_time_is_longer_when_slower() {
    let f = figure("fig2");
    assert_eq!(f.impacts.len(), 6);
    for v0 in [0.5, 1.0] {
        let mut at: Vec<_> = f.impacts.iter().filter(|i| i.v0_m_s == v0).collect();
        at.sort_by(|a, b| a.diameter_m.total_cmp(&b.diameter_m));
        let d: Vec<f64> = at.iter().map(|i| i.diameter_m).collect();
        assert_eq!(d, [0.06, 0.08, 0.1]);
        // Mass scaled with D^3 from 0.107 kg at 80 mm.
        for i in &at {
            assert_rel(
                "mass",
                i.mass_kg,
                0.107 * (i.diameter_m / 0.08).powi(3),
                1e-12,
            );
        }
        let p: Vec<f64> = at.iter().map(|i| i.peak_force_n).collect();
        let t: Vec<f64> = at.iter().map(|i| i.contact_time_s).collect();
        println!("v0 {v0}: P {p:?} t {t:?}");
        assert!(strictly_rising(&p) && strictly_rising(&t), "v0 {v0}");
    }
    for d in [0.06, 0.08, 0.1] {
        let t = |v0: f64| {
            f.impacts
                .iter()
                .find(|i| i.diameter_m == d && i.v0_m_s == v0)
                .unwrap()
                .contact_time_s
        };
        assert!(t(0.5) > t(1.0), "D {d}: slower impact lasts longer");
    }
}

#[test]
fn fig3_harder_apples_hit_harder_and_shorter() {
    let f = figure("fig3");
    let g: Vec<f64> = f.impacts.iter().map(|i| i.apple_shear_modulus_pa).collect();
    assert_eq!(g, [6e5, 8e5, 1e6, 1.2e6, 1.4e6, 1.6e6]);
    let p: Vec<f64> = f.impacts.iter().map(|i| i.peak_force_n).collect();
    let t: Vec<f64> = f.impacts.iter().map(|i| -i.contact_time_s).collect();
    println!("P {p:?}\n-t {t:?}");
    assert!(strictly_rising(&p), "force rises with G1");
    assert!(strictly_rising(&t), "contact time falls with G1");
}

#[test]
fn fig4_stiff_platforms_change_nothing_and_soft_ones_lower_the_force() {
    let f = figure("fig4");
    let steel = f
        .impacts
        .iter()
        .find(|i| i.platform_shear_modulus_pa == 8.1e10)
        .expect("steel run");
    let (mut stiff, mut soft) = (0, 0);
    for i in &f.impacts {
        let change = i.peak_force_n / steel.peak_force_n - 1.0;
        println!(
            "G2 {:e} Pa: {:.3} N, {:+.3} % vs steel",
            i.platform_shear_modulus_pa,
            i.peak_force_n,
            100.0 * change
        );
        if i.platform_shear_modulus_pa >= 1e8 {
            assert!(
                change.abs() < 0.005,
                "G2 >= 1e8 Pa changes the force < 0.5 %"
            );
            stiff += 1;
        }
        if i.platform_shear_modulus_pa <= i.apple_shear_modulus_pa {
            assert!(change <= -0.20, "G2 <= G1 lowers the force by >= 20 %");
            soft += 1;
        }
    }
    assert_eq!(
        (stiff, soft),
        (3, 4),
        "1e8, wood, steel; 1e4, 1e5, 5e5, 1e6"
    );
}

#[test]
fn fig5_bottom_layer_force_grows_with_layers() {
    let f = figure("fig5");
    for v in [0.25, 0.5] {
        let mut at: Vec<_> = f
            .impacts
            .iter()
            .filter(|i| i.param("v0_m_s") == -v)
            .collect();
        at.sort_by(|a, b| a.param("layers").total_cmp(&b.param("layers")));
        let p: Vec<f64> = at.iter().map(|i| i.peak_force_n).collect();
        println!("v0 {v}: bottom apple P over 1, 2, 3 layers {p:?}");
        assert_eq!(p.len(), 3);
        assert!(strictly_rising(&p), "v0 {v}");
    }
}

#[test]
fn figs6_7_every_case_rolls_within_a_tenth_of_a_second_with_mu_0_3() {
    for id in ["fig6", "fig7"] {
        let f = figure(id);
        assert_eq!(f.rolls.len(), 4);
        for r in &f.rolls {
            println!("{id} {}: rolls at {:.5} s", r.label, r.t_roll_s);
            assert_eq!(r.friction, 0.3);
            assert!(r.t_roll_s.is_finite() && r.t_roll_s < 0.1, "{}", r.label);
            assert_rel(
                "time to rolling, lever R - u",
                r.t_roll_s,
                r.closed.time_s,
                0.005,
            );
            assert_rel(
                "rolling speed, lever R - u",
                r.rolling_speed_m_s,
                r.closed.speed_m_s,
                0.005,
            );
        }
    }
}

#[test]
fn every_check_passes_and_is_in_the_report() {
    let (out, v) = validation();
    let failed: Vec<String> = v.failed().iter().map(|c| c.key.clone()).collect();
    assert!(failed.is_empty(), "failed checks: {failed:?}");
    let text = std::fs::read_to_string(out.join(validate::REPORT)).unwrap();
    let n = v.checks().count();
    assert!(n >= 100, "{n} checks");
    // One table row per check, each ending in its verdict.
    assert_eq!(text.matches(" | PASS |\n").count(), n);
    assert!(text.contains(&format!("**{n} of {n} checks pass.**")));
    // Keys are unique (tests and readers look checks up by them).
    let mut keys: Vec<&str> = v.checks().map(|c| c.key.as_str()).collect();
    keys.sort();
    keys.dedup();
    assert_eq!(keys.len(), n);
}

#[test]
fn report_renders_tables_and_charts() {
    let (out, v) = validation();
    let text = std::fs::read_to_string(out.join(validate::REPORT)).unwrap();
    // Every table row has as many cells as its header.
    let mut cols = 0;
    for line in text.lines() {
        if !line.starts_with('|') {
            cols = 0;
            continue;
        }
        let cells = line.matches(" | ").count() + 1;
        if cols == 0 {
            cols = cells;
        } else if !line.starts_with("|---") {
            assert_eq!(cells, cols, "row with a wrong cell count: {line}");
        }
    }
    // Every chart the report shows is a well-formed SVG beside it, with a curve per run.
    let mut shown = 0;
    for line in text.lines().filter(|l| l.starts_with("![")) {
        let file = line.rsplit_once("](").unwrap().1.trim_end_matches(')');
        let svg = std::fs::read_to_string(out.join(file)).unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap_or_else(|e| panic!("{file}: {e}"));
        let curves = doc
            .descendants()
            .filter(|n| n.has_tag_name("polyline"))
            .count();
        assert!(curves >= 4, "{file}: {curves} polylines");
        shown += 1;
    }
    assert_eq!(
        shown, 10,
        "5 force charts of Figs. 1-5, 2 x 2 of Figs. 6-7, eq. 12"
    );
    assert_eq!(v.files.len(), shown + 1);
    // The paper's inconsistencies are all there.
    for n in 1..=8 {
        assert!(text.contains(&format!("\n### {n}. ")), "erratum {n}");
    }
}

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            files_under(&p, out);
        } else {
            out.push(p);
        }
    }
}

#[test]
fn the_command_reproduces_the_report_byte_for_byte() {
    let (a, v) = validation();
    let b = tmp("validation-cli");
    let _ = std::fs::remove_dir_all(&b);
    let o = Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args(["validate", "--out", b.to_str().unwrap(), "--jobs", "1"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    // The report and its charts (no wall times in them)...
    for f in &v.files {
        let name = f.file_name().unwrap();
        let (x, y) = (
            std::fs::read(f).unwrap(),
            std::fs::read(b.join(name)).unwrap(),
        );
        assert!(
            x == y,
            "{} differs between two runs",
            name.to_string_lossy()
        );
    }
    // ... and every figure's merged table (metrics without wall time), with other --jobs.
    let (mut xs, mut ys) = (vec![], vec![]);
    files_under(&a.join("runs"), &mut xs);
    files_under(&b.join("runs"), &mut ys);
    let merged = |v: &[PathBuf], root: &Path| -> Vec<PathBuf> {
        v.iter()
            .filter(|p| p.ends_with("merged.csv"))
            .map(|p| p.strip_prefix(root).unwrap().to_path_buf())
            .collect()
    };
    let (mx, my) = (merged(&xs, a), merged(&ys, &b));
    assert_eq!(mx.len(), 8, "seven figures and the eq. 12 batch");
    assert_eq!(mx, my);
    for m in &mx {
        assert_eq!(
            std::fs::read(a.join(m)).unwrap(),
            std::fs::read(b.join(m)).unwrap(),
            "{}",
            m.display()
        );
    }
    let _ = std::fs::remove_dir_all(&b);
}

/// The committed copy under docs/validation/ is what the command writes now (issue 7: "a copy
/// of the report and figures committed under docs/validation/, regenerated by the command").
/// A change of the physics that moves a number makes this fail until the copy is regenerated.
#[test]
fn the_committed_copy_in_docs_validation_is_current() {
    let (_, v) = validation();
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/validation");
    let regenerate = validate::report::COMMAND;
    let mut names: Vec<String> = Vec::new();
    for f in &v.files {
        let name = f.file_name().unwrap().to_string_lossy().to_string();
        let committed = std::fs::read(docs.join(&name)).unwrap_or_else(|e| {
            panic!("docs/validation/{name}: {e}; regenerate with `{regenerate}`")
        });
        assert!(
            committed == std::fs::read(f).unwrap(),
            "docs/validation/{name} is stale: regenerate with `{regenerate}`"
        );
        names.push(name);
    }
    // Nothing else in the folder: no chart left over from an older report.
    let mut present: Vec<String> = std::fs::read_dir(&docs)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    present.sort();
    names.sort();
    assert_eq!(present, names, "files in docs/validation/");
}

/// A specs folder edited out of shape is an error message and a non-zero exit, never a panic:
/// here Fig. 1's apple is set down on the plate without speed, so it has no impact to measure.
#[test]
fn a_spec_out_of_shape_is_an_error_not_a_panic() {
    let specs = tmp("validation-bad-specs");
    let _ = std::fs::remove_dir_all(&specs);
    std::fs::create_dir_all(&specs).unwrap();
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/paper");
    for e in std::fs::read_dir(&shipped).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, specs.join(p.file_name().unwrap())).unwrap();
    }
    let fig1 = std::fs::read_to_string(specs.join("fig1.json")).unwrap();
    let at_rest = fig1.replace("[-0.2, -0.4, -0.6, -0.8, -1.0, -1.2, -1.4]", "[0.0]");
    assert_ne!(fig1, at_rest, "the edit applies");
    std::fs::write(specs.join("fig1.json"), at_rest).unwrap();
    let out = tmp("validation-bad-out");
    let o = Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args(["validate", "--specs", specs.to_str().unwrap()])
        .args(["--out", out.to_str().unwrap(), "--jobs", "1"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    println!("{stderr}");
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("fig1.json") && stderr.contains("must approach"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    // Bad options too.
    for args in [vec!["--jobs", "0"], vec!["--specs", "no/such/folder"]] {
        let o = Command::new(env!("CARGO_BIN_EXE_applesim"))
            .arg("validate")
            .args(&args)
            .args(["--out", out.to_str().unwrap()])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.starts_with("error: "), "{args:?}: {stderr}");
    }
    let _ = std::fs::remove_dir_all(&specs);
    let _ = std::fs::remove_dir_all(&out);
}
