//! What a scenario will cost, estimated before anything is built: how many apples it can hold and
//! the memory they need. A scenario beyond the limit is refused with the estimate at once,
//! instead of allocating for minutes and aborting (a source of 1e9 apples asked for 152 GB).
//!
//! The figure per apple is measured, with a margin: the 8036-apple reference pile peaks at
//! 41.5 MiB and the 1000-apple one at 11.2 MiB (docs/performance.md), 4.4 KiB per added apple
//! (rapier's body, the layer's per-apple arrays, about seven open contacts, the finished contacts
//! of a 5 s run); a force history adds up to 64 KiB per contact (4096 samples of time and force)
//! with `output.force_history: "full"`, far less with impact histories (the default up to 50 apples).
//!
//! The output files are estimated file by file ([`output_estimate`]) at the scenario's precision
//! and compression: the same estimate refuses a run beyond `model.max_output_mb` and is printed
//! before a large run.

use super::{ForceHistory, GeneratorSpec, Precision, Scenario, ScenarioError};

/// Memory an apple costs while a run holds it, contacts and records included (bytes; measured
/// 4.4 KiB, see the module documentation).
pub const BYTES_PER_APPLE: f64 = 8.0 * 1024.0;

/// Memory a kept force history costs per apple (bytes) with `output.force_history: "full"`: one
/// contact's full history (4096 samples of time and force).
pub const HISTORY_BYTES_PER_APPLE: f64 = 64.0 * 1024.0;

/// Memory impact histories (`true`) cost per apple (bytes): [`CONTACTS_PER_APPLE`] contacts
/// of [`IMPACT_HISTORY_SAMPLES`] samples of 16 bytes.
pub const IMPACT_HISTORY_BYTES_PER_APPLE: f64 = CONTACTS_PER_APPLE * IMPACT_HISTORY_SAMPLES * 16.0;

/// Default limit of the estimated memory of a run (MiB): `model.max_memory_mb`.
pub const DEFAULT_MAX_MEMORY_MB: f64 = 8192.0;

/// Default limit of the estimated size of a run's output files (MiB): `model.max_output_mb`.
pub const DEFAULT_MAX_OUTPUT_MB: f64 = 4096.0;

/// Bytes of one row of `bodies.csv` at full precision (measured: 283 on the 150-apple bin fill,
/// 189 on the 1000-apple pile, 154 on the handling line; the largest, rounded up).
pub const BODIES_ROW_BYTES: f64 = 290.0;

/// Bytes of one row of `bodies.csv` at 9 significant digits (measured: 183 on the 150-apple bin
/// fill; rounded up). Other precisions are interpolated between this and [`BODIES_ROW_BYTES`]
/// by the digits.
pub const BODIES_ROW_BYTES_9: f64 = 190.0;

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

/// Contacts a run holds per apple (measured: 18.5 on the 150-apple bin fill, 2782 contacts; 2.6
/// apple-apple ones per apple in the 1000-apple pile; rounded up).
pub const CONTACTS_PER_APPLE: f64 = 20.0;

/// Bytes of a row of `contacts.csv` at 9 digits (measured: 513 on the bin fill).
pub const CONTACT_ROW_BYTES: f64 = 520.0;

/// Bytes per contact of `apple_contacts.csv` at 9 digits (measured: 441 on the bin fill).
pub const APPLE_CONTACT_ROW_BYTES: f64 = 450.0;

/// Bytes per contact of `summary.json` (its `contacts` list, in full precision; measured: 2096
/// on the bin fill, the rest of the file small beside it).
pub const SUMMARY_BYTES_PER_CONTACT: f64 = 2100.0;

/// Samples of a contact's default (impact) force history (measured: a mean of 98.5 on the bin
/// fill, whose apple-apple impacts last 26 ms at the median; rounded up).
pub const IMPACT_HISTORY_SAMPLES: f64 = 100.0;

