//! The handling line's documented results (docs/handling_line.md, the report of its run, and
//! the handling-line sections of docs/transitions.md and docs/accuracy.md).
//!
//! The run is deterministic (byte-identical files, tests/determinism.rs), but the pile in the
//! bin is chaotic: its figures have no closed form. They are checked as committed golden values
//! (the docs' own figures, at their printed digits: counts exactly, a figure printed to d
//! decimals within one unit of the d-th decimal, i.e. twice the rounding). The parts of the line
//! that are not chaotic (each impact before apples meet) are checked against an independent
//! RK4 integration of the impact (tests/common/ode.rs), given the apple's size and touch speed.

use crate::common;
use applesim::record::events::ContactEvent;
use applesim::scenario::{Accuracy, TimeStep};
use common::ode::{self, Setup};
use common::*;
use std::collections::BTreeMap;
use std::path::PathBuf;

const APPLE: (f64, f64) = (1.1e6, 0.18);
/// Rubber: E = 5 MPa, nu 0.45, as a shear modulus E / (2 (1 + nu)).
const RUBBER: (f64, f64) = (5.0e6 / (2.0 * 1.45), 0.45);
const STEEL: (f64, f64) = (8.1e10, 0.28);
const PLASTIC: (f64, f64) = (1.0e9, 0.3);
const G: f64 = 9.81;

/// `got` printed to `decimals` reads `stated` (within one unit of the last printed digit).
#[track_caller]
fn assert_printed(what: &str, got: f64, stated: f64, decimals: i32) {
    let unit = 10f64.powi(-decimals);
    println!("{what}: {got} (stated {stated})");
    assert!(
        (got - stated).abs() <= unit,
        "{what}: {got} does not read {stated} (golden value, docs)"
    );
}

/// `applesim run scenarios/handling_line.json --out DIR`, once for the tests of this file.
fn line_run() -> &'static PathBuf {
    static DIR: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        let out = std::env::temp_dir().join(format!("applesim-line-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&out);
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_applesim"))
            .args(["run", "scenarios/handling_line.json", "--quiet", "--out"])
            .arg(&out)
            .current_dir(repo(""))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        out
    })
}

fn rows(file: &str) -> Vec<BTreeMap<String, String>> {
    let mut rd = csv::Reader::from_path(line_run().join(file)).unwrap();
    let h = rd.headers().unwrap().clone();
    rd.records()
        .map(|r| {
            let r = r.unwrap();
            h.iter()
                .map(String::from)
                .zip(r.iter().map(String::from))
                .collect()
        })
        .collect()
}

fn num(row: &BTreeMap<String, String>, col: &str) -> f64 {
    row[col]
        .parse()
        .unwrap_or_else(|_| panic!("{col}: {}", row[col]))
}

fn summary() -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(line_run().join("summary.json")).unwrap()).unwrap()
}

/// docs/handling_line.md is `applesim report` of this run, byte for byte (regenerate it with
/// `applesim run scenarios/handling_line.json --out out/line && applesim report out/line --out
/// docs/handling_line.md`).
#[test]
fn the_doc_is_the_report_of_the_run() {
    let want = std::fs::read_to_string(repo("docs/handling_line.md")).unwrap();
    let got = applesim::output::report::line_report(
        line_run(),
        "applesim report out/line --out docs/handling_line.md",
    )
    .unwrap();
    assert!(
        got == want,
        "docs/handling_line.md is not the report of the run; regenerate it. The run's report:\n{got}"
    );
}

