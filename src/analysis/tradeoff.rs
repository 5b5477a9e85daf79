//! Speed against accuracy for one scenario: run it across a ladder of fidelity levels and step
//! sizes, take the finest rung as the reference, and measure every other rung's errors and cost.
//!
//! Errors are measured on what users read off a run. A scene with several apples is chaotic once
//! they meet (a pile, a bin: individual apples take different paths at any step size, and pairing
//! apple by apple would measure the chaos, not the accuracy), so the errors compare
//! *distributions*: the 10, 25, 50, 75 and 90 % quantiles and the maximum of
//! - the apples' peak forces (each apple's largest normal force over the run), relative;
//! - the durations of the first contact of each (apple, surface) pair, relative, and their
//!   restitutions, absolute;
//! - the apples' final heights (along -gravity), in apple radii.
//!
//! Each row reports the largest and the median of these quantile errors. For a single apple they
//! are the plain errors.
//!
//! A rung that the stability guard refuses is reported as refused, with the message.

use crate::record::events::ContactEvent;
use crate::record::series::NoSamples;
use crate::scenario::{Accuracy, Fidelity, Scenario, TimeStep};
use crate::sim::{RunResult, Simulation};
use serde::Serialize;
use std::path::Path;

/// One rung of the ladder.
#[derive(Debug, Clone, PartialEq)]
pub struct Rung {
    /// Label in the table.
    pub label: String,
    /// Fidelity level.
    pub fidelity: Fidelity,
    /// Time-step policy.
    pub time_step: TimeStep,
    /// Accuracy target (steps per contact) for `auto` and `adaptive`.
    pub accuracy: Accuracy,
}

/// The default ladder: every fidelity level, `auto` at preview / balanced / precise, `adaptive` at
/// balanced, and the scenario's own step; the reference is `full` at 200 steps per contact.
pub fn default_ladder(sc: &Scenario) -> (Rung, Vec<Rung>) {
    let reference = Rung {
        label: "reference: full, auto, 200 steps/contact".into(),
        fidelity: Fidelity::Full,
        time_step: TimeStep::Auto,
        accuracy: Accuracy::Steps(200.0),
    };
    let mut rungs = Vec::new();
    for fidelity in [Fidelity::HertzDamped, Fidelity::Full, Fidelity::Hertz] {
        let name = serde_json::to_value(fidelity).unwrap_or_default();
        let name = name.as_str().unwrap_or("?").to_string();
        for (acc, acc_name) in [
            (Accuracy::Preview, "preview"),
            (Accuracy::Balanced, "balanced"),
            (Accuracy::Precise, "precise"),
        ] {
            rungs.push(Rung {
                label: format!("{name}, auto, {acc_name}"),
                fidelity,
                time_step: TimeStep::Auto,
                accuracy: acc,
            });
        }
        rungs.push(Rung {
            label: format!("{name}, adaptive, balanced"),
            fidelity,
            time_step: TimeStep::Adaptive,
            accuracy: Accuracy::Balanced,
        });
    }
    if let TimeStep::Fixed(dt) = sc.time_step_s {
        rungs.push(Rung {
            label: format!(
                "scenario's own: {}, fixed {dt:e} s",
                fidelity_name(sc.fidelity)
            ),
            fidelity: sc.fidelity,
            time_step: sc.time_step_s,
            accuracy: sc.accuracy.unwrap_or_default(),
        });
    }
    rungs.push(Rung {
        label: "rigid, auto".into(),
        fidelity: Fidelity::Rigid,
        time_step: TimeStep::Auto,
        accuracy: Accuracy::Balanced,
    });
    (reference, rungs)
}

fn fidelity_name(f: Fidelity) -> String {
    serde_json::to_value(f)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

/// One row of the table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TradeoffRow {
    /// Rung label.
    pub rung: String,
    /// Fidelity level.
    pub fidelity: String,
    /// `fixed`, `auto` or `adaptive`.
    pub step_policy: String,
    /// Steps per contact aimed at.
    pub steps_per_contact: f64,
    /// Mean step (s).
    pub time_step_s: f64,
    /// Steps taken.
    pub steps: u64,
    /// Wall time of the stepping loop (s).
    pub wall_time_s: f64,
    /// Contact events.
    pub contact_events: usize,
    /// Largest relative error of a quantile of the apples' peak forces (%).
    pub peak_force_err_max_pct: f64,
    /// Median relative error of those quantiles (%).
    pub peak_force_err_median_pct: f64,
    /// Largest relative error of a quantile of the first surface contacts' durations (%).
    pub contact_time_err_max_pct: f64,
    /// Median relative error of those quantiles (%).
    pub contact_time_err_median_pct: f64,
    /// Largest absolute error of a quantile of the first surface contacts' restitutions.
    pub restitution_err_max: f64,
    /// Largest error of a quantile of the final heights, in apple radii.
    pub final_position_err_max_r: f64,
    /// Median error of the quantiles of the final heights, in apple radii.
    pub final_position_err_median_r: f64,
    /// Largest error of a quantile of the final speeds (m/s).
    pub final_velocity_err_max_m_s: f64,
    /// Why the guard refused the rung, if it did.
    pub refused: Option<String>,
}

