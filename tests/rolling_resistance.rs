//! Rolling resistance (issue 19; docs/physics.md section 11) against the closed forms derived
//! there, each with its tolerance and the figure measured with this build:
//!
//! - flat, `constant-torque` (LIGGGHTS `cdt`): a rolling apple decelerates at
//!   a = mu_r g R rho / (rho^2 + 2/5 R^2) = 5/7 mu_r g (1 + 3/7 u/R + ...), rho = R - u the
//!   contact-point lever on a rigid flat, and stops after v0^2 / (2 a) in v0 / a
//!   (with rho = R: 7 v0^2 / (10 mu_r g), 7 v0 / (5 mu_r g)). The 1 % against the R forms
//!   (stated 0.25 %, the lever); the rho forms to 0.036 % (0.0043 % with `elastic-plastic`) (11.3).
//! - flat, `elastic-plastic`: while rolling the spring sits at its cap, the same closed forms.
//! - slope: rolls down at a = g (sin t - mu_r cos t R / rho) / (1 + 2/5 R^2 / rho^2)
//!   (= 5/7 g (sin t - mu_r cos t) with rho = R) when tan t > mu_r; with `elastic-plastic` it stays
//!   (drift under 1 mm over 2 s, the bound) when tan t < mu_r (11.3).
//! - belt: an apple set at rest on a belt running at V reaches V after exactly
//!   T = (rho / R) V / (mu_r g), slip phase included (its angular momentum about a point of the
//!   belt changes only by the rolling torque), and then rides with it (within 2 % of V) (11.3).
//! - a settled pile and a lone apple on a gentle slope with the default model stay put (11.5).
//!
//! Each measured figure stated in docs/physics.md is checked at twice its value (docs/claims.md),
//! as well as at the tolerance.
//!
//! The apple is the paper's Figs. 6-7 apple (D 80 mm, G 1 MPa, nu 0.18, 0.107 kg) on steel,
//! friction 0.3 (0.5 on the belt), mu_r 0.03 (the default) and 0.05. `constant-torque` runs with
//! the viscoelastic damping (its LIGGGHTS pairing: at rest the Hertz part that LIGGGHTS's torque
//! uses is the load); applesim's torque acts on the load, so it gives the same closed forms with
//! the eq. 12 dampings (tested below).
//! Every reference is written here (no crate helper); the lever uses the closed-form static sag.

use crate::common;
use applesim::math::Vec3;
use applesim::record::series::AppleState;
use applesim::scenario::{self, Scenario};
use common::ode;
use common::*;
use serde_json::{json, Value};

const R: f64 = 0.04;
const M: f64 = 0.107;
const G: f64 = 9.81;
const APPLE: (f64, f64) = (1.0e6, 0.18);
const STEEL: (f64, f64) = (8.1e10, 0.28);
const KE: f64 = 0.09;

/// The normal damping of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Damp {
    /// The paper's eq. 12 (ke 0.09, lambda 1000 s/m): at rest (1 + ke)/2 of Hertz.
    Eq12,
    /// Eq. 12 with the full Hertz force at rest.
    ElasticRest,
    /// LIGGGHTS's viscoelastic Hertz, restitution 0.3.
    Visco,
}

fn contact(d: Damp, mu: f64, rolling: &str, mu_r: f64) -> Value {
    let mut c = match d {
        Damp::Eq12 => json!({"friction": mu, "ke": KE, "lambda_s_m": 1000, "damping": "eq12"}),
        Damp::ElasticRest => json!({"friction": mu, "ke": KE, "lambda_s_m": 1000,
            "damping": "eq12-elastic-rest"}),
        Damp::Visco => json!({"friction": mu, "damping": "viscoelastic", "restitution": 0.3}),
    };
    c["rolling"] = json!(rolling);
    c["rolling_friction"] = json!(mu_r);
    c
}

fn materials() -> Value {
    json!({
        "apple": {"shear_modulus_pa": APPLE.0, "poisson_ratio": APPLE.1, "density_kg_m3": 800},
        "steel": {"shear_modulus_pa": STEEL.0, "poisson_ratio": STEEL.1}})
}

/// Static overlap under the normal load `load_n` on steel (docs/physics.md 11.2): eq. 12 carries
/// (1 + ke)/2 of Hertz at rest, the other two the whole.
fn sag(d: Damp, load_n: f64) -> f64 {
    let k = ode::hertz_k(APPLE.0, APPLE.1, STEEL.0, STEEL.1, R);
    match d {
        Damp::Eq12 => ode::resting_sag(k, KE, load_n),
        _ => (load_n / k).powf(2.0 / 3.0),
    }
}

