//! Adaptive step control: the longest next step that resolves the contacts in progress and those
//! about to start (see [`super::StepControl`]). Pure functions of one contact's figures.

use super::clock::StepLimit;
use super::config::StepControl;
use crate::contact::theory;
use crate::record::events::OpenContact;

/// Time until a gap closes, if within `horizon` (s): the smallest h > 0 with
/// (closing + accel h) h >= gap. Rapier's symplectic Euler moves a body by its kicked velocity
/// v + a h over the whole step, so a step planned from the current closing speed alone overshoots
/// the touch (measured: a 6.9 ms step onto a belt started the contact at half its peak overlap).
pub(super) fn time_to_touch(gap: f64, closing: f64, accel: f64, horizon: f64) -> Option<f64> {
    let gap = gap.max(0.0);
    if (closing + accel * horizon) * horizon < gap {
        return None;
    }
    // Stable root of accel h^2 + closing h - gap = 0 (accel >= 0; the test above guarantees a
    // root in (0, horizon]).
    let disc = (closing * closing + 4.0 * accel * gap).sqrt();
    let h = if closing >= 0.0 {
        2.0 * gap / (closing + disc)
    } else {
        (disc - closing) / (2.0 * accel)
    };
    (h.is_finite() && closing + accel * h > 0.0).then_some(h)
}

/// Elastic contact time and maximum overlap of an impact at approach speed `v` (zeros for v <= 0).
pub(super) fn impact_scale(m_n: f64, k: f64, v: f64) -> (f64, f64) {
    if v > 0.0 {
        let u = (5.0 * m_n * v * v / (4.0 * k)).powf(0.4);
        (2.0 * theory::HERTZ_TIME_INTEGRAL * u / v, u)
    } else {
        (0.0, 0.0)
    }
}

/// With step control: the longest step that resolves a contact in progress (see
/// [`StepControl`]). `u` overlap, `impact` = (contact time, max overlap) of its impact at the
/// approach speed (see [`impact_scale`]), `rate` current du/dt (> 0 approaching), `unloading_ke`
/// the eq. 12 ke of the pair (1 when elastic), `age` time since first touch. An impact (younger
/// than 1.2 times eq. 12's contact time, (1 + 1/sqrt(ke)) / 2 elastic ones) gets N steps per
/// contact time of an impact reaching max(u, u_max), and while it separates N steps per contact
/// time of its softer unloading curve (ke k); a resting contact after that gets
/// N/4 (at least 4) per contact time at max(u, u_max(s)): its normal oscillation, which needs
/// resolving only for stability (omega dt = 4 / steps; explicit stepping is stable below 2), and
/// as many per half period `t_stick` of its tangential stick spring, which for two free apples
/// oscillates 2.5 times faster than the normal one (k_t = 8 G* a against dP/du = 2 E* a, on a
/// seventh of the mass): with the normal time alone, 4 steps put the stick spring at omega dt = 2,
/// the edge of stability, and a settled pile rattled at 1-2 cm/s and never slept (measured on the
/// 1000-apple pile at `preview`: 973 of 1000 apples awake at 3 s, against 34 at `balanced`).
#[allow(clippy::too_many_arguments)]
pub(super) fn contact_step_limit(
    c: &StepControl,
    m_n: f64,
    k: f64,
    u: f64,
    impact: (f64, f64),
    rate: f64,
    unloading_ke: f64,
    age: f64,
    tangential: impl FnOnce() -> f64,
) -> (f64, StepLimit) {
    let (t_a, u_a) = impact;
    let s = rate.abs();
    // An impact lasts (1 + 1/sqrt(ke)) / 2 elastic contact times with eq. 12 (physics.md section
    // 3); 20 % more covers the lower speeds' longer contacts.
    let window = 1.2 * t_a * 0.5 * (1.0 + 1.0 / unloading_ke.max(1e-4).sqrt());
    if age < window {
        let mut t = if u > u_a {
            theory::contact_time_at_overlap(m_n, k, u)
        } else {
            t_a
        };
        if rate < 0.0 && unloading_ke < 1.0 {
            // Separating: eq. 12 unloads along ke times the Hertz curve, a contact of stiffness
            // ke k, whose time scale is 1 / sqrt(ke) longer; N steps of that scale resolve it.
            t /= unloading_ke.max(1e-4).sqrt();
        }
        return (t / c.steps_per_contact, StepLimit::Impact);
    }
    // u_max(s) > u  <=>  5 m s^2 / (4 k) > u^(5/2): compared without powers.
    let u_eff = if 1.25 * m_n * s * s / k > u * u * u.sqrt() {
        impact_scale(m_n, k, s).1
    } else {
        u
    };
    let t_stick = tangential();
    (resting_step(c, m_n, k, u_eff, t_stick), StepLimit::Resting)
}

