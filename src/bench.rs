//! Performance measurement of a whole run (`applesim bench`, issue 11): the figures a DEM code
//! such as LIGGGHTS reports for the same scene, so that the two can be set side by side.
//!
//! A run is stepped with [`Simulation::step`] and no outputs, and measured per window of
//! simulated time `[from, to)`: steps, wall time, apple-steps per second (apples present x steps
//! / wall seconds: what LIGGGHTS's loop timings give), mean awake apples, and contacts per apple
//! at the window's end, and for an adaptive run what set its steps ([`StepsSetBy`]: the user who
//! trades speed for accuracy sees which contacts the steps are spent on). Only the steps are timed: the bookkeeping of the measurement (counting
//! sleepers and contacts) runs between them, off the clock, so that it does not inflate the cost
//! being measured.

use crate::layer::StepLimit;
use crate::record::series::NoSamples;
use crate::scenario::{Scenario, ScenarioError};
use crate::sim::{SimError, Simulation};
use serde::Serialize;
use std::path::Path;
use std::time::Instant;
use thiserror::Error;

/// Errors of a benchmark run.
#[derive(Debug, Error)]
pub enum BenchError {
    /// A window argument that is not `A:B` with 0 <= A < B.
    #[error("--window '{text}': {message}")]
    BadWindow {
        /// The argument as given.
        text: String,
        /// What is wrong.
        message: String,
    },
    /// A window that does not lie within the run.
    #[error("window {from_s}:{to_s} s: {message}")]
    OutsideRun {
        /// Window start (s).
        from_s: f64,
        /// Window end (s).
        to_s: f64,
        /// What is wrong.
        message: String,
    },
    /// The scenario is wrong.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The world could not be built, or the run went wrong (unstable, too many steps).
    #[error(transparent)]
    Run(#[from] SimError),
}

/// A window of simulated time `[from_s, to_s)`: the steps that start in it are measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Window {
    /// Name in reports: the LIGGGHTS phase (`falling`, `impact`, `settled`), `whole run`, or
    /// `A:B` for a window given by hand.
    pub label: String,
    /// Start (s of simulated time).
    pub from_s: f64,
    /// End, excluded (s of simulated time).
    pub to_s: f64,
}

impl Window {
    /// Parses `A:B` (seconds of simulated time, 0 <= A < B).
    pub fn parse(text: &str) -> Result<Self, BenchError> {
        let bad = |message: &str| BenchError::BadWindow {
            text: text.to_string(),
            message: message.to_string(),
        };
        let (a, b) = text
            .split_once(':')
            .ok_or_else(|| bad("give FROM:TO in seconds of simulated time, e.g. 0.5:1"))?;
        let num = |s: &str| -> Result<f64, BenchError> {
            s.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(&format!("'{s}' is not a finite number of seconds")))
        };
        let (from_s, to_s) = (num(a)?, num(b)?);
        if from_s < 0.0 || to_s <= from_s {
            return Err(bad("needs 0 <= FROM < TO"));
        }
        Ok(Self {
            label: text.trim().to_string(),
            from_s,
            to_s,
        })
    }

    /// The LIGGGHTS reference phases (shared/bench/liggghts/README.md: falling 0-0.5 s, impact
    /// 0.5-1 s, settled 3-5 s) for a run of at least 5 s, otherwise the whole run.
    pub fn defaults(duration_s: f64) -> Vec<Self> {
        let w = |label: &str, from_s: f64, to_s: f64| Self {
            label: label.to_string(),
            from_s,
            to_s,
        };
        if duration_s >= 5.0 * (1.0 - 1e-9) {
            vec![
                w("falling", 0.0, 0.5),
                w("impact", 0.5, 1.0),
                w("settled", 3.0, 5.0),
            ]
        } else {
            vec![w("whole run", 0.0, duration_s)]
        }
    }
}

