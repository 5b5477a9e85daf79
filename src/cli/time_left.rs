//! The time left of a run, for its progress bar (issue 31): the simulated time still to go over
//! the rate at which simulated time has advanced lately.
//!
//! A run's cost per simulated second changes along it: apples fed in, a pile building up,
//! adaptive steps long in free flight and short through impacts, apples falling asleep. The
//! average rate since the start then misjudges the rest (a bin fill gets dearer as it fills), and
//! the progress bar's own estimate, fed with positions in jumps, read "1s left" through most of a
//! 6.6 s run. The rate here is measured over a recent window: the last quarter of the elapsed
//! time, and at least [`MIN_WINDOW_S`]. Nothing of the run's results depends on it.

use std::collections::VecDeque;

/// The shortest window the rate is measured over (s of the clock).
pub const MIN_WINDOW_S: f64 = 2.0;

/// The share of the elapsed time the window spans once that is longer.
pub const WINDOW_SHARE: f64 = 0.25;

/// The estimator: fed (clock, fraction of the simulated time done) as the run goes.
#[derive(Debug, Default)]
pub struct TimeLeft {
    seen: VecDeque<(f64, f64)>,
}

impl TimeLeft {
    /// Records that at `clock_s` (wall seconds since the start) the run had done `fraction` of its
    /// simulated time, and returns the clock seconds left at the recent rate (`None` until the
    /// rate is known).
    pub fn observe(&mut self, clock_s: f64, fraction: f64) -> Option<f64> {
        self.seen.push_back((clock_s, fraction));
        let window = MIN_WINDOW_S.max(WINDOW_SHARE * clock_s);
        // Keep the newest sample at or before the window's start, and what follows it.
        while self.seen.len() > 2 && self.seen[1].0 <= clock_s - window {
            self.seen.pop_front();
        }
        let &(c0, f0) = self.seen.front()?;
        (clock_s > c0 && fraction > f0)
            .then(|| (1.0 - fraction).max(0.0) * (clock_s - c0) / (fraction - f0))
    }
}

/// Seconds as the bar shows them: "4s", "1m 05s", "2h 03m".
pub fn show(s: f64) -> String {
    let s = s.max(0.0).round() as u64;
    match s {
        0..=59 => format!("{s}s"),
        60..=3599 => format!("{}m {:02}s", s / 60, s % 60),
        _ => format!("{}h {:02}m", s / 3600, (s % 3600) / 60),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_steady_run_is_read_exactly() {
        let mut t = TimeLeft::default();
        let mut last = None;
        for k in 1..=100 {
            let clock = 0.1 * k as f64;
            last = t.observe(clock, clock / 10.0);
            if k > 1 {
                let left = last.unwrap();
                assert!((left - (10.0 - clock)).abs() < 1e-9, "{k}: {left}");
            }
        }
        assert!(last.unwrap().abs() < 1e-9);
        assert_eq!(show(65.4), "1m 05s");
        assert_eq!(show(7384.0), "2h 03m");
        assert_eq!(show(-1.0), "0s");
    }

    /// The shipped bin fill: apples are fed in over 18 s and pile up, so a simulated second
    /// costs more and more (its adaptive steps shorten as contacts grow, each step costs more
    /// per apple). The clock here is deterministic: each step costs one unit per apple present,
    /// the work a step does. Against the truth (the cost still to come), the recent rate must
    /// read the second half of the run far better than the average since the start, which the
    /// bar's own estimate amounted to.
    #[test]
    fn a_run_whose_cost_grows_is_read_from_its_recent_rate() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let path = root.join("scenarios/lines/bin_filling.json");
        let mut sc = applesim::scenario::load(&path).unwrap();
        sc.duration_s = 9.0;
        let mut sim = applesim::sim::Simulation::new(&sc, &root.join("scenarios/lines")).unwrap();
        let mut sink = applesim::record::series::NoSamples;
        let (mut cost, mut next) = (0.0, 0.0);
        let mut trace = vec![];
        while !sim.done() {
            sim.step(&mut sink).unwrap();
            cost += sim.world().roster.len() as f64;
            let f = sim.time_s() / sc.duration_s;
            if f >= next {
                trace.push((cost, f));
                next += 0.005;
            }
        }
        let total = cost;
        let (mut recent, mut average) = (vec![], vec![]);
        let mut t = TimeLeft::default();
        for &(c, f) in &trace {
            let est = t.observe(c / total * 100.0, f).map(|x| x * total / 100.0);
            if (0.5..0.99).contains(&f) {
                let truth = total - c;
                recent.push((est.unwrap() - truth).abs() / truth);
                average.push((c * (1.0 - f) / f - truth).abs() / truth);
            }
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        println!(
            "second half: recent rate off by {:.1} % on average, worst {:.1} %; the average since the start {:.1} %",
            100.0 * mean(&recent),
            100.0 * recent.iter().copied().fold(0.0, f64::max),
            100.0 * mean(&average)
        );
        assert!(mean(&recent) < 0.5 * mean(&average));
    }
}
