//! Two layouts compared (`applesim audit A B`, docs/damage.md section 9): which is better on
//! the three headline figures of the fruit's damage, for the line and per transfer point, and
//! whether a difference is larger than the scatter.
//!
//! The figures (lower is better):
//! - **apples downgraded**: the share of the run's fruit graded below the standard's best class
//!   (per transfer point: whose downgrade was caused there, `downgraded_by`);
//! - **bruise volume**: the total over the fruit (mm^3; per point: what arose there);
//! - **95th percentile peak g**: over the apples, of each apple's hardest impact (per point: over
//!   the impacts there, each apple of an apple-apple impact counted, as `audit.csv`'s
//!   `peak_g_p95`), by nearest rank.
//!
//! Each difference is A - B with a 95 % interval, and a difference whose interval holds 0 is "no
//! change". From one run of each layout ([`compare_runs`]) the apples are the samples: the
//! downgraded share by Newcombe's interval, the others by a bootstrap over each run's apples
//! ([`super::interval`]); that is the apple-to-apple scatter within the two runs. Over paired
//! feed seeds ([`compare_seeds`]) each seed gives one difference and the interval is Student's t
//! over them: the run-to-run scatter.

use super::interval::{self, Interval};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;

/// One impact of one apple (a row of `apple_contacts.csv` with a bruise site).
#[derive(Debug, Clone, PartialEq)]
pub struct HitSample {
    /// Where in the line.
    pub transfer_point: String,
    /// The apple's peak acceleration in the impact (g).
    pub peak_g: f64,
    /// The impact's part of its site's bruise volume (mm^3; `None` for an onset model).
    pub volume_mm3: Option<f64>,
}

/// One fruit apple of a run, as the comparison samples it.
#[derive(Debug, Clone, PartialEq)]
pub struct AppleSample {
    /// Its name.
    pub apple: String,
    /// The transfer point of the hit that first put it below the best class, when it is.
    pub downgraded_at: Option<String>,
    /// Its bruise volume (mm^3; `None` for an onset model).
    pub bruise_volume_mm3: Option<f64>,
    /// Its impacts.
    pub hits: Vec<HitSample>,
}

impl AppleSample {
    /// Whether it is graded below the best class.
    pub fn downgraded(&self) -> bool {
        self.downgraded_at.is_some()
    }
}

/// The fruit of one run (from its folder: `output::compare::read_run`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunSample {
    /// The fruit apples, in the run's order.
    pub apples: Vec<AppleSample>,
}

/// A headline figure (lower is better).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Figure {
    /// The share of the fruit downgraded (0..1).
    Downgraded,
    /// The total bruise volume (mm^3).
    BruiseVolume,
    /// The 95th percentile peak g.
    P95PeakG,
}

impl Figure {
    /// The three, in the order they are reported.
    pub const ALL: [Figure; 3] = [Figure::Downgraded, Figure::BruiseVolume, Figure::P95PeakG];

    /// The figure's name in the table.
    pub fn label(self) -> &'static str {
        match self {
            Figure::Downgraded => "apples downgraded",
            Figure::BruiseVolume => "bruise volume (mm^3)",
            Figure::P95PeakG => "95th percentile peak g",
        }
    }

    /// The figure's key in `compare.csv`.
    pub fn key(self) -> &'static str {
        match self {
            Figure::Downgraded => "apples_downgraded_share",
            Figure::BruiseVolume => "bruise_volume_mm3",
            Figure::P95PeakG => "p95_peak_g",
        }
    }
}

/// What a difference says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The interval holds 0 (or there is no difference at all).
    NoChange,
    /// A is lower (better), the interval below 0.
    ABetter,
    /// B is lower (better), the interval above 0.
    BBetter,
    /// A is lower, with no interval to judge it by (a run of fewer than 2 apples, or seeds
    /// without the figure).
    ALowerNoInterval,
    /// B is lower, with no interval to judge it by.
    BLowerNoInterval,
    /// A layout has no such figure (an onset model has no volume; no impacts at the point).
    NotComparable,
}

