//! The virtual instrumented sphere: an apple that records what an impact-recording sensor ball
//! (an "IRD" or instrumented sphere, Zapp et al. 1990) records on a real line, so that a simulated
//! line can be checked against a real audit.
//!
//! A real device samples its accelerometer at a fixed rate and keeps a window around each
//! sample that crosses its trigger level; for each window it reports the peak acceleration (g)
//! and the velocity change (the integral of the acceleration over the impact). Here the
//! accelerometer reads the probe's total contact force over its mass, |F| / m: what an
//! accelerometer measures (gravity is not felt in free fall; a probe at rest reads 1 g). The
//! reading between two steps is interpolated linearly at the sampling instants, so that the
//! trace is the one a device of that rate would see, with its sampling error (docs/analysis.md,
//! "Virtual instrumented sphere").

use crate::analysis::impacts::STANDARD_GRAVITY;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// How a probe apple samples (`apples[].probe` of a scenario).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    /// Sampling rate of the accelerometer (Hz). Real devices sample at 3-10 kHz; a pulse
    /// shorter than about ten samples has its peak under-read (docs/analysis.md).
    #[serde(default = "default_rate")]
    pub sample_rate_hz: f64,
    /// Trigger level (g): a sample at or above it starts an impact.
    #[serde(default = "default_trigger")]
    pub trigger_g: f64,
    /// Samples kept before the trigger and after the reading falls back under it (s).
    #[serde(default = "default_window")]
    pub window_s: f64,
}

fn default_rate() -> f64 {
    10_000.0
}
fn default_trigger() -> f64 {
    5.0
}
fn default_window() -> f64 {
    0.002
}

impl Default for ProbeSpec {
    fn default() -> Self {
        Self {
            sample_rate_hz: default_rate(),
            trigger_g: default_trigger(),
            window_s: default_window(),
        }
    }
}

/// Longest name of a probe apple (characters): its name makes the names of its two files,
/// `probe_NAME_trace.csv` and `probe_NAME_impacts.csv`, each written first under a temporary
/// name `.probe_NAME_impacts.csv.tmp-PID`: 31 characters more than NAME, and a file name has at
/// most 255 bytes on the common file systems (every character of NAME is one byte there, see
/// [`file_stem`]). 200 leaves a margin.
pub const MAX_PROBE_NAME_CHARS: usize = 200;

/// The file name stem of a probe apple's files: `probe_NAME`, with every character of the
/// apple's name but ASCII letters, digits, `-` and `_` replaced by `_` (a name may hold `/`,
/// spaces or letters a file system may not keep). Two names can make one stem ("a 1" and
/// "a_1"): validation refuses that, and names longer than [`MAX_PROBE_NAME_CHARS`].
pub fn file_stem(apple: &str) -> String {
    let safe: String = apple
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("probe_{safe}")
}

/// One impact as the device reports it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ProbeImpact {
    /// First sample at or above the trigger (s).
    pub t_trigger_s: f64,
    /// Start and end of the pulse: the samples where the reading, followed outwards from the
    /// triggered samples, stops falling (s).
    pub t_start_s: f64,
    /// End of the pulse (s).
    pub t_end_s: f64,
    /// Largest sample (g).
    pub peak_g: f64,
    /// Time of the largest sample (s).
    pub t_peak_s: f64,
    /// Velocity change: standard gravity times the trapezoid integral of the samples over the
    /// pulse (m/s).
    pub velocity_change_m_s: f64,
}

/// Records one probe apple's accelerometer.
#[derive(Debug, Clone)]
pub struct ProbeRecorder {
    spec: ProbeSpec,
    mass_kg: f64,
    /// The last observed (time, reading in g).
    last: Option<(f64, f64)>,
    /// Index of the next sampling instant.
    next: u64,
    /// Samples before a trigger (time, g), at most the window.
    pre: VecDeque<(f64, f64)>,
    /// The samples kept: windows around impacts, in order of time.
    trace: Vec<(f64, f64)>,
    /// Samples of the window being recorded (pre-trigger ones included).
    current: Vec<(f64, f64)>,
    /// Samples left to record after the reading fell under the trigger (0: not recording).
    post_left: usize,
    window_samples: usize,
    impacts: Vec<ProbeImpact>,
}

