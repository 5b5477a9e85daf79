//! rapier's own cost per body and step, without any contact: the floor under applesim's cost per
//! apple-step (docs/performance.md). Dynamic balls at rest in free fall, num_solver_iterations = 1,
//! CCD off, rapier's sleeping off, dt = 1e-4 s, one thread (or rayon's pool with the
//! `rapier-parallel` feature):
//!
//! ```sh
//! cargo bench --bench rapier_floor
//! cargo bench --bench rapier_floor --features rapier-parallel   # RAYON_NUM_THREADS=1 or 2
//! ```
//!
//! Last, the split of issue 30 item 2 (`World::split_apples`): 1000 collider-less bodies with
//! forces, in 1, 2 or 4 worlds stepped concurrently on rayon's pool (run inside a pool, as
//! applesim runs), each checked bit for bit against the same bodies stepped in one world.
//!
//! Variants: bodies without colliders (as applesim's apples), the same with gyroscopic forces off
//! (applesim: a ball's w x (I w) is zero), with a force set through `get_mut` every step (what the
//! layer does), and with a ball collider in a group that meets nothing (the earlier design).

use rapier3d_f64::prelude::*;
use std::time::Instant;

fn run(variant: &str, n: usize, steps: usize) {
    let mut w = PhysicsWorld::new();
    w.gravity = Vector::new(0.0, 0.0, -9.81);
    w.integration_parameters.num_solver_iterations = 1;
    w.integration_parameters.max_ccd_substeps = 0;
    w.integration_parameters.dt = 1e-4;
    let side = (n as f64).sqrt().ceil() as usize;
    let collider = variant.starts_with("collider");
    let mut handles = Vec::new();
    for k in 0..n {
        let p = Vector::new(
            (k % side) as f64 * 0.1,
            ((k / side) % side) as f64 * 0.1,
            100.0 + (k / (side * side)) as f64 * 0.1,
        );
        let body = RigidBodyBuilder::dynamic()
            .translation(p)
            .can_sleep(false)
            .gyroscopic_forces_enabled(!variant.contains("no gyro"));
        let h = if collider {
            let groups = InteractionGroups::new(
                Group::GROUP_32,
                Group::ALL & !Group::GROUP_32,
                InteractionTestMode::And,
            );
            let ball = ColliderBuilder::ball(0.04)
                .density(800.0)
                .collision_groups(groups);
            w.insert(body, ball).0
        } else {
            let props = MassProperties::from_ball(800.0, 0.04);
            w.bodies.insert(body.additional_mass_properties(props))
        };
        handles.push(h);
    }
    let forced = variant.contains("force");
    let clock = Instant::now();
    for _ in 0..steps {
        if forced {
            for &h in &handles {
                let rb = w.bodies.get_mut(h).expect("body");
                rb.reset_forces(false);
                rb.add_force(Vector::new(0.0, 0.0, 1e-3), false);
            }
        }
        w.step_with_events(&(), &());
    }
    let wall = clock.elapsed().as_secs_f64();
    println!(
        "{variant:34} {n:5} bodies: {:.3} us per body-step ({:.3e} body-steps/s)",
        wall * 1e6 / (n * steps) as f64,
        (n * steps) as f64 / wall
    );
}

/// The bodies split over `sets` rapier worlds of their own (no colliders), stepped concurrently
/// on rayon's pool as `World::advance` does. Checks every pose and velocity against the same
/// bodies stepped in one world, bit for bit.
fn split(n: usize, steps: usize, sets: usize) {
    use rayon::prelude::*;
    let build = |count: usize, first: usize| {
        let mut w = PhysicsWorld::new();
        w.gravity = Vector::new(0.0, 0.0, -9.81);
        w.integration_parameters.num_solver_iterations = 1;
        w.integration_parameters.max_ccd_substeps = 0;
        w.integration_parameters.dt = 1e-4;
        let mut handles = Vec::new();
        for k in first..first + count {
            let body = RigidBodyBuilder::dynamic()
                .translation(Vector::new(k as f64 * 0.1, 0.0, 100.0))
                .linvel(Vector::new(0.0, 0.01 * k as f64, 0.0))
                .angvel(Vector::new(0.1, 0.0, 0.02 * k as f64))
                .can_sleep(false)
                .gyroscopic_forces_enabled(false);
            let props = MassProperties::from_ball(800.0, 0.04);
            handles.push(w.bodies.insert(body.additional_mass_properties(props)));
        }
        (w, handles)
    };
    // A force that differs per body and step, set through `get_mut` as the layer does.
    let force = |w: &mut PhysicsWorld, hs: &[RigidBodyHandle], first: usize, step: usize| {
        for (j, &h) in hs.iter().enumerate() {
            let rb = w.bodies.get_mut(h).expect("body");
            rb.reset_forces(false);
            let f = 1e-3 * ((first + j + step) % 7) as f64;
            rb.add_force(Vector::new(f, 0.0, 1e-3), false);
        }
    };
    let per = n / sets;
    let mut parts: Vec<_> = (0..sets).map(|s| build(per, s * per)).collect();
    let clock = Instant::now();
    for step in 0..steps {
        parts.par_iter_mut().enumerate().for_each(|(s, (w, hs))| {
            force(w, hs, s * per, step);
            w.step_with_events(&(), &());
        });
    }
    let wall = clock.elapsed().as_secs_f64();
    let (mut one, hs) = build(per * sets, 0);
    for step in 0..steps {
        force(&mut one, &hs, 0, step);
        one.step_with_events(&(), &());
    }
    let same = parts.iter().enumerate().all(|(s, (w, part))| {
        part.iter().enumerate().all(|(j, &h)| {
            let (a, b) = (&w.bodies[h], &one.bodies[hs[s * per + j]]);
            a.position() == b.position() && a.linvel() == b.linvel() && a.angvel() == b.angvel()
        })
    });
    println!(
        "split: {sets} set(s) of {per} bodies, {} thread(s): {:.3} us per body-step; the same bits as one set: {same}",
        rayon::current_num_threads(),
        wall * 1e6 / (n * steps) as f64,
    );
}

fn main() {
    for v in [
        "no collider",
        "no collider, no gyro",
        "no collider, no gyro, force",
        "collider",
        "collider, force",
    ] {
        run(v, 1000, 3000);
    }
    run("no collider, no gyro, force", 8000, 400);
    run("collider, force", 8000, 400);
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            for sets in [1, 2, 4, 1, 2, 4] {
                split(1000, 3000, sets);
            }
        });
    }
}
