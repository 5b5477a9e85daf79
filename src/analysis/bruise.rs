//! The fruit's damage in a run: every hit of every apple through its material's damage model,
//! the hits placed on the apple's own surface and combined per site, each apple graded by the
//! scenario's standard (docs/damage.md). The models themselves are pure ([`super::damage`]);
//! this module only gathers each apple's hits from the contact events.
//!
//! A contact is an impact (from touch until the pulse is over) and possibly a resting time after
//! it (`record::events`). Each impact is a hit for each apple in it: the energy the apple
//! absorbed (its share of the impact's loss, `contact::share`), the peak force, the peak centre
//! pressure 1.5 P / (pi a^2), the contact radius, the apple's own deformation and where on the
//! apple it landed. Each is also reported as an instrumented sphere reports it: peak acceleration
//! in g and velocity change over the pulse (`analysis::impacts`). A contact that starts at rest
//! has no impact and bruises nothing; its resting load is flagged against the optional static
//! thresholds (`damage.static_force_n`, `damage.static_pressure_pa`).
//!
//! Virtual instrumented spheres (`apples[].probe`) are not fruit: they get no assessment, and a
//! contact with one is the instrument's, left out of the fruit's figures (the line is judged as it
//! runs without the instrument; the probe has its own table, `probe_NAME_impacts.csv`).

use super::damage::grade::{self, BruiseSize};
use super::damage::sites::{self, PlacedHit};
use super::damage::{model, DamageParams, Hit};
use crate::record::events::{ContactEvent, ImpactPulse, Party};
use crate::scenario::damage::{standard, GradeClass, DEFAULT_STANDARD};
use crate::scenario::Scenario;
use crate::world::RosterApple;
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::Arc;

/// One contact as seen by one apple (a row of `apple_contacts.csv`; a contact between two
/// apples gives two).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactAssessment {
    /// Index of the contact in `contacts.csv` / `RunResult::events`.
    pub contact: usize,
    /// The apple assessed.
    pub apple: Arc<str>,
    /// What it touched (a surface or another apple).
    pub other: Arc<str>,
    /// Where in the line (the audit's transfer point).
    pub transfer_point: String,
    /// First touch (s).
    pub t_start_s: f64,
    /// Time of the peak force (s).
    pub t_peak_s: f64,
    /// Contact point at the peak force (m, world).
    pub contact_point_m: [f64; 3],
    /// Peak normal force of the impact (N; 0 for a contact that starts at rest).
    pub peak_force_n: f64,
    /// Peak centre pressure of the impact, 1.5 P / (pi a^2) (Pa).
    pub peak_pressure_pa: f64,
    /// Energy this apple absorbed in the impact (J): its share of the impact's loss.
    pub absorbed_energy_j: f64,
    /// The impact's whole loss (J; both bodies).
    pub contact_absorbed_energy_j: f64,
    /// Velocity change of this apple over the impact pulse (m/s; 0 without an impact).
    pub velocity_change_m_s: f64,
    /// Peak acceleration of this apple in the impact, force / (m g) (g; 0 without an impact).
    pub peak_g: f64,
    /// Normal approach speed at first touch (m/s).
    pub approach_speed_m_s: f64,
    /// Whether this hit alone bruises by the apple's model.
    pub bruised: bool,
    /// The bruise site the hit landed in (index into the apple's sites), if an impact.
    pub site: Option<usize>,
    /// This hit's part of its site's bruise volume (mm^3; `None` for an onset model).
    pub volume_mm3: Option<f64>,
    /// Largest force of the resting time after the impact, if any (N).
    pub static_max_force_n: Option<f64>,
    /// Largest mean pressure of the resting time, if any (Pa).
    pub static_max_pressure_pa: Option<f64>,
    /// The static thresholds exceeded (`static-force`, `static-pressure`, joined by `+`).
    pub exceeded: String,
    /// Why the hit lies outside the model's validity, if it does.
    pub outside_validity: Option<&'static str>,
}