/// The line's figures per surface (docs/handling_line.md's audit table: contacts and largest
/// peak force; apple-apple contacts are its "apples on ..." rows together), the bin, the 80 N
/// threshold, the warning.
#[test]
fn documented_results_of_the_line() {
    let contacts = rows("contacts.csv");
    // (contacts, largest peak force N printed to 0.1, contacts above 80 N) per surface.
    let table: [(&str, usize, f64, usize); 6] = [
        ("bin/floor", 19, 294.0, 11),
        ("bin/x_max", 35, 176.2, 7),
        ("another apple", 180, 192.9, 28),
        ("chute", 40, 77.2, 0),
        ("bin/x_min", 3, 27.0, 0),
        ("belt", 20, 22.1, 0),
    ];
    for (surface, n, peak, above) in table {
        let of: Vec<f64> = contacts
            .iter()
            .filter(|r| {
                if surface == "another apple" {
                    r["b"].starts_with("feed-")
                } else {
                    r["b"] == surface
                }
            })
            .map(|r| num(r, "peak_force_n"))
            .collect();
        assert_eq!(of.len(), n, "{surface}: contacts");
        assert_printed(
            &format!("{surface}: largest peak force"),
            of.iter().cloned().fold(0.0, f64::max),
            peak,
            1,
        );
        assert_eq!(
            of.iter().filter(|&&p| p > 80.0).count(),
            above,
            "{surface}: contacts above 80 N"
        );
    }
    // The scene as the doc describes it (scenario.json, the scenario as run).
    let sc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(line_run().join("scenario.json")).unwrap()).unwrap();
    let f = |v: &serde_json::Value| v.as_f64().unwrap();
    let feed = &sc["sources"][0];
    assert_eq!(
        [
            f(&feed["count"]),
            f(&feed["rate_per_s"]),
            f(&feed["diameter_m"]["mean_m"]),
            f(&feed["diameter_m"]["spread_m"])
        ],
        [20.0, 4.0, 0.075, 0.005]
    );
    let surf = |n: &str| {
        sc["surfaces"]
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["name"] == n)
            .unwrap()
            .clone()
    };
    let belt = surf("belt");
    assert_eq!(f(&belt["belt_velocity_m_s"]), 0.5);
    // Belt top 0.8 m high: centre 0.78 m, 0.04 m thick.
    assert_printed(
        "belt top",
        f(&belt["position_m"][2]) + 0.5 * f(&belt["size_m"][2]),
        0.8,
        2,
    );
    let chute = surf("chute");
    assert_eq!(
        [f(&chute["incline_deg"]), f(&chute["length_m"])],
        [20.0, 1.0]
    );
    assert_eq!(
        [f(&sc["contact"]["ke"]), f(&sc["contact"]["lambda_s_m"])],
        [0.09, 1000.0]
    );
    assert_eq!(
        [
            f(&sc["contact"]["friction"]),
            f(&sc["pairs"][0]["friction"])
        ],
        [0.5, 0.3]
    );
    let s = summary();
    // 10 s in 200 000 steps of 50 us.
    assert_eq!(s["steps"], 200_000);
    assert_eq!(s["time_step_s"].as_f64(), Some(5e-5));
    // All 20 apples end in the bin (inside 1.9997 +- 0.25 m, 0 +- 0.2 m, floor to wall top).
    let apples = s["apples"].as_array().unwrap();
    assert_eq!(apples.len(), 20);
    for a in apples {
        let p: Vec<f64> = a["final_position_m"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert!(
            (p[0] - 1.9997).abs() < 0.25 && p[1].abs() < 0.2 && p[2] > 0.0 && p[2] < 0.35,
            "{}: ends at {p:?}, outside the bin",
            a["name"]
        );
        // Every apple takes at least one impact above the 80 N threshold.
        assert!(a["peak_force_n"].as_f64().unwrap() > 80.0, "{}", a["name"]);
    }
    // The chute's lower end is about 0.4 m above the bin floor (z = 0.589 - 0.5 sin 20 deg).
    assert_printed(
        "chute end height",
        0.589 - 0.5 * 20f64.to_radians().sin(),
        0.4,
        1,
    );
    // They leave the chute at about 2.0 m/s horizontally (transitions.csv: airborne from the
    // chute, moving along its 20 degree slope).
    for r in rows("transitions.csv")
        .iter()
        .filter(|r| r["from_surface"] == "chute" && r["to"] == "airborne" && num(r, "x_m") > 1.5)
    {
        let vx = num(r, "speed_m_s") * 20f64.to_radians().cos();
        assert_printed(&format!("{} leaves the chute", r["apple"]), vx, 2.0, 1);
    }
    // Two warnings: the feed is exactly symmetric (20 apples down one lane, no jitter: issue
    // 31), and an apple-apple overlap of 22.0 % of the radius.
    let w = s["warnings"].as_array().unwrap();
    assert_eq!(w.len(), 2, "{w:?}");
    let (feed, overlap) = (w[0].as_str().unwrap(), w[1].as_str().unwrap());
    assert!(
        feed.starts_with("source 'feed' (sources[0]) feeds 20 apples from one spot with no jitter across gravity: every apple starts on the vertical line through [-0.6, 0, 0.842] m"),
        "{feed}"
    );
    assert!(
        overlap.contains("an overlap of 22.0 % of the radius"),
        "{overlap}"
    );
}

