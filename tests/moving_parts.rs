//! Moving parts (issue 22; docs/physics.md section 12) against closed forms, each with its
//! tolerance and the figure measured with this build (docs/physics.md 12.4):
//!
//! - a steel tray (a `box` with a keyframed `motion.translation`: at rest, then a ramp to V) under
//!   an apple resting on it: the apple reaches V at T = (rho/R) V / (mu_r g) after the ramp
//!   starts, whatever the ramp (the angular momentum about a point of the tray's surface changes
//!   only by the rolling torque and the pseudo-force of the ramp, whose total is m rho V);
//! - two powered rollers turning alike: an apple in their valley spins at
//!   w_a = w_r R_r / rho (rho = R - u its lever), no slip at either roller;
//! - an apple dropped on a roller (no gravity, elastic): peak force and contact time of the
//!   elliptic Hertz law, and the recorded area and pressure of the true ellipse (Johnson's a and
//!   b); the references written in tests/common (elliptic.rs, ode.rs), not the crate's
//!   contact::elliptic or contact::theory;
//! - a sleeping apple is woken by a part that moves into it;
//! - refusals naming the field.

use crate::common;
use applesim::record::series::MemorySeries;
use applesim::scenario::{self, Scenario};
use common::*;
use serde_json::{json, Value};

const G: f64 = 9.81;
fn materials() -> Value {
    apple_and_steel()
}

fn e_star() -> f64 {
    e_star_of(PAPER_APPLE, PAPER_STEEL)
}

/// Hertz stiffness k = 4/3 E* sqrt(R*) (physics.md section 2) of the paper's apple on steel.
fn stiffness(r_star: f64) -> f64 {
    4.0 / 3.0 * e_star() * r_star.sqrt()
}

fn parse(v: &Value) -> Scenario {
    scenario::from_json(&v.to_string(), "moving").unwrap()
}

/// Item 2a: the paper's Figs. 6-7 apple (D 80 mm, 0.107 kg) at its static sag on a steel tray at
/// rest; at t0 = 0.2 s the tray starts by a ramp to V over 0.1 s (the parabola x = V t^2 / (2 t_r)
/// in 20 keyframes, then V), friction 0.5, eq. 12 with `elastic-plastic` rolling resistance. The
/// centre reaches V at t0 + (rho/R) V/(mu_r g): within 1 % (the issue); stated 0.01 %, measured
/// 0.0017 %, checked at twice the measured. Then it rides within 0.1 % of V (measured 0.092 %,
/// checked at twice that).
#[test]
fn a_tray_started_by_a_ramp_brings_an_apple_to_its_speed_at_the_closed_form_time() {
    let (r, m, mu, ke) = (0.04, 0.107, 0.5, 0.09);
    let k = stiffness(r);
    for (v, mu_r) in [(0.4, 0.03), (0.8, 0.05)] {
        let sag = (2.0 * m * G / ((1.0 + ke) * k)).powf(2.0 / 3.0);
        let rho = r - sag;
        let (t0, tr) = (0.2, 0.1);
        let t_cf = rho / r * v / (mu_r * G);
        let end = t0 + t_cf + 1.0;
        let mut keys = vec![json!([0.0, [0.0, 0.0, 0.0]])];
        for i in 0..=20 {
            let t = tr * i as f64 / 20.0;
            keys.push(json!([t0 + t, [v * t * t / (2.0 * tr), 0.0, 0.0]]));
        }
        keys.push(json!([end, [v * tr / 2.0 + v * (end - t0 - tr), 0.0, 0.0]]));
        let sc = parse(&json!({
            "duration_s": end, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -G],
            "output": {"sample_interval_s": 1e-3, "force_history": false},
            "materials": materials(),
            "contact": {"friction": mu, "ke": ke, "lambda_s_m": 1000, "rolling": "elastic-plastic",
                        "rolling_friction": mu_r},
            "model": {"sleep": {"enabled": false}},
            "apples": [{"name": "a1", "material": "apple", "diameter_m": 2.0 * r, "mass_kg": m,
                "position_m": [-0.3, 0, rho]}],
            "surfaces": [{"name": "tray", "type": "box", "material": "steel",
                "size_m": [1.5, 0.3, 0.02], "position_m": [0, 0, -0.01],
                "motion": {"translation": {"keyframes": keys}}}]
        }));
        let (_, s) = run(&sc);
        let s = s.of(0);
        let target = v * (1.0 - 1e-4);
        let i = s
            .iter()
            .position(|(_, a)| a.velocity.x >= target)
            .expect("reaches V");
        let ((ta, va), (tb, vb)) = (
            (s[i - 1].0, s[i - 1].1.velocity.x),
            (s[i].0, s[i].1.velocity.x),
        );
        let t_reach = ta + (target - va) * (tb - ta) / (vb - va) - t0;
        let what = format!("V {v} mu_r {mu_r}");
        assert_ref(
            &format!("{what}: time to V from the ramp's start, (rho/R) V/(mu_r g)"),
            t_reach,
            t_cf,
            0.01,
            "closed form (issue)",
        );
        assert_ref(
            &format!("{what}: time to V"),
            t_reach,
            t_cf,
            2.0 * 0.0017e-2,
            "closed form",
        );
        let worst = s
            .iter()
            .filter(|(t, _)| *t >= t0 + t_cf)
            .map(|(_, a)| (a.velocity.x - v).abs())
            .fold(0.0, f64::max);
        println!("{what}: after T |v - V| <= {worst:.3e} m/s");
        assert!(worst <= 2.0 * 0.092e-2 * v, "rides with the tray");
    }
}

