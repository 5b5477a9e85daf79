//! SVG charts of one or several run folders (`applesim run --plots`, `applesim plot`): the
//! paper's Figs. 1-5 (normal force against time since first touch, one curve per contact, several
//! runs on one chart) and Figs. 6-7 (speed and angular speed of the apples against time); with
//! `transitions.csv`, the slip speed against time with the transitions marked and, per surface, a
//! histogram of where apples start rolling.
//!
//! Charts are drawn from the files of the run folders (`contacts.csv`, `forces.csv`,
//! `bodies.csv`), so saved runs can be compared at any time. plotters' SVG backend writes text
//! as SVG `<text>` and needs no font files. Every chart is written whole or not at all.

use super::atomic;
use plotters::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Header of `forces.csv`: one row per recorded force sample of a contact (`contact` is the
/// contact's row index in `contacts.csv`, from 0).
pub const FORCES_HEADER: [&str; 5] = ["contact", "a", "b", "time_s", "force_n"];

/// Chart file names.
pub const FORCE_CHART: &str = "force_time.svg";
/// Linear speed chart.
pub const SPEED_CHART: &str = "linear_velocity.svg";
/// Angular speed chart.
pub const SPIN_CHART: &str = "angular_velocity.svg";
/// Slip speed chart with the transitions marked.
pub const SLIP_CHART: &str = "slip_speed.svg";
/// Where apples start rolling, per surface.
pub const ROLLING_STARTS_CHART: &str = "rolling_starts.svg";

/// Most points drawn per curve; longer series are reduced keeping each bucket's min and max, so
/// short impact spikes survive.
pub const MAX_POINTS_PER_SERIES: usize = 4000;

/// Errors of the charts.
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
    /// plotters failed.
    #[error("drawing {chart}: {message}")]
    Draw {
        /// Chart file.
        chart: String,
        /// plotters' message.
        message: String,
    },
}

/// One curve of a chart.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// (x, y) points in drawing order.
    pub points: Vec<(f64, f64)>,
}

/// A line chart.
#[derive(Debug, Clone, PartialEq)]
pub struct LineChart {
    /// Title.
    pub title: String,
    /// x axis caption, with unit.
    pub x_label: String,
    /// y axis caption, with unit.
    pub y_label: String,
    /// Curves.
    pub series: Vec<Series>,
    /// Marked points (drawn as circles, one legend entry per group), e.g. transitions.
    pub markers: Vec<Series>,
}

/// Ten well-separated colours (the "tab10" palette), cycled.
const COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

fn padded_range(lo: f64, hi: f64, pad_lo: bool) -> std::ops::Range<f64> {
    let (lo, hi) = if lo.is_finite() && hi.is_finite() {
        (lo, hi)
    } else {
        (0.0, 1.0)
    };
    let span = if hi > lo { hi - lo } else { lo.abs().max(1.0) };
    let lo2 = if pad_lo { lo - 0.03 * span } else { lo };
    lo2..hi + 0.05 * span
}

