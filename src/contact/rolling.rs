//! Rolling resistance: a torque that opposes the relative rolling of the two bodies at a
//! contact (the paper omits it; docs/physics.md section 11).
//!
//! Without it a sphere rolls on a flat for ever, and an apple set on a running belt rolls
//! backwards relative to the belt and rides at 2/7 of its speed for ever; a pile of spheres
//! spreads into a single layer. Real fruit rolls against a small resistance from the
//! deformation of its contact patch (hysteresis of the flesh, the patch's asymmetry). DEM codes
//! model it with a torque proportional to the normal load; the two sub-models here are those of
//! LIGGGHTS (`rolling_friction cdt` and `epsd2`), so a parameter set calibrated there (or in
//! EDEM, whose "type A" is `cdt`) means the same thing here:
//!
//! - [`RollingModel::ConstantTorque`] (`cdt`): M = -mu_r R* F_n w_t / |w_t|, w_t the relative
//!   angular velocity in the contact plane. A rolling ball decelerates at 5/7 mu_r g. At rest
//!   |w_t| -> 0 and the direction flips every step; the torque is bounded by the one that stops the
//!   relative rolling within one step (the velocity-kill bound of the friction dashpot), so a
//!   ball that has stopped stays stopped instead of rocking.
//! - [`RollingModel::ElasticPlastic`] (`epsd2`): a torsion spring M_s += -k_r w_t dt with
//!   k_r = k_t R*^2 (k_t = 8 G* a, the tangential stiffness), capped at mu_r R* |F_n|: the
//!   torque that an apple resting on a gentle slope needs to stay put. Below the cap a viscous
//!   torque -C_r w_t damps the spring's rocking, C_r = eta_r 2 sqrt(I_r k_r) as in LIGGGHTS's
//!   `epsd` (Ai et al. 2011; I_r the moment of inertia about the contact point); `epsd2` itself
//!   has none (eta_r = 0), and an undamped spring rocks a resting pile for ever (measured: a
//!   settled 27-apple pile crept 1.6 um in 2 s, against 0.06 nm without rolling resistance).
//!
//! Twisting (spin about the normal) is not resisted here; only the tangential part of the
//! relative spin counts, as in LIGGGHTS without `torsionTorque`. Twisting resistance is its own
//! sub-model, [`super::twisting`].

use crate::math::Vec3;

/// Which rolling-resistance sub-model a pair of materials uses.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum RollingModel {
    /// No rolling resistance (the paper).
    #[default]
    None,
    /// A constant torque mu_r R* F_n against the relative rolling (LIGGGHTS `cdt`, EDEM type A).
    ConstantTorque,
    /// An elastic torsion spring k_r = k_t R*^2 limited by mu_r R* F_n (LIGGGHTS `epsd2`).
    ElasticPlastic,
}

/// The part of the relative angular velocity w1 - w2 that rolls (in the contact plane, normal
/// `n`).
#[inline]
pub fn rolling_velocity(rel_angular_velocity: Vec3, n: Vec3) -> Vec3 {
    rel_angular_velocity - n * rel_angular_velocity.dot(n)
}

/// The `cdt` torque on body 1: -mu_r R* F_n w_t / |w_t|, bounded by `kill` |w_t| (N m s: the
/// torque that stops the relative rolling within one step, see the module documentation).
/// `normal_force_n` is the elastic (Hertz) part of the normal force, as in LIGGGHTS.
#[inline]
pub fn constant_torque(
    mu_r: f64,
    r_star_m: f64,
    normal_force_n: f64,
    w_t: Vec3,
    kill: f64,
) -> Vec3 {
    let w = w_t.length();
    if w == 0.0 || normal_force_n <= 0.0 {
        return Vec3::ZERO;
    }
    let limit = mu_r * r_star_m * normal_force_n;
    let m = limit.min(kill * w);
    w_t * (-m / w)
}

