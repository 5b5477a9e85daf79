//! Wall time per stage of a step, for profiling: built with `--features stage-clocks`, each stage
//! of [`super::ContactLayer::step_in`] and rapier's stepping (`World::advance`) adds its wall time
//! to a process-wide sum, which `examples/profile_window` prints per step of its window
//! (docs/performance.md, "The neighbour list's rebuild"). Without the feature a clock is never
//! read: [`Clock::start`] holds nothing and [`Clock::stop`] does nothing, and the optimiser removes
//! both. The sums are per process and shared by all threads: a profile of one run at a time.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// A stage of a step (in the order a step runs them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Reading the awake apples' bodies from rapier (and the riders' carried poses).
    Read,
    /// Detection: which contacts exist at the current poses (the rebuild included).
    Detect,
    /// Of detection: the neighbour list's rebuild, the surface candidates and the reorder of the
    /// contacts, when some apple moved half the skin.
    Rebuild,
    /// Of detection: the listed apple pairs examined at the current poses.
    Pairs,
    /// Of detection: the surface contacts found at the current poses.
    Surfaces,
    /// The contact law of every contact and the load sums.
    Law,
    /// The sleep rule.
    Sleep,
    /// Handing the forces to rapier's bodies.
    Handoff,
    /// rapier's stepping of every body set (`World::advance`).
    Rapier,
}

impl Stage {
    /// Every stage, in the order a step runs them.
    pub const ALL: [Stage; 9] = [
        Stage::Read,
        Stage::Detect,
        Stage::Rebuild,
        Stage::Pairs,
        Stage::Surfaces,
        Stage::Law,
        Stage::Sleep,
        Stage::Handoff,
        Stage::Rapier,
    ];

    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Read => "read",
            Stage::Detect => "detect",
            Stage::Rebuild => "of which rebuild",
            Stage::Pairs => "of which apple pairs",
            Stage::Surfaces => "of which surfaces",
            Stage::Law => "law and sums",
            Stage::Sleep => "sleep",
            Stage::Handoff => "hand-off",
            Stage::Rapier => "rapier",
        }
    }
}

/// Whether this build keeps the clocks (`--features stage-clocks`).
pub const ENABLED: bool = cfg!(feature = "stage-clocks");

static NANOS: [AtomicU64; Stage::ALL.len()] = [const { AtomicU64::new(0) }; Stage::ALL.len()];

/// A running clock of one stage (nothing without the feature).
#[must_use]
pub struct Clock(Option<Instant>);

impl Clock {
    /// Starts a clock.
    #[inline(always)]
    pub fn start() -> Self {
        Self(ENABLED.then(Instant::now))
    }

    /// Adds the time since [`Self::start`] to `stage`'s sum.
    #[inline(always)]
    pub fn stop(self, stage: Stage) {
        if let Some(t) = self.0 {
            NANOS[stage as usize].fetch_add(t.elapsed().as_nanos() as u64, Ordering::Relaxed);
        }
    }
}

/// Each stage's summed wall time since the last [`reset`] (s); zeros without the feature.
pub fn totals_s() -> [(Stage, f64); Stage::ALL.len()] {
    Stage::ALL.map(|s| (s, NANOS[s as usize].load(Ordering::Relaxed) as f64 * 1e-9))
}

/// Sets every sum to zero.
pub fn reset() {
    for n in &NANOS {
        n.store(0, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_clock_adds_to_its_stage_only_with_the_feature() {
        reset();
        let c = Clock::start();
        std::thread::sleep(std::time::Duration::from_millis(2));
        c.stop(Stage::Sleep);
        let t = totals_s();
        let sleep = t.iter().find(|(s, _)| *s == Stage::Sleep).unwrap().1;
        if ENABLED {
            // Other tests of this binary may add to the sums at the same time: at least ours.
            assert!(sleep >= 2e-3, "{sleep}");
        } else {
            assert!(t.iter().all(|(_, v)| *v == 0.0));
        }
    }
}
