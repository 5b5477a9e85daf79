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
use super::impacts::STANDARD_GRAVITY;
use crate::record::events::{ContactEvent, Party};
use crate::world::zones::{Location, Zones};
use crate::world::Roster;
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

/// The figures of one transfer point (fruit only: a virtual instrumented sphere's contacts are
/// left out).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TransferPoint {
    /// The surface, or `apples on PART`, `apples in BIN`, `apples in the air`.
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
    /// Energy the apples absorbed there (J, their own shares): in all, the most one apple took
    /// in one hit.
    pub absorbed_energy_j: [f64; 2],
    /// Apples bruised there: whose bruise volume grew there (an onset model: with a bruising hit
    /// there).
    pub apples_bruised: usize,
    /// The bruise volume that arose there per apple hit there (mm^3): median, 95th percentile,
    /// and the total over them (NaN for an onset model).
    pub bruise_volume_mm3: [f64; 3],
    /// Apples whose downgrade (below the standard's best class) was caused there: the hit that
    /// first put them below it happened there.
    pub apples_downgraded: usize,
}

/// The audit of a run: one row per transfer point, most bruise volume first (then largest peak
/// g).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Audit {
    /// The transfer points.
    pub points: Vec<TransferPoint>,
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

/// Name of the transfer point of apple-apple hits inside (or on a heap above) bin `bin`.
pub fn in_bin(bin: &str) -> String {
    format!("apples in {bin}")
}

/// The transfer point of each contact (index in `events`). A surface contact's is its surface
/// (a roller bed's rollers: the bed). Two apples' is where their contact point lies at the peak
/// of the hit (`zones`, with the bins and parts where their motions have them then), so that a
/// hit is counted where it happens, not where an apple was last:
///
/// 1. inside a bin's walls: `apples in BIN`;
/// 2. else, if either apple is touching a surface then (the one it has touched the longest, if
///    both are): `apples on SURFACE` (a bin's wall: `apples in BIN`);
/// 3. else over a part within two of the largest apple's diameters (the nearest below it):
///    `apples on PART`, or above a bin's inside, on the heap: `apples in BIN`;
/// 4. else `apples in the air`.
pub fn points_of(events: &[ContactEvent], zones: &Zones, roster: &Roster) -> Vec<String> {
    let reach = 4.0
        * roster
            .apples()
            .iter()
            .map(|a| a.radius_m)
            .fold(0.0, f64::max);
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
    // The surface an apple touches at `t` (the earliest of those open then), with its start.
    let touching = |apple: u32, t: f64| -> Option<(f64, &str)> {
        surfaces
            .get(&apple)?
            .iter()
            .filter(|(t0, t1, _)| *t0 <= t && t <= *t1)
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .map(|&(t0, _, s)| (t0, s))
    };
    let on = |surface: &str| {
        let r = region(surface);
        if zones.is_bin(r) {
            in_bin(r)
        } else {
            format!("apples on {}", surface_point(surface))
        }
    };
    events
        .iter()
        .map(|e| match e.b_party {
            Party::Surface(_) => surface_point(&e.b).to_string(),
            Party::Apple(j) => {
                let t = e.impact.map_or(e.t_start_s, |i| i.t_peak_s);
                let p = crate::math::vec3(e.contact_point_m);
                let at = zones.locate(p, t, reach);
                if let Location::InBin(b) = at {
                    return in_bin(b);
                }
                let touched = match (touching(e.a_index, t), touching(j, t)) {
                    (Some(x), Some(y)) => Some(if x.0 <= y.0 { x } else { y }),
                    (x, y) => x.or(y),
                };
                if let Some((_, s)) = touched {
                    return on(s);
                }
                match at {
                    Location::InBin(b) | Location::OverBin(b) => in_bin(b),
                    Location::Over(part) => on(part),
                    Location::Air => "apples in the air".to_string(),
                }
            }
        })
        .collect()
}

