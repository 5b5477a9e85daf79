//! Slip-to-roll transitions as results (issue 8 acceptance): the detector's transition time,
//! speed, slide distance and position against physics.md section 6's closed forms on a flat
//! plate and a belt; roll -> slide at a transfer onto a steep chute and none onto a gentle one;
//! no chatter; the outputs (transitions.csv, summary.json section, metrics, bodies.csv slip).

use crate::common;
use applesim::contact::theory;
use applesim::record::transitions::{Motion, Transition};
use applesim::scenario::Scenario;
use common::ode;
use common::*;
use serde_json::json;

const R: f64 = 0.04;
const G: f64 = 9.81;

/// The shipped slip-to-roll apple on its steel plate with the given launch and friction.
fn plate(v0: f64, w0: f64, mu: f64, duration: f64) -> Scenario {
    let mut sc = shipped("scenarios/slip_to_roll.json");
    sc.apples[0].velocity_m_s = [v0, 0.0, 0.0];
    sc.apples[0].angular_velocity_rad_s = [0.0, w0, 0.0];
    sc.contact.friction = mu;
    sc.duration_s = duration;
    sc.output.sample_interval_s = Some(0.01);
    sc
}

fn only_transition(t: &[Transition]) -> &Transition {
    assert_eq!(t.len(), 1, "one transition expected, got {t:#?}");
    &t[0]
}

/// A row of docs/transitions.md's table "Measured against the closed forms": the launch, and the
/// stated figures: transition time (ms, golden at 3 decimals), its error against the closed form
/// with R and with the lever R - u (%), the rolling speed's error with R - u (%), the slide
/// distance (mm, golden) and its errors with R and with R - u (%).
struct PlateRow {
    v0: f64,
    w0: f64,
    mu: f64,
    t_ms: f64,
    t_err: f64,
    t_err_lever: f64,
    v_err_lever: f64,
    slide_mm: f64,
    slide_err: f64,
    slide_err_lever: f64,
}

#[rustfmt::skip]
const PLATE: [PlateRow; 9] = [
    PlateRow { v0: 0.0, w0: 20.0, mu: 0.2, t_ms: 116.756, t_err: 0.22, t_err_lever: 0.00011, v_err_lever: 0.00016, slide_mm: 46.462, slide_err: 0.30, slide_err_lever: 0.00035 },
    PlateRow { v0: 0.0, w0: 20.0, mu: 0.3, t_ms: 77.838, t_err: 0.22, t_err_lever: 0.000069, v_err_lever: 0.00018, slide_mm: 30.974, slide_err: 0.30, slide_err_lever: 0.00050 },
    PlateRow { v0: 0.0, w0: 20.0, mu: 0.6, t_ms: 38.919, t_err: 0.22, t_err_lever: 0.00011, v_err_lever: 0.00019, slide_mm: 15.487, slide_err: 0.30, slide_err_lever: 0.00092 },
    PlateRow { v0: 0.5, w0: -10.0, mu: 0.2, t_ms: 131.729, t_err: 0.51, t_err_lever: 0.00020, v_err_lever: 0.00026, slide_mm: 59.142, slide_err: 0.28, slide_err_lever: 0.0000074 },
    PlateRow { v0: 0.5, w0: -10.0, mu: 0.3, t_ms: 87.819, t_err: 0.51, t_err_lever: 0.00021, v_err_lever: 0.00032, slide_mm: 39.428, slide_err: 0.28, slide_err_lever: 0.000076 },
    PlateRow { v0: 0.5, w0: -10.0, mu: 0.6, t_ms: 43.910, t_err: 0.51, t_err_lever: 0.00012, v_err_lever: 0.00039, slide_mm: 19.714, slide_err: 0.28, slide_err_lever: 0.00039 },
    PlateRow { v0: 0.5, w0: 0.0, mu: 0.2, t_ms: 73.351, t_err: 0.74, t_err_lever: 0.00031, v_err_lever: 0.00017, slide_mm: 18.338, slide_err: 0.74, slide_err_lever: 0.00018 },
    PlateRow { v0: 0.5, w0: 0.0, mu: 0.3, t_ms: 48.901, t_err: 0.74, t_err_lever: 0.00028, v_err_lever: 0.00020, slide_mm: 12.225, slide_err: 0.74, slide_err_lever: 0.000020 },
    PlateRow { v0: 0.5, w0: 0.0, mu: 0.6, t_ms: 24.450, t_err: 0.74, t_err_lever: 0.000044, v_err_lever: 0.00023, slide_mm: 6.113, slide_err: 0.74, slide_err_lever: 0.00055 },
];