/// docs/transitions.md, "The handling line": 841 transitions, 253 slip episodes, all 20 apples
/// rolling (at rest) at the end; rolling starts on the belt 0.160-0.168 m from its upstream end
/// and on the chute 39-74 mm from its top.
#[test]
fn documented_transitions_of_the_line() {
    let s = summary();
    let m = &s["metrics"];
    assert_eq!(m["transitions"], 841.0);
    assert_eq!(m["slip_episodes"], 253.0);
    assert_eq!(m["apples_rolling_at_end"], 20.0);
    assert_eq!(rows("transitions.csv").len(), 841);
    let along = |surface: &str| -> Vec<f64> {
        s["transitions"]["surfaces"]
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["surface"] == surface)
            .unwrap()["rolling_start_along_m"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let belt = along("belt");
    assert_printed("belt: first rolling start", belt[0], 0.160, 3);
    assert_printed("belt: last rolling start", belt[2], 0.168, 3);
    let chute = along("chute");
    assert_printed("chute: first rolling start (mm)", 1e3 * chute[0], 39.0, 0);
    assert_printed("chute: last rolling start (mm)", 1e3 * chute[2], 74.0, 0);
}

/// The RK4 peak force of an impact of the line's eq. 12 (ke 0.09, lambda 1000 s/m) at the
/// event's touch speed, for an apple of the event's radius (a^2 / u = R on a flat) and density
/// 800 kg/m^3, against a surface of (G, nu), with gravity g_n into the surface.
fn rk4_peak(e: &ContactEvent, other: (f64, f64), g_n: f64) -> f64 {
    let r = e.max_contact_radius_m.powi(2) / e.max_overlap_m;
    Setup {
        mass_kg: 800.0 * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3),
        k: ode::hertz_k(APPLE.0, APPLE.1, other.0, other.1, r),
        r_star_m: r,
        ke: 0.09,
        lambda_s_m: 1000.0,
        g_n,
    }
    .peak_force(e.approach_speed_m_s)
}

