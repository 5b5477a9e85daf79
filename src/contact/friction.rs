//! Amontons-Coulomb friction (paper eq. 11) with a stick regularisation.
//!
//! The paper's law is F_t = -mu P s_t / |s_t| for the slip velocity s_t of the two surfaces at the
//! contact point. Taken literally it chatters as |s_t| -> 0 and cannot hold an apple at rest on a
//! slope or in a pile. Following LAMMPS's GRANULAR `tangential linear_history` / `mindlin` models
//! we carry an elastic tangential displacement xi per contact:
//!
//! ```text
//! xi      += s_t dt                                  (elastic shear of the contact patch)
//! xi       = xi * min(1, mu P / (k_t |xi|))          (the spring alone never exceeds mu P)
//! F_trial  = -k_t xi - gamma_t s_t                   (Mindlin spring + dashpot)
//! F_t      = F_trial * min(1, mu P / |F_trial|)      (Coulomb cap: sliding when it bites)
//! ```
//!
//! * k_t = 8 G* a (Mindlin, with the Hertz contact radius a), so the tangential spring is as stiff
//!   as the real contact patch and adds no time scale shorter than the normal one.
//! * While sliding, |F_t| = mu P exactly and F_t opposes the current slip (the dashpot term
//!   dominates the direction once |s_t| > mu P / gamma_t): the paper's law, so slip-to-roll times
//!   and speeds follow the closed forms of physics.md section 6.
//! * LAMMPS instead rescales xi so that spring + dashpot equal the cap. Measured on a decelerating
//!   slide that lowers the friction force to about mu P / (1 + gamma_t dt / m_eff) (the stored
//!   dashpot part lags the slip), which breaks the closed forms; capping the spring alone does not.
//!   The net impulse after the slip vanishes is m_eff times the change of slip, zero, so the stored
//!   spring does not change the rolling speed either.
//! * gamma_t is chosen by the caller (the layer uses a fraction of the "velocity-kill" value
//!   m_eff / dt, shared among an apple's contacts, see [`crate::layer`]); a rolling apple has
//!   s_t = 0 and feels no force, so it neither creeps nor jitters, and a loaded stuck contact stops
//!   creeping once k_t xi carries the load.

use crate::math::Vec3;

/// Tangential parameters of one contact at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TangentialParams {
    /// Coulomb coefficient mu (dimensionless).
    pub mu: f64,
    /// Tangential spring stiffness k_t (N/m); 0 turns the spring off (pure regularised Coulomb).
    pub stiffness_n_m: f64,
    /// Tangential dashpot gamma_t (N s/m).
    pub damping_n_s_m: f64,
}

/// Result of the tangential law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TangentialForce {
    /// Force on body 1 (the opposite acts on body 2), N.
    pub force: Vec3,
    /// Whether the contact is at the Coulomb limit (sliding).
    pub sliding: bool,
}

/// Mindlin tangential stiffness k_t = 8 G* a.
pub fn mindlin_stiffness(g_star_pa: f64, a_m: f64) -> f64 {
    8.0 * g_star_pa * a_m
}

/// Keeps the stored displacement in the current tangent plane with its length (LAMMPS's
/// history rotation): the contact frame turns as the bodies roll.
#[inline]
pub fn project_history(xi: Vec3, n: Vec3) -> Vec3 {
    let len2 = xi.length_squared();
    if len2 == 0.0 {
        return xi;
    }
    let t = xi - n * xi.dot(n);
    let tl2 = t.length_squared();
    // One square root instead of two. A history (nearly) along the normal has no tangential part
    // left: the contact frame turned by a right angle; it is dropped.
    if tl2 > 1e-30 * len2 {
        t * (len2 / tl2).sqrt()
    } else {
        Vec3::ZERO
    }
}