impl ProbeRecorder {
    /// A recorder for an apple of `mass_kg`.
    pub fn new(spec: ProbeSpec, mass_kg: f64) -> Self {
        let window_samples = (spec.window_s * spec.sample_rate_hz).ceil().max(1.0) as usize;
        Self {
            spec,
            mass_kg,
            last: None,
            next: 0,
            pre: VecDeque::with_capacity(window_samples + 1),
            trace: Vec::new(),
            current: Vec::new(),
            post_left: 0,
            window_samples,
            impacts: Vec::new(),
        }
    }

    /// Observes the probe's total contact force `force_n` (magnitude, N) at the poses of
    /// `time_s`. Samples every sampling instant up to `time_s`, interpolating from the last
    /// observation.
    pub fn observe(&mut self, time_s: f64, force_n: f64) {
        let g = force_n / (self.mass_kg * STANDARD_GRAVITY);
        let period = 1.0 / self.spec.sample_rate_hz;
        loop {
            // k / f, not k * (1 / f): the instant nearest to the device's clock tick, printed
            // as a person writes it (2.2211, not 2.2211000000000003).
            let ts = self.next as f64 / self.spec.sample_rate_hz;
            if ts > time_s + 1e-12 * period {
                break;
            }
            let value = match self.last {
                Some((t0, g0)) if time_s > t0 && ts < time_s => {
                    g0 + (g - g0) * ((ts - t0) / (time_s - t0)).max(0.0)
                }
                _ => g,
            };
            self.sample(ts, value);
            self.next += 1;
        }
        self.last = Some((time_s, g));
    }

    fn sample(&mut self, t: f64, g: f64) {
        let above = g >= self.spec.trigger_g;
        if self.current.is_empty() {
            if above {
                self.current.extend(self.pre.drain(..));
                self.current.push((t, g));
                self.post_left = self.window_samples;
            } else {
                if self.pre.len() == self.window_samples {
                    self.pre.pop_front();
                }
                self.pre.push_back((t, g));
            }
            return;
        }
        self.current.push((t, g));
        if above {
            self.post_left = self.window_samples;
        } else {
            self.post_left -= 1;
            if self.post_left == 0 {
                self.close();
            }
        }
    }

    /// Ends the window being recorded: its impacts go to the table, its samples to the trace.
    fn close(&mut self) {
        let w = std::mem::take(&mut self.current);
        self.impacts.extend(impacts_of(&w, self.spec.trigger_g));
        self.trace.extend_from_slice(&w);
    }

    /// How it samples.
    pub fn spec(&self) -> &ProbeSpec {
        &self.spec
    }

    /// The trace (time s, reading g) and the impacts, closing a window still open at the end.
    pub fn finish(mut self) -> (Vec<(f64, f64)>, Vec<ProbeImpact>) {
        if !self.current.is_empty() {
            self.close();
        }
        (self.trace, self.impacts)
    }
}