/// Samples of a contact's `"full"` force history (measured: a mean of 674 on the bin fill, at
/// most 4096).
pub const FULL_HISTORY_SAMPLES: f64 = 700.0;

/// Bytes of one row of `forces.csv` at 9 digits (contact index, names, time, force; measured:
/// 44 on the bin fill).
pub const FORCES_ROW_BYTES: f64 = 45.0;

/// Size of a gzipped CSV over the plain one (`output.compress`; measured on the bin fill's files
/// at 9 digits: bodies.csv 0.30, forces.csv 0.22, contacts.csv 0.38, apple_contacts.csv 0.27,
/// transitions.csv 0.35; the share of the largest).
pub const GZIP_RATIO: f64 = 0.3;

/// What summary.json holds beside its contact list, as a share of the whole (measured: 0.17 on
/// the bin fill): its size with `output.compress`, which writes the list gzipped beside it.
pub const SUMMARY_SHARE_BESIDE_CONTACTS: f64 = 0.2;

/// The estimate is printed before a run (`applesim run`) when it reaches this many MB.
pub const ESTIMATE_SHOWN_MB: f64 = 20.0;

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

/// The memory a kept force history costs per apple (bytes; 0 without).
fn history_bytes_per_apple(sc: &Scenario) -> f64 {
    match sc.force_history() {
        ForceHistory::Full => HISTORY_BYTES_PER_APPLE,
        ForceHistory::Impact => IMPACT_HISTORY_BYTES_PER_APPLE,
        ForceHistory::Off => 0.0,
    }
}

/// The memory a run of `sc` is estimated to need (bytes): its apples, and its probes' traces.
pub fn memory_bytes(sc: &Scenario) -> f64 {
    apples_memory_bytes(sc) + probes_memory_bytes(sc)
}

fn apples_memory_bytes(sc: &Scenario) -> f64 {
    planned_apples(sc) * (BYTES_PER_APPLE + history_bytes_per_apple(sc))
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
                match sc.force_history() {
                    ForceHistory::Full => " with whole force histories; output.force_history: true (the impacts only) or false saves most of it",
                    ForceHistory::Impact => " with impact force histories; output.force_history: false saves them",
                    ForceHistory::Off => "",
                }
            ),
        ));
    }
    Ok(())
}

/// One output file's estimated size.
#[derive(Debug, Clone, PartialEq)]
pub struct FileEstimate {
    /// The file's name as written (`bodies.csv.gz` when compressed).
    pub name: String,
    /// Bytes.
    pub bytes: f64,
}

/// The estimated output of a run: its largest files, largest first.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputEstimate {
    /// The files (those that grow with the run: samples and contacts).
    pub files: Vec<FileEstimate>,
}

impl OutputEstimate {
    /// Bytes of all the files.
    pub fn total_bytes(&self) -> f64 {
        self.files.iter().map(|f| f.bytes).sum()
    }

    /// One line: `about 24 MB in 6 files (bodies.csv 14 MB, summary.json 7 MB, ...)`.
    pub fn line(&self) -> String {
        let mb = |b: f64| {
            let m = b / 1e6;
            if m >= 10.0 {
                format!("{m:.0} MB")
            } else {
                format!("{m:.1} MB")
            }
        };
        let parts: Vec<String> = self
            .files
            .iter()
            .map(|f| format!("{} {}", f.name, mb(f.bytes)))
            .collect();
        format!(
            "about {} in {} files ({})",
            mb(self.total_bytes()),
            self.files.len(),
            parts.join(", ")
        )
    }
}

/// Bytes of a `bodies.csv` row at the scenario's precision.
pub fn bodies_row_bytes(sc: &Scenario) -> f64 {
    match sc.output.precision {
        Precision::Full => BODIES_ROW_BYTES,
        Precision::Digits(n) => {
            let per_digit = (BODIES_ROW_BYTES - BODIES_ROW_BYTES_9) / (17.0 - 9.0);
            (BODIES_ROW_BYTES_9 + per_digit * (f64::from(n) - 9.0)).max(60.0)
        }
    }
}

