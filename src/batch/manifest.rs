//! The files a batch keeps beside its runs: `OUT/batch.json` (the expansion, so that
//! `applesim merge OUT` knows every run that should exist without the spec),
//! `OUT/runs/<id>/params.json` and `OUT/runs/<id>.failed.json`.

use super::spec::{Batch, Parameter};
use super::BatchError;
use crate::output::atomic;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// File name of the manifest in the output folder.
pub const MANIFEST: &str = "batch.json";
/// Sub-folder holding one folder per run.
pub const RUNS: &str = "runs";
/// File name of a run's parameters, in its folder.
pub const PARAMS: &str = "params.json";

/// One run as listed in `batch.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestRun {
    /// Position in expansion order.
    pub index: usize,
    /// Run id (folder name under `runs/`).
    pub id: String,
    /// Parameter values by name.
    pub params: BTreeMap<String, Value>,
}

/// `batch.json`: what the batch is made of. Written from the spec alone (no paths, no times),
/// so every shard of a cluster job writes the same bytes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// applesim version that expanded the spec.
    pub applesim_version: String,
    /// The spec's description.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// The varied parameters, in column order.
    pub parameters: Vec<Parameter>,
    /// Every run of the batch, in expansion order (all shards).
    pub runs: Vec<ManifestRun>,
}

impl Manifest {
    /// The manifest of an expanded batch.
    pub fn of(batch: &Batch) -> Manifest {
        Manifest {
            applesim_version: env!("CARGO_PKG_VERSION").to_string(),
            description: batch.description.clone(),
            parameters: batch.parameters.clone(),
            runs: batch
                .runs
                .iter()
                .map(|r| ManifestRun {
                    index: r.index,
                    id: r.id.clone(),
                    params: r.params(&batch.parameters),
                })
                .collect(),
        }
    }

    /// Reads `OUT/batch.json`.
    pub fn read(out: &Path) -> Result<Manifest, BatchError> {
        let path = out.join(MANIFEST);
        let bytes = std::fs::read(&path).map_err(|e| BatchError::Output {
            path: path.clone(),
            message: format!("{e}: is this the --out folder of an `applesim batch`?"),
        })?;
        serde_json::from_slice(&bytes).map_err(|e| BatchError::Output {
            path,
            message: format!("not a batch manifest: {e}"),
        })
    }

    /// Writes `OUT/batch.json` unless it already holds exactly this manifest. Returns whether
    /// an older, different manifest was replaced (the spec changed: runs whose scenario did not
    /// change keep their id and are reused).
    pub fn write(&self, out: &Path) -> Result<bool, BatchError> {
        let path = out.join(MANIFEST);
        let bytes = pretty(self)?;
        let old = std::fs::read(&path).ok();
        if old.as_deref() == Some(&bytes[..]) {
            return Ok(false);
        }
        if let Err(source) = atomic::write_file(&path, &bytes) {
            // Another shard may have written the same file at the same moment.
            if std::fs::read(&path).ok().as_deref() != Some(&bytes[..]) {
                return Err(BatchError::Io { path, source });
            }
        }
        Ok(old.is_some())
    }
}

/// `runs/<id>/params.json`: the varied values of one run, beside its results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunParams {
    /// Position in expansion order when it ran (`batch.json` is authoritative if the spec was
    /// changed since).
    pub index: usize,
    /// Run id.
    pub id: String,
    /// Parameter values by name.
    pub params: BTreeMap<String, Value>,
}

/// `runs/<id>.failed.json`: why a run failed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailedRun {
    /// Position in expansion order.
    pub index: usize,
    /// Run id.
    pub id: String,
    /// Parameter values by name.
    pub params: BTreeMap<String, Value>,
    /// The error, as `applesim run` would print it; for a run whose process ended otherwise
    /// (an abort, a signal, out of memory), how it ended and its last words.
    pub error: String,
    /// Exit code of the run's process, when it exited without an answer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exit_code: Option<i32>,
    /// Signal that ended the run's process (6: SIGABRT, an abort such as a failed
    /// allocation; 9: SIGKILL, a user, a scheduler or the out-of-memory killer).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub signal: Option<i32>,
    /// Name of that signal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub signal_name: Option<String>,
    /// The end of the run's process's standard error (a panic's or an abort's message).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub stderr: String,
}

/// Pretty JSON with a final newline.
pub fn pretty<T: Serialize>(v: &T) -> Result<Vec<u8>, BatchError> {
    let mut bytes = serde_json::to_vec_pretty(v).map_err(|e| BatchError::Output {
        path: PathBuf::new(),
        message: e.to_string(),
    })?;
    bytes.push(b'\n');
    Ok(bytes)
}

/// `OUT/runs/<id>` (the folder of a finished run).
pub fn run_dir(out: &Path, id: &str) -> PathBuf {
    out.join(RUNS).join(id)
}

/// `OUT/runs/<id>.failed.json`.
pub fn failed_path(out: &Path, id: &str) -> PathBuf {
    out.join(RUNS).join(format!("{id}.failed.json"))
}

/// Whether run `id` finished: its folder exists (it appears only by the folder switch) and
/// holds `summary.json`.
pub fn is_done(out: &Path, id: &str) -> bool {
    run_dir(out, id).join("summary.json").is_file()
}
