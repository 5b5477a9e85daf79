//! Two layouts rerun over paired feed seeds (`applesim audit A B --seeds N`, docs/damage.md
//! section 9): the run-to-run scatter of a comparison.
//!
//! Each layout's scenario (a run folder's `scenario.json`, or a scenario file) becomes a batch
//! of N runs ([`seeded`]): run k (1..N) gives every generator and source that has a seed the
//! seed [`seed_of`]`(k, j)`, j its place among them (generators first, then sources, in the
//! scenario's order): k for the first, k + 2^32 for the second, ... So run k of A and run k of
//! B are fed alike (the same sizes, spawn offsets and timing where their feeds are alike) and
//! their difference is one paired sample, and two feeds of one scenario never draw the same
//! stream. The batches run with the batch machinery ([`super::runner`]): each run in a process of
//! its own, `--jobs` at a time, into `OUT/a/runs/<id>/` and `OUT/b/runs/<id>/`; a rerun of the
//! same command reuses the runs done (ids are hashes of the scenarios).
//!
//! A scenario whose feeds draw nothing from their seeds (fixed sizes, no jitter, no random
//! fill) is refused ([`SeedsError::NoRandomFeed`]): its N runs would be the same run.

use super::runner::{self, Observer, Options};
use super::spec::{self, Mode, ParamSpec, SpecFile};
use super::{manifest, Batch, BatchError};
use crate::scenario::{self, DiameterSpec, GeneratorSpec};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Most seeds a comparison runs (each is a run of both layouts).
pub const MAX_SEEDS: usize = 1000;

