//! Spheroidal apples against closed forms (issue 29; docs/shape.md): an 80 mm x 72 mm apple
//! (a = 40 mm equatorial radius, c = 36 mm polar half-height) through the layer's library API,
//! as a rapier user attaches it.
//!
//! Closed forms, written here:
//! - Elastic impact of mass m at v on a Hertz contact of stiffness k = 4/3 E* sqrt(R_k):
//!   u_max = (5 m v^2 / (4 k))^(2/5), P_max = k u_max^(3/2), t_H = 2 x 1.4716 u_max / v
//!   (physics.md section 4). On the pole R_k = a^2/c (circular); on the cheek R' = a (along the
//!   equator), R'' = c^2/a (along the meridian), R_k from the elliptic law (Johnson 4.2, by the
//!   exact solve `contact::elliptic::elliptic_hertz`). P_max scales as R_k^(1/5) at equal m, v:
//!   the pole-to-cheek ratio is (R_pole / R_k,cheek)^(1/5).
//! - Rest under gravity: k u^(3/2) = m g, or with eq. 12 at rest (1 + ke)/2 k u^(3/2) = m g
//!   (docs/physics.md 11.2).
//! - Rocking without slip about a resting pose with curvature radius rho at the contact and the
//!   centre at height h above it: omega^2 = m g (rho - h) / (I + m h^2) (small angles; the
//!   instantaneous axis is the contact line, the centre rises by (rho - h) theta^2 / 2).
//! - A body rolling about its own axis of symmetry on its equator (lever a, I = 2/5 m a^2),
//!   launched sliding without spin: it ends rolling at v0 / (1 + I/(m a^2)) = 5/7 v0.

use crate::common;
use applesim::contact::elliptic::elliptic_hertz;
use applesim::contact::spheroid::Spheroid;
use applesim::contact::Material;
use applesim::layer::{ContactLayer, LayerConfig, SurfaceOptions};
use common::ode;
use rapier3d_f64::prelude::*;

const A: f64 = 0.040;
const C: f64 = 0.036;
const DENSITY: f64 = 800.0;

fn steel() -> Material {
    Material::from_youngs(2.0736e11, 0.28, None).unwrap()
}

fn apple() -> Material {
    Material::from_shear(1.1e6, 0.18, Some(DENSITY)).unwrap()
}

fn e_star() -> f64 {
    let (a, s) = (apple(), steel());
    let (na, ns) = (a.poisson_ratio, s.poisson_ratio);
    1.0 / ((1.0 - na * na) / a.youngs_modulus_pa + (1.0 - ns * ns) / s.youngs_modulus_pa)
}

struct Scene {
    world: PhysicsWorld,
    layer: ContactLayer,
    body: RigidBodyHandle,
    mass: f64,
}

/// A rapier world stepped as the layer needs it: exact symplectic Euler (one solver
/// iteration), no CCD sub-steps.
fn physics_world(gravity: f64, dt: f64) -> PhysicsWorld {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, 0.0, -gravity);
    world.integration_parameters.num_solver_iterations = 1;
    world.integration_parameters.max_ccd_substeps = 0;
    world.integration_parameters.dt = dt;
    world
}

/// A spheroid's rigid body: its mass at DENSITY, its principal inertia, gyroscopic forces on.
fn spheroid_body(shape: &Spheroid, pose: Pose, vel: Vector, angvel: Vector) -> RigidBodyBuilder {
    let mass = DENSITY * shape.volume_m3();
    let (ieq, iax) = shape.principal_inertia(mass);
    RigidBodyBuilder::dynamic()
        .pose(pose)
        .linvel(vel)
        .angvel(angvel)
        .additional_mass_properties(MassProperties::new(
            Vector::ZERO,
            mass,
            Vector::new(ieq, ieq, iax),
        ))
        .gyroscopic_forces_enabled(true)
        .can_sleep(false)
}