impl Verdict {
    /// The verdict of difference `d` (A - B) with its interval.
    pub fn of(d: f64, interval: Option<&Interval>) -> Verdict {
        if !d.is_finite() {
            return Verdict::NotComparable;
        }
        match interval {
            Some(i) if i.contains(0.0) => Verdict::NoChange,
            Some(i) if i.high < 0.0 => Verdict::ABetter,
            Some(_) => Verdict::BBetter,
            None if d == 0.0 => Verdict::NoChange,
            None if d < 0.0 => Verdict::ALowerNoInterval,
            None => Verdict::BLowerNoInterval,
        }
    }

    /// The verdict in the table.
    pub fn label(self) -> &'static str {
        match self {
            Verdict::NoChange => "no change",
            Verdict::ABetter => "**A better**",
            Verdict::BBetter => "**B better**",
            Verdict::ALowerNoInterval => "A lower (no interval)",
            Verdict::BLowerNoInterval => "B lower (no interval)",
            Verdict::NotComparable => "-",
        }
    }

    /// The verdict in `compare.csv`.
    pub fn key(self) -> &'static str {
        match self {
            Verdict::NoChange => "no_change",
            Verdict::ABetter => "a_better",
            Verdict::BBetter => "b_better",
            Verdict::ALowerNoInterval => "a_lower_no_interval",
            Verdict::BLowerNoInterval => "b_lower_no_interval",
            Verdict::NotComparable => "",
        }
    }
}

/// How the intervals were found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// From one run of each layout, the apples as samples.
    Apples,
    /// Over this many paired feed seeds.
    Seeds(usize),
}

/// One layout's side of a row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Side {
    /// The figure (over seeds: its mean over the seeds where both layouts have it).
    pub value: f64,
    /// Over seeds: the figure's standard deviation (NaN from one run).
    pub sd: f64,
    /// Apples downgraded in the row's scope (over seeds: the mean).
    pub downgraded: f64,
    /// Fruit apples of the run (over seeds: the mean).
    pub apples: f64,
    /// Samples behind the interval: apples, or the seeds where both layouts have the figure
    /// (the mean is over them).
    pub samples: usize,
}

/// One figure of one scope compared.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The transfer point, or `None` for the whole line.
    pub point: Option<String>,
    /// The figure.
    pub figure: Figure,
    /// Layout A.
    pub a: Side,
    /// Layout B.
    pub b: Side,
    /// A - B (over seeds: the mean of the paired differences).
    pub difference: f64,
    /// Its 95 % interval, when there is one.
    pub interval: Option<Interval>,
    /// How the interval was found: `newcombe`, `bootstrap`, `paired_t` (empty without one).
    pub interval_method: &'static str,
    /// What the difference says.
    pub verdict: Verdict,
}

/// Two layouts compared.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// How the intervals were found.
    pub method: Method,
    /// The whole line's three figures, then per transfer point (most damage first) three each.
    pub rows: Vec<Row>,
}

/// One apple's part in a scope (the line, or a transfer point): what each figure needs of it.
#[derive(Debug, Clone)]
struct Unit {
    downgraded: bool,
    volume_mm3: Option<f64>,
    /// The peak g values it adds to the percentile: its hardest impact (line), its impacts
    /// there (a point).
    peak_g: Vec<f64>,
}

fn units(run: &RunSample, point: Option<&str>) -> Vec<Unit> {
    run.apples
        .iter()
        .map(|a| match point {
            None => Unit {
                downgraded: a.downgraded(),
                volume_mm3: a.bruise_volume_mm3,
                peak_g: vec![a.hits.iter().map(|h| h.peak_g).fold(0.0, f64::max)],
            },
            Some(p) => {
                let here: Vec<&HitSample> =
                    a.hits.iter().filter(|h| h.transfer_point == p).collect();
                // An apple without a size model has no volume anywhere.
                let volume_mm3 = a.bruise_volume_mm3.map(|_| {
                    here.iter()
                        .filter_map(|h| h.volume_mm3)
                        .fold(0.0, |s, v| s + v)
                });
                Unit {
                    downgraded: a.downgraded_at.as_deref() == Some(p),
                    volume_mm3,
                    peak_g: here.iter().map(|h| h.peak_g).collect(),
                }
            }
        })
        .collect()
}