/// Two steel rollers of radius `rr`, axes along x at y = +-d, z = 0, turning at `w` about +x, and
/// an apple of radius `ra` (paper apple) set touching both in their valley.
fn roller_pair(ra: f64, rr: f64, w: f64, rolling: &str, duration: f64) -> (Scenario, f64) {
    let beta: f64 = 30f64.to_radians();
    let d = (ra + rr) * beta.sin();
    let z = (ra + rr) * beta.cos();
    let roller = |name: &str, y: f64| {
        json!({"name": name, "type": "roller", "material": "steel", "radius_m": rr,
               "length_m": 0.3, "position_m": [0, y, 0], "axis": [1, 0, 0],
               "angular_velocity_rad_s": w})
    };
    let sc = parse(&json!({
        "duration_s": duration, "time_step_s": 2e-5, "gravity_m_s2": [0, 0, -G],
        "output": {"sample_interval_s": 1e-3, "force_history": false},
        "materials": materials(),
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000, "rolling": rolling},
        "model": {"sleep": {"enabled": false}},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 2.0 * ra,
            "position_m": [0, 0, z]}],
        "surfaces": [roller("r1", -d), roller("r2", d)]
    }));
    (sc, beta)
}

/// Item 2b: an apple (R 37 mm, the paper's material, 800 kg/m^3) set in the valley of two steel
/// rollers (R_r 20 and 40 mm, contact 30 degrees from the vertical) turning alike at 20 rad/s: it
/// spins the other way at w_a = w_r R_r / (R - u), u its overlap (no slip at either roller;
/// docs/physics.md 12.2), and its centre stays in the valley. Mean spin over the last 0.5 s of
/// 1.5 s: within 1 % of w_r R_r / R, above it (the issue; measured +0.64 to +0.80 %, the lever)
/// and of the R - u form (u from the apple's final centre) within 0.001 % without rolling
/// resistance (measured 0.0008 %) and 0.06 % with the default `elastic-plastic` (measured
/// 0.059 %: the apple leans on one roller, the two overlaps differ by 4 %), each checked at twice
/// the measured figure. The spin-up leaves the Mindlin stick springs of the two contacts loaded
/// against each other: the resting normal forces are 1.12-1.36 N, above the 0.96 N the weight
/// needs, and the overlaps 0.21-0.29 mm against the static sag's 0.22-0.23 mm (docs/physics.md
/// 12.2; each range to one unit of its last digit).
#[test]
fn powered_rollers_spin_an_apple_at_their_surface_speed() {
    let ra: f64 = 0.037;
    let m = 800.0 * 4.0 / 3.0 * std::f64::consts::PI * ra.powi(3);
    for rr in [0.02, 0.04] {
        for rolling in ["none", "elastic-plastic"] {
            let w = 20.0;
            let (sc, beta) = roller_pair(ra, rr, w, rolling, 1.5);
            let (res, s) = run(&sc);
            let s = s.of(0);
            let late: Vec<_> = s.iter().filter(|(t, _)| *t >= 1.0).collect();
            let spin =
                late.iter().map(|(_, a)| a.angular_velocity.x).sum::<f64>() / late.len() as f64;
            // Static sag at each roller: the normal load m g / (2 cos beta), eq. 12 at rest.
            let h = elliptic::sphere_on_cylinder(ra, rr);
            let k = stiffness(h.stiffness_radius_m);
            let load = m * G / (2.0 * beta.cos());
            let u = (2.0 * load / (1.09 * k)).powf(2.0 / 3.0);
            let what = format!("R_r {rr} rolling {rolling}");
            // The apple's overlap with each roller from its final centre (the rollers at
            // y = +-d, z = 0).
            let c = s.last().unwrap().1.position;
            let d = (ra + rr) * beta.sin();
            let u_of = |y: f64| ra + rr - ((c.y - y).powi(2) + c.z.powi(2)).sqrt();
            let (u1, u2) = (u_of(-d), u_of(d));
            let loads: Vec<f64> = res
                .events
                .iter()
                .filter(|e| e.t_end_s.is_none())
                .map(|e| e.resting.as_ref().map_or(f64::NAN, |r| r.mean_force_n))
                .collect();
            println!(
                "{what}: overlaps {:.4} / {:.4} mm (static sag {:.4} mm), resting normal forces {loads:.4?} N against m g / (2 cos beta) = {:.4} N",
                1e3 * u1,
                1e3 * u2,
                1e3 * u,
                load
            );
            assert_ref(
                &format!("{what}: spin, w_r R_r / R"),
                -spin,
                w * rr / ra,
                0.01,
                "closed form (issue)",
            );
            assert!(
                -spin > w * rr / ra,
                "{what}: faster than w_r R_r / R (the lever R - u)"
            );
            // The resting contacts (physics.md 12.2): 1.12-1.36 N each, above the weight's
            // share m g / (2 cos beta) = 0.96 N; overlaps 0.21-0.29 mm against the static sag's
            // 0.22-0.23 mm.
            assert_eq!(loads.len(), 2, "{what}: two resting contacts");
            assert!((load - 0.96).abs() <= 0.01, "{load}");
            for f in &loads {
                assert!(
                    (1.11..=1.37).contains(f) && *f > load,
                    "{what}: resting force {f} N"
                );
            }
            for ui in [u1, u2] {
                assert!((0.20e-3..=0.30e-3).contains(&ui), "{what}: overlap {ui}");
            }
            assert!((0.21e-3..=0.24e-3).contains(&u), "{what}: static sag {u}");
            // No slip at either roller: w_a (R - u) = w_r R_r with the overlap the apple has
            // (the roller's own share of it is 1e-5 of u: steel).
            // With rolling resistance the apple leans on one roller (unequal overlaps, a slip of
            // a few 1e-4 at one of them): the mean overlap's form is looser.
            let u_mean = 0.5 * (u1 + u2);
            let stated = if rolling == "none" {
                0.0008e-2
            } else {
                0.059e-2
            };
            assert_ref(
                &format!("{what}: spin, w_r R_r / (R - u)"),
                -spin,
                w * rr / (ra - u_mean),
                2.0 * stated,
                "closed form",
            );
            let y_end = res.apples[0].final_position_m[1];
            println!(
                "{what}: centre y at the end {:.3} mm (sag u {:.1} um)",
                1e3 * y_end,
                1e6 * u
            );
            if rolling == "none" {
                assert!(y_end.abs() < 1e-4, "stays in the valley");
            } else {
                assert!(y_end.abs() < 5e-3, "leans, stays in the valley");
            }
        }
    }
}