/// The whole table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TradeoffTable {
    /// The reference rung's label.
    pub reference: String,
    /// Its wall time (s).
    pub reference_wall_time_s: f64,
    /// The rows, in ladder order.
    pub rows: Vec<TradeoffRow>,
}

/// Errors of the tradeoff command.
#[derive(Debug, thiserror::Error)]
pub enum TradeoffError {
    /// The reference rung itself failed.
    #[error("the reference run failed: {0}")]
    Reference(String),
}

fn run_rung(sc: &Scenario, rung: &Rung, base_dir: &Path) -> Result<RunResult, String> {
    let mut s = sc.clone();
    s.fidelity = rung.fidelity;
    s.time_step_s = rung.time_step;
    s.accuracy = Some(rung.accuracy);
    s.output.force_history = Some(crate::scenario::ForceHistory::Off);
    // No time series is kept: do not let the output interval cap the step.
    s.output.sample_interval_s = Some(s.sample_interval_s().max(s.duration_s / 20.0));
    let sim = Simulation::new(&s, base_dir).map_err(|e| e.to_string())?;
    sim.run(&mut NoSamples, &mut |_| {})
        .map_err(|e| e.to_string())
}

fn first_surface_contacts(events: &[ContactEvent]) -> Vec<&ContactEvent> {
    let mut seen = std::collections::BTreeSet::new();
    let mut out = Vec::new();
    for e in events {
        if matches!(e.b_party, crate::record::events::Party::Surface(_))
            && seen.insert((e.a.to_string(), e.b.to_string()))
        {
            out.push(e);
        }
    }
    out
}

fn median(mut v: Vec<f64>) -> f64 {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn max(v: &[f64]) -> f64 {
    v.iter()
        .copied()
        .filter(|x| x.is_finite())
        .fold(f64::NAN, f64::max)
}

/// Quantile `q` of sorted finite values (linear interpolation).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let x = q * (sorted.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x - x.floor());
    if i + 1 < sorted.len() {
        sorted[i] * (1.0 - f) + sorted[i + 1] * f
    } else {
        sorted[i]
    }
}

/// Errors between the quantiles of two samples: (largest, median) over 10, 25, 50, 75, 90 % and
/// the maximum; relative (in %) or absolute.
fn quantile_errors(ours: &[f64], theirs: &[f64], relative: bool) -> (f64, f64) {
    let clean = |v: &[f64]| {
        let mut v: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
        v.sort_by(f64::total_cmp);
        v
    };
    let (a, b) = (clean(ours), clean(theirs));
    if a.is_empty() || b.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let errs: Vec<f64> = [0.1, 0.25, 0.5, 0.75, 0.9, 1.0]
        .iter()
        .map(|&q| {
            let (x, y) = (quantile(&a, q), quantile(&b, q));
            if relative {
                if y != 0.0 {
                    100.0 * (x - y).abs() / y.abs()
                } else {
                    f64::NAN
                }
            } else {
                (x - y).abs()
            }
        })
        .collect();
    (max(&errs), median(errs))
}

