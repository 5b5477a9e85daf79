//! Where each apple ended: in a bin, on a surface, out of the scene, or still moving; when
//! apples entered each bin (throughput per exit); and what the sources fed in.
//!
//! A line designer's first question about a run is whether every apple arrived where it should,
//! and how fast: an apple that fell off a belt must not pass in silence (one that went back off
//! a chute once fell to z = -146 m without a word). The driver lets the [`Tracker`] look at the
//! apples at every output sample; apples that left the scene are taken out of the run then
//! ([`crate::world::World::take_out`]).
//!
//! Leaving the scene: an apple leaves when its centre is more than its radius below the lowest
//! point of every surface while it moves down (with gravity: nothing is left that it could land
//! on, so it falls for ever), or when its centre leaves `model.scene_bounds`. Both are seen at
//! the output samples, so the time of leaving is the first sample after it.

use super::AppleFinal;
use crate::layer::{AppleId, SurfaceId};
use crate::math::{arr3, vec3, Vec3};
use crate::record::events::{ContactEvent, Party};
use crate::record::series::AppleState;
use crate::scenario::{BoundsSpec, Scenario};
use crate::world::{Origin, SourceFeed, World};
use serde::Serialize;
use std::collections::{BTreeMap, VecDeque};

/// Most apples listed one per line in the warnings when apples leave the scene; the rest are
/// counted on one line (every one is in `summary.json`'s `apples[].fate`).
pub const MAX_LEFT_WARNINGS: usize = 20;

/// A surface counts as touched at the end when the apple is within this share of its radius of
/// it (resting contacts overlap by the sag, ~0.3 % of R; rapier's own contacts of a `rigid`
/// surface keep a small gap).
const TOUCH_MARGIN_RATIO: f64 = 0.01;

/// Where an apple ended (`summary.json` `apples[].fate`, tagged by `kind`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Fate {
    /// At rest inside a bin (its centre inside the bin's inner box, below the walls' top).
    InBin {
        /// The bin's name.
        bin: String,
        /// When its centre entered the bin (s; interpolated between output samples as it
        /// crossed the walls' top); `None` for an apple that was in the bin from the start.
        entered_s: Option<f64>,
    },
    /// At rest on a surface outside every bin: touching it, or lying on apples that do.
    OnSurface {
        /// The surface (a bin's wall is `BIN/x_min`, ...).
        surface: String,
    },
    /// At rest touching nothing (a scene without gravity).
    Floating {},
    /// Left the scene: fell below every surface, or left `model.scene_bounds`. It was taken out
    /// of the run then: its later rows in `bodies.csv` keep that place, at rest.
    LeftScene {
        /// Why: `below_every_surface` or `outside_scene_bounds`.
        reason: LeaveReason,
        /// When (s): the first output sample at which it had left.
        time_s: f64,
        /// Where its centre was then (m).
        position_m: [f64; 3],
        /// Its velocity then (m/s).
        velocity_m_s: [f64; 3],
        /// Its last contact with a surface: where it went off the line.
        last_surface: Option<LastContact>,
    },
    /// Still moving at the end: its centre, or its rolling spin times its radius, faster than
    /// `model.sleep.speed_m_s` (default by accuracy), the speed under which apples may fall
    /// asleep (a spin about the scene's up axis alone does not count, [`Tracker::finish`]).
    Moving {
        /// Centre speed at the end (m/s).
        speed_m_s: f64,
        /// The bin it is inside, if any.
        in_bin: Option<String>,
        /// The surface it touches (directly), if any: a belt it rides, a chute it rolls down.
        on: Option<String>,
    },
}

impl Fate {
    /// The `kind` tag.
    pub fn kind(&self) -> &'static str {
        match self {
            Fate::InBin { .. } => "in_bin",
            Fate::OnSurface { .. } => "on_surface",
            Fate::Floating {} => "floating",
            Fate::LeftScene { .. } => "left_scene",
            Fate::Moving { .. } => "moving",
        }
    }
}

/// Why an apple left the scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LeaveReason {
    /// More than its radius below the lowest point of every surface, moving down.
    BelowEverySurface,
    /// Its centre left `model.scene_bounds`.
    OutsideSceneBounds,
}