fn figure_of(f: Figure, u: &[&Unit]) -> f64 {
    match f {
        Figure::Downgraded => {
            if u.is_empty() {
                f64::NAN
            } else {
                u.iter().filter(|x| x.downgraded).count() as f64 / u.len() as f64
            }
        }
        Figure::BruiseVolume => u
            .iter()
            .filter_map(|x| x.volume_mm3)
            .fold(f64::NAN, |s, v| if s.is_nan() { v } else { s + v }),
        Figure::P95PeakG => {
            let mut g: Vec<f64> = u.iter().flat_map(|x| x.peak_g.iter().copied()).collect();
            g.sort_by(f64::total_cmp);
            interval::nearest_rank(&g, 0.95)
        }
    }
}

fn whole(f: Figure, u: &[Unit]) -> f64 {
    figure_of(f, &u.iter().collect::<Vec<_>>())
}

/// The transfer points of the runs (impacts or downgrades there), most damage first: by the
/// larger total bruise volume there over the runs, then the larger 95th percentile peak g, then
/// by name.
fn points<'a>(runs: impl Iterator<Item = &'a RunSample> + Clone) -> Vec<String> {
    let mut names: BTreeSet<&str> = BTreeSet::new();
    for r in runs.clone() {
        for a in &r.apples {
            names.extend(a.hits.iter().map(|h| h.transfer_point.as_str()));
            names.extend(a.downgraded_at.as_deref());
        }
    }
    let nan0 = |x: f64| if x.is_nan() { -1.0 } else { x };
    let mut keyed: Vec<(f64, f64, f64, &str)> = names
        .into_iter()
        .map(|p| {
            let mut key = (0.0f64, 0.0f64, 0.0f64);
            for r in runs.clone() {
                let u = units(r, Some(p));
                key.0 = key.0.max(whole(Figure::Downgraded, &u));
                key.1 = key.1.max(nan0(whole(Figure::BruiseVolume, &u)));
                key.2 = key.2.max(nan0(whole(Figure::P95PeakG, &u)));
            }
            (key.0, key.1, key.2, p)
        })
        .collect();
    keyed.sort_by(|x, y| {
        y.0.total_cmp(&x.0)
            .then(y.1.total_cmp(&x.1))
            .then(y.2.total_cmp(&x.2))
            .then(x.3.cmp(y.3))
    });
    keyed.into_iter().map(|k| k.3.to_string()).collect()
}

/// The line's scope, then each transfer point's.
fn scopes(points: Vec<String>) -> Vec<Option<String>> {
    std::iter::once(None)
        .chain(points.into_iter().map(Some))
        .collect()
}

/// Compares one run of layout A with one of layout B, the apples as samples: the downgraded
/// share by Newcombe's interval ([`interval::newcombe`]), bruise volume and the 95th percentile
/// peak g by a bootstrap over each run's apples ([`interval::bootstrap`], an apple drawn with
/// all its impacts). The intervals are the apple-to-apple scatter within these two runs.
pub fn compare_runs(a: &RunSample, b: &RunSample) -> Comparison {
    let mut rows = Vec::new();
    for scope in scopes(points([a, b].into_iter())) {
        let ua = units(a, scope.as_deref());
        let ub = units(b, scope.as_deref());
        for f in Figure::ALL {
            let side = |u: &[Unit]| Side {
                value: whole(f, u),
                sd: f64::NAN,
                downgraded: u.iter().filter(|x| x.downgraded).count() as f64,
                apples: u.len() as f64,
                samples: u.len(),
            };
            let (sa, sb) = (side(&ua), side(&ub));
            let difference = sa.value - sb.value;
            let (interval, how) = match f {
                Figure::Downgraded => (
                    interval::newcombe(
                        sa.downgraded as usize,
                        ua.len(),
                        sb.downgraded as usize,
                        ub.len(),
                    ),
                    "newcombe",
                ),
                _ => (
                    interval::bootstrap(
                        &ua,
                        &ub,
                        |s| figure_of(f, s),
                        interval::BOOTSTRAP_RESAMPLES,
                        interval::BOOTSTRAP_SEED,
                    ),
                    "bootstrap",
                ),
            };
            let interval = interval.filter(|_| difference.is_finite());
            rows.push(Row {
                point: scope.clone(),
                figure: f,
                a: sa,
                b: sb,
                difference,
                verdict: Verdict::of(difference, interval.as_ref()),
                interval_method: if interval.is_some() { how } else { "" },
                interval,
            });
        }
    }
    Comparison {
        method: Method::Apples,
        rows,
    }
}

