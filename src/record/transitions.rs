//! Slip/roll transitions (issue 8): the records of where and when each apple stops sliding and
//! starts rolling, and whether it slips again at a transfer (docs/transitions.md): one
//! [`Transition`] per change of state, and the summary section of summary.json. The detector
//! that finds them from the layer's per-contact slips runs beside the driver
//! (`sim::slip_roll`).

use crate::scenario::TransitionSpec;
use serde::Serialize;
use std::sync::Arc;

/// The state of an apple.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Motion {
    /// No contact.
    Airborne,
    /// A contact slides.
    Sliding,
    /// In contact, no contact slides.
    Rolling,
}

impl Motion {
    /// The name used in the outputs.
    pub fn as_str(self) -> &'static str {
        match self {
            Motion::Airborne => "airborne",
            Motion::Sliding => "sliding",
            Motion::Rolling => "rolling",
        }
    }
}

/// One transition of an apple's state (or of the surface it slides or rolls on).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Transition {
    /// The apple.
    pub apple: Arc<str>,
    /// Index of the apple in the layer.
    #[serde(skip)]
    pub apple_index: u32,
    /// State before.
    pub from: Motion,
    /// State after.
    pub to: Motion,
    /// What it slid or rolled on before (`None` when airborne).
    pub from_surface: Option<Arc<str>>,
    /// What it slides or rolls on after (`None` when airborne).
    pub surface: Option<Arc<str>>,
    /// The instant (s), dated back to where the new state began.
    pub time_s: f64,
    /// Centre of the apple then (m).
    pub position_m: [f64; 3],
    /// Contact point on `surface` then, as the distance along it (m) from its start (a belt's
    /// upstream end, a chute's top end, a box's -x end; see `SurfacePart::along`); `None` when
    /// airborne, on another apple, or on a surface without a running direction (a plane, a bin
    /// wall, a mesh).
    pub along_m: Option<f64>,
    /// Centre speed |v| (m/s).
    pub speed_m_s: f64,
    /// Angular speed |w| (rad/s).
    pub spin_rad_s: f64,
    /// Slip speed of the contact it is on (m/s; 0 when airborne).
    pub slip_m_s: f64,
    /// Distance slid since the previous transition (m): the contact point's path over the
    /// surfaces, slips too brief to count included.
    pub slid_m: f64,
    /// Time spent sliding since the previous transition (s).
    pub sliding_time_s: f64,
    /// Time since the previous transition (or since the apple appeared) (s).
    pub since_previous_s: f64,
}

/// Per apple: the headline figures of its slip/roll history (summary.json).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AppleSlipSummary {
    /// The apple.
    pub apple: Arc<str>,
    /// First time it was rolling (s), or `None` if it never rolled.
    pub first_rolling_s: Option<f64>,
    /// Total distance slid (m).
    pub slide_distance_m: f64,
    /// Number of sliding episodes that counted (the initial one included).
    pub slip_episodes: u32,
    /// State at the end.
    pub final_state: Motion,
    /// Surfaces (and apples) it slid or rolled on, in order of first contact.
    pub surfaces: Vec<Arc<str>>,
}

/// Per surface: where apples start rolling on it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SurfaceRollSummary {
    /// The surface.
    pub surface: Arc<str>,
    /// Transitions to rolling on it.
    pub rolling_starts: usize,
    /// Transitions to sliding on it (landings that slide included).
    pub sliding_starts: usize,
    /// Distance along the surface where apples start rolling (m): min, mean, max.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rolling_start_along_m: Option<[f64; 3]>,
    /// Histogram of those distances: bin edges (m, one more than counts) and counts.
    pub histogram_edges_m: Vec<f64>,
    /// Counts per bin.
    pub histogram_counts: Vec<u32>,
}

/// The transitions section of summary.json.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TransitionSummary {
    /// Settings used.
    pub settings: TransitionSpec,
    /// Number of transitions (rows of transitions.csv).
    pub transitions: usize,
    /// Per apple.
    pub apples: Vec<AppleSlipSummary>,
    /// Per surface on which some apple slid or rolled.
    pub surfaces: Vec<SurfaceRollSummary>,
}