/// README "Slip and roll": on a flat plate the transition time is within 0.0006 % and the slide
/// distance within 0.002 % of the closed forms with the true lever arm (R - u from the static
/// sag; the worst cases are slip_sweep's 0.25 m/s at mu = 0.6: 0.00056 % and 0.0018 %).
const README_TIME: f64 = 0.0006e-2;
const README_SLIDE: f64 = 0.002e-2;

fn check_plate(row: &PlateRow) {
    let (v0, w0, mu) = (row.v0, row.w0, row.mu);
    let cf = theory::slip_to_roll(v0, w0, R, mu, G);
    let x0 = 0.0;
    let (r, _) = run(&plate(v0, w0, mu, 1.5 * cf.time_s + 0.03));
    let e = only_transition(&r.transitions);
    println!("v0 {v0} w0 {w0} mu {mu}: {e:?}");
    assert_eq!((e.from, e.to), (Motion::Sliding, Motion::Rolling));
    assert_eq!(e.surface.as_deref(), Some("plate"));
    // The transition time and slide distance as docs/transitions.md prints them (golden values,
    // within one unit of the last printed digit).
    assert!(
        (1e3 * e.time_s - row.t_ms).abs() <= 1e-3,
        "t {} ms, table {}",
        1e3 * e.time_s,
        row.t_ms
    );
    assert!(
        (1e3 * e.slid_m - row.slide_mm).abs() <= 1e-3,
        "slide {} mm, table {}",
        1e3 * e.slid_m,
        row.slide_mm
    );
    // Against the closed forms with R (physics.md section 6), within twice the stated errors.
    assert_rel(
        "transition time",
        e.time_s,
        cf.time_s,
        2.0 * row.t_err / 100.0,
    );
    assert_rel(
        "slide distance",
        e.slid_m,
        cf.slide_distance_m,
        2.0 * row.slide_err / 100.0,
    );
    assert_rel(
        "sliding time",
        e.sliding_time_s,
        cf.time_s,
        2.0 * row.t_err / 100.0,
    );
    // The rolling speed with R: the 1 % rule of physics.md section 6.
    assert_rel("rolling speed", e.speed_m_s, cf.speed_m_s.abs(), 0.01);
    // Where it starts rolling: the centre travel while sliding, within 0.61 % of the closed form
    // with R (docs/transitions.md), checked at twice that.
    let travel = e.position_m[0] - x0;
    if cf.centre_travel_m.abs() > 1e-3 {
        assert_rel("centre travel", travel, cf.centre_travel_m, 2.0 * 0.61e-2);
    }
    // The centre at the transition: 0.06-0.15 um below R - u, u the closed-form sag
    // (docs/transitions.md: the scenario starts it 0.19 um deep and the resting contact relaxes
    // back), within twice the larger figure.
    let u_cf = ode::resting_sag(ode::hertz_k(1.0e6, 0.18, 8.1e10, 0.28, R), 0.09, 0.107 * G);
    let depth = (R - u_cf) - e.position_m[2];
    println!("centre {:.3} um below R - u", 1e6 * depth);
    assert!(
        depth > 0.0 && depth <= 2.0 * 0.15e-6,
        "{depth} m below R - u"
    );
    // With the true lever arm R - u from the closed form (the resting sag under eq. 12,
    // tests/common/ode.rs): within twice the table's figure, and within twice README's.
    let tight = theory::slip_to_roll_with_lever(v0, w0, R, ode::fig6_lever(), mu, G);
    let t_tol = (2.0 * row.t_err_lever / 100.0).min(2.0 * README_TIME);
    let s_tol = (2.0 * row.slide_err_lever / 100.0).min(2.0 * README_SLIDE);
    assert_rel(
        "transition time, lever R - u",
        e.time_s,
        tight.time_s,
        t_tol,
    );
    assert_rel(
        "rolling speed, lever R - u",
        e.speed_m_s,
        tight.speed_m_s.abs(),
        2.0 * row.v_err_lever / 100.0,
    );
    assert_rel(
        "slide distance, lever R - u",
        e.slid_m,
        tight.slide_distance_m,
        s_tol,
    );
    // The summary agrees with the event.
    let s = r.transition_summary.as_ref().unwrap();
    assert_eq!(s.apples[0].first_rolling_s, Some(e.time_s));
    assert_eq!(s.apples[0].slip_episodes, 1);
    assert_eq!(s.apples[0].final_state, Motion::Rolling);
    assert_eq!(s.apples[0].slide_distance_m, e.slid_m);
}