/// One bruise site of an apple (a row of `bruises.csv`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BruiseSite {
    /// The apple.
    pub apple: Arc<str>,
    /// The site's index on the apple.
    pub site: usize,
    /// Where on the apple: unit vector from its centre, in its own frame.
    pub direction: [f64; 3],
    /// First and last hit (s).
    pub first_hit_s: f64,
    /// Last hit (s).
    pub last_hit_s: f64,
    /// Hits at the site.
    pub hits: usize,
    /// The transfer points of its hits (each once, in order of first hit).
    pub transfer_points: Vec<String>,
    /// Energy the apple absorbed there (J).
    pub absorbed_energy_j: f64,
    /// Whether it is a bruise.
    pub bruised: bool,
    /// Bruise volume (mm^3; `None` for an onset model).
    pub volume_mm3: Option<f64>,
    /// Surface area (mm^2).
    pub area_mm2: Option<f64>,
    /// Depth (mm).
    pub depth_mm: Option<f64>,
    /// Surface diameter (mm).
    pub diameter_mm: Option<f64>,
}

impl BruiseSite {
    fn size(&self) -> BruiseSize {
        BruiseSize {
            volume_mm3: self.volume_mm3,
            diameter_mm: self.diameter_mm,
            depth_mm: self.depth_mm,
            area_mm2: self.area_mm2,
        }
    }
}

/// The hit behind a grade or a first bruise.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cause {
    /// Where in the line.
    pub transfer_point: String,
    /// What the apple hit.
    pub with: Arc<str>,
    /// When (time of the peak force, s).
    pub t_s: f64,
    /// The contact (index in `contacts.csv`).
    pub contact: usize,
}

/// The largest bruise of an apple.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LargestBruise {
    /// Its site.
    pub site: usize,
    /// Volume (mm^3).
    pub volume_mm3: Option<f64>,
    /// Surface diameter (mm).
    pub diameter_mm: Option<f64>,
    /// Depth (mm).
    pub depth_mm: Option<f64>,
    /// Surface area (mm^2).
    pub area_mm2: Option<f64>,
}

/// One apple over the whole run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AppleAssessment {
    /// Apple name.
    pub apple: Arc<str>,
    /// Its material.
    pub material: String,
    /// Its damage model (`energy`, `pressure-area`, `peak-force`).
    pub model: &'static str,
    /// Contacts it had.
    pub contacts: usize,
    /// Impacts among them.
    pub impacts: usize,
    /// Largest peak force of its impacts (N).
    pub peak_force_n: f64,
    /// Largest peak acceleration in one impact (g).
    pub max_peak_g: f64,
    /// Largest velocity change in one impact (m/s).
    pub max_velocity_change_m_s: f64,
    /// Energy it absorbed in all its impacts (J): its own shares.
    pub absorbed_energy_j: f64,
    /// Its bruises (bruised sites).
    pub bruises: usize,
    /// Bruise volume, all bruises (mm^3; `None` for an onset model).
    pub bruise_volume_mm3: Option<f64>,
    /// Bruised surface area, all bruises (mm^2).
    pub bruised_area_mm2: Option<f64>,
    /// Its largest bruise, if any.
    pub largest_bruise: Option<LargestBruise>,
    /// Its grade by the standard.
    pub grade: String,
    /// The grade's rank (0 the best class).
    pub grade_rank: usize,
    /// Why not the best class (empty when it meets it).
    pub grade_why: String,
    /// Whether it is graded below the best class.
    pub downgraded: bool,
    /// The hit that first put it below the best class.
    pub downgraded_by: Option<Cause>,
    /// Its first bruising hit.
    pub first_bruise: Option<Cause>,
    /// Largest static force of a resting contact (N).
    pub max_static_force_n: f64,
    /// Whether a resting load exceeded a static threshold.
    pub static_overload: bool,
}

