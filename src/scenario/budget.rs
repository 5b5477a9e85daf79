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

/// How many apples a run of `sc` can hold: the listed ones, every generator's count and every
/// source's count (counted, not generated: this is what must be checked before generating).
pub fn planned_apples(sc: &Scenario) -> f64 {
    let generated: f64 = sc.generators.iter().map(GeneratorSpec::count).sum();
    let fed: f64 = sc.sources.iter().map(|s| f64::from(s.count)).sum();
    sc.apples.len() as f64 + generated + fed
}

/// The memory a run of `sc` is estimated to need (bytes).
pub fn memory_bytes(sc: &Scenario) -> f64 {
    let per_apple = BYTES_PER_APPLE
        + if sc.output.force_history {
            HISTORY_BYTES_PER_APPLE
        } else {
            0.0
        };
    planned_apples(sc) * per_apple
}

/// Refuses a scenario whose estimated memory exceeds `max_memory_mb`, naming the field to change.
pub fn check_memory(sc: &Scenario, max_memory_mb: f64) -> Result<(), ScenarioError> {
    let bytes = memory_bytes(sc);
    let limit = max_memory_mb * 1024.0 * 1024.0;
    if bytes > limit {
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
                bytes / planned_apples(sc) / 1024.0,
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
/// row per apple per sample (the other files grow with the contacts, far less).
pub fn output_bytes(sc: &Scenario) -> f64 {
    let samples = (sc.duration_s / sc.output.sample_interval_s).floor() + 2.0;
    samples * planned_apples(sc) * BODIES_ROW_BYTES
}

/// Refuses a scenario whose output is estimated beyond `max_output_mb`, naming the field to
/// change (a sample interval of 1e-9 s over 1 ms wrote a 97 MB `bodies.csv` for one apple).
pub fn check_output(sc: &Scenario, max_output_mb: f64) -> Result<(), ScenarioError> {
    let bytes = output_bytes(sc);
    if bytes > max_output_mb * 1024.0 * 1024.0 {
        return Err(ScenarioError::invalid(
            "output.sample_interval_s",
            format!(
                "{} s over {} s for {:.3e} apples writes about {:.1} GiB of bodies.csv ({} bytes per apple per sample), more than model.max_output_mb = {max_output_mb} MiB: sample less often, or raise model.max_output_mb",
                sc.output.sample_interval_s,
                sc.duration_s,
                planned_apples(sc),
                bytes / (1024.0 * 1024.0 * 1024.0),
                BODIES_ROW_BYTES
            ),
        ));
    }
    Ok(())
}