fn plate_rows(v0: f64, w0: f64) {
    let mut n = 0;
    for row in PLATE.iter().filter(|r| r.v0 == v0 && r.w0 == w0) {
        check_plate(row);
        n += 1;
    }
    assert_eq!(n, 3, "three friction coefficients");
}

#[test]
fn flat_plate_from_speed_only() {
    plate_rows(0.5, 0.0);
}

#[test]
fn flat_plate_from_spin_only() {
    plate_rows(0.0, 20.0);
}

#[test]
fn flat_plate_from_speed_and_backspin() {
    plate_rows(0.5, -10.0);
}

/// An apple at rest on a steel belt moving at `v_belt`: it slides until it rolls with the belt
/// after 2 V / (7 mu g), at 2 V / 7.
#[test]
fn belt_from_rest() {
    let v_belt = 1.0;
    let mu = 0.3;
    let t_cf = 2.0 * v_belt / (7.0 * mu * G);
    let (r, _) = run(&belt(v_belt, mu, 1.5 * t_cf + 0.03));
    let e = only_transition(&r.transitions);
    println!("{e:?}");
    assert_eq!((e.from, e.to), (Motion::Sliding, Motion::Rolling));
    // docs/transitions.md: 97.801 ms (golden) against 2V/(7 mu g) = 97.083 ms, 0.74 %; speed
    // over ground 0.28783 m/s against 2V/7 (0.74 %); slide 48.90 mm against V t / 2 (0.74 %).
    assert!(
        (1e3 * e.time_s - 97.801).abs() <= 1e-3,
        "{} ms",
        1e3 * e.time_s
    );
    assert!((e.speed_m_s - 0.28783).abs() <= 1e-5, "{} m/s", e.speed_m_s);
    assert!(
        (1e3 * e.slid_m - 48.90).abs() <= 1e-2,
        "{} mm",
        1e3 * e.slid_m
    );
    assert_rel("belt transition time", e.time_s, t_cf, 2.0 * 0.74e-2);
    assert_rel(
        "speed over ground",
        e.speed_m_s,
        2.0 * v_belt / 7.0,
        2.0 * 0.74e-2,
    );
    assert_rel(
        "slide distance",
        e.slid_m,
        v_belt * t_cf / 2.0,
        2.0 * 0.74e-2,
    );
    // With the lever arm R - u from the closed form (the same apple and steel as the plate):
    // the slip falls at mu g (1 + 5/2 (rho/R)^2); stated 0.0003 %, checked at twice that.
    let rho = ode::fig6_lever();
    let t_lever = v_belt / (mu * G * (1.0 + 2.5 * (rho / R).powi(2)));
    assert_rel(
        "belt transition time, lever R - u",
        e.time_s,
        t_lever,
        2.0 * 0.0003e-2,
    );
    // Along the belt from its upstream end (x = -0.5).
    let along = e.along_m.unwrap();
    assert!(
        (along - (0.5 + e.position_m[0])).abs() < 1e-3,
        "along {along}"
    );
}