/// Errors of a seeded comparison.
#[derive(Debug, thiserror::Error)]
pub enum SeedsError {
    /// The scenario file cannot be read.
    #[error("{path}: {source} (give a run folder written by `applesim run`, or a scenario file)")]
    Read {
        /// The file.
        path: PathBuf,
        /// OS error.
        source: std::io::Error,
    },
    /// The scenario does not parse (the message names the file).
    #[error("{message}")]
    Scenario {
        /// The file.
        path: PathBuf,
        /// The scenario's own message.
        message: String,
    },
    /// No feed of the scenario draws anything from its seed.
    #[error("{path}: no random feed: no generator or source draws anything from its seed (sizes fixed, no `jitter_m`, no random fill), so every seed gives the same run and N runs would be one run N times; compare the two run folders without --seeds (the intervals are then the apple-to-apple scatter), or give a source a `jitter_m` or a size distribution")]
    NoRandomFeed {
        /// The scenario file.
        path: PathBuf,
    },
    /// The two layouts' feeds cannot be paired seed by seed.
    #[error("{a} has {na} seeded feed(s) (generators and sources with a seed) and {b} has {nb}: run k of each must draw the same seeds; give both layouts the same feeds")]
    Unpaired {
        /// Layout A's scenario file.
        a: String,
        /// Its seeded feeds.
        na: usize,
        /// Layout B's scenario file.
        b: String,
        /// Its seeded feeds.
        nb: usize,
    },
    /// Fewer than 2 seeds, or more than [`MAX_SEEDS`].
    #[error("--seeds {0}: give at least 2 (one difference per seed; the interval needs two) and at most {MAX_SEEDS}")]
    SeedCount(usize),
    /// The batch could not be set up or run.
    #[error(transparent)]
    Batch(#[from] BatchError),
    /// Runs failed.
    #[error("{failed} of {runs} runs of {layout} failed ({first}); the errors are in {dir}/<id>.failed.json")]
    Failed {
        /// The layout's scenario file.
        layout: String,
        /// Failed runs.
        failed: usize,
        /// Runs of the layout.
        runs: usize,
        /// The first failure's message.
        first: String,
        /// The `runs/` folder.
        dir: PathBuf,
    },
}

/// One layout to rerun over seeds.
#[derive(Debug, Clone)]
pub struct Layout {
    /// The scenario file (a run folder's `scenario.json`, or the file given).
    pub file: PathBuf,
    /// The scenario as JSON.
    pub scenario: Value,
    /// Where its relative paths (meshes, apple files) resolve: the scenario file's folder.
    pub base_dir: PathBuf,
    /// JSON Pointers of the seeds of its seeded feeds (generators, then sources).
    pub seeds: Vec<String>,
    /// Whether any feed draws from its seed.
    pub random: bool,
}

/// Whether a size spec draws from the seed.
fn spread(d: &DiameterSpec) -> bool {
    match d {
        DiameterSpec::Fixed(_) => false,
        DiameterSpec::Distribution(s) => s.spread_m > 0.0,
    }
}

/// Reads layout `path`: a run folder (its `scenario.json`, relative paths resolved in the
/// folder) or a scenario file.
pub fn layout(path: &Path) -> Result<Layout, SeedsError> {
    let file = if path.is_dir() {
        path.join("scenario.json")
    } else {
        path.to_path_buf()
    };
    let text = std::fs::read_to_string(&file).map_err(|source| SeedsError::Read {
        path: file.clone(),
        source,
    })?;
    let bad = |message: String| SeedsError::Scenario {
        path: file.clone(),
        message,
    };
    let value: Value = serde_json::from_str(&text)
        .map_err(|e| bad(format!("{}: not JSON: {e}", file.display())))?;
    let sc =
        scenario::from_json(&text, &file.display().to_string()).map_err(|e| bad(e.to_string()))?;
    let mut seeds = Vec::new();
    let mut random = false;
    for (k, g) in sc.generators.iter().enumerate() {
        match g {
            GeneratorSpec::Grid(s) => {
                seeds.push(format!("/generators/{k}/seed"));
                random |= s.jitter_m > 0.0 || spread(&s.diameter_m);
            }
            GeneratorSpec::RandomFill(_) => {
                seeds.push(format!("/generators/{k}/seed"));
                random = true;
            }
            GeneratorSpec::File(_) => {}
        }
    }
    for (k, s) in sc.sources.iter().enumerate() {
        seeds.push(format!("/sources/{k}/seed"));
        random |= !s.jitter_m.is_zero() || spread(&s.diameter_m);
    }
    Ok(Layout {
        base_dir: file.parent().map(Path::to_path_buf).unwrap_or_default(),
        file,
        scenario: value,
        seeds,
        random,
    })
}

/// The seed of the `j`-th seeded feed (0-based) in run `k` (1-based): k + 2^32 j.
pub fn seed_of(k: usize, j: usize) -> u64 {
    k as u64 + ((j as u64) << 32)
}

/// The batch of `n` runs of `layout`, run k with every seeded feed's seed [`seed_of`]`(k, j)`
/// (one parameter per feed, zipped, named by its pointer).
pub fn seeded(layout: &Layout, n: usize) -> Result<Batch, SeedsError> {
    if !layout.random {
        return Err(SeedsError::NoRandomFeed {
            path: layout.file.clone(),
        });
    }
    let parameters = layout
        .seeds
        .iter()
        .enumerate()
        .map(|(j, p)| ParamSpec {
            name: Some(p.clone()),
            path: p.clone(),
            values: Some((1..=n).map(|k| Value::from(seed_of(k, j))).collect()),
            range: None,
            group: None,
        })
        .collect();
    let spec = SpecFile {
        description: Some(format!(
            "{}: {n} paired feed seeds (applesim audit --seeds)",
            layout.file.display()
        )),
        base: layout.scenario.clone(),
        mode: Mode::Zip,
        set: BTreeMap::new(),
        parameters,
    };
    Ok(spec::expand(&spec, &layout.file, &layout.base_dir)?)
}

/// Runs layouts `a` and `b` over `n` paired seeds into `out/a` and `out/b` (batches: each run
/// in its own process as `opts` says; runs done before are reused; `observers` hear of A's
/// runs and of B's) and returns each layout's run folders in seed order.
pub fn run_pair(
    a: &Layout,
    b: &Layout,
    n: usize,
    out: &Path,
    opts: &Options,
    observers: [&dyn Observer; 2],
) -> Result<[Vec<PathBuf>; 2], SeedsError> {
    if !(2..=MAX_SEEDS).contains(&n) {
        return Err(SeedsError::SeedCount(n));
    }
    if a.seeds.len() != b.seeds.len() {
        return Err(SeedsError::Unpaired {
            a: a.file.display().to_string(),
            na: a.seeds.len(),
            b: b.file.display().to_string(),
            nb: b.seeds.len(),
        });
    }
    // Both refused before either runs.
    let batches = [seeded(a, n)?, seeded(b, n)?];
    let mut folders: [Vec<PathBuf>; 2] = [Vec::new(), Vec::new()];
    for (((batch, layout), observer), (sub, dirs)) in batches
        .iter()
        .zip([a, b])
        .zip(observers)
        .zip(["a", "b"].into_iter().zip(folders.iter_mut()))
    {
        let dir = out.join(sub);
        let report = runner::run(batch, &dir, opts, observer)?;
        let failed: Vec<&(usize, String, String)> =
            report.failed.iter().chain(&report.failed_before).collect();
        if let Some(first) = failed.first() {
            return Err(SeedsError::Failed {
                layout: layout.file.display().to_string(),
                failed: failed.len(),
                runs: batch.runs.len(),
                first: first.2.clone(),
                dir: dir.join(manifest::RUNS),
            });
        }
        for r in &batch.runs {
            if !manifest::is_done(&dir, &r.id) {
                return Err(SeedsError::Batch(BatchError::Output {
                    path: manifest::run_dir(&dir, &r.id),
                    message: "not finished (another process holds its lock?): run the command again when it is done".into(),
                }));
            }
            dirs.push(manifest::run_dir(&dir, &r.id));
        }
    }
    Ok(folders)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, v: &Value) -> PathBuf {
        std::fs::create_dir_all(dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, v.to_string()).unwrap();
        p
    }

