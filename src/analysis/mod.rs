//! What a run means for the fruit: the paper's force-pulse fit (eqs. 13-15, [`pulse`]), the
//! fruit's damage ([`bruise`], through the pure models of [`damage`]: bruise volume, sites,
//! grade), the line audit per transfer point ([`audit`]), two layouts compared with the
//! intervals of their differences ([`compare`], [`interval`]), the calibration of the eq. 12
//! coefficient ke against a measured restitution ([`calibrate`]), and the calibration of a damage
//! model against a lab's drop tests ([`calibrate_bruise`]). User guides: docs/analysis.md,
//! docs/damage.md.
//!
//! [`analyse`] runs the first three on a finished run; `run::to_dir` writes their files
//! (`pulse_fits.csv`, `apple_contacts.csv`, `bruises.csv`, `audit.csv`, `audit.md`, `ird.svg`)
//! and adds their headline figures to `RunResult::metrics`.

pub mod audit;
pub mod bruise;
pub mod calibrate;
pub mod calibrate_bruise;
pub mod compare;
pub mod damage;
pub mod impacts;
pub mod interval;
pub mod pulse;
pub mod tradeoff;

use crate::scenario::Scenario;
use crate::sim::RunResult;
use serde::Serialize;
use std::collections::BTreeMap;

/// The analysis of one run.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Analysis {
    /// Eq. 13 fits of the impacts with a force history.
    pub pulse_fits: Vec<pulse::PulseFit>,
    /// Bruise assessment.
    pub bruise: bruise::BruiseReport,
    /// The line audit: impacts per transfer point.
    pub audit: audit::Audit,
    /// The transfer point of each contact event, in the run's event order
    /// ([`audit::points_of`]; contacts.csv's `transfer_point`).
    pub contact_points: Vec<String>,
}

/// Fits the pulses and assesses the fruit's damage of a finished run of `sc` (its damage models
/// and grading); each apple's material and mass come from the run's roster, the parts of the
/// line from its zones.
pub fn analyse(sc: &Scenario, r: &RunResult) -> Analysis {
    let roster = r.roster.by_name();
    let mass = |name: &str| roster.get(name).map_or(f64::NAN, |a| a.mass_kg);
    let order: Vec<&str> = r.apples.iter().map(|a| a.name.as_str()).collect();
    let contact_points = audit::points_of(&r.events, &r.zones, &r.roster);
    let bruise = bruise::assess(sc, &r.events, &roster, &order, &contact_points);
    let audit = audit::audit(&r.events, &contact_points, &r.roster, &bruise);
    Analysis {
        pulse_fits: pulse::fit_events(&r.events, &mass),
        bruise,
        audit,
        contact_points,
    }
}

impl Analysis {
    /// Headline figures for `RunResult::metrics`, of the fruit only (probes left out):
    /// `apples_bruised`, `apples_downgraded` (below the standard's best class),
    /// `total_bruise_volume_mm3`, `max_bruise_volume_mm3` (one bruise), `max_absorbed_energy_j`
    /// (the most one apple absorbed in one hit), `total_absorbed_energy_j` (all apples' own
    /// shares), `max_velocity_change_m_s`, `max_peak_g`, and the median fitted `pulse_eps`,
    /// `pulse_tau`, `pulse_k_p` when impacts were fitted, and the audit's figures per transfer
    /// point ([`audit::Audit::metrics`]: a batch's `merged.csv` gets a column each). Only finite
    /// values.
    pub fn add_metrics(&self, m: &mut BTreeMap<String, f64>) {
        let b = &self.bruise;
        m.insert("apples_bruised".into(), b.apples_bruised() as f64);
        m.insert("apples_downgraded".into(), b.apples_downgraded() as f64);
        m.insert(
            "total_bruise_volume_mm3".into(),
            b.total_bruise_volume_mm3(),
        );
        m.insert(
            "max_bruise_volume_mm3".into(),
            b.sites
                .iter()
                .filter(|s| s.bruised)
                .filter_map(|s| s.volume_mm3)
                .fold(f64::NAN, f64::max),
        );
        let max = |f: fn(&bruise::ContactAssessment) -> f64| {
            b.contacts.iter().map(f).fold(f64::NAN, f64::max)
        };
        m.insert("max_absorbed_energy_j".into(), max(|c| c.absorbed_energy_j));
        m.insert(
            "total_absorbed_energy_j".into(),
            b.contacts
                .iter()
                .map(|c| c.absorbed_energy_j)
                .fold(0.0, |s, e| s + e),
        );
        m.insert(
            "max_velocity_change_m_s".into(),
            max(|c| c.velocity_change_m_s),
        );
        m.insert("max_peak_g".into(), max(|c| c.peak_g));
        let median = |f: fn(&pulse::PulseFit) -> f64| {
            let mut v: Vec<f64> = self.pulse_fits.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            match v.len() {
                0 => f64::NAN,
                n if n % 2 == 1 => v[n / 2],
                n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
            }
        };
        m.insert("pulse_eps".into(), median(|p| p.fit_eps));
        m.insert("pulse_tau".into(), median(|p| p.fit_tau));
        m.insert("pulse_k_p".into(), median(|p| p.k_p));
        m.extend(self.audit.metrics());
        m.retain(|_, v| v.is_finite());
    }
}