/// Item 3: an apple (R 37 mm, 0.107 kg) dropped at 1 m/s onto a fixed steel roller (R_r 20 and
/// 60 mm), no gravity, elastic (`hertz` fidelity): peak force and contact time of the elliptic
/// Hertz law P = 4/3 E* sqrt(R_k) u^(3/2) (section 4's closed forms with R_k, R_k from Johnson's
/// equations: both written in tests/common, elliptic.rs and ode.rs): within 1 % (the issue);
/// stated 0.05 %, measured 1e-5 % (5.9e-8), checked at twice the measured. Johnson's bare
/// sqrt(R' R'') would be 0.9-0.2 % off the peak force (printed).
#[test]
fn an_apple_dropped_on_a_roller_hits_with_the_elliptic_hertz_law() {
    let (ra, m, v0) = (0.037, 0.107, 1.0);
    for rr in [0.02, 0.06] {
        let sc = parse(&json!({
            "duration_s": 0.012, "time_step_s": 2e-6, "gravity_m_s2": [0, 0, 0],
            "fidelity": "hertz",
            "output": {"sample_interval_s": 1e-3, "force_history": false},
            "materials": materials(),
            "contact": {"friction": 0.3, "ke": 1, "lambda_s_m": 0, "rolling": "none"},
            "model": {"sleep": {"enabled": false}},
            "apples": [{"name": "a1", "material": "apple", "diameter_m": 2.0 * ra, "mass_kg": m,
                "position_m": [0, 0, rr + ra + 1e-4], "velocity_m_s": [0, 0, -v0]}],
            "surfaces": [{"name": "roller", "type": "roller", "material": "steel", "radius_m": rr,
                "length_m": 0.3, "position_m": [0, 0, 0], "axis": [1, 0, 0]}]
        }));
        let (res, _) = run(&sc);
        let e = &res.events[0];
        let h = elliptic::sphere_on_cylinder(ra, rr);
        let (_, p_max, t_h, _) =
            ode::elastic_closed_form(m, v0, stiffness(h.stiffness_radius_m), h.stiffness_radius_m);
        let what = format!("R_r {rr}");
        for tol in [0.01, 2.0 * 1e-7] {
            assert_ref(
                &format!("{what}: peak force"),
                e.peak_force_n,
                p_max,
                tol,
                "elliptic Hertz",
            );
            assert_ref(
                &format!("{what}: contact time"),
                e.duration_s.unwrap(),
                t_h,
                tol,
                "elliptic Hertz",
            );
        }
        let re = elliptic::equivalent_radius(ra, ra * rr / (ra + rr));
        let (_, bare, _, _) = ode::elastic_closed_form(m, v0, stiffness(re), re);
        println!(
            "{what}: with sqrt(R' R'') bare the peak force would be {:+.3} % off",
            100.0 * (bare / p_max - 1.0)
        );
        // The recorded contact radius and mean pressure are the true ellipse's: pi r^2 = pi a b
        // and P / (pi a b), a and b from Johnson's equations at the recorded peak force (written
        // in tests/common/elliptic.rs; measured 1.6e-15, checked at twice that). The law's own
        // sqrt(R_k u) would be 3.0 % (20 mm) and 0.64 % (60 mm) high.
        let (a, b) = elliptic::semi_axes(ra, ra * rr / (ra + rr), e_star(), e.peak_force_n);
        let area = std::f64::consts::PI * a * b;
        let recorded = std::f64::consts::PI * e.max_contact_radius_m.powi(2);
        println!(
            "{what}: area {:+.2e}, mean pressure {:+.2e} (relative)",
            recorded / area - 1.0,
            e.max_pressure_pa / (e.peak_force_n / area) - 1.0
        );
        assert_ref(
            &format!("{what}: contact area"),
            recorded,
            area,
            2.0 * 1.6e-15,
            "Johnson 4.2",
        );
        let p_mean = e.peak_force_n / area;
        assert_ref(
            &format!("{what}: mean pressure"),
            e.max_pressure_pa,
            p_mean,
            2.0 * 1.6e-15,
            "Johnson 4.2",
        );
        let law_radius = (h.stiffness_radius_m * e.max_overlap_m).sqrt();
        println!(
            "{what}: a = {:.4} mm, b = {:.4} mm; sqrt(R_k u) would be {:+.2} % off sqrt(a b)",
            a * 1e3,
            b * 1e3,
            100.0 * (law_radius / (a * b).sqrt() - 1.0)
        );
    }
}

