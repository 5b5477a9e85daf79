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
    t_stick: f64,
    h_damping: f64,
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
    (
        (theory::contact_time_at_overlap(m_n, k, u_eff).min(t_stick)
            / (0.25 * c.steps_per_contact).max(4.0))
        .min(h_damping),
        StepLimit::Resting,
    )
}

/// The longest stable step of an explicit tangential dashpot of coefficient `gamma_t` on the
/// tangential effective mass `m_t`: gamma_t h / m_t <= 0.6 (LIGGGHTS `tangential history`
/// damps without bound; with e = 0.3 its damping ratio is 0.61, and at the resting steps of
/// `preview` (gamma_t h / m_t = 0.96) the 1000-apple pile jiggled with every apple awake in
/// 3-5 s; both LIGGGHTS and applesim settle at a fixed 5e-4 s (0.67) and jiggle at 6e-4 s
/// (0.81); docs/liggghts_models.md). Infinite without damping.
pub(super) fn damping_step(gamma_t: f64, m_t: f64) -> f64 {
    if gamma_t > 0.0 {
        0.6 * m_t / gamma_t
    } else {
        f64::INFINITY
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
    t_stick: f64,
    h_damping: f64,
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
        t_stick,
        h_damping,
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
