//! The line scenarios of issue 19 (docs/lines.md): a belt carries apples at its speed, and
//! apples poured into a bin build a heap, with the default rolling resistance (elastic-plastic,
//! mu_r = 0.03); with `"rolling": "none"` (the paper's model) the belt carries them at 2V/7 for
//! ever and the pour spreads into a single layer.
//!
//! The belt is checked against the closed form of docs/lines.md (derived there): a slip phase of
//! t1 = 2V/(7 mu g) ending at 2V/7, then rolling backwards relative to the belt while rolling
//! resistance accelerates the apple at 5/7 mu_r g, which brings it to V after V/(mu_r g). The
//! heap has no closed form (a pile is chaotic): its figures are checked within stated ranges that
//! hold over seeds (docs/lines.md gives five), not as golden values.

use crate::common;
use applesim::record::events::ContactEvent;
use applesim::record::series::MemorySeries;
use applesim::scenario::models::{Rolling, Twisting};
use applesim::scenario::Scenario;
use applesim::sim::RunResult;
use common::*;

const G: f64 = 9.81;

/// belt_conveying.json: belt speed, apple-rubber friction, default rolling friction.
const V: f64 = 0.4;
const MU: f64 = 0.5;
const MU_R: f64 = 0.03;

fn speed(v: applesim::math::Vec3) -> f64 {
    v.length()
}

/// Touch time of apple `i` on `surface` (its first contact there).
fn touch(events: &[ContactEvent], i: u32, surface: &str) -> f64 {
    events
        .iter()
        .filter(|e| e.a_index == i && &*e.b == surface)
        .map(|e| e.t_start_s)
        .fold(f64::INFINITY, f64::min)
}

fn belt_run(rolling: Option<Rolling>) -> (RunResult, MemorySeries) {
    let mut sc: Scenario = shipped("scenarios/lines/belt_conveying.json");
    if let Some(r) = rolling {
        sc.contact.rolling = r;
    }
    run(&sc)
}

/// The rolling-phase acceleration with the model's lever (docs/physics.md 11.3, a flat):
/// a = mu_r g R rho / (rho^2 + 2/5 R^2), rho = R - u c1/(c1 + c2) the contact point's distance
/// from the centre (physics.md section 5: the apple's share of the overlap), u the static sag of
/// eq. 12 at rest, k u^(3/2) (1 + ke)/2 = m g, on the line's rubber (E 5 MPa, nu 0.45) for the
/// apple-paper flesh (G 1.1 MPa, nu 0.18), ke 0.09. Written here from the docs.
fn lever_acceleration(radius_m: f64, mass_kg: f64) -> f64 {
    let c_apple = (1.0 - 0.18f64.powi(2)) / (2.0 * 1.1e6 * 1.18);
    let c_rubber = (1.0 - 0.45f64.powi(2)) / 5e6;
    let k = 4.0 / 3.0 / (c_apple + c_rubber) * radius_m.sqrt();
    let u = ode::resting_sag(k, 0.09, mass_kg * G);
    let rho = radius_m - u * c_apple / (c_apple + c_rubber);
    MU_R * G * radius_m * rho / (rho * rho + 0.4 * radius_m * radius_m)
}

/// Least-squares line through (t, v): (slope, value at t_at).
fn fit(points: &[(f64, f64)], t_at: f64) -> (f64, f64) {
    let n = points.len() as f64;
    let mt = points.iter().map(|p| p.0).sum::<f64>() / n;
    let mv = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = points.iter().map(|p| (p.0 - mt) * (p.1 - mv)).sum();
    let sxx: f64 = points.iter().map(|p| (p.0 - mt) * (p.0 - mt)).sum();
    let slope = sxy / sxx;
    (slope, mv + slope * (t_at - mt))
}

/// docs/lines.md's approach table: each apple's speed at t0 + t1 + k V/(mu_r g), k = 0, 0.25,
/// 0.5, 0.75, 1, 1.25 (the sample nearest each time; golden values at their printed digits).
/// Re-pinned when adaptive steps stopped landing on the output samples (issue 31: a sample inside
/// a step carries that step's velocity); before: 0.1274, 0.2677, 0.3395 (feed-1), 0.1338, 0.3418
/// (feed-2), 0.1281, 0.2701, 0.3418 (feed-3), 0.1309, 0.3418, 0.3999 (feed-4). Re-pinned again
/// when apples at rest on a belt began to ride it and adaptive steps began to land on each
/// source's emission (the touch, hence the sampled times, moved by up to 6 ms); before: 0.1273
/// (feed-1), 0.1350, 0.2004, 0.2721, 0.3438, 0.3998 (feed-2), 0.1278, 0.1982, 0.2699, 0.3416
/// (feed-3), 0.1301, 0.2003, 0.2720, 0.3436, 0.4001 (feed-4).
const TABLE: [[f64; 6]; 4] = [
    [0.1271, 0.1981, 0.2676, 0.3393, 0.4001, 0.4000],
    [0.1371, 0.2005, 0.2722, 0.3417, 0.3999, 0.4000],
    [0.1275, 0.1983, 0.2700, 0.3417, 0.3998, 0.4000],
    [0.1300, 0.2006, 0.2722, 0.3418, 0.3999, 0.4000],
];