/// A spheroid on a steel half-space z = 0, turned by `rot` (its frame to the world's).
#[allow(clippy::too_many_arguments)]
fn scene(
    shape: Spheroid,
    rot: Rotation,
    pos: Vector,
    vel: Vector,
    angvel: Vector,
    gravity: f64,
    dt: f64,
    config: LayerConfig,
    friction: f64,
    ke: f64,
) -> Scene {
    let mut world = physics_world(gravity, dt);
    let floor = world
        .colliders
        .insert(ColliderBuilder::new(SharedShape::halfspace(Vector::Z)));
    let mass = DENSITY * shape.volume_m3();
    let body = world.bodies.insert(spheroid_body(
        &shape,
        Pose::from_parts(pos, rot),
        vel,
        angvel,
    ));
    let mut layer = ContactLayer::new(config);
    let fruit = layer.add_material("apple", apple());
    let st = layer.add_material("steel", steel());
    layer.set_default_coefficients(friction, ke, 100.0);
    layer
        .add_spheroid_body(&world.bodies, body, shape, fruit, "a1")
        .unwrap();
    layer
        .add_surface(
            &mut world.colliders,
            floor,
            SurfaceOptions::hertz("floor", st),
        )
        .unwrap();
    Scene {
        world,
        layer,
        body,
        mass,
    }
}

impl Scene {
    fn step(&mut self, t: f64) {
        let dt = self.world.integration_parameters.dt;
        self.layer
            .apply_forces(
                &mut self.world.bodies,
                &self.world.colliders,
                &self.world.islands,
                t,
                dt,
            )
            .unwrap();
        self.world.step_with_events(self.layer.hooks(), &());
    }

    fn run(&mut self, duration: f64) {
        let dt = self.world.integration_parameters.dt;
        let n = (duration / dt).round() as usize;
        for k in 0..n {
            self.step(k as f64 * dt);
        }
    }

    fn rb(&self) -> &RigidBody {
        &self.world.bodies[self.body]
    }
}