/// The impacts in one window of samples: each run of samples at or above `trigger` is one
/// impact, widened on each side while the reading keeps falling (the foot of the pulse, down to
/// the reading at rest or in flight).
pub fn impacts_of(w: &[(f64, f64)], trigger: f64) -> Vec<ProbeImpact> {
    let mut out = Vec::new();
    let mut k = 0;
    while k < w.len() {
        if w[k].1 < trigger {
            k += 1;
            continue;
        }
        let first = k;
        while k < w.len() && w[k].1 >= trigger {
            k += 1;
        }
        let last = k - 1;
        let mut a = first;
        while a > 0 && w[a - 1].1 < w[a].1 {
            a -= 1;
        }
        let mut b = last;
        while b + 1 < w.len() && w[b + 1].1 < w[b].1 {
            b += 1;
        }
        let (mut peak, mut t_peak) = (f64::NEG_INFINITY, w[first].0);
        for &(t, g) in &w[first..=last] {
            if g > peak {
                peak = g;
                t_peak = t;
            }
        }
        let area: f64 = w[a..=b]
            .windows(2)
            .map(|p| 0.5 * (p[0].1 + p[1].1) * (p[1].0 - p[0].0))
            .sum();
        out.push(ProbeImpact {
            t_trigger_s: w[first].0,
            t_start_s: w[a].0,
            t_end_s: w[b].0,
            peak_g: peak,
            t_peak_s: t_peak,
            velocity_change_m_s: area * STANDARD_GRAVITY,
        });
        k = b.max(last) + 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A half-sine pulse of amplitude A g and length T sampled finely: peak A, velocity change
    /// g0 A 2 T / pi (the half-sine's area).
    #[test]
    fn a_half_sine_pulse_reads_its_peak_and_area() {
        let spec = ProbeSpec {
            sample_rate_hz: 1e6,
            trigger_g: 5.0,
            window_s: 1e-3,
        };
        let m = 0.2;
        let (amp, len) = (100.0, 4e-3);
        let mut r = ProbeRecorder::new(spec, m);
        let dt = 1e-6;
        for k in 0..20_000 {
            let t = k as f64 * dt;
            let x = (t - 0.005) / len;
            let g = if (0.0..=1.0).contains(&x) {
                amp * (std::f64::consts::PI * x).sin()
            } else {
                0.0
            };
            r.observe(t, g * m * STANDARD_GRAVITY);
        }
        let (trace, imp) = r.finish();
        assert_eq!(imp.len(), 1);
        let i = imp[0];
        assert!((i.peak_g - amp).abs() < 1e-6 * amp, "{i:?}");
        let dv = STANDARD_GRAVITY * amp * 2.0 * len / std::f64::consts::PI;
        assert!(
            (i.velocity_change_m_s / dv - 1.0).abs() < 1e-6,
            "{i:?} {dv}"
        );
        assert!((i.t_start_s - 0.005).abs() < 2e-6 && (i.t_end_s - 0.009).abs() < 2e-6);
        // The trace holds the window: 1 ms before the trigger to 1 ms after the reading fell back
        // under it (sin(pi x) = 5 / 100 at x = 1 - asin(0.05) / pi).
        let fall = 0.005 + len * (1.0 - (0.05f64).asin() / std::f64::consts::PI);
        assert!(trace.first().unwrap().0 < i.t_trigger_s - 0.99e-3);
        let last = trace.last().unwrap().0;
        assert!(
            last > fall + 0.99e-3 && last < fall + 1.01e-3,
            "{last} {fall}"
        );
    }

    /// Sampled more coarsely than the steps, the reading is the interpolated value at each
    /// sampling instant (a device of that rate), and two pulses are two impacts.
    #[test]
    fn samples_fall_on_the_device_clock() {
        let spec = ProbeSpec {
            sample_rate_hz: 1000.0,
            trigger_g: 5.0,
            window_s: 1e-3,
        };
        let mut r = ProbeRecorder::new(spec, 1.0 / STANDARD_GRAVITY);
        // Steps of 0.4 ms; the force in N equals the reading in g.
        for k in 0..100 {
            let t = k as f64 * 4e-4;
            let g = if (10..20).contains(&k) || (60..70).contains(&k) {
                t * 1000.0
            } else {
                0.0
            };
            r.observe(t, g);
        }
        let (trace, imp) = r.finish();
        assert_eq!(imp.len(), 2);
        assert!(trace
            .iter()
            .all(|&(t, _)| (t * 1000.0 - (t * 1000.0).round()).abs() < 1e-9));
        // At t = 5 ms (between steps 12 and 13: 4.8 ms and 5.2 ms) the reading is 5.0.
        let at5 = trace.iter().find(|p| (p.0 - 5e-3).abs() < 1e-9).unwrap();
        assert!((at5.1 - 5.0).abs() < 1e-9, "{at5:?}");
    }
}