/// Compares layout A with layout B over paired feed seeds: `a[k]` and `b[k]` ran with the same
/// seed. Each figure's difference is the mean of the per-seed differences with its paired t
/// interval ([`interval::paired_t`]), over the seeds where both runs have the figure: the
/// run-to-run scatter. `a` and `b` must be of the same length (extra runs are ignored).
pub fn compare_seeds(a: &[RunSample], b: &[RunSample]) -> Comparison {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut rows = Vec::new();
    for scope in scopes(points(a.iter().chain(b))) {
        let ua: Vec<Vec<Unit>> = a.iter().map(|r| units(r, scope.as_deref())).collect();
        let ub: Vec<Vec<Unit>> = b.iter().map(|r| units(r, scope.as_deref())).collect();
        for f in Figure::ALL {
            let va: Vec<f64> = ua.iter().map(|u| whole(f, u)).collect();
            let vb: Vec<f64> = ub.iter().map(|u| whole(f, u)).collect();
            // The seeds where both layouts have the figure: each side's mean is over them, so
            // that the two means differ by the mean difference (a side's own seeds otherwise).
            let paired: Vec<usize> = (0..n)
                .filter(|&k| va[k].is_finite() && vb[k].is_finite())
                .collect();
            let side = |v: &[f64], u: &[Vec<Unit>]| {
                let finite: Vec<f64> = if paired.is_empty() {
                    v.iter().copied().filter(|x| x.is_finite()).collect()
                } else {
                    paired.iter().map(|&k| v[k]).collect()
                };
                let (value, sd) = if finite.is_empty() {
                    (f64::NAN, f64::NAN)
                } else {
                    interval::mean_sd(&finite)
                };
                let count = |g: &dyn Fn(&[Unit]) -> f64| {
                    u.iter().map(|x| g(x)).sum::<f64>() / u.len().max(1) as f64
                };
                Side {
                    value,
                    sd,
                    downgraded: count(&|x| x.iter().filter(|y| y.downgraded).count() as f64),
                    apples: count(&|x| x.len() as f64),
                    samples: finite.len(),
                }
            };
            let d: Vec<f64> = va
                .iter()
                .zip(&vb)
                .map(|(x, y)| x - y)
                .filter(|x| x.is_finite())
                .collect();
            let difference = if d.is_empty() {
                f64::NAN
            } else {
                d.iter().sum::<f64>() / d.len() as f64
            };
            let interval = interval::paired_t(&d);
            rows.push(Row {
                point: scope.clone(),
                figure: f,
                a: side(&va, &ua),
                b: side(&vb, &ub),
                difference,
                verdict: Verdict::of(difference, interval.as_ref()),
                interval_method: if interval.is_some() { "paired_t" } else { "" },
                interval,
            });
        }
    }
    Comparison {
        method: Method::Seeds(n),
        rows,
    }
}

/// Header of `compare.csv`: one row per scope (`all`, the whole line, or a transfer point) and
/// figure; `a` and `b` the figures (over seeds, their means), `difference` A - B, `low_95` and
/// `high_95` its interval, `verdict` (`no_change`, `a_better`, `b_better`,
/// `a_lower_no_interval`, `b_lower_no_interval`, empty without a figure), `interval` how it was
/// found (`newcombe`, `bootstrap`, `paired_t`), `samples_a` and `samples_b` the apples, or the
/// seeds with the figure, `sd_a` and `sd_b` over seeds the figures' standard deviations (empty
/// from one run). Shares are fractions (0..1).
pub const COMPARE_HEADER: [&str; 13] = [
    "transfer_point",
    "figure",
    "a",
    "b",
    "difference",
    "low_95",
    "high_95",
    "verdict",
    "interval",
    "samples_a",
    "samples_b",
    "sd_a",
    "sd_b",
];

/// The scope name of the whole line in `compare.csv`.
pub const WHOLE_LINE: &str = "all";