/// The step limit of a resting contact at effective overlap `u_eff` (see
/// [`contact_step_limit`]): N/4 (at least 4) steps per contact time at `u_eff` and per half
/// period `t_stick` of the stick spring. Both terms fall as the overlap grows. The dashpots set
/// no limit: each is bounded by a share of the rate that stops its contact's motion within a
/// step, shared among the apple's contacts (`contact::evaluate`; LIGGGHTS's `history` dashpot at
/// `crate::contact::HISTORY_DASHPOT_BOUND`), so none grows at the steps the stick spring allows.
fn resting_step(c: &StepControl, m_n: f64, k: f64, u_eff: f64, t_stick: f64) -> f64 {
    theory::contact_time_at_overlap(m_n, k, u_eff).min(t_stick)
        / (0.25 * c.steps_per_contact).max(4.0)
}

/// A lower bound of a resting contact's step limit, good while its overlap stays at or below
/// `u_m` and its overlap rate's square at or below `rate2` (so that its impact overlap at that
/// rate stays at or below `u_m` too).
///
/// Why: with step control, every touching pair asks for its limit at every step, and a resting
/// contact's costs several square roots (its contact time, the stick spring's half period),
/// while only the shortest limit sets the step. Each term is a
/// monotone function of the overlap (rounded operations that never rise as it grows:
/// `sqrt`, products and quotients of positive numbers), so the limit at a slightly larger
/// overlap bounds it from below for as long as the overlap stays under it; detection skips the
/// exact limit of a contact whose bound already exceeds the shortest limit offered before it. The
/// step is the same, bit for bit: a skipped contact could not have set it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestingBound {
    /// Largest overlap covered (m); NaN: no bound.
    pub u_m: f64,
    /// Largest square of the overlap rate covered (m^2/s^2).
    pub rate2: f64,
    /// The bound (s).
    pub dt_s: f64,
}

impl RestingBound {
    /// No bound yet: covers nothing.
    pub const NONE: Self = Self {
        u_m: f64::NAN,
        rate2: f64::NAN,
        dt_s: f64::NAN,
    };

    /// Whether the bound holds at overlap `u` and overlap rate `rate`.
    #[inline]
    pub fn covers(&self, u: f64, rate: f64) -> bool {
        u <= self.u_m && rate * rate <= self.rate2
    }

    /// Whether the exact limit at overlap `u` and rate `rate` may be skipped: the bound holds
    /// there and exceeds `best`, a limit already offered, so the exact one cannot set the step.
    #[inline]
    pub fn skips(&self, best: f64, u: f64, rate: f64) -> bool {
        self.dt_s > best && self.covers(u, rate)
    }

    /// After an exact resting limit at overlap `u` and rate `rate`: a new bound from there
    /// unless the one held still covers them (arguments as [`Self::new`]).
    pub(super) fn refresh(
        &mut self,
        c: &StepControl,
        m_n: f64,
        k: f64,
        u: f64,
        rate: f64,
        tangential: impl FnOnce(f64) -> f64,
    ) {
        if !self.covers(u, rate) {
            *self = Self::new(c, m_n, k, u, tangential);
        }
    }

