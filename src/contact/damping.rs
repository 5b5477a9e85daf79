//! Energy loss in the normal direction: the paper's eq. 12 with the dissipative sign
//! (physics.md section 3), a variant of it whose resting contact carries the full Hertz force,
//! and the viscoelastic Hertz damping of LIGGGHTS `model hertz` / EDEM Hertz-Mindlin
//! ([`DampingModel`]; docs/physics.md section 11 compares them).
//!
//! Eq. 12: P(u, du/dt) = P_hertz(u) [1 + ke + (1 - ke) tanh(lambda du/dt)] / 2, du/dt > 0
//! approaching. Loading follows the elastic curve, unloading the curve scaled by ke, so the stored
//! energy comes back multiplied by ke and e -> sqrt(ke) when lambda v0 >> 1. The paper prints
//! tanh(-lambda du/dt), which creates energy (e = 1/sqrt(ke), erratum 4); never use it.

/// The eq. 12 factor multiplying the Hertz force. Lies in [min(ke,1), max(ke,1)], never negative.
///
/// `du_dt_m_s` is the rate of overlap (> 0 while the bodies approach). `ke = 1` is elastic.
pub fn hysteresis_factor(ke: f64, lambda_s_m: f64, du_dt_m_s: f64) -> f64 {
    if ke == 1.0 {
        return 1.0;
    }
    let f = 0.5 * (1.0 + ke + (1.0 - ke) * (lambda_s_m * du_dt_m_s).tanh());
    f.max(0.0)
}

/// The eq. 12 normal force for an elastic Hertz force `hertz_n`, with the rate-dependent part
/// bounded for explicit stepping.
///
/// Eq. 12 splits into a static part H (1 + ke)/2 and a rate part R = H (1 - ke)/2 tanh(lambda s),
/// s = du/dt. Near s = 0, R is a damper of slope (1 - ke)/2 lambda H: for an apple at the bottom
/// of a pile (H ~ 150 N, lambda = 1000 s/m) ~7e4 N s/m, c dt / m ~ 30 at dt = 1e-4 s, far beyond the
/// explicit stability limit (~2): stepped explicitly, the force flips between ke H and H every step
/// and a pile chatters at cm/s (measured; tests/regression_pile_chatter.rs). For resting contacts the
/// caller therefore passes `kill_rate`, a share of m_n / dt (the rate that stops the relative normal
/// motion within one step), and R is bounded by kill_rate |s|: the velocity-kill regularisation of
/// a Coulomb-like law, as for the friction dashpot. Exact eq. 12 once |s| > (1 - ke)/2 H / kill_rate,
/// a stable damper below. Impacts get `kill_rate` = infinity: an impact passes its turn once, and
/// the bound would bias it (measured at dt = 2e-4 s: a chute landing's restitution up 10 %, its
/// contact 7-14 % short). Alternatives tried and measured: a linearised implicit form (a loaded
/// column still chatters at 2 cm/s), a bound only after sign changes (1 cm/s).
/// `du_dt_next_m_s` is the rate expected at the end of the coming step: the factor is averaged
/// over the step (see [`step_mean_tanh`]); pass `du_dt_m_s` again to evaluate at the pose.
/// Never negative: the result lies between ke H and H.
#[inline]
pub fn hysteresis_force(
    hertz_n: f64,
    ke: f64,
    lambda_s_m: f64,
    du_dt_m_s: f64,
    du_dt_next_m_s: f64,
    kill_rate: f64,
) -> f64 {
    if ke == 1.0 {
        return hertz_n;
    }
    let static_part = 0.5 * (1.0 + ke) * hertz_n;
    let amplitude = 0.5 * (1.0 - ke) * hertz_n;
    let bound = kill_rate * du_dt_m_s.abs();
    if bound < amplitude && bound_bites(amplitude, bound, lambda_s_m, du_dt_m_s, du_dt_next_m_s) {
        // The result does not depend on the mean of tanh: skip its logarithms.
        return (static_part + bound * du_dt_m_s.signum()).max(0.0);
    }
    let mut rate_part = amplitude * step_mean_tanh(lambda_s_m, du_dt_m_s, du_dt_next_m_s);
    if rate_part.abs() > bound {
        rate_part = bound * du_dt_m_s.signum();
    }
    (static_part + rate_part).max(0.0)
}

