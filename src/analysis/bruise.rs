//! Bruise assessment: every contact of every apple against the thresholds of its material,
//! impacts and static loads apart.
//!
//! A contact is an impact (from touch until the pulse is over) and possibly a resting time after
//! it (`record::events`). The paper's criterion is the impact's peak force: 80 N for firm
//! varieties, 35-40 N for soft ones (physics.md section 8). Per material the scenario may change
//! it and add thresholds on the impact's peak mean contact pressure P / (pi a^2) and on the energy
//! it absorbs (the eq. 12 hysteresis loss, the work that damages tissue instead of coming back as
//! rebound), and thresholds on the static load of the resting time (its largest force and mean
//! pressure: the loads storage bruising depends on). A contact is at risk when it exceeds
//! (strictly) any threshold given; an apple is at risk when any of its contacts is. Each impact is
//! also reported as an instrumented sphere reports it: peak acceleration in g and velocity change
//! over the pulse (`analysis::impacts`); a contact that starts at rest has no impact.

use crate::record::events::{ContactEvent, Party};
use crate::scenario::{BruiseSpec, Scenario};
use crate::world::RosterApple;
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::Arc;

/// The paper's peak-force bruise threshold for firm varieties (N).
pub const DEFAULT_PEAK_FORCE_N: f64 = 80.0;

/// The thresholds applied to one apple.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Thresholds {
    /// Peak normal force (N).
    pub peak_force_n: f64,
    /// Peak mean contact pressure (Pa), if set.
    pub mean_pressure_pa: Option<f64>,
    /// Energy absorbed in one impact (J), if set.
    pub absorbed_energy_j: Option<f64>,
    /// Largest static force of a resting contact (N), if set.
    pub static_force_n: Option<f64>,
    /// Largest mean pressure of a resting contact (Pa), if set.
    pub static_pressure_pa: Option<f64>,
}

impl Thresholds {
    /// The thresholds of a material's `bruise` entry, with the paper's 80 N when absent.
    pub fn from_spec(spec: Option<&BruiseSpec>) -> Self {
        Self {
            peak_force_n: spec
                .and_then(|b| b.peak_force_n)
                .unwrap_or(DEFAULT_PEAK_FORCE_N),
            mean_pressure_pa: spec.and_then(|b| b.mean_pressure_pa),
            absorbed_energy_j: spec.and_then(|b| b.absorbed_energy_j),
            static_force_n: spec.and_then(|b| b.static_force_n),
            static_pressure_pa: spec.and_then(|b| b.static_pressure_pa),
        }
    }

    /// Which thresholds a contact exceeds, joined by `+` (`force+pressure`, `static-force`);
    /// empty when none. The impact's figures meet the impact thresholds, the resting load's
    /// the static ones.
    pub fn exceeded(&self, e: &ContactEvent) -> String {
        let mut why = Vec::new();
        if let Some(i) = &e.impact {
            if i.peak_force_n > self.peak_force_n {
                why.push("force");
            }
            if self.mean_pressure_pa.is_some_and(|p| i.max_pressure_pa > p) {
                why.push("pressure");
            }
            if self
                .absorbed_energy_j
                .is_some_and(|w| i.absorbed_energy_j > w)
            {
                why.push("energy");
            }
        }
        if let Some(r) = &e.resting {
            if self.static_force_n.is_some_and(|f| r.max_force_n > f) {
                why.push("static-force");
            }
            if self
                .static_pressure_pa
                .is_some_and(|p| r.max_pressure_pa > p)
            {
                why.push("static-pressure");
            }
        }
        why.join("+")
    }
}

