//! Twisting resistance (docs/physics.md section 11.8) against its closed form.
//!
//! An apple resting on a steel floor at its static sag u, spinning about the vertical at w0, is
//! braked by the Coulomb friction over its Hertz patch of radius a = sqrt(R u): the torque
//! M = (3 pi / 16) mu a m g (Johnson, Contact Mechanics, 1985, section 7.3) decelerates the spin
//! at M / I (I = 2/5 m R^2) and stops it after T = I w0 / M, having turned w0^2 I / (2 M). The
//! tangential force stays nil (the contact point is on the spin axis), so the apple stays where
//! it is. Without the model the spin goes on (the gap it closes). The figures measured with this
//! build are in docs/physics.md 11.8 and checked there at twice their value (docs/claims.md).
//!
//! The apple is the paper's Figs. 6-7 apple (D 80 mm, G 1 MPa, nu 0.18, 0.107 kg) on steel.

use crate::common;
use applesim::scenario::{self, Scenario};
use common::ode;
use common::*;
use serde_json::json;

const R: f64 = 0.04;
const M: f64 = 0.107;
const G: f64 = 9.81;
const APPLE: (f64, f64) = (1.0e6, 0.18);
const STEEL: (f64, f64) = (8.1e10, 0.28);

/// The apple at its static sag on the floor, spinning at `w0` about z. `eq12`: the paper's
/// damping (ke 0.09: at rest (1 + ke)/2 of Hertz), else viscoelastic (Hertz at rest).
fn spinning(eq12: bool, twisting: &str, mu: f64, w0: f64, duration_s: f64) -> (Scenario, f64) {
    let k = ode::hertz_k(APPLE.0, APPLE.1, STEEL.0, STEEL.1, R);
    let (u, mut c) = if eq12 {
        (
            ode::resting_sag(k, 0.09, M * G),
            json!({"friction": mu, "ke": 0.09, "lambda_s_m": 1000, "damping": "eq12"}),
        )
    } else {
        (
            (M * G / k).powf(2.0 / 3.0),
            json!({"friction": mu, "damping": "viscoelastic", "restitution": 0.3}),
        )
    };
    c["twisting"] = json!(twisting);
    c["rolling"] = json!("none");
    let s = json!({
        "duration_s": duration_s, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -G],
        "output": {"sample_interval_s": 1e-3, "force_history": false},
        "materials": {
            "apple": {"shear_modulus_pa": APPLE.0, "poisson_ratio": APPLE.1, "density_kg_m3": 800},
            "steel": {"shear_modulus_pa": STEEL.0, "poisson_ratio": STEEL.1}},
        "contact": c,
        "model": {"sleep": {"enabled": false}},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 2.0 * R, "mass_kg": M,
            "position_m": [0, 0, R - u], "angular_velocity_rad_s": [0, 0, w0]}],
        "surfaces": [{"name": "floor", "type": "plane", "material": "steel",
            "point_m": [0, 0, 0], "normal": [0, 0, 1]}]
    });
    (scenario::from_json(&s.to_string(), "twisting").unwrap(), u)
}

/// (t, w_z, x, y) of every sample.
fn trace(sc: &Scenario) -> Vec<(f64, f64, f64, f64)> {
    let (_, s) = run(sc);
    s.of(0)
        .iter()
        .map(|(t, a)| (*t, a.angular_velocity.z, a.position.x, a.position.y))
        .collect()
}