/// Issue 19's acceptance: each apple fed onto the belt rides at the belt speed, within 2 %, from
/// t0 + t1 + V/(mu_r g) on (t0 its touch), and is below that before (checked up to
/// t0 + t1 + 0.9 V/(mu_r g)); the approach is the closed form's: rolling phase accelerating at
/// 5/7 mu_r g (docs/lines.md: +0.27 to +0.29 %, the lever R - u c1/(c1 + c2), which predicts
/// +0.27 to +0.28 %: each checked), starting from 2V/7 raised by the landing's shorter lever arm
/// and the rolling resistance during the slip (docs/lines.md: 10-12 %).
#[test]
fn belt_carries_apples_at_belt_speed() {
    let (r, series) = belt_run(None);
    let apples = r.roster.apples();
    assert_eq!(apples.len(), 4, "four apples fed");
    let t1 = 2.0 * V / (7.0 * MU * G);
    let t_r = V / (MU_R * G);
    let a_cf = 5.0 / 7.0 * MU_R * G;
    println!(
        "t1 = {:.4} s, V/(mu_r g) = {:.4} s, closed-form ride time {:.4} s after touch; wall {:.3} s, {} steps",
        t1,
        t_r,
        t1 + t_r,
        r.wall_time_s,
        r.steps
    );
    let mut worst_after: f64 = 0.0;
    for (i, a) in apples.iter().enumerate() {
        let i = i as u32;
        let t0 = touch(&r.events, i, "belt");
        assert!(t0.is_finite(), "{} never touched the belt", a.name);
        let ride = t0 + t1 + t_r;
        assert!(
            ride < r.simulated_time_s - 0.5,
            "the run ends too early to see {} ride",
            a.name
        );
        let s: Vec<(f64, f64)> = series
            .of(i)
            .into_iter()
            .map(|(t, st)| (t, speed(st.velocity)))
            .collect();
        // Within 2 % of V after the closed-form time, every sample.
        let after: Vec<_> = s.iter().filter(|p| p.0 >= ride).collect();
        assert!(
            after.len() > 50,
            "{}: {} samples after the ride time",
            a.name,
            after.len()
        );
        for &&(t, v) in &after {
            let e = (v - V).abs() / V;
            worst_after = worst_after.max(e);
            assert!(
                e <= 0.02,
                "{}: {v} m/s at t = {t} s, {:.3} % from V",
                a.name,
                100.0 * e
            );
        }
        // Below the 2 % band before (up to 90 % of the rolling phase).
        for &(t, v) in s.iter().filter(|p| p.0 > t0 && p.0 <= t0 + t1 + 0.9 * t_r) {
            assert!(v < 0.98 * V, "{}: already {v} m/s at t = {t} s", a.name);
        }
        // The approach: the rolling phase against the closed form.
        let roll: Vec<(f64, f64)> = s
            .iter()
            .copied()
            .filter(|p| p.0 >= t0 + t1 + 0.1 * t_r && p.0 <= t0 + t1 + 0.8 * t_r)
            .collect();
        let (acc, v_start) = fit(&roll, t0 + t1);
        println!(
            "{}: touch {:.4} s; rolling phase {:.5} m/s^2 (5/7 mu_r g {:.5}, {:+.2} %), from {:.5} m/s at t0 + t1 (2V/7 {:.5}, {:+.2} %)",
            a.name,
            t0,
            acc,
            a_cf,
            100.0 * (acc / a_cf - 1.0),
            v_start,
            2.0 * V / 7.0,
            100.0 * (v_start / (2.0 * V / 7.0) - 1.0)
        );
        // docs/lines.md: +0.27 to +0.29 % from 5/7 mu_r g (checked above it and within 0.58 %,
        // twice the 0.29 % first measured, inside the 1 %); the model's lever predicts
        // +0.27 to +0.28 %: against the lever form within 0.0043 % (checked at twice that).
        let lever = lever_acceleration(a.radius_m, a.mass_kg);
        println!(
            "  the lever R - u c1/(c1 + c2) predicts {:+.3} %; measured against it {:+.4} %",
            100.0 * (lever / a_cf - 1.0),
            100.0 * (acc / lever - 1.0)
        );
        assert!(
            acc > a_cf && acc / a_cf - 1.0 <= 2.0 * 0.29e-2,
            "{}: rolling-phase acceleration {acc}",
            a.name
        );
        assert!(
            (0.26e-2..=0.30e-2).contains(&(lever / a_cf - 1.0)),
            "{}: the lever predicts {lever}",
            a.name
        );
        assert_ref(
            "rolling phase against the lever",
            acc,
            lever,
            2.0 * 0.0043e-2,
            "closed form",
        );
        let above = v_start / (2.0 * V / 7.0) - 1.0;
        assert!(
            (0.09..=0.13).contains(&above),
            "{}: rolling starts at {v_start} m/s, {:.1} % above 2V/7",
            a.name,
            100.0 * above
        );
        for (k, stated) in [0.0, 0.25, 0.5, 0.75, 1.0, 1.25]
            .into_iter()
            .zip(TABLE[i as usize])
        {
            let t = t0 + t1 + k * t_r;
            let (ts, v) = *s
                .iter()
                .min_by(|p, q| (p.0 - t).abs().total_cmp(&(q.0 - t).abs()))
                .unwrap();
            let cf = (2.0 * V / 7.0 + a_cf * (ts - t0 - t1)).min(V);
            println!(
                "  t - t0 = {:.3} s: {:.4} m/s, closed form {:.4} m/s ({:+.4} m/s)",
                ts - t0,
                v,
                cf,
                v - cf
            );
            // docs/lines.md's table (golden, printed digits).
            assert!(
                (v - stated).abs() <= 1e-4,
                "{}: {v} at {ts} s, docs/lines.md {stated}",
                a.name
            );
        }
        // The closed-form time is an upper bound: V is reached (0.1 %) within 0.1 s before it,
        // and the 2 % band entered before it too (docs/lines.md: about 1.28 s after touch).
        let first = |tol: f64| {
            s.iter()
                .find(|p| p.0 > t0 && (p.1 - V).abs() <= tol * V)
                .unwrap()
                .0
        };
        let (t_v, t_band) = (first(1e-3), first(0.02));
        println!(
            "  V (0.1 %) reached {:.3} s after touch, the 2 % band entered {:.3} s after touch (closed form {:.3} s)",
            t_v - t0,
            t_band - t0,
            t1 + t_r
        );
        assert!(t_v <= ride && t_v >= ride - 0.1, "{}: V at {t_v} s", a.name);
        // docs/lines.md: V (0.1 %) 1.348-1.352 s after touch, the 2 % band entered at
        // 1.278-1.288 s (each range to one unit of its last digit; before riding and the steps
        // landing on the emissions: 1.347-1.358 s and 1.277-1.288 s).
        assert!(
            (1.347..=1.353).contains(&(t_v - t0)),
            "{}: V at {} s after touch",
            a.name,
            t_v - t0
        );
        assert!(
            t_band < t_v && (1.277..=1.289).contains(&(t_band - t0)),
            "{}: band at {t_band} s",
            a.name
        );
        // Distance travelled from the feed point by the ride time: V T - lag, the lag
        // 8 mm + 5 V^2 / (14 mu_r g) (docs/lines.md: 0.35 m), within 10 % (the early start).
        let x = |t: f64| {
            series
                .of(i)
                .into_iter()
                .min_by(|p, q| (p.0 - t).abs().total_cmp(&(q.0 - t).abs()))
                .unwrap()
                .1
                .position
                .x
        };
        let lag = V * t1 - MU * G * t1 * t1 / 2.0 + 5.0 * V * V / (14.0 * MU_R * G);
        let cf_dist = V * (t1 + t_r) - lag;
        let d = x(ride) - x(t0);
        println!(
            "  travelled {d:.3} m by the ride time (closed form {cf_dist:.3} m, lag {lag:.3} m)"
        );
        // Beyond the closed form (the early start), by 4.2-5.3 % (4.2-6.2 % before riding):
        // checked above it, within 10.8 % (twice the 5.4 % first measured).
        assert!(
            d > cf_dist && d / cf_dist - 1.0 <= 2.0 * 0.054,
            "{}: {d} m",
            a.name
        );
        assert!(
            (0.3655..=0.3695).contains(&d),
            "{}: {d} m, docs/lines.md 0.366-0.369",
            a.name
        );
        // docs/lines.md: the feed impacts on the belt peak at 15.1-19.3 N.
        let peaks: Vec<f64> = r
            .events
            .iter()
            .filter(|e| e.a_index == i)
            .map(|e| e.peak_force_n)
            .collect();
        assert!(
            peaks.len() == 1 && (15.05..=19.35).contains(&peaks[0]),
            "{}: {peaks:?}",
            a.name
        );
        // Every apple ends riding: its speed within 0.1 % of V (docs/lines.md: 0.040 % at worst).
        let (_, v_end) = *s.last().unwrap();
        assert!(
            (v_end - V).abs() <= 1e-3 * V,
            "{}: ends at {v_end} m/s",
            a.name
        );
    }
    println!(
        "largest deviation from V after the ride time: {:.4} %",
        100.0 * worst_after
    );
    // docs/lines.md: 0.040 % (checked at 0.082 %, twice the 0.041 % first measured; 0.042 %
    // before riding).
    assert!(worst_after <= 8.2e-4, "{worst_after}");
}

/// The contrast: with `"rolling": "none"` the same apples ride at 2V/7 for ever (docs/lines.md:
/// 0.11601-0.11622 m/s to the end, +1.5 to +1.7 %, the landing's shorter lever arm: every sample
/// from 0.2 s after the touch above 2V/7 and within 3 %, inside twice 1.7 %; the last to the
/// printed digits).
#[test]
fn without_rolling_resistance_apples_lag_at_two_sevenths() {
    let (r, series) = belt_run(Some(Rolling::None));
    let t1 = 2.0 * V / (7.0 * MU * G);
    let t_r = V / (MU_R * G);
    for (i, a) in r.roster.apples().iter().enumerate() {
        let i = i as u32;
        let t0 = touch(&r.events, i, "belt");
        let mut n = 0;
        for (t, st) in series.of(i) {
            if t >= t0 + 0.2 {
                let v = speed(st.velocity);
                assert!(
                    v > 2.0 * V / 7.0 && v / (2.0 * V / 7.0) - 1.0 <= 0.03,
                    "{}: {v} m/s at t = {t} s, not 2V/7",
                    a.name
                );
                n += 1;
            }
        }
        assert!(n > 50);
        let (t_end, st) = *series.of(i).last().unwrap();
        assert!(
            (0.116005..=0.116225).contains(&speed(st.velocity)),
            "{}: ends at {}",
            a.name,
            speed(st.velocity)
        );
        println!(
            "{}: {:.5} m/s at t - t0 = {:.2} s (2V/7 = {:.5}; with rolling resistance it would ride at V after {:.3} s)",
            a.name,
            speed(st.velocity),
            t_end - t0,
            2.0 * V / 7.0,
            t1 + t_r
        );
    }
}