/// An apple's last contact with a surface before it left the scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LastContact {
    /// The surface.
    pub surface: String,
    /// When that contact ended (s): the apple went off the line there and then.
    pub t_end_s: Option<f64>,
}

/// Apples per fate, for the whole run (`summary.json` `fates`).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct FateCounts {
    /// At rest in a bin.
    pub in_bin: usize,
    /// At rest on a surface outside the bins.
    pub on_surface: usize,
    /// At rest touching nothing.
    pub floating: usize,
    /// Left the scene.
    pub left_scene: usize,
    /// Still moving at the end.
    pub moving: usize,
    /// Apples of the sources never fed in (their time had not come, or their spot was still
    /// taken), per source in `sources`.
    pub never_fed: usize,
    /// Apples at rest (in a bin or on a surface) that still spin about the scene's up axis faster
    /// than the rest speed at their rim: nothing stops that spin without twisting resistance
    /// (`twisting: none`, the paper's model); warned.
    pub spinning_at_rest: usize,
    /// The fastest such spin (rad/s; 0 when none).
    pub fastest_spin_at_rest_rad_s: f64,
}

/// One apple's entry into a bin.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Entry {
    /// The apple.
    pub apple: String,
    /// When its centre entered the bin (s).
    pub time_s: f64,
}

/// The apples that arrived in one bin (`summary.json` `throughput[]`): those inside it at the
/// end that entered during the run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BinThroughput {
    /// The bin's name.
    pub bin: String,
    /// Apples that entered during the run and are inside at the end.
    pub apples: usize,
    /// Apples inside at the end that were there from the start (not counted in the rate).
    pub from_start: usize,
    /// First entry (s).
    pub first_entry_s: Option<f64>,
    /// Last entry (s).
    pub last_entry_s: Option<f64>,
    /// Arrival rate (apples per second): (apples - 1) / (last - first), the mean rate between
    /// the first and the last arrival (needs two arrivals at different times).
    pub apples_per_s: Option<f64>,
    /// Every entry, in order of time.
    pub entries: Vec<Entry>,
}

/// How the run ended for the line: fates, throughput per bin, and the sources' feed (flattened
/// into `summary.json`).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct LineEnd {
    /// Apples per fate.
    pub fates: FateCounts,
    /// Per bin, the apples that arrived in it.
    pub throughput: Vec<BinThroughput>,
    /// Per source, what it fed and what held it up.
    pub sources: Vec<SourceFeed>,
    /// Per free-turning roller, its rate and the angle it turned at the end (absent without
    /// free rollers).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub free_rollers: Vec<crate::world::free_roller::FreeRollerState>,
}

impl LineEnd {
    /// Its headline figures (columns of a batch's `merged.csv`): `apples_in_bins`,
    /// `apples_on_surfaces`, `apples_left_scene`, `apples_moving_at_end`, `apples_never_fed`,
    /// `apples_waited`, `source_wait_s`; with bins `bin_apples` and `bin_apples_per_s` (into
    /// every bin together), and per bin `bin_apples.NAME`, `bin_apples_per_s.NAME` when there
    /// are several.
    pub fn metrics(&self) -> Vec<(String, f64)> {
        let f = &self.fates;
        let mut m = vec![
            ("apples_in_bins".to_string(), f.in_bin as f64),
            ("apples_on_surfaces".to_string(), f.on_surface as f64),
            ("apples_left_scene".to_string(), f.left_scene as f64),
            ("apples_moving_at_end".to_string(), f.moving as f64),
        ];
        if !self.sources.is_empty() {
            m.push(("apples_never_fed".into(), f.never_fed as f64));
            m.push((
                "apples_waited".into(),
                self.sources.iter().map(|s| s.waited as f64).sum(),
            ));
            m.push((
                "source_wait_s".into(),
                self.sources.iter().map(|s| s.wait_total_s).sum(),
            ));
        }
        if !self.throughput.is_empty() {
            let mut all: Vec<f64> = self
                .throughput
                .iter()
                .flat_map(|b| b.entries.iter().map(|e| e.time_s))
                .collect();
            all.sort_by(f64::total_cmp);
            m.push(("bin_apples".into(), all.len() as f64));
            if let Some(r) = rate(&all) {
                m.push(("bin_apples_per_s".into(), r));
            }
            if self.throughput.len() > 1 {
                for b in &self.throughput {
                    m.push((format!("bin_apples.{}", b.bin), b.apples as f64));
                    if let Some(r) = b.apples_per_s {
                        m.push((format!("bin_apples_per_s.{}", b.bin), r));
                    }
                }
            }
        }
        m.retain(|(_, v)| v.is_finite());
        m
    }
}

