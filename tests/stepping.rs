//! Time-step policies, fidelity levels and the stability guard (issue 6).

use crate::common;
use applesim::record::series::NoSamples;
use applesim::scenario::{Accuracy, Fidelity, TimeStep};
use applesim::sim::{SimError, Simulation};
use common::*;

/// The closed forms of physics.md section 4 for the Fig. 1 apple on steel, written in
/// tests/common/ode.rs (not the crate's `theory`).
struct ClosedForm {
    peak_force_n: f64,
    contact_time_s: f64,
}

fn fig1_closed_form(v0: f64) -> ClosedForm {
    let (_, p, t, _) = common::ode::elastic_closed_form(0.107, v0, common::ode::fig1_k(), 0.04);
    ClosedForm {
        peak_force_n: p,
        contact_time_s: t,
    }
}

fn fig1(time_step: TimeStep, accuracy: Option<Accuracy>) -> applesim::sim::RunResult {
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.gravity_m_s2 = [0.0, 0.0, 0.0];
    sc.time_step_s = time_step;
    sc.accuracy = accuracy;
    // Samples every 1 ms: the output interval does not cap the step.
    sc.output.sample_interval_s = Some(1e-3);
    run(&sc).0
}

/// docs/accuracy.md, "Steps per contact against error: one elastic impact": (accuracy, steps in
/// contact, peak force error %, contact time error %) against the closed form of physics.md
/// section 4 (no gravity). Each error is checked within twice the stated figure.
const AUTO_ROWS: [(Accuracy, u64, f64, f64); 3] = [
    (Accuracy::Preview, 10, 0.57, 0.52),
    (Accuracy::Balanced, 20, 0.024, 0.12),
    (Accuracy::Precise, 50, 0.017, 0.020),
];

#[test]
fn auto_at_balanced_meets_half_a_percent_within_40_steps() {
    let r = fig1(TimeStep::Auto, Some(Accuracy::Balanced));
    let e = &r.events[0];
    let cf = fig1_closed_form(1.4);
    println!(
        "auto, balanced: dt {:e} s, {} steps in contact",
        r.time_step_s, e.steps
    );
    assert_eq!(r.step_policy, "auto");
    // Issue 6's acceptance (within 0.5 % with at most 40 steps per contact), at the tolerance of
    // the measured figures docs/accuracy.md states: 0.024 % and 0.12 %, twice each.
    assert!(e.steps <= 40, "{} steps per contact", e.steps);
    assert_rel(
        "peak force",
        e.peak_force_n,
        cf.peak_force_n,
        2.0 * 0.024e-2,
    );
    assert_rel(
        "contact time",
        e.duration_s.unwrap(),
        cf.contact_time_s,
        2.0 * 0.12e-2,
    );
}

#[test]
fn auto_is_refined_by_the_accuracy_target() {
    let cf = fig1_closed_form(1.4);
    let mut last_err = f64::INFINITY;
    for (acc, steps, peak, time) in AUTO_ROWS {
        let r = fig1(TimeStep::Auto, Some(acc));
        let e = &r.events[0];
        let err = rel(e.peak_force_n, cf.peak_force_n);
        println!(
            "{acc:?}: {} steps in contact, peak force error {:.4} %, contact time error {:.4} %",
            e.steps,
            100.0 * err,
            100.0 * rel(e.duration_s.unwrap(), cf.contact_time_s)
        );
        assert_eq!(e.steps, steps, "{acc:?}: steps in contact");
        // docs/accuracy.md: `auto` is one fixed step, t_H / N of the stiffest impact the scene can
        // produce (here the apple's own 1.4 m/s: no gravity, no other body).
        assert_rel(
            "auto step = t_H / N",
            r.time_step_s,
            cf.contact_time_s / acc.steps_per_contact(),
            1e-9,
        );
        assert!(e.steps as f64 >= acc.steps_per_contact() * 0.95);
        assert_rel(
            "peak force",
            e.peak_force_n,
            cf.peak_force_n,
            2.0 * peak / 100.0,
        );
        assert_rel(
            "contact time",
            e.duration_s.unwrap(),
            cf.contact_time_s,
            2.0 * time / 100.0,
        );
        assert!(err < last_err + 1e-6, "finer steps are not more accurate");
        last_err = err;
    }
}