/// One contact as seen by one apple (a contact between two apples gives two of these).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactAssessment {
    /// Index of the contact in `contacts.csv` / `RunResult::events`.
    pub contact: usize,
    /// The apple assessed.
    pub apple: Arc<str>,
    /// What it touched (a surface or another apple).
    pub other: Arc<str>,
    /// First touch (s).
    pub t_start_s: f64,
    /// Time of the peak force (s).
    pub t_peak_s: f64,
    /// Contact point at the peak force (m, world).
    pub contact_point_m: [f64; 3],
    /// Peak normal force of the impact (N; 0 for a contact that starts at rest).
    pub peak_force_n: f64,
    /// Peak mean contact pressure of the impact (Pa).
    pub mean_pressure_pa: f64,
    /// Energy absorbed in the impact (J).
    pub absorbed_energy_j: f64,
    /// Velocity change of this apple over the impact pulse (m/s; 0 without an impact).
    pub velocity_change_m_s: f64,
    /// Peak acceleration of this apple in the impact, force / (m g) (g; 0 without an impact).
    pub peak_g: f64,
    /// Normal approach speed at first touch (m/s).
    pub approach_speed_m_s: f64,
    /// Largest force of the resting time after the impact, if any (N).
    pub static_max_force_n: Option<f64>,
    /// Largest mean pressure of the resting time, if any (Pa).
    pub static_max_pressure_pa: Option<f64>,
    /// The thresholds of this apple's material.
    pub thresholds: Thresholds,
    /// Which thresholds were exceeded (`force`, `pressure`, `energy`, joined by `+`).
    pub exceeded: String,
}

impl ContactAssessment {
    /// Whether the contact may bruise the apple.
    pub fn at_risk(&self) -> bool {
        !self.exceeded.is_empty()
    }
}

/// One apple over the whole run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AppleAssessment {
    /// Apple name.
    pub apple: Arc<str>,
    /// Its material.
    pub material: String,
    /// Its thresholds.
    pub thresholds: Thresholds,
    /// Contacts it had.
    pub contacts: usize,
    /// Largest peak force of its contacts (N).
    pub peak_force_n: f64,
    /// Largest mean contact pressure (Pa).
    pub peak_mean_pressure_pa: f64,
    /// Energy absorbed in all its impacts (J); an impact between two apples counts for both.
    pub absorbed_energy_j: f64,
    /// Largest velocity change in one impact (m/s).
    pub max_velocity_change_m_s: f64,
    /// Largest peak acceleration in one impact (g).
    pub max_peak_g: f64,
    /// Largest static force of a resting contact (N).
    pub max_static_force_n: f64,
    /// Whether any contact exceeded a threshold.
    pub at_risk: bool,
    /// Contacts that exceeded a threshold.
    pub contacts_at_risk: usize,
    /// The first contact at risk: what it hit (surface or apple) ...
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_risk_with: Option<Arc<str>>,
    /// ... when (time of its peak force, s) ...
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_risk_t_s: Option<f64>,
    /// ... and where (contact point at the peak, m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_risk_point_m: Option<[f64; 3]>,
}

/// The bruise assessment of a run.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct BruiseReport {
    /// One entry per apple, scenario order.
    pub apples: Vec<AppleAssessment>,
    /// One entry per apple per contact, in contact order (the rows of `bruise.csv`).
    pub contacts: Vec<ContactAssessment>,
}

impl BruiseReport {
    /// Apples at risk.
    pub fn apples_at_risk(&self) -> usize {
        self.apples.iter().filter(|a| a.at_risk).count()
    }

    /// Contact assessments at risk.
    pub fn contacts_at_risk(&self) -> impl Iterator<Item = &ContactAssessment> {
        self.contacts.iter().filter(|c| c.at_risk())
    }

    /// Whether apple `name` had a contact at risk whose peak came at or before `time_s` (the
    /// bruise flag of the ParaView frames).
    pub fn at_risk_by(&self, name: &str, time_s: f64) -> bool {
        self.apples
            .iter()
            .any(|a| &*a.apple == name && a.first_risk_t_s.is_some_and(|t| t <= time_s))
    }
}

