//! Closed forms of physics.md sections 4 and 6, shared by tests, the time-step policy and the
//! analysis commands. Nothing here touches rapier.

/// integral_0^1 (1 - x^(5/2))^(-1/2) dx: the Hertz contact-time constant (physics.md section 4).
pub const HERTZ_TIME_INTEGRAL: f64 = 1.471_637_6;

/// k_P = impulse / (P_max t_H) for an elastic Hertz impact = 8 / (5 * 2.9432752).
pub const ELASTIC_PULSE_COEFFICIENT: f64 = 0.543_612_1;

/// One elastic Hertz impact without gravity (physics.md section 4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElasticImpact {
    /// Maximum overlap u_max (m).
    pub max_overlap_m: f64,
    /// Peak force P_max (N).
    pub peak_force_n: f64,
    /// Contact time t_H (s).
    pub contact_time_s: f64,
    /// Largest contact radius a_max (m).
    pub max_contact_radius_m: f64,
}

/// Elastic impact of a body of (effective) mass `m` approaching at normal speed `v0` against a
/// Hertz contact of stiffness `k` and effective radius `r_star`.
pub fn elastic_impact(mass_kg: f64, v0_m_s: f64, k: f64, r_star_m: f64) -> ElasticImpact {
    let u_max = (5.0 * mass_kg * v0_m_s * v0_m_s / (4.0 * k)).powf(0.4);
    ElasticImpact {
        max_overlap_m: u_max,
        peak_force_n: k * u_max.powf(1.5),
        contact_time_s: 2.0 * HERTZ_TIME_INTEGRAL * u_max / v0_m_s,
        max_contact_radius_m: (r_star_m * u_max).sqrt(),
    }
}

/// Elastic contact time of the impact that reaches overlap `u_max_m` on a Hertz contact of
/// stiffness `k` with (effective) mass `m`: t_H = 2 * 1.4716 u_max / v0 with v0 from the energy
/// balance, i.e. 3.2906 sqrt(m / (k sqrt(u_max))). For a resting contact at overlap u this is the
/// time scale of its normal oscillation (its linearised stiffness is 1.5 k sqrt(u)).
pub fn contact_time_at_overlap(mass_kg: f64, k: f64, u_max_m: f64) -> f64 {
    let c = 2.0 * HERTZ_TIME_INTEGRAL / 0.8f64.sqrt();
    c * (mass_kg / (k * u_max_m.sqrt())).sqrt()
}

/// Reduced mass of two bodies, m1 m2 / (m1 + m2); an infinite mass gives the other one.
pub fn reduced_mass(m1: f64, m2: f64) -> f64 {
    if m2.is_infinite() {
        m1
    } else if m1.is_infinite() {
        m2
    } else {
        m1 * m2 / (m1 + m2)
    }
}

/// Slip-to-roll on a flat plate for a uniform solid sphere (physics.md section 6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlipToRoll {
    /// Time until rolling starts (s).
    pub time_s: f64,
    /// Centre speed once rolling (m/s).
    pub speed_m_s: f64,
    /// Distance the contact point slides over the plate (m).
    pub slide_distance_m: f64,
    /// Distance the centre travels while sliding (m).
    pub centre_travel_m: f64,
}

/// Slip-to-roll closed forms: `v0` centre speed, `w0` spin (positive rolls along v0), rolling
/// radius `r` (use R - u for the tightest comparisons), friction `mu`, gravity `g`.
pub fn slip_to_roll(v0: f64, w0: f64, r: f64, mu: f64, g: f64) -> SlipToRoll {
    let s0 = v0 - r * w0;
    let t = 2.0 * s0.abs() / (7.0 * mu * g);
    SlipToRoll {
        time_s: t,
        speed_m_s: (5.0 * v0 + 2.0 * r * w0) / 7.0,
        slide_distance_m: s0.abs() * t / 2.0,
        centre_travel_m: v0 * t - s0.signum() * mu * g * t * t / 2.0,
    }
}

/// Slip-to-roll with the true lever arm: the slip s = v - rho w of a sphere of radius `r` whose
/// contact point lies at `rho` = R - u from its centre decelerates at mu g (1 + m rho^2 / I),
/// I = 2/5 m R^2. With rho = R this is [`slip_to_roll`]; the Hertz sag makes rho about 0.5 % shorter
/// for the paper's apple, which lengthens the slide by about 0.7 % (physics.md section 6).
pub fn slip_to_roll_with_lever(v0: f64, w0: f64, r: f64, rho: f64, mu: f64, g: f64) -> SlipToRoll {
    let s0 = v0 - rho * w0;
    let kappa = 1.0 + 2.5 * (rho / r).powi(2);
    let t = s0.abs() / (mu * g * kappa);
    SlipToRoll {
        time_s: t,
        speed_m_s: v0 - s0 / kappa,
        slide_distance_m: s0.abs() * t / 2.0,
        centre_travel_m: v0 * t - s0.signum() * mu * g * t * t / 2.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_rapier_notes_reference() {
        // rapier-notes.md: 0.107 kg, k = 7.1545e5: u_max 0.56171 mm, Pmax 9.5245 N, t_c 8.2661 ms
        // at 0.2 m/s; 2.66435 mm, 98.392 N, 5.6012 ms at 1.4 m/s.
        let a = elastic_impact(0.107, 0.2, 7.1545e5, 0.04);
        assert!((a.max_overlap_m - 0.56171e-3).abs() / 0.56171e-3 < 1e-4);
        assert!((a.peak_force_n - 9.5245).abs() / 9.5245 < 1e-4);
        assert!((a.contact_time_s - 8.2661e-3).abs() / 8.2661e-3 < 1e-4);
        let b = elastic_impact(0.107, 1.4, 7.1545e5, 0.04);
        assert!((b.peak_force_n - 98.392).abs() / 98.392 < 1e-4);
        assert!((b.contact_time_s - 5.6012e-3).abs() / 5.6012e-3 < 1e-4);
        // The same contact time from the overlap it reaches.
        let t2 = contact_time_at_overlap(0.107, 7.1545e5, b.max_overlap_m);
        assert!((t2 - b.contact_time_s).abs() / b.contact_time_s < 1e-7);
        // k_P = impulse / (P_max t_H).
        let kp = 2.0 * 0.107 * 0.2 / (a.peak_force_n * a.contact_time_s);
        assert!((kp - ELASTIC_PULSE_COEFFICIENT).abs() < 1e-6);
    }

    #[test]
    fn slip_to_roll_belt_rule() {
        // An apple at rest on a belt moving at V is, in the belt frame, an apple sliding at -V.
        let s = slip_to_roll(-1.0, 0.0, 0.04, 0.3, 9.81);
        assert!((s.time_s - 2.0 / (7.0 * 0.3 * 9.81)).abs() < 1e-15);
        assert!((s.speed_m_s + 5.0 / 7.0).abs() < 1e-15);
    }
}