/// The mean arrival rate of sorted entry times: (n - 1) / (last - first).
fn rate(times: &[f64]) -> Option<f64> {
    let (first, last) = (times.first()?, times.last()?);
    (times.len() >= 2 && last > first).then(|| (times.len() - 1) as f64 / (last - first))
}

/// An apple that left the scene.
#[derive(Debug, Clone, PartialEq)]
struct Left {
    reason: LeaveReason,
    time_s: f64,
    position: Vec3,
    velocity: Vec3,
}

/// What the tracker knows of one apple.
#[derive(Debug, Clone, Default, PartialEq)]
struct Track {
    /// The last sample seen: (time, centre).
    prev: Option<(f64, Vec3)>,
    /// The bin its centre is inside now.
    inside: Option<usize>,
    /// Its last entry into a bin: (bin, time; `None` when it was inside from the start).
    entry: Option<(usize, Option<f64>)>,
    left: Option<Left>,
}

/// Watches the apples at the output samples: bin entries and apples leaving the scene.
pub struct Tracker {
    /// Against gravity (unit), without gravity `None`: nothing falls.
    up: Option<Vec3>,
    bounds: Option<BoundsSpec>,
    /// At rest: |v| and |w| R at most this (m/s).
    rest_speed_m_s: f64,
    apples: Vec<Track>,
}

impl Tracker {
    /// A tracker for the scenario's scene.
    pub fn new(sc: &Scenario) -> Self {
        let g = vec3(sc.gravity_m_s2);
        Self {
            up: (g.length() > 0.0).then(|| -g / g.length()),
            bounds: sc.model.scene_bounds.clone(),
            rest_speed_m_s: sc.model.sleep.rule(sc.accuracy).speed_m_s,
            apples: Vec::new(),
        }
    }

    /// Looks at the apples at time `t` (`states` in layer order): records bin entries, and
    /// returns the apples that left the scene now (the caller takes them out of the run).
    pub fn observe(&mut self, t: f64, states: &[AppleState], world: &World) -> Vec<usize> {
        self.apples.resize_with(states.len(), Track::default);
        let floor = self.up.and_then(|up| world.lowest_surface_height(up));
        let mut gone = Vec::new();
        for (k, s) in states.iter().enumerate() {
            let track = &mut self.apples[k];
            if track.left.is_some() {
                continue;
            }
            let seen = track.prev.is_some();
            // A sleeper has not moved since it was last seen.
            if seen && world.layer.is_asleep(AppleId(k as u32)) {
                continue;
            }
            let p = s.position;
            let r = s.diameter_m / 2.0;
            let outside = self.bounds.as_ref().is_some_and(|b| !b.contains(arr3(p)));
            let below = match (self.up, floor) {
                (Some(up), Some(h)) => p.dot(up) < h - r && s.velocity.dot(up) <= 0.0,
                _ => false,
            };
            if outside || below {
                track.left = Some(Left {
                    reason: if outside {
                        LeaveReason::OutsideSceneBounds
                    } else {
                        LeaveReason::BelowEverySurface
                    },
                    time_s: t,
                    position: p,
                    velocity: s.velocity,
                });
                gone.push(k);
                continue;
            }
            let bin = world.bins.iter().position(|b| b.contains(p, t));
            if let Some(b) = bin.filter(|&b| Some(b) != track.inside) {
                let when = match track.prev {
                    // Present from the start: not an arrival.
                    None if !matches!(world.roster.apples()[k].origin, Origin::Fed { .. }) => None,
                    // Fed in inside the bin: it arrived when it was fed (the step it appeared
                    // at, not the sample that first saw it: the output's sampling does not move it).
                    None => Some(world.fed_entry(k).map_or(t, |f| f.time_s)),
                    // Crossed the walls' top between the last sample and this one (the walls
                    // where the bin was at each sample: a lowered bin's rim moves down).
                    Some((t0, p0)) => {
                        let bx = &world.bins[b];
                        let h = bx.inner_size_m[2];
                        let (z0, z1) = (bx.local(p0, t0).z, bx.local(p, t).z);
                        Some(if z0 > h && z1 <= h {
                            t0 + (z0 - h) / (z0 - z1) * (t - t0)
                        } else {
                            t
                        })
                    }
                };
                track.entry = Some((b, when));
            }
            track.inside = bin;
            track.prev = Some((t, p));
        }
        gone
    }