/// Most bins a histogram has (see [`histogram`]).
pub const MAX_BINS: usize = 10_000;

/// A histogram of `x` with bins of width `bin` aligned on multiples of it: (edges, counts).
pub fn histogram(x: &[f64], bin: f64) -> (Vec<f64>, Vec<u32>) {
    let finite: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.is_empty() || bin.is_nan() || bin <= 0.0 {
        return (Vec::new(), Vec::new());
    }
    let lo = finite.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    // At most MAX_BINS bins: a narrow bin over a long line widens by a whole factor, so its
    // edges stay on multiples of the bin asked for (1 mm bins over 20 km asked for 2e7 bins).
    let span_bins = (hi / bin).floor() - (lo / bin).floor() + 1.0;
    let bin = if span_bins > MAX_BINS as f64 {
        bin * (span_bins / MAX_BINS as f64).ceil()
    } else {
        bin
    };
    let first = (lo / bin).floor() as i64;
    let last = ((hi / bin).floor() as i64).max(first);
    let nbins = (last - first + 1) as usize;
    let mut counts = vec![0u32; nbins];
    for v in finite {
        let b = ((v / bin).floor() as i64 - first).clamp(0, nbins as i64 - 1) as usize;
        counts[b] += 1;
    }
    let edges = (0..=nbins)
        .map(|i| (first + i as i64) as f64 * bin)
        .collect();
    (edges, counts)
}

/// The headline figures for a batch table (see [`crate::sim::RunResult::metrics`]).
pub fn metrics(s: &TransitionSummary) -> Vec<(String, f64)> {
    let mut m = vec![("transitions".to_string(), s.transitions as f64)];
    let roll: Vec<f64> = s.apples.iter().filter_map(|a| a.first_rolling_s).collect();
    let slid: Vec<f64> = s.apples.iter().map(|a| a.slide_distance_m).collect();
    m.push((
        "apples_rolling_at_end".into(),
        s.apples
            .iter()
            .filter(|a| a.final_state == Motion::Rolling)
            .count() as f64,
    ));
    m.push((
        "slip_episodes".into(),
        s.apples.iter().map(|a| a.slip_episodes as f64).sum(),
    ));
    if !roll.is_empty() {
        m.push((
            "mean_first_rolling_s".into(),
            roll.iter().sum::<f64>() / roll.len() as f64,
        ));
        m.push((
            "max_first_rolling_s".into(),
            roll.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        ));
    }
    if !slid.is_empty() {
        m.push((
            "mean_slide_distance_m".into(),
            slid.iter().sum::<f64>() / slid.len() as f64,
        ));
        m.push((
            "max_slide_distance_m".into(),
            slid.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        ));
    }
    m.retain(|(_, v)| v.is_finite());
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn histogram_bins_align_on_the_width() {
        let (e, c) = histogram(&[0.01, 0.04, 0.06, 0.26], 0.05);
        assert_eq!(c, vec![2, 1, 0, 0, 0, 1]);
        assert_eq!(e.len(), 7);
        assert!((e[0] - 0.0).abs() < 1e-12 && (e[6] - 0.30).abs() < 1e-12);
        let (e, c) = histogram(&[-0.02], 0.05);
        assert_eq!(c, vec![1]);
        assert!((e[0] + 0.05).abs() < 1e-12);
        assert_eq!(histogram(&[], 0.05), (vec![], vec![]));
    }

    #[test]
    fn histogram_of_a_long_span_widens_its_bins() {
        let (e, c) = histogram(&[0.0, 20_000.0], 0.001);
        assert!(c.len() <= MAX_BINS, "{} bins", c.len());
        assert_eq!(c.iter().sum::<u32>(), 2);
        // The bin widens by a whole factor: edges stay on multiples of 1 mm.
        let w = e[1] - e[0];
        assert!(((w / 0.001).round() - w / 0.001).abs() < 1e-6, "{w}");
    }
}