impl Comparison {
    /// The rows of `compare.csv` ([`COMPARE_HEADER`]; a figure that is not a number is empty).
    pub fn csv_rows(&self) -> Vec<[String; 13]> {
        let num = |x: f64| {
            if x.is_finite() {
                x.to_string()
            } else {
                String::new()
            }
        };
        self.rows
            .iter()
            .map(|r| {
                let (lo, hi) = r.interval.map_or((f64::NAN, f64::NAN), |i| (i.low, i.high));
                [
                    r.point.clone().unwrap_or_else(|| WHOLE_LINE.to_string()),
                    r.figure.key().to_string(),
                    num(r.a.value),
                    num(r.b.value),
                    num(r.difference),
                    num(lo),
                    num(hi),
                    r.verdict.key().to_string(),
                    r.interval_method.to_string(),
                    r.a.samples.to_string(),
                    r.b.samples.to_string(),
                    num(r.a.sd),
                    num(r.b.sd),
                ]
            })
            .collect()
    }

    /// The comparison as Markdown, for a packhouse engineer: what was compared, how to read it,
    /// the ranking of the whole line, then per transfer point, then how the intervals were found.
    /// `a` and `b` name the layouts (their folders or scenario files); `seeds_command` is the
    /// command line to suggest for seed-to-seed intervals (shown after one run of each).
    pub fn markdown(&self, a: &str, b: &str, seeds_command: &str) -> String {
        let mut s = String::from("# Layouts compared\n\n");
        let _ = writeln!(s, "- A: {a}\n- B: {b}");
        let line: Vec<&Row> = self.rows.iter().filter(|r| r.point.is_none()).collect();
        let apples = |side: fn(&Row) -> &Side| line.first().map_or(0.0, |r| side(r).apples);
        match self.method {
            Method::Apples => {
                let _ = writeln!(
                    s,
                    "- From one run of each: A {} apples, B {} apples.\n",
                    apples(|r| &r.a),
                    apples(|r| &r.b)
                );
            }
            Method::Seeds(n) => {
                let _ = writeln!(
                    s,
                    "- Over {n} feed seeds, paired: run k of A and run k of B were fed with the same seed k. Figures are the means over the seeds (+- their standard deviation); A - B is the mean of the {n} paired differences.\n"
                );
            }
        }
        s += "Lower is better for every figure. A - B is the difference with its 95 % interval; a difference whose interval holds 0 is **no change**: the layouts cannot be told apart by it.\n\n";
        match self.method {
            Method::Apples => {
                let _ = writeln!(
                    s,
                    "These intervals come from one run of each layout: they are the **apple-to-apple scatter** within those two runs (each run's apples taken as samples of the layout's apples), not the scatter from one feed to the next (sizes, spawn points, timing). Another feed can move a figure by more than these intervals say. For the seed-to-seed scatter, rerun both layouts over several feed seeds: `{seeds_command}`.\n"
                );
            }
            Method::Seeds(_) => {
                s += "These intervals are the **seed-to-seed scatter**: how much a figure's difference moves from one feed to another.\n\n";
            }
        }
        s += "## Ranking\n\n| figure | verdict | A | B | A - B | 95 % interval |\n|---|---|---|---|---|---|\n";
        for r in &line {
            s += &self.row_md(r, false);
        }
        let per_point: Vec<&Row> = self.rows.iter().filter(|r| r.point.is_some()).collect();
        if !per_point.is_empty() {
            s += "\n## Per transfer point\n\nApples downgraded there: whose downgrade was caused by a hit there, over all the run's apples. Bruise volume: what arose there. Peak g: the 95th percentile over the impacts there.\n\n| transfer point | figure | verdict | A | B | A - B | 95 % interval |\n|---|---|---|---|---|---|---|\n";
            for r in per_point {
                s += &self.row_md(r, true);
            }
        }
        s += "\n## The intervals\n\n";
        match self.method {
            Method::Apples => {
                let _ = writeln!(
                    s,
                    "- Apples downgraded: the difference of two shares, by Newcombe's hybrid score interval (Newcombe 1998, method 10; from each share's Wilson interval): it keeps its coverage for small runs and shares near 0 or 100 %, where the textbook interval shrinks to nothing.\n- Bruise volume and 95th percentile peak g: a percentile bootstrap over the apples of each run ({} resamples, each apple drawn with all its impacts; seeded, so the same runs give the same bytes). Volumes are skewed (most apples 0, a few large): no normal formula fits them.\n- A run of fewer than 2 apples has no scatter to judge by, nor a transfer point that so few apples reach that a tenth of the resamples miss it (no peak g there to take a percentile of): the difference is printed with no interval.",
                    interval::BOOTSTRAP_RESAMPLES
                );
            }
            Method::Seeds(n) => {
                let _ = writeln!(
                    s,
                    "- Each figure: the mean of the {n} paired differences A - B +- t(0.975, {}) s / sqrt({n}) (Student's t, s their standard deviation), over the seeds where both runs have the figure (a transfer point without impacts in a run has no peak g there; the interval then says over how many, and both layouts' figures are the means over those seeds). Pairing takes out what the feed does to both layouts alike. Fewer than 2 such seeds give no interval.",
                    n.saturating_sub(1)
                );
            }
        }
        s
    }