/// The figures of one window.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WindowReport {
    /// The window.
    #[serde(flatten)]
    pub window: Window,
    /// Steps that started in the window.
    pub steps: u64,
    /// Wall time of those steps (s).
    pub wall_s: f64,
    /// Apples present x steps / wall seconds, summed step by step (`None` without steps).
    pub apple_steps_per_s: Option<f64>,
    /// Apples neither asleep nor riding a belt, averaged over the window's steps (`None` without
    /// steps).
    pub mean_awake_apples: Option<f64>,
    /// Apples riding a belt (carried, their contact frozen), averaged over the window's steps
    /// (`None` without steps).
    pub mean_riding_apples: Option<f64>,
    /// Apples present at the window's end.
    pub apples_at_end: usize,
    /// Open contacts (apple-apple and apple-surface, sleepers' frozen contacts included) per apple
    /// at the window's end.
    pub contacts_per_apple: f64,
    /// Apple-apple contacts per apple at the window's end, each pair counted once (LIGGGHTS's
    /// `compute contact/atom` average is twice this: it counts each contact at both apples).
    pub apple_apple_contacts_per_apple: f64,
    /// Simulated time over steps: the mean step of the window (s; `None` without steps).
    pub mean_step_s: Option<f64>,
    /// What set the window's steps.
    pub steps_set_by: StepsSetBy,
}

/// How many of a window's steps each cause set (adaptive steps, `docs/accuracy.md`): the step
/// taken is the shortest of the layer's limit (an impact, a resting contact, a pair about to
/// touch, the pair-finding margins) and the driver's (the fixed step, the largest step, growth
/// by at most 2x a step, landing on the end).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct StepsSetBy {
    /// An impact in progress: N steps per contact time (`accuracy`).
    pub impact: u64,
    /// A resting contact: its normal oscillation, its stick spring, or the stability of its
    /// tangential damping.
    pub resting: u64,
    /// A pair about to touch.
    pub approaching: u64,
    /// An apple moving fast: the pair-finding margins.
    pub motion: u64,
    /// The driver: a fixed step, the largest step, the growth cap, or landing on the end.
    pub driver: u64,
}

impl StepsSetBy {
    /// Counts one step, set by the layer's limit (`by_limit`) for the reason `why`, or by the
    /// driver.
    fn count(&mut self, by_limit: bool, why: StepLimit) {
        let slot = match why {
            _ if !by_limit => &mut self.driver,
            StepLimit::Impact => &mut self.impact,
            StepLimit::Resting => &mut self.resting,
            StepLimit::Approaching => &mut self.approaching,
            StepLimit::Motion => &mut self.motion,
            StepLimit::None => &mut self.driver,
        };
        *slot += 1;
    }

    /// The causes with their shares of `steps`, largest first, those under 0.5 % left out:
    /// `impact 97 %, resting 3 %`.
    pub fn describe(&self, steps: u64) -> String {
        let mut parts = [
            ("impact", self.impact),
            ("resting", self.resting),
            ("approaching", self.approaching),
            ("motion", self.motion),
            ("driver", self.driver),
        ];
        parts.sort_by_key(|p| std::cmp::Reverse(p.1));
        let shown: Vec<String> = parts
            .iter()
            .filter(|(_, n)| steps > 0 && 200 * n >= steps)
            .map(|(name, n)| format!("{name} {:.0} %", 100.0 * *n as f64 / steps as f64))
            .collect();
        if shown.is_empty() {
            "-".into()
        } else {
            shown.join(", ")
        }
    }
}