impl LineChart {
    /// The chart as an SVG document.
    pub fn to_svg(&self, size: (u32, u32)) -> Result<String, String> {
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for s in self.series.iter().chain(&self.markers) {
            for &(x, y) in &s.points {
                if x.is_finite() && y.is_finite() {
                    x0 = x0.min(x);
                    x1 = x1.max(x);
                    y0 = y0.min(y);
                    y1 = y1.max(y);
                }
            }
        }
        // Forces and speeds are >= 0: start the y axis at 0 as the paper's figures do.
        let y0 = y0.min(0.0);
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            let mut chart = ChartBuilder::on(&root)
                .caption(&self.title, ("sans-serif", 20))
                .margin(12)
                .x_label_area_size(48)
                .y_label_area_size(70)
                .build_cartesian_2d(padded_range(x0, x1, false), padded_range(y0, y1, y0 < 0.0))
                .map_err(|e| e.to_string())?;
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .axis_desc_style(("sans-serif", 16))
                .label_style(("sans-serif", 13))
                .light_line_style(RGBColor(235, 235, 235))
                .draw()
                .map_err(|e| e.to_string())?;
            for (i, s) in self.series.iter().enumerate() {
                let colour = COLOURS[i % COLOURS.len()];
                chart
                    .draw_series(LineSeries::new(
                        s.points
                            .iter()
                            .copied()
                            .filter(|p| p.0.is_finite() && p.1.is_finite()),
                        colour.stroke_width(2),
                    ))
                    .map_err(|e| e.to_string())?
                    .label(s.label.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 22, y)], colour.stroke_width(2))
                    });
            }
            for (i, m) in self.markers.iter().enumerate() {
                // Dark, distinct from the curves' colours.
                let colour = [BLACK, RGBColor(200, 0, 0), RGBColor(0, 120, 0)][i % 3];
                chart
                    .draw_series(
                        m.points
                            .iter()
                            .filter(|p| p.0.is_finite() && p.1.is_finite())
                            .map(|&p| Circle::new(p, 5, colour.stroke_width(2))),
                    )
                    .map_err(|e| e.to_string())?
                    .label(m.label.as_str())
                    .legend(move |(x, y)| Circle::new((x + 11, y), 5, colour.stroke_width(2)));
            }
            if !self.series.is_empty() {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperRight)
                    .background_style(WHITE.mix(0.85))
                    .border_style(RGBColor(160, 160, 160))
                    .label_font(("sans-serif", 13))
                    .draw()
                    .map_err(|e| e.to_string())?;
            }
            root.present().map_err(|e| e.to_string())?;
        }
        Ok(svg)
    }

    /// Writes the chart to `path` (atomically).
    pub fn write_svg(&self, path: &Path) -> Result<(), PlotError> {
        let svg = self.to_svg((960, 600)).map_err(|message| PlotError::Draw {
            chart: path.display().to_string(),
            message,
        })?;
        atomic::write_file(path, svg.as_bytes()).map_err(|source| PlotError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// Reduces a series to at most about `max` points, keeping the minimum and maximum of each bucket.
pub fn decimate(points: &[(f64, f64)], max: usize) -> Vec<(f64, f64)> {
    if points.len() <= max || max < 4 {
        return points.to_vec();
    }
    let buckets = max / 2;
    let size = points.len().div_ceil(buckets);
    let mut out = Vec::with_capacity(2 * buckets + 1);
    for chunk in points.chunks(size) {
        let (mut imin, mut imax) = (0, 0);
        for (i, p) in chunk.iter().enumerate() {
            if p.1 < chunk[imin].1 {
                imin = i;
            }
            if p.1 > chunk[imax].1 {
                imax = i;
            }
        }
        let (a, b) = (imin.min(imax), imin.max(imax));
        out.push(chunk[a]);
        if b != a {
            out.push(chunk[b]);
        }
    }
    out
}

/// One contact's force curve read from a run folder.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceCurve {
    /// Row index in `contacts.csv`.
    pub contact: usize,
    /// Apple.
    pub a: String,
    /// Other body.
    pub b: String,
    /// First touch (s).
    pub t_start_s: f64,
    /// Peak force (N).
    pub peak_force_n: f64,
    /// (time since first touch s, force N), with the zero-force touch and parting instants.
    pub points: Vec<(f64, f64)>,
}

/// One apple's kinematics read from `bodies.csv`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Kinematics {
    /// (time s, centre speed m/s).
    pub speed: Vec<(f64, f64)>,
    /// (time s, angular speed rad/s).
    pub spin: Vec<(f64, f64)>,
    /// (time s, slip speed m/s) when `bodies.csv` has the `slip_m_s` column filled.
    pub slip: Vec<(f64, f64)>,
}

/// One row of `transitions.csv` as the charts need it.
#[derive(Debug, Clone, PartialEq)]
pub struct TransitionMark {
    /// Apple.
    pub apple: String,
    /// New state (`sliding`, `rolling`, `airborne`).
    pub to: String,
    /// Surface it is on after (empty when airborne).
    pub surface: String,
    /// Time (s).
    pub time_s: f64,
    /// Slip speed then (m/s).
    pub slip_m_s: f64,
    /// Distance along the surface (m; NaN when none).
    pub along_m: f64,
}

/// What the charts need from one run folder.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunCurves {
    /// Contacts with a recorded force curve (empty without `forces.csv`).
    pub forces: Vec<ForceCurve>,
    /// Apples in order of first appearance in `bodies.csv`.
    pub apples: Vec<(String, Kinematics)>,
    /// Whether `forces.csv` was there.
    pub has_forces: bool,
    /// Rows of `transitions.csv` (empty without it).
    pub transitions: Vec<TransitionMark>,
}