    fn row_md(&self, r: &Row, with_point: bool) -> String {
        let (d, unit) = match r.figure {
            Figure::Downgraded => (100.0, " pp"),
            Figure::BruiseVolume => (1.0, ""),
            Figure::P95PeakG => (1.0, ""),
        };
        let places = match r.figure {
            Figure::Downgraded => 1,
            Figure::BruiseVolume => 0,
            Figure::P95PeakG => 1,
        };
        let num = |x: f64| {
            if x.is_finite() {
                shown(x * d, places, false)
            } else {
                "-".into()
            }
        };
        let signed = |x: f64| {
            if x.is_finite() {
                shown(x * d, places, true)
            } else {
                "-".into()
            }
        };
        // A count: whole, or a mean over seeds to one decimal.
        let count = |x: f64| {
            if x.fract() == 0.0 {
                format!("{x}")
            } else {
                format!("{x:.1}")
            }
        };
        let side = |x: &Side| {
            let mut v = num(x.value);
            if x.sd.is_finite() && x.value.is_finite() {
                v += &format!(" +- {}", num(x.sd));
            }
            if r.figure == Figure::Downgraded && x.value.is_finite() {
                v = format!("{v} % ({} of {})", count(x.downgraded), count(x.apples));
            }
            v
        };
        let mut interval = match (&r.interval, r.difference.is_finite()) {
            (Some(i), _) => format!("{} to {}{unit}", signed(i.low), signed(i.high)),
            (None, true) => "none".into(),
            (None, false) => "-".into(),
        };
        // Over seeds, say when only some of them have the figure in both layouts.
        if let Method::Seeds(n) = self.method {
            if r.difference.is_finite() && r.a.samples < n {
                interval += &format!(" ({} of {n} seeds)", r.a.samples);
            }
        }
        let diff = if r.difference.is_finite() {
            format!("{}{unit}", signed(r.difference))
        } else {
            "-".into()
        };
        let point = if with_point {
            format!("| {} ", r.point.as_deref().unwrap_or(""))
        } else {
            String::new()
        };
        format!(
            "{point}| {} | {} | {} | {} | {diff} | {interval} |\n",
            r.figure.label(),
            r.verdict.label(),
            side(&r.a),
            side(&r.b),
        )
    }

    /// The rows of one scope (`None`: the whole line), by figure.
    pub fn scope(&self, point: Option<&str>) -> BTreeMap<Figure, &Row> {
        self.rows
            .iter()
            .filter(|r| r.point.as_deref() == point)
            .map(|r| (r.figure, r))
            .collect()
    }
}