    /// The fates of the apples at the end (`t_end`, `states` at the final poses), their bin
    /// entries, and the line's summary with the sources' `feeds`. `events` are the run's
    /// contacts, sorted by start (open ones at the end have no `t_end_s`).
    ///
    /// An apple is at rest when its centre is still and it does not roll: its speed and the
    /// rolling part of its spin (about axes across the scene's up) times its radius are below
    /// the sleep speed. A spin about the up axis alone, about the normal of the floor it lies on,
    /// moves nothing: the paper's model (`twisting: none`) has nothing to stop it, and a fruit
    /// lying still on a bin floor while it turns there is at rest.
    pub fn finish(
        mut self,
        t_end: f64,
        states: &[AppleState],
        world: &World,
        events: &[ContactEvent],
        feeds: Vec<SourceFeed>,
    ) -> (Vec<Fate>, LineEnd) {
        self.apples.resize_with(states.len(), Track::default);
        let n = states.len();
        // Apple-apple contacts open at the end: who rests on whom.
        let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); n];
        // Each apple's last contact with a surface: where it went off the line.
        let mut last: Vec<Option<&ContactEvent>> = vec![None; n];
        for e in events {
            let a = e.a_index as usize;
            match e.b_party {
                Party::Apple(j) => {
                    if e.t_end_s.is_none() && a < n && (j as usize) < n {
                        neighbours[a].push(j as usize);
                        neighbours[j as usize].push(a);
                    }
                }
                Party::Surface(_) if a < n => {
                    let end = |x: &ContactEvent| x.t_end_s.unwrap_or(f64::INFINITY);
                    if last[a].is_none_or(|x| end(e) >= end(x)) {
                        last[a] = Some(e);
                    }
                }
                Party::Surface(_) => {}
            }
        }
        let touched: Vec<Option<String>> = states.iter().map(|s| touching(world, s)).collect();
        let mut fates = Vec::with_capacity(n);
        let mut counts = FateCounts::default();
        let mut arrivals: Vec<Vec<Entry>> = vec![Vec::new(); world.bins.len()];
        let mut from_start = vec![0usize; world.bins.len()];
        for (k, s) in states.iter().enumerate() {
            let track = &self.apples[k];
            if let Some(l) = &track.left {
                counts.left_scene += 1;
                fates.push(Fate::LeftScene {
                    reason: l.reason,
                    time_s: l.time_s,
                    position_m: arr3(l.position),
                    velocity_m_s: arr3(l.velocity),
                    last_surface: last[k].map(|e| LastContact {
                        surface: e.b.to_string(),
                        t_end_s: e.t_end_s,
                    }),
                });
                continue;
            }
            let r = s.diameter_m / 2.0;
            let w = s.angular_velocity;
            let rolling = match self.up {
                Some(up) => w - up * w.dot(up),
                None => w,
            };
            let still = world.layer.is_asleep(AppleId(k as u32))
                || (s.velocity.length() <= self.rest_speed_m_s
                    && rolling.length() * r <= self.rest_speed_m_s);
            let bin = world
                .bins
                .iter()
                .position(|b| b.contains(s.position, t_end));
            let entered = match (bin, track.entry) {
                (Some(b), Some((e, when))) if e == b => when,
                _ => None,
            };
            if let Some(b) = bin {
                match entered {
                    Some(t) => arrivals[b].push(Entry {
                        apple: s.name.to_string(),
                        time_s: t,
                    }),
                    None => from_start[b] += 1,
                }
            }
            // At rest, spinning about the vertical: counted and warned (nothing else stops it).
            if still && !world.layer.is_asleep(AppleId(k as u32)) {
                if let Some(up) = self.up {
                    let spin = w.dot(up).abs();
                    if spin * r > self.rest_speed_m_s {
                        counts.spinning_at_rest += 1;
                        counts.fastest_spin_at_rest_rad_s =
                            counts.fastest_spin_at_rest_rad_s.max(spin);
                    }
                }
            }
            let fate = match (still, bin) {
                (true, Some(b)) => Fate::InBin {
                    bin: world.bins[b].name.clone(),
                    entered_s: entered,
                },
                (true, None) => match resting_on(k, &touched, &neighbours) {
                    Some(surface) => Fate::OnSurface { surface },
                    None => Fate::Floating {},
                },
                (false, _) => Fate::Moving {
                    speed_m_s: s.velocity.length(),
                    in_bin: bin.map(|b| world.bins[b].name.clone()),
                    on: touched[k].clone(),
                },
            };
            match &fate {
                Fate::InBin { .. } => counts.in_bin += 1,
                Fate::OnSurface { .. } => counts.on_surface += 1,
                Fate::Floating {} => counts.floating += 1,
                Fate::Moving { .. } => counts.moving += 1,
                Fate::LeftScene { .. } => counts.left_scene += 1,
            }
            fates.push(fate);
        }
        counts.never_fed = feeds.iter().map(|f| f.not_due + f.still_waiting).sum();
        let throughput = world
            .bins
            .iter()
            .zip(arrivals)
            .zip(from_start)
            .map(|((b, mut entries), from_start)| {
                entries.sort_by(|x, y| x.time_s.total_cmp(&y.time_s));
                let times: Vec<f64> = entries.iter().map(|e| e.time_s).collect();
                BinThroughput {
                    bin: b.name.clone(),
                    apples: entries.len(),
                    from_start,
                    first_entry_s: times.first().copied(),
                    last_entry_s: times.last().copied(),
                    apples_per_s: rate(&times),
                    entries,
                }
            })
            .collect();
        (
            fates,
            LineEnd {
                fates: counts,
                throughput,
                sources: feeds,
                free_rollers: Vec::new(),
            },
        )
    }
}