/// An apple on a steel plane tilted by `theta_deg` about y (its down-slope direction is
/// (cos t, 0, -sin t)), at its static sag, launched down the slope at `v0` rolling without slip
/// about the lever rho = R - u. Returns the scenario and rho.
#[allow(clippy::too_many_arguments)]
fn plane_scene(
    d: Damp,
    rolling: &str,
    mu_r: f64,
    mu: f64,
    theta_deg: f64,
    v0: f64,
    duration_s: f64,
    dt: f64,
) -> (Scenario, f64) {
    let th = theta_deg.to_radians();
    let n = Vec3::new(th.sin(), 0.0, th.cos());
    let rho = R - sag(d, M * G * th.cos());
    let c = n * rho;
    let v = Vec3::new(th.cos(), 0.0, -th.sin()) * v0;
    let s = json!({
        "duration_s": duration_s, "time_step_s": dt, "gravity_m_s2": [0, 0, -G],
        "output": {"sample_interval_s": 1e-3, "force_history": false},
        "materials": materials(),
        "contact": contact(d, mu, rolling, mu_r),
        "model": {"sleep": {"enabled": false}},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 2.0 * R, "mass_kg": M,
            "position_m": [c.x, c.y, c.z], "velocity_m_s": [v.x, v.y, v.z],
            "angular_velocity_rad_s": [0, v0 / rho, 0]}],
        "surfaces": [{"name": "floor", "type": "plane", "material": "steel",
            "point_m": [0, 0, 0], "normal": [n.x, n.y, n.z]}]
    });
    (scenario::from_json(&s.to_string(), "rolling").unwrap(), rho)
}

