//! What one impact does to one apple: the figures an instrumented sphere reports (peak
//! acceleration in g, velocity change), from the contact's impact pulse and the apple's mass.

use crate::math::{vec3, Vec3};
use crate::record::events::ImpactPulse;

/// Standard gravity (m/s^2): the unit `g` of accelerations.
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// One apple's side of an impact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AppleImpact {
    /// Peak contact acceleration, peak force / (m g) with g the standard gravity (g): what an
    /// accelerometer in the apple reads at the peak.
    pub peak_g: f64,
    /// Change of the apple's velocity along the contact normal over the pulse (m/s): the normal
    /// impulse over the mass plus gravity's share over the pulse, so a rebound from a fixed
    /// surface at v0 with restitution e gives (1 + e) v0 (with or without gravity).
    pub velocity_change_m_s: f64,
}

/// The impact `p` as apple of mass `mass_kg` saw it, under `gravity`; `towards_apple` tells
/// whether the pulse's normal points at this apple (the contact's apple `a`) or away from it (the
/// other apple of an apple-apple contact).
pub fn for_apple(p: &ImpactPulse, mass_kg: f64, gravity: Vec3, towards_apple: bool) -> AppleImpact {
    let n = if towards_apple {
        vec3(p.normal)
    } else {
        -vec3(p.normal)
    };
    AppleImpact {
        peak_g: p.peak_force_n / (mass_kg * STANDARD_GRAVITY),
        velocity_change_m_s: p.impulse_n_s / mass_kg + gravity.dot(n) * p.duration_s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rebound_changes_the_velocity_by_one_plus_e_v0() {
        // 0.1 kg at 1 m/s onto a floor, e = 0.5, pulse 5 ms under gravity: the floor's impulse is
        // m (1.5 m/s) + m g t.
        let g = Vec3::new(0.0, 0.0, -9.81);
        let p = ImpactPulse {
            t_end_s: 0.005,
            duration_s: 0.005,
            peak_force_n: 98.0665,
            t_peak_s: 0.002,
            impulse_n_s: 0.1 * 1.5 + 0.1 * 9.81 * 0.005,
            absorbed_energy_j: 0.0,
            max_pressure_pa: 0.0,
            normal: [0.0, 0.0, 1.0],
        };
        let a = for_apple(&p, 0.1, g, true);
        assert!((a.velocity_change_m_s - 1.5).abs() < 1e-12);
        assert!((a.peak_g - 100.0).abs() < 1e-12);
        // The other body of an apple-apple contact sees the normal reversed.
        let b = for_apple(&p, 0.1, Vec3::ZERO, false);
        assert!((b.velocity_change_m_s - p.impulse_n_s / 0.1).abs() < 1e-12);
    }
}