/// Radius of the apple of [`apple_on_floor`] (m).
const FLOOR_APPLE_R: f64 = 0.04;

/// The paper's Figs. 6-7 apple (0.107 kg) set 0.1 mm into a steel floor, with the surfaces
/// `parts` (a JSON array) beside the floor, for `duration_s`.
fn apple_on_floor(duration_s: f64, parts: Value) -> Scenario {
    let r = FLOOR_APPLE_R;
    let mut surfaces = vec![
        json!({"name": "floor", "type": "plane", "material": "steel",
        "point_m": [0, 0, 0], "normal": [0, 0, 1]}),
    ];
    surfaces.extend(parts.as_array().unwrap().iter().cloned());
    parse(&json!({
        "duration_s": duration_s, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -G],
        "output": {"sample_interval_s": 1e-2, "force_history": false},
        "materials": materials(),
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 2.0 * r, "mass_kg": 0.107,
            "position_m": [0, 0, r - 1e-4]}],
        "surfaces": surfaces
    }))
}

/// Item 1: an apple asleep on a fixed floor is woken by a pusher (a box moving by a keyframed
/// translation) that reaches it at about 1.1 s: without the wake it would pass through it.
#[test]
fn a_sleeping_apple_wakes_when_a_part_moves_into_it() {
    let sc = apple_on_floor(
        1.6,
        json!([{"name": "pusher", "type": "box", "material": "steel", "size_m": [0.02, 0.2, 0.1],
            "position_m": [-0.2, 0, 0.06],
            "motion": {"translation": {"keyframes": [[0.8, [0, 0, 0]], [1.5, [0.2, 0, 0]]]}}}]),
    );
    let mut sim = applesim::sim::Simulation::new(&sc, &repo("scenarios")).unwrap();
    let mut series = MemorySeries::default();
    let mut was_asleep = false;
    while !sim.done() {
        sim.step(&mut series).unwrap();
        let t = sim.time_s();
        if (0.7..0.8).contains(&t) {
            was_asleep |= sim.world().layer.is_asleep(applesim::layer::AppleId(0));
        }
    }
    assert!(was_asleep, "the apple fell asleep before the pusher moved");
    // The pusher's collider is out of rapier's broad phase (the layer owns its contacts), yet
    // rapier poses it with its body: its centre ends at -0.2 + 0.2 = 0.
    let w = sim.world();
    let co = &w.physics.colliders[w.surface_colliders[1]];
    assert!(
        !co.is_enabled(),
        "a layer surface is left in rapier's broad phase"
    );
    let cx = co.position().translation.x;
    assert!(cx.abs() < 1e-9, "the pusher's collider ends at x = {cx}");
    let x = series.of(0).last().unwrap().1.position.x;
    println!("pushed to x = {x:.4} m");
    // The pusher's face ends at -0.2 + 0.01 + 0.2 = 0.01 m: the apple's centre is beyond it.
    assert!(x > 0.01 + FLOOR_APPLE_R - 2e-3, "pushed: x = {x}");
}