/// Compares a run with the reference (see the module documentation). `up` is the unit vector
/// against gravity, `radius_m` the mean apple radius.
pub fn compare(
    run: &RunResult,
    reference: &RunResult,
    up: crate::math::Vec3,
    radius_m: f64,
) -> TradeoffRow {
    // A run with no contact records at all (the `rigid` level) cannot tell forces.
    let forces_known = !run.events.is_empty() || reference.events.is_empty();
    let peaks = |r: &RunResult| r.apples.iter().map(|a| a.peak_force_n).collect::<Vec<_>>();
    let (pk_max, pk_med) = if forces_known {
        quantile_errors(&peaks(run), &peaks(reference), true)
    } else {
        (f64::NAN, f64::NAN)
    };
    let firsts = |r: &RunResult| {
        let f = first_surface_contacts(&r.events);
        (
            f.iter().filter_map(|e| e.duration_s).collect::<Vec<_>>(),
            f.iter().filter_map(|e| e.restitution).collect::<Vec<_>>(),
        )
    };
    let (d_ours, e_ours) = firsts(run);
    let (d_ref, e_ref) = firsts(reference);
    let (ct_max, ct_med) = quantile_errors(&d_ours, &d_ref, true);
    let (rest_max, _) = quantile_errors(&e_ours, &e_ref, false);
    let heights = |r: &RunResult| {
        r.apples
            .iter()
            .map(|a| up.dot(crate::math::vec3(a.final_position_m)) / radius_m)
            .collect::<Vec<_>>()
    };
    let (h_max, h_med) = quantile_errors(&heights(run), &heights(reference), false);
    let speeds = |r: &RunResult| {
        r.apples
            .iter()
            .map(|a| crate::math::vec3(a.final_velocity_m_s).length())
            .collect::<Vec<_>>()
    };
    let (v_max, _) = quantile_errors(&speeds(run), &speeds(reference), false);
    TradeoffRow {
        rung: String::new(),
        fidelity: String::new(),
        step_policy: run.step_policy.to_string(),
        steps_per_contact: f64::NAN,
        time_step_s: run.time_step_s,
        steps: run.steps,
        wall_time_s: run.wall_time_s,
        contact_events: run.events.len(),
        peak_force_err_max_pct: pk_max,
        peak_force_err_median_pct: pk_med,
        contact_time_err_max_pct: ct_max,
        contact_time_err_median_pct: ct_med,
        restitution_err_max: rest_max,
        final_position_err_max_r: h_max,
        final_position_err_median_r: h_med,
        final_velocity_err_max_m_s: v_max,
        refused: None,
    }
}

/// Runs the ladder. `progress` gets each rung's label as it starts.
pub fn tradeoff(
    sc: &Scenario,
    base_dir: &Path,
    reference: &Rung,
    rungs: &[Rung],
    progress: &mut dyn FnMut(&str),
) -> Result<TradeoffTable, TradeoffError> {
    progress(&reference.label);
    let r = run_rung(sc, reference, base_dir).map_err(TradeoffError::Reference)?;
    let radii: Vec<f64> = match crate::world::roster::plan(sc) {
        Ok(plan) => plan
            .initial
            .iter()
            .map(|(a, _)| a)
            .chain(plan.feeds.iter().map(|(_, _, a)| a))
            .map(|a| a.diameter_m / 2.0)
            .collect(),
        Err(_) => Vec::new(),
    };
    let radius = radii.iter().sum::<f64>() / radii.len().max(1) as f64;
    let g = crate::math::vec3(sc.gravity_m_s2);
    let up = if g.length() > 0.0 {
        -g.normalize()
    } else {
        crate::math::Vec3::Z
    };
    let mut rows = Vec::new();
    for rung in rungs {
        progress(&rung.label);
        let mut row = match run_rung(sc, rung, base_dir) {
            Ok(run) => compare(&run, &r, up, radius),
            Err(e) => TradeoffRow {
                rung: String::new(),
                fidelity: String::new(),
                step_policy: String::new(),
                steps_per_contact: f64::NAN,
                time_step_s: f64::NAN,
                steps: 0,
                wall_time_s: f64::NAN,
                contact_events: 0,
                peak_force_err_max_pct: f64::NAN,
                peak_force_err_median_pct: f64::NAN,
                contact_time_err_max_pct: f64::NAN,
                contact_time_err_median_pct: f64::NAN,
                restitution_err_max: f64::NAN,
                final_position_err_max_r: f64::NAN,
                final_position_err_median_r: f64::NAN,
                final_velocity_err_max_m_s: f64::NAN,
                refused: Some(e),
            },
        };
        row.rung = rung.label.clone();
        row.fidelity = fidelity_name(rung.fidelity);
        row.steps_per_contact = rung.accuracy.steps_per_contact();
        rows.push(row);
    }
    Ok(TradeoffTable {
        reference: reference.label.clone(),
        reference_wall_time_s: r.wall_time_s,
        rows,
    })
}

fn cell(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.4}")
    } else {
        String::new()
    }
}