/// The estimated output files of a run of `sc`, from the scenario alone: `bodies.csv` (one row
/// per apple per sample), `rollers.csv` (one per free-turning roller per sample), and by
/// [`CONTACTS_PER_APPLE`] the contacts' files (`contacts.csv`, `apple_contacts.csv`,
/// `forces.csv` by the force histories kept, and `summary.json`; the others, a few per cent of a
/// run's output, are left out). Each CSV is counted at the
/// scenario's precision, and gzipped at [`GZIP_RATIO`] with `output.compress`. What the output
/// budget (`model.max_output_mb`) and the estimate `applesim run` prints are taken from.
pub fn output_estimate(sc: &Scenario) -> OutputEstimate {
    let samples = super::output::samples(sc.duration_s, sc.sample_interval_s());
    let apples = planned_apples(sc);
    let contacts = apples * CONTACTS_PER_APPLE;
    let full = sc.output.precision == Precision::Full;
    let digits_scale = bodies_row_bytes(sc) / BODIES_ROW_BYTES_9;
    let gz = if sc.output.compress { GZIP_RATIO } else { 1.0 };
    let csv = |name: &str, bytes: f64| FileEstimate {
        name: if sc.output.compress {
            format!("{name}.gz")
        } else {
            name.to_string()
        },
        bytes: bytes * gz,
    };
    let mut files = vec![csv("bodies.csv", samples * apples * bodies_row_bytes(sc))];
    let rollers = free_rollers(sc);
    if rollers > 0.0 {
        let row = if full {
            ROLLERS_ROW_BYTES
        } else {
            0.7 * ROLLERS_ROW_BYTES
        };
        files.push(csv("rollers.csv", samples * rollers * row));
    }
    let history = match sc.force_history() {
        ForceHistory::Full => FULL_HISTORY_SAMPLES,
        ForceHistory::Impact => IMPACT_HISTORY_SAMPLES,
        ForceHistory::Off => 0.0,
    };
    if history > 0.0 {
        files.push(csv(
            "forces.csv",
            contacts * history * FORCES_ROW_BYTES * digits_scale,
        ));
    }
    files.push(csv(
        "contacts.csv",
        contacts * CONTACT_ROW_BYTES * digits_scale,
    ));
    files.push(csv(
        "apple_contacts.csv",
        contacts * APPLE_CONTACT_ROW_BYTES * digits_scale,
    ));
    let summary = contacts * SUMMARY_BYTES_PER_CONTACT;
    if sc.output.compress {
        // The contact list gzipped beside summary.json (`output::CONTACTS_JSON_GZ`).
        files.push(FileEstimate {
            name: "summary.json".into(),
            bytes: summary * SUMMARY_SHARE_BESIDE_CONTACTS,
        });
        files.push(FileEstimate {
            name: "contacts.json.gz".into(),
            bytes: summary * GZIP_RATIO,
        });
    } else {
        files.push(FileEstimate {
            name: "summary.json".into(),
            bytes: summary,
        });
    }
    for (k, n) in probe_samples(sc) {
        files.push(csv(
            &format!(
                "{}_trace.csv",
                crate::record::probe::file_stem(&sc.apples[k].name)
            ),
            n * PROBE_ROW_BYTES,
        ));
    }
    files.sort_by(|a, b| b.bytes.total_cmp(&a.bytes).then(a.name.cmp(&b.name)));
    OutputEstimate { files }
}

/// The size of the output files a run of `sc` is estimated to write (bytes; [`output_estimate`]).
pub fn output_bytes(sc: &Scenario) -> f64 {
    output_estimate(sc).total_bytes()
}

/// Whether `applesim run` prints the estimate before running: when it reaches
/// [`ESTIMATE_SHOWN_MB`].
pub fn estimate_worth_showing(sc: &Scenario) -> bool {
    output_bytes(sc) >= ESTIMATE_SHOWN_MB * 1e6
}