#[test]
fn adaptive_matches_the_closed_form_with_few_steps() {
    let r = fig1(TimeStep::Adaptive, Some(Accuracy::Balanced));
    let e = &r.events[0];
    let cf = fig1_closed_form(1.4);
    println!(
        "adaptive: {} steps in all, {} in contact, steps {:?} s",
        r.steps, e.steps, r.step_range_s
    );
    assert_eq!(r.step_policy, "adaptive");
    // docs/accuracy.md: 46 steps in the run, 20 in contact, peak force within 0.028 %, contact
    // time 0.14 %, rebound 0.07 %; checked at twice each.
    assert_eq!((r.steps, e.steps), (46, 20), "steps in all, in contact");
    assert_rel(
        "peak force",
        e.peak_force_n,
        cf.peak_force_n,
        2.0 * 0.028e-2,
    );
    assert_rel(
        "contact time",
        e.duration_s.unwrap(),
        cf.contact_time_s,
        2.0 * 0.14e-2,
    );
    assert_rel(
        "rebound",
        e.separation_speed_m_s.unwrap(),
        1.4,
        2.0 * 0.07e-2,
    );
    // Free flight at the largest step (1 ms, the sample interval), impacts at the resolving one;
    // the last steps divide the time left to the end evenly (0.984 ms).
    assert!(r.step_range_s[1] >= 0.98e-3, "{:?}", r.step_range_s);
}

/// The Fig. 1 apple touching the plate at `phase` of a step after t = step (no gravity), at
/// fixed steps of t_H / n.
fn fixed_fraction(n: f64, phase: f64) -> applesim::record::events::ContactEvent {
    let v0 = 1.4;
    let h = fig1_closed_form(v0).contact_time_s / n;
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.gravity_m_s2 = [0.0, 0.0, 0.0];
    sc.apples[0].position_m = [0.0, 0.0, 0.04 + (1.0 + phase) * h * v0];
    sc.apples[0].velocity_m_s = [0.0, 0.0, -v0];
    sc.time_step_s = TimeStep::Fixed(h);
    sc.model.min_steps_per_impact = 5.0;
    sc.output.sample_interval_s = Some(0.01);
    run(&sc).0.events[0].clone()
}

/// physics.md section 10: symplectic Euler on one elastic impact, 10 steps per contact give
/// 0.9 % error in P_max, 20 steps 0.2 %, 40 steps 0.05 % (touch on a step). Checked at twice
/// each, against the closed form of section 4.
#[test]
fn peak_force_error_per_steps_per_contact_as_physics_md_states() {
    let cf = fig1_closed_form(1.4);
    for (n, stated) in [(10.0, 0.9), (20.0, 0.2), (40.0, 0.05)] {
        let e = fixed_fraction(n, 0.0);
        assert_rel(
            &format!("peak force at {n} steps per contact"),
            e.peak_force_n,
            cf.peak_force_n,
            2.0 * stated / 100.0,
        );
    }
}

/// docs/accuracy.md: where the steps fall on the pulse moves the peak force error, over the
/// touch's phase within a step from -1.3 % to +0.9 % at N = 10 and from -0.34 % to +0.20 % at
/// N = 20 (20 phases). Checked: every phase within twice the stated bound on its side.
#[test]
fn peak_force_error_over_the_phase_of_the_touch() {
    let cf = fig1_closed_form(1.4);
    for (n, low, high) in [(10.0, -1.3, 0.9), (20.0, -0.34, 0.20)] {
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        for j in 0..20 {
            let e = fixed_fraction(n, j as f64 / 20.0);
            let err = 100.0 * (e.peak_force_n / cf.peak_force_n - 1.0);
            lo = lo.min(err);
            hi = hi.max(err);
        }
        println!("N = {n}: peak force error from {lo:+.3} % to {hi:+.3} % over the phase");
        assert!(
            lo >= 2.0 * low && hi <= 2.0 * high,
            "N = {n}: {lo} .. {hi} %"
        );
        // The stated range is the measured one: both ends are reached (within half the bound).
        assert!(
            lo <= 0.5 * low && hi >= 0.5 * high,
            "N = {n}: {lo} .. {hi} %"
        );
    }
}