/// Whether the rate part `amplitude` * mean tanh is certainly larger than `bound` in magnitude,
/// from a lower bound of the mean alone (no exponentials): when s1 and s2 have one sign the mean of
/// tanh over the ramp is at least tanh(m) >= m / (1 + m), m = lambda min(|s1|, |s2|); 0.1 % is
/// kept in hand so that the shortcut is taken only where the full computation clamps too, and
/// gives the same bits. Resting contacts in a loaded pile take it most of the time.
fn bound_bites(amplitude: f64, bound: f64, lambda_s_m: f64, s1: f64, s2: f64) -> bool {
    if s1 * s2 <= 0.0 {
        return false;
    }
    let m = lambda_s_m * s1.abs().min(s2.abs());
    0.999 * amplitude * m > bound * (1.0 + m)
}

/// ln cosh(x2) - ln cosh(x1), without overflow and with one logarithm:
/// ln cosh x = |x| + ln(1 + e^(-2|x|)) - ln 2, and the two ln(1 + e) terms combine into
/// ln(1 + (e2 - e1) / (1 + e1)). e^(-2|x|) is below 1e-17 past |x| = 20: taken as 0 there.
fn ln_cosh_difference(x1: f64, x2: f64) -> f64 {
    let e = |x: f64| {
        let a = x.abs();
        if a > 20.0 {
            0.0
        } else {
            (-2.0 * a).exp()
        }
    };
    let (e1, e2) = (e(x1), e(x2));
    x2.abs() - x1.abs() + ((e2 - e1) / (1.0 + e1)).ln_1p()
}

/// Mean of tanh(lambda s) while s moves linearly from `s1` to `s2` over a step.
///
/// Eq. 12 switches from loading to unloading within |s| < 1/lambda, microseconds in an impact, while
/// the step lasts tenths of a millisecond: evaluated at the pose alone, the step that contains the
/// turn applies the loading force throughout, half a step too long on average, which kicks the
/// apple out early (measured: at 40 steps per contact a 0.79 m/s impact with ke = 0.09 was 10 %
/// short, e 3 % high). The mean over the step puts the switch at its right time within the step.
#[inline]
pub fn step_mean_tanh(lambda_s_m: f64, s1: f64, s2: f64) -> f64 {
    let (x1, x2) = (lambda_s_m * s1, lambda_s_m * s2);
    // Saturated on one side all along (tanh within 1e-17 of +-1): no logarithms needed.
    if x1.min(x2) > 20.0 {
        return 1.0;
    }
    if x1.max(x2) < -20.0 {
        return -1.0;
    }
    let d = lambda_s_m * (s2 - s1);
    // A small change within the step (a resting contact): the midpoint value, within d^2 / 15 of
    // the mean (2e-4 at d = 0.05), without logarithms.
    if d.abs() < 0.05 {
        return (lambda_s_m * 0.5 * (s1 + s2)).tanh();
    }
    ln_cosh_difference(x1, x2) / d
}

/// Which normal energy-loss sub-model a pair of materials uses.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub enum DampingModel {
    /// The paper's eq. 12 (ke, lambda). At rest it carries (1 + ke) / 2 of the Hertz force.
    #[default]
    Eq12,
    /// Eq. 12 loading on the elastic curve and unloading on the ke curve, with the rate part only
    /// while unloading: P = H [1 - (1 - ke) tanh(lambda max(-du/dt, 0))]. The same restitution
    /// sqrt(ke) when lambda v0 >> 1, and the full Hertz force at rest (a resting apple sags as
    /// elastic Hertz says, (m g / k)^(2/3)).
    Eq12ElasticRest,
    /// Viscoelastic Hertz (LIGGGHTS `model hertz`, EDEM Hertz-Mindlin): P = k u^(3/2) + c du/dt
    /// with c = 2 sqrt(5/6) |beta| sqrt(2 E* sqrt(R* u) m*), beta = ln e / sqrt(ln^2 e + pi^2),
    /// e the coefficient of restitution given; never pulling (LIGGGHTS `limitForce on`).
    Viscoelastic,
}

/// sqrt(5/6), the factor of LIGGGHTS's (and Tsuji's) Hertzian damping coefficient.
pub const SQRT_FIVE_SIXTHS: f64 = 0.912_870_929_175_276_9;

/// LIGGGHTS's damping ratio of a coefficient of restitution `e` in (0, 1]:
/// beta = ln e / sqrt(ln^2 e + pi^2) (<= 0; 0 when elastic).
pub fn beta_of_restitution(e: f64) -> f64 {
    let l = e.ln();
    l / (l * l + std::f64::consts::PI * std::f64::consts::PI).sqrt()
}

