//! The line audit: where in the line apples are hit, how hard, and how many of them, per
//! transfer point, the way packhouses read an instrumented sphere's run (peak acceleration and
//! velocity change at each point of the line, against bruise thresholds).
//!
//! A transfer point is a surface (a bin's walls apart: `bin/floor`, `bin/x_max`, ...; a roller
//! bed's rollers `bed/0`, `bed/1`, ... together: `bed`), or for
//! apple-on-apple hits the region they happen over: `apples on REGION`, REGION the surface (a
//! bin as a whole) that either apple touched last before the hit, `apples in the air` when
//! neither had touched one. Per point: the contacts there (as `contacts.csv` lists them), the
//! impacts, the share of the run's apples hit, peak force and peak g (median, 95th percentile,
//! largest), velocity change (median, 95th percentile, largest), energy absorbed (in all and
//! largest), and the apples with an impact over any bruise threshold there. Resting contacts
//! count as contacts, not impacts.

use super::bruise::BruiseReport;
use super::impacts::{self, STANDARD_GRAVITY};
use crate::record::events::{ContactEvent, Party};
use crate::world::Roster;
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

/// The figures of one transfer point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TransferPoint {
    /// The surface, or `apples on REGION`.
    pub point: String,
    /// Contacts there (impacts and resting contacts).
    pub contacts: usize,
    /// Impacts there (contacts that start with an approach; an apple-apple impact counts once
    /// as a contact and once per apple below).
    pub impacts: usize,
    /// Apples hit there at least once, over the apples of the run.
    pub apples_hit_share: f64,
    /// Peak force of the impacts (N): median, 95th percentile, largest.
    pub peak_force_n: [f64; 3],
    /// Peak acceleration of the apples hit (g): median, 95th percentile, largest.
    pub peak_g: [f64; 3],
    /// Velocity change of the apples hit (m/s): median, 95th percentile, largest.
    pub velocity_change_m_s: [f64; 3],
    /// Energy absorbed by the impacts (J): in all, largest.
    pub absorbed_energy_j: [f64; 2],
    /// Apples with a contact there over each bruise threshold of their material.
    pub apples_over: OverThreshold,
}

/// Apples over each bruise threshold at one transfer point (an apple counts once per threshold,
/// however many of its contacts there exceeded it; a threshold the material does not set counts
/// none). The names are those of `bruise.csv`'s `exceeded` column.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct OverThreshold {
    /// Over any threshold.
    pub any: usize,
    /// Impact peak force over `peak_force_n`.
    pub force: usize,
    /// Impact peak mean pressure over `mean_pressure_pa`.
    pub pressure: usize,
    /// Impact absorbed energy over `absorbed_energy_j`.
    pub energy: usize,
    /// Resting force over `static_force_n`.
    pub static_force: usize,
    /// Resting mean pressure over `static_pressure_pa`.
    pub static_pressure: usize,
}

impl OverThreshold {
    /// The counts with their names (`any`, `force`, ... as in `bruise.csv`), CSV column order.
    pub fn named(&self) -> [(&'static str, usize); 6] {
        [
            ("any", self.any),
            ("force", self.force),
            ("pressure", self.pressure),
            ("energy", self.energy),
            ("static-force", self.static_force),
            ("static-pressure", self.static_pressure),
        ]
    }
}

/// The audit of a run: one row per transfer point, hardest first (largest peak g).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Audit {
    /// The transfer points.
    pub points: Vec<TransferPoint>,
}

/// One apple's side of one impact, as the audit counts it.
struct Hit {
    apple: usize,
    peak_force_n: f64,
    peak_g: f64,
    dv: f64,
}

