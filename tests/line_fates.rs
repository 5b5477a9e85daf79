//! Issue 20 acceptance: where the apples of a line end, and what `applesim run` says about it.
//! A scenario whose source overlaps a chute is refused (the message names the source and the
//! surface); a scenario where apples fall off the line warns and lists them with time and
//! place (`summary.json` `apples[].fate`, the warnings, the CLI's end message); a source that
//! waits reports the wait in apples and seconds with its cause. The end message prints times as
//! a person writes them, an adaptive run its step range, and no progress bar when standard
//! error is not a terminal.

use crate::common;
use common::*;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("line_fates_{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The shipped handling line, as JSON, changed by `edit`, written to `dir/scenario.json`.
fn line_scenario(dir: &Path, edit: impl FnOnce(&mut Value)) -> PathBuf {
    let mut v: Value = serde_json::from_str(
        &std::fs::read_to_string(repo("scenarios/handling_line.json")).unwrap(),
    )
    .unwrap();
    edit(&mut v);
    let path = dir.join("scenario.json");
    std::fs::write(&path, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    path
}

/// `applesim run SCENARIO --out OUT ARGS...`, standard error a pipe (not a terminal).
fn applesim_run(scenario: &Path, out: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_applesim"))
        .arg("run")
        .arg(scenario)
        .arg("--out")
        .arg(out)
        .args(args)
        .output()
        .unwrap()
}

fn json_file(p: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap()
}

/// The line without its chute, the feed moved near the belt's end (x = 0.75 m): each apple
/// rides the belt off its end and falls past the bin (which starts at x = 1.75 m) to the floor
/// of the scene, three apples over 1.5 s.
fn line_without_chute(v: &mut Value) {
    v["surfaces"]
        .as_array_mut()
        .unwrap()
        .retain(|s| s["name"] != "chute");
    v["sources"][0]["count"] = json!(3);
    v["sources"][0]["position_m"][0] = json!(0.45);
    v["duration_s"] = json!(1.5);
}

#[test]
fn a_source_overlapping_the_chute_is_refused_naming_both() {
    let dir = tmp("overlap");
    // The feed's spawn point put on the chute's top (its position_m, on the steel).
    let sc = line_scenario(&dir, |v| {
        v["sources"][0]["position_m"] = v["surfaces"][1]["position_m"].clone();
    });
    let out = dir.join("out");
    let o = applesim_run(&sc, &out, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    println!("{err}");
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with("error: sources[0].position_m: the spawn point of source 'feed' overlaps surface 'chute' (surfaces[1]: its position_m, length_m, width_m, radius_m, incline_deg, thickness_m, rotation, place) by "),
        "{err}"
    );
    assert!(err.contains("move position_m"), "says what to do: {err}");
    assert_eq!(err.lines().count(), 1, "one plain line, no panic: {err}");
    assert!(!out.exists(), "nothing written");
    // The library says the same, as a typed error, before any step.
    let scen = applesim::scenario::load(&sc).expect("the scenario itself is valid");
    let mut series = applesim::record::series::MemorySeries::default();
    let e = applesim::sim::run(&scen, &repo("scenarios"), &mut series).expect_err("refused");
    assert!(
        e.to_string()
            .contains("source 'feed' overlaps surface 'chute'"),
        "{e}"
    );
}

#[test]
fn apples_falling_off_the_line_are_warned_about_with_time_and_place() {
    let dir = tmp("fall_off");
    let sc = line_scenario(&dir, line_without_chute);
    let out = dir.join("out");
    let o = applesim_run(&sc, &out, &[]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    println!("{stdout}");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = json_file(&out.join("summary.json"));
    let fates: Vec<&Value> = s["apples"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| &a["fate"])
        .collect();
    // feed-1 and feed-2 left; feed-3 (fed at 0.5 s) is still falling at 1.5 s.
    assert_eq!(
        s["fates"],
        json!({"in_bin": 0, "on_surface": 0, "floating": 0, "left_scene": 2, "moving": 1, "never_fed": 0, "spinning_at_rest": 0, "fastest_spin_at_rest_rad_s": 0.0})
    );
    assert_eq!(s["metrics"]["apples_left_scene"], json!(2.0));
    assert_eq!(fates[2]["kind"], "moving");
    let bodies = std::fs::read_to_string(out.join("bodies.csv")).unwrap();
    let mut rd = csv::Reader::from_reader(bodies.as_bytes());
    let h = rd.headers().unwrap().clone();
    let col = |n: &str| h.iter().position(|c| c == n).unwrap();
    let rows: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    let mut lines = Vec::new();
    for (k, f) in fates.iter().take(2).enumerate() {
        let name = format!("feed-{}", k + 1);
        assert_eq!(f["kind"], "left_scene", "{name}: {f}");
        assert_eq!(f["reason"], "below_every_surface", "{name}");
        assert_eq!(
            f["last_surface"]["surface"], "belt",
            "{name}: went off the belt"
        );
        let t = f["time_s"].as_f64().unwrap();
        let off = f["last_surface"]["t_end_s"].as_f64().unwrap();
        let p: Vec<f64> = f["position_m"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let d = s["apples"][k]["diameter_m"].as_f64().unwrap();
        // Below the lowest point of every surface (the bin's floor, z = 0) by more than its
        // radius, past the belt's end (x = 0.75 m), short of the bin (x = 1.75 m).
        assert!(p[2] < -d / 2.0, "{name}: z {}", p[2]);
        assert!(p[0] > 0.75 && p[0] < 1.75, "{name}: x {}", p[0]);
        // A fall of 0.91 m from the belt's top takes at most sqrt(2 h / g) = 0.43 s (less when
        // it tips off the edge moving down), seen at the first 10 ms sample after.
        assert!(
            t > off && t - off < 0.431 + 0.01,
            "{name}: off at {off} s, left at {t} s"
        );
        // bodies.csv has it there then, and keeps it at that place afterwards.
        let mine: Vec<&csv::StringRecord> =
            rows.iter().filter(|r| r[col("apple")] == name).collect();
        let at = |r: &csv::StringRecord| {
            ["x_m", "y_m", "z_m"].map(|c| r[col(c)].parse::<f64>().unwrap())
        };
        let after: Vec<[f64; 3]> = mine
            .iter()
            .filter(|r| r[col("time_s")].parse::<f64>().unwrap() >= t - 1e-9)
            .map(|r| at(r))
            .collect();
        assert!(after.len() > 1, "{name}: rows after leaving");
        for q in &after {
            for i in 0..3 {
                assert!((q[i] - p[i]).abs() < 1e-9, "{name}: {q:?} vs {p:?}");
            }
        }
        println!("{name}: off the belt at {off:.4} s, left at {t} s at {p:?}");
        lines.push((name, t, p, off));
    }
    // The warnings list each with time and place, in summary.json and on the terminal.
    let warnings: Vec<&str> = s["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap())
        .collect();
    for (name, t, _, _) in &lines {
        let w = warnings
            .iter()
            .find(|w| w.starts_with(&format!("apple '{name}' left the scene at t = ")))
            .unwrap_or_else(|| panic!("no warning about {name}: {warnings:?}"));
        assert!(
            w.contains(&format!("t = {} s at [", applesim::sim::fate::secs(*t))),
            "{w}"
        );
        assert!(
            w.contains("fell below every surface (it last touched 'belt', until t = "),
            "{w}"
        );
        assert!(stdout.contains(&format!("warning: {w}")), "{stdout}");
    }
    assert_eq!(
        warnings[0],
        "apple 'feed-1' left the scene at t = 1.04 s at [0.966, 0, -0.0744] m: it fell below every surface (it last touched 'belt', until t = 0.6456 s)"
    );
    assert!(
        stdout.contains("3 apples: 0 in bins, 0 on surfaces, 2 left the scene, 1 moving at the end, 0 never fed in"),
        "{stdout}"
    );

    // With model.scene_bounds, apples leave when their centre leaves the box (here: 0.5 m above
    // the bin's floor), all three, earlier.
    let dir = tmp("bounds");
    let sc = line_scenario(&dir, |v| {
        line_without_chute(v);
        v["model"] = json!({"scene_bounds": {"min_m": [-1, -1, 0.5], "max_m": [2.5, 1, 2]}});
    });
    let out = dir.join("out");
    let o = applesim_run(&sc, &out, &["--quiet"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let b = json_file(&out.join("summary.json"));
    assert_eq!(b["fates"]["left_scene"], json!(3));
    for k in 0..3 {
        let f = &b["apples"][k]["fate"];
        assert_eq!(f["reason"], "outside_scene_bounds", "{f}");
        assert!(f["position_m"][2].as_f64().unwrap() < 0.5, "{f}");
        assert!(
            f["time_s"].as_f64().unwrap()
                < fates
                    .get(k)
                    .and_then(|g| g["time_s"].as_f64())
                    .unwrap_or(2.0)
        );
    }
    assert!(
        b["warnings"][0]
            .as_str()
            .unwrap()
            .contains("it left model.scene_bounds"),
        "{}",
        b["warnings"]
    );
}

/// README, Many apples: a source's apple k appears at start_s + k / rate_per_s; if its spot is
/// still taken it waits, and the apples behind it wait too (the feed keeps its order). Apples of
/// 80 mm leave at 0.5 m/s, one due every 0.1 s, five of them: each enters when the one before
/// has moved a diameter (0.16 s after it), so apple k (from 0) enters at 0.16 k s and waits
/// 0.06 k s: 0.06, 0.12, 0.18 s; the fifth, due at 0.4 s, would enter at 0.64 s and is still
/// waiting when the run ends at 0.5 s (0.1 s). The cause of each wait is what held the spot when
/// the apple fell due.
#[test]
fn a_source_that_waits_reports_apples_seconds_and_cause() {
    let v = json!({
        "duration_s": 0.5, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, 0],
        "output": {"sample_interval_s": 1e-3, "force_history": false},
        "materials": {"apple": {"shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800}},
        "contact": {"friction": 0.3, "ke": 0.09, "lambda_s_m": 1000},
        "sources": [{"name": "feed", "material": "apple", "diameter_m": 0.08, "position_m": [0, 0, 0],
            "jitter_m": 0.0, "velocity_m_s": [0.5, 0, 0], "rate_per_s": 10, "start_s": 0.0,
            "count": 5, "seed": 1}]
    });
    let sc = applesim::scenario::from_json(&v.to_string(), "wait").unwrap();
    let (r, _) = run(&sc);
    let f = &r.line.sources[0];
    println!("{f:?}\n{:?}", r.warnings);
    assert_eq!((f.count, f.fed, f.not_due, f.still_waiting), (5, 4, 0, 1));
    assert_eq!(f.waited, 4, "the second to fifth apples waited");
    // Entries are seen at the 1 ms samples: each wait within 2 ms.
    let want = 0.06 + 0.12 + 0.18 + 0.1;
    assert!(
        (f.wait_total_s - want).abs() < 4.0 * 2e-3,
        "{} s, want {want} s",
        f.wait_total_s
    );
    assert!(
        (f.wait_longest_s - 0.18).abs() < 2e-3,
        "{} s",
        f.wait_longest_s
    );
    // The second waited for feed-1; the third for feed-2, and the fourth too (due at 0.3 s,
    // when feed-2 held the spot and the third waited); the fifth (due at 0.4 s) for feed-3.
    let causes: Vec<(&str, usize)> = f
        .blocked_by
        .iter()
        .map(|b| (b.what.as_str(), b.apples))
        .collect();
    assert_eq!(
        causes,
        [
            ("apple 'feed-2'", 2),
            ("apple 'feed-1'", 1),
            ("apple 'feed-3'", 1)
        ]
    );
    assert_eq!(r.line.fates.never_fed, 1);
    let w = r
        .warnings
        .iter()
        .find(|w| w.starts_with("source 'feed': 4 apples waited, "))
        .unwrap_or_else(|| panic!("{:?}", r.warnings));
    println!("{w}");
    assert!(
        w.contains(" s in all, longest 0.18") && w.contains(" s, for apple 'feed-2' (2 held up), apple 'feed-1' (1 held up), apple 'feed-3' (1 held up) to clear the spot"),
        "{w}"
    );
    assert!(
        w.ends_with("; 1 still waiting at the end, never fed in"),
        "{w}"
    );
}

#[test]
fn end_message_in_human_units_with_the_step_range_and_no_bar_on_a_pipe() {
    let dir = tmp("message");
    // A fixed step: "30000 steps of 5e-5 s (1.5 s simulated)", not 1.5000000000000002.
    let sc = line_scenario(&dir, line_without_chute);
    let o = applesim_run(&sc, &dir.join("fixed"), &[]);
    assert!(o.status.success());
    let stdout = String::from_utf8_lossy(&o.stdout);
    let first = stdout.lines().next().unwrap();
    println!("{first}");
    assert!(
        first.starts_with("30000 steps of 5e-5 s (1.5 s simulated) in "),
        "{first}"
    );
    assert!(
        stdout.contains("'feed-1' on 'belt' at t = 0.0407 s"),
        "{stdout}"
    );
    // Standard error is a pipe: no progress bar, no control characters.
    assert!(
        o.stderr.is_empty(),
        "{:?}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!stdout.contains('\r') && !stdout.contains('\x1b'));

    // An adaptive step: the range of the steps taken, as summary.json's step_range_s.
    let mut drop: Value = serde_json::from_str(
        &std::fs::read_to_string(repo("scenarios/drop_on_steel.json")).unwrap(),
    )
    .unwrap();
    drop["time_step_s"] = json!("adaptive");
    // Samples every 1 ms: the steps in free flight are not cut to the 0.1 ms of the shipped file.
    drop["output"]["sample_interval_s"] = json!(1e-3);
    let sc = dir.join("adaptive.json");
    std::fs::write(&sc, drop.to_string()).unwrap();
    let out = dir.join("adaptive");
    let o = applesim_run(&sc, &out, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let first = stdout.lines().next().unwrap();
    println!("{first}");
    let s = json_file(&out.join("summary.json"));
    assert_eq!(s["step_policy"], "adaptive");
    let range: Vec<f64> = s["step_range_s"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(range[0] < range[1], "{range:?}");
    let steps = s["steps"].as_u64().unwrap();
    assert!(
        first.starts_with(&format!("{steps} adaptive steps of ")),
        "{first}"
    );
    // "46 adaptive steps of 2.521e-4 to 9.893e-4 s (0.03 s simulated) in ...": both ends, to 4
    // significant digits, written alike.
    let (lo, hi) = first[format!("{steps} adaptive steps of ").len()..]
        .split_once(" s (")
        .unwrap()
        .0
        .split_once(" to ")
        .unwrap();
    let (lo, hi): (f64, f64) = (lo.parse().unwrap(), hi.parse().unwrap());
    assert!(
        rel(lo, range[0]) < 5e-4 && rel(hi, range[1]) < 5e-4,
        "{lo} {hi} vs {range:?}"
    );
    assert!(first.contains(" s (0.03 s simulated) in "), "{first}");
    assert!(first.contains(" of 2.521e-4 to 9.893e-4 s ("), "{first}");
}

/// README, Outputs: every field of `apples[].fate` (each kind), `fates`, `throughput`, `sources`
/// and the line's metrics is documented (as `name`), from the types `summary.json` is written
/// from.
#[test]
fn readme_documents_the_line_end() {
    use applesim::sim::fate::{
        BinThroughput, Entry, Fate, FateCounts, LastContact, LeaveReason, LineEnd,
    };
    use applesim::world::{Blocker, SourceFeed};
    let readme = std::fs::read_to_string(repo("README.md")).unwrap();
    let start = readme.find("- `apples[].fate`").expect("the fate section");
    let section = &readme[start..readme[start..].find("- `contacts.csv`").unwrap() + start];
    let documented = |what: &str, v: &Value| {
        for (k, x) in v.as_object().unwrap() {
            let shown = if k == "kind" {
                format!("`{}`", x.as_str().unwrap())
            } else {
                format!("`{k}`")
            };
            assert!(
                section.contains(&shown),
                "{what}: {shown} is not in the README"
            );
        }
    };
    let fates = [
        Fate::InBin {
            bin: "bin".into(),
            entered_s: Some(1.0),
        },
        Fate::OnSurface {
            surface: "belt".into(),
        },
        Fate::Floating {},
        Fate::LeftScene {
            reason: LeaveReason::BelowEverySurface,
            time_s: 1.0,
            position_m: [0.0; 3],
            velocity_m_s: [0.0; 3],
            last_surface: Some(LastContact {
                surface: "belt".into(),
                t_end_s: Some(0.5),
            }),
        },
        Fate::Moving {
            speed_m_s: 0.5,
            in_bin: None,
            on: None,
        },
    ];
    for f in &fates {
        let v = serde_json::to_value(f).unwrap();
        documented(f.kind(), &v);
        if let Some(l) = v.get("last_surface") {
            documented("last_surface", l);
        }
    }
    for r in [
        LeaveReason::BelowEverySurface,
        LeaveReason::OutsideSceneBounds,
    ] {
        let shown = format!("`{}`", serde_json::to_value(r).unwrap().as_str().unwrap());
        assert!(section.contains(&shown), "{shown}");
    }
    documented(
        "fates",
        &serde_json::to_value(FateCounts::default()).unwrap(),
    );
    let bin = |name: &str| BinThroughput {
        bin: name.into(),
        apples: 2,
        from_start: 0,
        first_entry_s: Some(1.0),
        last_entry_s: Some(2.0),
        apples_per_s: Some(1.0),
        entries: vec![
            Entry {
                apple: "a".into(),
                time_s: 1.0,
            },
            Entry {
                apple: "b".into(),
                time_s: 2.0,
            },
        ],
    };
    let b = serde_json::to_value(bin("one")).unwrap();
    documented("throughput", &b);
    documented("throughput entries", &b["entries"][0]);
    let feed = SourceFeed {
        name: "feed".into(),
        blocked_by: vec![Blocker {
            what: "apple 'feed-1'".into(),
            apples: 1,
        }],
        ..SourceFeed::default()
    };
    let s = serde_json::to_value(&feed).unwrap();
    documented("sources", &s);
    documented("blocked_by", &s["blocked_by"][0]);
    let line = LineEnd {
        fates: FateCounts::default(),
        throughput: vec![bin("one"), bin("two")],
        sources: vec![feed],
        free_rollers: Vec::new(),
    };
    documented(
        "free_rollers",
        &serde_json::to_value(applesim::world::free_roller::FreeRollerState {
            name: "r".into(),
            angular_velocity_rad_s: 1.0,
            angle_turned_rad: 2.0,
        })
        .unwrap(),
    );
    for (m, _) in line.metrics() {
        let generic = m.replace(".one", ".NAME").replace(".two", ".NAME");
        assert!(
            section.contains(&format!("`{generic}`")),
            "metric {generic} is not in the README"
        );
    }
    // model.scene_bounds in the scenario reference.
    assert!(readme.contains("| `model.scene_bounds` |"));
}

/// The fates and the bin throughput are the same whatever the thread count (the line's first
/// 6 s: apples have entered the bin, later ones are still on the belt).
#[test]
fn fates_and_throughput_do_not_depend_on_the_threads() {
    let dir = tmp("threads");
    let sc = line_scenario(&dir, |v| v["duration_s"] = json!(6.0));
    let mut got = Vec::new();
    for threads in ["1", "2"] {
        let out = dir.join(format!("t{threads}"));
        let o = applesim_run(&sc, &out, &["--quiet", "--threads", threads]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let s = json_file(&out.join("summary.json"));
        let fates: Vec<Value> = s["apples"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| a["fate"].clone())
            .collect();
        got.push((fates, s["fates"].clone(), s["throughput"].clone()));
    }
    let (fates, counts, throughput) = &got[0];
    println!("{counts}\n{throughput}");
    assert!(
        throughput[0]["apples"].as_u64().unwrap() > 0,
        "apples reached the bin"
    );
    assert!(counts["moving"].as_u64().unwrap() > 0);
    assert_eq!(got[0], got[1], "--threads 1 and 2");
    assert_eq!(fates.len(), 20);
}

/// On a terminal `applesim run` draws its bar (elapsed time, simulated time, time left) and
/// clears it before the end message. The terminal is a pseudo-terminal from util-linux
/// `script` (Debian's bsdutils, an essential package); without it the test fails, saying so: a
/// test that cannot see the bar must not pass.
#[test]
fn the_bar_is_drawn_on_a_terminal() {
    let st = Command::new("script")
        .arg("--version")
        .output()
        .unwrap_or_else(|e| {
            panic!(
                "util-linux `script` is needed to give applesim a terminal and could not be run \
             ({e}); on Debian it is in bsdutils (apt-get install bsdutils)"
            )
        });
    assert!(
        st.status.success() && String::from_utf8_lossy(&st.stdout).contains("util-linux"),
        "`script --version` is not util-linux's `script` (the test needs its -q -e -c): {}",
        String::from_utf8_lossy(&st.stdout)
    );
    let dir = tmp("terminal");
    let sc = line_scenario(&dir, line_without_chute);
    let cmd = format!(
        "'{}' run '{}' --out '{}'",
        env!("CARGO_BIN_EXE_applesim"),
        sc.display(),
        dir.join("out").display()
    );
    let o = Command::new("script")
        .args(["-qec", &cmd, "/dev/null"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{text}");
    let bar = text
        .split(['\r', '\n'])
        .find(|l| l.contains(" of 1.5 s simulated, "))
        .unwrap_or_else(|| panic!("no bar drawn: {text:?}"));
    println!("{bar}");
    // "00:00:00 [=>   ] 0.35 of 1.5 s simulated, 0s left"
    assert!(
        bar.contains("00:00:") && bar.contains('[') && bar.contains(" left"),
        "{bar}"
    );
    // Cleared (erase line) before the end message, which follows it whole.
    let end = text
        .find("30000 steps of 5e-5 s (1.5 s simulated)")
        .expect("end message");
    assert!(
        text[..end].ends_with("\x1b[2K"),
        "{:?}",
        &text[end.saturating_sub(80)..end]
    );
}

/// README, Many apples: a source's `mass_kg` is every fed apple's mass (summary.json apples[]
/// and bodies.csv carry it); without it the mass comes from the density and each apple's own
/// diameter; a mass that makes a density outside the range is refused, naming the field.
#[test]
fn a_source_mass_is_every_fed_apples_mass() {
    let source = |mass: Option<f64>| {
        let mut v = json!({
            "duration_s": 0.3, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, 0],
            "output": {"sample_interval_s": 1e-2, "force_history": false},
            "materials": {"apple": {"shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800}},
            "contact": {"friction": 0.3, "ke": 0.09, "lambda_s_m": 1000},
            "sources": [{"name": "feed", "material": "apple",
                "diameter_m": {"mean_m": 0.075, "spread_m": 0.005}, "position_m": [0, 0, 0],
                "velocity_m_s": [1.0, 0, 0], "rate_per_s": 10, "count": 3, "seed": 7}]
        });
        if let Some(m) = mass {
            v["sources"][0]["mass_kg"] = json!(m);
        }
        applesim::scenario::from_json(&v.to_string(), "source").and_then(|sc| {
            applesim::scenario::validate(&sc)?;
            Ok(sc)
        })
    };
    let (r, _) = run(&source(Some(0.15)).unwrap());
    assert_eq!(r.apples.len(), 3);
    for a in &r.apples {
        assert_eq!(a.mass_kg, 0.15, "{}", a.name);
    }
    let diameters: Vec<f64> = r.apples.iter().map(|a| a.diameter_m).collect();
    assert!(diameters[0] != diameters[1], "{diameters:?}");
    let (r, _) = run(&source(None).unwrap());
    for a in &r.apples {
        let want = 800.0 * std::f64::consts::PI / 6.0 * a.diameter_m.powi(3);
        assert_rel(&a.name, a.mass_kg, want, 1e-12);
    }
    // 1e-5 kg (the least mass the ranges take) in an apple of 70 to 80 mm is 0.04 to 0.06
    // kg/m^3, below the density range (1 kg/m^3 at least).
    let e = source(Some(1e-5)).unwrap_err().to_string();
    assert!(e.contains("sources[0].mass_kg"), "{e}");
    // bodies.csv carries it on every row (CLI).
    let dir = tmp("source_mass");
    let path = dir.join("s.json");
    let v: Value = serde_json::to_value(source(Some(0.15)).unwrap()).unwrap();
    std::fs::write(&path, v.to_string()).unwrap();
    let o = applesim_run(&path, &dir.join("out"), &["--quiet"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut rd = csv::Reader::from_path(dir.join("out/bodies.csv")).unwrap();
    let h = rd.headers().unwrap().clone();
    let m = h.iter().position(|c| c == "mass_kg").unwrap();
    let rows: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    assert!(!rows.is_empty());
    assert!(rows.iter().all(|r| &r[m] == "0.15"), "{:?}", rows[0]);
}

/// Issue 31 item 6: the closing line lists every file the run wrote, read back from the folder
/// (charts, the page and the probes' files included), sorted.
#[test]
fn the_closing_line_lists_every_file_of_the_folder() {
    for (scenario, args) in [
        ("scenarios/handling_line_probe.json", vec![]),
        ("scenarios/drop_on_steel.json", vec!["--plots"]),
    ] {
        let dir = tmp(&format!("closing_{}", args.len()));
        let out = dir.join("out");
        let o = applesim_run(&repo(scenario), &out, &args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = String::from_utf8_lossy(&o.stdout);
        let prefix = format!("wrote {}/{{", out.display());
        let line = text
            .lines()
            .find(|l| l.starts_with(&prefix))
            .unwrap_or_else(|| panic!("no closing line: {text}"));
        let listed: Vec<&str> = line[prefix.len()..line.len() - 1].split(", ").collect();
        let mut files: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| {
                let e = e.unwrap();
                let n = e.file_name().to_string_lossy().to_string();
                if e.file_type().unwrap().is_dir() {
                    n + "/"
                } else {
                    n
                }
            })
            .collect();
        files.sort();
        println!("{line}");
        assert_eq!(listed, files);
        assert!(files.iter().any(|f| f == "audit.md"));
    }
}