    fn fed(jitter: f64) -> Value {
        serde_json::json!({
            "duration_s": 0.1,
            "time_step_s": "adaptive",
            "gravity_m_s2": [0, 0, -9.81],
            "output": {"sample_interval_s": 0.01},
            "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
            "materials": {"apple": {"preset": "apple-paper"}, "steel": {"preset": "steel"}},
            "sources": [{"name": "feed", "material": "apple", "diameter_m": 0.075,
                         "position_m": [0, 0, 0.2], "jitter_m": jitter, "rate_per_s": 10,
                         "count": 2, "seed": 3}],
            "generators": [{"type": "grid", "name": "g", "material": "apple", "diameter_m": 0.07,
                            "count": [1, 1, 1], "spacing_m": [0.1, 0.1, 0.1],
                            "origin_m": [1, 0, 0.2]}],
            "surfaces": [{"name": "plate", "type": "box", "material": "steel",
                          "size_m": [3, 1, 0.02], "position_m": [0, 0, -0.01]}]
        })
    }

    #[test]
    fn run_k_seeds_every_feed_and_a_fixed_feed_is_refused() {
        let dir = std::env::temp_dir().join(format!("applesim-seeds-{}", std::process::id()));
        let p = write(&dir, "fed.json", &fed(0.01));
        let l = layout(&p).unwrap();
        assert_eq!(l.seeds, ["/generators/0/seed", "/sources/0/seed"]);
        assert!(l.random);
        let b = seeded(&l, 3).unwrap();
        assert_eq!(b.runs.len(), 3);
        let sc = b.runs[2].scenario.as_ref().unwrap();
        assert_eq!(sc["generators"][0]["seed"], 3);
        assert_eq!(sc["sources"][0]["seed"], 3 + (1u64 << 32));
        assert_eq!(b.base_dir, dir);
        let fixed = layout(&write(&dir, "fixed.json", &fed(0.0))).unwrap();
        let e = seeded(&fixed, 3).unwrap_err().to_string();
        assert!(e.contains("fixed.json: no random feed"), "{e}");
        let e = run_pair(&l, &l, 1, &dir, &Options::default(), [&runner::Silent; 2])
            .unwrap_err()
            .to_string();
        assert!(e.contains("--seeds 1: give at least 2"), "{e}");
        let mut one = fed(0.01);
        one["generators"] = serde_json::json!([]);
        let one = layout(&write(&dir, "one.json", &one)).unwrap();
        let e = run_pair(&l, &one, 3, &dir, &Options::default(), [&runner::Silent; 2])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("has 2 seeded feed(s)") && e.contains("has 1"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