/// Everything `applesim bench` reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BenchReport {
    /// Rayon threads the run had (`--threads`).
    pub threads: usize,
    /// rapier body sets the apples were spread over, stepped concurrently (1 on one thread, or
    /// with fewer than [`crate::world::APPLE_SETS_MIN_APPLES`] apples).
    pub body_sets: usize,
    /// Apples at the start.
    pub apples: usize,
    /// Steps taken.
    pub steps: u64,
    /// The fixed step, or the first step of an adaptive run (s).
    pub time_step_s: f64,
    /// Simulated time reached (s).
    pub simulated_time_s: f64,
    /// Wall time of building the world (rapier bodies, colliders, first pair search) (s); not
    /// part of `wall_s`, as LIGGGHTS's setup is not part of its loop time.
    pub setup_wall_s: f64,
    /// Per window.
    pub windows: Vec<WindowReport>,
    /// Wall time of all steps, the time loop (s).
    pub wall_s: f64,
    /// Apples present x steps / wall seconds over the whole run.
    pub apple_steps_per_s: f64,
    /// Largest apple-centre z at the end (m): LIGGGHTS's `reduce max z` of in.apple, the height
    /// of the settled pile.
    pub pile_height_m: f64,
    /// Peak resident memory of the process (MiB, VmHWM); `None` where /proc is missing.
    pub peak_rss_mib: Option<f64>,
}

/// Window bookkeeping during a run.
struct Meter {
    window: Window,
    steps: u64,
    wall_s: f64,
    apple_steps: f64,
    awake_sum: f64,
    riding_sum: f64,
    simulated_s: f64,
    set_by: StepsSetBy,
    end: Option<(usize, f64, f64)>,
}

/// Runs a validated scenario to its end and measures it. `base_dir` resolves relative asset
/// paths (meshes); `windows` must lie within the run (an empty list means the defaults,
/// [`Window::defaults`]).
pub fn run(sc: &Scenario, base_dir: &Path, windows: &[Window]) -> Result<BenchReport, BenchError> {
    let windows = if windows.is_empty() {
        Window::defaults(sc.duration_s)
    } else {
        windows.to_vec()
    };
    // A window is taken to reach the end of the run when it ends within a billionth of the
    // duration of it (5 s is 5 s, whatever rounding the step sum has).
    let tol = 1e-9 * sc.duration_s;
    for w in &windows {
        if w.to_s > sc.duration_s + tol {
            return Err(BenchError::OutsideRun {
                from_s: w.from_s,
                to_s: w.to_s,
                message: format!("ends after the run (duration_s = {} s)", sc.duration_s),
            });
        }
    }
    let setup = Instant::now();
    let mut sim = Simulation::new(sc, base_dir)?;
    let setup_wall_s = setup.elapsed().as_secs_f64();
    let time_step_s = sim.plan().initial_s;
    for w in &windows {
        if w.to_s - w.from_s < time_step_s * (1.0 - 1e-9) {
            return Err(BenchError::OutsideRun {
                from_s: w.from_s,
                to_s: w.to_s,
                message: format!("shorter than one time step ({time_step_s} s)"),
            });
        }
    }
    let apples = sim.world().layer.apple_count();
    let mut meters: Vec<Meter> = windows
        .into_iter()
        .map(|window| Meter {
            window,
            steps: 0,
            wall_s: 0.0,
            apple_steps: 0.0,
            awake_sum: 0.0,
            riding_sum: 0.0,
            simulated_s: 0.0,
            set_by: StepsSetBy::default(),
            end: None,
        })
        .collect();
    let mut wall_s = 0.0;
    let mut apple_steps = 0.0;
    while !sim.done() {
        let t = sim.time_s();
        close_ended(&mut meters, &sim, t, tol);
        let clock = Instant::now();
        sim.step(&mut NoSamples)?;
        let dt_wall = clock.elapsed().as_secs_f64();
        let layer = &sim.world().layer;
        let present = layer.apple_count() as f64;
        let dt = sim.time_s() - t;
        let stats = layer.stats();
        wall_s += dt_wall;
        apple_steps += present;
        let mut awake = None;
        for m in meters.iter_mut() {
            if m.end.is_none() && t >= m.window.from_s - tol && t < m.window.to_s - tol {
                m.steps += 1;
                m.wall_s += dt_wall;
                m.apple_steps += present;
                m.awake_sum += *awake.get_or_insert_with(|| layer.awake_count() as f64);
                m.riding_sum += layer.riding_count() as f64;
                m.simulated_s += dt;
                m.set_by.count(stats.dt_set_by_limit, stats.dt_limit_reason);
            }
        }
    }
    close_ended(&mut meters, &sim, f64::INFINITY, tol);
    let pile_height_m = sim
        .apple_states()
        .iter()
        .map(|s| s.position.z)
        .fold(f64::NEG_INFINITY, f64::max);
    let windows = meters
        .into_iter()
        .map(|m| {
            let (apples_at_end, all, apple_apple) = m.end.unwrap_or((0, 0.0, 0.0));
            let per = |x: f64| {
                if apples_at_end > 0 {
                    x / apples_at_end as f64
                } else {
                    0.0
                }
            };
            WindowReport {
                steps: m.steps,
                wall_s: m.wall_s,
                apple_steps_per_s: (m.steps > 0 && m.wall_s > 0.0)
                    .then(|| m.apple_steps / m.wall_s),
                mean_awake_apples: (m.steps > 0).then(|| m.awake_sum / m.steps as f64),
                mean_riding_apples: (m.steps > 0).then(|| m.riding_sum / m.steps as f64),
                apples_at_end,
                contacts_per_apple: per(all),
                apple_apple_contacts_per_apple: per(apple_apple),
                mean_step_s: (m.steps > 0).then(|| m.simulated_s / m.steps as f64),
                steps_set_by: m.set_by,
                window: m.window,
            }
        })
        .collect();
    Ok(BenchReport {
        threads: rayon::current_num_threads(),
        body_sets: sim.world().body_set_count(),
        apples,
        steps: sim.steps_done(),
        time_step_s,
        simulated_time_s: sim.time_s(),
        setup_wall_s,
        windows,
        wall_s,
        apple_steps_per_s: if wall_s > 0.0 {
            apple_steps / wall_s
        } else {
            0.0
        },
        pile_height_m,
        peak_rss_mib: peak_rss_mib(),
    })
}