/// Item 1: mistakes in a motion or a roller are refused with the field named.
#[test]
fn bad_motions_are_refused_naming_the_field() {
    let base = |surface: Value| {
        json!({
            "duration_s": 0.1, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -G],
            "materials": materials(),
            "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
            "surfaces": [surface]
        })
    };
    let tray = |motion: Value| {
        base(
            json!({"name": "t", "type": "box", "material": "steel", "size_m": [1, 1, 0.02],
                    "position_m": [0, 0, 0], "motion": motion}),
        )
    };
    let cases = [
        (
            tray(json!({"translation": {"keyframes": [[0, [0, 0, 0]], [0.5, [0.1, 0, 0]], [0.5, [0.2, 0, 0]]]}})),
            "surfaces[0].motion.translation.keyframes[2][0]: t = 0.5 s is not after the keyframe before it (t = 0.5 s): keyframe times must increase",
        ),
        (
            tray(json!({"translation": {"keyframes": [[0, [0, 0, 0]], [0.001, [0.2, 0, 0]]]}})),
            "surfaces[0].motion.translation.keyframes[1]: moving 0.2 m in 0.001 s from the keyframe before is 200 m/s, outside the range of fruit handling (|v| <= 100 m/s): the profile jumps",
        ),
        (
            tray(json!({"rotation": {"axis": [0, 0, 0], "point_m": [0, 0, 0], "angular_velocity_rad_s": 1}})),
            "surfaces[0].motion.rotation.axis: [0, 0, 0]: a rotation axis needs a finite non-zero length",
        ),
        (
            tray(json!({"rotation": {"axis": [0, 0, 1], "point_m": [0, 0, 0], "keyframes": [[0, 0], [1, 30], [0.5, 60]]}})),
            "surfaces[0].motion.rotation.keyframes[2][0]: t = 0.5 s is not after the keyframe before it (t = 1 s): keyframe times must increase",
        ),
        (
            tray(json!({})),
            "surfaces[0].motion: empty: give a translation, a rotation or both",
        ),
        (
            base(json!({"name": "r", "type": "roller", "material": "steel", "radius_m": 0.03,
                        "length_m": 0.5, "position_m": [0, 0, 0], "axis": [0, 0, 0]})),
            "surfaces[0].axis: [0, 0, 0]: a rotation axis needs a finite non-zero length",
        ),
        (
            base(json!({"name": "r", "type": "roller", "material": "steel", "radius_m": 0.5,
                        "length_m": 0.5, "position_m": [0, 0, 0], "axis": [1, 0, 0],
                        "angular_velocity_rad_s": 300})),
            "surfaces[0].angular_velocity_rad_s: 300 rad/s on a radius of 0.5 m moves the roller's surface at 150 m/s, outside the range of fruit handling (|v| <= 100 m/s)",
        ),
    ];
    for (v, want) in cases {
        let sc = parse(&v);
        let e = scenario::validate(&sc).unwrap_err().to_string();
        assert_eq!(e, want);
    }
}

