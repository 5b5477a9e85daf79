//! Slip-to-roll on a steel plate (physics.md section 6, paper Figs. 6-7), issue 2 acceptance:
//! time to rolling and final speed within 1 % of the 5/7 and 2/7 rules, mu = 0.3.
//!
//! A second, tight check uses the true lever arm R - u of the sagging apple
//! (`ode::slip_to_roll` with rho = R - u, written in tests/common), which the 1 % rule ignores, with u from the closed form
//! (the static sag under eq. 12, tests/common/ode.rs), not from the run: within twice README's
//! 0.0006 % on the time ("Slip and roll") and twice docs/transitions.md's 5.1e-5 m/s on the speed
//! at the end of the run.
//!
//! The transition is taken where the slip speed of the contact point, v - (R - u) w, reaches
//! zero, interpolated linearly between the last two samples of the sliding phase (the slip falls
//! linearly while sliding).

use crate::common;
use common::ode;
use common::*;

/// Runs the shipped slip-to-roll scenario with the given launch and friction and returns
/// (transition time, rolling speed, spin at the end).
fn slip_roll(v0: f64, w0: f64, mu: f64) -> (f64, f64, f64) {
    let mut sc = shipped("scenarios/slip_to_roll.json");
    sc.apples[0].velocity_m_s = [v0, 0.0, 0.0];
    sc.apples[0].angular_velocity_rad_s = [0.0, w0, 0.0];
    sc.contact.friction = mu;
    let t_roll = ode::slip_to_roll(v0, w0, 0.04, 0.04, mu, 9.81).time_s;
    sc.duration_s = t_roll * 1.5 + 0.01;
    sc.output.sample_interval_s = Some(1e-4);
    let (_, series) = run(&sc);
    let s = series.of(0);
    let slip: Vec<(f64, f64)> = s
        .iter()
        .map(|(t, a)| {
            let lever = a.position.z; // contact point on the plate at z = 0
            (*t, a.velocity.x - lever * a.angular_velocity.y)
        })
        .collect();
    let s0 = slip[0].1;
    let k = slip
        .iter()
        .position(|&(_, v)| v.abs() < 1e-3 * s0.abs() || v.signum() != s0.signum())
        .expect("reaches rolling");
    let (t1, v1) = slip[k - 2];
    let (t2, v2) = slip[k - 1];
    let t_cross = t2 + v2 * (t2 - t1) / (v1 - v2);
    let last = s.last().unwrap().1;
    (t_cross, last.velocity.x, last.angular_velocity.y)
}

fn check(v0: f64, w0: f64, mu: f64) {
    let (t, v, w) = slip_roll(v0, w0, mu);
    let cf = ode::slip_to_roll(v0, w0, 0.04, 0.04, mu, 9.81);
    println!(
        "v0 {v0} w0 {w0} mu {mu}: t {t:.6} (closed form {:.6}), v {v:.6} ({:.6}), w {w:.4}",
        cf.time_s, cf.speed_m_s
    );
    assert_rel("time to rolling", t, cf.time_s, 0.01);
    assert_rel("rolling speed", v, cf.speed_m_s, 0.01);
    let tight = ode::slip_to_roll(v0, w0, 0.04, ode::fig6_lever(), mu, 9.81);
    assert_rel(
        "time to rolling, lever R - u",
        t,
        tight.time_s,
        2.0 * 0.0006e-2,
    );
    // The speed at the end of the run: the stick spring takes up the last of the slip after the
    // transition, which moves the rolling speed by up to 5.1e-5 m/s (docs/transitions.md).
    let dv = (v - tight.speed_m_s).abs();
    println!(
        "rolling speed at the end, lever R - u: {v} against {} ({dv:.2e} m/s)",
        tight.speed_m_s
    );
    assert!(
        dv <= 2.0 * 5.1e-5,
        "rolling speed {v} m/s, closed form {} m/s",
        tight.speed_m_s
    );
}

#[test]
fn from_speed_only_fig7() {
    for v0 in [0.25, 0.5, 1.0] {
        check(v0, 0.0, 0.3);
    }
}

#[test]
fn from_spin_only_fig6() {
    for w in [5.0, 20.0] {
        check(0.0, w, 0.3);
    }
}

#[test]
fn from_speed_and_backspin() {
    check(0.5, -10.0, 0.3);
}
