//! Elastic Hertz impacts against the closed forms of physics.md section 4 (issue 2 acceptance).
//! Tolerance: 0.5 % on peak force, contact time and max overlap, 0.1 % on the rebound speed,
//! at the shipped time step (1e-5 s), without gravity.

mod common;
use applesim::contact::{material::effective_modulus, normal, theory, Material};
use common::*;

fn fig1_apple_on_steel(v0: f64) {
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.gravity_m_s2 = [0.0, 0.0, 0.0];
    sc.apples[0].velocity_m_s = [0.0, 0.0, -v0];
    let (r, _) = run(&sc);
    assert_eq!(r.events.len(), 1, "one impact");
    let e = &r.events[0];
    let apple = Material::from_shear(1.1e6, 0.18, None).unwrap();
    let steel = Material::from_shear(8.1e10, 0.28, None).unwrap();
    let k = normal::stiffness(effective_modulus(&apple, &steel), 0.04);
    let cf = theory::elastic_impact(0.107, v0, k, 0.04);
    assert_rel("peak force", e.peak_force_n, cf.peak_force_n, 0.005);
    assert_rel(
        "contact time",
        e.duration_s.unwrap(),
        cf.contact_time_s,
        0.005,
    );
    assert_rel("max overlap", e.max_overlap_m, cf.max_overlap_m, 0.005);
    assert_rel(
        "max contact radius",
        e.max_contact_radius_m,
        cf.max_contact_radius_m,
        0.005,
    );
    assert_rel("rebound speed", e.separation_speed_m_s.unwrap(), v0, 0.001);
    assert_rel("impulse", e.impulse_n_s, 2.0 * 0.107 * v0, 0.001);
}

#[test]
fn fig1_apple_on_steel_at_0_2_m_s() {
    fig1_apple_on_steel(0.2);
}

#[test]
fn fig1_apple_on_steel_at_1_4_m_s() {
    fig1_apple_on_steel(1.4);
}

#[test]
fn two_equal_apples_head_on() {
    let sc = shipped("scenarios/two_apples_head_on.json");
    let (r, _) = run(&sc);
    assert_eq!(r.events.len(), 1);
    let e = &r.events[0];
    let apple = Material::from_shear(1.1e6, 0.18, None).unwrap();
    let m = applesim::world::sphere_mass(0.08, 800.0);
    let m_star = theory::reduced_mass(m, m);
    let r_star = 0.02;
    let k = normal::stiffness(effective_modulus(&apple, &apple), r_star);
    let cf = theory::elastic_impact(m_star, 1.0, k, r_star);
    assert_rel("peak force", e.peak_force_n, cf.peak_force_n, 0.005);
    assert_rel(
        "contact time",
        e.duration_s.unwrap(),
        cf.contact_time_s,
        0.005,
    );
    assert_rel("max overlap", e.max_overlap_m, cf.max_overlap_m, 0.005);
    assert_rel(
        "relative rebound speed",
        e.separation_speed_m_s.unwrap(),
        1.0,
        0.001,
    );
    // Each apple leaves with the other's speed, momentum conserved.
    let left = &r.apples[0];
    assert_rel("left final speed", -left.final_velocity_m_s[0], 0.5, 0.001);
}

#[test]
fn force_never_pulls() {
    // Strong hysteresis: the unloading force is small but never negative at any step.
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.gravity_m_s2 = [0.0, 0.0, 0.0];
    sc.contact.ke = 0.01;
    sc.contact.lambda_s_m = 10.0;
    sc.output.sample_interval_s = 1e-5;
    let (_, series) = run(&sc);
    let mut touched = false;
    for (_, s) in series.of(0) {
        assert!(
            s.contact_force.z >= 0.0,
            "pulling force {}",
            s.contact_force.z
        );
        touched |= s.contact_force.z > 0.0;
    }
    assert!(touched);
}
