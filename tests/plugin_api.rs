//! The layer as a library in a user's own rapier world: an apple may be a collider-less body
//! (`add_apple_body`) or a ball collider (`add_apple`), with the same results.

use applesim::contact::Material;
use applesim::layer::{ContactLayer, LayerConfig, SurfaceOptions};
use rapier3d_f64::prelude::*;

/// An apple launched spinning onto a floor and into a resting apple: returns the finished
/// contact events (peak force, duration bits) and the final centres.
fn run(with_colliders: bool) -> (Vec<(u64, u64)>, Vec<[u64; 3]>) {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, 0.0, -9.81);
    world.integration_parameters.num_solver_iterations = 1;
    world.integration_parameters.max_ccd_substeps = 0;
    let dt = 1e-5;
    world.integration_parameters.dt = dt;
    let floor = world
        .colliders
        .insert(ColliderBuilder::new(SharedShape::halfspace(Vector::Z)));
    let mut layer = ContactLayer::new(LayerConfig::default());
    let fruit = layer.add_material(
        "apple",
        Material::from_shear(1.1e6, 0.18, Some(800.0)).unwrap(),
    );
    let steel = layer.add_material(
        "steel",
        Material::from_youngs(2.0736e11, 0.28, None).unwrap(),
    );
    layer.set_default_coefficients(0.3, 0.09, 1000.0);
    let (m, r) = (0.107, 0.04);
    let starts = [
        (
            Vector::new(-0.2, 0.0, 0.06),
            Vector::new(1.0, 0.0, -0.5),
            Vector::new(0.0, 10.0, 0.0),
        ),
        (Vector::new(0.0, 0.0, 0.0399), Vector::ZERO, Vector::ZERO),
    ];
    let mut bodies = Vec::new();
    for (k, (p, v, w)) in starts.into_iter().enumerate() {
        let body = RigidBodyBuilder::dynamic()
            .translation(p)
            .linvel(v)
            .angvel(w)
            .gyroscopic_forces_enabled(false)
            .can_sleep(false);
        let name = format!("a{k}");
        if with_colliders {
            let (bh, ch) = world.insert(body, ColliderBuilder::ball(r).mass(m));
            layer
                .add_apple(&mut world.colliders, ch, fruit, &name)
                .unwrap();
            bodies.push(bh);
        } else {
            let props = MassProperties::new(Vector::ZERO, m, Vector::splat(0.4 * m * r * r));
            let bh = world.bodies.insert(body.additional_mass_properties(props));
            layer
                .add_apple_body(&world.bodies, bh, r, fruit, &name)
                .unwrap();
            bodies.push(bh);
        }
    }
    layer
        .add_surface(
            &mut world.colliders,
            floor,
            SurfaceOptions::hertz("floor", steel),
        )
        .unwrap();
    for step in 0..30_000 {
        let t = step as f64 * dt;
        layer
            .apply_forces(&mut world.bodies, &world.colliders, &world.islands, t, dt)
            .unwrap();
        world.step_with_events(layer.hooks(), &());
    }
    let events = layer
        .finished_events()
        .iter()
        .map(|e| (e.peak_force_n.to_bits(), e.duration_s.unwrap().to_bits()))
        .collect();
    let ends = bodies
        .iter()
        .map(|&b| {
            let p = world.bodies[b].translation();
            [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
        })
        .collect();
    (events, ends)
}

#[test]
fn an_apple_with_a_collider_moves_as_one_without() {
    let (e1, p1) = run(false);
    let (e2, p2) = run(true);
    assert!(
        e1.len() >= 2,
        "the launched apple lands and hits the other: {} events",
        e1.len()
    );
    assert_eq!(e1, e2, "contact events");
    assert_eq!(p1, p2, "final centres");
}
