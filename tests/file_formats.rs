//! The file promises of README ("Scenario format", "Outputs", "Slip and roll"), docs/analysis.md
//! ("What a run writes", pulse fits), docs/damage.md (the damage files) and docs/transitions.md ("Outputs", "Settings"):
//! every column and key as the docs list them, the documented defaults as they appear in the
//! files a run writes (scenario.json is the scenario as run, defaults filled in), and the
//! sampling rules. The lists below are the docs' own, in their order.

use crate::common;
use common::*;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn cli_run(scenario: &Path, name: &str) -> PathBuf {
    let out = std::env::temp_dir().join(format!("applesim-files-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_applesim"))
        .arg("run")
        .arg(scenario)
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

fn header(path: &Path) -> Vec<String> {
    let mut rd = csv::Reader::from_path(path).unwrap();
    rd.headers().unwrap().iter().map(String::from).collect()
}

fn rows(path: &Path) -> Vec<csv::StringRecord> {
    csv::Reader::from_path(path)
        .unwrap()
        .records()
        .map(|r| r.unwrap())
        .collect()
}

fn json_file(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// The keys of a JSON object, sorted (serde_json's map is sorted when read back).
fn keys(v: &Value) -> Vec<String> {
    let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
    k.sort();
    k
}

fn sorted(v: &[&str]) -> Vec<String> {
    let mut k: Vec<String> = v.iter().map(|s| s.to_string()).collect();
    k.sort();
    k
}

fn has_all(what: &str, got: &[String], want: &[&str]) {
    for w in want {
        assert!(got.iter().any(|g| g == w), "{what}: no '{w}' in {got:?}");
    }
}

#[test]
fn csv_columns_are_as_documented() {
    let drop = cli_run(&repo("scenarios/drop_on_steel.json"), "drop");
    let slip = cli_run(&repo("scenarios/slip_to_roll.json"), "slip");
    // README, Outputs.
    assert_eq!(
        header(&drop.join("contacts.csv")),
        [
            "a",
            "b",
            "t_start_s",
            "t_end_s",
            "duration_s",
            "peak_force_n",
            "t_peak_s",
            "impulse_n_s",
            "max_overlap_m",
            "max_contact_radius_m",
            "max_pressure_pa",
            "approach_speed_m_s",
            "separation_speed_m_s",
            "restitution",
            "absorbed_energy_j",
            "a_absorbed_energy_j",
            "b_absorbed_energy_j",
            "steps",
            "contact_point_m",
            "a_diameter_m",
            "a_mass_kg",
            "b_diameter_m",
            "b_mass_kg",
            "impact_peak_force_n",
            "impact_t_peak_s",
            "impact_duration_s",
            "impact_impulse_n_s",
            "impact_absorbed_energy_j",
            "impact_a_absorbed_energy_j",
            "impact_b_absorbed_energy_j",
            "impact_max_pressure_pa",
            "a_velocity_change_m_s",
            "a_peak_g",
            "b_velocity_change_m_s",
            "b_peak_g",
            "resting_s",
            "resting_mean_force_n",
            "resting_max_force_n",
            "resting_mean_pressure_pa",
            "resting_max_pressure_pa",
            "transfer_point",
            "force_history_cut_s",
        ]
    );
    // README, Line audit.
    assert_eq!(
        header(&drop.join("audit.csv")),
        [
            "transfer_point",
            "contacts",
            "impacts",
            "apples_hit_share",
            "peak_force_n_p50",
            "peak_force_n_p95",
            "peak_force_n_max",
            "peak_g_p50",
            "peak_g_p95",
            "peak_g_max",
            "velocity_change_m_s_p50",
            "velocity_change_m_s_p95",
            "velocity_change_m_s_max",
            "absorbed_energy_j_total",
            "absorbed_energy_j_max",
            "apples_bruised",
            "bruise_volume_mm3_p50",
            "bruise_volume_mm3_p95",
            "bruise_volume_mm3_total",
            "apples_downgraded",
        ]
    );
    assert_eq!(
        header(&drop.join("bodies.csv")),
        [
            "time_s",
            "apple",
            "x_m",
            "y_m",
            "z_m",
            "vx_m_s",
            "vy_m_s",
            "vz_m_s",
            "wx_rad_s",
            "wy_rad_s",
            "wz_rad_s",
            "fx_n",
            "fy_n",
            "fz_n",
            "slip_m_s",
            "diameter_m",
            "mass_kg"
        ]
    );
    // README, Slip and roll; docs/transitions.md, Outputs.
    assert_eq!(
        header(&slip.join("transitions.csv")),
        [
            "apple",
            "from",
            "to",
            "from_surface",
            "surface",
            "time_s",
            "x_m",
            "y_m",
            "z_m",
            "along_m",
            "speed_m_s",
            "spin_rad_s",
            "slip_m_s",
            "slid_m",
            "sliding_time_s",
            "since_previous_s"
        ]
    );
    // docs/analysis.md.
    assert_eq!(
        header(&drop.join("forces.csv")),
        ["contact", "a", "b", "time_s", "force_n"]
    );
    // docs/damage.md.
    assert_eq!(
        header(&drop.join("apple_contacts.csv")),
        [
            "contact",
            "apple",
            "other",
            "transfer_point",
            "t_start_s",
            "t_peak_s",
            "contact_point_m",
            "peak_force_n",
            "peak_pressure_pa",
            "absorbed_energy_j",
            "contact_absorbed_energy_j",
            "velocity_change_m_s",
            "peak_g",
            "approach_speed_m_s",
            "bruised",
            "site",
            "volume_mm3",
            "apple_grade",
            "static_max_force_n",
            "static_max_pressure_pa",
            "exceeded",
            "outside_validity"
        ]
    );
    assert_eq!(
        header(&drop.join("bruises.csv")),
        [
            "apple",
            "site",
            "x",
            "y",
            "z",
            "first_hit_s",
            "last_hit_s",
            "hits",
            "transfer_points",
            "absorbed_energy_j",
            "bruised",
            "volume_mm3",
            "area_mm2",
            "depth_mm",
            "diameter_mm",
            "apple_grade"
        ]
    );
    assert_eq!(
        header(&drop.join("pulse_fits.csv")),
        [
            "contact",
            "a",
            "b",
            "samples",
            "fit_peak_force_n",
            "fit_contact_time_s",
            "fit_eps",
            "fit_tau",
            "rms_residual_n",
            "converged",
            "k_p",
            "k_p_shape",
            "k_p_measured",
            "peak_force_n",
            "contact_time_s",
            "restitution",
            "effective_mass_kg",
            "eq15_peak_force_n",
            "eq15_error"
        ]
    );
    // summary.json's pulse_fits carry the CSV's fields but eq15_error (docs/analysis.md).
    let s = json_file(&drop.join("summary.json"));
    has_all(
        "summary pulse_fits",
        &keys(&s["pulse_fits"][0]),
        &["k_p", "k_p_shape", "k_p_measured", "eq15_peak_force_n"],
    );
    let mut csv_cols = header(&drop.join("pulse_fits.csv"));
    csv_cols.retain(|c| c != "eq15_error");
    csv_cols.sort();
    assert_eq!(
        keys(&s["pulse_fits"][0]),
        csv_cols,
        "summary pulse_fits: the CSV's fields but eq15_error"
    );

    // contacts.csv semantics: restitution is the ratio of the speeds, empty for a contact that
    // starts at rest (the slip-to-roll apple rests on its plate from t = 0); contact_point_m at
    // the peak force lies on the plate under the apple.
    let c = &rows(&drop.join("contacts.csv"))[0];
    let f = |i: usize| c[i].parse::<f64>().unwrap();
    // Three numbers printed with 9 significant digits, each within 5e-9 of its value.
    assert_rel(
        "restitution = separation / approach",
        f(13),
        f(12) / f(11),
        2e-8,
    );
    let p: Vec<f64> = c[18].split(' ').map(|x| x.parse().unwrap()).collect();
    // (The plate takes 1e-5 of the overlap: the point is 32 nm below its surface.)
    assert!(
        p[0].abs() < 1e-9 && p[1].abs() < 1e-9 && p[2].abs() < 1e-6,
        "contact point {p:?}"
    );
    let at_rest = &rows(&slip.join("contacts.csv"))[0];
    assert_eq!(
        &at_rest[13], "",
        "a contact that starts at rest has no restitution"
    );
    // bodies.csv: slip_m_s is 0 in the air (the drop's first sample, above the plate).
    assert_eq!(
        rows(&drop.join("bodies.csv"))[0][14]
            .parse::<f64>()
            .unwrap(),
        0.0
    );
    // transitions.csv: along_m is empty on a plane (no running direction).
    assert_eq!(&rows(&slip.join("transitions.csv"))[0][9], "");
    // apple_contacts.csv: the default damage model is the `generic` energy model, threshold
    // 0.08 J (docs/damage.md): the shipped drop is elastic (ke = 1), its apple absorbs nothing
    // and is not bruised; its one hit is one site of bruises.csv.
    let row = &rows(&drop.join("apple_contacts.csv"))[0];
    assert!(row[9].parse::<f64>().unwrap() < 1e-6);
    assert_eq!((&row[14], &row[15]), ("false", "0"));
    assert_eq!(rows(&drop.join("bruises.csv")).len(), 1);
    for d in [drop, slip] {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn summary_keys_are_as_documented() {
    let slip = cli_run(&repo("scenarios/slip_to_roll.json"), "summary");
    let s = json_file(&slip.join("summary.json"));
    // README, Outputs.
    has_all(
        "summary",
        &keys(&s),
        &[
            "steps",
            "simulated_time_s",
            "time_step_s",
            "step_policy",
            "step_range_s",
            "sampling",
            "wall_time_s",
            "contacts",
            "apples",
            "warnings",
            "metrics",
            "damage",
            "pulse_fits",
            "transitions",
            "fates",
            "throughput",
            "sources",
        ],
    );
    assert_eq!(
        keys(&s["apples"][0]),
        sorted(&[
            "fate",
            "name",
            "diameter_m",
            "mass_kg",
            "final_position_m",
            "final_velocity_m_s",
            "final_angular_velocity_rad_s",
            "peak_force_n",
            "peak_pressure_pa",
            "contacts",
            "absorbed_energy_j",
            "bruises",
            "bruise_volume_mm3",
            "grade",
            "grade_why"
        ])
    );
    // summary.json's contacts carry contacts.csv's columns, the impact and the resting load as
    // objects (the CSV flattens them, and adds each apple's size, mass, velocity change and
    // peak g, which need the roster, the other body's part of the loss, which follows from the
    // apple's, the transfer point, which the summary's audit section sums up, and where the
    // force history kept in forces.csv stops).
    let mut h: Vec<String> = header(&slip.join("contacts.csv"))
        .into_iter()
        .filter(|c| {
            c == "a_absorbed_energy_j"
                || !(c.starts_with("impact_")
                    || c.starts_with("resting_")
                    || c.starts_with("a_")
                    || c.starts_with("b_")
                    || c == "transfer_point"
                    || c == "force_history_cut_s")
        })
        .chain(["impact".to_string(), "resting".to_string()])
        .collect();
    h.sort();
    assert_eq!(keys(&s["contacts"][0]), h);
    // docs/damage.md: metrics and the damage section.
    let m = keys(&s["metrics"]);
    has_all(
        "metrics",
        &m,
        &[
            "apples_bruised",
            "apples_downgraded",
            "total_bruise_volume_mm3",
            "max_absorbed_energy_j",
            "total_absorbed_energy_j",
            "max_velocity_change_m_s",
        ],
    );
    // docs/batch.md: the metrics a batch's merged.csv copies (the drop: a contact that ends).
    let drop = cli_run(&repo("scenarios/drop_on_steel.json"), "summary-drop");
    let ds = json_file(&drop.join("summary.json"));
    let dm = keys(&ds["metrics"]);
    let _ = std::fs::remove_dir_all(drop);
    has_all(
        "metrics",
        &dm,
        &[
            "contact_events",
            "max_peak_force_n",
            "max_pressure_pa",
            "max_overlap_m",
            "max_contact_duration_s",
            "mean_contact_duration_s",
            "max_final_speed_m_s",
            "mean_final_speed_m_s",
        ],
    );
    // README Slip and roll; docs/transitions.md: metrics and the transitions section.
    has_all(
        "metrics",
        &m,
        &[
            "transitions",
            "slip_episodes",
            "apples_rolling_at_end",
            "mean_first_rolling_s",
            "max_first_rolling_s",
            "mean_slide_distance_m",
            "max_slide_distance_m",
        ],
    );
    assert_eq!(
        keys(&s["damage"]),
        sorted(&[
            "standard",
            "grades",
            "apples_bruised",
            "apples_downgraded",
            "total_bruise_volume_mm3",
            "apples_per_grade",
            "models"
        ])
    );
    // A drop that loses energy (ke 0.09) bruises its apple: its largest bruise and the hit that
    // downgraded it.
    let lossy =
        std::env::temp_dir().join(format!("applesim-files-lossy-{}.json", std::process::id()));
    std::fs::write(
        &lossy,
        std::fs::read_to_string(repo("scenarios/drop_on_steel.json"))
            .unwrap()
            .replace(r#""ke": 1.0"#, r#""ke": 0.09"#)
            .replace(
                r#""velocity_m_s": [0, 0, -1.4]"#,
                r#""velocity_m_s": [0, 0, -3]"#,
            ),
    )
    .unwrap();
    let bruised = cli_run(&lossy, "summary-lossy");
    let ds = json_file(&bruised.join("summary.json"));
    let _ = std::fs::remove_dir_all(bruised);
    let _ = std::fs::remove_file(lossy);
    has_all(
        "apples",
        &keys(&ds["apples"][0]),
        &["largest_bruise", "downgraded_by", "grade", "grade_why"],
    );
    assert_eq!(
        keys(&ds["apples"][0]["largest_bruise"]),
        sorted(&["site", "volume_mm3", "diameter_mm", "depth_mm", "area_mm2"])
    );
    assert_eq!(
        keys(&ds["apples"][0]["downgraded_by"]),
        sorted(&["transfer_point", "with", "t_s", "contact"])
    );
    let t = &s["transitions"];
    assert_eq!(
        keys(t),
        sorted(&["settings", "transitions", "apples", "surfaces"])
    );
    has_all(
        "transitions apples",
        &keys(&t["apples"][0]),
        &[
            "first_rolling_s",
            "slide_distance_m",
            "slip_episodes",
            "final_state",
            "surfaces",
        ],
    );
    // (rolling_start_along_m only on surfaces with a running direction: a plane has none; the
    // belt's and chute's are tests/handling_line.rs.)
    assert!(t["surfaces"][0].get("rolling_start_along_m").is_none());
    has_all(
        "transitions surfaces",
        &keys(&t["surfaces"][0]),
        &[
            "rolling_starts",
            "sliding_starts",
            "histogram_edges_m",
            "histogram_counts",
        ],
    );
    // README / docs/transitions.md, Settings: the defaults.
    assert_eq!(
        t["settings"],
        json!({"enabled": true, "slip_speed_m_s": 0.005, "relative_tolerance": 0.01, "hysteresis": 2.0, "min_dwell_s": 0.01, "histogram_bin_m": 0.05})
    );
    // The scenario as run, model defaults filled in (README, Scenario format): overlap 0.5,
    // 10 steps per impact, energy 5 %, the history dashpot bound 1.5, 2e8 steps, 8192 MiB of
    // memory and 4096 MiB of output, sleeping on at 5 mm/s for 0.2 s, riding belts on; the
    // default fidelity is hertz-damped.
    let sc = json_file(&slip.join("scenario.json"));
    assert_eq!(
        sc["model"],
        json!({"max_overlap_ratio": 0.5, "min_steps_per_impact": 10.0, "sleep": {"enabled": true, "speed_m_s": 0.005, "time_s": 0.2, "carried": true}, "energy_tolerance": 0.05, "history_dashpot_bound": 1.5, "max_steps": 200_000_000, "max_memory_mb": 8192.0, "max_output_mb": 4096.0})
    );
    assert_eq!(sc["fidelity"], "hertz-damped");
    assert!(s["fidelity"].as_str().unwrap().starts_with("hertz-damped"));
    let _ = std::fs::remove_dir_all(slip);
}

/// One apple in free flight (no surface): the step policies' caps and the sampling rules.
fn flight(time_step: &str, sample: Option<f64>) -> (applesim::sim::RunResult, Vec<f64>) {
    let mut v = json!({
        "duration_s": 0.5, "time_step_s": time_step, "gravity_m_s2": [0, 0, -9.81],
        "output": {},
        "materials": {"apple": {"shear_modulus_pa": 1.0e5, "poisson_ratio": 0.18, "density_kg_m3": 800}},
        "contact": {"friction": 0.3, "ke": 0.09, "lambda_s_m": 1000},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 0.08, "position_m": [0, 0, 10]}]
    });
    if let Some(x) = sample {
        v["output"]["sample_interval_s"] = json!(x);
    }
    let sc = applesim::scenario::from_json(&v.to_string(), "flight").unwrap();
    let (r, s) = run(&sc);
    let times = s.of(0).iter().map(|(t, _)| *t).collect();
    (r, times)
}

#[test]
fn step_caps_and_sampling_are_as_documented() {
    // README: max_time_step_s defaults to the output interval, at most 1 ms for auto, 10 ms for
    // adaptive.
    let (r, _) = flight("auto", Some(0.1));
    assert_eq!(r.time_step_s, 1e-3, "auto is capped at 1 ms");
    let (r, _) = flight("adaptive", Some(0.1));
    assert!(
        (r.step_range_s[1] - 1e-2).abs() < 1e-12,
        "adaptive is capped at 10 ms: {:?}",
        r.step_range_s
    );
    let (r, _) = flight("auto", Some(2e-4));
    assert_eq!(r.time_step_s, 2e-4, "capped by the output interval");
    // README: output.sample_interval_s defaults to 1 ms for a short run (one apple, 0.5 s).
    let (_, t) = flight("auto", None);
    assert_eq!(t.len(), 501);
    assert!(t.windows(2).all(|w| (w[1] - w[0] - 1e-3).abs() < 1e-12));
    // ... and is rounded to whole steps: 25 us at 10 us steps samples every 3 steps.
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.output.sample_interval_s = Some(2.5e-5);
    sc.duration_s = 1e-3;
    let (_, s) = run(&sc);
    let t: Vec<f64> = s.of(0).iter().map(|(t, _)| *t).collect();
    // Every sample on the 30 us grid (the end state at 1 ms comes last).
    let (grid, last) = t.split_at(t.len() - 1);
    for (k, x) in grid.iter().enumerate() {
        assert!(
            (x - 3e-5 * k as f64).abs() < 1e-12,
            "sample {k} at {x}: {grid:?}"
        );
    }
    assert!((last[0] - 1e-3).abs() < 1e-12, "{last:?}");
}
