//! SVG charts of one or several run folders (`applesim run --plots`, `applesim plot`): the
//! paper's Figs. 1-5 (normal force against time since first touch, one curve per contact, several
//! runs on one chart) and Figs. 6-7 (speed and angular speed of the apples against time); with
//! `transitions.csv`, the slip speed against time with the transitions marked and, per surface, a
//! histogram of where apples start rolling.
//!
//! Charts are drawn from the files of the run folders, read by [`run_folder`], so saved runs can
//! be compared at any time; the drawing itself is [`crate::chart`]'s. Every chart is written
//! whole or not at all.

pub mod run_folder;

pub use run_folder::{read_run, ForceCurve, Kinematics, RunCurves, TransitionMark, FORCES_HEADER};

use crate::chart::{decimate, histogram_outline, ChartError, LineChart, Series};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Force chart (the paper's Figs. 1-5). The chart file names are fixed so that a script, a test or
/// a reader of the report finds the same chart in every run folder.
pub const FORCE_CHART: &str = "force_time.svg";
/// Linear speed chart.
pub const SPEED_CHART: &str = "linear_velocity.svg";
/// Angular speed chart.
pub const SPIN_CHART: &str = "angular_velocity.svg";
/// Slip speed chart with the transitions marked.
pub const SLIP_CHART: &str = "slip_speed.svg";
/// Where apples start rolling, per surface.
pub const ROLLING_STARTS_CHART: &str = "rolling_starts.svg";

/// Most points drawn per curve; longer series are reduced by [`decimate`], which keeps each
/// bucket's min and max, so short impact spikes survive.
pub const MAX_POINTS_PER_SERIES: usize = 4000;

/// Errors of the run charts: reading a run folder, or drawing and writing a chart.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// File.
        path: PathBuf,
        /// OS error.
        source: std::io::Error,
    },
    /// A CSV file of a run could not be parsed.
    #[error("{path}: {message}")]
    Parse {
        /// File.
        path: PathBuf,
        /// What was wrong.
        message: String,
    },
    /// Nothing to draw.
    #[error("{0}")]
    Empty(String),
    /// A chart could not be drawn or written.
    #[error(transparent)]
    Chart(#[from] ChartError),
    /// A time window given as an argument is not `FROM:TO` with FROM < TO.
    #[error("{flag} {text}: {message}")]
    BadWindow {
        /// The option (`--window`, `--time-window`).
        flag: String,
        /// The argument as given.
        text: String,
        /// What is wrong.
        message: String,
    },
}

/// A time window of a chart: the part of its time axis drawn, `from..=to` in the chart's own
/// unit (ms since first touch for the force chart, s for the charts against time).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartWindow {
    /// Start.
    pub from: f64,
    /// End.
    pub to: f64,
}

impl ChartWindow {
    /// Parses `FROM:TO` (0 <= FROM < TO, in `unit`) given to the option `flag`; either end may
    /// be left out (`:20` is 0 to 20, `5:` from 5 to the end).
    pub fn parse(flag: &str, text: &str, unit: &str) -> Result<Self, PlotError> {
        let bad = |message: String| PlotError::BadWindow {
            flag: flag.to_string(),
            text: text.to_string(),
            message,
        };
        let (a, b) = text
            .split_once(':')
            .ok_or_else(|| bad(format!("give FROM:TO in {unit}, e.g. 0:20")))?;
        let num = |s: &str, empty: f64| -> Result<f64, PlotError> {
            let s = s.trim();
            if s.is_empty() {
                return Ok(empty);
            }
            s.parse::<f64>()
                .ok()
                .filter(|x| !x.is_nan())
                .ok_or_else(|| bad(format!("'{s}' is not a number of {unit}")))
        };
        let (from, to) = (num(a, 0.0)?, num(b, f64::INFINITY)?);
        if !(from >= 0.0 && from.is_finite() && to > from) {
            return Err(bad(format!("needs 0 <= FROM < TO ({unit})")));
        }
        Ok(Self { from, to })
    }

    /// Whether `x` lies in the window.
    pub fn contains(&self, x: f64) -> bool {
        x >= self.from && x <= self.to
    }