/// The elastic-plastic torque on body 1 and the spring's new state: the stored torque `spring`
/// (the torque body 1 receives) grows by -k_r w_t dt and is capped at mu_r R* |F_n| (then
/// the rolling is fully mobilised: no damping); below the cap the viscous torque -c_r w_t is
/// added, the total capped again. The stored torque is kept in the contact plane (projected,
/// its length kept) as the normal turns.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn elastic_plastic(
    mu_r: f64,
    r_star_m: f64,
    normal_force_n: f64,
    k_r: f64,
    c_r: f64,
    w_t: Vec3,
    n: Vec3,
    spring: &mut Vec3,
    dt_s: f64,
) -> Vec3 {
    let limit = mu_r * r_star_m * normal_force_n.abs();
    if limit <= 0.0 {
        *spring = Vec3::ZERO;
        return Vec3::ZERO;
    }
    let mut m = super::friction::project_history(*spring, n) - w_t * (k_r * dt_s);
    let mag2 = m.length_squared();
    if mag2 > limit * limit {
        m *= limit / mag2.sqrt();
        *spring = m;
        return m;
    }
    *spring = m;
    if c_r == 0.0 {
        return m;
    }
    let total = m - w_t * c_r;
    let t2 = total.length_squared();
    if t2 > limit * limit {
        total * (limit / t2.sqrt())
    } else {
        total
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rolling_velocity_drops_the_twist() {
        let w = rolling_velocity(Vec3::new(1.0, 2.0, 3.0), Vec3::Z);
        assert_eq!(w, Vec3::new(1.0, 2.0, 0.0));
    }

    #[test]
    fn cdt_torque_is_mu_r_r_fn_against_the_rolling() {
        let t = constant_torque(0.03, 0.04, 2.0, Vec3::new(0.0, 5.0, 0.0), f64::INFINITY);
        assert!((t.y + 0.03 * 0.04 * 2.0).abs() < 1e-15);
        assert_eq!((t.x, t.z), (0.0, 0.0));
        // Nearly stopped: no more than what stops it within the step.
        let t = constant_torque(0.03, 0.04, 2.0, Vec3::new(0.0, 1e-4, 0.0), 1.0);
        assert!((t.y + 1e-4).abs() < 1e-18);
        assert_eq!(
            constant_torque(0.03, 0.04, 2.0, Vec3::ZERO, 1.0),
            Vec3::ZERO
        );
    }

    #[test]
    fn epsd2_spring_then_plastic_cap() {
        let (mu_r, r, f, k_r, dt) = (0.03, 0.04, 2.0, 10.0, 1e-4);
        let mut s = Vec3::ZERO;
        // Elastic: k_r w dt per step against the rolling.
        let y = Vec3::new(0.0, 1.0, 0.0);
        let t = elastic_plastic(mu_r, r, f, k_r, 0.0, y, Vec3::Z, &mut s, dt);
        assert!((t.y + k_r * dt).abs() < 1e-15);
        // Held long enough, it caps at mu_r R F_n and stays there.
        for _ in 0..10_000 {
            elastic_plastic(mu_r, r, f, k_r, 0.0, y, Vec3::Z, &mut s, dt);
        }
        assert!((s.length() - mu_r * r * f).abs() < 1e-15);
        // Rolling back unloads the spring at once (elastic).
        let t = elastic_plastic(mu_r, r, f, k_r, 0.0, -y, Vec3::Z, &mut s, dt);
        assert!((t.y + mu_r * r * f - k_r * dt).abs() < 1e-15);
        // Below the cap the dashpot adds -c_r w_t; fully mobilised, none.
        let mut s = Vec3::ZERO;
        let t = elastic_plastic(mu_r, r, f, k_r, 1e-5, y * 0.1, Vec3::Z, &mut s, dt);
        assert!((t.y + k_r * dt * 0.1 + 1e-6).abs() < 1e-15);
        let mut s = Vec3::new(0.0, -mu_r * r * f, 0.0);
        let t = elastic_plastic(mu_r, r, f, k_r, 1.0, y, Vec3::Z, &mut s, dt);
        assert!((t.y + mu_r * r * f).abs() < 1e-15);
    }
}