#[test]
fn fidelity_levels_do_what_they_say() {
    let mut sc = shipped("scenarios/slip_to_roll.json");
    sc.duration_s = 0.1;
    // rigid: rapier's own contact, nothing recorded, but the apple still moves and stays up.
    sc.fidelity = Fidelity::Rigid;
    let (r, s) = run(&sc);
    assert!(r.events.is_empty());
    let last = s.of(0).last().unwrap().1.clone();
    assert!(
        last.position.x > 0.02 && last.position.z > 0.035,
        "{last:?}"
    );
    // hertz: elastic, so a drop comes back at its approach speed whatever ke says.
    let mut d = shipped("scenarios/drop_on_steel.json");
    d.contact.ke = Some(0.09);
    d.gravity_m_s2 = [0.0; 3];
    d.fidelity = Fidelity::Hertz;
    let (r, _) = run(&d);
    // Restitution 1 (README): measured within 5e-8 (docs/claims.md; docs/design.md's closed
    // forms hold to 1e-6), checked at twice that.
    assert_rel(
        "hertz: rebound",
        r.events[0].restitution.unwrap(),
        1.0,
        1e-7,
    );
    d.fidelity = Fidelity::HertzDamped;
    let (r, _) = run(&d);
    assert!(r.events[0].restitution.unwrap() < 0.32);
    // full: the eq. 9 patch shift moves the point where the normal force acts, which changes the
    // moments while the apple slides (a small effect: about 1e-4 on the rolling speed; its size
    // against a closed form is tests/patch_shift.rs).
    sc.fidelity = Fidelity::HertzDamped;
    let (_, a) = run(&sc);
    sc.fidelity = Fidelity::Full;
    let (_, b) = run(&sc);
    let (va, vb) = (
        a.of(0).last().unwrap().1.velocity.x,
        b.of(0).last().unwrap().1.velocity.x,
    );
    println!("rolling speed: hertz-damped {va}, full {vb}");
    assert!(vb != va, "the patch shift changed nothing");
}

#[test]
fn the_guard_refuses_a_run_that_blows_up() {
    // An apple resting on steel at a step far beyond its contact's stability (omega dt ~ 3),
    // with the steps-per-impact check switched off: only the energy or overlap guard is left.
    let mut sc = shipped("scenarios/slip_to_roll.json");
    sc.apples[0].velocity_m_s = [0.0; 3];
    sc.time_step_s = TimeStep::Fixed(8e-3);
    sc.duration_s = 2.0;
    sc.model.min_steps_per_impact = 0.0;
    sc.model.sleep.enabled = false;
    let sim = Simulation::new(&sc, &repo("scenarios")).unwrap();
    let err = sim.run(&mut NoSamples, &mut |_| {}).unwrap_err();
    println!("{err}");
    let msg = err.to_string();
    assert!(msg.contains("unstable"), "{msg}");
    assert!(
        matches!(err, SimError::EnergyRise { .. } | SimError::Layer(_)),
        "{err:?}"
    );
}

#[test]
fn too_many_steps_are_refused() {
    // A fixed step: the count is known, the run is refused before it starts (0.03 s in steps of
    // 1e-5 s is 3000 steps).
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.model.max_steps = 1000;
    let err = Simulation::new(&sc, &repo("scenarios"))
        .err()
        .expect("refused before it starts");
    let msg = err.to_string();
    assert!(msg.contains("model.max_steps = 1000"), "{msg}");
    assert!(msg.contains("3.000e3 steps"), "{msg}");
    // Adaptive steps: the estimate (0.03 s in steps of at most 1 ms, 30) passes, the run takes
    // more (the impact is resolved in 20 steps per contact time) and is stopped while running.
    sc.time_step_s = TimeStep::Adaptive;
    sc.output.sample_interval_s = Some(1e-3);
    sc.model.max_steps = 35;
    let sim = Simulation::new(&sc, &repo("scenarios")).unwrap();
    let err = sim.run(&mut NoSamples, &mut |_| {}).unwrap_err();
    assert!(matches!(err, SimError::TooManySteps { .. }), "{err:?}");
    assert!(err.to_string().contains("model.max_steps = 35"), "{err}");
}