/// The apple at rest on a 2 m steel belt (x from -0.5 to 1.5) running at `v_belt`.
fn belt(v_belt: f64, mu: f64, duration: f64) -> Scenario {
    let v = json!({
        "duration_s": duration, "time_step_s": 1e-5, "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 0.01, "force_history": false},
        "materials": {
            "apple": {"shear_modulus_pa": 1.0e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "steel": {"shear_modulus_pa": 8.1e10, "poisson_ratio": 0.28}},
        "contact": {"friction": mu, "ke": 0.09, "lambda_s_m": 1000, "rolling": "none"},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 0.08, "mass_kg": 0.107,
            "position_m": [0, 0, 0.0397936]}],
        "surfaces": [{"name": "belt", "type": "conveyor", "material": "steel",
            "size_m": [2.0, 0.5, 0.02], "position_m": [0.5, 0, -0.01], "belt_velocity_m_s": v_belt}]
    });
    applesim::scenario::from_json(&v.to_string(), "belt").unwrap()
}

/// A belt carrying an apple onto a chute inclined at `incline_deg` (friction 0.5 everywhere).
fn transfer(incline_deg: f64) -> Scenario {
    let th = incline_deg.to_radians();
    let len = 1.0;
    // The chute's top edge sits just past and below the belt's end: apples roll over it.
    let top = [0.005, 0.0, -0.004];
    let centre = [
        top[0] + 0.5 * len * th.cos(),
        0.0,
        top[2] - 0.5 * len * th.sin(),
    ];
    let v = json!({
        "duration_s": 1.6, "time_step_s": 2e-5, "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 0.005, "force_history": false},
        "materials": {
            "apple": {"shear_modulus_pa": 1.0e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "steel": {"shear_modulus_pa": 8.1e10, "poisson_ratio": 0.28}},
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000, "rolling": "none"},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 0.08, "mass_kg": 0.107,
            "position_m": [-0.1, 0, 0.0397936], "velocity_m_s": [0.1, 0, 0]}],
        "surfaces": [
            {"name": "belt", "type": "conveyor", "material": "steel",
             "size_m": [0.6, 0.3, 0.02], "position_m": [-0.3, 0, -0.01], "belt_velocity_m_s": 0.1},
            {"name": "chute", "type": "chute", "profile": "flat", "material": "steel",
             "length_m": len, "width_m": 0.3, "incline_deg": incline_deg, "position_m": centre}]
    });
    applesim::scenario::from_json(&v.to_string(), "transfer").unwrap()
}