/// Refuses a scenario whose output is estimated beyond `max_output_mb`, naming the field to
/// change (a sample interval of 1e-9 s over 1 ms wrote a 97 MB `bodies.csv` for one apple; a
/// probe at 10 MHz wrote 573 MB of trace in two seconds of line: its `sample_rate_hz` is named
/// when its trace is the larger part).
pub fn check_output(sc: &Scenario, max_output_mb: f64) -> Result<(), ScenarioError> {
    let estimate = output_estimate(sc);
    let bytes = estimate.total_bytes();
    if bytes > max_output_mb * 1024.0 * 1024.0 {
        // A probe's trace the larger part: its sampling rate is the field to change.
        let samples_bytes: f64 = estimate
            .files
            .iter()
            .filter(|f| f.name.starts_with("bodies.csv") || f.name.starts_with("rollers.csv"))
            .map(|f| f.bytes)
            .sum();
        if let Some((k, samples)) = largest_probe(sc) {
            if samples * PROBE_ROW_BYTES >= samples_bytes {
                return Err(probe_refusal(
                    sc,
                    k,
                    samples,
                    &format!(
                        "about {:.1} GiB of its trace file ({PROBE_ROW_BYTES} bytes per row; the run's output {:.1} GiB in all)",
                        samples * PROBE_ROW_BYTES / GIB,
                        bytes / GIB
                    ),
                    &format!("model.max_output_mb = {max_output_mb} MiB"),
                ));
            }
        }
        // The contacts' files the larger part: they grow with the apples, not the sampling; the
        // field that brings the most apples is the one to change.
        if samples_bytes < bytes / 2.0 {
            let (field, n) = largest_apple_field(sc);
            return Err(ScenarioError::invalid(
                field,
                format!(
                    "{n} apples ({:.3e} in all) write about {CONTACTS_PER_APPLE} contacts each, {}, more than model.max_output_mb = {max_output_mb} MiB: the contact files grow with the apples, not the sampling: fewer apples, or raise model.max_output_mb",
                    planned_apples(sc),
                    estimate.line(),
                ),
            ));
        }
        let interval = sc.sample_interval_s();
        return Err(ScenarioError::invalid(
            "output.sample_interval_s",
            format!(
                "{} s{} over {} s for {:.3e} apples{} writes {}, more than model.max_output_mb = {max_output_mb} MiB: sample less often, or raise model.max_output_mb",
                interval,
                if sc.output.sample_interval_s.is_none() { " (the default)" } else { "" },
                sc.duration_s,
                planned_apples(sc),
                rollers_part(sc, " and {} free-turning rollers"),
                estimate.line(),
            ),
        ));
    }
    Ok(())
}