/// Takes the end-of-window figures of the windows that end at `t` (the time of the poses about
/// to be stepped from). Contacts are the layer's open contacts as of its last force pass, which
/// include the frozen contacts of sleeping apples (the per-step statistics skip those).
fn close_ended(meters: &mut [Meter], sim: &Simulation, t: f64, tol: f64) {
    if !meters
        .iter()
        .any(|m| m.end.is_none() && t >= m.window.to_s - tol)
    {
        return;
    }
    let layer = &sim.world().layer;
    let (all, apple_apple) = layer.contact_counts();
    let figures = (layer.apple_count(), all as f64, apple_apple as f64);
    for m in meters.iter_mut() {
        if m.end.is_none() && t >= m.window.to_s - tol {
            m.end = Some(figures);
        }
    }
}

/// Peak resident memory of this process (MiB): `VmHWM` of /proc/self/status; `None` where
/// /proc is missing (not Linux) or unreadable.
pub fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line
        .trim_start_matches("VmHWM:")
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kib / 1024.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_parse_and_refuse() {
        let w = Window::parse("0.5:1").unwrap();
        assert_eq!((w.from_s, w.to_s, w.label.as_str()), (0.5, 1.0, "0.5:1"));
        for bad in ["0.5", "1:0.5", "a:1", "-1:1", "1:1", "0:inf", "0:NaN"] {
            assert!(Window::parse(bad).is_err(), "{bad} accepted");
        }
        let d = Window::defaults(5.0);
        assert_eq!(
            d.iter().map(|w| (w.from_s, w.to_s)).collect::<Vec<_>>(),
            [(0.0, 0.5), (0.5, 1.0), (3.0, 5.0)]
        );
        let d = Window::defaults(1.5);
        assert_eq!((d.len(), d[0].from_s, d[0].to_s), (1, 0.0, 1.5));
    }

    #[test]
    fn peak_rss_is_read_on_linux() {
        if Path::new("/proc/self/status").exists() {
            let m = peak_rss_mib().expect("VmHWM in /proc/self/status");
            assert!(m > 0.0 && m < 1e6, "{m} MiB");
        }
    }
}
