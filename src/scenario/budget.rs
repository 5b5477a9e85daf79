//! What a scenario will cost, estimated before anything is built: how many apples it can hold and
//! the memory they need. A scenario beyond the limit is refused with the estimate at once,
//! instead of allocating for minutes and aborting (a source of 1e9 apples asked for 152 GB).
//!
//! The figure per apple is measured, with a margin: the 8036-apple reference pile peaks at
//! 41.5 MiB and the 1000-apple one at 11.2 MiB (docs/performance.md), 4.4 KiB per added apple
//! (rapier's body, the layer's per-apple arrays, about seven open contacts, the finished contacts
//! of a 5 s run); a force history adds up to 64 KiB per contact (4096 samples of time and force).

use super::{GeneratorSpec, Scenario, ScenarioError};

/// Memory an apple costs while a run holds it, contacts and records included (bytes; measured
/// 4.4 KiB, see the module documentation).
pub const BYTES_PER_APPLE: f64 = 8.0 * 1024.0;

/// Memory a kept force history costs per apple (bytes): one contact's full history.
pub const HISTORY_BYTES_PER_APPLE: f64 = 64.0 * 1024.0;

/// Default limit of the estimated memory of a run (MiB): `model.max_memory_mb`.
pub const DEFAULT_MAX_MEMORY_MB: f64 = 8192.0;

/// Default limit of the estimated size of a run's output files (MiB): `model.max_output_mb`.
pub const DEFAULT_MAX_OUTPUT_MB: f64 = 4096.0;

/// Bytes of one row of `bodies.csv` (measured: 189 on the 1000-apple pile, 154 on the handling
/// line; rounded up).
pub const BODIES_ROW_BYTES: f64 = 200.0;

/// Bytes of one row of `rollers.csv` (a roller's name and three numbers in full precision: about
/// 70; rounded up).
pub const ROLLERS_ROW_BYTES: f64 = 100.0;

/// Memory a probe apple's kept trace may cost per sample (bytes): a sample is a time and a
/// reading (16 bytes), held in the window being recorded and then in the trace, each vector up
/// to twice its length as it grows (4 x 16).
pub const PROBE_SAMPLE_BYTES: f64 = 64.0;

/// Bytes of one row of `probe_NAME_trace.csv` (measured: 28.6 on a 10 MHz trace of the handling
/// line, a time and a reading in full precision; rounded up).
pub const PROBE_ROW_BYTES: f64 = 40.0;

/// How many samples the trace of a probe apple of `sc` can keep: every sampling instant of the
/// run, `duration_s` times its rate (the windows kept around impacts cannot hold more; how many
/// impacts a line gives is not known before the run). Listed in order of the apples: (index,
/// samples).
pub fn probe_samples(sc: &Scenario) -> Vec<(usize, f64)> {
    sc.apples
        .iter()
        .enumerate()
        .filter_map(|(k, a)| {
            let p = a.probe?;
            Some((k, (sc.duration_s * p.sample_rate_hz).floor() + 1.0))
        })
        .collect()
}

