//! Resting and rolling without creeping (README "Friction"; physics.md section 5: "a resting or
//! rolling apple must not creep or jitter"), each with a stated bound over a stated time:
//!
//! - an apple pressed between a 20 degree slope and a parallel cover (a tilted crate) needs
//!   friction to stay, and cannot roll (its two contacts would slip in opposite senses): under
//!   10 nm along the slope from 0.5 to 3 s. (A Coulomb law regularised by a linear ramp below
//!   5 mm/s would have to slip at about 1 mm/s to carry that load: 2.5 mm in the same time.)
//! - a settled pile of 27 apples in a box, sleeping off: no apple moves more than 1 nm from 2 to
//!   4 s.
//! - a lone apple on a 20 degree slope cannot rest (no rolling resistance): it rolls down without
//!   slipping (slip under 0.1 mm/s) at the closed-form acceleration g sin(theta) / (1 + I / (m
//!   rho^2)), rho = R - u the lever arm of its resting sag (physics.md section 6).
//! - the resting sag itself against the closed form k u^(3/2) (1 + ke)/2 = m g, and how slowly a
//!   disturbed resting contact relaxes to it.
//!
//! Each bound is checked at twice its stated figure.

mod common;
use applesim::math::Vec3;
use applesim::scenario::{self, Scenario, TimeStep};
use common::ode;
use common::*;
use serde_json::json;

const R: f64 = 0.04;
const M: f64 = 0.107;
const G: f64 = 9.81;
const FIG6_APPLE: (f64, f64) = (1.0e6, 0.18);
const STEEL: (f64, f64) = (8.1e10, 0.28);

fn materials() -> serde_json::Value {
    json!({
        "apple": {"shear_modulus_pa": FIG6_APPLE.0, "poisson_ratio": FIG6_APPLE.1, "density_kg_m3": 800},
        "steel": {"shear_modulus_pa": STEEL.0, "poisson_ratio": STEEL.1}})
}

/// The Figs. 6-7 apple squeezed by `squeeze` (m, shared by the two contacts) between a slope
/// at `theta_deg` and a parallel cover, released at rest.
fn crate_scene(theta_deg: f64, squeeze: f64) -> Scenario {
    let th = theta_deg.to_radians();
    let n = [th.sin(), 0.0, th.cos()];
    let at = |d: f64| [n[0] * d, 0.0, n[2] * d];
    let v = json!({
        "duration_s": 3.0, "time_step_s": 1e-5, "gravity_m_s2": [0, 0, -G],
        "output": {"sample_interval_s": 0.01, "force_history": false},
        "materials": materials(),
        "contact": {"friction": 0.3, "ke": 0.09, "lambda_s_m": 1000, "rolling": "none"},
        "model": {"sleep": {"enabled": false}},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 2.0 * R, "mass_kg": M,
            "position_m": at(R - 0.5 * squeeze)}],
        "surfaces": [
            {"name": "slope", "type": "plane", "material": "steel", "point_m": [0, 0, 0], "normal": n},
            {"name": "cover", "type": "plane", "material": "steel",
             "point_m": at(2.0 * R - squeeze), "normal": [-n[0], 0, -n[2]]}]
    });
    scenario::from_json(&v.to_string(), "tilted crate").unwrap()
}

#[test]
fn an_apple_held_on_a_slope_does_not_creep() {
    let th = 20f64.to_radians();
    let down = Vec3::new(th.cos(), 0.0, -th.sin());
    // 0.78 mm: each contact carries 2-3 N (overlaps within the 1 % start limit); 0.6 mm: less grip.
    for squeeze in [0.78e-3, 0.6e-3] {
        let (r, s) = run(&crate_scene(20.0, squeeze));
        assert_eq!(r.events.len(), 2, "slope and cover both hold it");
        let pts = s.of(0);
        let at = |t: f64| pts.iter().find(|(x, _)| *x >= t - 1e-9).unwrap().1.clone();
        let drift = (at(3.0).position - at(0.5).position).dot(down).abs();
        println!("squeeze {squeeze} m: along-slope drift 0.5 .. 3 s: {drift:.3e} m");
        // Stated: under 10 nm (README, Friction); checked at twice that.
        assert!(drift < 2.0 * 10e-9, "crept {drift} m down the slope");
        assert!(at(3.0).velocity.length() < 1e-6);
    }
}