/// Regression (adaptive steps): an apple dropped from rest lands after a few long free-flight
/// steps. The step onto the plate must end near the touch (rapier moves a body by its velocity
/// after gravity's kick, so the gap closes sooner than at the current speed), the first contact
/// force must be kicked only over the contact's age, and the approach speed must be the one of
/// the touch, not the staggered mid-step velocity. Before the fix: approach speed 6 % low and
/// peak force 3.6 % low on a belt landing.
#[test]
fn adaptive_landing_after_free_fall_matches_a_fine_fixed_step() {
    let drop = |time_step: TimeStep| {
        let mut sc = shipped("scenarios/drop_on_steel.json");
        // Radius 40 mm; from rest 6 mm above the plate: v = sqrt(2 g h) = 0.343 m/s.
        sc.apples[0].position_m = [0.0, 0.0, 0.046];
        sc.apples[0].velocity_m_s = [0.0, 0.0, 0.0];
        sc.duration_s = 0.06;
        sc.time_step_s = time_step;
        sc.accuracy = Some(Accuracy::Balanced);
        sc.output.sample_interval_s = Some(0.01);
        run(&sc).0
    };
    let fine = drop(TimeStep::Fixed(1e-6));
    let adaptive = drop(TimeStep::Adaptive);
    let (f, a) = (&fine.events[0], &adaptive.events[0]);
    println!(
        "fine: approach {:.5} m/s peak {:.4} N; adaptive ({} steps, {:?}): approach {:.5} m/s peak {:.4} N, {} steps in contact",
        f.approach_speed_m_s,
        f.peak_force_n,
        adaptive.steps,
        adaptive.step_range_s,
        a.approach_speed_m_s,
        a.peak_force_n,
        a.steps
    );
    let v = (2.0 * 9.81 * 0.006_f64).sqrt();
    assert_rel("fine approach speed", f.approach_speed_m_s, v, 0.001);
    assert_rel(
        "approach speed",
        a.approach_speed_m_s,
        f.approach_speed_m_s,
        0.005,
    );
    // A peak sampled at 20 steps per contact: within 1 % of the fine step's.
    assert_rel("peak force", a.peak_force_n, f.peak_force_n, 0.01);
    assert!(
        adaptive.step_range_s[1] > 2e-3,
        "{:?}",
        adaptive.step_range_s
    );
}

/// `applesim bench` says what set an adaptive run's steps (docs/accuracy.md, "What sets the
/// steps"): on the Fig. 1 drop at `balanced` (no gravity), the 20 steps in contact are the
/// impact's (N = 20 per elastic contact time, the closed form of physics.md section 10), the
/// free flight before and after is stepped by the driver's cap (growth by at most 2x a step, the
/// largest step) or a pair about to touch, and every step is counted once. A fixed step is all
/// the driver's.
#[test]
fn bench_counts_what_set_each_step() {
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.gravity_m_s2 = [0.0, 0.0, 0.0];
    sc.time_step_s = TimeStep::Adaptive;
    sc.accuracy = Some(Accuracy::Balanced);
    sc.output.sample_interval_s = Some(1e-3);
    let r = applesim::bench::run(&sc, std::path::Path::new("scenarios"), &[]).unwrap();
    let w = &r.windows[0];
    let by = w.steps_set_by;
    println!("{} steps: {by:?}, {}", w.steps, by.describe(w.steps));
    assert_eq!(w.steps, 46);
    assert_eq!(
        by.impact + by.resting + by.approaching + by.motion + by.driver,
        w.steps
    );
    assert_eq!(by.impact, 20, "the steps in contact");
    assert_eq!(by.resting + by.motion, 0);
    let mean = w.mean_step_s.unwrap();
    assert!(
        (mean * 46.0 - sc.duration_s).abs() < 1e-12,
        "mean step {mean}"
    );

    sc.time_step_s = TimeStep::Fixed(1e-4);
    let r = applesim::bench::run(&sc, std::path::Path::new("scenarios"), &[]).unwrap();
    let w = &r.windows[0];
    assert_eq!(w.steps_set_by.driver, w.steps);
    assert_eq!(w.steps_set_by.describe(w.steps), "driver 100 %");
}
