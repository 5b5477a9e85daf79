//! Twisting resistance: the torque that opposes the relative spin of two bodies about their
//! contact normal (the paper omits it, as LIGGGHTS and EDEM do by default; docs/physics.md
//! section 11.8).
//!
//! A point contact offers no lever against a spin about its normal: the tangential force acts at
//! the contact point, which such a spin does not move. Without a twisting torque an apple set
//! spinning about the vertical on a floor (by an oblique knock, a roller, a brush) spins there for
//! ever, and in a pile the few apples left twisting keep themselves and their neighbours awake
//! (measured on the 1000-apple pile: all of the apples still awake in 3-5 s were twisting on the
//! floor or leaning on them). A real contact is a patch of radius a: Coulomb friction over the
//! patch resists the spin. With the Hertz pressure p = p0 sqrt(1 - r^2/a^2) and full slip the
//! torque is
//!
//! ```text
//!     M = integral of mu p r dA = (3 pi / 16) mu a F_n      (Johnson, Contact Mechanics, 1985, section 7.3)
//! ```
//!
//! [`TwistingModel::Coulomb`] applies that torque against the relative spin, bounded (like the
//! friction dashpot and the `cdt` rolling torque) by the torque that stops the relative spin within
//! one step: a spinning apple on a flat decelerates at M / I and stops after I w0 / M, then stays
//! stopped instead of flipping the torque every step. The short elastic twist before full slip
//! (Lubkin's torsion of the Hertz contact, at most a few milliradians) is not modelled.

use crate::math::Vec3;

/// Which twisting-resistance sub-model a pair of materials uses.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum TwistingModel {
    /// None (the paper, and LIGGGHTS / EDEM by default): a spin about the normal is free.
    #[default]
    None,
    /// Coulomb friction over the Hertz patch: (3 pi / 16) mu a F_n against the spin.
    Coulomb,
}

/// The full-slip twisting torque (3 pi / 16) mu a F_n of a Hertz patch of radius `a` under the
/// normal force `normal_force_n` (N m).
#[inline]
pub fn coulomb_limit(mu: f64, contact_radius_m: f64, normal_force_n: f64) -> f64 {
    3.0 * std::f64::consts::PI / 16.0 * mu * contact_radius_m * normal_force_n.max(0.0)
}

/// The twisting torque on body 1: -min(`limit`, `kill` |w_n|) along the relative spin
/// w_n = ((w1 - w2) . n) n about the normal `n`; `kill` (N m s) is the torque per unit spin that
/// stops the relative spin within one step.
#[inline]
pub fn coulomb_torque(limit: f64, rel_angular_velocity: Vec3, n: Vec3, kill: f64) -> Vec3 {
    let spin = rel_angular_velocity.dot(n);
    if spin == 0.0 || limit <= 0.0 {
        return Vec3::ZERO;
    }
    n * (-limit.min(kill * spin.abs()) * spin.signum())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limit_is_the_hertz_patch_integral() {
        // Integrate mu p r over the patch numerically: p = p0 sqrt(1 - r^2/a^2),
        // F = 2/3 pi p0 a^2.
        let (mu, a, f) = (0.5, 0.004, 3.0);
        let p0 = 3.0 * f / (2.0 * std::f64::consts::PI * a * a);
        let n = 200_000;
        let dr = a / n as f64;
        let m: f64 = (0..n)
            .map(|i| {
                let r = (i as f64 + 0.5) * dr;
                mu * p0 * (1.0 - r * r / (a * a)).sqrt() * r * 2.0 * std::f64::consts::PI * r * dr
            })
            .sum();
        let exact = coulomb_limit(mu, a, f);
        assert!((m / exact - 1.0).abs() < 1e-6, "{m} against {exact}");
    }

    #[test]
    fn torque_opposes_the_spin_about_the_normal_only() {
        let n = Vec3::Z;
        // Rolling (tangential) spin gives no twisting torque.
        assert_eq!(
            coulomb_torque(1.0, Vec3::new(3.0, 4.0, 0.0), n, 1e9),
            Vec3::ZERO
        );
        // Fast spin: the full limit, against it.
        let t = coulomb_torque(0.02, Vec3::new(3.0, 0.0, -2.0), n, 1e9);
        assert_eq!(t, Vec3::new(0.0, 0.0, 0.02));
        // Slow spin: what stops it within the step.
        let t = coulomb_torque(0.02, Vec3::new(0.0, 0.0, 1e-3), n, 1.0);
        assert_eq!(t, Vec3::new(0.0, 0.0, -1e-3));
        // No load, no torque.
        assert_eq!(coulomb_torque(0.0, Vec3::Z, n, 1.0), Vec3::ZERO);
        assert_eq!(coulomb_limit(0.5, 0.004, -1.0), 0.0);
    }
}