/// Least-squares slope of y(t).
fn slope(pts: &[(f64, f64)]) -> f64 {
    let n = pts.len() as f64;
    let (mt, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    pts.iter().map(|p| (p.0 - mt) * (p.1 - my)).sum::<f64>()
        / pts.iter().map(|p| (p.0 - mt).powi(2)).sum::<f64>()
}

/// Deceleration a = mu_r g R rho / (rho^2 + 2/5 R^2) of an apple rolling on a flat against the
/// torque mu_r R m g (docs/physics.md 11.3; rho = R gives 5/7 mu_r g).
fn flat_deceleration(mu_r: f64, rho: f64) -> f64 {
    mu_r * G * R * rho / (rho * rho + 0.4 * R * R)
}

/// What a run on a flat measured: deceleration (fit over 10-90 % of the stop), stopping time
/// (v through 0, interpolated) and distance (the farthest x).
struct Stop {
    deceleration: f64,
    time_s: f64,
    distance_m: f64,
}

fn stop_of(s: &[(f64, &AppleState)]) -> Stop {
    let k = s
        .iter()
        .position(|(_, a)| a.velocity.x <= 1e-5)
        .expect("the apple stops");
    let ((t1, v1), (t2, v2)) = (
        (s[k - 1].0, s[k - 1].1.velocity.x),
        (s[k].0, s[k].1.velocity.x),
    );
    let time_s = t1 + v1 * (t2 - t1) / (v1 - v2);
    let pts: Vec<(f64, f64)> = s
        .iter()
        .filter(|(t, _)| *t > 0.1 * time_s && *t < 0.9 * time_s)
        .map(|(t, a)| (*t, a.velocity.x))
        .collect();
    Stop {
        deceleration: -slope(&pts),
        time_s,
        distance_m: s.iter().map(|(_, a)| a.position.x).fold(f64::MIN, f64::max)
            - s[0].1.position.x,
    }
}

/// Checks a stop against the closed forms with the lever R (7 v0^2 / (10 mu_r g), 7 v0 / (5 mu_r
/// g), 5/7 mu_r g) at `loose` (twice the measured figure physics.md prints beside the stated
/// 0.25 %; the 1 % is looser), and at `tight` with the lever rho = R - u.
fn check_stop(what: &str, got: &Stop, v0: f64, mu_r: f64, rho: f64, loose: f64, tight: f64) {
    let a_r = 5.0 / 7.0 * mu_r * G;
    assert_ref(
        &format!("{what}: deceleration, lever R"),
        got.deceleration,
        a_r,
        loose,
        "closed form",
    );
    assert_ref(
        &format!("{what}: stopping distance 7 v0^2 / (10 mu_r g)"),
        got.distance_m,
        7.0 * v0 * v0 / (10.0 * mu_r * G),
        loose,
        "closed form",
    );
    assert_ref(
        &format!("{what}: stopping time 7 v0 / (5 mu_r g)"),
        got.time_s,
        7.0 * v0 / (5.0 * mu_r * G),
        loose,
        "closed form",
    );
    let a = flat_deceleration(mu_r, rho);
    assert_ref(
        &format!("{what}: deceleration, lever R - u"),
        got.deceleration,
        a,
        tight,
        "closed form",
    );
    assert_ref(
        &format!("{what}: distance, lever R - u"),
        got.distance_m,
        v0 * v0 / (2.0 * a),
        tight,
        "closed form",
    );
    assert_ref(
        &format!("{what}: time, lever R - u"),
        got.time_s,
        v0 / a,
        tight,
        "closed form",
    );
}

/// Item 1: `constant-torque` on a flat (viscoelastic damping, its LIGGGHTS pairing), two speeds,
/// two coefficients, dt 1e-4 s and 1e-5 s. docs/physics.md 11.3: within 1 % of the R forms (the
/// issue; u/R = 0.34 % moves them by 3/7 of that: measured 0.16 % at most, stated 0.25 %), within
/// 0.036 % of the R - u forms (the stopping time at v0 0.25 m/s, mu_r 0.05, dt 1e-4 s: the
/// stopping bound, the torque that stops the spin about the centre within a step, spreads the
/// last of the stop over a few steps; 0.016 % before it used the moment about the contact point,
/// which rocked the stopped apple), each checked at twice the stated figure.
#[test]
fn constant_torque_on_a_flat_stops_at_the_closed_form() {
    // docs/physics.md 11.3: the example (v0 0.5 m/s, mu_r 0.03; +-1 digit) and the first-order
    // expansion a = 5/7 mu_r g (1 + 3/7 u/R) (to (u/R)^2).
    let a_r = 5.0 / 7.0 * 0.03 * G;
    assert!((a_r - 0.2102).abs() <= 1e-4);
    assert!((0.25 * 0.7 / (0.03 * G) - 0.5946).abs() <= 1e-4);
    assert!((0.5 * 1.4 / (0.03 * G) - 2.379).abs() <= 1e-3);
    for d in [Damp::Visco, Damp::Eq12] {
        let u = sag(d, M * G);
        let exact = flat_deceleration(0.03, R - u) / a_r - 1.0;
        println!(
            "{d:?}: u/R {:.3} %, a / (5/7 mu_r g) - 1 = {:.3} %",
            100.0 * u / R,
            100.0 * exact
        );
        assert!((exact - 3.0 / 7.0 * u / R).abs() <= (u / R).powi(2));
    }
    for (v0, mu_r, dt) in [(0.5, 0.03, 1e-4), (0.25, 0.05, 1e-4), (0.5, 0.03, 1e-5)] {
        let t_stop = 7.0 * v0 / (5.0 * mu_r * G);
        let (sc, rho) = plane_scene(
            Damp::Visco,
            "constant-torque",
            mu_r,
            0.3,
            0.0,
            v0,
            1.1 * t_stop,
            dt,
        );
        let (_, s) = run(&sc);
        let stop = stop_of(&s.of(0));
        check_stop(
            &format!("cdt v0 {v0} mu_r {mu_r} dt {dt}"),
            &stop,
            v0,
            mu_r,
            rho,
            2.0 * 0.16e-2,
            2.0 * 0.036e-2,
        );
    }
}

/// Item 1 with the default rolling model: `elastic-plastic` on a flat stops at the same closed
/// forms (its spring sits at the cap mu_r R |F_n| while rolling, F_n the whole normal force, which
/// averages m g whatever the damping). docs/physics.md 11.3: within 0.25 % of the R forms
/// (measured 0.22 %, eq. 12's deeper sag) and 0.0043 % of the R - u forms (the distance of the
/// eq12-elastic-rest run; 0.020 % before resting contacts' eq. 12 step mean took the support into
/// account), each checked at twice that.
#[test]
fn elastic_plastic_on_a_flat_stops_at_the_same_closed_form() {
    let (v0, mu_r) = (0.5, 0.03);
    for d in [Damp::Eq12, Damp::ElasticRest, Damp::Visco] {
        let (sc, rho) = plane_scene(d, "elastic-plastic", mu_r, 0.3, 0.0, v0, 2.6, 1e-4);
        let (_, s) = run(&sc);
        let stop = stop_of(&s.of(0));
        check_stop(
            &format!("epsd {d:?}"),
            &stop,
            v0,
            mu_r,
            rho,
            2.0 * 0.22e-2,
            2.0 * 0.0043e-2,
        );
    }
}

/// `constant-torque` acts on the load (the whole normal force), so with the eq. 12 dampings too it
/// decelerates at the R - u form (docs/physics.md 11.3): eq12 at dt 1e-4 s and eq12-elastic-rest
/// at 1e-5 s within 0.0041 % on the deceleration and the distance (measured: -0.0000 % and
/// -0.0041 %; +0.0001 % and -0.0003 %), checked at twice that and at the 1 %. (When it
/// took the Hertz part, as LIGGGHTS's cdt takes k_n delta, eq. 12's resting contact, which
/// carries (1 + ke)/2 of Hertz, got 2 / (1 + ke) = 1.83 times the torque: +88 % and -50 %.)
#[test]
fn constant_torque_with_the_eq12_dampings_decelerates_at_five_sevenths_mu_r_g() {
    let (v0, mu_r) = (0.5, 0.03);
    let mut failures = Vec::new();
    for (d, dt) in [(Damp::Eq12, 1e-4), (Damp::ElasticRest, 1e-5)] {
        let (sc, rho) = plane_scene(d, "constant-torque", mu_r, 0.3, 0.0, v0, 2.6, dt);
        let (_, s) = run(&sc);
        let stop = stop_of(&s.of(0));
        let a = flat_deceleration(mu_r, rho);
        let (e_a, e_d) = (
            stop.deceleration / a - 1.0,
            stop.distance_m / (v0 * v0 / (2.0 * a)) - 1.0,
        );
        println!(
            "cdt with {d:?} at dt {dt}: deceleration {:+.4} %, distance {:+.4} %",
            100.0 * e_a,
            100.0 * e_d
        );
        if e_a.abs() > 0.01 || e_d.abs() > 0.01 {
            failures.push(format!("the issue's 1 %: {d:?}"));
        }
        if e_a.abs() > 2.0 * 0.0041e-2 || e_d.abs() > 2.0 * 0.0041e-2 {
            failures.push(format!(
                "{d:?}: {:+.2} %, {:+.2} %",
                100.0 * e_a,
                100.0 * e_d
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// A stopped `constant-torque` apple stays stopped (docs/physics.md 11.3): its torque is bounded
/// by the one that stops the relative spin about the centre within one step (kill_rate I |w|).
/// Measured at dt 1e-4 s after the stop (v0 0.5 m/s, mu_r 0.03, stop at 2.38 s): it rolls back
/// 2.15 um from its furthest point as it stops, then 0.34 nm from 2.5 to 4.5 s,
/// checked at twice that, and |w| under 1e-6 rad/s from 4 s (measured 1.5e-54). (With the moment
/// about the contact point, I + m R^2, in the bound it reversed w by 1.75 times w every step:
/// +-1.2e-3 rad/s, creeping back at 3.5e-6 m/s.)
#[test]
fn constant_torque_after_the_stop_stays_stopped() {
    let (v0, mu_r) = (0.5, 0.03);
    let (mut sc, _) = plane_scene(
        Damp::Visco,
        "constant-torque",
        mu_r,
        0.3,
        0.0,
        v0,
        4.5,
        1e-4,
    );
    sc.output.sample_interval_s = Some(1e-4);
    let (_, s) = run(&sc);
    let s = s.of(0);
    let at = |t: f64| s.iter().find(|(x, _)| *x >= t - 1e-9).unwrap().1;
    let creep = (at(4.5).position.x - at(2.5).position.x).abs();
    let rock = s
        .iter()
        .filter(|(t, _)| *t >= 4.0)
        .map(|(_, a)| a.angular_velocity.y.abs())
        .fold(0.0, f64::max);
    // How far it rolls back from its furthest point (the stop) by the end.
    let furthest = s.iter().map(|(_, a)| a.position.x).fold(f64::MIN, f64::max);
    let back = furthest - at(4.5).position.x;
    println!("after the stop (2.5 .. 4.5 s): moved {creep:.3e} m; |w| up to {rock:.3e} rad/s; back from the furthest point {back:.3e} m");
    assert!(creep < 2.0 * 0.34e-9, "crept {creep} m");
    assert!(rock < 1e-6, "rocks at {rock} rad/s");
    // As it stops, the bounded torque lets it roll back a little once (measured 2.15 um; at
    // twice that).
    assert!(back < 2.0 * 2.15e-6, "rolled back {back} m");
}

/// Acceleration down a slope (fit over 0.05-0.5 s) of an apple released at rest.
fn slope_acceleration(d: Damp, rolling: &str, mu_r: f64, theta_deg: f64, dt: f64) -> (f64, f64) {
    let (sc, rho) = plane_scene(d, rolling, mu_r, 0.3, theta_deg, 0.0, 0.5, dt);
    let (_, s) = run(&sc);
    let th = theta_deg.to_radians();
    let down = Vec3::new(th.cos(), 0.0, -th.sin());
    let pts: Vec<(f64, f64)> = s
        .of(0)
        .iter()
        .filter(|(t, _)| *t >= 0.05)
        .map(|(t, a)| (*t, a.velocity.dot(down)))
        .collect();
    (slope(&pts), rho)
}

/// Item 2: on a slope with tan t > mu_r (3 and 5 degrees, mu_r 0.03: tan t = 1.7 and 2.9 mu_r)
/// both models roll down at a = g (sin t - mu_r cos t R/rho) / (1 + 2/5 R^2/rho^2) (docs/physics.md
/// 11.3): within 1 % (the issue) and 0.0007 % (stated; measured 0.00066 %, `constant-torque` at 3
/// degrees; 0.062 % before resting contacts' eq. 12 step mean took the support into account),
/// checked at twice the measured figure. The plain 5/7 g (sin t - mu_r cos t) within 1 % at 5
/// degrees (measured -0.56 %: below it, checked at 2x with its sign, the 1 % tighter);
/// near the threshold the lever matters: at 3 degrees with eq. 12's sag it is -0.99 % off (to one
/// unit of the last digit), the R - u form over ten times closer (checked).
#[test]
fn rolls_down_a_slope_at_the_closed_form_when_tan_exceeds_mu_r() {
    let mu_r = 0.03;
    for (d, rolling) in [
        (Damp::Visco, "constant-torque"),
        (Damp::Eq12, "elastic-plastic"),
    ] {
        for theta_deg in [3.0f64, 5.0] {
            let th = theta_deg.to_radians();
            assert!(th.tan() > mu_r);
            let (a, rho) = slope_acceleration(d, rolling, mu_r, theta_deg, 1e-4);
            let cf = G * (th.sin() - mu_r * th.cos() * R / rho) / (1.0 + 0.4 * R * R / (rho * rho));
            let what = format!("{d:?} {rolling} {theta_deg} deg");
            assert_ref(
                &format!("{what}: acceleration, lever R - u"),
                a,
                cf,
                2.0 * 0.00066e-2,
                "closed form",
            );
            let plain = 5.0 / 7.0 * G * (th.sin() - mu_r * th.cos());
            if theta_deg == 5.0 {
                assert_ref(
                    &format!("{what}: 5/7 g (sin - mu_r cos)"),
                    a,
                    plain,
                    0.01,
                    "closed form",
                );
                assert!(a < plain, "{what}: below the plain form (-0.56 %)");
            } else if d == Damp::Eq12 {
                // Near the threshold the lever matters: the closed form with R - u is closer.
                let off = rel(a, plain);
                println!("{what}: 5/7 g (sin - mu_r cos) off by {:.3} %", 100.0 * off);
                assert!(
                    a < plain && (off - 0.99e-2).abs() <= 0.01e-2,
                    "{what}: {off}"
                );
                assert!(
                    rel(a, cf) < 0.1 * off,
                    "the lever matters here: {off} against {}",
                    rel(a, cf)
                );
            }
        }
    }
}

/// docs/physics.md 11.3: with rolling resistance an apple rolls down without slip while
/// tan t <= (7 mu - 5 mu_r)/2 (44.3 degrees at mu 0.3, mu_r 0.03) and slides beyond, at
/// g (sin t - mu cos t) whatever resists its rolling. `constant-torque` (viscoelastic): at 40
/// degrees it rolls at the R - u form (stated 0.0007 %, as above; measured 0.00019 %, checked at
/// twice that), at 50 degrees it slides (within 1 %, physics.md section 6's rule; measured to
/// 1e-8, checked at twice that).
#[test]
fn slides_beyond_the_rolling_limit_of_the_slope() {
    let (mu, mu_r) = (0.3, 0.03);
    let limit = ((7.0 * mu - 5.0 * mu_r) / 2.0f64).atan().to_degrees();
    assert!((limit - 44.3).abs() <= 0.05, "{limit}");
    let th = 40f64.to_radians();
    let (a, rho) = slope_acceleration(Damp::Visco, "constant-torque", mu_r, 40.0, 1e-4);
    let cf = G * (th.sin() - mu_r * th.cos() * R / rho) / (1.0 + 0.4 * R * R / (rho * rho));
    assert_ref("40 degrees: rolls", a, cf, 2.0 * 0.00019e-2, "closed form");
    let th = 50f64.to_radians();
    let (a, _) = slope_acceleration(Damp::Visco, "constant-torque", mu_r, 50.0, 1e-4);
    assert_ref(
        "50 degrees: slides at g (sin t - mu cos t)",
        a,
        G * (th.sin() - mu * th.cos()),
        2e-8,
        "closed form",
    );
}

/// Item 2: with `elastic-plastic` and tan t < mu_r (1 and 1.5 degrees: 0.58 and 0.87 mu_r) a
/// lone apple released at rest stays: the bound, under 1 mm over 2 s. docs/physics.md
/// 11.3: it settles within 6 um (the rolling spring and the stick spring taking the load:
/// measured 2.9-5.3 um) and moves less than 0.1 um from 0.5 to 2 s (measured 0.07 nm, checked
/// at twice that; 14 nm
/// before resting contacts' eq. 12 step mean took the support into account), at dt 1e-4 s.
#[test]
fn elastic_plastic_holds_an_apple_on_a_slope_below_mu_r() {
    let mu_r = 0.03;
    for d in [Damp::Eq12, Damp::ElasticRest, Damp::Visco] {
        for theta_deg in [1.0f64, 1.5] {
            let th = theta_deg.to_radians();
            assert!(th.tan() < mu_r);
            let (sc, _) = plane_scene(d, "elastic-plastic", mu_r, 0.3, theta_deg, 0.0, 2.0, 1e-4);
            let (_, s) = run(&sc);
            let s = s.of(0);
            let down = Vec3::new(th.cos(), 0.0, -th.sin());
            let at = |t: f64| s.iter().find(|(x, _)| *x >= t - 1e-9).unwrap().1.position;
            let drift = (at(2.0) - at(0.0)).dot(down);
            let late = (at(2.0) - at(0.5)).dot(down).abs();
            println!(
                "{d:?} {theta_deg} deg: drift 0 .. 2 s {drift:.3e} m, 0.5 .. 2 s {late:.3e} m"
            );
            assert!(drift.abs() < 1e-3, "the issue's bound");
            assert!(
                drift.abs() < 6e-6 && late < 2.0 * 0.07e-9,
                "drift {drift} m, late {late} m"
            );
        }
    }
}

/// docs/physics.md 11.3: `constant-torque` cannot hold an apple on a slope, however gentle: its
/// torque points against the rolling and vanishes with it (bounded by the velocity-kill rate
/// times |w|), so the apple creeps down at the speed where that bound carries the load. Measured
/// at 1.5 degrees (tan t = 0.87 mu_r), viscoelastic damping, dt 1e-4 s: 258 um over 2 s, still
/// moving (191 um from 0.5 to 2 s; 76 and 55 um when the bound used the moment about the contact
/// point); each checked to one unit of its last digit (a regression pin of this build: the creep
/// speed is set by the stopping bound and the step, no closed form), and both far beyond what
/// `elastic-plastic` allows (under 6 um). Use `elastic-plastic`.
#[test]
fn constant_torque_cannot_hold_an_apple_on_a_gentle_slope() {
    let th = 1.5f64.to_radians();
    let (sc, _) = plane_scene(
        Damp::Visco,
        "constant-torque",
        0.03,
        0.3,
        1.5,
        0.0,
        2.0,
        1e-4,
    );
    let (_, s) = run(&sc);
    let s = s.of(0);
    let down = Vec3::new(th.cos(), 0.0, -th.sin());
    let at = |t: f64| s.iter().find(|(x, _)| *x >= t - 1e-9).unwrap().1.position;
    let (drift, late) = ((at(2.0) - at(0.0)).dot(down), (at(2.0) - at(0.5)).dot(down));
    println!("cdt, 1.5 degrees: drift 0 .. 2 s {drift:.3e} m, 0.5 .. 2 s {late:.3e} m");
    assert!(
        (drift - 258e-6).abs() <= 1e-6 && (late - 191e-6).abs() <= 1e-6,
        "creeps: {drift} m, {late} m"
    );
}

/// An apple at rest at its sag on a steel belt running at `v_belt` along +x.
fn belt_scene(
    d: Damp,
    rolling: &str,
    mu_r: f64,
    mu: f64,
    v_belt: f64,
    duration_s: f64,
) -> (Scenario, f64) {
    let rho = R - sag(d, M * G);
    let v = json!({
        "duration_s": duration_s, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -G],
        "output": {"sample_interval_s": 1e-3, "force_history": false},
        "materials": materials(),
        "contact": contact(d, mu, rolling, mu_r),
        "model": {"sleep": {"enabled": false}},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 2.0 * R, "mass_kg": M,
            "position_m": [-1.2, 0, rho]}],
        "surfaces": [{"name": "belt", "type": "conveyor", "material": "steel",
            "size_m": [4.0, 0.4, 0.02], "position_m": [0.5, 0, -0.01], "belt_velocity_m_s": v_belt}]
    });
    (scenario::from_json(&v.to_string(), "belt").unwrap(), rho)
}

/// Item 3: an apple set at rest on a belt reaches the belt speed V after T = (rho/R) V / (mu_r g)
/// (docs/physics.md 11.3, the slip phase included) and rides with it. Within 1 % (the issue) and
/// 0.01 % (stated; measured 0.0099 % at most; 0.027 % before resting contacts' eq. 12 step mean
/// took the support into account), checked at twice the measured figure. The first-order
/// form 2V/(7 mu g) + V/(mu_r g) is 2.0-3.3 % late (2 mu_r / (7 mu) = 1.7 and 2.9 % from
/// neglecting the rolling resistance during the slip, the rest from the lever; checked within one
/// unit of the last digit of that range, late). After T the centre speed stays within 2 % of V
/// (the issue) and 0.1 % (stated; measured 0.091 %, checked at twice that). Default model (eq. 12, `elastic-plastic`) and `constant-torque` with
/// viscoelastic damping; belt 0.4 m/s with mu_r 0.03 and 0.8 m/s with 0.05, friction 0.5.
#[test]
fn a_belt_brings_an_apple_to_its_speed_at_the_closed_form_time() {
    let mu = 0.5;
    for (d, rolling) in [
        (Damp::Eq12, "elastic-plastic"),
        (Damp::Visco, "constant-torque"),
    ] {
        for (v_belt, mu_r) in [(0.4, 0.03), (0.8, 0.05)] {
            let t_cf = v_belt / (mu_r * G);
            let (sc, rho) = belt_scene(d, rolling, mu_r, mu, v_belt, t_cf + 1.0);
            let (_, s) = run(&sc);
            let s = s.of(0);
            // The time the centre reaches V (its speed crosses V (1 - 1e-4), interpolated: the
            // speed rises at 5/7 mu_r g, so the offset is 1e-4 V / (0.21 m/s^2) = 0.2 ms).
            let target = v_belt * (1.0 - 1e-4);
            let k = s
                .iter()
                .position(|(_, a)| a.velocity.x >= target)
                .expect("reaches the belt speed");
            let ((t1, v1), (t2, v2)) = (
                (s[k - 1].0, s[k - 1].1.velocity.x),
                (s[k].0, s[k].1.velocity.x),
            );
            let t_reach = t1 + (target - v1) * (t2 - t1) / (v2 - v1);
            let what = format!("{d:?} {rolling} V {v_belt} mu_r {mu_r}");
            let exact = rho / R * t_cf;
            assert_ref(
                &format!("{what}: time to V, (rho/R) V/(mu_r g)"),
                t_reach,
                exact,
                2.0 * 0.0099e-2,
                "closed form",
            );
            let first_order = 2.0 * v_belt / (7.0 * mu * G) + t_cf;
            let off = rel(t_reach, first_order);
            println!(
                "{what}: the first-order form {first_order:.5} s is {:.3} % off",
                100.0 * off
            );
            assert!(t_reach < first_order && (0.019..=0.034).contains(&off));
            let worst = s
                .iter()
                .filter(|(t, _)| *t >= exact)
                .map(|(_, a)| (a.velocity.x - v_belt).abs())
                .fold(0.0, f64::max);
            println!(
                "{what}: after T, |v - V| up to {worst:.3e} m/s ({:.3} % of V)",
                100.0 * worst / v_belt
            );
            assert!(worst <= 0.02 * v_belt, "rides with the belt (the issue)");
            assert!(worst <= 2.0 * 0.091e-2 * v_belt, "rides with the belt");
        }
    }
}

/// The 27-apple pile of tests/slope_rest.rs (sleeping off) with the given `rolling_damping`
/// (None: the default) and otherwise default rolling resistance, run for `duration_s`: the
/// largest displacement of an apple between two sample times (every 0.5 s), and the apple-apple
/// contacts open at the end.
fn pile(eta_r: Option<f64>, duration_s: f64) -> (impl Fn(f64, f64) -> f64, usize) {
    let plane = |name: &str, p: [f64; 3], n: [f64; 3]| json!({"name": name, "type": "plane", "material": "steel", "point_m": p, "normal": n});
    let mut contact = json!({"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000});
    if let Some(e) = eta_r {
        contact["rolling_damping"] = json!(e);
    }
    let v = json!({
        "duration_s": duration_s, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -G],
        "output": {"sample_interval_s": 0.5, "force_history": false, "transitions": {"enabled": false}},
        "materials": {
            "apple": {"youngs_modulus_pa": 2.6e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "steel": {"youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.3}},
        "contact": contact,
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
    let open = r
        .events
        .iter()
        .filter(|e| e.t_end_s.is_none() && e.b.starts_with("p-"))
        .count();
    let worst = move |a: f64, b: f64| {
        let at = |t: f64| {
            &s.samples
                .iter()
                .find(|(x, _)| (*x - t).abs() < 1e-9)
                .unwrap()
                .1
        };
        at(a)
            .iter()
            .zip(at(b))
            .map(|(x, y)| (x.position - y.position).length())
            .fold(0.0, f64::max)
    };
    (worst, open)
}

/// Item 5: a settled 27-apple pile with the default rolling model (elastic-plastic, mu_r 0.03,
/// eta_r 1) does not creep: the largest displacement from 4 to 6 s under 1 nm (the issue's
/// example; measured 0.14 nm, checked at twice that), and 96 nm from 2 to 4 s (checked at twice
/// that), which is the pile still settling, not creep: the largest displacement per half second
/// falls from 0.14 um (2-2.5 s) to 0.41 nm (3.5-4 s) (each to one unit of its last digit), and
/// from 7.5 s on it is under 1e-15 m (rounding). Without the rolling dashpot (eta_r = 0,
/// LIGGGHTS's epsd2) the spring keeps rocking the pile: 3.0 um from 4 to 6 s (to one unit of the
/// last digit, and over 1000 times the default's), which is why the default is eta_r = 1
/// (docs/physics.md 11.5). The pile is chaotic: these are regression pins of this build, beside
/// the physical check, the 1 nm bound on creep.
#[test]
fn a_settled_pile_with_the_default_rolling_model_does_not_creep() {
    let (worst, open) = pile(None, 8.0);
    let (early, late) = (worst(2.0, 4.0), worst(4.0, 6.0));
    println!("default rolling model: largest displacement 2 .. 4 s {early:.3e} m, 4 .. 6 s {late:.3e} m; {open} apple-apple contacts");
    for t in [2.0, 2.5, 3.0, 3.5, 6.0, 6.5, 7.0, 7.5] {
        println!("  {t} .. {} s: {:.3e} m", t + 0.5, worst(t, t + 0.5));
    }
    assert!(open > 10, "the pile is packed");
    assert!(
        late < 1e-9,
        "the issue's bound: an apple moved {late} m from 4 to 6 s"
    );
    assert!(
        late < 2.0 * 0.14e-9,
        "an apple moved {late} m from 4 to 6 s"
    );
    assert!(
        early < 2.0 * 96e-9,
        "an apple moved {early} m from 2 to 4 s"
    );
    assert!((worst(2.0, 2.5) - 0.14e-6).abs() <= 0.01e-6);
    assert!((worst(3.5, 4.0) - 0.41e-9).abs() <= 0.01e-9);
    assert!(worst(7.5, 8.0) < 1e-15);
    let late0 = pile(Some(0.0), 6.0).0(4.0, 6.0);
    println!("eta_r = 0 (epsd2): largest displacement 4 .. 6 s {late0:.3e} m");
    assert!(
        late0 > 1000.0 * late && (late0 - 3.0e-6).abs() <= 0.1e-6,
        "epsd2 rocks the pile: {late0} m against {late} m"
    );
}

/// Item 5: a lone apple on a gentle slope (1.5 degrees, tan t = 0.87 mu_r) with the default
/// model (no sub-model field in the scenario: eq. 12, Mindlin, elastic-plastic, mu_r 0.03, eta_r
/// 1) stays: under 1 mm over 2 s (the issue), under 6 um (measured 4.3 um), at dt 1e-4 s.
#[test]
fn a_lone_apple_on_a_gentle_slope_stays_with_the_default_model() {
    // The default mu_r 0.03 holds an apple on slopes up to atan(0.03) = 1.7 degrees.
    assert!((0.03f64.atan().to_degrees() - 1.7).abs() <= 0.05);
    let th = 1.5f64.to_radians();
    let n = Vec3::new(th.sin(), 0.0, th.cos());
    let c = n * (R - sag(Damp::Eq12, M * G * th.cos()));
    let v = json!({
        "duration_s": 2.0, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -G],
        "output": {"sample_interval_s": 1e-2, "force_history": false},
        "materials": materials(),
        "contact": {"friction": 0.3, "ke": KE, "lambda_s_m": 1000},
        "model": {"sleep": {"enabled": false}},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 2.0 * R, "mass_kg": M,
            "position_m": [c.x, c.y, c.z]}],
        "surfaces": [{"name": "slope", "type": "plane", "material": "steel",
            "point_m": [0, 0, 0], "normal": [n.x, n.y, n.z]}]
    });
    let sc = scenario::from_json(&v.to_string(), "gentle slope").unwrap();
    assert_eq!(
        sc.contact.rolling,
        applesim::scenario::models::Rolling::ElasticPlastic
    );
    assert_eq!(
        (sc.contact.rolling_friction, sc.contact.rolling_damping),
        (0.03, 1.0)
    );
    assert_eq!(
        (sc.contact.damping, sc.contact.tangential),
        (
            applesim::scenario::models::Damping::Eq12,
            applesim::scenario::models::Tangential::Mindlin
        )
    );
    let (_, s) = run(&sc);
    let s = s.of(0);
    let down = Vec3::new(th.cos(), 0.0, -th.sin());
    let drift = (s.last().unwrap().1.position - s[0].1.position).dot(down);
    println!("default model, 1.5 degrees: drift over 2 s {drift:.3e} m");
    assert!(drift.abs() < 1e-3, "the issue's bound");
    assert!(drift.abs() < 6e-6, "drift {drift} m");
}

/// docs/physics.md 11.4: the paper's scenarios keep the paper's model: `eq12`, `mindlin`, no
/// rolling resistance, in `contact` and every `pairs[]` entry (the shipped single scenarios of
/// scenarios/paper/ and the three top-level paper cases; the batch specs there build on them).
#[test]
fn the_papers_scenarios_keep_the_papers_model() {
    use applesim::scenario::models::{Damping, Rolling, Tangential};
    let mut files = vec![
        "scenarios/drop_on_steel.json".to_string(),
        "scenarios/slip_to_roll.json".to_string(),
        "scenarios/two_apples_head_on.json".to_string(),
    ];
    for entry in std::fs::read_dir(repo("scenarios/paper")).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let v: Value = serde_json::from_str(&text).unwrap();
        if v.get("base").is_none() {
            files.push(format!(
                "scenarios/paper/{}",
                path.file_name().unwrap().to_string_lossy()
            ));
        }
    }
    assert!(files.len() >= 11, "{files:?}");
    for f in files {
        let sc = shipped(&f);
        let c = &sc.contact;
        assert_eq!(
            (c.damping, c.tangential, c.rolling),
            (Damping::Eq12, Tangential::Mindlin, Rolling::None),
            "{f}"
        );
        for p in &sc.pairs {
            let c = p.over(&sc.contact);
            assert_eq!(
                (c.damping, c.tangential, c.rolling),
                (Damping::Eq12, Tangential::Mindlin, Rolling::None),
                "{f}: pair {:?}",
                p.materials
            );
        }
    }
}
