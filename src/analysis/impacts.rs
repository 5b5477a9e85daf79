//! What one impact does to one apple: the figures an instrumented sphere reports (peak
//! acceleration in g, velocity change), from the contact's impact pulse and the apple's mass.

use crate::record::events::ImpactPulse;

/// Standard gravity (m/s^2): the unit `g` of accelerations.
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// One apple's side of an impact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AppleImpact {
    /// Peak contact acceleration, peak force / (m g) with g the standard gravity (g): what an
    /// accelerometer in the apple reads at the peak of this contact's force.
    pub peak_g: f64,
    /// Change of the apple's velocity along the contact normal over the pulse (m/s;
    /// [`ImpactPulse::velocity_change_m_s`]): a rebound from a fixed surface at v0 with
    /// restitution e gives (1 + e) v0.
    pub velocity_change_m_s: f64,
}

/// The impact `p` as apple of mass `mass_kg` saw it; `towards_apple` tells whether the pulse's
/// normal points at this apple (the contact's apple `a`) or away from it (the other apple of an
/// apple-apple contact).
pub fn for_apple(p: &ImpactPulse, mass_kg: f64, towards_apple: bool) -> AppleImpact {
    AppleImpact {
        peak_g: p.peak_force_n / (mass_kg * STANDARD_GRAVITY),
        velocity_change_m_s: p.velocity_change_m_s[usize::from(!towards_apple)],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_apple_reads_its_own_side() {
        let p = ImpactPulse {
            t_end_s: 0.005,
            duration_s: 0.005,
            peak_force_n: 98.0665,
            t_peak_s: 0.002,
            impulse_n_s: 0.15,
            absorbed_energy_j: 0.0,
            a_absorbed_energy_j: 0.0,
            max_pressure_pa: 0.0,
            max_overlap_m: 0.0,
            max_contact_radius_m: 0.0,
            a_indentation_m: 0.0,
            overlap_at_peak_m: 0.0,
            sites: [[0.0; 3]; 2],
            normal: [0.0, 0.0, 1.0],
            velocity_change_m_s: [1.5, 0.7],
        };
        let a = for_apple(&p, 0.1, true);
        assert_eq!(a.velocity_change_m_s, 1.5);
        assert!((a.peak_g - 100.0).abs() < 1e-12);
        let b = for_apple(&p, 0.2, false);
        assert_eq!(b.velocity_change_m_s, 0.7);
        assert!((b.peak_g - 50.0).abs() < 1e-12);
    }
}
