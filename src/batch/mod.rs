//! Scripted scenario batches: sweeps of a base scenario (or a folder of scenarios) run in
//! parallel, resumable after a crash, split into shards over a cluster job array, and merged
//! into one table. User guide: docs/batch.md.
//!
//! Data flow: [`spec`] expands a spec into runs (each an expanded scenario with a stable
//! [`id`]); [`runner`] runs this [`shard`]'s share of them into `OUT/runs/<id>/`, each run in a
//! process of its own ([`isolate`]) under a lock, each folder switched in whole;
//! [`merge`](mod@merge) reads `OUT/batch.json` and every run's `summary.json` into
//! `OUT/merged.csv`. [`seeds`] reruns two layouts over paired feed seeds as two such batches
//! (`applesim audit A B --seeds N`).

pub mod id;
pub mod isolate;
pub mod manifest;
pub mod merge;
pub mod pointer;
pub mod runner;
pub mod seeds;
pub mod shard;
pub mod spec;

pub use isolate::Isolation;
pub use merge::{merge, MergeReport};
pub use runner::{Observer, Options, Outcome, Report, Skip};
pub use shard::Shard;
pub use spec::{load, Batch, Parameter, PlannedRun};

use std::path::PathBuf;

/// Errors of a batch as a whole (a failing run is not one: it is recorded and the batch goes on).
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    /// The spec is wrong: the field at fault and what is wrong with it.
    #[error("{file}: {field}: {message}")]
    Spec {
        /// The spec file (or folder).
        file: String,
        /// JSON path of the field in the spec (`parameters[2].range`).
        field: String,
        /// What is wrong and what would be right.
        message: String,
    },
    /// A file or folder could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// OS error.
        source: std::io::Error,
    },
    /// The output folder is not what a batch writes.
    #[error("{path}: {message}")]
    Output {
        /// The file or folder.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}