/// The field that brings the most apples, as the user wrote it, and how many: a source's
/// `count`, a generator's `count`, or the `apples` list.
fn largest_apple_field(sc: &Scenario) -> (String, f64) {
    let mut best = ("apples".to_string(), sc.apples.len() as f64);
    for (k, g) in sc.generators.iter().enumerate() {
        if g.count() > best.1 {
            let key = match g {
                GeneratorSpec::File(_) => "file",
                _ => "count",
            };
            best = (format!("generators[{k}].{key}"), g.count());
        }
    }
    for (k, src) in sc.sources.iter().enumerate() {
        if f64::from(src.count) > best.1 {
            best = (format!("sources[{k}].count"), f64::from(src.count));
        }
    }
    best
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
    /// about 190 MB of bodies.csv (under the default 4 GiB), but a bed of 1000 free-turning
    /// rollers adds 1000 rows of rollers.csv a sample (about 70 GB): refused, the message
    /// naming the rollers and the files.
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
        let bodies = |sc: &Scenario| {
            output_estimate(sc)
                .files
                .iter()
                .find(|f| f.name == "bodies.csv")
                .unwrap()
                .bytes
        };
        assert_eq!(bodies(&powered), samples * BODIES_ROW_BYTES_9);
        let rollers = |sc: &Scenario| {
            output_estimate(sc)
                .files
                .iter()
                .find(|f| f.name == "rollers.csv")
                .map(|f| f.bytes)
        };
        assert_eq!(rollers(&powered), None);
        assert_eq!(
            rollers(&free),
            Some(samples * 1000.0 * 0.7 * ROLLERS_ROW_BYTES)
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
            e.contains("(rollers.csv 70000 MB, bodies.csv 190 MB"),
            "{e}"
        );
    }

    /// The shipped bin fill without its `output` section (the default 20 ms sampling, 9 digits,
    /// no force histories for its 150 apples): about 35 MB estimated (24.9 MB written,
    /// docs/performance.md); with impact histories about 48 MB (38 MB written); gzipped
    /// the CSV files and summary.json's contact list count 0.3 of it; full precision, whole histories and 1 ms sampling (the
    /// defaults before issue 31) about 1.1 GB (538 MB written: the estimate counts every apple
    /// from the start).
    /// Regression (the issue 28 fuzz campaign at 1800 cases, which then named the exact field in
    /// 97.7 % of its refusals): a source of a million apples was refused naming
    /// `output.sample_interval_s` and told to sample less often, though its output is the
    /// contacts' files (20 contacts an apple), which no sampling changes. The field that brings
    /// the apples is named; a run whose samples are the larger part still names the interval.
    #[test]
    fn a_budget_refusal_names_the_apples_when_the_contacts_files_dominate() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/lines/bin_filling.json"
        );
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        v["sources"][0]["count"] = serde_json::json!(1_000_000);
        let sc = crate::scenario::from_json(&v.to_string(), "bin").unwrap();
        let e = check_output(&sc, 4096.0).unwrap_err().to_string();
        assert!(e.starts_with("sources[0].count: 1000000 apples"), "{e}");
        assert!(e.contains("the contact files grow with the apples"), "{e}");
        v["sources"][0]["count"] = serde_json::json!(150);
        v["output"]["sample_interval_s"] = serde_json::json!(1e-6);
        let sc = crate::scenario::from_json(&v.to_string(), "bin").unwrap();
        let e = check_output(&sc, 4096.0).unwrap_err().to_string();
        assert!(e.starts_with("output.sample_interval_s: "), "{e}");
    }

    #[test]
    fn the_estimate_counts_precision_compression_and_histories() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/lines/bin_filling.json"
        );
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        v.as_object_mut().unwrap().remove("output");
        let sc = |output: serde_json::Value| {
            let mut v = v.clone();
            v["output"] = output;
            crate::scenario::from_json(&v.to_string(), "bin").unwrap()
        };
        let mb = |sc: &Scenario| output_bytes(sc) / 1e6;
        let default = sc(serde_json::json!({}));
        assert!((30.0..40.0).contains(&mb(&default)), "{}", mb(&default));
        let impacts = sc(serde_json::json!({"force_history": true}));
        assert!((40.0..55.0).contains(&mb(&impacts)), "{}", mb(&impacts));
        let gz = sc(serde_json::json!({"compress": true}));
        let summary = 150.0 * CONTACTS_PER_APPLE * SUMMARY_BYTES_PER_CONTACT / 1e6;
        // Gzipped: the CSV files and the contact list; summary.json's rest stays plain.
        let gz_csv = mb(&gz) - summary * SUMMARY_SHARE_BESIDE_CONTACTS;
        assert!((gz_csv / mb(&default) - GZIP_RATIO).abs() < 1e-9);
        let old = sc(
            serde_json::json!({"sample_interval_s": 1e-3, "precision": "full", "force_history": "full"}),
        );
        assert!((900.0..1300.0).contains(&mb(&old)), "{}", mb(&old));
        let line = output_estimate(&gz).line();
        assert!(
            line.starts_with("about ") && line.contains("bodies.csv.gz"),
            "{line}"
        );
        assert!(memory_bytes(&old) > memory_bytes(&default));
    }
}