/// The surface an apple touches at the end (the deepest, if several), from the geometry: it
/// holds for every fidelity, rapier's own contacts of `rigid` surfaces included.
fn touching(world: &World, s: &AppleState) -> Option<String> {
    let r = s.diameter_m / 2.0;
    let mut hits = Vec::new();
    let mut best: Option<(f64, usize)> = None;
    for (k, &ch) in world.surface_colliders.iter().enumerate() {
        let Some(co) = world.physics.colliders.get(ch) else {
            continue;
        };
        hits.clear();
        let shape = world.layer.surface_shape(SurfaceId(k as u32));
        crate::layer::surface::surface_hits(
            shape,
            co,
            s.position,
            r,
            TOUCH_MARGIN_RATIO * r,
            &mut hits,
        );
        for h in &hits {
            if best.is_none_or(|b| h.overlap_m > b.0) {
                best = Some((h.overlap_m, k));
            }
        }
    }
    best.map(|(_, k)| world.layer.surface_name(SurfaceId(k as u32)).to_string())
}

/// The surface an apple at rest lies on: the one it touches, or the one under the apples it
/// rests on (the nearest through the open apple-apple contacts).
fn resting_on(k: usize, touched: &[Option<String>], neighbours: &[Vec<usize>]) -> Option<String> {
    let mut seen = vec![false; touched.len()];
    let mut queue = VecDeque::from([k]);
    seen[k] = true;
    while let Some(i) = queue.pop_front() {
        if let Some(s) = &touched[i] {
            return Some(s.clone());
        }
        for &j in &neighbours[i] {
            if !seen[j] {
                seen[j] = true;
                queue.push_back(j);
            }
        }
    }
    None
}