/// The damping coefficient of LIGGGHTS's viscoelastic Hertz at overlap `u`:
/// c = -2 sqrt(5/6) beta sqrt(S_n m*), S_n = 2 E* sqrt(R* u) (N s/m). `sqrt_r_star_u` is
/// sqrt(R* u), the contact radius.
#[inline]
pub fn viscoelastic_coefficient(beta: f64, e_star_pa: f64, sqrt_r_star_u: f64, m_eff: f64) -> f64 {
    -2.0 * SQRT_FIVE_SIXTHS * beta * (2.0 * e_star_pa * sqrt_r_star_u * m_eff).sqrt()
}

/// The viscoelastic Hertz normal force: elastic `hertz_n` plus `coefficient` du/dt, never
/// negative.
#[inline]
pub fn viscoelastic_force(hertz_n: f64, coefficient: f64, du_dt_m_s: f64) -> f64 {
    (hertz_n + coefficient * du_dt_m_s).max(0.0)
}

/// The normal force of [`DampingModel::Eq12ElasticRest`] for an elastic Hertz force `hertz_n`:
/// H [1 - (1 - ke) g], g the mean over the step of tanh(lambda max(-du/dt, 0)) (see
/// [`step_mean_tanh`]); the rate part, which only lowers the force while unloading, is bounded by
/// `kill_rate` |du/dt| for resting contacts as in [`hysteresis_force`]. Lies in [ke H, H].
#[inline]
pub fn elastic_rest_force(
    hertz_n: f64,
    ke: f64,
    lambda_s_m: f64,
    du_dt_m_s: f64,
    du_dt_next_m_s: f64,
    kill_rate: f64,
) -> f64 {
    if ke == 1.0 || (du_dt_m_s >= 0.0 && du_dt_next_m_s >= 0.0) {
        return hertz_n;
    }
    let amplitude = (1.0 - ke) * hertz_n;
    // Mean of tanh(lambda min(s, 0)) while s moves linearly from s1 to s2: the unloading part of
    // the step only (the antiderivative ln cosh(lambda min(s, 0)) / lambda is flat for s > 0).
    let (s1, s2) = (du_dt_m_s.min(0.0), du_dt_next_m_s.min(0.0));
    let d = lambda_s_m * (du_dt_next_m_s - du_dt_m_s);
    let mean = if d.abs() < 0.05 {
        (lambda_s_m * 0.5 * (du_dt_m_s + du_dt_next_m_s).min(0.0)).tanh()
    } else {
        ln_cosh_difference(lambda_s_m * s1, lambda_s_m * s2) / d
    };
    let rate_part = (amplitude * mean).max(-kill_rate * du_dt_m_s.abs());
    (hertz_n + rate_part).max(0.0)
}

/// Restitution in the limit lambda v0 >> 1: e = sqrt(ke).
pub fn restitution_limit(ke: f64) -> f64 {
    ke.sqrt()
}