    /// The bound over overlaps up to `u` (1 + 1/64) (0.4 % below the limit at `u`; detection
    /// makes a new one when the overlap or its rate passes it) for the pair's normal mass
    /// `m_n` and stiffness `k`; `tangential(u)` gives the stick spring's half period at overlap
    /// `u`, as the exact limit takes it.
    pub(super) fn new(
        c: &StepControl,
        m_n: f64,
        k: f64,
        u: f64,
        tangential: impl FnOnce(f64) -> f64,
    ) -> Self {
        let u_m = u * (1.0 + 1.0 / 64.0);
        // Rates whose impact overlap stays within u_m: 5 m s^2 / (4 k) <= u_m^(5/2), the test of
        // `contact_step_limit`; its power is rounded, so the contact time is taken at an overlap
        // 1e-9 larger still.
        let rate2 = u_m * u_m * u_m.sqrt() * k / (1.25 * m_n);
        let t_stick = tangential(u_m);
        Self {
            u_m,
            rate2,
            dt_s: resting_step(c, m_n, k, u_m * (1.0 + 1e-9), t_stick),
        }
    }
}

/// Half period pi sqrt(m_t / k_t) of a contact's tangential stick spring k_t = 8 G* a at overlap
/// `u` (a = sqrt(R* u)), on the tangential effective mass `m_t`; infinite without friction.
pub(super) fn stick_half_period(g_star_pa: f64, r_star_m: f64, u: f64, m_t: f64) -> f64 {
    let k_t = crate::contact::friction::mindlin_stiffness(g_star_pa, (r_star_m * u).sqrt());
    if k_t > 0.0 {
        std::f64::consts::PI * (m_t / k_t).sqrt()
    } else {
        f64::INFINITY
    }
}

/// The step limit of a contact in progress (see [`contact_step_limit`]), from its record when it
/// has one (approach speed, start time), else from the current overlap rate as a new contact.
#[allow(clippy::too_many_arguments)]
pub(super) fn limit_in_contact(
    c: &StepControl,
    record: Option<&mut OpenContact>,
    m_n: f64,
    k: f64,
    u: f64,
    rate: f64,
    unloading_ke: f64,
    time_s: f64,
    tangential: impl FnOnce() -> f64,
) -> (f64, StepLimit) {
    let (scale, start) = match record {
        Some(o) => (
            o.impact_scale(|v| impact_scale(m_n, k, v)),
            o.start_time_s(),
        ),
        None => (impact_scale(m_n, k, rate), time_s),
    };
    contact_step_limit(
        c,
        m_n,
        k,
        u,
        scale,
        rate,
        unloading_ke,
        time_s - start,
        tangential,
    )
}

/// With step control: the longest step in which no awake apple moves more than the pair-finding
/// margins (`max_displacement_m`, and half the grid's skin: two apples closing at up to 2 v_max
/// must not cross the skin of the list unseen). `None` when nothing moves or the skin is not known
/// yet (sources may add the first apples late). Centres only: spin moves no centre.
pub(super) fn motion_limit(
    c: &StepControl,
    awake: &[u32],
    vel: &[crate::math::Vec3],
    skin_m: f64,
) -> Option<f64> {
    let mut v_max: f64 = 0.0;
    for &k in awake {
        v_max = v_max.max(vel[k as usize].length());
    }
    let reach = c.max_displacement_m.min(0.5 * skin_m);
    (v_max > 0.0 && reach > 0.0).then(|| reach / v_max)
}