#[test]
fn a_settled_pile_does_not_creep() {
    let plane = |name: &str, p: [f64; 3], n: [f64; 3]| json!({"name": name, "type": "plane", "material": "steel", "point_m": p, "normal": n});
    let v = json!({
        "duration_s": 4.0, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -G],
        "output": {"sample_interval_s": 0.5, "force_history": false, "transitions": {"enabled": false}},
        "materials": {
            "apple": {"youngs_modulus_pa": 2.6e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "steel": {"youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.3}},
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000, "rolling": "none"},
        "model": {"sleep": {"enabled": false}},
        "generators": [{"type": "grid", "name": "p", "material": "apple",
            "diameter_m": {"mean_m": 0.08, "spread_m": 0.008}, "count": [3, 3, 3],
            "spacing_m": [0.1, 0.1, 0.1], "origin_m": [-0.1, -0.1, 0.05], "jitter_m": 0.005, "seed": 1}],
        "surfaces": [plane("floor", [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
                     plane("x_min", [-0.15, 0.0, 0.0], [1.0, 0.0, 0.0]),
                     plane("x_max", [0.15, 0.0, 0.0], [-1.0, 0.0, 0.0]),
                     plane("y_min", [0.0, -0.15, 0.0], [0.0, 1.0, 0.0]),
                     plane("y_max", [0.0, 0.15, 0.0], [0.0, -1.0, 0.0])]
    });
    let sc = scenario::from_json(&v.to_string(), "pile").unwrap();
    let (r, s) = run(&sc);
    let at = |t: f64| {
        &s.samples
            .iter()
            .find(|(x, _)| (*x - t).abs() < 1e-9)
            .unwrap()
            .1
    };
    let (a, b) = (at(2.0), at(4.0));
    assert_eq!((a.len(), b.len()), (27, 27));
    let worst = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x.position - y.position).length())
        .fold(0.0, f64::max);
    println!("27-apple pile, largest displacement 2 .. 4 s: {worst:.3e} m");
    // The pile is packed: apples rest on apples.
    assert!(
        r.events
            .iter()
            .filter(|e| e.t_end_s.is_none() && e.b.starts_with("p-"))
            .count()
            > 10
    );
    // Stated: under 1 nm (README, Friction); checked at twice that.
    assert!(worst < 2.0 * 1e-9, "an apple of the pile moved {worst} m");
}

#[test]
fn a_lone_apple_on_a_slope_rolls_down_without_slipping() {
    let th = 20f64.to_radians();
    let k = ode::hertz_k(FIG6_APPLE.0, FIG6_APPLE.1, STEEL.0, STEEL.1, R);
    let u = ode::resting_sag(k, 0.09, M * G * th.cos());
    let rho = R - u;
    let n = Vec3::new(th.sin(), 0.0, th.cos());
    let c = n * rho;
    let v = json!({
        "duration_s": 0.3, "time_step_s": 1e-5, "gravity_m_s2": [0, 0, -G],
        "output": {"sample_interval_s": 1e-3, "force_history": false},
        "materials": materials(),
        "contact": {"friction": 0.3, "ke": 0.09, "lambda_s_m": 1000, "rolling": "none"},
        "model": {"sleep": {"enabled": false}},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 2.0 * R, "mass_kg": M,
            "position_m": [c.x, c.y, c.z]}],
        "surfaces": [{"name": "slope", "type": "plane", "material": "steel",
            "point_m": [0, 0, 0], "normal": [n.x, n.y, n.z]}]
    });
    let sc = scenario::from_json(&v.to_string(), "slope").unwrap();
    let (r, s) = run(&sc);
    assert!(
        r.transitions.is_empty(),
        "it never slides: {:?}",
        r.transitions
    );
    let down = Vec3::new(th.cos(), 0.0, -th.sin());
    let mut worst: f64 = 0.0;
    for (t, a) in s.of(0) {
        if t > 0.02 {
            worst = worst.max((a.velocity.dot(down) - rho * a.angular_velocity.y).abs());
        }
    }
    println!("rolling on 20 degrees: largest slip after 20 ms {worst:.3e} m/s");
    // Stated: under 0.1 mm/s; checked at twice that.
    assert!(worst < 2.0 * 1e-4, "slips at {worst} m/s");
    // Rolling with the lever rho: a = g sin / (1 + 2/5 R^2 / rho^2); the 1 % rule with R is
    // tests/geometry.rs. Least squares over 0.05 .. 0.3 s; stated within 0.01 %.
    let pts: Vec<(f64, f64)> = s
        .of(0)
        .iter()
        .filter(|(t, _)| *t >= 0.05)
        .map(|(t, a)| (*t, a.velocity.dot(down)))
        .collect();
    let nn = pts.len() as f64;
    let (mt, mv) = (
        pts.iter().map(|p| p.0).sum::<f64>() / nn,
        pts.iter().map(|p| p.1).sum::<f64>() / nn,
    );
    let acc = pts.iter().map(|p| (p.0 - mt) * (p.1 - mv)).sum::<f64>()
        / pts.iter().map(|p| (p.0 - mt).powi(2)).sum::<f64>();
    let want = G * th.sin() / (1.0 + 0.4 * R * R / (rho * rho));
    assert_ref(
        "rolling acceleration, lever R - u",
        acc,
        want,
        2.0 * 0.01e-2,
        "closed form",
    );
}