    /// The part of a curve inside the window, with points interpolated where it crosses the
    /// window's ends, so that a curve cut by the window still reaches its edge.
    pub fn clip(&self, points: &[(f64, f64)]) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        let at = |p: (f64, f64), q: (f64, f64), x: f64| {
            let f = if q.0 != p.0 {
                (x - p.0) / (q.0 - p.0)
            } else {
                0.0
            };
            (x, p.1 + f * (q.1 - p.1))
        };
        for (i, &p) in points.iter().enumerate() {
            if let Some(&q) = i.checked_sub(1).and_then(|j| points.get(j)) {
                // Entering through the start, or leaving through the end, between q and p.
                if q.0 < self.from && p.0 > self.from {
                    out.push(at(q, p, self.from));
                }
                if q.0 < self.to && p.0 > self.to {
                    out.push(at(q, p, self.to));
                }
            }
            if self.contains(p.0) {
                out.push(p);
            }
        }
        out
    }
}

/// Choices of [`plot_runs`].
#[derive(Debug, Clone, PartialEq)]
pub struct PlotOptions {
    /// Most curves per chart (the largest peak forces; the first apples).
    pub max_series: usize,
    /// Only these apples (all when empty).
    pub apples: Vec<String>,
    /// Time window of the force chart (ms since first touch); `None`: [`force_window`].
    pub force_window_ms: Option<ChartWindow>,
    /// Time window of the charts against time (slip, speed, angular speed; s of simulated
    /// time); `None`: the whole run.
    pub time_window_s: Option<ChartWindow>,
    /// Bin width of the rolling-start histogram (m).
    pub histogram_bin_m: f64,
}

impl Default for PlotOptions {
    fn default() -> Self {
        Self {
            max_series: 10,
            apples: Vec::new(),
            force_window_ms: None,
            time_window_s: None,
            histogram_bin_m: 0.05,
        }
    }
}

/// Below this share of its peak a contact's force counts as past its impact pulse (the fallback
/// of [`force_window_ms`], for run folders without `impact_duration_s`).
pub const PULSE_END_SHARE: f64 = 0.25;

/// The margin of the force chart's default window after the last impact pulse, as a share of
/// that pulse: enough to see the force settle to its resting level, or reach zero.
pub const IMPACT_WINDOW_MARGIN: f64 = 0.2;

/// An impact reported longer than this many times its rise to the peak is no pulse: the contact
/// record ends an impact at separation or when the overlap turns back to loading, and an apple
/// that lands without rebounding (an overdamped landing on a belt) never turns back, so its
/// "impact" spans its whole resting time. A rebound lasts about 1 to 5 times its rise (elastic:
/// 2; eq. 12 with ke = 0.09: about 4.3).
pub const PULSE_RISE_FACTOR: f64 = 20.0;

/// The end of a curve's impact pulse (s since touch): `impact_duration_s` when it is a pulse,
/// else the first instant after the peak when the force has come three quarters of the way down
/// to the level it ends at (its resting load, or zero); `None` for a contact without an impact.
pub fn pulse_end_s(c: &ForceCurve) -> Option<f64> {
    let d = c.impact_duration_s?;
    let (ipk, peak) =
        c.points.iter().enumerate().fold(
            (0, f64::MIN),
            |a, (i, p)| if p.1 > a.1 { (i, p.1) } else { a },
        );
    let t_peak = c.points.get(ipk).map_or(0.0, |p| p.0);
    if d <= PULSE_RISE_FACTOR * t_peak || t_peak <= 0.0 {
        return Some(d);
    }
    let last = c.points.last().map_or(0.0, |p| p.1);
    let level = last + PULSE_END_SHARE * (peak - last);
    c.points[ipk..]
        .iter()
        .find(|p| p.1 <= level)
        .map(|p| p.0)
        .or(Some(d))
}