/// belt_transfer.json: the fast and the slow belt's speeds.
const V_FAST: f64 = 0.6;
const V_SLOW: f64 = 0.2;

fn transfer_run() -> (RunResult, MemorySeries) {
    run(&shipped("scenarios/lines/belt_transfer.json"))
}

/// Last moment apple `i` touches `surface`.
fn leave(events: &[ContactEvent], i: u32, surface: &str) -> f64 {
    events
        .iter()
        .filter(|e| e.a_index == i && &*e.b == surface)
        .map(|e| e.t_end_s.unwrap_or(f64::INFINITY))
        .fold(f64::NEG_INFINITY, f64::max)
}

/// The fast-to-slow transfer (docs/lines.md): each apple rides the fast belt at V1 (2 %) from
/// t0 + t1 + V1/(mu_r g) until it leaves it; it lands on the slow belt rolling forward relative
/// to it (5/7 of the speed difference in the closed form), is slowed at 5/7 mu_r g (docs/lines.md:
/// +0.27 %, the lever; checked above it within 0.56 %, twice the 0.28 % first measured,
/// and against the lever form)
/// and rides at V2 (2 %) from t_land + (V1 - V2)/(mu_r g) on, faster than that before.
#[test]
fn transfer_slows_apples_to_the_slow_belt() {
    let (r, series) = transfer_run();
    let apples = r.roster.apples();
    assert_eq!(apples.len(), 3);
    let dv = V_FAST - V_SLOW;
    let t1 = 2.0 * V_FAST / (7.0 * MU * G);
    let a_cf = 5.0 / 7.0 * MU_R * G;
    println!("wall {:.3} s, {} steps", r.wall_time_s, r.steps);
    for (i, a) in apples.iter().enumerate() {
        let i = i as u32;
        let t0 = touch(&r.events, i, "fast");
        let t_off = leave(&r.events, i, "fast");
        let t_land = touch(&r.events, i, "slow");
        assert!(
            t0 + t1 + V_FAST / (MU_R * G) < t_off - 0.2,
            "{}: leaves the fast belt before riding it",
            a.name
        );
        assert!(
            t_land > t_off && t_land + dv / (MU_R * G) < r.simulated_time_s - 0.5,
            "{}",
            a.name
        );
        let s: Vec<(f64, f64)> = series
            .of(i)
            .into_iter()
            .map(|(t, st)| (t, speed(st.velocity)))
            .collect();
        let mut worst_fast: f64 = 0.0;
        for &(t, v) in s
            .iter()
            .filter(|p| p.0 >= t0 + t1 + V_FAST / (MU_R * G) && p.0 <= t_off - 0.05)
        {
            let e = (v - V_FAST).abs() / V_FAST;
            worst_fast = worst_fast.max(e);
            assert!(e <= 0.02, "{}: {v} m/s at {t} s on the fast belt", a.name);
        }
        let ride = t_land + dv / (MU_R * G);
        let mut worst_slow: f64 = 0.0;
        for &(t, v) in s.iter().filter(|p| p.0 >= ride) {
            let e = (v - V_SLOW).abs() / V_SLOW;
            worst_slow = worst_slow.max(e);
            assert!(e <= 0.02, "{}: {v} m/s at {t} s on the slow belt", a.name);
        }
        for &(t, v) in s
            .iter()
            .filter(|p| p.0 >= t_land + 0.05 && p.0 <= t_land + 0.9 * dv / (MU_R * G))
        {
            assert!(v > 1.02 * V_SLOW, "{}: already {v} m/s at {t} s", a.name);
        }
        let roll: Vec<(f64, f64)> = s
            .iter()
            .copied()
            .filter(|p| p.0 >= t_land + 0.1 && p.0 <= t_land + 0.8 * dv / (MU_R * G))
            .collect();
        let (dec, v_land) = fit(&roll, t_land);
        println!(
            "{}: touches the fast belt at {t0:.3} s, leaves it at {t_off:.3} s (within {:.3} % of V1 from {:.3} s), lands at {t_land:.3} s; \
             rolls on at {:.4} m/s relative to the slow belt (closed form 5/7 (V1 - V2) = {:.4}, {:+.1} %), \
             slowed at {:.5} m/s^2 ({:+.2} % from 5/7 mu_r g); within {:.3} % of V2 from {ride:.3} s",
            a.name,
            100.0 * worst_fast,
            t0 + t1 + V_FAST / (MU_R * G),
            v_land - V_SLOW,
            5.0 / 7.0 * dv,
            100.0 * ((v_land - V_SLOW) / (5.0 / 7.0 * dv) - 1.0),
            -dec,
            100.0 * (-dec / a_cf - 1.0),
            100.0 * worst_slow
        );
        // docs/lines.md: +0.27 % (checked with its sign within 0.56 %, twice the 0.28 %
        // first measured, inside the 1 %), as the lever R - u c1/(c1 + c2) predicts
        // (within 0.018 %, checked at twice that).
        assert!(
            -dec > a_cf && -dec / a_cf - 1.0 <= 2.0 * 0.28e-2,
            "{}: slowed at {}",
            a.name,
            -dec
        );
        let lever = lever_acceleration(a.radius_m, a.mass_kg);
        assert_ref(
            "slowing against the lever",
            -dec,
            lever,
            2.0 * 0.018e-2,
            "closed form",
        );
        // docs/lines.md: rolls on at 0.267-0.268 m/s relative to the slow belt; within
        // 0.004-0.014 % of V1 on the fast belt, 0.022-0.034 % of V2 on the slow one (checked at
        // twice the 0.013 % first measured and the 0.034 %; before riding: 0.004-0.013 %,
        // 0.032 %).
        assert!(
            (0.2665..=0.2685).contains(&(v_land - V_SLOW)),
            "{}: {v_land}",
            a.name
        );
        assert!(
            worst_fast <= 2.6e-4 && worst_slow <= 6.8e-4,
            "{worst_fast} {worst_slow}"
        );
        // docs/lines.md: feed impacts 12.7-18.5 N on the fast belt, landings 53.0-62.3 N on the
        // slow (re-pinned when adaptive steps stopped landing on the output samples, issue 31;
        // before: 12.8-18.6 N, 52-62 N; and again when apples began to ride belts and steps to
        // land on the emissions, before: 53.0-62.5 N).
        let peak = |surface: &str| {
            r.events
                .iter()
                .filter(|e| e.a_index == i && &*e.b == surface)
                .map(|e| e.peak_force_n)
                .fold(0.0, f64::max)
        };
        println!(
            "  peaks: fast belt {:.1} N, slow belt {:.1} N",
            peak("fast"),
            peak("slow")
        );
        assert!(
            (12.65..=18.55).contains(&peak("fast")) && (52.95..=62.35).contains(&peak("slow")),
            "{}: fast {}, slow {}",
            a.name,
            peak("fast"),
            peak("slow")
        );
        // Slow belt used before the apple rides it: V2 dV/(mu_r g) + 5 dV^2/(14 mu_r g)
        // (docs/lines.md: 0.47 m), within 10 % (the slower start of the relative rolling).
        let x = |t: f64| {
            series
                .of(i)
                .into_iter()
                .min_by(|p, q| (p.0 - t).abs().total_cmp(&(q.0 - t).abs()))
                .unwrap()
                .1
                .position
                .x
        };
        let cf_dist = V_SLOW * dv / (MU_R * G) + 5.0 * dv * dv / (14.0 * MU_R * G);
        let d = x(ride) - x(t_land);
        println!("  {d:.3} m of slow belt from the landing to the ride time (closed form {cf_dist:.3} m)");
        // Short of the closed form 0.466 m by 5.2-5.4 % (the relative rolling starts 6 % slower;
        // 5.1-5.3 % before riding): checked below it, within 10.8 % (twice the 5.4 %).
        assert!(
            d < cf_dist && 1.0 - d / cf_dist <= 2.0 * 0.054,
            "{}: {d} m",
            a.name
        );
        assert!(
            (0.4405..=0.4425).contains(&d),
            "{}: {d} m, docs/lines.md 0.441-0.442",
            a.name
        );
    }
}