/// The resting sag of the Figs. 6-7 apple on steel (ke = 0.09) against the closed form
/// k u^(3/2) (1 + ke)/2 = m g, released at rest at (about) that sag. docs/physics.md ("How
/// applesim implements this reference") states: the rest state is the closed form (at a 1e-4 s
/// step the sag equals it within 1e-6 after 2.5 s), but a resting eq. 12 contact is overdamped and
/// relaxes slowly once disturbed: at 1e-5 s the apple first sinks and is still 2.4 % too deep at
/// 0.5 s and 0.4 % at 3 s. Checked at twice each figure.
#[test]
fn resting_sag_against_the_closed_form() {
    let u_cf = ode::resting_sag(
        ode::hertz_k(FIG6_APPLE.0, FIG6_APPLE.1, STEEL.0, STEEL.1, R),
        0.09,
        M * G,
    );
    let sag = |dt: f64, duration: f64| {
        let mut sc = shipped("scenarios/slip_to_roll.json");
        sc.apples[0].velocity_m_s = [0.0; 3];
        sc.time_step_s = TimeStep::Fixed(dt);
        sc.duration_s = duration;
        sc.model.sleep.enabled = false;
        sc.output.sample_interval_s = 0.5;
        let (_, s) = run(&sc);
        s.of(0)
            .iter()
            .map(|(t, a)| (*t, R - a.position.z))
            .collect::<Vec<_>>()
    };
    // At 1e-4 s: settled on the closed form.
    let settled = sag(1e-4, 2.5);
    let (_, u) = *settled.last().unwrap();
    assert_ref(
        "resting sag at dt 1e-4 s after 2.5 s",
        u,
        u_cf,
        2.0 * 1e-6,
        "closed form",
    );
    // At 1e-5 s: deeper, relaxing towards it (2.4 % at 0.5 s, 0.4 % at 3 s).
    let relaxing = sag(1e-5, 3.0);
    for (t, stated) in [(0.5, 2.4), (3.0, 0.4)] {
        let (_, u) = *relaxing.iter().find(|(x, _)| (x - t).abs() < 1e-9).unwrap();
        let excess = 100.0 * (u / u_cf - 1.0);
        println!("dt 1e-5 s, t {t} s: sag {u:.6e} m, closed form {u_cf:.6e} m: {excess:+.3} %");
        assert!(excess > 0.0 && excess <= 2.0 * stated, "t {t}: {excess} %");
    }
    let after: Vec<f64> = relaxing
        .iter()
        .filter(|(t, _)| *t >= 0.5)
        .map(|p| p.1)
        .collect();
    assert!(
        after.windows(2).all(|w| w[1] < w[0]),
        "relaxes monotonically: {after:?}"
    );
}
