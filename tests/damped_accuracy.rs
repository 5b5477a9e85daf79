//! The damped model (eq. 12 with ke = 0.09, lambda = 1000 s/m: the paper's apple restitution) at
//! fixed steps of t_H / N and at the `auto` and `adaptive` policies, against an independent RK4
//! integration of m u'' = m g - P(u, u') (tests/common/ode.rs: it calls nothing of the crate).
//! The figures are those of docs/accuracy.md ("Steps per contact against error: eq. 12"); each
//! error is checked to lie within twice the figure stated there, and the steps in contact exactly.

use crate::common;
use applesim::scenario::{Accuracy, TimeStep};
use common::ode::{self, Setup};
use common::*;

const M: f64 = 0.107;
const R: f64 = 0.04;
const KE: f64 = 0.09;
const LAMBDA: f64 = 1000.0;

/// The Fig. 1 apple on steel with eq. 12, gravity `g` (0 or 9.81) into the plate.
fn reference(g: f64) -> Setup {
    Setup {
        mass_kg: M,
        k: ode::fig1_k(),
        r_star_m: R,
        ke: KE,
        lambda_s_m: LAMBDA,
        g_n: g,
    }
}

/// Elastic contact time at v0 (physics.md section 4), the unit of the fixed steps t_H / N.
fn t_h(v0: f64) -> f64 {
    let u_max = (5.0 * M * v0 * v0 / (4.0 * ode::fig1_k())).powf(0.4);
    2.0 * 1.471_637_6 * u_max / v0
}

/// The shipped Fig. 1 drop at `v0` with ke = 0.09, touching the plate at t = 0.
fn drop(
    v0: f64,
    gravity: bool,
    step: TimeStep,
    accuracy: Option<Accuracy>,
) -> applesim::sim::RunResult {
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.contact.ke = Some(KE);
    sc.contact.lambda_s_m = Some(LAMBDA);
    sc.apples[0].position_m = [0.0, 0.0, R];
    sc.apples[0].velocity_m_s = [0.0, 0.0, -v0];
    if !gravity {
        sc.gravity_m_s2 = [0.0; 3];
    }
    sc.time_step_s = step;
    sc.accuracy = accuracy;
    sc.duration_s = 0.04;
    sc.output.sample_interval_s = Some(0.01);
    sc.output.force_history = Some(false.into());
    // t_H / 10 is at the guard's default limit: let the N = 10 row run.
    sc.model.min_steps_per_impact = 5.0;
    sc.model.sleep.enabled = false;
    run(&sc).0
}

/// A row of docs/accuracy.md: the case, the steps in contact, and the stated errors (%) of the
/// peak force, the contact time and the restitution against the RK4 reference.
struct Row {
    label: &'static str,
    steps: u64,
    peak: f64,
    time: f64,
    restitution: f64,
}

fn check(r: &applesim::sim::RunResult, want: &ode::Impact, v0: f64, row: &Row) {
    let e = &r.events[0];
    let t_want = want.contact_time_s.unwrap();
    let e_want = want.rebound_m_s.unwrap() / v0;
    println!(
        "{}: {} steps in contact (stated {})",
        row.label, e.steps, row.steps
    );
    // Each error within twice the stated one (docs/accuracy.md); the reference is RK4.
    assert_ref(
        &format!("{}: peak force", row.label),
        e.peak_force_n,
        want.peak_force_n,
        2.0 * row.peak.abs() / 100.0,
        "RK4",
    );
    assert_ref(
        &format!("{}: contact time", row.label),
        e.duration_s.unwrap(),
        t_want,
        2.0 * row.time.abs() / 100.0,
        "RK4",
    );
    assert_ref(
        &format!("{}: restitution", row.label),
        e.restitution.unwrap(),
        e_want,
        2.0 * row.restitution.abs() / 100.0,
        "RK4",
    );
    assert_eq!(e.steps, row.steps, "{}: steps in contact", row.label);
}

/// docs/accuracy.md, first table: v0 = 0.79 m/s, no gravity, fixed steps t_H / N.
#[test]
fn fixed_steps_against_rk4_without_gravity() {
    let v0 = 0.79;
    let want = reference(0.0).impact(v0, 0.1);
    println!("RK4: {want:?}");
    // The RK4 reference itself against physics.md section 3 (no gravity, lambda v0 = 790 >> 1:
    // e = sqrt(ke) = 0.3 to the table's three digits).
    assert!((want.rebound_m_s.unwrap() / v0 - 0.3).abs() < 5e-4);
    let rows = [
        (
            10.0,
            Row {
                label: "t_H/10",
                steps: 17,
                peak: -6.790,
                time: -18.610,
                restitution: 10.187,
            },
        ),
        (
            20.0,
            Row {
                label: "t_H/20",
                steps: 39,
                peak: -1.769,
                time: -9.568,
                restitution: 2.714,
            },
        ),
        (
            50.0,
            Row {
                label: "t_H/50",
                steps: 104,
                peak: -0.287,
                time: -3.731,
                restitution: 0.446,
            },
        ),
        (
            100.0,
            Row {
                label: "t_H/100",
                steps: 212,
                peak: -0.069,
                time: -1.756,
                restitution: 0.110,
            },
        ),
        (
            1000.0,
            Row {
                label: "t_H/1000",
                steps: 2162,
                peak: 0.0005,
                time: 0.022,
                restitution: -0.0007,
            },
        ),
    ];
    for (n, row) in rows {
        let r = drop(v0, false, TimeStep::Fixed(t_h(v0) / n), None);
        check(&r, &want, v0, &row);
    }
}