/// The damage of a run.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct BruiseReport {
    /// The grading standard's name (`user` for the scenario's own classes).
    pub standard: String,
    /// Its classes, best first, then the grade below them.
    pub grades: Vec<String>,
    /// One entry per fruit apple, layer order.
    pub apples: Vec<AppleAssessment>,
    /// One entry per fruit apple per contact, in contact order (`apple_contacts.csv`).
    pub contacts: Vec<ContactAssessment>,
    /// The bruise sites, apple by apple (`bruises.csv`).
    pub sites: Vec<BruiseSite>,
    /// Hits outside their model's validity, per material, in words (the run's warnings).
    pub warnings: Vec<String>,
    /// The force threshold of each apple material with the peak-force model (N).
    pub force_thresholds: BTreeMap<String, f64>,
}

impl BruiseReport {
    /// Apples with at least one bruise.
    pub fn apples_bruised(&self) -> usize {
        self.apples.iter().filter(|a| a.bruises > 0).count()
    }

    /// Apples graded below the best class.
    pub fn apples_downgraded(&self) -> usize {
        self.apples.iter().filter(|a| a.downgraded).count()
    }

    /// Bruise volume of all apples (mm^3; NaN when the models give no sizes).
    pub fn total_bruise_volume_mm3(&self) -> f64 {
        self.apples
            .iter()
            .filter_map(|a| a.bruise_volume_mm3)
            .fold(f64::NAN, |s, v| if s.is_nan() { v } else { s + v })
    }

    /// Whether apple `name` had its first bruise at or before `time_s` (the bruise flag of the
    /// ParaView frames).
    pub fn bruised_by(&self, name: &str, time_s: f64) -> bool {
        self.apples
            .iter()
            .any(|a| &*a.apple == name && a.first_bruise.as_ref().is_some_and(|c| c.t_s <= time_s))
    }
}

/// The grading standard of a scenario: its name, classes (best first) and the grade below.
pub fn grading(sc: &Scenario) -> (String, Vec<GradeClass>, String) {
    let g = sc.grading.clone().unwrap_or_default();
    match g.classes {
        Some(classes) => (
            "user".into(),
            classes,
            g.below.unwrap_or_else(|| "reject".into()),
        ),
        None => {
            let s = standard(g.standard.as_deref().unwrap_or(DEFAULT_STANDARD))
                .or_else(|| standard(DEFAULT_STANDARD))
                .expect("the default standard exists");
            (s.name.into(), s.classes, s.below.into())
        }
    }
}

/// The hit an apple takes in an impact, and where on it (the unit vector from its centre in its
/// own frame): apple `a` of the contact when `towards`, else the other body (an apple too). The
/// energy it absorbed is its share of the impact's loss (`contact::share`), the peak centre
/// pressure 1.5 times the largest mean pressure (Hertz: p0 = 3 P / (2 pi a^2)), its
/// deformation its share of the overlap at the peak. The one definition of a hit: a run's
/// assessment ([`assess`]) and `applesim calibrate-bruise` (`analysis::calibrate_bruise`) both
/// take it from here.
pub fn hit_of(pulse: &ImpactPulse, towards: bool) -> (Hit, [f64; 3]) {
    let (absorbed, indentation, direction) = if towards {
        (
            pulse.a_absorbed_energy_j,
            pulse.a_indentation_m,
            pulse.sites[0],
        )
    } else {
        (
            pulse.absorbed_energy_j - pulse.a_absorbed_energy_j,
            pulse.overlap_at_peak_m - pulse.a_indentation_m,
            pulse.sites[1],
        )
    };
    let hit = Hit {
        absorbed_energy_j: absorbed,
        peak_force_n: pulse.peak_force_n,
        peak_pressure_pa: 1.5 * pulse.max_pressure_pa,
        contact_radius_m: pulse.max_contact_radius_m,
        indentation_m: indentation,
        stored_share: if pulse.overlap_at_peak_m > 0.0 {
            indentation / pulse.overlap_at_peak_m
        } else {
            1.0
        },
    };
    (hit, direction)
}

/// One side of an impact, with what the assessment needs of it.
struct Side {
    event: usize,
    hit: Hit,
    direction: [f64; 3],
    t_s: f64,
    other: Arc<str>,
    row: usize,
}