/// The default time window of the force chart (ms since first touch): from the touch to the end
/// of the last impact pulse of the curves drawn ([`pulse_end_s`]: `contacts.csv`
/// `impact_duration_s`, the pulse until the apple rebounds or its overlap turns back to loading),
/// plus [`IMPACT_WINDOW_MARGIN`] of it, and no longer than the longest curve. An apple that
/// lands and rests has a contact lasting seconds whose impact is over in milliseconds: spanning
/// its resting force would squeeze every pulse against the axis. Curves without an impact
/// (contacts that started at rest) do not set it; when no curve has one, the window spans them
/// all, and a run folder written before `impact_duration_s` existed gets [`force_window_ms`].
pub fn force_window(curves: &[&ForceCurve]) -> ChartWindow {
    let longest = curves
        .iter()
        .filter_map(|c| c.points.last().map(|p| 1e3 * p.0))
        .fold(0.0, f64::max);
    let pulse = curves
        .iter()
        .filter_map(|c| pulse_end_s(c))
        .fold(f64::NAN, f64::max);
    let old_folder = curves.iter().any(|c| !c.impact_known);
    let to = if old_folder {
        let ms: Vec<Vec<(f64, f64)>> = curves
            .iter()
            .map(|c| c.points.iter().map(|&(t, p)| (1e3 * t, p)).collect())
            .collect();
        let refs: Vec<&[(f64, f64)]> = ms.iter().map(|c| c.as_slice()).collect();
        force_window_ms(&refs)
    } else if pulse.is_finite() {
        (1e3 * pulse * (1.0 + IMPACT_WINDOW_MARGIN)).min(longest)
    } else {
        longest
    };
    ChartWindow {
        from: 0.0,
        to: if to > 0.0 {
            to
        } else {
            longest.max(f64::MIN_POSITIVE)
        },
    }
}

/// A window from the curves' shapes alone (ms): five times the longest impact pulse (time
/// from touch until the force first falls below [`PULSE_END_SHARE`] of its peak after the peak),
/// but no longer than the longest contact. Whole impacts (which end within about 1.3 times
/// their pulse, or 4.3 times for ke = 0.09) are drawn whole; a resting contact never falls
/// below the share, so a run with one is better served by [`force_window`].
pub fn force_window_ms(curves: &[&[(f64, f64)]]) -> f64 {
    let mut pulse = 0.0f64;
    let mut longest = 0.0f64;
    for c in curves {
        let Some(last) = c.last() else { continue };
        longest = longest.max(last.0);
        let (ipk, peak) =
            c.iter().enumerate().fold(
                (0, f64::MIN),
                |a, (i, p)| if p.1 > a.1 { (i, p.1) } else { a },
            );
        let end = c[ipk..]
            .iter()
            .find(|p| p.1 < PULSE_END_SHARE * peak)
            .map_or(last.0, |p| p.0);
        pulse = pulse.max(end);
    }
    (5.0 * pulse).min(longest)
}

/// A time in ms as a note prints it: to 0.1 ms, finer below 1 ms.
fn short_ms(x: f64) -> String {
    crate::sim::fate::human(x, 2, 1)
}

/// What [`plot_runs`] wrote.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlotSummary {
    /// Charts written.
    pub written: Vec<PathBuf>,
    /// Notes for the user (curves left out, runs without force curves).
    pub notes: Vec<String>,
}

/// Labels of the runs: their folder names, or whole paths when two folders share a name.
pub fn run_labels(dirs: &[PathBuf]) -> Vec<String> {
    let names: Vec<String> = dirs
        .iter()
        .map(|d| {
            d.file_name()
                .map(|n| n.to_string_lossy().to_string())
                .unwrap_or_else(|| d.display().to_string())
        })
        .collect();
    names
        .iter()
        .zip(dirs)
        .map(|(n, d)| {
            if names.iter().filter(|m| *m == n).count() > 1 {
                d.display().to_string()
            } else {
                n.clone()
            }
        })
        .collect()
}

/// Writes `chart` as `file` into `out_dir` and records it in `summary`.
fn write(
    out_dir: &Path,
    file: &str,
    chart: &LineChart,
    summary: &mut PlotSummary,
) -> Result<(), PlotError> {
    let path = out_dir.join(file);
    chart.write_svg(&path)?;
    summary.written.push(path);
    Ok(())
}