/// docs/accuracy.md, second table: the shipped drop (1.4 m/s, gravity) with ke = 0.09 at the
/// `auto` and `adaptive` policies of each accuracy level.
#[test]
fn auto_and_adaptive_against_rk4_with_gravity() {
    let v0 = 1.4;
    let want = reference(9.81).impact(v0, 0.1);
    println!("RK4: {want:?}");
    // The RK4 reference against physics.md section 8 (the loading is elastic Hertz up to the
    // turn: 99.97 N with gravity at 1.4 m/s).
    assert!(
        (want.peak_force_n - 99.97).abs() < 0.01,
        "{}",
        want.peak_force_n
    );
    let rows = [
        (
            TimeStep::Auto,
            Accuracy::Preview,
            Row {
                label: "auto, preview",
                steps: 25,
                peak: -0.873,
                time: -0.460,
                restitution: -0.852,
            },
        ),
        (
            TimeStep::Auto,
            Accuracy::Balanced,
            Row {
                label: "auto, balanced",
                steps: 46,
                peak: 0.262,
                time: -9.981,
                restitution: 3.050,
            },
        ),
        (
            TimeStep::Auto,
            Accuracy::Precise,
            Row {
                label: "auto, precise",
                steps: 126,
                peak: -0.064,
                time: -1.414,
                restitution: 0.046,
            },
        ),
        (
            TimeStep::Adaptive,
            Accuracy::Preview,
            Row {
                label: "adaptive, preview",
                steps: 10,
                peak: 0.839,
                time: -19.940,
                restitution: 11.867,
            },
        ),
        (
            TimeStep::Adaptive,
            Accuracy::Balanced,
            Row {
                label: "adaptive, balanced",
                steps: 20,
                peak: 0.184,
                time: -9.270,
                restitution: 3.500,
            },
        ),
        (
            TimeStep::Adaptive,
            Accuracy::Precise,
            Row {
                label: "adaptive, precise",
                steps: 52,
                peak: 0.010,
                time: -2.170,
                restitution: 0.459,
            },
        ),
    ];
    for (step, acc, row) in rows {
        let r = drop(v0, true, step, Some(acc));
        check(&r, &want, v0, &row);
    }
}

/// physics.md section 3: for lambda v0 >> 1 the contact lasts t_c = t_H / 2 (1 + 1/sqrt(ke)),
/// peaks at tau = 1 / (1 + 1/sqrt(ke)) of it, with P_max unchanged (the elastic one). Measured at
/// lambda v0 = 1e4, no gravity, dt = 1e-5 s: docs/physics.md ("How applesim implements this
/// reference") states the agreement; checked at twice each figure.
#[test]
fn sqrt_ke_limit_of_contact_time_and_peak() {
    let v0 = 1.0;
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.contact.ke = Some(KE);
    sc.contact.lambda_s_m = Some(1e4);
    sc.apples[0].position_m = [0.0, 0.0, R];
    sc.apples[0].velocity_m_s = [0.0, 0.0, -v0];
    sc.gravity_m_s2 = [0.0; 3];
    sc.duration_s = 0.04;
    sc.model.sleep.enabled = false;
    let e = run(&sc).0.events[0].clone();
    let (_, p_max, t_h, _) = ode::elastic_closed_form(M, v0, ode::fig1_k(), R);
    let t_c = 0.5 * t_h * (1.0 + 1.0 / KE.sqrt());
    let tau = 1.0 / (1.0 + 1.0 / KE.sqrt());
    let t = e.duration_s.unwrap();
    assert_ref("contact time", t, t_c, 2.0 * 0.05e-2, "closed form");
    assert_ref(
        "peak force",
        e.peak_force_n,
        p_max,
        2.0 * 0.001e-2,
        "closed form",
    );
    assert_ref(
        "tau",
        (e.t_peak_s - e.t_start_s) / t,
        tau,
        2.0 * 0.15e-2,
        "closed form",
    );
}