/// Assesses every contact of a run of scenario `sc`. `roster` describes every apple by name;
/// `order` lists the apples of the run (layer order), which sets the order of
/// [`BruiseReport::apples`]; `points` is each event's transfer point
/// ([`super::audit::points_of`]).
pub fn assess(
    sc: &Scenario,
    events: &[ContactEvent],
    roster: &BTreeMap<&str, &RosterApple>,
    order: &[&str],
    points: &[String],
) -> BruiseReport {
    let mut params: BTreeMap<String, DamageParams> = BTreeMap::new();
    let mut params_of = |material: &str| -> DamageParams {
        params
            .entry(material.to_string())
            .or_insert_with(|| {
                DamageParams::of(sc.materials.get(material).and_then(|m| m.damage.as_ref()))
            })
            .clone()
    };
    let fruit = |name: &str| roster.get(name).is_some_and(|a| !a.probe);
    let (std_name, classes, below) = grading(sc);
    let mut grades: Vec<String> = classes.iter().map(|c| c.name.clone()).collect();
    grades.push(below.clone());

    // Each fruit apple's contacts and hits, in event order (events are in order of start).
    let mut index: BTreeMap<&str, usize> = BTreeMap::new();
    let mut names: Vec<&str> = Vec::new();
    for n in order.iter().copied().filter(|n| fruit(n)) {
        index.entry(n).or_insert_with(|| {
            names.push(n);
            names.len() - 1
        });
    }
    let mut rows: Vec<ContactAssessment> = Vec::new();
    let mut sides: Vec<Vec<Side>> = Vec::new();
    sides.resize_with(names.len(), Vec::new);
    // Each apple's rows.
    let mut rows_of: Vec<Vec<usize>> = vec![Vec::new(); names.len()];
    let mut outside: BTreeMap<String, (usize, BTreeMap<&str, ()>, &'static str)> = BTreeMap::new();
    for (k, e) in events.iter().enumerate() {
        let mut who = vec![(e.a.clone(), e.b.clone(), true)];
        if let Party::Apple(_) = e.b_party {
            who.push((e.b.clone(), e.a.clone(), false));
        }
        // A contact with an instrument is the instrument's.
        if who.iter().any(|(n, _, _)| !fruit(n)) {
            continue;
        }
        for (name, other, towards) in who {
            let i = *index
                .entry(roster[&*name].name.as_str())
                .or_insert_with(|| {
                    names.push(roster[&*name].name.as_str());
                    sides.push(Vec::new());
                    rows_of.push(Vec::new());
                    names.len() - 1
                });
            let apple = roster[&*name];
            let p = params_of(&apple.material);
            let mut row = ContactAssessment {
                contact: k,
                apple: name.clone(),
                other: other.clone(),
                transfer_point: points.get(k).cloned().unwrap_or_default(),
                t_start_s: e.t_start_s,
                t_peak_s: e.impact.map_or(e.t_peak_s, |i| i.t_peak_s),
                contact_point_m: e.contact_point_m,
                peak_force_n: 0.0,
                peak_pressure_pa: 0.0,
                absorbed_energy_j: 0.0,
                contact_absorbed_energy_j: 0.0,
                velocity_change_m_s: 0.0,
                peak_g: 0.0,
                approach_speed_m_s: e.approach_speed_m_s,
                bruised: false,
                site: None,
                volume_mm3: None,
                static_max_force_n: e.resting.map(|r| r.max_force_n),
                static_max_pressure_pa: e.resting.map(|r| r.max_pressure_pa),
                exceeded: String::new(),
                outside_validity: None,
            };
            if let Some(pulse) = &e.impact {
                let (hit, direction) = hit_of(pulse, towards);
                let absorbed = hit.absorbed_energy_j;
                let side = super::impacts::for_apple(pulse, apple.mass_kg, towards);
                let own = model::evaluate(&p, &hit);
                row.peak_force_n = pulse.peak_force_n;
                row.peak_pressure_pa = hit.peak_pressure_pa;
                row.absorbed_energy_j = absorbed;
                row.contact_absorbed_energy_j = pulse.absorbed_energy_j;
                row.velocity_change_m_s = side.velocity_change_m_s;
                row.peak_g = side.peak_g;
                row.bruised = own.bruised;
                row.outside_validity = model::outside_validity(&p, &hit);
                if let Some(why) = row.outside_validity {
                    let o =
                        outside
                            .entry(apple.material.clone())
                            .or_insert((0, BTreeMap::new(), why));
                    o.0 += 1;
                    o.1.insert(roster[&*name].name.as_str(), ());
                }
                sides[i].push(Side {
                    event: k,
                    hit,
                    direction,
                    t_s: pulse.t_peak_s,
                    other: other.clone(),
                    row: rows.len(),
                });
            }
            let mut over = Vec::new();
            if let Some(r) = &e.resting {
                if p.static_force_n.is_some_and(|f| r.max_force_n > f) {
                    over.push("static-force");
                }
                if p.static_pressure_pa.is_some_and(|s| r.max_pressure_pa > s) {
                    over.push("static-pressure");
                }
            }
            row.exceeded = over.join("+");
            rows_of[i].push(rows.len());
            rows.push(row);
        }
    }

    let mut apples = Vec::with_capacity(names.len());
    let mut all_sites = Vec::new();
    for (i, &name) in names.iter().enumerate() {
        let apple = roster[name];
        let p = params_of(&apple.material);
        let mut hits = std::mem::take(&mut sides[i]);
        hits.sort_by(|a, b| a.t_s.total_cmp(&b.t_s).then(a.event.cmp(&b.event)));
        let placed: Vec<PlacedHit> = hits
            .iter()
            .map(|s| PlacedHit {
                direction: s.direction,
                contact_radius_m: s.hit.contact_radius_m,
                damage: model::evaluate(&p, &s.hit),
                absorbed_energy_j: s.hit.absorbed_energy_j,
                full_width_mm: model::full_width_mm(&p, &s.hit),
                full_depth_mm: model::full_depth_mm(&p, &s.hit),
            })
            .collect();
        let found = sites::sites(&p, apple.radius_m, &placed);
        let name_arc: Arc<str> = name.into();
        let mut rows_of_apple: Vec<BruiseSite> = Vec::new();
        for (si, s) in found.iter().enumerate() {
            for (&h, &part) in s.hits.iter().zip(&s.parts_mm3) {
                let r = &mut rows[hits[h].row];
                r.site = Some(si);
                r.volume_mm3 = p.model.sizes().then_some(part);
            }
            let mut tp: Vec<String> = Vec::new();
            for &h in &s.hits {
                let t = &rows[hits[h].row].transfer_point;
                if !tp.contains(t) {
                    tp.push(t.clone());
                }
            }
            rows_of_apple.push(BruiseSite {
                apple: name_arc.clone(),
                site: si,
                direction: s.direction,
                first_hit_s: hits[s.hits[0]].t_s,
                last_hit_s: hits[*s.hits.last().expect("a site has a hit")].t_s,
                hits: s.hits.len(),
                transfer_points: tp,
                absorbed_energy_j: s.absorbed_energy_j,
                bruised: s.bruised,
                volume_mm3: s.volume_mm3,
                area_mm2: s.area_mm2(),
                depth_mm: s.depth_mm,
                diameter_mm: s.diameter_mm,
            });
        }
        let bruises: Vec<&BruiseSite> = rows_of_apple.iter().filter(|s| s.bruised).collect();
        let sizes: Vec<BruiseSize> = bruises.iter().map(|s| s.size()).collect();
        let g = grade::grade(&classes, &below, &sizes);
        let cause = |h: &Side| Cause {
            transfer_point: rows[h.row].transfer_point.clone(),
            with: h.other.clone(),
            t_s: h.t_s,
            contact: h.event,
        };
        // The first hit after which the apple is below the best class: grades only fall as hits
        // are added (volumes and areas only grow), so search for it.
        let downgraded_by = (g.rank > 0).then(|| {
            let below_best = |n: usize| {
                let s = sites::sites(&p, apple.radius_m, &placed[..n]);
                let sizes: Vec<BruiseSize> = s
                    .iter()
                    .filter(|s| s.bruised)
                    .map(|s| BruiseSize {
                        volume_mm3: s.volume_mm3,
                        diameter_mm: s.diameter_mm,
                        depth_mm: s.depth_mm,
                        area_mm2: s.area_mm2(),
                    })
                    .collect();
                grade::grade(&classes, &below, &sizes).rank > 0
            };
            let (mut lo, mut hi) = (0usize, hits.len());
            while lo + 1 < hi {
                let mid = (lo + hi) / 2;
                if below_best(mid) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            cause(&hits[hi - 1])
        });
        let first_bruise = found
            .iter()
            .filter(|s| s.bruised)
            .filter_map(|s| {
                // The hit that made the site a bruise: the first after which it is one.
                (1..=s.hits.len()).find_map(|n| {
                    let upto: Vec<PlacedHit> = s.hits[..n].iter().map(|&h| placed[h]).collect();
                    let one = sites::sites(&p, apple.radius_m, &upto);
                    one.iter().any(|x| x.bruised).then(|| &hits[s.hits[n - 1]])
                })
            })
            .min_by(|a, b| a.t_s.total_cmp(&b.t_s))
            .map(cause);
        let largest = bruises
            .iter()
            .max_by(|a, b| {
                a.volume_mm3
                    .unwrap_or(0.0)
                    .total_cmp(&b.volume_mm3.unwrap_or(0.0))
                    .then(b.site.cmp(&a.site))
            })
            .map(|s| LargestBruise {
                site: s.site,
                volume_mm3: s.volume_mm3,
                diameter_mm: s.diameter_mm,
                depth_mm: s.depth_mm,
                area_mm2: s.area_mm2,
            });
        let sum = |f: fn(&BruiseSite) -> Option<f64>| {
            p.model
                .sizes()
                .then(|| bruises.iter().filter_map(|s| f(s)).fold(0.0, |s, v| s + v))
        };
        let mine: Vec<&ContactAssessment> = rows_of[i].iter().map(|&r| &rows[r]).collect();
        let max = |f: fn(&ContactAssessment) -> f64| mine.iter().map(|r| f(r)).fold(0.0, f64::max);
        apples.push(AppleAssessment {
            apple: name_arc.clone(),
            material: apple.material.clone(),
            model: p.model.name(),
            contacts: mine.len(),
            impacts: hits.len(),
            peak_force_n: max(|r| r.peak_force_n),
            max_peak_g: max(|r| r.peak_g),
            max_velocity_change_m_s: max(|r| r.velocity_change_m_s),
            absorbed_energy_j: hits
                .iter()
                .map(|h| h.hit.absorbed_energy_j)
                .fold(0.0, |s, e| s + e),
            bruises: bruises.len(),
            bruise_volume_mm3: sum(|s| s.volume_mm3),
            bruised_area_mm2: sum(|s| s.area_mm2),
            largest_bruise: largest,
            grade: g.grade.clone(),
            grade_rank: g.rank,
            grade_why: g.why.clone(),
            downgraded: g.rank > 0,
            downgraded_by,
            first_bruise,
            max_static_force_n: mine
                .iter()
                .filter_map(|r| r.static_max_force_n)
                .fold(0.0, f64::max),
            static_overload: mine.iter().any(|r| !r.exceeded.is_empty()),
        });
        all_sites.extend(rows_of_apple);
    }
    let warnings = outside
        .into_iter()
        .map(|(material, (hits, apples, why))| {
            let p = params_of(&material);
            format!(
                "damage model of '{material}' ({} preset '{}'): {hits} hit(s) of {} apple(s) outside the range it was measured in ({}): {why}; treat their bruises as extrapolated",
                p.model.name(),
                p.preset,
                apples.len(),
                p.validity.text
            )
        })
        .collect();
    let force_thresholds = names
        .iter()
        .filter_map(|n| {
            let m = &roster[*n].material;
            match params_of(m).model {
                super::damage::Model::PeakForce { threshold_n } => Some((m.clone(), threshold_n)),
                _ => None,
            }
        })
        .collect();
    BruiseReport {
        force_thresholds,
        standard: std_name,
        grades,
        apples,
        contacts: rows,
        sites: all_sites,
        warnings,
    }
}