/// Evaluates the tangential law. `slip_t` is the tangential slip of body 1's surface point
/// relative to body 2's (m/s), `normal_force_n` the normal force P >= 0 and `xi` the stored
/// tangential displacement (already projected on the tangent plane), updated in place.
#[inline]
pub fn tangential_force(
    p: &TangentialParams,
    normal_force_n: f64,
    slip_t: Vec3,
    xi: &mut Vec3,
    dt_s: f64,
) -> TangentialForce {
    let cap = p.mu * normal_force_n;
    if cap <= 0.0 {
        *xi = Vec3::ZERO;
        return TangentialForce {
            force: Vec3::ZERO,
            sliding: slip_t != Vec3::ZERO,
        };
    }
    let k = p.stiffness_n_m;
    let mut spring = Vec3::ZERO;
    if k > 0.0 {
        *xi += slip_t * dt_s;
        // |xi| k > cap, compared as squares: the root only when the spring is capped.
        let stretch2 = xi.length_squared() * k * k;
        if stretch2 > cap * cap {
            *xi *= cap / stretch2.sqrt();
        }
        spring = -(*xi * k);
    } else {
        *xi = Vec3::ZERO;
    }
    let trial = spring - slip_t * p.damping_n_s_m;
    let mag2 = trial.length_squared();
    if mag2 <= cap * cap {
        return TangentialForce {
            force: trial,
            sliding: false,
        };
    }
    TangentialForce {
        force: trial * (cap / mag2.sqrt()),
        sliding: true,
    }
}

/// Which tangential sub-model a pair of materials uses.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum TangentialModel {
    /// The Mindlin stick spring with a bounded dashpot and the Coulomb cap of
    /// [`tangential_force`] (applesim's own, tuned for the slip-to-roll closed forms).
    #[default]
    Mindlin,
    /// LIGGGHTS `tangential history`: the same spring k_t = 8 G* a; its history loses its normal
    /// part as the normal turns; above the Coulomb cap the spring is rescaled to the cap (no
    /// dashpot while sliding); below it a viscous damping -gamma_t s_t with
    /// gamma_t = -2 sqrt(5/6) beta sqrt(k_t m*) (see [`history_force`]).
    History,
}