/// The audit of a run's fruit contacts (`bruise`: the damage assessment, whose rows carry each
/// apple's side of each contact with its transfer point and bruise).
pub fn audit(
    events: &[ContactEvent],
    points: &[String],
    roster: &Roster,
    bruise: &BruiseReport,
) -> Audit {
    let _ = events;
    let fruit = roster.apples().iter().filter(|a| !a.probe).count();
    #[derive(Default)]
    struct At<'a> {
        contacts: BTreeSet<usize>,
        impacts: BTreeSet<usize>,
        apples: BTreeSet<&'a str>,
        force: Vec<f64>,
        g: Vec<f64>,
        dv: Vec<f64>,
        absorbed: (f64, f64),
        /// Per apple: bruise volume arising here, and whether a hit here bruised (onset).
        volume: BTreeMap<&'a str, (f64, bool)>,
        downgraded: usize,
    }
    let mut at: BTreeMap<&str, At> = BTreeMap::new();
    for c in &bruise.contacts {
        let p = points.get(c.contact).map_or("", String::as_str);
        let x = at.entry(p).or_default();
        x.contacts.insert(c.contact);
        if c.site.is_none() {
            continue;
        }
        x.impacts.insert(c.contact);
        x.apples.insert(&c.apple);
        x.force.push(c.peak_force_n);
        x.g.push(c.peak_g);
        x.dv.push(c.velocity_change_m_s);
        x.absorbed.0 += c.absorbed_energy_j;
        x.absorbed.1 = x.absorbed.1.max(c.absorbed_energy_j);
        let v = x.volume.entry(&c.apple).or_insert((0.0, false));
        v.0 += c.volume_mm3.unwrap_or(f64::NAN);
        v.1 |= c.bruised;
    }
    for a in bruise
        .apples
        .iter()
        .filter_map(|a| a.downgraded_by.as_ref())
    {
        if let Some(x) = at.get_mut(a.transfer_point.as_str()) {
            x.downgraded += 1;
        }
    }
    let n = fruit.max(1) as f64;
    let mut out: Vec<TransferPoint> = at
        .into_iter()
        .map(|(p, x)| {
            let volumes: Vec<f64> = x.volume.values().map(|v| v.0).collect();
            let sizes = volumes.iter().all(|v| !v.is_nan());
            let q = if sizes && !volumes.is_empty() {
                let q = quantiles(volumes.clone());
                [q[0], q[1], volumes.iter().fold(0.0, |s, v| s + v)]
            } else {
                [f64::NAN; 3]
            };
            TransferPoint {
                point: p.to_string(),
                contacts: x.contacts.len(),
                impacts: x.impacts.len(),
                apples_hit_share: x.apples.len() as f64 / n,
                peak_force_n: quantiles(x.force),
                peak_g: quantiles(x.g),
                velocity_change_m_s: quantiles(x.dv),
                absorbed_energy_j: [x.absorbed.0, x.absorbed.1],
                apples_bruised: x
                    .volume
                    .values()
                    .filter(|v| if sizes { v.0 > 0.0 } else { v.1 })
                    .count(),
                bruise_volume_mm3: q,
                apples_downgraded: x.downgraded,
            }
        })
        .collect();
    // Most bruise volume first, then the hardest; points without impacts last, by name.
    out.sort_by(|a, b| {
        let key = |t: &TransferPoint| {
            let nan0 = |x: f64| if x.is_nan() { -1.0 } else { x };
            (
                t.apples_downgraded,
                nan0(t.bruise_volume_mm3[2]),
                nan0(t.peak_g[2]),
            )
        };
        let (ka, kb) = (key(a), key(b));
        kb.0.cmp(&ka.0)
            .then(kb.1.total_cmp(&ka.1))
            .then(kb.2.total_cmp(&ka.2))
            .then(a.point.cmp(&b.point))
    });
    Audit { points: out }
}

impl Audit {
    /// Headline figures per transfer point for a batch table: `POINT.impacts`,
    /// `POINT.max_peak_force_n`, `POINT.p95_peak_g`, `POINT.max_peak_g`,
    /// `POINT.max_velocity_change_m_s`, `POINT.apples_bruised`, `POINT.bruise_volume_mm3` (the
    /// total that arose there), `POINT.apples_downgraded` (first caused there); only finite
    /// values.
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
            m.push((format!("{p}.apples_bruised"), t.apples_bruised as f64));
            m.push((format!("{p}.bruise_volume_mm3"), t.bruise_volume_mm3[2]));
            m.push((format!("{p}.apples_downgraded"), t.apples_downgraded as f64));
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
            "One row per transfer point, where the fruit is damaged most first. Downgraded: apples whose grade first fell below the standard's best class through a hit there. Bruise volume: what arose there, per apple hit there (median / 95th percentile) and in all. Peak g is the peak contact force over the apple's weight (g = 9.80665 m/s^2); the velocity change is the apple's over the impact pulse; median / 95th percentile / largest over the apples hit. Absorbed: the energy the apples themselves took (their share of each contact's loss), in all and the most in one hit.\n\n| transfer point | apples downgraded | apples bruised | bruise volume (mm^3): median / p95 / total | contacts | impacts | apples hit | peak force (N) | peak g | velocity change (m/s) | absorbed by the apples (J): all / largest |\n|---|---|---|---|---|---|---|---|---|---|---|\n"
        );
        for t in &self.points {
            let q =
                |v: [f64; 3], d: usize| format!("{} / {} / {}", f(v[0], d), f(v[1], d), f(v[2], d));
            s += &format!(
                "| {} | {} | {} | {} | {} | {} | {:.0} % | {} | {} | {} | {} / {} |\n",
                t.point,
                t.apples_downgraded,
                t.apples_bruised,
                q(t.bruise_volume_mm3, 0),
                t.contacts,
                t.impacts,
                100.0 * t.apples_hit_share,
                q(t.peak_force_n, 1),
                q(t.peak_g, 1),
                q(t.velocity_change_m_s, 2),
                f(t.absorbed_energy_j[0], 4),
                f(t.absorbed_energy_j[1], 4),
            );
        }
        s
    }
}

/// The IRD-style chart of a run: one point per apple per impact, peak acceleration (g) against
/// velocity change (m/s), one colour per transfer point (`points`: [`points_of`] the run's
/// contacts), as a packhouse reads an instrumented sphere's run. For a material with the
/// peak-force damage model the bruise boundary drawn is its threshold F as an acceleration,
/// F / (m g), for the lightest and the heaviest apple of that material that was hit (one line
/// when they weigh the same): a hit above the line of its apple's mass bruises. The energy and
/// pressure-area models depend on the impact's other figures and have no line on these axes
/// (`apple_contacts.csv` has each hit's verdict). `None` when the run had no impact.
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
            if let Some(&f) = bruise.force_thresholds.get(&a.material) {
                let b = bounds
                    .entry(a.material.as_str())
                    .or_insert((f, f64::INFINITY, 0.0));
                b.1 = b.1.min(a.mass_kg);
                b.2 = b.2.max(a.mass_kg);
            }
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