/// The contrast: with `"rolling": "none"` the apples cross the fast belt at 2V1/7 (3 %) and
/// roll on over the slow belt faster than it (over 1.2 V2) for ever.
#[test]
fn without_rolling_resistance_the_transfer_does_not_slow_apples_to_the_belt() {
    // At 2V1/7 the first apple reaches the slow belt only after 8.2 s: run 12 s.
    let mut sc: Scenario = shipped("scenarios/lines/belt_transfer.json");
    sc.contact.rolling = Rolling::None;
    sc.duration_s = 12.0;
    let (r, series) = run(&sc);
    let t_end = r.simulated_time_s;
    let mut fast = Vec::new();
    let mut slow = Vec::new();
    for i in 0..r.roster.len() as u32 {
        let t0 = touch(&r.events, i, "fast");
        let t_land = touch(&r.events, i, "slow");
        for (t, st) in series.of(i) {
            let v = speed(st.velocity);
            if t >= t0 + 0.2 && t < t_land.min(t_end) - 0.2 {
                // docs/lines.md: +1.6 % (above 2V1/7; checked within 3 %, inside twice that).
                assert!(
                    v > 2.0 * V_FAST / 7.0 && v / (2.0 * V_FAST / 7.0) - 1.0 <= 0.03,
                    "{v} m/s at {t} s on the fast belt"
                );
                fast.push(v);
            }
            if t >= t_land + 0.2 {
                assert!(v > 1.2 * V_SLOW, "{v} m/s at {t} s on the slow belt");
                // docs/lines.md: 0.250-0.264 m/s.
                assert!(
                    (0.2495..=0.2645).contains(&v),
                    "{v} m/s at {t} s on the slow belt"
                );
                slow.push(v);
            }
        }
    }
    // docs/lines.md: the first apple reaches the slow belt at 8.2 s (3.1 s with rolling
    // resistance).
    let first_landing = touch(&r.events, 0, "slow");
    assert!((first_landing - 8.2).abs() <= 0.05, "{first_landing}");
    assert!(
        !fast.is_empty() && !slow.is_empty(),
        "an apple reaches the slow belt within the run"
    );
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
    println!(
        "without rolling resistance: {:.4} m/s on the fast belt (2V1/7 = {:.4}), {:.4} m/s on the slow belt (V2 = {V_SLOW})",
        mean(&fast),
        2.0 * V_FAST / 7.0,
        mean(&slow)
    );
}

/// The heap left in the bin, measured from the final positions (docs/lines.md, "Measuring the
/// heap").
#[derive(Debug)]
#[allow(dead_code)] // every field is printed (Debug); not every one is asserted
struct Heap {
    apples: usize,
    /// Fraction of the apples touching the bin floor at the end (an open contact with it).
    floor_fraction: f64,
    /// Top of the highest apple above the floor (m).
    height_m: f64,
    /// height over the mean diameter.
    layers: f64,
    /// Radius around the pile's axis holding 95 % of the apples (m).
    r95_m: f64,
    /// Angle of a least-squares line through the surface profile (deg).
    fit_angle_deg: f64,
    /// Angle from the apex to the edge: atan((height - D) / r95) (deg).
    apex_edge_angle_deg: f64,
    /// Largest final speed (m/s).
    max_speed_m_s: f64,
    /// Apples touching a wall of the bin at the end.
    at_walls: usize,
}

