//! The cost of one spheroid contact against one sphere contact (issue 29: at most 3x).
//!
//! `cargo run --release --example contact_cost [rounds]`
//!
//! The layer's whole work for a step (pose read, detection, the contact law, the loads) is timed
//! with `ContactLayer::apply_forces` alone, on scenes where every apple has exactly one contact:
//!
//! - `surface`: 1000 apples resting on a steel floor, 0.2 m apart (no apple-apple pairs);
//! - `pair`: 500 pairs of touching apples, no surface, pairs 0.3 m apart.
//!
//! rapier does not step. Each scene is measured still (a resting pile's contacts) and turning:
//! before every timed call each apple is turned 0.002 rad about a tilted axis (off the clock; an
//! apple rolling at 20 rad/s with steps of 1e-4 s), rocking back and forth, so that a
//! spheroid's contact moves over its surface and its stiffness is made again every step.
//! Spheres are turned too. The overlap stays about 0.2 mm. Rounds alternate sphere / spheroid (80 x 72 mm,
//! aspect 0.9) so that load changes hit both alike; the figure is the median over rounds of
//! (wall time of 2000 calls) / (contacts x 2000), and the ratio of the medians.

use applesim::contact::spheroid::Spheroid;
use applesim::contact::Material;
use applesim::layer::{ContactLayer, LayerConfig, SurfaceOptions};
use rapier3d_f64::prelude::*;
use std::time::Instant;

const STEPS: usize = 2000;

fn build(spheroid: bool, pairs: bool) -> (PhysicsWorld, ContactLayer, Vec<RigidBodyHandle>, usize) {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, 0.0, -9.81);
    world.integration_parameters.num_solver_iterations = 1;
    world.integration_parameters.dt = 1e-5;
    let config = LayerConfig {
        gravity: world.gravity,
        ..Default::default()
    };
    let mut layer = ContactLayer::new(config);
    let fruit = layer.add_material(
        "apple",
        Material::from_shear(1.1e6, 0.18, Some(800.0)).unwrap(),
    );
    let steel = layer.add_material(
        "steel",
        Material::from_youngs(2.0736e11, 0.28, None).unwrap(),
    );
    layer.set_default_coefficients(0.5, 0.5, 100.0);
    let shape = if spheroid {
        Spheroid::new(0.04, 0.036)
    } else {
        Spheroid::new(0.04, 0.04)
    };
    let mass = 800.0 * shape.volume_m3();
    let (ieq, iax) = shape.principal_inertia(mass);
    let mut bodies = Vec::new();
    let mut add = |world: &mut PhysicsWorld, layer: &mut ContactLayer, p: Vector, k: usize| {
        let b = world.bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(p)
                .additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    mass,
                    Vector::new(ieq, ieq, iax),
                ))
                .gyroscopic_forces_enabled(spheroid)
                .can_sleep(false),
        );
        layer
            .add_spheroid_body(&world.bodies, b, shape, fruit, &format!("a{k}"))
            .unwrap();
        bodies.push(b);
    };
    let contacts = if pairs {
        // Two apples 0.2 mm into each other along x: pole to pole for the spheroids.
        let reach = 2.0 * shape.c - 2e-4;
        for k in 0..500 {
            let base = Vector::new((k % 25) as f64 * 0.3, (k / 25) as f64 * 0.3, 0.5);
            add(&mut world, &mut layer, base, 2 * k);
            add(
                &mut world,
                &mut layer,
                base + Vector::new(0.0, 0.0, reach),
                2 * k + 1,
            );
        }
        500
    } else {
        let floor = world
            .colliders
            .insert(ColliderBuilder::new(SharedShape::halfspace(Vector::Z)));
        layer
            .add_surface(
                &mut world.colliders,
                floor,
                SurfaceOptions::hertz("floor", steel),
            )
            .unwrap();
        for k in 0..1000 {
            let p = Vector::new((k % 40) as f64 * 0.2, (k / 40) as f64 * 0.2, shape.c - 2e-4);
            add(&mut world, &mut layer, p, k);
        }
        1000
    };
    (world, layer, bodies, contacts)
}

/// Nanoseconds per contact per step, the apples turned by `angle` rad every step.
fn measure(spheroid: bool, pairs: bool, angle: f64) -> f64 {
    let (mut world, mut layer, bodies, contacts) = build(spheroid, pairs);
    let turn = Rotation::from_scaled_axis(Vector::new(0.3, 1.0, 0.2).normalize() * angle);
    let turn_back = turn.inverse();
    let mut wall = 0.0;
    for step in 0..STEPS {
        // Rock each apple back and forth (its contact moves; it never rolls away).
        let r = if (step / 50) % 2 == 0 {
            turn
        } else {
            turn_back
        };
        for &b in &bodies {
            let rb = &mut world.bodies[b];
            let rot = r * *rb.rotation();
            rb.set_rotation(rot, false);
        }
        let t = Instant::now();
        layer
            .apply_forces(
                &mut world.bodies,
                &world.colliders,
                &world.islands,
                step as f64 * 1e-5,
                1e-5,
            )
            .unwrap();
        wall += t.elapsed().as_secs_f64();
        assert_eq!(layer.stats().contacts, contacts, "one contact per apple");
    }
    1e9 * wall / (contacts * STEPS) as f64
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let rounds: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(7);
    for (what, pairs, angle) in [
        ("apple-surface, still", false, 0.0),
        ("apple-surface, turning 0.002 rad/step", false, 0.002),
        ("apple-apple, still", true, 0.0),
        ("apple-apple, turning 0.002 rad/step", true, 0.002),
    ] {
        let (mut sph, mut oid) = (Vec::new(), Vec::new());
        for _ in 0..rounds {
            sph.push(measure(false, pairs, angle));
            oid.push(measure(true, pairs, angle));
        }
        let (a, b) = (median(sph.clone()), median(oid.clone()));
        println!(
            "{what}: sphere {a:.1} ns/contact-step, spheroid {b:.1} ns/contact-step, ratio {:.2} (medians of {rounds} alternating rounds; sphere {:?}, spheroid {:?})",
            b / a,
            sph.iter().map(|x| (x * 10.0).round() / 10.0).collect::<Vec<_>>(),
            oid.iter().map(|x| (x * 10.0).round() / 10.0).collect::<Vec<_>>()
        );
    }
}
