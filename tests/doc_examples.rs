//! The command examples the docs print are what the commands print now: every ```text block of
//! README.md, docs/analysis.md and docs/batch.md that starts with `$ applesim ...` is run from the
//! repository root, and each line the block shows must appear in the output, in order (a line
//! with `(...)` matches on the text before and after the elision; a line `...` stands for lines
//! left out). The shown lines are committed golden values (the docs themselves). Where the
//! physics gives an independent figure, the example's numbers are also checked against it: the
//! calibration table against RK4 (tests/common/ode.rs), the README's error examples by
//! reproducing the mistakes they show.

use crate::common;
use common::ode::Setup;
use common::*;
use std::process::Command;

/// (command line, shown output lines) of every `$ applesim` text block of a doc.
fn examples(doc: &str) -> Vec<(String, Vec<String>)> {
    let text = std::fs::read_to_string(repo(doc)).unwrap();
    let mut out = Vec::new();
    let mut rest = text.as_str();
    while let Some(i) = rest.find("```text\n") {
        let body = &rest[i + 8..];
        let end = body.find("```").unwrap();
        let block: Vec<&str> = body[..end].lines().collect();
        if let Some(cmd) = block.first().and_then(|l| l.strip_prefix("$ applesim ")) {
            out.push((
                cmd.to_string(),
                block[1..].iter().map(|l| l.to_string()).collect(),
            ));
        }
        rest = &body[end + 3..];
    }
    out
}

fn run_applesim(cmd: &str) -> (Option<i32>, Vec<String>) {
    let o = Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args(cmd.split_whitespace())
        .current_dir(repo(""))
        .output()
        .unwrap();
    let mut lines: Vec<String> = String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(String::from)
        .collect();
    lines.extend(String::from_utf8_lossy(&o.stderr).lines().map(String::from));
    (o.status.code(), lines)
}

fn line_matches(shown: &str, got: &str) -> bool {
    match shown.split_once("(...)") {
        Some((a, b)) => got.starts_with(a) && got.ends_with(b),
        None => shown == got,
    }
}

/// Every shown line appears in `got`, in order.
fn assert_shown(cmd: &str, shown: &[String], got: &[String]) {
    let mut k = 0;
    for s in shown.iter().filter(|s| s.trim() != "...") {
        match got[k..].iter().position(|g| line_matches(s, g)) {
            Some(j) => k += j + 1,
            None => panic!(
                "`applesim {cmd}` no longer prints\n  {s}\nit prints:\n{}",
                got.join("\n")
            ),
        }
    }
}

#[test]
fn analysis_and_batch_examples_are_current() {
    let mut n = 0;
    for doc in ["docs/analysis.md", "docs/batch.md", "README.md"] {
        for (cmd, shown) in examples(doc) {
            // `batch` examples other than --dry-run write folders and take long: tests/batch.rs.
            if cmd.starts_with("batch") && !cmd.contains("--dry-run") {
                continue;
            }
            let (_, got) = run_applesim(&cmd);
            println!("{doc}: applesim {cmd}: {} lines shown", shown.len());
            assert_shown(&cmd, &shown, &got);
            n += 1;
        }
    }
    // docs/analysis.md: three calibrate examples; docs/batch.md: the dry run.
    assert!(n >= 4, "{n} examples");
}