/// The warning lines of a run's end: apples that left the scene (one line each, the first
/// [`MAX_LEFT_WARNINGS`]), and per source the apples that waited and those never fed in.
pub fn warnings(apples: &[AppleFinal], line: &LineEnd, end_s: f64) -> Vec<String> {
    let mut out = Vec::new();
    let f = &line.fates;
    if f.spinning_at_rest > 0 {
        out.push(format!(
            "{} apple(s) lie still but keep spinning about the vertical (up to {} rad/s): without twisting resistance (`\"twisting\": \"none\"`, the paper's and LIGGGHTS's default) nothing stops that spin, while real fruit stops within a second; `\"contact\": {{\"twisting\": \"coulomb\"}}` adds the contact patch's friction (docs/physics.md section 11.8). They count as at rest (their centres are still)",
            f.spinning_at_rest,
            human(f.fastest_spin_at_rest_rad_s, 3, 1)
        ));
    }
    let left: Vec<&AppleFinal> = apples
        .iter()
        .filter(|a| matches!(a.fate, Fate::LeftScene { .. }))
        .collect();
    for a in left.iter().take(MAX_LEFT_WARNINGS) {
        let Fate::LeftScene {
            reason,
            time_s,
            position_m,
            last_surface,
            ..
        } = &a.fate
        else {
            continue;
        };
        let why = match reason {
            LeaveReason::BelowEverySurface => "fell below every surface",
            LeaveReason::OutsideSceneBounds => "left model.scene_bounds",
        };
        let last = match last_surface {
            Some(c) => match c.t_end_s {
                Some(t) => format!(
                    " (it last touched '{}', until t = {} s)",
                    c.surface,
                    secs(t),
                ),
                None => format!(" (it was touching '{}')", c.surface),
            },
            None => " (it had touched no surface)".to_string(),
        };
        out.push(format!(
            "apple '{}' left the scene at t = {} s at {}: it {why}{last}",
            a.name,
            secs(*time_s),
            place(*position_m)
        ));
    }
    if left.len() > MAX_LEFT_WARNINGS {
        out.push(format!(
            "... and {} more apples left the scene (summary.json apples[].fate)",
            left.len() - MAX_LEFT_WARNINGS
        ));
    }
    for s in &line.sources {
        if s.waited > 0 {
            let by: Vec<String> = s
                .blocked_by
                .iter()
                .take(3)
                .map(|b| {
                    if s.blocked_by.len() == 1 {
                        b.what.clone()
                    } else {
                        format!("{} ({} held up)", b.what, b.apples)
                    }
                })
                .collect();
            let more = match s.blocked_by.len() {
                0..=3 => String::new(),
                4 => " and 1 other".to_string(),
                m => format!(" and {} others", m - 3),
            };
            out.push(format!(
                "source '{}': {} apple{} waited, {} s in all, longest {} s, for {}{more} to clear the spot (the source feeds faster than the line takes its apples away){}",
                s.name,
                s.waited,
                if s.waited == 1 { "" } else { "s" },
                secs(s.wait_total_s),
                secs(s.wait_longest_s),
                by.join(", "),
                if s.still_waiting > 0 {
                    format!("; {} still waiting at the end, never fed in", s.still_waiting)
                } else {
                    String::new()
                }
            ));
        }
        if s.not_due > 0 {
            out.push(format!(
                "source '{}': {} of its {} apples were never fed in: their time had not come when the run ended at t = {} s",
                s.name,
                s.not_due,
                s.count,
                secs(end_s)
            ));
        }
    }
    out
}

/// Per source name, its apples never fed in (for the CLI and tests).
pub fn never_fed(line: &LineEnd) -> BTreeMap<&str, usize> {
    line.sources
        .iter()
        .map(|s| (s.name.as_str(), s.not_due + s.still_waiting))
        .collect()
}

pub use crate::math::{human, secs};

/// A position as `[x, y, z] m` to the millimetre.
fn place(p: [f64; 3]) -> String {
    format!(
        "[{}, {}, {}] m",
        human(p[0], 3, 3),
        human(p[1], 3, 3),
        human(p[2], 3, 3)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_as_a_person_writes_them() {
        assert_eq!(secs(0.030000000000000002), "0.03");
        assert_eq!(secs(2.41237), "2.412");
        assert_eq!(secs(10.0), "10");
        assert_eq!(secs(0.00005), "0.00005");
        // Rounded from the binary value: -146.2345 is -146.23449999..., written -146.234.
        assert_eq!(human(-146.2346, 3, 3), "-146.235");
        assert_eq!(human(-146.2345, 3, 3), "-146.234");
        assert_eq!(human(-0.0001, 3, 3), "-0.0001");
        assert_eq!(human(-0.00001, 1, 3), "-0.00001");
    }

    #[test]
    fn arrival_rate() {
        assert_eq!(rate(&[1.0, 1.25, 1.5, 1.75]), Some(4.0));
        assert_eq!(rate(&[1.0]), None);
        assert_eq!(rate(&[]), None);
    }
}