/// `x` to `places` decimals (with its sign when `signed`), or to as many more, up to 4, as it
/// takes not to print a number other than 0 as 0 (an interval bound of -0.2 mm^3 is not 0); 0
/// itself without a sign.
fn shown(x: f64, places: usize, signed: bool) -> String {
    if x == 0.0 {
        return format!("{:.places$}", 0.0);
    }
    let mut p = places;
    while p < places + 4 && (x * 10f64.powi(p as i32)).abs() < 0.5 {
        p += 1;
    }
    if signed {
        format!("{x:+.p$}")
    } else {
        format!("{x:.p$}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_numbers_are_not_printed_as_zero() {
        assert_eq!(shown(-0.21, 0, true), "-0.2");
        assert_eq!(shown(0.0, 1, true), "0.0");
        assert_eq!(shown(12.34, 1, true), "+12.3");
        assert_eq!(shown(0.004, 1, false), "0.004");
    }

    fn apple(name: &str, down: Option<&str>, vol: f64, hits: &[(&str, f64, f64)]) -> AppleSample {
        AppleSample {
            apple: name.into(),
            downgraded_at: down.map(String::from),
            bruise_volume_mm3: Some(vol),
            hits: hits
                .iter()
                .map(|&(p, g, v)| HitSample {
                    transfer_point: p.into(),
                    peak_g: g,
                    volume_mm3: Some(v),
                })
                .collect(),
        }
    }

    fn run(scale: f64, n: usize) -> RunSample {
        RunSample {
            apples: (0..n)
                .map(|k| {
                    let v = scale * (k % 5) as f64 * 100.0;
                    let down = (v > 250.0).then_some("plate");
                    apple(
                        &format!("a-{k}"),
                        down,
                        v,
                        &[("plate", scale * (50.0 + k as f64), v), ("belt", 5.0, 0.0)],
                    )
                })
                .collect(),
        }
    }

    #[test]
    fn a_run_against_itself_is_no_change_everywhere() {
        let r = run(1.0, 30);
        let c = compare_runs(&r, &r);
        assert_eq!(c.rows.len(), 9);
        for row in &c.rows {
            assert_eq!(row.verdict, Verdict::NoChange, "{row:?}");
            assert_eq!(row.difference, 0.0);
        }
        let md = c.markdown("x", "x", "cmd");
        assert!(
            !md.contains("A better") && !md.contains("B better") && !md.contains("worse"),
            "{md}"
        );
        assert!(md.contains("apple-to-apple scatter") && md.contains("`cmd`"));
    }

    #[test]
    fn a_large_difference_is_ranked_with_an_interval_off_zero() {
        let (a, b) = (run(0.3, 30), run(1.0, 30));
        let c = compare_runs(&a, &b);
        let line = c.scope(None);
        for f in Figure::ALL {
            assert_eq!(line[&f].verdict, Verdict::ABetter, "{:?}", line[&f]);
            assert!(line[&f].interval.unwrap().high < 0.0);
        }
        // The belt does the same in both: no change there.
        let belt = c.scope(Some("belt"));
        assert_eq!(belt[&Figure::P95PeakG].verdict, Verdict::NoChange);
        assert_eq!(belt[&Figure::Downgraded].verdict, Verdict::NoChange);
        assert_eq!(
            c.rows[3].point.as_deref(),
            Some("plate"),
            "most damage first"
        );
    }

    #[test]
    fn seeds_pair_the_runs() {
        let a: Vec<RunSample> = (0..3).map(|k| run(0.5 + 0.01 * k as f64, 10)).collect();
        let b: Vec<RunSample> = (0..3).map(|k| run(1.0 + 0.01 * k as f64, 10)).collect();
        let c = compare_seeds(&a, &b);
        assert_eq!(c.method, Method::Seeds(3));
        let line = c.scope(None);
        assert_eq!(line[&Figure::BruiseVolume].verdict, Verdict::ABetter);
        let same = compare_seeds(&a, &a);
        assert!(same.rows.iter().all(|r| r.verdict == Verdict::NoChange));
        assert!(same.markdown("a", "a", "").contains("seed-to-seed scatter"));
    }

    #[test]
    fn one_apple_has_no_interval_and_an_onset_model_no_volume() {
        let a = RunSample {
            apples: vec![apple("x", None, 10.0, &[("plate", 20.0, 10.0)])],
        };
        let b = RunSample {
            apples: vec![apple("x", None, 30.0, &[("plate", 40.0, 30.0)])],
        };
        let c = compare_runs(&a, &b);
        let line = c.scope(None);
        assert_eq!(
            line[&Figure::BruiseVolume].verdict,
            Verdict::ALowerNoInterval
        );
        assert_eq!(line[&Figure::Downgraded].verdict, Verdict::NoChange);
        let mut onset = a.clone();
        onset.apples[0].bruise_volume_mm3 = None;
        onset.apples[0].hits[0].volume_mm3 = None;
        let c = compare_runs(&onset, &onset);
        assert_eq!(
            c.scope(None)[&Figure::BruiseVolume].verdict,
            Verdict::NotComparable
        );
    }
}