impl TradeoffTable {
    /// The table as CSV text (empty cells: not measurable, e.g. forces of a `rigid` run).
    pub fn to_csv(&self) -> String {
        let mut w = csv::Writer::from_writer(Vec::new());
        let _ = w.write_record([
            "rung",
            "fidelity",
            "step_policy",
            "steps_per_contact",
            "time_step_s",
            "steps",
            "wall_time_s",
            "speed_up_vs_reference",
            "contact_events",
            "peak_force_err_max_pct",
            "peak_force_err_median_pct",
            "contact_time_err_max_pct",
            "contact_time_err_median_pct",
            "restitution_err_max",
            "final_position_err_max_r",
            "final_position_err_median_r",
            "final_velocity_err_max_m_s",
            "refused",
        ]);
        for r in &self.rows {
            let _ = w.write_record([
                r.rung.clone(),
                r.fidelity.clone(),
                r.step_policy.clone(),
                cell(r.steps_per_contact),
                if r.time_step_s.is_finite() {
                    format!("{:e}", r.time_step_s)
                } else {
                    String::new()
                },
                r.steps.to_string(),
                cell(r.wall_time_s),
                cell(self.reference_wall_time_s / r.wall_time_s),
                r.contact_events.to_string(),
                cell(r.peak_force_err_max_pct),
                cell(r.peak_force_err_median_pct),
                cell(r.contact_time_err_max_pct),
                cell(r.contact_time_err_median_pct),
                cell(r.restitution_err_max),
                cell(r.final_position_err_max_r),
                cell(r.final_position_err_median_r),
                cell(r.final_velocity_err_max_m_s),
                r.refused.clone().unwrap_or_default(),
            ]);
        }
        String::from_utf8(w.into_inner().unwrap_or_default()).unwrap_or_default()
    }

    /// The table as a Markdown table (for docs/accuracy.md).
    pub fn to_markdown(&self) -> String {
        let mut s = format!(
            "Reference: {} ({:.2e} s wall time).\n\n| rung | mean step (s) | steps | wall (s) | peak forces err max / median (%) | first surface contact times err max / median (%) | restitution err max | final heights err max / median (R) |\n|---|---|---|---|---|---|---|---|\n",
            self.reference, self.reference_wall_time_s
        );
        let f = |x: f64, d: usize| {
            if x.is_finite() {
                format!("{x:.d$}")
            } else {
                "-".into()
            }
        };
        for r in &self.rows {
            if let Some(e) = &r.refused {
                s += &format!("| {} | refused: {} |||||||\n", r.rung, e.replace('|', "/"));
                continue;
            }
            s += &format!(
                "| {} | {:.2e} | {} | {} | {} / {} | {} / {} | {} | {} / {} |\n",
                r.rung,
                r.time_step_s,
                r.steps,
                format_args!("{:.2e}", r.wall_time_s),
                f(r.peak_force_err_max_pct, 3),
                f(r.peak_force_err_median_pct, 3),
                f(r.contact_time_err_max_pct, 3),
                f(r.contact_time_err_median_pct, 3),
                f(r.restitution_err_max, 4),
                f(r.final_position_err_max_r, 3),
                f(r.final_position_err_median_r, 3),
            );
        }
        s
    }

    /// Error against wall time, one series per error measure (log10 of both).
    pub fn chart(&self, title: &str) -> crate::chart::LineChart {
        use crate::chart::{LineChart, Series};
        let mut series = Vec::new();
        for (label, get) in [
            (
                "peak forces, median quantile error (%)",
                (|r: &TradeoffRow| r.peak_force_err_median_pct) as fn(&TradeoffRow) -> f64,
            ),
            (
                "peak forces, largest quantile error (%)",
                |r: &TradeoffRow| r.peak_force_err_max_pct,
            ),
            (
                "first contact times, median quantile error (%)",
                |r: &TradeoffRow| r.contact_time_err_median_pct,
            ),
            (
                "final heights, median quantile error (% of R)",
                |r: &TradeoffRow| 100.0 * r.final_position_err_median_r,
            ),
        ] {
            let mut pts: Vec<(f64, f64)> = self
                .rows
                .iter()
                .filter(|r| r.refused.is_none() && r.wall_time_s > 0.0)
                .map(|r| (r.wall_time_s.log10(), get(r).log10()))
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            series.push(Series {
                label: label.into(),
                points: pts,
            });
        }
        LineChart {
            title: title.into(),
            x_label: "log10 of wall time (s)".into(),
            y_label: "log10 of error".into(),
            series,
            markers: Vec::new(),
            marker_colours: crate::chart::MarkerColours::Dark,
        }
    }
}