/// With step control: the longest step in which no moving part moves more than the pair-finding
/// margins either (`surface_speed_m_s` its fastest point): a part is seen coming, by the apples
/// near it and by the sleepers it wakes. Without this a wall at 5 m/s moved 50 mm per 10 ms
/// step and passed through a sleeping apple unseen, at `preview` and `precise`. Taken apart
/// from the apples' limit (not added to their speed), so a slow part (a bin lowered at 13 mm/s)
/// changes no step. `None` when no part moves.
pub(super) fn surface_motion_limit(
    c: &StepControl,
    surface_speed_m_s: f64,
    skin_m: f64,
) -> Option<f64> {
    let reach = c.max_displacement_m.min(0.5 * skin_m);
    (surface_speed_m_s > 0.0 && reach > 0.0).then(|| reach / surface_speed_m_s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::theory::reduced_mass;

    /// Two 80 mm apples of the paper (G 1.1 MPa, nu 0.18, 800 kg/m^3): normal mass, Hertz
    /// stiffness, and the stick spring's half period at an overlap.
    fn pair() -> (f64, f64, impl Fn(f64) -> f64) {
        let (r, g, nu) = (0.04, 1.1e6, 0.18);
        let m = 800.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
        let e_star = 2.0 * g * (1.0 + nu) / (2.0 * (1.0 - nu * nu));
        let g_star = g / (2.0 * (2.0 - nu));
        let r_star = r / 2.0;
        let m_n = reduced_mass(m, m);
        let k = crate::contact::normal::stiffness(e_star, r_star);
        // A sphere's own tangential mass 2 m / 7; two of them in series.
        let m_t = m / 7.0;
        let tangential = move |u: f64| stick_half_period(g_star, r_star, u, m_t);
        (m_n, k, tangential)
    }

    fn resting(
        c: &StepControl,
        m_n: f64,
        k: f64,
        u: f64,
        rate: f64,
        t: &impl Fn(f64) -> f64,
    ) -> f64 {
        let impact = impact_scale(m_n, k, 0.5);
        let (dt, why) = contact_step_limit(c, m_n, k, u, impact, rate, 0.09, 1.0, || t(u));
        assert_eq!(why, StepLimit::Resting);
        dt
    }

    /// The bound lies below the exact limit everywhere it covers (overlaps up to 1/64 above the
    /// one it was made at, rates up to the one whose impact reaches that overlap), by the closed
    /// form at its own overlap: every term goes as u^(-1/4) (the contact time as 1 / sqrt(k
    /// sqrt(u)); the stick spring's half period as 1 / sqrt(k_t), k_t = 8 G* sqrt(R* u)), so it
    /// is (65/64)^(-1/4) of the limit at the overlap it was made at.
    #[test]
    fn a_resting_bound_is_below_every_limit_it_covers() {
        let (m_n, k, tangential) = pair();
        for n in [10.0, 20.0, 40.0] {
            let c = StepControl {
                steps_per_contact: n,
                max_displacement_m: 0.01,
            };
            for u in [1e-5, 1e-4, 1e-3, 3e-3] {
                let b = RestingBound::new(&c, m_n, k, u, &tangential);
                let exact = resting(&c, m_n, k, u, 0.0, &tangential);
                let ratio = b.dt_s / exact;
                let expected = (65.0f64 / 64.0).powf(-0.25);
                assert!(
                    (ratio - expected).abs() < 1e-8,
                    "N {n}, u {u}: bound / limit {ratio}, closed form {expected}"
                );
                // Over what it covers, down to half the overlap and from rest to the largest rate.
                let top = b.rate2.sqrt() * (1.0 - 1e-12);
                for f in [0.5, 0.9, 1.0, 1.0 + 1.0 / 128.0, 1.0 + 1.0 / 64.0] {
                    let u2 = (u * f).min(b.u_m);
                    for rate in [0.0, 0.5 * top, -0.9 * top, top, -top] {
                        assert!(b.covers(u2, rate));
                        let dt = resting(&c, m_n, k, u2, rate, &tangential);
                        assert!(
                            b.dt_s <= dt,
                            "N {n}, u {u2}, rate {rate}: {} > {dt}",
                            b.dt_s
                        );
                    }
                }
            }
        }
    }

    /// Past its overlap or its rate, or before it is made, a bound covers nothing.
    #[test]
    fn a_resting_bound_covers_nothing_past_its_reach() {
        let (m_n, k, tangential) = pair();
        let c = StepControl {
            steps_per_contact: 10.0,
            max_displacement_m: 0.01,
        };
        let b = RestingBound::new(&c, m_n, k, 1e-4, tangential);
        assert!(b.covers(1e-4, 0.0));
        assert!(!b.covers(b.u_m * (1.0 + 1e-12), 0.0));
        assert!(!b.covers(1e-4, 1.001 * b.rate2.sqrt()));
        assert!(!RestingBound::NONE.covers(0.0, 0.0));
        // The largest rate covered is the one whose impact reaches the bound's overlap.
        let (_, u_max) = impact_scale(m_n, k, b.rate2.sqrt());
        assert!(
            (u_max / b.u_m - 1.0).abs() < 1e-12,
            "{u_max} against {}",
            b.u_m
        );
    }
}
