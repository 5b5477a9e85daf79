//! `applesim merge OUT`: one table of the whole batch, `OUT/merged.csv`.
//!
//! One row per run of `OUT/batch.json`, in expansion order: `index`, `id`, `status` (`ok`,
//! `failed`, `missing`), one column per varied parameter, then every key of the runs'
//! `summary.json` `metrics` (the union over runs, sorted; empty where a run has no such key),
//! and last `error` (the message of a failed run). Metrics are copied as written in
//! summary.json, digit for digit; `wall_time_s` is not a metric, so the same batch merges to the
//! same bytes however, wherever and in whatever order its runs ran.

use super::manifest::{self, FailedRun, Manifest};
use super::BatchError;
use crate::output::atomic::AtomicCsv;
use serde::Deserialize;
use serde_json::value::RawValue;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// File name of the table, in the output folder.
pub const MERGED: &str = "merged.csv";

/// State of one run in the table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Finished: its folder holds summary.json.
    Ok,
    /// Failed: `runs/<id>.failed.json` says why.
    Failed,
    /// Neither: not run yet (another shard, a killed batch), or its files were removed.
    Missing,
}

impl Status {
    /// The word in the `status` column.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Failed => "failed",
            Status::Missing => "missing",
        }
    }
}

/// What a merge found.
#[derive(Debug, Clone, Default)]
pub struct MergeReport {
    /// The table written.
    pub csv: PathBuf,
    /// Rows (runs of the batch).
    pub rows: usize,
    /// Runs that finished.
    pub ok: usize,
    /// Failed runs: (index, id, error).
    pub failed: Vec<(usize, String, String)>,
    /// Runs with neither results nor a failure record: (index, id).
    pub missing: Vec<(usize, String)>,
}

#[derive(Deserialize)]
struct SummaryMetrics {
    #[serde(default)]
    metrics: BTreeMap<String, Box<RawValue>>,
}

/// A parameter value as a cell: strings bare, numbers as written, anything else (vectors,
/// objects) as compact JSON.
pub fn cell(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Null => String::new(),
        other => other.to_string(),
    }
}

/// Merges the runs of the batch in `out` into `out/merged.csv` (written whole or not at all).
pub fn merge(out: &Path) -> Result<MergeReport, BatchError> {
    let manifest = Manifest::read(out)?;
    let mut rows: Vec<(Status, BTreeMap<String, Box<RawValue>>, String)> = Vec::new();
    let mut report = MergeReport {
        csv: out.join(MERGED),
        rows: manifest.runs.len(),
        ..MergeReport::default()
    };
    for run in &manifest.runs {
        let summary = manifest::run_dir(out, &run.id).join("summary.json");
        let failed = manifest::failed_path(out, &run.id);
        let row = if summary.is_file() {
            let bytes = std::fs::read(&summary).map_err(|source| BatchError::Io {
                path: summary.clone(),
                source,
            })?;
            let s: SummaryMetrics =
                serde_json::from_slice(&bytes).map_err(|e| BatchError::Output {
                    path: summary.clone(),
                    message: format!("unreadable summary: {e}"),
                })?;
            report.ok += 1;
            (Status::Ok, s.metrics, String::new())
        } else if failed.is_file() {
            let error = std::fs::read(&failed)
                .ok()
                .and_then(|b| serde_json::from_slice::<FailedRun>(&b).ok())
                .map(|f| f.error)
                .unwrap_or_else(|| format!("(unreadable failure record {})", failed.display()));
            report
                .failed
                .push((run.index, run.id.clone(), error.clone()));
            (Status::Failed, BTreeMap::new(), error)
        } else {
            report.missing.push((run.index, run.id.clone()));
            (Status::Missing, BTreeMap::new(), String::new())
        };
        rows.push(row);
    }
    let keys: BTreeSet<&String> = rows.iter().flat_map(|(_, m, _)| m.keys()).collect();

    let io = |source| BatchError::Io {
        path: report.csv.clone(),
        source,
    };
    let csv_err = |e: csv::Error| BatchError::Io {
        path: report.csv.clone(),
        source: std::io::Error::other(e),
    };
    let mut header: Vec<&str> = vec!["index", "id", "status"];
    header.extend(manifest.parameters.iter().map(|p| p.name.as_str()));
    header.extend(keys.iter().map(|k| k.as_str()));
    header.push("error");
    let mut w = AtomicCsv::create(&report.csv, &header).map_err(io)?;
    for (run, (status, metrics, error)) in manifest.runs.iter().zip(&rows) {
        let mut rec: Vec<String> = vec![
            run.index.to_string(),
            run.id.clone(),
            status.as_str().into(),
        ];
        rec.extend(
            manifest
                .parameters
                .iter()
                .map(|p| run.params.get(&p.name).map(cell).unwrap_or_default()),
        );
        rec.extend(keys.iter().map(|k| {
            metrics
                .get(*k)
                .map(|v| v.get().to_string())
                .unwrap_or_default()
        }));
        rec.push(error.clone());
        w.write_record(&rec).map_err(csv_err)?;
    }
    w.commit().map_err(io)?;
    Ok(report)
}