/// The median, 95th percentile (nearest rank) and largest of `v` (NaN when empty).
fn quantiles(mut v: Vec<f64>) -> [f64; 3] {
    if v.is_empty() {
        return [f64::NAN; 3];
    }
    v.sort_by(f64::total_cmp);
    let rank = |q: f64| v[((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
    [rank(0.5), rank(0.95), v[v.len() - 1]]
}

/// The region a surface belongs to (a bin's walls make one bin, a roller bed's rollers one bed).
fn region(surface: &str) -> &str {
    surface.split('/').next().unwrap_or(surface)
}

/// The transfer point of a surface contact: the surface, but a roller bed's rollers (`BED/0`,
/// `BED/1`, ...: '/' and a number) are one point, the bed, as a line designer reads a bed (a
/// bin's walls, `BIN/floor`, stay apart: which wall is hit matters).
fn surface_point(surface: &str) -> &str {
    match surface.rsplit_once('/') {
        Some((bed, i)) if !i.is_empty() && i.bytes().all(|b| b.is_ascii_digit()) => bed,
        _ => surface,
    }
}

/// The transfer point of each contact (index in `events`): a surface contact's surface; for two
/// apples, the region (a surface, or a bin with its walls) where the hit happens: that of the
/// surface either apple is touching at the hit (the one it has touched the longest, if both
/// are), else of the surface either apple touched last, the earlier arrival's (an apple coming
/// off the chute hits the apples waiting in the bin: "apples on bin"); "apples in the air" if
/// neither has touched a surface yet.
pub fn points_of(events: &[ContactEvent]) -> Vec<String> {
    // Each apple's surface contacts: (start, end, surface), in order of start.
    let mut surfaces: BTreeMap<u32, Vec<(f64, f64, &str)>> = BTreeMap::new();
    for e in events {
        if let Party::Surface(_) = e.b_party {
            surfaces.entry(e.a_index).or_default().push((
                e.t_start_s,
                e.t_end_s.unwrap_or(f64::INFINITY),
                &e.b,
            ));
        }
    }
    // The apple's place at `t`: (touching a surface now, -start of that contact, surface),
    // the larger the better placed: a surface touched now, then the earliest arrival.
    let place = |apple: u32, t: f64| -> Option<(bool, f64, &str)> {
        let list = surfaces.get(&apple)?;
        let open = list
            .iter()
            .filter(|(t0, t1, _)| *t0 <= t && t <= *t1)
            .min_by(|x, y| x.0.total_cmp(&y.0));
        match open {
            Some(&(t0, _, s)) => Some((true, -t0, s)),
            None => list
                .iter()
                .rev()
                .find(|(t0, _, _)| *t0 <= t)
                .map(|&(t0, _, s)| (false, -t0, s)),
        }
    };
    events
        .iter()
        .map(|e| match e.b_party {
            Party::Surface(_) => surface_point(&e.b).to_string(),
            Party::Apple(j) => {
                let t = e.impact.map_or(e.t_start_s, |i| i.t_peak_s);
                let best = match (place(e.a_index, t), place(j, t)) {
                    (Some(x), Some(y)) => Some(if (x.0, x.1) >= (y.0, y.1) { x } else { y }),
                    (x, y) => x.or(y),
                };
                match best {
                    Some((_, _, s)) => format!("apples on {}", region(s)),
                    None => "apples in the air".to_string(),
                }
            }
        })
        .collect()
}

/// The audit of a run's contacts; `bruise` tells which impacts exceeded a threshold.
pub fn audit(
    events: &[ContactEvent],
    points: &[String],
    roster: &Roster,
    bruise: &BruiseReport,
) -> Audit {
    let names = roster.by_name();
    let index: BTreeMap<&str, usize> = roster
        .apples()
        .iter()
        .enumerate()
        .map(|(k, a)| (a.name.as_str(), k))
        .collect();
    let mut contacts: BTreeMap<&str, usize> = BTreeMap::new();
    let mut impacts: BTreeMap<&str, usize> = BTreeMap::new();
    let mut hits: BTreeMap<&str, Vec<Hit>> = BTreeMap::new();
    let mut absorbed: BTreeMap<&str, (f64, f64)> = BTreeMap::new();
    // (point, threshold name) -> apples over it there.
    let mut over: BTreeMap<(&str, &str), BTreeSet<usize>> = BTreeMap::new();
    for (e, p) in events.iter().zip(points) {
        let p = p.as_str();
        *contacts.entry(p).or_default() += 1;
        let Some(pulse) = &e.impact else { continue };
        *impacts.entry(p).or_default() += 1;
        let w = absorbed.entry(p).or_insert((0.0, 0.0));
        w.0 += pulse.absorbed_energy_j;
        w.1 = w.1.max(pulse.absorbed_energy_j);
        let mut sides = vec![(&e.a, true)];
        if let Party::Apple(_) = e.b_party {
            sides.push((&e.b, false));
        }
        for (name, towards) in sides {
            let (Some(a), Some(&k)) = (names.get(&**name), index.get(&**name)) else {
                continue;
            };
            let side = impacts::for_apple(pulse, a.mass_kg, towards);
            hits.entry(p).or_default().push(Hit {
                apple: k,
                peak_force_n: pulse.peak_force_n,
                peak_g: side.peak_g,
                dv: side.velocity_change_m_s,
            });
        }
    }
    for c in bruise.contacts.iter().filter(|c| c.at_risk()) {
        let (Some(p), Some(&k)) = (points.get(c.contact), index.get(&*c.apple)) else {
            continue;
        };
        over.entry((p.as_str(), "any")).or_default().insert(k);
        for why in c.exceeded.split('+') {
            over.entry((p.as_str(), why)).or_default().insert(k);
        }
    }
    let n = roster.len().max(1) as f64;
    let mut out: Vec<TransferPoint> = contacts
        .iter()
        .map(|(&p, &c)| {
            let h = hits.get(p).map(Vec::as_slice).unwrap_or(&[]);
            let apples: BTreeSet<usize> = h.iter().map(|x| x.apple).collect();
            let w = absorbed.get(p).copied().unwrap_or((0.0, 0.0));
            TransferPoint {
                point: p.to_string(),
                contacts: c,
                impacts: impacts.get(p).copied().unwrap_or(0),
                apples_hit_share: apples.len() as f64 / n,
                peak_force_n: quantiles(h.iter().map(|x| x.peak_force_n).collect()),
                peak_g: quantiles(h.iter().map(|x| x.peak_g).collect()),
                velocity_change_m_s: quantiles(h.iter().map(|x| x.dv).collect()),
                absorbed_energy_j: [w.0, w.1],
                apples_over: {
                    let n = |why: &str| over.get(&(p, why)).map_or(0, BTreeSet::len);
                    OverThreshold {
                        any: n("any"),
                        force: n("force"),
                        pressure: n("pressure"),
                        energy: n("energy"),
                        static_force: n("static-force"),
                        static_pressure: n("static-pressure"),
                    }
                },
            }
        })
        .collect();
    // Hardest first; points without impacts last, by name.
    out.sort_by(|a, b| {
        let key = |t: &TransferPoint| {
            if t.peak_g[2].is_nan() {
                -1.0
            } else {
                t.peak_g[2]
            }
        };
        key(b).total_cmp(&key(a)).then(a.point.cmp(&b.point))
    });
    Audit { points: out }
}

impl Audit {
    /// Headline figures per transfer point for a batch table: `POINT.impacts`,
    /// `POINT.max_peak_force_n`, `POINT.p95_peak_g`, `POINT.max_peak_g`,
    /// `POINT.max_velocity_change_m_s`, `POINT.apples_over_threshold` (apples over any
    /// threshold there; only finite values).
    pub fn metrics(&self) -> Vec<(String, f64)> {
        let mut m = Vec::new();
        for t in &self.points {
            let p = &t.point;
            m.push((format!("{p}.impacts"), t.impacts as f64));
            m.push((format!("{p}.max_peak_force_n"), t.peak_force_n[2]));
            m.push((format!("{p}.p95_peak_g"), t.peak_g[1]));
            m.push((format!("{p}.max_peak_g"), t.peak_g[2]));
            m.push((
                format!("{p}.max_velocity_change_m_s"),
                t.velocity_change_m_s[2],
            ));
            m.push((
                format!("{p}.apples_over_threshold"),
                t.apples_over.any as f64,
            ));
        }
        m.retain(|(_, v)| v.is_finite());
        m
    }

    /// The audit as a Markdown document (`audit.md`): a title and [`Self::table`].
    pub fn markdown(&self, title: &str) -> String {
        format!("# Line audit: {title}\n\n{}", self.table())
    }

    /// The audit as a Markdown table with a line that says how to read it.
    pub fn table(&self) -> String {
        let f = |x: f64, d: usize| {
            if x.is_finite() {
                format!("{x:.d$}")
            } else {
                "-".to_string()
            }
        };
        let mut s = String::from(
            "One row per transfer point, hardest first. Peak g is the peak contact force over the apple's weight (g = 9.80665 m/s^2); the velocity change is the apple's over the impact pulse. Median / 95th percentile / largest over the apples hit.\n\n| transfer point | contacts | impacts | apples hit | peak force (N) | peak g | velocity change (m/s) | absorbed (J): all / largest | apples over a threshold (force, pressure, energy, static force, static pressure) |\n|---|---|---|---|---|---|---|---|---|\n"
        );
        for t in &self.points {
            let q =
                |v: [f64; 3], d: usize| format!("{} / {} / {}", f(v[0], d), f(v[1], d), f(v[2], d));
            s += &format!(
                "| {} | {} | {} | {:.0} % | {} | {} | {} | {} / {} | {} ({}, {}, {}, {}, {}) |\n",
                t.point,
                t.contacts,
                t.impacts,
                100.0 * t.apples_hit_share,
                q(t.peak_force_n, 1),
                q(t.peak_g, 1),
                q(t.velocity_change_m_s, 2),
                f(t.absorbed_energy_j[0], 4),
                f(t.absorbed_energy_j[1], 4),
                t.apples_over.any,
                t.apples_over.force,
                t.apples_over.pressure,
                t.apples_over.energy,
                t.apples_over.static_force,
                t.apples_over.static_pressure
            );
        }
        s
    }
}

/// The transfer points of several runs side by side (`applesim audit RUN_A RUN_B ...`), as
/// Markdown: per transfer point (in the first run's order, then the points only later runs
/// have), its largest and 95th-percentile peak g, largest velocity change, impacts and apples
/// over a threshold in each run, and each later run against the first: the relative change of
/// each figure and whether it is better (lower) or worse. A point a run does not have reads `-`.
pub fn compare(runs: &[(String, Audit)]) -> String {
    let mut order: Vec<&str> = Vec::new();
    for (_, a) in runs {
        for t in &a.points {
            if !order.contains(&t.point.as_str()) {
                order.push(&t.point);
            }
        }
    }
    type Figure = (&'static str, fn(&TransferPoint) -> f64, usize);
    let figures: [Figure; 5] = [
        ("largest peak g", |t| t.peak_g[2], 1),
        ("95th percentile peak g", |t| t.peak_g[1], 1),
        (
            "largest velocity change (m/s)",
            |t| t.velocity_change_m_s[2],
            2,
        ),
        ("impacts", |t| t.impacts as f64, 0),
        ("apples over a threshold", |t| t.apples_over.any as f64, 0),
    ];
    let cell = |x: Option<f64>, d: usize| match x {
        Some(x) if x.is_finite() => format!("{x:.d$}"),
        _ => "-".to_string(),
    };
    let change = |base: Option<f64>, x: Option<f64>| -> String {
        match (base.filter(|b| b.is_finite()), x.filter(|v| v.is_finite())) {
            (Some(b), Some(v)) if v == b => "same".into(),
            (Some(b), Some(v)) if b != 0.0 => {
                let pct = 100.0 * (v - b) / b.abs();
                let word = if v < b { "better" } else { "worse" };
                format!("{pct:+.1} % ({word})")
            }
            (Some(_), Some(v)) => format!("from 0 to {v} (worse)"),
            (Some(_), None) => "gone".into(),
            (None, Some(_)) => "new".into(),
            (None, None) => "-".into(),
        }
    };
    let mut s = String::from("# Line audit: runs compared\n\n");
    for (k, (label, _)) in runs.iter().enumerate() {
        s += &format!("- run {}: {label}\n", k + 1);
    }
    s += "\nPer transfer point, each figure in each run, and each later run against run 1 (lower is better).\n\n| transfer point | figure |";
    for k in 0..runs.len() {
        s += &format!(" run {} |", k + 1);
    }
    for k in 1..runs.len() {
        s += &format!(" run {} vs 1 |", k + 1);
    }
    s += "\n|---|---|";
    s += &"---|".repeat(2 * runs.len() - 1);
    s += "\n";
    for p in order {
        let at: Vec<Option<&TransferPoint>> = runs
            .iter()
            .map(|(_, a)| a.points.iter().find(|t| t.point == p))
            .collect();
        for (name, get, d) in &figures {
            let v: Vec<Option<f64>> = at.iter().map(|t| t.map(get)).collect();
            s += &format!("| {p} | {name} |");
            for x in &v {
                s += &format!(" {} |", cell(*x, *d));
            }
            for x in &v[1..] {
                s += &format!(" {} |", change(v[0], *x));
            }
            s += "\n";
        }
    }
    s
}

/// The IRD-style chart of a run: one point per apple per impact, peak acceleration (g) against
/// velocity change (m/s), one colour per transfer point (`points`: [`points_of`] the run's
/// contacts), as a packhouse reads an instrumented sphere's run. The bruise boundary drawn is
/// each material's peak-force threshold F as an acceleration, F / (m g), for the lightest and
/// the heaviest apple of that material that was hit (one line when they weigh the same): a hit
/// above the line of its apple's mass is over the threshold. The pressure and energy thresholds
/// depend on the impact's other figures and have no line on these axes (`bruise.csv` holds
/// them). `None` when the run had no impact.
pub fn ird_chart(
    points: &[String],
    bruise: &BruiseReport,
    roster: &Roster,
    title: &str,
) -> Option<crate::chart::LineChart> {
    use crate::chart::{LineChart, MarkerColours, Series};
    let names = roster.by_name();
    let mut groups: BTreeMap<&str, Vec<(f64, f64)>> = BTreeMap::new();
    // material -> (threshold, lightest, heaviest).
    let mut bounds: BTreeMap<&str, (f64, f64, f64)> = BTreeMap::new();
    let mut dv_max: f64 = 0.0;
    for c in bruise.contacts.iter().filter(|c| c.peak_g > 0.0) {
        let Some(p) = points.get(c.contact) else {
            continue;
        };
        groups
            .entry(p.as_str())
            .or_default()
            .push((c.velocity_change_m_s, c.peak_g));
        dv_max = dv_max.max(c.velocity_change_m_s);
        if let Some(a) = names.get(&*c.apple) {
            let b = bounds.entry(a.material.as_str()).or_insert((
                c.thresholds.peak_force_n,
                f64::INFINITY,
                0.0,
            ));
            b.1 = b.1.min(a.mass_kg);
            b.2 = b.2.max(a.mass_kg);
        }
    }
    if groups.is_empty() {
        return None;
    }
    let x1 = if dv_max > 0.0 { 1.05 * dv_max } else { 1.0 };
    let mut series = Vec::new();
    for (material, (f, light, heavy)) in bounds {
        let mut masses = vec![heavy];
        if light < heavy {
            masses.push(light);
        }
        for m in masses {
            let g = f / (m * STANDARD_GRAVITY);
            series.push(Series {
                label: format!(
                    "{material}: {f} N on a {:.0}-gram apple = {g:.1} g",
                    1000.0 * m
                ),
                points: vec![(0.0, g), (x1, g)],
            });
        }
    }
    let mut chart = LineChart::new(
        &format!("Impacts per transfer point: {title}"),
        "velocity change (m/s)",
        "peak acceleration (g)",
        series,
    );
    chart.markers = groups
        .into_iter()
        .map(|(p, pts)| Series {
            label: p.to_string(),
            points: pts,
        })
        .collect();
    chart.marker_colours = MarkerColours::Palette;
    Some(chart)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_by_nearest_rank() {
        assert_eq!(quantiles(vec![3.0, 1.0, 2.0]), [2.0, 3.0, 3.0]);
        let v: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(quantiles(v), [50.0, 95.0, 100.0]);
        assert!(quantiles(vec![])[0].is_nan());
    }
}