/// The spin stops at the closed form: deceleration (least squares over 10-90 % of the stop),
/// stopping time (w_z through w0 / 1000, interpolated) and angle turned, within 0.0072 % (stated
/// 0.005 %, measured 0.0036 % at most: twice the measured figure), for both dampings and two
/// friction coefficients; the centre stays put (drift exactly 0, as stated) and the stopped
/// apple stays stopped (|w_z| < 1e-6 rad/s after, as stated; measured below 1e-190).
#[test]
fn a_spinning_apple_stops_at_the_closed_form() {
    for (eq12, mu, w0) in [(false, 0.3, 5.0), (true, 0.3, 5.0), (false, 0.5, 8.0)] {
        let k = ode::hertz_k(APPLE.0, APPLE.1, STEEL.0, STEEL.1, R);
        let u = if eq12 {
            ode::resting_sag(k, 0.09, M * G)
        } else {
            (M * G / k).powf(2.0 / 3.0)
        };
        let a = (R * u).sqrt();
        let torque = 3.0 * std::f64::consts::PI / 16.0 * mu * a * M * G;
        let inertia = 0.4 * M * R * R;
        let alpha = torque / inertia;
        let t_stop = w0 / alpha;
        let (sc, _) = spinning(eq12, "coulomb", mu, w0, 1.3 * t_stop);
        let tr = trace(&sc);
        // The stop: w_z through w0 / 1000 (interpolated; the stopping bound makes the last
        // thousandth decay geometrically over a few steps), at (1 - 1e-3) T.
        let w_end = 1e-3 * w0;
        let kx = tr
            .iter()
            .position(|p| p.1 <= w_end)
            .expect("the spin stops");
        let ((t1, w1), (t2, w2)) = ((tr[kx - 1].0, tr[kx - 1].1), (tr[kx].0, tr[kx].1));
        let t_meas = t1 + (w1 - w_end) * (t2 - t1) / (w1 - w2);
        let pts: Vec<(f64, f64)> = tr
            .iter()
            .filter(|p| p.0 > 0.1 * t_stop && p.0 < 0.9 * t_stop)
            .map(|p| (p.0, p.1))
            .collect();
        let n = pts.len() as f64;
        let (mt, mw) = (
            pts.iter().map(|p| p.0).sum::<f64>() / n,
            pts.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let decel = -pts.iter().map(|p| (p.0 - mt) * (p.1 - mw)).sum::<f64>()
            / pts.iter().map(|p| (p.0 - mt).powi(2)).sum::<f64>();
        // Angle turned: trapezoidal integral of w_z.
        let angle: f64 = tr
            .windows(2)
            .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
            .sum();
        let what = format!("eq12 {eq12}, mu {mu}, w0 {w0}");
        assert_ref(
            &format!("{what}: spin deceleration (3 pi/16) mu a m g / I"),
            decel,
            alpha,
            2.0 * 0.0036e-2,
            "closed form",
        );
        assert_ref(
            &format!("{what}: stopping time I w0 / M (to w0 / 1000)"),
            t_meas,
            (1.0 - 1e-3) * t_stop,
            2.0 * 0.0036e-2,
            "closed form",
        );
        assert_ref(
            &format!("{what}: angle turned w0^2 I / (2 M)"),
            angle,
            w0 * w0 / (2.0 * alpha),
            2.0 * 0.0036e-2,
            "closed form",
        );
        let drift = tr
            .iter()
            .map(|p| (p.2 * p.2 + p.3 * p.3).sqrt())
            .fold(0.0, f64::max);
        println!("{what}: centre drift {drift:.3e} m");
        assert_eq!(drift, 0.0, "{what}: the centre moved {drift} m");
        let after = tr
            .iter()
            .filter(|p| p.0 > 1.1 * t_stop)
            .map(|p| p.1.abs())
            .fold(0.0, f64::max);
        println!("{what}: |w_z| after the stop {after:.3e} rad/s");
        assert!(after < 1e-6, "{what}: spins again at {after} rad/s");
    }
}

/// Without the model (the paper's, LIGGGHTS's and EDEM's default) the spin about the normal is
/// free: after 2 s it is still w0 to 1e-9.
#[test]
fn without_twisting_resistance_the_spin_goes_on() {
    let (sc, _) = spinning(false, "none", 0.3, 5.0, 2.0);
    let tr = trace(&sc);
    let last = tr.last().unwrap().1;
    println!("w_z after 2 s without twisting resistance: {last} rad/s");
    assert!((last - 5.0).abs() < 5e-9);
}

/// The twisting model is refused where it is unknown, naming the field.
#[test]
fn an_unknown_twisting_model_is_refused_naming_the_field() {
    let (sc, _) = spinning(false, "none", 0.3, 5.0, 0.01);
    let mut v = serde_json::to_value(&sc).unwrap();
    v["contact"]["twisting"] = json!("sticky");
    let e = scenario::from_json(&v.to_string(), "bad.json").unwrap_err();
    let msg = e.to_string();
    println!("{msg}");
    assert!(msg.contains("contact.twisting"), "{msg}");
}