/// docs/accuracy.md, "Adaptive against fixed steps on the handling line": each policy's steps
/// and its peak force errors against RK4 on the impacts that are not chaotic: the 20 belt
/// landings (worst and mean of |error|), the first apple's chute impact and its bin floor impact.
#[test]
fn policies_on_the_line_against_rk4() {
    // (label, step, accuracy, steps, belt worst %, belt mean %, chute %, bin floor %).
    type Row = (
        &'static str,
        TimeStep,
        Option<Accuracy>,
        u64,
        f64,
        f64,
        f64,
        f64,
    );
    let table: [Row; 4] = [
        (
            "adaptive, balanced",
            TimeStep::Adaptive,
            Some(Accuracy::Balanced),
            12_306,
            1.65,
            0.40,
            0.18,
            -0.19,
        ),
        (
            "auto, balanced",
            TimeStep::Auto,
            Some(Accuracy::Balanced),
            46_664,
            0.44,
            0.17,
            -0.51,
            -0.25,
        ),
        (
            "auto, preview",
            TimeStep::Auto,
            Some(Accuracy::Preview),
            23_332,
            1.30,
            0.52,
            0.077,
            -2.9,
        ),
        (
            "own 5e-5 s",
            TimeStep::Fixed(5e-5),
            None,
            200_000,
            0.085,
            0.046,
            -0.006,
            -0.032,
        ),
    ];
    // A fixed 8.58e-4 s is refused: the fastest impacts would get fewer than 10 steps.
    let mut sc = shipped("scenarios/handling_line.json");
    sc.time_step_s = TimeStep::Fixed(8.58e-4);
    let err = applesim::sim::run(
        &sc,
        &repo("scenarios"),
        &mut applesim::record::series::NoSamples,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("need >= 10"), "{err}");
    let chute_g = G * 20f64.to_radians().cos();
    for (label, step, acc, steps, worst, mean, chute, floor) in table {
        let mut sc = shipped("scenarios/handling_line.json");
        sc.time_step_s = step;
        sc.accuracy = acc;
        sc.output.sample_interval_s = Some(0.5);
        let (r, _) = run(&sc);
        assert_eq!(r.steps, steps, "{label}: steps");
        // Each apple's first contact is its landing on the belt.
        let mut seen = std::collections::BTreeSet::new();
        let landings: Vec<f64> = r
            .events
            .iter()
            .filter(|e| seen.insert(e.a.to_string()))
            .map(|e| {
                assert_eq!(&*e.b, "belt", "{label}: {} lands first on {}", e.a, e.b);
                100.0 * (e.peak_force_n / rk4_peak(e, RUBBER, G) - 1.0).abs()
            })
            .collect();
        assert_eq!(landings.len(), 20);
        let w = landings.iter().cloned().fold(0.0, f64::max);
        let m = landings.iter().sum::<f64>() / 20.0;
        let first = |b: &str| {
            r.events
                .iter()
                .find(|e| &*e.a == "feed-1" && &*e.b == b)
                .unwrap()
        };
        let c = first("chute");
        let f = first("bin/floor");
        let ec = 100.0 * (c.peak_force_n / rk4_peak(c, STEEL, chute_g) - 1.0);
        let ef = 100.0 * (f.peak_force_n / rk4_peak(f, PLASTIC, G) - 1.0);
        println!(
            "{label}: belt worst {w:.3} % mean {m:.3} %, chute {ec:+.3} % ({:.4} m/s), floor {ef:+.3} % ({:.4} m/s, {:.2} N)",
            c.approach_speed_m_s, f.approach_speed_m_s, f.peak_force_n
        );
        // Each within twice the stated figure (docs/accuracy.md).
        assert!(
            w <= 2.0 * worst,
            "{label}: worst belt landing {w} % (stated {worst} %)"
        );
        assert!(
            m <= 2.0 * mean,
            "{label}: mean belt landing {m} % (stated {mean} %)"
        );
        assert!(
            ec.abs() <= 2.0 * chute.abs(),
            "{label}: chute {ec} % (stated {chute} %)"
        );
        assert!(
            ef.abs() <= 2.0 * floor.abs(),
            "{label}: floor {ef} % (stated {floor} %)"
        );
    }
}

/// docs/accuracy.md: the first apple hits the empty bin's floor at 2.95 m/s with 294 N (golden
/// values; `policies_on_the_line_against_rk4` checks that force against RK4 at the scenario's
/// own step).
#[test]
fn bin_floor_impact_reads_as_documented() {
    let contacts = rows("contacts.csv");
    let f = contacts
        .iter()
        .find(|r| r["a"] == "feed-1" && r["b"] == "bin/floor")
        .unwrap();
    assert_printed("touch speed", num(f, "approach_speed_m_s"), 2.95, 2);
    assert_printed("peak force", num(f, "peak_force_n"), 294.0, 0);
}