/// Item 4: the shipped roller singulator (scenarios/lines/roller_singulator.json; docs/lines.md
/// section 4). Each of the four apples crosses the camera station (x 0.45-0.55 m): there its
/// centre moves with the bed at V = 0.1 m/s (within 0.01 %; measured 0.0018 %, checked at twice
/// that) and it spins at w_r R_r / R = 8.0 rad/s (within 1 %, the issue's tolerance, and above it:
/// measured +0.49 to +0.54 %, the lever R - u), turning 1.267 times in view (to the digit: more
/// than a turn, so the camera sees every side). The landings (dropped 1 mm into the valleys)
/// peak at 9.18 N (to the digit; a regression pin of this build).
#[test]
fn the_roller_singulator_turns_each_apple_under_the_camera() {
    let sc = shipped("scenarios/lines/roller_singulator.json");
    let (res, s) = run(&sc);
    let (v, w_r, r_r, r_a) = (0.1, 10.0, 0.03, 0.0375);
    for k in 0..4u32 {
        let pts: Vec<_> = s
            .of(k)
            .into_iter()
            .filter(|(_, a)| (0.45..=0.55).contains(&a.position.x))
            .collect();
        assert!(
            pts.len() > 80,
            "apple {k} crosses the station ({} samples)",
            pts.len()
        );
        let worst_v = pts
            .iter()
            .map(|(_, a)| (a.velocity.x - v).abs() / v)
            .fold(0.0, f64::max);
        let spin = pts.iter().map(|(_, a)| -a.angular_velocity.y).sum::<f64>() / pts.len() as f64;
        let span = pts.last().unwrap().0 - pts[0].0;
        let turns = spin * span / (2.0 * std::f64::consts::PI);
        println!(
            "{}: in view {:.2}-{:.2} s, |v - V| <= {:.4} % of V, spin {spin:.4} rad/s, {turns:.3} turns",
            res.apples[k as usize].name,
            pts[0].0,
            pts.last().unwrap().0,
            100.0 * worst_v
        );
        assert!(worst_v <= 2.0 * 0.0018e-2, "rides with the bed");
        assert_ref(
            "spin under the camera, w_r R_r / R",
            spin,
            w_r * r_r / r_a,
            0.01,
            "closed form (issue)",
        );
        assert!(
            spin > w_r * r_r / r_a,
            "the lever R - u: faster than w_r R_r / R"
        );
        assert!(
            (turns - 1.267).abs() <= 0.001 && turns > 1.0,
            "turns {turns}"
        );
        let landing = res
            .events
            .iter()
            .filter(|e| e.a_index == k)
            .map(|e| e.peak_force_n)
            .fold(0.0, f64::max);
        println!("  landing peak {landing:.3} N");
        assert!((landing - 9.18).abs() <= 0.01, "landing {landing} N");
    }
}