fn elastic() -> LayerConfig {
    let mut c = LayerConfig::default();
    c.parts.energy_loss = false;
    c.sleep.enabled = false;
    c
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// Pole down: identity (the apple's z axis vertical). Cheek down: turned a quarter about x.
fn pole_down() -> Rotation {
    Rotation::IDENTITY
}
fn cheek_down() -> Rotation {
    Rotation::from_rotation_x(std::f64::consts::FRAC_PI_2)
}

/// Drops the apple at 1 m/s without gravity; returns (peak force, contact time) of its impact.
fn drop(rot: Rotation, low: f64) -> (f64, f64, f64) {
    let dt = 1e-5;
    let mut s = scene(
        Spheroid::new(A, C),
        rot,
        Vector::new(0.0, 0.0, low + 1e-5),
        Vector::new(0.0, 0.0, -1.0),
        Vector::ZERO,
        0.0,
        dt,
        elastic(),
        0.3,
        1.0,
    );
    s.run(0.02);
    let ev = s.layer.finished_events();
    assert_eq!(ev.len(), 1, "one impact");
    let m = s.mass;
    (ev[0].peak_force_n, ev[0].duration_s.unwrap(), m)
}

/// Checks an impact's peak force and contact time against the closed form of an elastic Hertz
/// impact (tests/common/ode.rs) of mass `m` at 1 m/s on stiffness 4/3 E* sqrt(R_k), within `tol`.
fn assert_impact(what: &str, p: f64, t: f64, m: f64, e_star: f64, r_k: f64, tol: f64) {
    let k = 4.0 / 3.0 * e_star * r_k.sqrt();
    let (_, p_closed, t_closed, _) = ode::elastic_closed_form(m, 1.0, k, r_k);
    println!("{what}: P {p} ({p_closed}), t {t} ({t_closed})");
    assert!(rel(p, p_closed) < tol, "{what}: peak {p} vs {p_closed}");
    assert!(rel(t, t_closed) < tol, "{what}: time {t} vs {t_closed}");
}

/// Elastic pole drop: circular Hertz with R = a^2 / c.
#[test]
fn pole_drop_is_hertz_with_the_pole_radius() {
    let (p, t, m) = drop(pole_down(), C);
    // The issue asks 0.5 %; docs/shape.md prints 9e-7 for both, held at twice that.
    assert_impact("pole", p, t, m, e_star(), A * A / C, 1.9e-6);
}

/// Elastic cheek drop: the elliptic law with R' = a, R'' = c^2 / a.
#[test]
fn cheek_drop_is_the_elliptic_law() {
    let (p, t, m) = drop(cheek_down(), A);
    let r_k = elliptic_hertz(A, C * C / A).stiffness_radius_m;
    // The issue asks 0.5 %; docs/shape.md prints 9e-7 for both, held at twice that.
    assert_impact("cheek", p, t, m, e_star(), r_k, 1.9e-6);
}

/// The pole hits harder than the cheek by (R_pole / R_k,cheek)^(1/5).
#[test]
fn pole_to_cheek_peak_force_ratio() {
    let (pp, _, _) = drop(pole_down(), C);
    let (pc, _, _) = drop(cheek_down(), A);
    let closed = (A * A / C / elliptic_hertz(A, C * C / A).stiffness_radius_m).powf(0.2);
    println!("ratio {} closed {closed}", pp / pc);
    // The issue asks 0.5 %; docs/shape.md prints 1.4e-6, held at twice that.
    assert!(rel(pp / pc, closed) < 2.8e-6, "{} vs {closed}", pp / pc);
    assert!(closed > 1.03 && closed < 1.06, "about 4 % apart: {closed}");
}

fn damped() -> LayerConfig {
    let mut c = LayerConfig::default();
    c.sleep.enabled = false;
    c.gravity = Vector::new(0.0, 0.0, -9.81);
    c
}

/// Settles the apple at rest on `rot`'s lowest point and returns (overlap, closed form).
fn rest(shape: Spheroid, rot: Rotation, r_k: f64) -> (f64, f64) {
    let low = shape.point_with_normal(&rot, -Vector::Z).support_m;
    let mut s = scene(
        shape,
        rot,
        Vector::new(0.0, 0.0, low),
        Vector::ZERO,
        Vector::ZERO,
        9.81,
        1e-5,
        damped(),
        0.3,
        0.5,
    );
    s.run(0.5);
    let u = low - s.rb().translation().z;
    let k = 4.0 / 3.0 * e_star() * r_k.sqrt();
    // Eq. 12 (ke 0.5) carries (1 + ke)/2 of Hertz at rest (docs/physics.md 11.2).
    let closed = (s.mass * 9.81 / (0.75 * k)).powf(2.0 / 3.0);
    // Still upright: the axis where it started.
    let axis = *s.rb().rotation() * Vector::Z;
    assert!((axis - rot * Vector::Z).length() < 1e-6, "turned: {axis:?}");
    (u, closed)
}

/// Rest on the pole: circular Hertz with R = a^2/c carries m g.
#[test]
fn rest_on_the_pole() {
    let (u, closed) = rest(Spheroid::new(A, C), pole_down(), A * A / C);
    println!("pole rest u {u} closed {closed}");
    // The issue asks 0.5 %; docs/shape.md prints 4e-12 and 1.4e-12, held at 1e-11.
    assert!(rel(u, closed) < 1e-11, "{u} vs {closed}");
}

/// Rest on the cheek of an elongated apple (80 mm wide, 88 mm tall: stable on its side): the
/// elliptic law with R' = c^2/a along the meridian, R'' = a along the equator.
#[test]
fn rest_on_the_cheek() {
    let shape = Spheroid::new(A, 0.044);
    let h = elliptic_hertz(0.044 * 0.044 / A, A);
    let (u, closed) = rest(shape, cheek_down(), h.stiffness_radius_m);
    println!("cheek rest u {u} closed {closed}");
    // The issue asks 0.5 %; docs/shape.md prints 4e-12 and 1.4e-12, held at 1e-11.
    assert!(rel(u, closed) < 1e-11, "{u} vs {closed}");
}

/// Times of the upward zero crossings of `x(t)` sampled every `dt`.
fn upward_crossings(xs: &[f64], dt: f64) -> Vec<f64> {
    let mut out = Vec::new();
    for k in 1..xs.len() {
        if xs[k - 1] < 0.0 && xs[k] >= 0.0 {
            out.push(dt * ((k - 1) as f64 + xs[k - 1] / (xs[k - 1] - xs[k])));
        }
    }
    out
}

/// An oblate apple rocking on its pole, tilted 0.02 rad and released: the small-oscillation
/// period 2 pi sqrt((I + m h^2) / (m g (rho - h))) with rho = a^2/c, h = c, I = m (a^2 + c^2)/5,
/// within 1 %. Elastic contact, friction 0.8 (no slip).
#[test]
fn rocking_period_on_the_pole() {
    let shape = Spheroid::new(A, C);
    let tilt = 0.02;
    let rot = Rotation::from_rotation_y(tilt);
    let low = shape.point_with_normal(&rot, -Vector::Z).support_m;
    let dt = 1e-5;
    let mut config = elastic();
    config.gravity = Vector::new(0.0, 0.0, -9.81);
    let mut s = scene(
        shape,
        rot,
        Vector::new(0.0, 0.0, low - 1.5e-4),
        Vector::ZERO,
        Vector::ZERO,
        9.81,
        dt,
        config,
        0.8,
        1.0,
    );
    let mut xs = Vec::new();
    let n = (4.0 / dt) as usize;
    for k in 0..n {
        s.step(k as f64 * dt);
        xs.push((*s.rb().rotation() * Vector::Z).x);
    }
    let ups = upward_crossings(&xs, dt);
    assert!(ups.len() >= 4, "{} crossings", ups.len());
    let period = (ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f64;
    let m = s.mass;
    let (ieq, _) = shape.principal_inertia(m);
    let (rho, h) = (A * A / C, C);
    let closed = 2.0 * std::f64::consts::PI * ((ieq + m * h * h) / (m * 9.81 * (rho - h))).sqrt();
    println!(
        "rocking period {period} closed {closed} ({} periods)",
        ups.len() - 1
    );
    // The issue asks 1 %; docs/shape.md prints 0.34 %, held at twice that.
    assert!(rel(period, closed) < 0.0068, "{period} vs {closed}");
}

/// An elongated apple (80 x 88 mm) on its side, launched sliding at 1 m/s across its axis
/// without spin: it rolls straight about its own axis at v0 / (1 + I / (m l^2)) with
/// I = 2/5 m a^2 about the axis and the lever l = a - u from the centre to the contact point on
/// the flat (u its resting overlap): the sphere's 5/7 when u -> 0 (0.7116 here against 0.7143).
/// Its axis keeps its direction, and it rolls: w l = v.
#[test]
fn rolling_about_the_axis_goes_straight_at_five_sevenths() {
    let shape = Spheroid::new(A, 0.044);
    let rot = cheek_down(); // apple axis along -y
    let low = shape.point_with_normal(&rot, -Vector::Z).support_m;
    let mut s = scene(
        shape,
        rot,
        Vector::new(0.0, 0.0, low - 2.0e-4),
        Vector::new(1.0, 0.0, 0.0),
        Vector::ZERO,
        9.81,
        1e-5,
        damped(),
        0.3,
        0.5,
    );
    s.run(0.4);
    let v = s.rb().linvel();
    let w = s.rb().angvel();
    let axis = *s.rb().rotation() * Vector::Z;
    println!("rolling v {v:?} w {w:?} axis {axis:?}");
    let u = low - s.rb().translation().z;
    let lever = A - u;
    let closed = 1.0 / (1.0 + 0.4 * (A / lever).powi(2));
    println!("closed {closed} (5/7 = {}), u {u}", 5.0 / 7.0);
    // docs/shape.md prints 3e-6, held at twice that.
    assert!(rel(v.x, closed) < 6e-6, "v {} vs {closed}", v.x);
    assert!(v.y.abs() < 1e-6, "straight: v_y {}", v.y);
    assert!((axis + Vector::Y).length() < 1e-6, "axis turned: {axis:?}");
    assert!(
        rel(w.y * lever, v.x) < 1.3e-4,
        "w_y l {} v {}",
        w.y * lever,
        v.x
    );
}

/// Total energy of the apple: kinetic (translation and rotation about its principal axes),
/// gravity's and the contact's elastic energy.
fn energy(s: &Scene) -> f64 {
    let rb = s.rb();
    let m = s.mass;
    let shape = Spheroid::new(A, 0.044);
    let (ieq, iax) = shape.principal_inertia(m);
    let wb = rb.rotation().inverse() * rb.angvel();
    let rot_ke = 0.5 * (ieq * (wb.x * wb.x + wb.y * wb.y) + iax * wb.z * wb.z);
    0.5 * m * rb.linvel().length_squared()
        + rot_ke
        + m * 9.81 * rb.translation().z
        + s.layer.stats().elastic_energy_j
}

/// Launched rolling about a tilted axis (not its own) on a frictionless flat, the elongated
/// apple wobbles: its centre rises and falls as it turns. Without a loss model the energy is
/// conserved within issue 2's stated 0.1 % (the elastic runs' tolerance); measured: the largest
/// deviation over 1 s at dt 1e-5 s is 1.24e-4 of the launch kinetic energy (docs/shape.md),
/// held here at twice that. The velocities are rapier's staggered ones, uncorrected: the
/// deviation is the O(dt) phase error of symplectic Euler, not a drift.
#[test]
fn a_wobbling_spheroid_conserves_energy() {
    let shape = Spheroid::new(A, 0.044);
    let rot = Rotation::from_rotation_x(1.2);
    let low = shape.point_with_normal(&rot, -Vector::Z).support_m;
    let mut config = elastic();
    config.gravity = Vector::new(0.0, 0.0, -9.81);
    let mut s = scene(
        shape,
        rot,
        Vector::new(0.0, 0.0, low - 2.0e-4),
        Vector::new(0.3, 0.0, 0.0),
        Vector::new(0.0, 20.0, 3.0),
        9.81,
        1e-5,
        config,
        0.0,
        1.0,
    );
    s.step(0.0);
    let e0 = energy(&s);
    let ke0 = 0.5 * s.mass * 0.09 + 0.5 * 400.0 * 0.2 * s.mass * (A * A + 0.044 * 0.044);
    let (mut zmin, mut zmax) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut worst: f64 = 0.0;
    for k in 1..100_000 {
        s.step(k as f64 * 1e-5);
        let z = s.rb().translation().z;
        zmin = zmin.min(z);
        zmax = zmax.max(z);
        worst = worst.max((energy(&s) - e0).abs());
    }
    println!(
        "wobble: z {zmin}..{zmax}, worst energy deviation {worst:e} J of {ke0} J ({:e})",
        worst / ke0
    );
    assert!(zmax - zmin > 1e-3, "it wobbles: z range {}", zmax - zmin);
    assert!(worst < 1e-3 * e0, "beyond 0.1 %: {worst:e} of {e0}");
    assert!(
        worst < 2.5e-4 * ke0,
        "deviation {:e} of the kinetic energy",
        worst / ke0
    );
}

/// Two 80 x 72 mm apples meeting head-on at 1 m/s (no gravity, elastic), turned by `r1`, `r2`
/// and approaching along x: (peak force, contact time, mass of one).
fn head_on(r1: Rotation, r2: Rotation) -> (f64, f64, f64) {
    let shape = Spheroid::new(A, C);
    let dt = 1e-5;
    let mut world = physics_world(0.0, dt);
    let mass = DENSITY * shape.volume_m3();
    let mut layer = ContactLayer::new(elastic());
    let fruit = layer.add_material("apple", apple());
    layer.set_default_coefficients(0.3, 1.0, 100.0);
    for (k, (rot, x, v)) in [(r1, -1.0, 0.5), (r2, 1.0, -0.5)].into_iter().enumerate() {
        let reach = shape.point_with_normal(&rot, Vector::X * x).support_m;
        let pose = Pose::from_parts(Vector::new(x * (reach + 1e-5), 0.0, 0.0), rot);
        let body = world.bodies.insert(spheroid_body(
            &shape,
            pose,
            Vector::new(v, 0.0, 0.0),
            Vector::ZERO,
        ));
        layer
            .add_spheroid_body(&world.bodies, body, shape, fruit, &format!("a{k}"))
            .unwrap();
    }
    for k in 0..3000 {
        layer
            .apply_forces(
                &mut world.bodies,
                &world.colliders,
                &world.islands,
                k as f64 * dt,
                dt,
            )
            .unwrap();
        world.step_with_events(layer.hooks(), &());
    }
    let ev = layer.finished_events();
    assert_eq!(ev.len(), 1, "one impact");
    (ev[0].peak_force_n, ev[0].duration_s.unwrap(), mass)
}

fn e_star_apples() -> f64 {
    let a = apple();
    let na = a.poisson_ratio;
    0.5 * a.youngs_modulus_pa / (1.0 - na * na)
}

/// Pole against pole: circular, R* = (a^2/c) / 2. Cheek against cheek with the axes crossed:
/// the curvatures 1/a and a/c^2 add crosswise to a circle, R* = 1 / (1/a + a/c^2). Cheeks with
/// the axes parallel: elliptic, R' = a/2, R'' = c^2/(2a). m* = m/2, relative speed 1 m/s.
#[test]
fn two_spheroids_head_on() {
    let pole_x = Rotation::from_rotation_y(std::f64::consts::FRAC_PI_2); // axis along x
    let axis_z = Rotation::IDENTITY; // cheek towards x, axis along z
    let axis_y = Rotation::from_rotation_x(std::f64::consts::FRAC_PI_2); // cheek towards x, axis along y
    let cases = [
        ("pole-pole", pole_x, pole_x, 0.5 * A * A / C),
        (
            "cheek-cheek crossed",
            axis_z,
            axis_y,
            1.0 / (1.0 / A + A / (C * C)),
        ),
        (
            "cheek-cheek parallel",
            axis_z,
            axis_z,
            elliptic_hertz(0.5 * A, 0.5 * C * C / A).stiffness_radius_m,
        ),
    ];
    for (what, r1, r2, r_k) in cases {
        let (p, t, m) = head_on(r1, r2);
        // docs/shape.md prints at most 1.3e-6, held at twice that.
        assert_impact(what, p, t, 0.5 * m, e_star_apples(), r_k, 2.6e-6);
    }
}

/// First time the apple falls asleep and its tilt then, released at rest tilted `theta0` on its
/// pole, over `duration` s.
fn first_sleep(theta0: f64, duration: f64) -> (Option<(f64, f64)>, f64) {
    let shape = Spheroid::new(A, C);
    let rot = Rotation::from_rotation_y(theta0);
    let low = shape.point_with_normal(&rot, -Vector::Z).support_m;
    let config = LayerConfig {
        gravity: Vector::new(0.0, 0.0, -9.81),
        ..Default::default()
    };
    let dt = 1e-5;
    let mut s = scene(
        shape,
        rot,
        Vector::new(0.0, 0.0, low - 2.2e-4),
        Vector::ZERO,
        Vector::ZERO,
        9.81,
        dt,
        config,
        0.5,
        0.5,
    );
    let m = s.mass;
    let (ieq, _) = shape.principal_inertia(m);
    let omega2 = m * 9.81 * (A * A / C - C) / (ieq + m * C * C);
    let theta_max = 0.005 / (A * 0.2 * omega2);
    for k in 0..(duration / dt) as usize {
        s.step(k as f64 * dt);
        if s.layer.sleeping_count() == 1 {
            let tilt = (s.rb().rotation() * Vector::Z).x.abs();
            return (Some((k as f64 * dt, tilt)), theta_max);
        }
    }
    (None, theta_max)
}

/// The sleeping rule and a spheroid off its resting pose. An apple sleeps when it has been
/// still (|v| and |w| R below v_s = 5 mm/s) for T_s = 0.2 s and its mean load would not change
/// that within T_s. Rocking on its pole at omega^2 = m g (rho - h) / (I + m h^2) (as
/// `rocking_period_on_the_pole`; omega = 6.65 rad/s) from theta0, its |w| R peaks at
/// R omega theta0: below v_s while theta0 < v_s / (R omega) = 0.0188 rad, so stillness alone
/// would let it sleep anywhere in its swing. The rule's torque part (a spheroid's mean contact
/// torque about its centre, I alpha < I v_s / (R T_s), alpha = omega^2 theta) lets it sleep only
/// tilted less than theta_max = v_s / (R T_s omega^2) = 0.0141 rad for the 80 x 72 apple.
/// - Released from 0.01-0.018 rad it sleeps, tilted less than theta_max.
/// - Released from 0.02 and 0.025 rad (its rocking, without rolling resistance, hardly decays)
///   it is never still: it stays awake.
#[test]
fn a_tilted_spheroid_sleeps_only_near_its_resting_pose() {
    for th in [0.01, 0.012, 0.015, 0.018] {
        let (slept, theta_max) = first_sleep(th, 2.0);
        println!("theta_max {theta_max}; from {th} rad, first asleep (s, rad): {slept:?}");
        assert!((theta_max - 0.0141).abs() < 5e-5);
        let (_, tilt) = slept.expect("it sleeps");
        assert!(tilt < theta_max, "asleep at tilt {tilt}");
    }
    for th in [0.02, 0.025] {
        let (slept, _) = first_sleep(th, 3.0);
        println!("from {th} rad: {slept:?}");
        assert!(slept.is_none(), "asleep while rocking: {slept:?}");
    }
}