#[test]
fn belt_onto_steep_chute_slides_and_onto_gentle_chute_keeps_rolling() {
    let mu: f64 = 0.5;
    // Steep: tan(65 deg) = 2.14 > 7/2 mu = 1.75: it cannot roll without slipping.
    let steep = 65.0f64;
    assert!(steep.to_radians().tan() > 3.5 * mu);
    let (r, _) = run(&transfer(steep));
    for e in &r.transitions {
        println!("steep: {e:?}");
    }
    // Roll -> slide at the transfer: the first slip is where it leaves the belt, from rolling.
    let slip = r
        .transitions
        .iter()
        .position(|e| e.to == Motion::Sliding)
        .expect("it slides on the steep chute");
    let e = &r.transitions[slip];
    assert_eq!(e.from, Motion::Rolling, "{e:?}");
    assert!(
        e.position_m[0] > -0.04 && e.position_m[0] < 0.1,
        "at the transfer (belt end x = 0): {e:?}"
    );
    // Before: rolling with the belt all along (possibly handed over to the chute's edge).
    assert!(r.transitions[..slip]
        .iter()
        .all(|e| e.to == Motion::Rolling && e.from == Motion::Rolling));
    // After: it never rolls again, and ends sliding down the chute.
    assert!(r.transitions[slip..]
        .iter()
        .all(|e| e.to != Motion::Rolling));
    let last = r.transitions.last().unwrap();
    assert_eq!(
        (last.to, last.surface.as_deref()),
        (Motion::Sliding, Some("chute"))
    );
    let s = r.transition_summary.as_ref().unwrap();
    assert_eq!(s.apples[0].final_state, Motion::Sliding);
    // docs/transitions.md (golden values at their printed digits): rolling hand-over to the
    // chute at 1.1634 s, sliding at 1.1716 s, airborne at 1.1949 s, landing on the chute's face
    // sliding at 1.2419 s, 31 mm along it, slip 0.52 m/s.
    let kinds: Vec<(Motion, Motion, f64)> = r
        .transitions
        .iter()
        .map(|e| (e.from, e.to, e.time_s))
        .collect();
    let want = [
        (Motion::Rolling, Motion::Rolling, 1.1634),
        (Motion::Rolling, Motion::Sliding, 1.1716),
        (Motion::Sliding, Motion::Airborne, 1.1949),
        (Motion::Airborne, Motion::Sliding, 1.2419),
    ];
    assert_eq!(kinds.len(), want.len(), "{kinds:?}");
    for ((f, t, time), (wf, wt, wtime)) in kinds.iter().zip(want) {
        assert_eq!((*f, *t), (wf, wt));
        assert!((time - wtime).abs() <= 1e-4, "{time} s, stated {wtime} s");
    }
    let landing = r.transitions.last().unwrap();
    assert!((1e3 * landing.along_m.unwrap() - 31.0).abs() <= 1.0);
    assert!((landing.slip_m_s - 0.52).abs() <= 0.01);

    // Gentle: tan(10 deg) = 0.18 < 1.75: it rolls down; the mismatch at the transfer (the belt's
    // 0.1 m/s) dies out within the dwell time, so no slip episode counts.
    let gentle = 10.0f64;
    assert!(gentle.to_radians().tan() < 3.5 * mu);
    let (r, _) = run(&transfer(gentle));
    for e in &r.transitions {
        println!("gentle: {e:?}");
    }
    assert!(
        r.transitions.iter().all(|e| e.to != Motion::Sliding),
        "no slip on the gentle chute"
    );
    let s = r.transition_summary.as_ref().unwrap();
    assert_eq!(s.apples[0].final_state, Motion::Rolling);
    assert_eq!(s.apples[0].slip_episodes, 0);
    assert!(
        r.transitions
            .iter()
            .any(|e| e.surface.as_deref() == Some("chute") && e.to == Motion::Rolling),
        "it ends up rolling on the chute"
    );
    // docs/transitions.md: one hand-over, rolling (belt) -> rolling (chute) at 1.1421 s; the
    // transfer's slip, 0.39 mm over 5.6 ms, is shorter than the dwell and does not count.
    assert_eq!(r.transitions.len(), 1, "{:?}", r.transitions);
    let h = &r.transitions[0];
    assert!((h.time_s - 1.1421).abs() <= 1e-4, "{}", h.time_s);
    assert!((1e3 * h.slid_m - 0.39).abs() <= 0.01, "{}", h.slid_m);
    assert!(
        (1e3 * h.sliding_time_s - 5.6).abs() <= 0.1,
        "{}",
        h.sliding_time_s
    );
}

/// No chatter: an apple that slides, then rolls on a flat plate records exactly one transition
/// over 1 s; one launched rolling records none.
#[test]
fn rolling_apple_does_not_chatter() {
    let (r, _) = run(&plate(0.5, 0.0, 0.3, 1.0));
    only_transition(&r.transitions);
    // Launched rolling: v = rho w with the lever arm of its resting sag (closed form).
    let rho = ode::fig6_lever();
    let (r, _) = run(&plate(0.5, 0.5 / rho, 0.3, 1.0));
    assert!(r.transitions.is_empty(), "{:#?}", r.transitions);
    assert_eq!(
        r.transition_summary.as_ref().unwrap().apples[0].final_state,
        Motion::Rolling
    );
}