fn heap(r: &RunResult, floor: &str, wall_prefix: &str, mean_d: f64) -> Heap {
    let roster = r.roster.apples();
    let n = r.apples.len();
    assert_eq!(roster.len(), n);
    let on_floor = (0..n as u32)
        .filter(|&i| {
            r.events
                .iter()
                .any(|e| e.a_index == i && &*e.b == floor && e.t_end_s.is_none())
        })
        .count();
    // The pile's axis: the mean of the apples' horizontal positions.
    let cx = r.apples.iter().map(|a| a.final_position_m[0]).sum::<f64>() / n as f64;
    let cy = r.apples.iter().map(|a| a.final_position_m[1]).sum::<f64>() / n as f64;
    let at_walls = (0..n as u32)
        .filter(|&i| {
            r.events.iter().any(|e| {
                e.a_index == i
                    && e.t_end_s.is_none()
                    && e.b.starts_with(wall_prefix)
                    && &*e.b != floor
            })
        })
        .count();
    let mut pts: Vec<(f64, f64)> = r
        .apples
        .iter()
        .zip(roster)
        .map(|(a, ra)| {
            assert_eq!(a.name, ra.name);
            let p = a.final_position_m;
            ((p[0] - cx).hypot(p[1] - cy), p[2] + ra.radius_m)
        })
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let height = pts.iter().map(|p| p.1).fold(0.0, f64::max);
    let r95 = pts[(0.95 * n as f64).ceil() as usize - 1].0;
    // Surface profile: the highest apple top in each annulus D/2 wide, out to r95.
    let w = mean_d / 2.0;
    let mut top = std::collections::BTreeMap::<usize, f64>::new();
    for &(rr, h) in pts.iter().filter(|p| p.0 <= r95) {
        let e = top.entry((rr / w) as usize).or_insert(0.0);
        *e = e.max(h);
    }
    let prof: Vec<(f64, f64)> = top
        .iter()
        .map(|(&k, &h)| ((k as f64 + 0.5) * w, h))
        .collect();
    let (slope, _) = fit(&prof, 0.0);
    let max_speed = r
        .apples
        .iter()
        .map(|a| {
            let v = a.final_velocity_m_s;
            (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
        })
        .fold(0.0, f64::max);
    Heap {
        apples: n,
        floor_fraction: on_floor as f64 / n as f64,
        height_m: height,
        layers: height / mean_d,
        r95_m: r95,
        fit_angle_deg: (-slope).atan().to_degrees(),
        apex_edge_angle_deg: ((height - mean_d) / r95).atan().to_degrees(),
        max_speed_m_s: max_speed,
        at_walls,
    }
}

/// Largest peak force and contacts above 80 N on each surface (apple-apple as "apple").
fn impacts(r: &RunResult) -> std::collections::BTreeMap<String, (usize, f64, usize)> {
    let mut m = std::collections::BTreeMap::new();
    for e in &r.events {
        let key = match e.b_party {
            applesim::record::events::Party::Apple(_) => "apple".to_string(),
            applesim::record::events::Party::Surface(_) => e.b.to_string(),
        };
        let s = m.entry(key).or_insert((0, 0.0f64, 0));
        s.0 += 1;
        s.1 = s.1.max(e.peak_force_n);
        s.2 += usize::from(e.peak_force_n > 80.0);
    }
    m
}

fn bin_run(edit: impl FnOnce(&mut Scenario)) -> (RunResult, Heap) {
    let mut sc: Scenario = shipped("scenarios/lines/bin_filling.json");
    edit(&mut sc);
    let (r, _) = run(&sc);
    let h = heap(&r, "bin/floor", "bin/", 0.075);
    println!(
        "{h:?}; wall {:.2} s, {} steps, {} contact events",
        r.wall_time_s,
        r.steps,
        r.events.len()
    );
    (r, h)
}

/// Issue 19's acceptance: the 150 poured apples build a heap with rolling resistance (more than
/// two diameters high, a slope of 5-15 degrees, not all of them on the floor) and spread into a
/// single layer without it (every apple on the floor, one diameter high, no slope; some apples
/// still rolling at the end, as nothing stops them). The height is held on the mean of the five
/// pour seeds of docs/lines.md's table (2.07 D; each over 1.5 D): one pour is one draw of a
/// chaotic heap, and seed 19's was 1.93 D after issue 31 (2.33 D before; 2.10 D since apples
/// ride belts and adaptive steps land on the emissions). Fewer than
/// half on the floor is out of reach for 150 apples at these angles (docs/lines.md: a cone of
/// 150 apples has most of them in its bottom layer).
#[test]
fn poured_apples_heap_with_rolling_resistance_and_spread_without() {
    let (r, h) = bin_run(|_| {});
    assert_eq!(h.apples, 150, "every apple poured");
    assert!(h.max_speed_m_s < 1e-3, "settled: {h:?}");
    let mut heights = vec![h.layers];
    for seed in [1, 2, 3, 4] {
        let (_, hs) = bin_run(|sc| sc.sources[0].seed = seed);
        heights.push(hs.layers);
    }
    let mean = heights.iter().sum::<f64>() / heights.len() as f64;
    println!("heights over seeds 19, 1, 2, 3, 4: {heights:.2?} D, mean {mean:.2} D");
    assert!(
        mean > 2.0 && heights.iter().all(|&x| x > 1.5),
        "a heap: {heights:?}"
    );
    assert!(h.floor_fraction < 0.9, "not a single layer: {h:?}");
    assert!((5.0..=15.0).contains(&h.fit_angle_deg), "slope: {h:?}");
    assert!(
        (5.0..=15.0).contains(&h.apex_edge_angle_deg),
        "slope: {h:?}"
    );
    let imp = impacts(&r);
    println!("impacts per surface (contacts, largest peak N, above 80 N): {imp:?}");
    // docs/lines.md's seed-19 row (golden values at their printed digits: the pile is chaotic).
    // Re-pinned in issue 31: the shipped `jitter_m` 0.03 scattered the spawn height by +-30 mm
    // as well; a number is horizontal only now, so every apple starts 0.3 m up (before: 128 on
    // the floor, 2.12 D, 8.0 and 8.3 degrees, r95 0.577 m, three at a wall). Re-pinned again when
    // adaptive steps stopped landing on the output samples (issue 31; before: 118 on the floor,
    // 2.33 D, 9.8 and 10.3 degrees, r95 0.550 m, none at a wall). Re-pinned again when adaptive
    // steps began to land on each source's emission (before: 122 on the floor, 1.93 D, 7.4 and
    // 6.9 degrees, r95 0.582 m, one at a wall).
    assert_eq!(
        h.at_walls, 2,
        "two apples of the heap's edge at a wall: {h:?}"
    );
    assert_eq!((h.floor_fraction * 150.0).round() as usize, 118, "{h:?}");
    assert!(
        (h.layers - 2.10).abs() <= 0.01 && (h.fit_angle_deg - 8.0).abs() <= 0.1,
        "{h:?}"
    );
    assert!(
        (h.apex_edge_angle_deg - 8.9).abs() <= 0.1 && (h.r95_m - 0.525).abs() <= 0.001,
        "{h:?}"
    );
    // docs/lines.md's impact table and bruised apples (golden; re-pinned in issue 31, before:
    // floor 276 contacts, 279.2 N, 107 above 80 N; apples 2531, 100.4 N, 19; 85 apples over 80 N;
    // and again when adaptive steps stopped landing on the output samples, before: floor 251,
    // 268.3 N, 100; apples 2788, 106.6 N, 17; 81 apples over 80 N; and again when adaptive steps
    // began to land on each source's emission, before: floor 269, 257.1 N, 114; apples 2633,
    // 95.8 N, 20; x_max 2, 63.6 N; x_min 6, 59.4 N; y_max 5, 46.8 N; y_min 3, 41.0 N; 91 apples
    // over 80 N).
    for (surface, n, peak, over) in [
        ("bin/floor", 255, 255.4, 100),
        ("apple", 3061, 96.2, 13),
        ("bin/x_max", 4, 66.2, 0),
        ("bin/y_min", 4, 40.2, 0),
    ] {
        let got = imp[surface];
        assert!(
            got.0 == n && (got.1 - peak).abs() <= 0.1 && got.2 == over,
            "{surface}: {got:?}, docs/lines.md ({n}, {peak}, {over})"
        );
    }
    assert_eq!(imp.len(), 4);
    let mut over_80 = std::collections::BTreeSet::new();
    for e in r.events.iter().filter(|e| e.peak_force_n > 80.0) {
        over_80.insert(e.a_index);
        if let applesim::record::events::Party::Apple(j) = e.b_party {
            over_80.insert(j);
        }
    }
    println!("{} apples with a contact above 80 N", over_80.len());
    assert_eq!(over_80.len(), 75);
    // The hardest impacts are the first apples' landings on the bare floor.
    let floor_peak = imp["bin/floor"].1;
    assert!(imp.values().all(|s| s.1 <= floor_peak));

    let (_, flat) = bin_run(|sc| sc.contact.rolling = Rolling::None);
    assert_eq!(flat.apples, 150);
    // Nothing stops an apple rolling on the floor in the paper's model: some still roll.
    assert!(flat.floor_fraction >= 0.98, "a single layer: {flat:?}");
    assert!(flat.layers < 1.1, "a single layer: {flat:?}");
    assert!(flat.fit_angle_deg.abs() < 2.0, "flat: {flat:?}");
    assert!(
        flat.r95_m > h.r95_m + 0.1,
        "spread wider: {flat:?} against {h:?}"
    );
    // docs/lines.md's seed-19 row without rolling resistance (golden; re-pinned in issue 31,
    // before: -0.5 degrees, r95 0.738 m; and again when adaptive steps stopped landing on the
    // output samples, before: -0.6 degrees; and when they began to land on each source's
    // emission, before: -0.2 degrees, r95 0.742 m).
    assert!(
        (flat.layers - 1.06).abs() <= 0.01 && (flat.fit_angle_deg + 0.6).abs() <= 0.1,
        "{flat:?}"
    );
    assert!(
        (flat.apex_edge_angle_deg - 0.4).abs() <= 0.1 && (flat.r95_m - 0.741).abs() <= 0.001,
        "{flat:?}"
    );
    assert!(flat.max_speed_m_s > 0.01, "some still roll: {flat:?}");
}

/// docs/lines.md: the shipped bin filler sets `"twisting": "coulomb"`; with the default
/// (`none`, as LIGGGHTS and EDEM) the same pour still builds a heap (apples spinning about the
/// vertical on the floor never stop). Seed 19 heaps lower and flatter than with `coulomb`
/// (1.94 D against 2.10 D), with more apples on the floor (130 against 118); before the last
/// re-pin below it heaped higher (2.40 D against 1.93 D): one seed each, within the seeds'
/// scatter. Issue 19 asks for defaults that make a bin heap; this is that default (golden at the
/// printed digits, seed 19; re-pinned in issue 31, horizontal jitter: before 1.85 D, 7.4 and 6.0
/// degrees, 129 on the floor; again when adaptive steps stopped landing on the output samples:
/// before 1.96 D, 7.2 and 6.4 degrees, 128 on the floor; and when they began to land on each
/// source's emission: before 2.40 D, 10.8 and 11.1 degrees, 127 on the floor).
#[test]
fn with_the_default_twisting_the_pour_still_heaps() {
    let (_, h) = bin_run(|sc| sc.contact.twisting = Twisting::None);
    assert_eq!(h.apples, 150, "every apple poured");
    assert!(h.max_speed_m_s < 1e-3, "settled: {h:?}");
    assert!(h.layers > 1.5, "a heap: {h:?}");
    assert!(h.floor_fraction < 0.9, "not a single layer: {h:?}");
    assert!(h.fit_angle_deg > 3.0, "sloped: {h:?}");
    assert!((h.layers - 1.94).abs() <= 0.01, "{h:?}");
    assert!((h.fit_angle_deg - 7.2).abs() <= 0.1, "{h:?}");
    assert!((h.apex_edge_angle_deg - 7.2).abs() <= 0.1, "{h:?}");
    assert_eq!((h.floor_fraction * 150.0).round() as usize, 130, "{h:?}");
}

/// docs/lines.md: poured from 0.45 m at 1 m/s (landing at 3 m/s) instead of 0.3 m at 0.5 m/s,
/// the same apples with the same rolling and twisting resistance build a lower, wider, flatter
/// heap (nearly a single layer): the apples thrown off the landing point roll further, some to
/// the walls.
#[test]
fn a_higher_pour_spreads_wider_and_flatter() {
    let (_, h) = bin_run(|sc| {
        let s = &mut sc.sources[0];
        s.position_m[2] = 0.45;
        s.velocity_m_s[2] = -1.0;
        s.rate_per_s = 12.0;
        sc.duration_s = 15.0;
    });
    let (_, shipped) = bin_run(|_| {});
    assert_eq!(h.apples, 150);
    assert!(
        h.floor_fraction > shipped.floor_fraction
            && h.r95_m > shipped.r95_m + 0.05
            && h.fit_angle_deg < shipped.fit_angle_deg - 1.0
            && h.layers < shipped.layers,
        "lower, wider, flatter: {h:?} against {shipped:?}"
    );
    assert!(h.at_walls > 0, "rolled to the walls: {h:?}");
    // docs/lines.md (golden, seed 19): 149 of 150 on the floor, 1.50 diameters, 0.4 degrees
    // (3.2 apex to edge), r95 0.675 m, seven at the walls. Re-pinned in issue 31 (horizontal
    // jitter; before: 138 on the floor, 1.96 D, 6.2 degrees, r95 0.672 m, four at the walls),
    // again when adaptive steps stopped landing on the output samples (before: 149 on the
    // floor, 1.60 D, 0.3 and 3.8 degrees, r95 0.679 m, ten at the walls), and when they began to
    // land on each source's emission (before: 148 on the floor, 1.81 D, 1.9 and 5.1 degrees, r95
    // 0.681 m, five at the walls).
    assert_eq!((h.floor_fraction * 150.0).round() as usize, 149, "{h:?}");
    assert!((h.layers - 1.50).abs() <= 0.01, "{h:?}");
    assert!((h.fit_angle_deg - 0.4).abs() <= 0.1, "{h:?}");
    assert!((h.apex_edge_angle_deg - 3.2).abs() <= 0.1, "{h:?}");
    assert!((h.r95_m - 0.675).abs() <= 0.001 && h.at_walls == 7, "{h:?}");
}

/// The heap's figures over five pour seeds, with and without rolling resistance (docs/lines.md's
/// table): `cargo test --release --test suite line_scenarios::heap_over_seeds -- --ignored
/// --nocapture`.
#[test]
#[ignore = "docs/lines.md's seed table: 12 runs, about 15 s"]
fn heap_over_seeds() {
    // mu_r, apples poured, the figures.
    #[allow(clippy::type_complexity)]
    // Every apple is fed at both (before steps landed on the emissions, the heap reached the
    // source at mu_r 0.1 and 7 apples were never fed).
    const STRONGER: [(f64, usize, [f64; 5]); 2] = [
        (0.06, 150, [0.673, 2.56, 9.6, 14.3, 0.458]),
        (0.1, 150, [0.580, 3.22, 21.5, 20.9, 0.437]),
    ];
    // The table's rows (golden, printed digits): floor fraction, height / D, fit angle,
    // apex-edge angle, r95. Re-pinned in issue 31: a number `jitter_m` no longer scatters the
    // spawn height, again when adaptive steps stopped landing on the output samples, and again
    // when they began to land on each source's emission (docs/lines.md gives seed 19's figures
    // and the ranges before each).
    let table: [(u64, bool, [f64; 5]); 10] = [
        (19, true, [0.787, 2.10, 8.0, 8.9, 0.525]),
        (19, false, [1.000, 1.06, -0.6, 0.4, 0.741]),
        (1, true, [0.860, 2.18, 5.6, 8.7, 0.577]),
        (1, false, [1.000, 1.06, -0.3, 0.4, 0.744]),
        (2, true, [0.807, 2.20, 6.7, 8.8, 0.581]),
        (2, false, [1.000, 1.06, -0.6, 0.4, 0.740]),
        (3, true, [0.840, 1.88, 7.8, 6.0, 0.626]),
        (3, false, [1.000, 1.06, 0.0, 0.4, 0.748]),
        (4, true, [0.847, 1.97, 8.6, 7.2, 0.582]),
        (4, false, [1.000, 1.06, 0.0, 0.4, 0.742]),
    ];
    let figures = |h: &Heap| {
        [
            h.floor_fraction,
            h.layers,
            h.fit_angle_deg,
            h.apex_edge_angle_deg,
            h.r95_m,
        ]
    };
    // Every row is measured and printed before any is checked, so a change of the contact code
    // shows the whole new table at once.
    let mut measured: Vec<([f64; 5], [f64; 5])> = Vec::new();
    let mut rows = table.iter();
    println!("| seed | rolling | floor fraction | height / D | fit angle | apex-edge angle | r95 (m) | wall (s) |");
    for seed in [19, 1, 2, 3, 4] {
        for rolling in [Rolling::ElasticPlastic, Rolling::None] {
            let (r, h) = bin_run(|sc| {
                sc.sources[0].seed = seed;
                sc.contact.rolling = rolling;
            });
            let &(s, rr, want) = rows.next().unwrap();
            assert_eq!((s, rr), (seed, rolling == Rolling::ElasticPlastic));
            measured.push((figures(&h), want));
            println!(
                "| {seed} | {rolling:?} | {:.3} | {:.2} | {:.1} | {:.1} | {:.3} | {:.2} |",
                h.floor_fraction,
                h.layers,
                h.fit_angle_deg,
                h.apex_edge_angle_deg,
                h.r95_m,
                r.wall_time_s
            );
        }
    }
    // Stronger rolling resistance (seed 19): what it takes to heap higher.
    for (mu_r, n, want) in STRONGER {
        let (r, h) = bin_run(|sc| sc.contact.rolling_friction = mu_r);
        measured.push((figures(&h), want));
        println!(
            "| 19 | mu_r {mu_r} ({} apples poured) | {:.3} | {:.2} | {:.1} | {:.1} | {:.3} | {:.2} |",
            h.apples, h.floor_fraction, h.layers, h.fit_angle_deg, h.apex_edge_angle_deg, h.r95_m, r.wall_time_s
        );
        assert_eq!(h.apples, n);
    }
    for (got, want) in measured {
        for ((g, w), unit) in got.iter().zip(want).zip([1e-3, 1e-2, 0.1, 0.1, 1e-3]) {
            assert!((g - w).abs() <= unit, "{got:?}, docs/lines.md {want:?}");
        }
    }
}

/// The arithmetic of docs/lines.md (its closed forms and estimates at their printed digits).
#[test]
fn closed_form_figures_of_the_doc() {
    let digit = |got: f64, stated: f64, unit: f64| {
        println!("{got} (stated {stated})");
        assert!(
            (got - stated).abs() <= unit,
            "{got}, docs/lines.md {stated}"
        );
    };
    // Section 1: the belt.
    let t1 = 2.0 * V / (7.0 * MU * G);
    let t_r = V / (MU_R * G);
    digit(1e3 * t1, 23.3, 0.1);
    digit(5.0 / 7.0 * MU_R * G, 0.2102, 1e-4);
    digit(t_r, 1.359, 1e-3);
    digit(t1 + t_r, 1.382, 1e-3);
    digit(1e3 * (V * t1 - MU * G * t1 * t1 / 2.0), 8.0, 1.0);
    let roll_lag = 5.0 * V * V / (14.0 * MU_R * G);
    digit(roll_lag, 0.194, 1e-3);
    digit(
        V * (t1 + t_r) - (V * t1 - MU * G * t1 * t1 / 2.0) - roll_lag,
        0.351,
        1e-3,
    );
    digit(2.0 * V / 7.0, 0.1143, 1e-4);
    digit(V / (1.0 + 2.5 * (1.0 - MU_R / MU)), 0.1194, 1e-4);
    let h = 1.0 - 0.026;
    digit(V / (1.0 + 2.5 * h * (h - MU_R / MU)), 0.1240, 1e-4);
    // Section 2: the transfer.
    let dv = V_FAST - V_SLOW;
    digit(
        2.0 * V_FAST / (7.0 * MU * G) + V_FAST / (MU_R * G),
        2.07,
        0.01,
    );
    digit(5.0 / 7.0 * dv, 0.286, 1e-3);
    digit(dv / (MU_R * G), 1.359, 1e-3);
    digit(5.0 * dv * dv / (14.0 * MU_R * G), 0.194, 1e-3);
    digit(
        V_SLOW * dv / (MU_R * G) + 5.0 * dv * dv / (14.0 * MU_R * G),
        0.466,
        1e-3,
    );
    digit(2.0 * V_FAST / 7.0, 0.1714, 1e-4);
    // Section 3: the bin. Landing speeds (source centre 0.3 m, 0.5 m/s; 0.45 m, 1 m/s; a 75 mm
    // apple touches when its centre is R above the floor).
    digit((0.5f64.powi(2) + 2.0 * G * (0.3 - 0.0375)).sqrt(), 2.3, 0.1);
    digit((1.0f64 + 2.0 * G * (0.45 - 0.0375)).sqrt(), 3.0, 0.1);
    // A cone of 150 apples (75 mm, packing 0.6): base radius and close-packed floor apples.
    let d = 0.075f64;
    let bulk = 150.0 * std::f64::consts::PI * d.powi(3) / 6.0 / 0.6;
    for (deg, r_stated, n_stated) in [(30.0f64, 0.45, 131.0), (45.0, 0.375, 91.0)] {
        let r = (3.0 * bulk / (std::f64::consts::PI * deg.to_radians().tan())).cbrt();
        digit(r, r_stated, if deg == 30.0 { 0.01 } else { 1e-3 });
        digit(
            std::f64::consts::PI * r * r / (3f64.sqrt() / 2.0 * d * d),
            n_stated,
            1.0,
        );
    }
    // The groove's thrust on a floor apple over its load (m g / 2 tan 30 over 1.5 m g).
    digit(100.0 * 0.5 * 30f64.to_radians().tan() / 1.5, 19.0, 1.0);
    // An apple rolling at 0.8 m/s, slowed at 5/7 mu_r g, needs 1.5 m.
    digit(0.8 * 0.8 / (2.0 * 5.0 / 7.0 * MU_R * G), 1.5, 0.1);
}

/// Issue 22's bin filler (scenarios/lines/bin_filler.json): the same pour into a bin that starts
/// 0.2 m higher, 0.1 m under the pour, and is lowered as it fills (keyframed translation) takes
/// the hardest floor impacts out of the fixed bin's (docs/lines.md, "A bin filler"). Golden
/// values of the shipped runs (the piles are chaotic): largest apple-floor peak force 133.2 N
/// against 255.4 N, floor contacts above 80 N 21 of 172 against 100 of 255. Re-pinned in issue
/// 31 (a number `jitter_m` is horizontal only: the pour no longer starts up to 30 mm higher;
/// before: 165.0 N against 279.2 N, 39 against 107), again when adaptive steps stopped landing
/// on the output samples (before: 132.7 N against 268.3 N, 31 of 175 against 100 of 251), and
/// when they began to land on each source's emission (before: 166.2 N against 257.1 N, 22 of 177
/// against 114 of 269).
#[test]
fn a_bin_filler_lowering_the_bin_softens_the_floor_impacts() {
    let fixed = shipped("scenarios/lines/bin_filling.json");
    let filler = shipped("scenarios/lines/bin_filler.json");
    let floor = |sc: &Scenario| {
        let (r, series) = run(sc);
        assert_eq!(r.apples.len(), 150, "every apple poured");
        let f: Vec<f64> = r
            .events
            .iter()
            .filter(|e| &*e.b == "bin/floor")
            .map(|e| e.peak_force_n)
            .collect();
        let max = f.iter().copied().fold(0.0, f64::max);
        let over = f.iter().filter(|&&p| p > 80.0).count();
        // The first apple's landing on the bare floor (no heap yet): not chaotic.
        let first = r
            .events
            .iter()
            .filter(|e| &*e.b == "bin/floor")
            .min_by(|a, b| a.t_start_s.total_cmp(&b.t_start_s))
            .unwrap();
        let apple = &r.roster.apples()[first.a_index as usize];
        // Its first sample, in free fall: (time, height, vertical speed).
        let (ts, st) = series.of(first.a_index)[0];
        let landing = (
            apple.radius_m,
            apple.mass_kg,
            (ts, st.position.z, st.velocity.z),
            first.t_start_s,
            first.approach_speed_m_s,
            first.peak_force_n,
        );
        (max, over, f.len(), landing)
    };
    let (max_fixed, over_fixed, n_fixed, first_fixed) = floor(&fixed);
    let (max_filler, over_filler, n_filler, first_filler) = floor(&filler);
    println!(
        "largest apple-floor peak: fixed bin {max_fixed:.1} N ({over_fixed} of {n_fixed} floor contacts above 80 N), bin filler {max_filler:.1} N ({over_filler} of {n_filler})"
    );
    // The physical check beside these pins: the first apple's landing on each bin's bare floor,
    // against the closed forms (free fall from its first sample; the fixed floor's top at z = 0,
    // the lowered one starting 0.2 m higher and sinking at 0.2/15 m/s; the peak from the energy
    // balance 1/2 m v^2 + m g u = 2/5 k u^(5/2), eq. 12 loading on the Hertz curve at
    // lambda v >> 1, k = 4/3 E* sqrt(R), apple-paper on plastic-paper).
    let e_star = e_star_of((1.1e6, 0.18), (1e9, 0.3));
    for (what, (r, m, (ts, zs, vs), t, v, p), floor_z0, floor_v) in [
        ("fixed bin", first_fixed, 0.0, 0.0),
        ("bin filler", first_filler, 0.2, 0.2 / 15.0),
    ] {
        // Touch at t = ts + x: zs + vs x - g x^2 / 2 - r = floor_z0 - floor_v (ts + x).
        let (a, b, c) = (0.5 * G, -vs - floor_v, r + floor_z0 - floor_v * ts - zs);
        let x = (-b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
        let (t_cf, v_cf) = (ts + x, -vs + G * x - floor_v);
        let p_cf = ode::landing_peak(m, v_cf, G, 4.0 / 3.0 * e_star * r.sqrt(), r);
        println!(
            "{what}: first landing at {t:.4} s (closed form {t_cf:.4}), {v:.4} m/s ({v_cf:.4}, {:+.3} %), peak {p:.2} N ({p_cf:.2}, {:+.3} %)",
            100.0 * (v / v_cf - 1.0),
            100.0 * (p / p_cf - 1.0)
        );
        // docs/lines.md 3b: the landing speed within 0.004 % (measured -0.0003 % and -0.0023 %;
        // free fall is exact up to the step's O(dt) position error: checked at 0.004 %, twice
        // the 0.002 % first measured) and the peak within the 2 % that
        // docs/accuracy.md gives `adaptive` at `balanced` (the sampled peak's error has either
        // sign: it depends on where the steps fall in the 20 of them per contact).
        assert!((t - t_cf).abs() <= 1e-4, "{what}: touch {t} against {t_cf}");
        assert_ref(
            &format!("{what}: landing speed"),
            v,
            v_cf,
            2.0 * 0.002e-2,
            "free fall",
        );
        let dp = p / p_cf - 1.0;
        assert!(
            dp.abs() < 2e-2,
            "{what}: peak {dp:+e} against the energy balance"
        );
    }
    // The lowered bin's first landing is the softer by the drop it saves (0.26 m against 0.06 m
    // above the bare floor).
    assert!(first_filler.5 < 0.5 * first_fixed.5);
    assert_eq!((n_fixed, n_filler), (255, 172), "floor contacts");
    assert!(max_filler < max_fixed && over_filler < over_fixed);
    assert!(
        (max_fixed - 255.4).abs() <= 0.1 && over_fixed == 100,
        "{max_fixed} {over_fixed}"
    );
    assert!(
        (max_filler - 133.2).abs() <= 0.1 && over_filler == 21,
        "{max_filler} {over_filler}"
    );
}

/// A bin fill's figures from its run's files: the apples fed in and those of them still moving
/// at the end, the largest fall of an apple from its entry to its first contact (and whose), the
/// largest apple-floor peak force, the floor contacts above 80 N and in all, the apples that
/// waited for their spot (those never fed included) and their waits together (s).
#[derive(Debug)]
struct Fill {
    fed: usize,
    moving: usize,
    max_fall_m: f64,
    max_fall_apple: String,
    floor_peak_n: f64,
    floor_over_80: usize,
    floor_contacts: usize,
    waited: u64,
    wait_s: f64,
}

/// Runs a shipped bin fill into a scratch folder and reads its figures back from the files: each
/// apple's entry (summary.json `apples[].fed`: time, centre, velocity) and its first contact
/// (contacts.csv, the earliest `t_start_s` where it is `a` or `b`); in between it flies free, so
/// its centre falls -(v_z tau - g tau^2 / 2) in tau. Every apple fed in ends in the bin, at rest
/// (fate `in_bin`) or still settling (fate `moving`, inside the bin: counted); the source's others
/// are still waiting for their spot at the end (summary.json `fates` `never_fed`, the source's
/// `still_waiting`).
fn fill_from_files(rel: &str) -> Fill {
    let sc = shipped(rel);
    let out = std::env::temp_dir().join(format!(
        "applesim-fill-{}-{}",
        std::process::id(),
        rel.rsplit('/').next().unwrap()
    ));
    let _ = std::fs::remove_dir_all(&out);
    applesim::run::to_dir(&sc, &repo("scenarios"), &out, &mut |_| {}).unwrap();
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    let mut first: std::collections::BTreeMap<String, f64> = Default::default();
    let (mut floor_peak_n, mut floor_over_80, mut floor_contacts) = (0.0f64, 0, 0);
    let mut rd = csv::Reader::from_path(out.join("contacts.csv")).unwrap();
    let h = rd.headers().unwrap().clone();
    let col = |name: &str| h.iter().position(|c| c == name).unwrap();
    let (ca, cb, ct, cp) = (col("a"), col("b"), col("t_start_s"), col("peak_force_n"));
    for r in rd.records() {
        let r = r.unwrap();
        let t: f64 = r[ct].parse().unwrap();
        for who in [&r[ca], &r[cb]] {
            let e = first.entry(who.to_string()).or_insert(t);
            *e = e.min(t);
        }
        if &r[cb] == "bin/floor" {
            let p: f64 = r[cp].parse().unwrap();
            floor_peak_n = floor_peak_n.max(p);
            floor_over_80 += usize::from(p > 80.0);
            floor_contacts += 1;
        }
    }
    let apples = summary["apples"].as_array().unwrap();
    let source = &summary["sources"][0];
    let never_fed = summary["fates"]["never_fed"].as_u64().unwrap() as usize;
    assert_eq!(apples.len() + never_fed, 150, "{rel}: 150 apples planned");
    assert_eq!(
        source["still_waiting"].as_u64().unwrap() as usize,
        never_fed,
        "{rel}: the apples never fed were waiting for their spot"
    );
    let mut worst = (0.0f64, String::new());
    let mut moving = 0;
    for a in apples {
        let name = a["name"].as_str().unwrap();
        let fed = &a["fed"];
        let t0 = fed["time_s"].as_f64().unwrap();
        let vz = fed["velocity_m_s"][2].as_f64().unwrap();
        let tau = first[name] - t0;
        let fall = -(vz * tau - 0.5 * G * tau * tau);
        if fall > worst.0 {
            worst = (fall, name.to_string());
        }
        let fate = &a["fate"];
        if fate["kind"] == "moving" && fate["in_bin"] == "bin" {
            moving += 1;
        } else {
            assert_eq!(fate["kind"], "in_bin", "{rel}: {name}");
        }
    }
    let _ = std::fs::remove_dir_all(&out);
    let f = Fill {
        fed: apples.len(),
        moving,
        max_fall_m: worst.0,
        max_fall_apple: worst.1,
        floor_peak_n,
        floor_over_80,
        floor_contacts,
        waited: source["waited"].as_u64().unwrap(),
        wait_s: source["wait_total_s"].as_f64().unwrap(),
    };
    println!("{rel}: {f:?}");
    f
}

/// Issue 31's bin filler whose fill head is lowered with the bin
/// (scenarios/lines/bin_filler_head.json): the head rides the bin's lift (the same keyframes),
/// its spawn point 0.235 m above the floor, so no apple falls more than H = 0.2 m into the bin:
/// the smallest apple (70 mm) from its centre 0.235 m up to the bare floor, anything else it
/// lands on being higher. Each apple enters with the head's velocity (the lift's 13.3 mm/s) added
/// to its own 0.5 m/s.
///
/// The margin, from the physics: the floor sinks with the lift while the apple falls, v_lift
/// tau_max = 13.3 mm/s x 0.157 s = 2.1 mm (tau_max the fall time of H from 0.5 m/s: relative to
/// the bin the apple starts at 0.5 m/s); the contact is seen at the first step with an overlap,
/// at most one step's travel (1 mm, half rapier's prediction distance: the adaptive step's cap)
/// after the touch; symplectic Euler's centre trails the parabola by at most g dt tau / 2
/// (1.5 mm at 2 ms, the longest step the cap allows at 0.5 m/s). The spawn offset adds nothing:
/// a number jitter is horizontal. 4.6 mm in all. The fixed head over a fixed bin
/// (bin_filling.json) is held to its own cap, 0.3 m less the smallest radius, with the step's
/// part of the margin (nothing moves).
///
/// docs/lines.md, "A fill head lowered with the bin", compares the three fills (golden values of
/// the shipped runs at their printed digits: the piles are chaotic). The lowered head's heap
/// reaches it: its 124th apple comes to rest 71.5 mm under the next spawn point, so the last 26
/// are never fed (148 fed, the last two blocked, before steps landed on the emissions); and the fixed head over the lowered bin feeds its last apple at 17.1 s, so
/// at 18 s 14 of its apples are still settling in the bin (regression pins like the others;
/// re-pinned when adaptive steps stopped landing on the output samples, issue 31: before, all
/// 150 were fed and every apple was at rest at the end; the lowered head's 54 waited, 34.5 s;
/// the two fixed heads' rows re-pinned again when adaptive steps began to land on each source's
/// emission: before, 0.1261 m, 166.2 N, 22 of 177, 15 moving, 284.1 s; 0.2648 m, 257.1 N, 114 of
/// 269, 5 waited, 0.1 s).
#[test]
fn a_fill_head_lowered_with_the_bin_caps_every_fall() {
    let head = fill_from_files("scenarios/lines/bin_filler_head.json");
    let (h_set, v0, v_lift) = (0.2, 0.5, 0.2 / 15.0);
    let tau_max = ((v0 * v0 + 2.0 * G * h_set).sqrt() - v0) / G;
    let step_part = 1e-3 + 0.5 * G * 2e-3 * tau_max;
    let margin = v_lift * tau_max + step_part;
    println!(
        "tau_max {tau_max:.4} s: lift {:.2} mm, margin {:.2} mm",
        1e3 * v_lift * tau_max,
        1e3 * margin
    );
    assert!(margin <= 4.7e-3, "{margin}");
    assert!(head.max_fall_m <= h_set + margin, "{head:?}");
    let fixed_bin = fill_from_files("scenarios/lines/bin_filling.json");
    assert!(
        fixed_bin.max_fall_m <= 0.3 - 0.035 + step_part,
        "{fixed_bin:?}"
    );
    let fixed_head = fill_from_files("scenarios/lines/bin_filler.json");
    // Golden values (docs/lines.md's table; before the re-pin: head 150 fed, 0.2018 m, 218.6 N,
    // 86 of 229, 54 waited, 34.5 s; fixed head 0.1237 m, 132.7 N, 31 of 175, 149, 280.3 s; fixed
    // bin 0.2650 m, 268.3 N, 100 of 251, 12, 0.8 s).
    for (f, (fed, moving), fall, peak, over, n, waited, wait) in [
        (&head, (124, 0), 0.2018, 206.3, 64, 192, 72, 121.0),
        (&fixed_head, (150, 14), 0.1234, 133.2, 21, 172, 149, 319.0),
        (&fixed_bin, (150, 0), 0.2647, 255.4, 100, 255, 8, 0.2),
    ] {
        assert!(
            (f.fed, f.moving) == (fed, moving)
                && (f.max_fall_m - fall).abs() <= 1e-4
                && (f.floor_peak_n - peak).abs() <= 0.1
                && (f.floor_over_80, f.floor_contacts, f.waited) == (over, n, waited)
                && (f.wait_s - wait).abs() <= 0.1,
            "{f:?}"
        );
    }
    assert_eq!(head.max_fall_apple, "pour-6");
}