/// The probe whose trace weighs most, with its samples, if the scenario has probes.
fn largest_probe(sc: &Scenario) -> Option<(usize, f64)> {
    probe_samples(sc)
        .into_iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// The refusal of a probe trace's estimate (`what`: memory or output) naming the probe's rate.
fn probe_refusal(sc: &Scenario, k: usize, samples: f64, what: &str, limit: &str) -> ScenarioError {
    let a = &sc.apples[k];
    let rate = a.probe.map_or(0.0, |p| p.sample_rate_hz);
    ScenarioError::invalid(
        format!("apples[{k}].probe.sample_rate_hz"),
        format!(
            "the probe '{}' sampled at {} Hz over {} s can keep {samples:.3e} samples in its trace, {what}, more than {limit}: sample less often, or raise {limit_field}",
            a.name,
            super::ranges::num(rate),
            super::ranges::num(sc.duration_s),
            limit_field = limit.split(" =").next().unwrap_or(limit),
        ),
    )
}

/// How many free-turning rollers `sc` has (a bed counts each of its rollers): the rows of
/// `rollers.csv` per sample.
/// Counted from the specs, never by expanding a bed: the budgets are checked before a bed's
/// `count` is (a count of 4294967295 expanded here asked for 1.2 TB).
pub fn free_rollers(sc: &Scenario) -> f64 {
    sc.surfaces
        .iter()
        .map(|s| match s {
            super::SurfaceSpec::Roller(r) if r.free_turning.is_some() => 1.0,
            super::SurfaceSpec::RollerBed(b) if b.free_turning.is_some() => f64::from(b.count),
            _ => 0.0,
        })
        .sum()
}

/// How many apples a run of `sc` can hold: the listed ones, every generator's count and every
/// source's count (counted, not generated: this is what must be checked before generating).
pub fn planned_apples(sc: &Scenario) -> f64 {
    let generated: f64 = sc.generators.iter().map(GeneratorSpec::count).sum();
    let fed: f64 = sc.sources.iter().map(|s| f64::from(s.count)).sum();
    sc.apples.len() as f64 + generated + fed
}

/// The memory a run of `sc` is estimated to need (bytes): its apples, and its probes' traces.
pub fn memory_bytes(sc: &Scenario) -> f64 {
    apples_memory_bytes(sc) + probes_memory_bytes(sc)
}

fn apples_memory_bytes(sc: &Scenario) -> f64 {
    let per_apple = BYTES_PER_APPLE
        + if sc.output.force_history {
            HISTORY_BYTES_PER_APPLE
        } else {
            0.0
        };
    planned_apples(sc) * per_apple
}

fn probes_memory_bytes(sc: &Scenario) -> f64 {
    probe_samples(sc)
        .iter()
        .map(|(_, n)| n * PROBE_SAMPLE_BYTES)
        .sum()
}

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// Refuses a scenario whose estimated memory exceeds `max_memory_mb`, naming the field to change:
/// a probe's `sample_rate_hz` when its trace weighs more than the apples (a probe sampling at
/// 10 MHz over a 30 s line asked for 8 GiB and aborted), else the apples' field.
pub fn check_memory(sc: &Scenario, max_memory_mb: f64) -> Result<(), ScenarioError> {
    let bytes = memory_bytes(sc);
    let limit = max_memory_mb * 1024.0 * 1024.0;
    if bytes > limit {
        if let Some((k, samples)) = largest_probe(sc) {
            if samples * PROBE_SAMPLE_BYTES >= apples_memory_bytes(sc) {
                return Err(probe_refusal(
                    sc,
                    k,
                    samples,
                    &format!(
                        "about {:.1} GiB of memory ({PROBE_SAMPLE_BYTES} bytes per sample; the run's estimate {:.1} GiB in all)",
                        samples * PROBE_SAMPLE_BYTES / GIB,
                        bytes / GIB
                    ),
                    &format!("model.max_memory_mb = {max_memory_mb} MiB"),
                ));
            }
        }
        let field = if sc.sources.iter().any(|s| f64::from(s.count) > 1e5) {
            "sources"
        } else if sc.generators.is_empty() {
            "apples"
        } else {
            "generators"
        };
        return Err(ScenarioError::invalid(
            field,
            format!(
                "the scenario holds {:.3e} apples, about {:.1} GiB of memory for the run (estimated {:.0} KiB per apple{}), more than model.max_memory_mb = {max_memory_mb} MiB: fewer apples, or raise model.max_memory_mb",
                planned_apples(sc),
                bytes / (1024.0 * 1024.0 * 1024.0),
                apples_memory_bytes(sc) / planned_apples(sc) / 1024.0,
                if sc.output.force_history {
                    " with force histories; output.force_history: false saves most of it"
                } else {
                    ""
                }
            ),
        ));
    }
    Ok(())
}

/// The size of the output files a run of `sc` is estimated to write (bytes): `bodies.csv`, one
/// row per apple per sample, and `rollers.csv`, one row per free-turning roller per sample (the
/// other files grow with the contacts, far less).
pub fn output_bytes(sc: &Scenario) -> f64 {
    samples_output_bytes(sc) + probes_output_bytes(sc)
}

/// `bodies.csv` and `rollers.csv`.
fn samples_output_bytes(sc: &Scenario) -> f64 {
    let samples = (sc.duration_s / sc.output.sample_interval_s).floor() + 2.0;
    samples * (planned_apples(sc) * BODIES_ROW_BYTES + free_rollers(sc) * ROLLERS_ROW_BYTES)
}

/// The probes' `probe_NAME_trace.csv`, at most a row per sampling instant.
fn probes_output_bytes(sc: &Scenario) -> f64 {
    probe_samples(sc)
        .iter()
        .map(|(_, n)| n * PROBE_ROW_BYTES)
        .sum()
}

/// Refuses a scenario whose output is estimated beyond `max_output_mb`, naming the field to
/// change (a sample interval of 1e-9 s over 1 ms wrote a 97 MB `bodies.csv` for one apple; a
/// probe at 10 MHz wrote 573 MB of trace in two seconds of line: its `sample_rate_hz` is named
/// when its trace is the larger part).
pub fn check_output(sc: &Scenario, max_output_mb: f64) -> Result<(), ScenarioError> {
    let bytes = output_bytes(sc);
    if bytes > max_output_mb * 1024.0 * 1024.0 {
        if let Some((k, samples)) = largest_probe(sc) {
            if samples * PROBE_ROW_BYTES >= samples_output_bytes(sc) {
                return Err(probe_refusal(
                    sc,
                    k,
                    samples,
                    &format!(
                        "about {:.1} GiB of probe_NAME_trace.csv ({PROBE_ROW_BYTES} bytes per row; the run's output {:.1} GiB in all)",
                        samples * PROBE_ROW_BYTES / GIB,
                        bytes / GIB
                    ),
                    &format!("model.max_output_mb = {max_output_mb} MiB"),
                ));
            }
        }
        return Err(ScenarioError::invalid(
            "output.sample_interval_s",
            format!(
                "{} s over {} s for {:.3e} apples{} writes about {:.1} GiB of bodies.csv ({} bytes per apple per sample){}, more than model.max_output_mb = {max_output_mb} MiB: sample less often, or raise model.max_output_mb",
                sc.output.sample_interval_s,
                sc.duration_s,
                planned_apples(sc),
                rollers_part(sc, " and {} free-turning rollers"),
                bytes / (1024.0 * 1024.0 * 1024.0),
                BODIES_ROW_BYTES,
                rollers_part(sc, " and rollers.csv")
            ),
        ));
    }
    Ok(())
}

/// `text` (with `{}` replaced by the count) if `sc` has free-turning rollers, else nothing.
fn rollers_part(sc: &Scenario, text: &str) -> String {
    match free_rollers(sc) {
        n if n > 0.0 => text.replace("{}", &n.to_string()),
        _ => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `rollers.csv` counts in the output estimate: one apple sampled every 1e-6 s for 1 s writes
    /// about 191 MiB of bodies.csv (under the default 4 GiB), but a bed of 1000 free-turning
    /// rollers adds 1000 rows of rollers.csv a sample (about 93 GiB): refused, the message
    /// naming both files and the rollers.
    #[test]
    fn free_rollers_count_in_the_output_estimate() {
        let scenario = |free: bool| -> Scenario {
            let turning = if free {
                r#", "free_turning": {"moment_of_inertia_kg_m2": 1e-3}"#
            } else {
                ""
            };
            crate::scenario::from_json(
                &format!(
                    r#"{{"duration_s": 1, "time_step_s": 1e-6, "gravity_m_s2": [0, 0, -9.81],
                    "output": {{"sample_interval_s": 1e-6}},
                    "materials": {{"apple": {{"shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800}},
                                   "steel": {{"youngs_modulus_pa": 2e11, "poisson_ratio": 0.28}}}},
                    "contact": {{"friction": 0.3, "ke": 0.09, "lambda_s_m": 1000}},
                    "apples": [{{"name": "a", "material": "apple", "diameter_m": 0.08, "position_m": [0, -1, 1]}}],
                    "surfaces": [{{"type": "roller_bed", "name": "bed", "material": "steel", "radius_m": 0.01,
                      "length_m": 0.3, "position_m": [0, 0, 0], "axis": [0, 1, 0], "pitch_m": 0.03,
                      "pitch_direction": [1, 0, 0], "count": 1000{turning}}}]}}"#
                ),
                "test",
            )
            .unwrap()
        };
        let (powered, free) = (scenario(false), scenario(true));
        assert_eq!(free_rollers(&powered), 0.0);
        assert_eq!(free_rollers(&free), 1000.0);
        let samples = 1e6 + 2.0;
        assert_eq!(output_bytes(&powered), samples * BODIES_ROW_BYTES);
        assert_eq!(
            output_bytes(&free),
            samples * (BODIES_ROW_BYTES + 1000.0 * ROLLERS_ROW_BYTES)
        );
        assert!(check_output(&powered, DEFAULT_MAX_OUTPUT_MB).is_ok());
        let e = check_output(&free, DEFAULT_MAX_OUTPUT_MB)
            .unwrap_err()
            .to_string();
        assert!(e.contains("output.sample_interval_s"), "{e}");
        assert!(
            e.contains("1.000e0 apples and 1000 free-turning rollers"),
            "{e}"
        );
        assert!(
            e.contains("of bodies.csv (200 bytes per apple per sample) and rollers.csv"),
            "{e}"
        );
    }
}
