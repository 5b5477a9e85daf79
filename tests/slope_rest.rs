//! Resting and rolling without creeping (README "Friction"; physics.md section 5: "a resting or
//! rolling apple must not creep or jitter"), each with a stated bound over a stated time:
//!
//! - an apple pressed between a 20 degree slope and a parallel cover (a tilted crate) needs
//!   friction to stay, and cannot roll (its two contacts would slip in opposite senses): 28 nm
//!   along the slope from 0.5 to 3 s while its contacts settle, under 1 pm from 3 to 6 s. (A
//!   Coulomb law regularised by a linear ramp below 5 mm/s would have to slip at about 1 mm/s to
//!   carry that load: 2.5 mm in 2.5 s.)
//! - a settled pile of 27 apples in a box, sleeping off: no apple moves more than 1 nm from 2 to
//!   4 s.
//! - a lone apple on a 20 degree slope cannot rest (no rolling resistance): it rolls down without
//!   slipping (slip under 0.1 mm/s) at the closed-form acceleration g sin(theta) / (1 + I / (m
//!   rho^2)), rho = R - u the lever arm of its resting sag (physics.md section 6).
//! - the resting sag itself against the closed form k u^(3/2) (1 + ke)/2 = m g, and how a
//!   disturbed resting contact relaxes to it.
//!
//! Each bound is checked at twice its stated figure.

use crate::common;
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

/// Stated (README, Friction): while its two contacts settle (the normal load shifting from the
/// cover to the slope: the centre moves 47-54 um towards the slope, its speed falling e-fold
/// every 0.18-0.25 s) the apple moves 28 nm along the slope from 0.5 to 3 s; then it stays: under
/// 1 pm from 3 to 6 s (measured 0.65 pm; nothing at all after 6 s). Checked at twice each.
#[test]
fn an_apple_held_on_a_slope_does_not_creep() {
    let th = 20f64.to_radians();
    let down = Vec3::new(th.cos(), 0.0, -th.sin());
    let normal = Vec3::new(th.sin(), 0.0, th.cos());
    // 0.78 mm: each contact carries 2-3 N (overlaps within the 1 % start limit); 0.6 mm: less grip.
    for squeeze in [0.78e-3, 0.6e-3] {
        let mut sc = crate_scene(20.0, squeeze);
        sc.duration_s = 6.0;
        let (r, s) = run(&sc);
        assert_eq!(r.events.len(), 2, "slope and cover both hold it");
        let pts = s.of(0);
        let at = |t: f64| pts.iter().find(|(x, _)| *x >= t - 1e-9).unwrap().1.clone();
        let along = |a: f64, b: f64| (at(b).position - at(a).position).dot(down).abs();
        let settling = along(0.5, 3.0);
        let after = along(3.0, 6.0);
        println!(
            "squeeze {squeeze} m: towards the slope {:.2} um by 3 s; along the slope 0.5 .. 3 s \
             {settling:.3e} m (0.5 .. 1 s {:.3e}, 1 .. 2 s {:.3e}, 2 .. 3 s {:.3e}), 3 .. 6 s {after:.3e} m",
            -1e6 * (at(3.0).position - at(0.0).position).dot(normal),
            along(0.5, 1.0),
            along(1.0, 2.0),
            along(2.0, 3.0),
        );
        assert!(
            settling < 2.0 * 28e-9,
            "moved {settling} m down the slope while settling"
        );
        assert!(
            after < 2.0 * 1e-12,
            "crept {after} m down the slope after settling"
        );
        assert!(at(6.0).velocity.length() < 1e-9);
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
    // tests/geometry.rs. Least squares over 0.05 .. 0.3 s; stated within 0.0018 % (0.0089 % before
    // resting contacts' eq. 12 step mean took the support into account).
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
        2.0 * 0.0018e-2,
        "closed form",
    );
}