/// Issue 22: a moving part that would push an apple through another part is refused, naming the
/// pair and the time, not returned as a result: a pusher closes on a fixed wall with an apple
/// between them until the gap is 40 % of the apple's diameter; the stability guard (overlap over
/// half the radius, `model.max_overlap_ratio`) stops the run.
#[test]
fn a_part_that_crushes_an_apple_against_another_is_refused_naming_the_pair() {
    let r = FLOOR_APPLE_R;
    let sc = apple_on_floor(
        1.0,
        json!([
            {"name": "wall", "type": "box", "material": "steel", "size_m": [0.02, 0.2, 0.1],
             "position_m": [r + 0.01, 0, 0.06]},
            {"name": "pusher", "type": "box", "material": "steel", "size_m": [0.02, 0.2, 0.1],
             "position_m": [-r - 0.02, 0, 0.06],
             "motion": {"translation": {"keyframes": [[0.1, [0, 0, 0]], [0.9, [0.058, 0, 0]]]}}}]),
    );
    scenario::validate(&sc).unwrap();
    let mut series = MemorySeries::default();
    let e = applesim::sim::run(&sc, &repo("scenarios"), &mut series)
        .expect_err("the apple cannot be pushed through the wall")
        .to_string();
    println!("{e}");
    assert!(
        e.contains("'a1'") && (e.contains("'wall'") || e.contains("'pusher'")),
        "{e}"
    );
    assert!(e.contains("pass through each other"), "{e}");
}

/// Regression: a moving part starts at its pose at t = 0, not at its rest pose (where the
/// scenario places it). A tray keyframed 0.2 m up at t = 0 and lowered at 0.1 m/s, and one keyframed
/// 0.2 m down and raised at 0.1 m/s, each carry an apple set on the tray's displaced top, moving
/// with it: after 50 ms the apple rides with the tray, its centre at the tray top + rho and its
/// speed the tray's. (The body was built at the rest pose and only posed by its profile from the
/// first step on, with a velocity of 0.2 m / dt for that step: the apple rode 30-60 times less
/// smoothly, see the figures below.)
#[test]
fn a_part_starts_at_its_pose_at_time_zero() {
    let (r, m, ke) = (0.04, 0.107, 0.09);
    let k = stiffness(r);
    let rho = r - (2.0 * m * G / ((1.0 + ke) * k)).powf(2.0 / 3.0);
    for (start, speed) in [(0.2, -0.1), (-0.2, 0.1)] {
        let t_end = -start / speed;
        let sc = parse(&json!({
            "duration_s": 1.0, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -G],
            "output": {"sample_interval_s": 1e-2, "force_history": false},
            "materials": materials(),
            "contact": {"friction": 0.5, "ke": ke, "lambda_s_m": 1000},
            "model": {"sleep": {"enabled": false}},
            "apples": [{"name": "a1", "material": "apple", "diameter_m": 2.0 * r, "mass_kg": m,
                "position_m": [0, 0, start + rho], "velocity_m_s": [0, 0, speed]}],
            "surfaces": [{"name": "tray", "type": "box", "material": "steel",
                "size_m": [0.5, 0.5, 0.02], "position_m": [0, 0, -0.01],
                "motion": {"translation": {"keyframes": [[0.0, [0, 0, start]],
                    [t_end, [0, 0, 0]]]}}}]
        }));
        let (_, s) = run(&sc);
        let mut worst_z: f64 = 0.0;
        let mut worst_v: f64 = 0.0;
        for (t, a) in s.of(0) {
            // Moved at constant speed the contact carries m g: the apple sits at the static sag.
            let top = start + speed * t.min(t_end);
            let v_tray = if t < t_end { speed } else { 0.0 };
            if t >= 0.05 {
                worst_z = worst_z.max((a.position.z - (top + rho)).abs());
                worst_v = worst_v.max((a.velocity.z - v_tray).abs());
            }
        }
        println!(
            "tray from {start} m at {speed} m/s: centre from the tray top + rho {worst_z:.3e} m; speed from the tray's {worst_v:.3e} m/s"
        );
        // Measured 3.1e-8 m and 2.2e-7 m/s (both trays), checked at twice that; with the bug
        // 1.8e-6 m and 1.3e-5 m/s (lowered), 3.0e-7 m and 2.1e-6 m/s (raised).
        assert!(worst_z < 6.2e-8, "{worst_z}");
        assert!(worst_v < 4.4e-7, "{worst_v}");
    }
}