/// The files: transitions.csv with its header and one row per transition, the summary section,
/// the batch metrics and the slip column of bodies.csv.
#[test]
fn outputs_carry_the_transitions() {
    let sc = plate(0.5, 0.0, 0.3, 0.1);
    let dir = std::env::temp_dir().join(format!("applesim_transitions_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let r = applesim::run::to_dir(&sc, &repo("scenarios"), &dir, &mut |_| {}).unwrap();
    let csv = std::fs::read_to_string(dir.join("transitions.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        applesim::output::TRANSITION_HEADER.join(",")
    );
    let row: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(&row[..5], &["a1", "sliding", "rolling", "plate", "plate"]);
    // The CSV prints 9 significant digits (summary.json the full number).
    let t = r.transitions[0].time_s;
    assert_eq!(row[5], applesim::output::NumberFormat::default().num(t));
    assert!(lines.next().is_none());
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap();
    let tr = &summary["transitions"];
    assert_eq!(tr["transitions"], 1);
    assert_eq!(tr["apples"][0]["first_rolling_s"].as_f64().unwrap(), t);
    assert_eq!(tr["surfaces"][0]["surface"], "plate");
    assert_eq!(tr["surfaces"][0]["rolling_starts"], 1);
    let m = &summary["metrics"];
    assert_eq!(m["mean_first_rolling_s"].as_f64().unwrap(), t);
    assert!(m["mean_slide_distance_m"].as_f64().unwrap() > 0.0);
    let bodies = std::fs::read_to_string(dir.join("bodies.csv")).unwrap();
    assert!(bodies.lines().next().unwrap().contains(",slip_m_s,"));
    let first: Vec<&str> = bodies.lines().nth(1).unwrap().split(',').collect();
    let slip0: f64 = first[14].parse().unwrap();
    assert!((slip0 - 0.5).abs() < 1e-3, "slip at launch {slip0}");
    // Off: no file, no section, an empty slip column.
    let mut off = sc.clone();
    off.output.transitions.enabled = false;
    let dir2 = dir.join("off");
    let r2 = applesim::run::to_dir(&off, &repo("scenarios"), &dir2, &mut |_| {}).unwrap();
    assert!(r2.transitions.is_empty() && r2.transition_summary.is_none());
    assert!(!dir2.join("transitions.csv").exists());
    let bodies = std::fs::read_to_string(dir2.join("bodies.csv")).unwrap();
    // The slip column (15th) is empty.
    assert_eq!(bodies.lines().nth(1).unwrap().split(',').nth(14), Some(""));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Bad settings name their field.
#[test]
fn bad_settings_are_refused_by_name() {
    for (field, value) in [
        ("slip_speed_m_s", json!(0.0)),
        ("hysteresis", json!(0.5)),
        ("min_dwell_s", json!(-1.0)),
        ("relative_tolerance", json!(-0.1)),
        ("histogram_bin_m", json!(0.0)),
    ] {
        let mut v: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(repo("scenarios/slip_to_roll.json")).unwrap(),
        )
        .unwrap();
        v["output"]["transitions"] = json!({ field: value });
        let err = applesim::scenario::from_json(&v.to_string(), "x")
            .and_then(|sc| applesim::scenario::validate(&sc).map(|_| sc))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(&format!("output.transitions.{field}")),
            "{field}: {err}"
        );
    }
}

/// The charts: slip speed against time with the transition marked, and the histogram of where
/// apples start rolling (SVG, well-formed, with the expected legend).
#[test]
fn plots_mark_the_transitions() {
    use applesim::output::plot::{self, PlotOptions};
    let root = std::env::temp_dir().join(format!("applesim_tr_plots_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let run_dir = root.join("run");
    let mut sc = belt(0.5, 0.3, 0.1);
    sc.output.sample_interval_s = Some(1e-3);
    let r = applesim::run::to_dir(&sc, &repo("scenarios"), &run_dir, &mut |_| {}).unwrap();
    let out = root.join("charts");
    let s = plot::plot_runs(
        std::slice::from_ref(&run_dir),
        &out,
        &PlotOptions::default(),
    )
    .unwrap();
    assert!(s.written.contains(&out.join(plot::SLIP_CHART)));
    assert!(s.written.contains(&out.join(plot::ROLLING_STARTS_CHART)));
    let texts = |f: &str| -> Vec<String> {
        let svg = std::fs::read_to_string(out.join(f)).unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap();
        doc.descendants()
            .filter(|n| n.is_text())
            .filter_map(|n| n.text().map(|t| t.trim().to_string()))
            .filter(|t| !t.is_empty())
            .collect()
    };
    let slip = texts(plot::SLIP_CHART);
    assert!(slip.iter().any(|t| t == "a1"), "{slip:?}");
    assert!(slip.iter().any(|t| t == "to rolling"), "{slip:?}");
    let starts = texts(plot::ROLLING_STARTS_CHART);
    assert!(
        starts.iter().any(|t| t == "belt (1 rolling starts)"),
        "{starts:?}"
    );
    // The curve read back: the slip falls from the belt's 0.5 m/s to about zero at the transition.
    let curves = plot::read_run(&run_dir).unwrap();
    let k = &curves.apples[0].1;
    assert!((k.slip[0].1 - 0.5).abs() < 1e-3);
    let t_roll = r.transitions[0].time_s;
    let after = k.slip.iter().find(|p| p.0 > t_roll + 0.005).unwrap();
    assert!(after.1 < 5e-3, "slip after rolling {after:?}");
    assert_eq!(curves.transitions.len(), 1);
    let _ = std::fs::remove_dir_all(&root);
}

/// The shipped friction sweep: `applesim batch` then `applesim merge` put the first rolling time
/// and the slide distance in merged.csv, matching the closed form per row.
#[test]
fn batch_merge_has_the_transition_columns() {
    let bin = env!("CARGO_BIN_EXE_applesim");
    let out = std::env::temp_dir().join(format!("applesim_tr_batch_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let st = std::process::Command::new(bin)
        .args([
            "batch",
            "scenarios/batches/slip_sweep.json",
            "-q",
            "-j",
            "2",
            "--out",
        ])
        .arg(&out)
        .current_dir(repo(""))
        .status()
        .unwrap();
    assert!(st.success());
    let st = std::process::Command::new(bin)
        .arg("merge")
        .arg(&out)
        .status()
        .unwrap();
    assert!(st.success());
    let mut rd = csv::Reader::from_path(out.join("merged.csv")).unwrap();
    let h = rd.headers().unwrap().clone();
    let col = |n: &str| {
        h.iter()
            .position(|c| c == n)
            .unwrap_or_else(|| panic!("{n}"))
    };
    let (mu, v0, t, d) = (
        col("friction"),
        col("vx_m_s"),
        col("mean_first_rolling_s"),
        col("mean_slide_distance_m"),
    );
    let mut rows = 0;
    let mut quoted = 0;
    for rec in rd.records() {
        let rec = rec.unwrap();
        let f = |i: usize| rec[i].parse::<f64>().unwrap();
        // The 1 % rule with R (physics.md section 6), and within README's 0.0006 % / 0.002 %
        // (twice each) of the closed forms with the lever R - u.
        let cf = theory::slip_to_roll(f(v0), 0.0, R, f(mu), G);
        assert_rel("merged first rolling time", f(t), cf.time_s, 0.01);
        assert_rel("merged slide distance", f(d), cf.slide_distance_m, 0.01);
        let tight = theory::slip_to_roll_with_lever(f(v0), 0.0, R, ode::fig6_lever(), f(mu), G);
        assert_rel(
            "merged time, lever R - u",
            f(t),
            tight.time_s,
            2.0 * README_TIME,
        );
        assert_rel(
            "merged slide, lever R - u",
            f(d),
            tight.slide_distance_m,
            2.0 * README_SLIDE,
        );
        // docs/transitions.md quotes two rows (golden values).
        if (f(mu), f(v0)) == (0.3, 0.5) {
            assert!((1e3 * f(t) - 48.901).abs() <= 1e-3 && (1e3 * f(d) - 12.225).abs() <= 1e-3);
            quoted += 1;
        }
        if (f(mu), f(v0)) == (0.2, 1.0) {
            assert!((1e3 * f(t) - 146.70).abs() <= 1e-2 && (1e3 * f(d) - 73.35).abs() <= 1e-2);
            quoted += 1;
        }
        rows += 1;
    }
    assert_eq!((rows, quoted), (9, 2));
    let _ = std::fs::remove_dir_all(&out);
}