/// Draws `force_time.svg`, `linear_velocity.svg` and `angular_velocity.svg` of the run folders
/// `dirs` into `out_dir` (created if missing). With several runs each curve's legend starts with
/// its run's folder name; each run gets an equal share of `max_series`.
pub fn plot_runs(
    dirs: &[PathBuf],
    out_dir: &Path,
    opts: &PlotOptions,
) -> Result<PlotSummary, PlotError> {
    if dirs.is_empty() {
        return Err(PlotError::Empty("no run folder given".into()));
    }
    let labels = run_labels(dirs);
    let runs: Vec<RunCurves> = dirs.iter().map(|d| read_run(d)).collect::<Result<_, _>>()?;
    std::fs::create_dir_all(out_dir).map_err(|source| PlotError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let multi = dirs.len() > 1;
    let share = opts.max_series.max(1).div_ceil(dirs.len());
    let prefix = |r: usize| {
        if multi {
            format!("{}: ", labels[r])
        } else {
            String::new()
        }
    };
    let wanted = |name: &str| opts.apples.is_empty() || opts.apples.iter().any(|a| a == name);
    let mut summary = PlotSummary::default();

    // Figs. 1-5: force against time since first touch.
    let mut force_series = Vec::new();
    let mut drawn: Vec<&ForceCurve> = Vec::new();
    for (r, run) in runs.iter().enumerate() {
        if !run.has_forces {
            summary.notes.push(format!(
                "{}: no forces.csv (scenario output.force_history is false): no force curves",
                dirs[r].display()
            ));
            continue;
        }
        let mut curves: Vec<&ForceCurve> = run
            .forces
            .iter()
            .filter(|c| wanted(&c.a) || wanted(&c.b))
            .collect();
        let total = curves.len();
        curves.sort_by(|x, y| {
            y.peak_force_n
                .total_cmp(&x.peak_force_n)
                .then(x.contact.cmp(&y.contact))
        });
        curves.truncate(share);
        if curves.len() < total {
            summary.notes.push(format!(
                "{}: {} of {} contacts drawn (largest peak forces; --max-series)",
                dirs[r].display(),
                curves.len(),
                total
            ));
        }
        curves.sort_by_key(|c| c.contact);
        let repeated = |c: &ForceCurve| {
            run.forces
                .iter()
                .filter(|d| d.a == c.a && d.b == c.b)
                .count()
                > 1
        };
        for c in curves {
            drawn.push(c);
            let when = if repeated(c) {
                format!(" at {:.1} ms", c.t_start_s * 1e3)
            } else {
                String::new()
            };
            force_series.push(Series {
                label: format!(
                    "{}{} - {}{} ({:.1} N)",
                    prefix(r),
                    c.a,
                    c.b,
                    when,
                    c.peak_force_n
                ),
                points: decimate(
                    &c.points
                        .iter()
                        .map(|&(t, p)| (t * 1e3, p))
                        .collect::<Vec<_>>(),
                    MAX_POINTS_PER_SERIES,
                ),
            });
        }
    }
    if !force_series.is_empty() {
        let longest = force_series
            .iter()
            .filter_map(|s| s.points.last().map(|p| p.0))
            .fold(0.0, f64::max);
        let (window, why) = match opts.force_window_ms {
            Some(w) => (w, "--window"),
            None => (
                force_window(&drawn),
                "the impact pulses and a fifth more; --window",
            ),
        };
        if window.from > 0.0 || window.to < longest {
            summary.notes.push(format!(
                "force chart: {} to {} ms since first touch ({why}; the longest contact lasts {longest:.1} ms)",
                short_ms(window.from),
                short_ms(window.to.min(longest)),
            ));
            for s in &mut force_series {
                s.points = window.clip(&s.points);
            }
        }
        let chart = LineChart::new(
            "Normal contact force",
            "time since first touch (ms)",
            "normal force P (N)",
            force_series,
        );
        write(out_dir, FORCE_CHART, &chart, &mut summary)?;
    }

    // Figs. 6-7: speed and angular speed against time.
    let mut speed = Vec::new();
    let mut spin = Vec::new();
    for (r, run) in runs.iter().enumerate() {
        let apples: Vec<&(String, Kinematics)> =
            run.apples.iter().filter(|(n, _)| wanted(n)).collect();
        if apples.len() > share {
            summary.notes.push(format!(
                "{}: {} of {} apples drawn (the first; --max-series, --apple)",
                dirs[r].display(),
                share,
                apples.len()
            ));
        }
        for (name, k) in apples.into_iter().take(share) {
            let label = format!("{}{}", prefix(r), name);
            speed.push(Series {
                label: label.clone(),
                points: decimate(&k.speed, MAX_POINTS_PER_SERIES),
            });
            spin.push(Series {
                label,
                points: decimate(&k.spin, MAX_POINTS_PER_SERIES),
            });
        }
    }
    // Slip speed against time, transitions marked; where apples start rolling, per surface.
    let mut slip = Vec::new();
    let mut marks: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    let mut starts = Vec::new();
    for (r, run) in runs.iter().enumerate() {
        let apples: Vec<&(String, Kinematics)> = run
            .apples
            .iter()
            .filter(|(n, k)| wanted(n) && !k.slip.is_empty())
            .take(share)
            .collect();
        for (name, k) in &apples {
            slip.push(Series {
                label: format!("{}{}", prefix(r), name),
                points: decimate(&k.slip, MAX_POINTS_PER_SERIES),
            });
            for t in run.transitions.iter().filter(|t| &t.apple == name) {
                marks
                    .entry(format!("to {}", t.to))
                    .or_default()
                    .push((t.time_s, t.slip_m_s));
            }
        }
        let mut by_surface: BTreeMap<&str, Vec<f64>> = BTreeMap::new();
        for t in &run.transitions {
            if t.to == "rolling" && t.along_m.is_finite() {
                by_surface.entry(&t.surface).or_default().push(t.along_m);
            }
        }
        for (surface, x) in by_surface {
            let bin = opts.histogram_bin_m;
            let (edges, counts) = crate::record::transitions::histogram(&x, bin);
            starts.push(Series {
                label: format!("{}{} ({} rolling starts)", prefix(r), surface, x.len()),
                points: histogram_outline(&edges, &counts),
            });
        }
    }
    if let Some(w) = opts.time_window_s {
        for s in speed
            .iter_mut()
            .chain(spin.iter_mut())
            .chain(slip.iter_mut())
        {
            s.points = w.clip(&s.points);
        }
        for points in marks.values_mut() {
            points.retain(|p| w.contains(p.0));
        }
        marks.retain(|_, p| !p.is_empty());
        let series = speed.iter().chain(&slip);
        if speed.len() + slip.len() > 0 && series.clone().all(|s| s.points.is_empty()) {
            summary.notes.push(format!(
                "--time-window {}:{} s holds no sample of the runs: the charts against time are empty",
                w.from, w.to
            ));
        }
    }
    if !slip.is_empty() {
        let mut chart = LineChart::new(
            "Slip speed at the contact the apple is on",
            "time (s)",
            "slip speed (m/s)",
            slip,
        );
        chart.markers = marks
            .into_iter()
            .map(|(label, points)| Series { label, points })
            .collect();
        write(out_dir, SLIP_CHART, &chart, &mut summary)?;
    }
    if !starts.is_empty() {
        let chart = LineChart::new(
            "Where apples start rolling",
            "distance along the surface from its start (m)",
            "rolling starts",
            starts,
        );
        write(out_dir, ROLLING_STARTS_CHART, &chart, &mut summary)?;
    }
    if !speed.is_empty() {
        for (file, title, y, series) in [
            (SPEED_CHART, "Centre speed", "speed |v| (m/s)", speed),
            (
                SPIN_CHART,
                "Angular speed",
                "angular speed |w| (rad/s)",
                spin,
            ),
        ] {
            let chart = LineChart::new(title, "time (s)", y, series);
            write(out_dir, file, &chart, &mut summary)?;
        }
    }
    if summary.written.is_empty() {
        return Err(PlotError::Empty(format!(
            "nothing to plot in {}: no apple in bodies.csv and no force curve",
            dirs.iter()
                .map(|d| d.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    Ok(summary)
}