/// Contact time with hysteresis in the limit lambda v0 >> 1: t_c = t_H / 2 (1 + 1/sqrt(ke)).
pub fn contact_time_limit(t_hertz_s: f64, ke: f64) -> f64 {
    0.5 * t_hertz_s * (1.0 + 1.0 / ke.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factor_limits() {
        assert_eq!(hysteresis_factor(1.0, 100.0, -5.0), 1.0);
        // Fast loading: plain Hertz; fast unloading: ke times Hertz.
        assert!((hysteresis_factor(0.09, 1000.0, 1.0) - 1.0).abs() < 1e-12);
        assert!((hysteresis_factor(0.09, 1000.0, -1.0) - 0.09).abs() < 1e-12);
        // At the turning point (du/dt = 0) the factor is (1 + ke) / 2.
        assert!((hysteresis_factor(0.25, 10.0, 0.0) - 0.625).abs() < 1e-15);
        for &v in &[-10.0, -0.1, 0.0, 0.1, 10.0] {
            let f = hysteresis_factor(0.0, 50.0, v);
            assert!((0.0..=1.0).contains(&f));
        }
    }

    #[test]
    fn bounded_rate_part_only_bites_near_rest() {
        // Fast motion: the bound is far above the paper's force, eq. 12 unchanged.
        let h = 100.0;
        let kill = 0.107 / 1e-5;
        for v in [-1.0, -0.1, 0.1, 1.0] {
            let paper = h * hysteresis_factor(0.09, 1000.0, v);
            assert!((hysteresis_force(h, 0.09, 1000.0, v, v, kill) - paper).abs() < 1e-9);
        }
        // At rest: the static part (1 + ke)/2 H, reached continuously.
        assert!((hysteresis_force(h, 0.09, 1000.0, 0.0, 0.0, kill) - 54.5).abs() < 1e-12);
        let tiny = hysteresis_force(h, 0.09, 1000.0, 1e-6, 1e-6, kill);
        assert!((tiny - 54.5 - kill * 1e-6).abs() < 1e-9, "{tiny}");
        // Bounded by ke H and H whatever the bound.
        for v in [-10.0, 10.0] {
            let f = hysteresis_force(h, 0.09, 1000.0, v, v, f64::INFINITY);
            assert!((9.0 - 1e-9..=100.0 + 1e-9).contains(&f));
        }
    }

    #[test]
    fn step_mean_of_tanh() {
        // Far from the switch: the plain value; across it: the share of the step on each side.
        assert!((step_mean_tanh(1000.0, 0.5, 0.4) - 1.0).abs() < 1e-12);
        let m = step_mean_tanh(1000.0, 0.03, -0.01); // a quarter of the step after the turn
        assert!((m - 0.5).abs() < 1e-3, "{m}");
        let exact = |a: f64, b: f64| {
            let n = 100_000;
            (0..n)
                .map(|i| (1000.0 * (a + (b - a) * (i as f64 + 0.5) / n as f64)).tanh())
                .sum::<f64>()
                / n as f64
        };
        for (a, b) in [(0.002, -0.001), (0.0, 0.01), (-0.3, 0.2)] {
            assert!((step_mean_tanh(1000.0, a, b) - exact(a, b)).abs() < 1e-6);
        }
        // Small changes use the midpoint: within 2e-4 of the mean.
        for (a, b) in [(0.0, 4e-5), (1e-3, 1.04e-3), (-2e-4, -1.6e-4)] {
            assert!((step_mean_tanh(1000.0, a, b) - exact(a, b)).abs() < 2e-4);
        }
    }

    #[test]
    fn ln_cosh_difference_matches_the_direct_formula() {
        let ln_cosh = |x: f64| {
            let a = x.abs();
            a + (-2.0 * a).exp().ln_1p() - std::f64::consts::LN_2
        };
        for (a, b) in [
            (0.1, 0.3),
            (-2.0, 5.0),
            (19.5, 21.0),
            (-30.0, 0.2),
            (3.0, -3.0),
            (0.0, 1e-3),
        ] {
            let direct = ln_cosh(b) - ln_cosh(a);
            assert!((ln_cosh_difference(a, b) - direct).abs() < 1e-13, "{a} {b}");
        }
    }

    #[test]
    fn bound_shortcut_gives_the_same_bits() {
        // The shortcut returns the clamped value only where the full computation clamps as well.
        let full = |h: f64, s1: f64, s2: f64, kill: f64| {
            let static_part = 0.5 * 1.09 * h;
            let mut rate = 0.5 * 0.91 * h * step_mean_tanh(1000.0, s1, s2);
            let bound = kill * s1.abs();
            if rate.abs() > bound {
                rate = bound * s1.signum();
            }
            (static_part + rate).max(0.0)
        };
        let mut taken = 0;
        for h in [0.1, 3.0, 50.0, 400.0] {
            for s1 in [-0.05, -2e-3, -1e-4, -1e-7, 1e-7, 1e-4, 2e-3, 0.05] {
                for ds in [-0.01, -1e-4, 0.0, 1e-4, 0.01] {
                    for kill in [10.0, 300.0, 1e4, 1e6] {
                        let s2 = s1 + ds;
                        if 0.5 * 0.91 * h > kill * f64::abs(s1)
                            && bound_bites(0.5 * 0.91 * h, kill * s1.abs(), 1000.0, s1, s2)
                        {
                            taken += 1;
                        }
                        let got = hysteresis_force(h, 0.09, 1000.0, s1, s2, kill);
                        assert_eq!(
                            got.to_bits(),
                            full(h, s1, s2, kill).to_bits(),
                            "{h} {s1} {s2} {kill}"
                        );
                    }
                }
            }
        }
        assert!(taken > 100, "the shortcut was exercised {taken} times");
    }

    #[test]
    fn dissipative_sign() {
        // Unloading (du/dt < 0) must give less force than loading at the same overlap.
        let load = hysteresis_factor(0.3, 20.0, 0.2);
        let unload = hysteresis_factor(0.3, 20.0, -0.2);
        assert!(unload < load);
    }
}