/// Assesses every contact of a run of scenario `sc` (its thresholds). `roster` describes every
/// apple by name (the run's roster, [`crate::world::Roster::by_name`]); `order` lists the apples of the run (layer order), which sets the
/// order of [`BruiseReport::apples`].
pub fn assess(
    sc: &Scenario,
    events: &[ContactEvent],
    roster: &BTreeMap<&str, &RosterApple>,
    order: &[&str],
) -> BruiseReport {
    let thresholds = |material: &str| {
        Thresholds::from_spec(sc.materials.get(material).and_then(|m| m.bruise.as_ref()))
    };
    let new_apple = |name: &str| {
        let material = roster
            .get(name)
            .map(|a| a.material.clone())
            .unwrap_or_default();
        AppleAssessment {
            apple: name.into(),
            thresholds: thresholds(&material),
            material,
            contacts: 0,
            peak_force_n: 0.0,
            peak_mean_pressure_pa: 0.0,
            absorbed_energy_j: 0.0,
            max_velocity_change_m_s: 0.0,
            max_peak_g: 0.0,
            max_static_force_n: 0.0,
            at_risk: false,
            contacts_at_risk: 0,
            first_risk_with: None,
            first_risk_t_s: None,
            first_risk_point_m: None,
        }
    };
    let mut apples: Vec<AppleAssessment> = order.iter().map(|n| new_apple(n)).collect();
    let mut index: BTreeMap<Arc<str>, usize> = apples
        .iter()
        .enumerate()
        .map(|(k, a)| (a.apple.clone(), k))
        .collect();
    let mut contacts = Vec::new();
    for (k, e) in events.iter().enumerate() {
        let mut sides = vec![(e.a.clone(), e.b.clone(), true)];
        if let Party::Apple(_) = e.b_party {
            sides.push((e.b.clone(), e.a.clone(), false));
        }
        for (name, other, towards) in sides {
            let i = *index.entry(name.clone()).or_insert_with(|| {
                apples.push(new_apple(&name));
                apples.len() - 1
            });
            let th = apples[i].thresholds;
            let mass = roster.get(&*name).map_or(f64::NAN, |a| a.mass_kg);
            let side = e
                .impact
                .as_ref()
                .map(|p| super::impacts::for_apple(p, mass, towards));
            let c = ContactAssessment {
                contact: k,
                apple: name,
                other,
                t_start_s: e.t_start_s,
                t_peak_s: e.impact.map_or(e.t_peak_s, |i| i.t_peak_s),
                contact_point_m: e.contact_point_m,
                peak_force_n: e.impact.map_or(0.0, |i| i.peak_force_n),
                mean_pressure_pa: e.impact.map_or(0.0, |i| i.max_pressure_pa),
                absorbed_energy_j: e.impact.map_or(0.0, |i| i.absorbed_energy_j),
                velocity_change_m_s: side.map_or(0.0, |s| s.velocity_change_m_s),
                peak_g: side.map_or(0.0, |s| s.peak_g),
                approach_speed_m_s: e.approach_speed_m_s,
                static_max_force_n: e.resting.map(|r| r.max_force_n),
                static_max_pressure_pa: e.resting.map(|r| r.max_pressure_pa),
                thresholds: th,
                exceeded: th.exceeded(e),
            };
            let a = &mut apples[i];
            a.contacts += 1;
            a.peak_force_n = a.peak_force_n.max(c.peak_force_n);
            a.peak_mean_pressure_pa = a.peak_mean_pressure_pa.max(c.mean_pressure_pa);
            a.absorbed_energy_j += c.absorbed_energy_j;
            a.max_velocity_change_m_s = a.max_velocity_change_m_s.max(c.velocity_change_m_s);
            a.max_peak_g = a.max_peak_g.max(c.peak_g);
            a.max_static_force_n = a
                .max_static_force_n
                .max(c.static_max_force_n.unwrap_or(0.0));
            if c.at_risk() {
                a.at_risk = true;
                a.contacts_at_risk += 1;
                if a.first_risk_t_s.is_none_or(|t| c.t_peak_s < t) {
                    a.first_risk_t_s = Some(c.t_peak_s);
                    a.first_risk_with = Some(c.other.clone());
                    a.first_risk_point_m = Some(c.contact_point_m);
                }
            }
            contacts.push(c);
        }
    }
    BruiseReport { apples, contacts }
}