fn reader(path: &Path) -> Result<csv::Reader<std::fs::File>, PlotError> {
    csv::Reader::from_path(path).map_err(|e| PlotError::Parse {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// Column indices of `names` in a CSV header.
fn columns(
    path: &Path,
    rd: &mut csv::Reader<std::fs::File>,
    names: &[&str],
) -> Result<Vec<usize>, PlotError> {
    let h = rd.headers().map_err(|e| PlotError::Parse {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    names
        .iter()
        .map(|n| {
            h.iter()
                .position(|c| c == *n)
                .ok_or_else(|| PlotError::Parse {
                    path: path.to_path_buf(),
                    message: format!("no column '{n}'"),
                })
        })
        .collect()
}

fn num(path: &Path, s: &str) -> Result<f64, PlotError> {
    if s.is_empty() {
        return Ok(f64::NAN);
    }
    s.parse().map_err(|_| PlotError::Parse {
        path: path.to_path_buf(),
        message: format!("'{s}' is not a number"),
    })
}

/// Reads the curves of a run folder.
pub fn read_run(dir: &Path) -> Result<RunCurves, PlotError> {
    let mut out = RunCurves::default();
    let contacts_path = dir.join("contacts.csv");
    let forces_path = dir.join("forces.csv");
    if forces_path.exists() {
        out.has_forces = true;
        let mut rd = reader(&contacts_path)?;
        let c = columns(
            &contacts_path,
            &mut rd,
            &["a", "b", "t_start_s", "t_end_s", "peak_force_n"],
        )?;
        let mut by_index = Vec::new();
        for rec in rd.records() {
            let rec = rec.map_err(|e| PlotError::Parse {
                path: contacts_path.clone(),
                message: e.to_string(),
            })?;
            let t0 = num(&contacts_path, &rec[c[2]])?;
            let t1 = num(&contacts_path, &rec[c[3]])?;
            by_index.push(ForceCurve {
                contact: by_index.len(),
                a: rec[c[0]].to_string(),
                b: rec[c[1]].to_string(),
                t_start_s: t0,
                peak_force_n: num(&contacts_path, &rec[c[4]])?,
                points: if t1.is_finite() {
                    vec![(t1 - t0, 0.0)]
                } else {
                    vec![]
                },
            });
        }
        let mut rd = reader(&forces_path)?;
        let c = columns(&forces_path, &mut rd, &["contact", "time_s", "force_n"])?;
        let mut curves: BTreeMap<usize, Vec<(f64, f64)>> = BTreeMap::new();
        for rec in rd.records() {
            let rec = rec.map_err(|e| PlotError::Parse {
                path: forces_path.clone(),
                message: e.to_string(),
            })?;
            let k: usize = rec[c[0]].parse().map_err(|_| PlotError::Parse {
                path: forces_path.clone(),
                message: format!("bad contact index '{}'", &rec[c[0]]),
            })?;
            curves.entry(k).or_default().push((
                num(&forces_path, &rec[c[1]])?,
                num(&forces_path, &rec[c[2]])?,
            ));
        }
        for (k, pts) in curves {
            let Some(fc) = by_index.get_mut(k) else {
                return Err(PlotError::Parse {
                    path: forces_path.clone(),
                    message: format!("contact {k} is not in contacts.csv"),
                });
            };
            let end = fc.points.pop();
            let t0 = fc.t_start_s;
            fc.points.push((0.0, 0.0));
            fc.points.extend(pts.into_iter().map(|(t, p)| (t - t0, p)));
            fc.points.extend(end);
        }
        out.forces = by_index
            .into_iter()
            .filter(|f| f.points.len() > 2)
            .collect();
    }
    let bodies_path = dir.join("bodies.csv");
    let mut rd = reader(&bodies_path)?;
    let c = columns(
        &bodies_path,
        &mut rd,
        &[
            "time_s", "apple", "vx_m_s", "vy_m_s", "vz_m_s", "wx_rad_s", "wy_rad_s", "wz_rad_s",
        ],
    )?;
    let slip_col = rd
        .headers()
        .ok()
        .and_then(|h| h.iter().position(|c| c == "slip_m_s"));
    let mut order: BTreeMap<String, usize> = BTreeMap::new();
    for rec in rd.records() {
        let rec = rec.map_err(|e| PlotError::Parse {
            path: bodies_path.clone(),
            message: e.to_string(),
        })?;
        let t = num(&bodies_path, &rec[c[0]])?;
        let g = |i: usize| num(&bodies_path, &rec[c[i]]);
        let v = (g(2)?.powi(2) + g(3)?.powi(2) + g(4)?.powi(2)).sqrt();
        let w = (g(5)?.powi(2) + g(6)?.powi(2) + g(7)?.powi(2)).sqrt();
        let name = &rec[c[1]];
        let k = match order.get(name) {
            Some(&k) => k,
            None => {
                order.insert(name.to_string(), out.apples.len());
                out.apples.push((name.to_string(), Kinematics::default()));
                out.apples.len() - 1
            }
        };
        out.apples[k].1.speed.push((t, v));
        out.apples[k].1.spin.push((t, w));
        if let Some(sc) = slip_col {
            let x = num(&bodies_path, rec.get(sc).unwrap_or(""))?;
            if x.is_finite() {
                out.apples[k].1.slip.push((t, x));
            }
        }
    }
    let tr_path = dir.join("transitions.csv");
    if tr_path.exists() {
        let mut rd = reader(&tr_path)?;
        let c = columns(
            &tr_path,
            &mut rd,
            &["apple", "to", "surface", "time_s", "slip_m_s", "along_m"],
        )?;
        for rec in rd.records() {
            let rec = rec.map_err(|e| PlotError::Parse {
                path: tr_path.clone(),
                message: e.to_string(),
            })?;
            out.transitions.push(TransitionMark {
                apple: rec[c[0]].to_string(),
                to: rec[c[1]].to_string(),
                surface: rec[c[2]].to_string(),
                time_s: num(&tr_path, &rec[c[3]])?,
                slip_m_s: num(&tr_path, &rec[c[4]])?,
                along_m: num(&tr_path, &rec[c[5]])?,
            });
        }
    }
    Ok(out)
}

/// The outline of a histogram as a staircase curve: (edges, counts) -> points.
pub fn histogram_outline(edges: &[f64], counts: &[u32]) -> Vec<(f64, f64)> {
    let mut pts = Vec::with_capacity(2 * counts.len() + 2);
    if edges.len() != counts.len() + 1 || counts.is_empty() {
        return pts;
    }
    pts.push((edges[0], 0.0));
    for (k, &c) in counts.iter().enumerate() {
        pts.push((edges[k], c as f64));
        pts.push((edges[k + 1], c as f64));
    }
    pts.push((edges[counts.len()], 0.0));
    pts
}

/// Choices of [`plot_runs`].
#[derive(Debug, Clone, PartialEq)]
pub struct PlotOptions {
    /// Most curves per chart (the largest peak forces; the first apples).
    pub max_series: usize,
    /// Only these apples (all when empty).
    pub apples: Vec<String>,
    /// Time window of the force chart (ms from first touch); `None`: [`force_window_ms`].
    pub window_ms: Option<f64>,
    /// Bin width of the rolling-start histogram (m).
    pub histogram_bin_m: f64,
}

impl Default for PlotOptions {
    fn default() -> Self {
        Self {
            max_series: 10,
            apples: Vec::new(),
            window_ms: None,
            histogram_bin_m: 0.05,
        }
    }
}

/// Below this share of its peak a contact's force counts as past its impact pulse.
pub const PULSE_END_SHARE: f64 = 0.25;

/// The automatic time window of the force chart (ms): five times the longest impact pulse (time
/// from touch until the force first falls below [`PULSE_END_SHARE`] of its peak after the peak),
/// but no longer than the longest contact. An apple that lands on a belt and rides it has one
/// contact lasting seconds; the window keeps its landing pulse visible, as in the paper's
/// figures, while whole impacts (which end within about 1.3 times their pulse, or 4.3 times
/// for ke = 0.09) are drawn whole.
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
        let window = opts.window_ms.unwrap_or_else(|| {
            let c: Vec<&[(f64, f64)]> = force_series.iter().map(|s| s.points.as_slice()).collect();
            force_window_ms(&c)
        });
        if window < longest {
            summary.notes.push(format!(
                "force chart: the first {window:.1} ms of each contact (the longest lasts {longest:.1} ms; --window-ms)"
            ));
            for s in &mut force_series {
                s.points.retain(|p| p.0 <= window);
            }
        }
        let path = out_dir.join(FORCE_CHART);
        LineChart {
            title: "Normal contact force".into(),
            x_label: "time since first touch (ms)".into(),
            y_label: "normal force P (N)".into(),
            series: force_series,
            markers: Vec::new(),
        }
        .write_svg(&path)?;
        summary.written.push(path);
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
    if !slip.is_empty() {
        let path = out_dir.join(SLIP_CHART);
        LineChart {
            title: "Slip speed at the contact the apple is on".into(),
            x_label: "time (s)".into(),
            y_label: "slip speed (m/s)".into(),
            series: slip,
            markers: marks
                .into_iter()
                .map(|(label, points)| Series { label, points })
                .collect(),
        }
        .write_svg(&path)?;
        summary.written.push(path);
    }
    if !starts.is_empty() {
        let path = out_dir.join(ROLLING_STARTS_CHART);
        LineChart {
            title: "Where apples start rolling".into(),
            x_label: "distance along the surface from its start (m)".into(),
            y_label: "rolling starts".into(),
            series: starts,
            markers: Vec::new(),
        }
        .write_svg(&path)?;
        summary.written.push(path);
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
            let path = out_dir.join(file);
            LineChart {
                title: title.into(),
                x_label: "time (s)".into(),
                y_label: y.into(),
                series,
                markers: Vec::new(),
            }
            .write_svg(&path)?;
            summary.written.push(path);
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