/// LIGGGHTS's `tangential history` force on body 1 (tangential_model_history.h): `xi` += s_t dt,
/// less its normal part; F = -k_t xi; if |F| > mu |P| the force (and the history) is rescaled to
/// mu |P| (sliding), else the damping -gamma_t s_t is added. `normal_force_n` is the whole normal
/// force (damping included), as in LIGGGHTS.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn history_force(
    mu: f64,
    stiffness_n_m: f64,
    gamma_t: f64,
    normal_force_n: f64,
    slip_t: Vec3,
    n: Vec3,
    xi: &mut Vec3,
    dt_s: f64,
) -> TangentialForce {
    *xi += slip_t * dt_s;
    *xi -= n * xi.dot(n);
    let mut force = -(*xi * stiffness_n_m);
    let shear = stiffness_n_m * xi.length();
    let cap = mu * normal_force_n.abs();
    if shear > cap {
        if shear > 0.0 {
            force *= cap / shear;
            *xi = if stiffness_n_m > 0.0 {
                -(force / stiffness_n_m)
            } else {
                Vec3::ZERO
            };
        }
        return TangentialForce {
            force,
            sliding: true,
        };
    }
    TangentialForce {
        force: force - slip_t * gamma_t,
        sliding: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> TangentialParams {
        TangentialParams {
            mu: 0.3,
            stiffness_n_m: 1e4,
            damping_n_s_m: 50.0,
        }
    }

    #[test]
    fn sliding_force_is_coulomb() {
        let mut xi = Vec3::ZERO;
        let s = Vec3::new(0.5, 0.0, 0.0);
        let f = tangential_force(&params(), 10.0, s, &mut xi, 1e-5);
        assert!(f.sliding);
        assert!((f.force.length() - 3.0).abs() < 1e-12);
        assert!(f.force.dot(s) < 0.0, "friction opposes slip");
        // Direction is exactly opposite the slip for a fresh contact.
        assert!(f.force.cross(s).length() < 1e-12);
    }

    #[test]
    fn decelerating_slide_keeps_full_coulomb_force() {
        // Regression: a LAMMPS-style rescale gave |F| = mu P / (1 + gamma dt / m) here.
        let p = TangentialParams {
            mu: 0.3,
            stiffness_n_m: 1e4,
            damping_n_s_m: 0.5 * 0.03 / 1e-5,
        };
        let mut xi = Vec3::ZERO;
        let mut s = 0.2;
        while s > 0.01 {
            let f = tangential_force(&p, 10.0, Vec3::new(s, 0.0, 0.0), &mut xi, 1e-5);
            assert!(f.sliding);
            assert!(
                (f.force.x + 3.0).abs() < 1e-9,
                "F = {:?} at s = {s}",
                f.force
            );
            s += f.force.x / 0.03 * 1e-5;
        }
    }

    #[test]
    fn friction_never_pushes_along_a_sudden_slip_drop() {
        let p = params();
        let mut xi = Vec3::ZERO;
        for _ in 0..100 {
            tangential_force(&p, 10.0, Vec3::new(1.0, 0.0, 0.0), &mut xi, 1e-5);
        }
        let f = tangential_force(&p, 10.0, Vec3::new(1e-3, 0.0, 0.0), &mut xi, 1e-5);
        assert!(f.force.x <= 0.0, "F = {:?}", f.force);
        assert!(f.force.length() <= 3.0 + 1e-12);
    }

    #[test]
    fn stick_holds_a_static_load() {
        // Zero slip with a stored displacement: the spring alone carries the force, below the cap.
        let p = params();
        let mut xi = Vec3::new(1e-4, 0.0, 0.0);
        let f = tangential_force(&p, 10.0, Vec3::ZERO, &mut xi, 1e-5);
        assert!(!f.sliding);
        assert!((f.force.x + 1.0).abs() < 1e-12);
    }

    #[test]
    fn zero_normal_force_gives_zero_friction() {
        let mut xi = Vec3::new(1.0, 0.0, 0.0);
        let f = tangential_force(&params(), 0.0, Vec3::new(1.0, 0.0, 0.0), &mut xi, 1e-5);
        assert_eq!(f.force, Vec3::ZERO);
        assert_eq!(xi, Vec3::ZERO);
    }

    #[test]
    fn history_projection_keeps_length() {
        let n = Vec3::new(0.0, 0.0, 1.0);
        let xi = Vec3::new(3.0, 0.0, 4.0);
        let p = project_history(xi, n);
        assert!((p.length() - 5.0).abs() < 1e-12);
        assert!(p.dot(n).abs() < 1e-12);
    }

    #[test]
    fn liggghts_history_rescales_and_damps_only_while_sticking() {
        let n = Vec3::Z;
        let mut xi = Vec3::ZERO;
        // Sticking: spring plus damping.
        let f = history_force(
            0.5,
            1e4,
            20.0,
            10.0,
            Vec3::new(0.1, 0.0, 0.0),
            n,
            &mut xi,
            1e-4,
        );
        assert!(!f.sliding);
        assert!((f.force.x - (-1e4 * 1e-5 - 20.0 * 0.1)).abs() < 1e-12);
        // Sliding: the spring alone rescaled to mu |P|, the history with it.
        let mut xi = Vec3::new(1.0, 0.0, 0.0);
        let f = history_force(
            0.5,
            1e4,
            20.0,
            -10.0,
            Vec3::new(0.1, 0.0, 0.0),
            n,
            &mut xi,
            1e-4,
        );
        assert!(f.sliding);
        assert!((f.force.x + 5.0).abs() < 1e-12);
        assert!((xi.x - 5e-4).abs() < 1e-15);
        // The history loses its normal part.
        let mut xi = Vec3::new(0.0, 0.0, 1e-6);
        history_force(0.5, 1e4, 0.0, 10.0, Vec3::ZERO, n, &mut xi, 1e-4);
        assert_eq!(xi, Vec3::ZERO);
    }
}