/// README, Scenario format: the error messages it shows, each from the mistake it describes made
/// in scenarios/drop_on_steel.json saved as `line.json` (a speed of 1e200 m/s; a modulus of
/// 5e-324 Pa; a Poisson ratio of 0.5; a second apple 70 mm from the first, 10 mm inside it; a
/// string in the floor's normal; the apple's diameter left out; a second JSON document after the
/// first; a 1 ms step for the 1.4 m/s drop on steel).
#[test]
fn readme_error_examples_are_current() {
    let readme = std::fs::read_to_string(repo("README.md")).unwrap();
    let shown: Vec<&str> = readme
        .lines()
        .filter(|l| l.starts_with("error: "))
        .collect();
    let text = std::fs::read_to_string(repo("scenarios/drop_on_steel.json")).unwrap();
    let base: serde_json::Value = serde_json::from_str(&text).unwrap();
    let edit = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut v = base.clone();
        f(&mut v);
        serde_json::to_string(&v).unwrap()
    };
    let mistakes: Vec<String> = vec![
        edit(&|v| v["apples"][0]["velocity_m_s"] = serde_json::json!([0, 0, 1e200])),
        edit(&|v| v["materials"]["apple"]["shear_modulus_pa"] = serde_json::json!(5e-324)),
        edit(&|v| v["materials"]["apple"]["poisson_ratio"] = serde_json::json!(0.5)),
        edit(&|v| {
            let mut a2 = v["apples"][0].clone();
            a2["name"] = serde_json::json!("a2");
            a2["position_m"] = serde_json::json!([0.07, 0, 0.0401]);
            v["apples"].as_array_mut().unwrap().push(a2);
        }),
        // The parser's mistakes are made in the file's own text: their positions are shown.
        text.replace(r#""normal": [0, 0, 1]"#, r#""normal": [0, "0", 1]"#),
        text.replace(r#""diameter_m": 0.08, "#, ""),
        format!("{text}{{}}\n"),
        edit(&|v| v["time_step_s"] = serde_json::json!(1e-3)),
    ];
    assert_eq!(shown.len(), mistakes.len(), "{shown:?}");
    let dir = std::env::temp_dir().join(format!("applesim-doc-errors-{}", std::process::id()));
    for (k, (sc, want)) in mistakes.iter().zip(&shown).enumerate() {
        let sub = dir.join(format!("e{k}"));
        std::fs::create_dir_all(&sub).unwrap();
        let p = sub.join("line.json");
        std::fs::write(&p, sc).unwrap();
        let (code, got) = run_applesim(&format!(
            "run {} --out {} -q",
            p.display(),
            sub.join("out").display()
        ));
        assert_eq!(code, Some(1), "{want}");
        // Parser errors name the file as given on the command line: compare from the name on.
        let got: Vec<String> = got
            .iter()
            .map(|g| g.replace(&format!("{}", p.display()), "line.json"))
            .collect();
        assert_shown("run", &[want.to_string()], &got);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The Fig. 1 apple with eq. 12 (ke 0.09, lambda 1000 s/m) and gravity: RK4 of one impact.
fn fig1_damped(v0: f64, ke: f64, lambda: f64, g: f64) -> common::ode::Impact {
    Setup {
        mass_kg: 0.107,
        k: common::ode::fig1_k(),
        r_star_m: 0.04,
        ke,
        lambda_s_m: lambda,
        g_n: g,
    }
    .impact(v0, 0.1)
}

/// docs/analysis.md: the calibration table against RK4: e within 5e-5, peak forces within
/// 0.003 %, contact times within 0.04 %, no lift-off where RK4 has none (checked at twice each).
#[test]
fn calibrate_table_against_rk4() {
    let (code, got) = run_applesim("calibrate scenarios/drop_on_steel.json --ke 0.09 --lambda-s-m 1000 --speeds 0.05,0.2,0.5,1,1.4");
    assert_eq!(code, Some(0));
    let mut n = 0;
    for line in got
        .iter()
        .filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit()))
    {
        let f: Vec<&str> = line.split_whitespace().collect();
        let v0: f64 = f[0].parse().unwrap();
        let want = fig1_damped(v0, 0.09, 1000.0, 9.81);
        if f[2] == "no" {
            assert!(want.rebound_m_s.is_none(), "{v0} m/s: RK4 lifts off");
            assert_ref(
                &format!("{v0} m/s peak"),
                f[5].parse().unwrap(),
                want.peak_force_n,
                2.0 * 0.003e-2,
                "RK4",
            );
        } else {
            let e: f64 = f[2].parse().unwrap();
            let e_want = want.rebound_m_s.unwrap() / v0;
            assert!(
                (e - e_want).abs() <= 2.0 * 5e-5,
                "{v0} m/s: e {e}, RK4 {e_want}"
            );
            assert_ref(
                &format!("{v0} m/s peak"),
                f[4].parse().unwrap(),
                want.peak_force_n,
                2.0 * 0.003e-2,
                "RK4",
            );
            assert_ref(
                &format!("{v0} m/s contact time"),
                f[5].parse::<f64>().unwrap() * 1e-3,
                want.contact_time_s.unwrap(),
                2.0 * 0.04e-2,
                "RK4",
            );
        }
        n += 1;
    }
    assert_eq!(n, 5);
}

/// docs/analysis.md, after the refusal: with gravity the lambda = 10 s/m, 0.2 m/s target is
/// reachable (ke = 0.1041): the 14 ms contact lets gravity take 0.14 m/s, 70 % of v0; e = 0.16 at
/// ke = 0.01 (golden at the printed digits, the contact time and e(0.01) also against RK4).
/// README, the layer example: e = 0.23 at 1 m/s (ke = 0.09, lambda 1000 s/m, gravity), the
/// unloading lasting 14 ms, gravity taking about 0.07 m/s off the rebound of sqrt(ke) = 0.3.
#[test]
fn calibration_figures_in_the_text() {
    let (_, got) = run_applesim(
        "calibrate scenarios/drop_on_steel.json --e 0.3 --speed-m-s 0.2 --lambda-s-m 10",
    );
    let line = got.iter().find(|l| l.starts_with("ke = ")).unwrap();
    let ke: f64 = line[5..]
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((ke - 0.1041).abs() <= 1e-4, "{line}");
    let r = fig1_damped(0.2, ke, 10.0, 9.81);
    let t = r.contact_time_s.unwrap();
    assert!((t * 1e3 - 14.0).abs() <= 1.0, "contact {t} s");
    assert!((9.81 * t - 0.14).abs() <= 0.01 && (9.81 * t / 0.2 - 0.70).abs() <= 0.01);
    let e001 = fig1_damped(0.2, 0.01, 10.0, 9.81).rebound_m_s.unwrap() / 0.2;
    assert!((e001 - 0.16).abs() <= 0.01, "e(ke = 0.01) = {e001}");
    let (_, got) = run_applesim(
        "calibrate scenarios/drop_on_steel.json --ke 0.01 --lambda-s-m 10 --speeds 0.2",
    );
    let row = got
        .iter()
        .find(|l| l.trim_start().starts_with("0.2"))
        .unwrap();
    let e: f64 = row.split_whitespace().nth(2).unwrap().parse().unwrap();
    assert!((e - 0.16).abs() <= 0.01, "{row}");
    // The layer example (README): RK4 at 1 m/s.
    let r = fig1_damped(1.0, 0.09, 1000.0, 9.81);
    let e = r.rebound_m_s.unwrap();
    assert!((e - 0.23).abs() <= 0.01, "e = {e}");
    assert!((r.contact_time_s.unwrap() * 1e3 - 14.0).abs() <= 1.0);
    assert!((0.3 - e - 0.07).abs() <= 0.01);
}