/// The resting sag of the Figs. 6-7 apple on steel (ke = 0.09) against the closed form
/// k u^(3/2) (1 + ke)/2 = m g. The shipped slip_to_roll scenario places the apple 0.19 um (0.09 %)
/// deeper (its height, 0.0397936 m, is rounded); released at rest there, it relaxes onto the
/// closed form. docs/physics.md ("How applesim implements this reference") states: monotonically
/// and never past it, with a time constant of 0.12 s at dt 1e-5 s and 0.14 s at 1e-4 s (where
/// the new contact's first millisecond, still an impact under the paper's law, first sinks it
/// 0.043 um more); within 2.1e-7 of the closed form after 1 s (8.9e-7 at 1e-4 s), 2.0e-10 after
/// 2 s (7.1e-10), and 2.4e-11 after 2.5 s at 1e-4 s. Each figure checked at twice its value, the
/// time constants to one unit of their last digit (0.01 s). (Before resting contacts' eq. 12 step mean took the support into
/// account, the apple first sank, 2.4 % too deep at 0.5 s and 0.4 % at 3 s at 1e-5 s.)
#[test]
fn resting_sag_against_the_closed_form() {
    let u_cf = ode::resting_sag(
        ode::hertz_k(FIG6_APPLE.0, FIG6_APPLE.1, STEEL.0, STEEL.1, R),
        0.09,
        M * G,
    );
    // (t, u / u_cf - 1) every millisecond.
    let sag = |dt: f64, duration: f64| {
        let mut sc = shipped("scenarios/slip_to_roll.json");
        sc.apples[0].velocity_m_s = [0.0; 3];
        sc.time_step_s = TimeStep::Fixed(dt);
        sc.duration_s = duration;
        sc.model.sleep.enabled = false;
        sc.output.sample_interval_s = Some(1e-3);
        let (_, s) = run(&sc);
        s.of(0)
            .iter()
            .map(|(t, a)| (*t, (R - a.position.z) / u_cf - 1.0))
            .collect::<Vec<_>>()
    };
    // (dt, run, time constant s, excess at 1 s and 2 s, the first sink um).
    for (dt, duration, tau_doc, at_1s, at_2s, sink_um) in [
        (1e-4, 2.5, 0.14, 8.9e-7, 7.1e-10, 0.043),
        (1e-5, 2.0, 0.12, 2.1e-7, 2.0e-10, 0.0),
    ] {
        let v = sag(dt, duration);
        let at = |t: f64| v.iter().find(|(x, _)| (x - t).abs() < 1e-9).unwrap().1;
        // Released 0.19 um deep.
        let start_um = 1e6 * at(0.0) * u_cf;
        assert!((start_um - 0.19).abs() <= 0.01, "starts {start_um} um deep");
        // The largest excess: the start, or at 1e-4 s the first step's sink.
        let top = v.iter().map(|p| p.1).fold(f64::MIN, f64::max);
        let sink_got = 1e6 * (top - at(0.0)) * u_cf;
        let tau = 0.5 / (at(0.5) / at(1.0)).ln();
        println!(
            "dt {dt:e} s: starts {start_um:.4} um deep, sinks {sink_got:.4} um more; relaxes with a time \
             constant {tau:.4} s; at 1 s {:+.3e}, at 2 s {:+.3e}, at the end {:+.3e}",
            at(1.0),
            at(2.0),
            v.last().unwrap().1
        );
        assert!(sink_got <= 2.0 * sink_um, "sinks {sink_got} um");
        // Monotonic from its deepest point on, and never past the closed form.
        let k = v.iter().position(|p| p.1 == top).unwrap();
        assert!(
            v[k..].windows(2).all(|w| w[1].1 <= w[0].1),
            "dt {dt}: relaxes monotonically"
        );
        assert!(v.iter().all(|p| p.1 > 0.0), "dt {dt}: never past the sag");
        assert!(
            (tau - tau_doc).abs() <= 0.01,
            "dt {dt}: time constant {tau} s"
        );
        assert!(at(1.0) <= 2.0 * at_1s, "dt {dt}: at 1 s {}", at(1.0));
        assert!(at(2.0) <= 2.0 * at_2s, "dt {dt}: at 2 s {}", at(2.0));
        if dt == 1e-4 {
            // After 2.5 s: on the closed form (docs/design.md: within 1e-6; stated 2.4e-11).
            let end = v.last().unwrap().1;
            assert!(end <= 2.0 * 2.4e-11, "at 2.5 s {end}");
        }
    }
}
