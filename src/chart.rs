//! Line charts as SVG: the drawing primitives every chart of applesim is made of (the run charts
//! of [`crate::output::plot`], the validation report's figures in [`crate::validate`], the
//! speed-against-accuracy chart of [`crate::analysis::tradeoff`]).
//!
//! They sit in a module of their own, below `output`, `analysis` and `validate`, so that an
//! analysis can return a chart without depending on the output layer that writes run folders.
//! plotters' SVG backend writes text as SVG `<text>` and needs no font files; the same chart gives
//! the same bytes, which the byte-for-byte tests of the charts rely on.

use crate::output::atomic;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Errors of drawing or writing a chart.
#[derive(Debug, thiserror::Error)]
pub enum ChartError {
    /// The chart file could not be written.
    #[error("{path}: {source}")]
    Io {
        /// Chart file.
        path: PathBuf,
        /// OS error.
        source: std::io::Error,
    },
    /// plotters failed.
    #[error("drawing {chart}: {message}")]
    Draw {
        /// Chart file.
        chart: String,
        /// plotters' message.
        message: String,
    },
}

/// One curve of a chart: a legend entry and its points, in the units of the chart's axes.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// (x, y) points in drawing order; non-finite points are skipped when drawn (a NaN from an
    /// unfinished contact must not break the whole chart).
    pub points: Vec<(f64, f64)>,
}

/// A line chart: what every chart of applesim is, whether force against time (the paper's
/// Figs. 1-5), speed against time (Figs. 6-7) or error against cost (the trade-off chart).
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
    /// How the marker groups are coloured.
    pub marker_colours: MarkerColours,
}

/// Colours of a chart's marker groups.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MarkerColours {
    /// Three dark colours, distinct from the curves' (marks on curves, e.g. transitions).
    #[default]
    Dark,
    /// The curves' palette, continued after the curves (a scatter chart of many groups, e.g.
    /// one per transfer point of the line audit).
    Palette,
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

/// The axis range of data spanning `lo..hi`: 5 % headroom above so the peak of a force pulse
/// does not touch the frame, 3 % below only when asked (axes that start at 0 start exactly
/// there, as the paper's figures do).
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
    /// A chart of `series` without markers, which is what most charts are.
    pub fn new(title: &str, x_label: &str, y_label: &str, series: Vec<Series>) -> LineChart {
        LineChart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series,
            markers: Vec::new(),
            marker_colours: MarkerColours::Dark,
        }
    }

    /// The chart as an SVG document of `size` pixels; the error is plotters' message.
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
                let colour = match self.marker_colours {
                    MarkerColours::Dark => [BLACK, RGBColor(200, 0, 0), RGBColor(0, 120, 0)][i % 3],
                    MarkerColours::Palette => COLOURS[(self.series.len() + i) % COLOURS.len()],
                };
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
            if !self.series.is_empty() || self.marker_colours == MarkerColours::Palette {
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

    /// Writes the chart to `path` at 960 x 600 pixels, whole or not at all (a reader of the
    /// folder never sees half a chart: [`atomic::write_file`]).
    pub fn write_svg(&self, path: &Path) -> Result<(), ChartError> {
        let svg = self
            .to_svg((960, 600))
            .map_err(|message| ChartError::Draw {
                chart: path.display().to_string(),
                message,
            })?;
        atomic::write_file(path, svg.as_bytes()).map_err(|source| ChartError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// Reduces a series to at most about `max` points, keeping the minimum and maximum of each
/// bucket: an SVG of a million-sample force history is unusable, and an even thinning would
/// drop the short impact spikes the charts are drawn for.
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
