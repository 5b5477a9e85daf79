//! Shards: a deterministic, balanced share of a batch for one task of a cluster job array.
//!
//! Run `k` (0-based, in expansion order) belongs to shard `k mod n` (printed 1-based as
//! `k mod n + 1` / `n`). Every run is in exactly one shard, shard sizes differ by at most one,
//! and because neighbouring runs of a sweep go to different shards, slow corners of the grid
//! (big apples, long contacts) are spread over all of them rather than landing on one.

use std::fmt;

/// One share of a batch: runs whose index is `index` modulo `count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// 0-based shard index, `< count`.
    pub index: usize,
    /// Number of shards, `>= 1`.
    pub count: usize,
}

/// Environment variables read by [`Shard::from_env`].
pub mod env {
    /// Slurm: this task's index in the job array.
    pub const SLURM_ID: &str = "SLURM_ARRAY_TASK_ID";
    /// Slurm: number of tasks in the array.
    pub const SLURM_COUNT: &str = "SLURM_ARRAY_TASK_COUNT";
    /// Slurm: lowest index of the array.
    pub const SLURM_MIN: &str = "SLURM_ARRAY_TASK_MIN";
    /// Slurm: highest index of the array.
    pub const SLURM_MAX: &str = "SLURM_ARRAY_TASK_MAX";
    /// Slurm: step between indices (`--array=0-20:2`).
    pub const SLURM_STEP: &str = "SLURM_ARRAY_TASK_STEP";
    /// Kubernetes indexed Job: this pod's completion index (0-based).
    pub const K8S_INDEX: &str = "JOB_COMPLETION_INDEX";
    /// The number of shards where the scheduler does not say it (a Kubernetes indexed Job
    /// sets no variable with its `completions`): set it to the same number in the pod spec.
    pub const COUNT: &str = "APPLESIM_SHARD_COUNT";
}

impl Shard {
    /// The whole batch.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Parses `i/n` with 1 <= i <= n.
    pub fn parse(s: &str) -> Result<Shard, String> {
        let bad = || format!("--shard '{s}': give i/n with 1 <= i <= n (e.g. 2/8), or 'auto'");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let i: usize = i.trim().parse().map_err(|_| bad())?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        if n == 0 || i == 0 || i > n {
            return Err(bad());
        }
        Ok(Shard {
            index: i - 1,
            count: n,
        })
    }

    /// The shard of this task of a Slurm job array or Kubernetes indexed Job, read through
    /// `var` (the process environment in the binary, a table in tests). `count` (from
    /// `--shard-count`) gives the number of shards; without it Slurm's own variables give it,
    /// and for Kubernetes `APPLESIM_SHARD_COUNT` must. Returns the shard and a line saying
    /// where it came from.
    ///
    /// A Slurm task resubmitted alone (`sbatch --array=2`) sees an array of one task, 2..2:
    /// Slurm keeps no trace of the array it came from. So an array that is not whole is never
    /// read as a whole batch: without a count, an array of one task or one that does not start
    /// at 0 or 1 is refused; with a count N, a task id names shard id+1 of an array counted
    /// from 0 and shard id of one counted from 1, and when the ids seen cannot tell which (a
    /// task 0 or a task N would), it is refused with the `--shard i/n` of each reading.
    pub fn from_env(
        var: impl Fn(&str) -> Option<String>,
        count: Option<usize>,
    ) -> Result<(Shard, String), AutoShardError> {
        let num = |name: &str| -> Result<Option<i64>, AutoShardError> {
            match var(name) {
                None => Ok(None),
                Some(s) if s.trim().is_empty() => Ok(None),
                Some(s) => s.trim().parse::<i64>().map(Some).map_err(|_| {
                    AutoShardError::plain(format!("--shard auto: {name}='{s}' is not an integer"))
                }),
            }
        };
        let env_count = match num(env::COUNT)? {
            Some(n) if n >= 1 => Some(n as usize),
            Some(n) => {
                return Err(AutoShardError::plain(format!(
                    "--shard auto: {}={n} must be >= 1",
                    env::COUNT
                )))
            }
            None => None,
        };
        let count = count.or(env_count);
        if let Some(id) = num(env::SLURM_ID)? {
            return slurm(id, &num, count);
        }
        if let Some(k) = num(env::K8S_INDEX)? {
            let Some(n) = count else {
                return Err(AutoShardError::plain(format!(
                    "--shard auto: {}={k} (Kubernetes indexed Job) but no shard count: give \
                     --shard-count N or set {} to the Job's completions",
                    env::K8S_INDEX,
                    env::COUNT
                )));
            };
            if k < 0 || k as usize >= n {
                return Err(AutoShardError::plain(format!(
                    "--shard auto: {}={k} must lie in 0..{n} (the shard count)",
                    env::K8S_INDEX
                )));
            }
            let shard = Shard {
                index: k as usize,
                count: n,
            };
            return Ok((shard, format!("Kubernetes completion index {k} of {n}")));
        }
        Err(AutoShardError::plain(format!(
            "--shard auto: neither {} (Slurm job array) nor {} (Kubernetes indexed Job) is set; \
             give --shard i/n",
            env::SLURM_ID,
            env::K8S_INDEX
        )))
    }

    /// Whether run `index` (0-based, expansion order) belongs to this shard.
    pub fn contains(&self, index: usize) -> bool {
        index % self.count == self.index
    }
}

/// `--shard auto` could not tell the shard; where a `--shard i/n` would do, `instead` lists
/// each (with the condition under which it is the right one), for the command line to print
/// as whole commands.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AutoShardError {
    /// What is wrong.
    pub message: String,
    /// `(when, shard)`: run `--shard <shard>` instead, if `when` holds (empty: always).
    pub instead: Vec<(String, Shard)>,
}

impl AutoShardError {
    fn plain(message: String) -> Self {
        AutoShardError {
            message,
            instead: vec![],
        }
    }
}

impl fmt::Display for AutoShardError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.message)?;
        for (when, s) in &self.instead {
            if when.is_empty() {
                write!(f, "; give --shard {s}")?;
            } else {
                write!(f, "; {when}: give --shard {s}")?;
            }
        }
        Ok(())
    }
}

impl std::error::Error for AutoShardError {}

/// The shard of Slurm array task `id` (see [`Shard::from_env`]).
fn slurm(
    id: i64,
    num: &dyn Fn(&str) -> Result<Option<i64>, AutoShardError>,
    count: Option<usize>,
) -> Result<(Shard, String), AutoShardError> {
    let plain = AutoShardError::plain;
    let min = num(env::SLURM_MIN)?.unwrap_or(id.min(0));
    let max = num(env::SLURM_MAX)?;
    let step = num(env::SLURM_STEP)?.unwrap_or(1);
    if step < 1 {
        return Err(plain(format!(
            "--shard auto: {}={step} must be >= 1",
            env::SLURM_STEP
        )));
    }
    let span = max.map(|max| (max - min) / step + 1);
    let tasks = num(env::SLURM_COUNT)?;
    let on_grid = |n: i64| {
        let off = id - min;
        (off >= 0 && off % step == 0 && off / step < n).then_some((off / step) as usize)
    };
    let Some(n) = count else {
        // The count from Slurm's own variables: only for an array that is evidently whole.
        let n = match (span, tasks) {
            (Some(a), Some(b)) if a != b => {
                return Err(plain(format!(
                    "--shard auto: the Slurm array is not a plain range ({}={b} tasks, but \
                     MIN..MAX spans {a}): submit it as --array=0-N (or 1-N, with an optional \
                     :step and %limit), or give --shard-count N",
                    env::SLURM_COUNT
                )))
            }
            (Some(a), _) => a,
            (None, Some(b)) => b,
            (None, None) => {
                return Err(plain(format!(
                    "--shard auto: {} is set but neither {} nor {}: give --shard-count N",
                    env::SLURM_ID,
                    env::SLURM_COUNT,
                    env::SLURM_MAX
                )))
            }
        };
        if n == 1 || !(min == 0 || min == 1) {
            return Err(AutoShardError {
                message: format!(
                    "--shard auto: Slurm task {id} belongs to an array of {n} task(s) from {min}: \
                     that is what a resubmit of some tasks of a larger array looks like (Slurm \
                     does not say how large), and reading it as a whole array would run \
                     other tasks' shards; give --shard-count N (the original array's size), \
                     or --shard {id}/N for an array counted from 1"
                ),
                instead: vec![],
            });
        }
        let Some(index) = on_grid(n) else {
            return Err(plain(format!(
                "--shard auto: Slurm task {id} is not one of the {n} tasks {min}, {}, ... (step {step})",
                min + step
            )));
        };
        let shard = Shard {
            index,
            count: n as usize,
        };
        return Ok((shard, format!("Slurm array task {id} of {n}")));
    };
    let n_i = n as i64;
    // A whole array of n tasks (any step): the k-th task is shard k.
    if span == Some(n_i) && tasks.is_none_or(|t| t == n_i) {
        if let Some(index) = on_grid(n_i) {
            let shard = Shard { index, count: n };
            return Ok((shard, format!("Slurm array task {id} of {n}")));
        }
    }
    // Part of an array (a resubmit): task ids name shards, counted from 0 or from 1.
    let max = max.unwrap_or(id).max(id);
    let from_zero = (0..n_i).contains(&id).then_some(Shard {
        index: id as usize,
        count: n,
    });
    let from_one = (1..=n_i).contains(&id).then_some(Shard {
        index: (id - 1).max(0) as usize,
        count: n,
    });
    let reading = if min == 0 {
        from_zero.map(|s| (s, 0))
    } else if max == n_i {
        from_one.map(|s| (s, 1))
    } else {
        None
    };
    if let Some((shard, base)) = reading {
        return Ok((
            shard,
            format!(
                "Slurm array task {id} of {n} counted from {base}; tasks {min}..{max} resubmitted"
            ),
        ));
    }
    let mut instead = vec![];
    if let Some(s) = from_one {
        instead.push((format!("if the array counts from 1 (--array=1-{n})"), s));
    }
    if let Some(s) = from_zero {
        instead.push((format!("if it counts from 0 (--array=0-{})", n - 1), s));
    }
    let message = if instead.is_empty() {
        format!(
            "--shard auto: Slurm task {id} is no shard of {n} (task ids 0..{} or 1..{n})",
            n - 1
        )
    } else {
        format!(
            "--shard auto: Slurm task {id} of an array {min}..{max}, part of an array of {n} \
             tasks: Slurm does not say whether that array counted from 0 or from 1"
        )
    };
    Err(AutoShardError { message, instead })
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index + 1, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn env(pairs: &[(&str, &str)]) -> impl Fn(&str) -> Option<String> {
        let m: BTreeMap<String, String> = pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        move |k| m.get(k).cloned()
    }

    #[test]
    fn shards_partition_every_batch_exactly_once_and_balanced() {
        for total in [0usize, 1, 2, 7, 21, 100] {
            for n in 1..=8 {
                let mut seen = vec![0; total];
                let mut sizes = vec![];
                for i in 1..=n {
                    let s = Shard::parse(&format!("{i}/{n}")).unwrap();
                    let mine: Vec<usize> = (0..total).filter(|&k| s.contains(k)).collect();
                    sizes.push(mine.len());
                    for k in mine {
                        seen[k] += 1;
                    }
                }
                assert!(
                    seen.iter().all(|&c| c == 1),
                    "total {total}, n {n}: {seen:?}"
                );
                let (lo, hi) = (sizes.iter().min().unwrap(), sizes.iter().max().unwrap());
                assert!(hi - lo <= 1, "total {total}, n {n}: sizes {sizes:?}");
            }
        }
    }

    #[test]
    fn parse_refuses_bad_shards() {
        assert_eq!(Shard::parse("2/3").unwrap(), Shard { index: 1, count: 3 });
        assert_eq!(Shard::parse("2/3").unwrap().to_string(), "2/3");
        for bad in ["0/3", "4/3", "1/0", "3", "a/b", "1/3/4", ""] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn slurm_arrays_from_zero_or_one_with_steps() {
        let (s, _) = Shard::from_env(
            env(&[
                ("SLURM_ARRAY_TASK_ID", "0"),
                ("SLURM_ARRAY_TASK_COUNT", "4"),
                ("SLURM_ARRAY_TASK_MIN", "0"),
                ("SLURM_ARRAY_TASK_MAX", "3"),
            ]),
            None,
        )
        .unwrap();
        assert_eq!(s, Shard { index: 0, count: 4 });
        let (s, _) = Shard::from_env(
            env(&[
                ("SLURM_ARRAY_TASK_ID", "10"),
                ("SLURM_ARRAY_TASK_MIN", "1"),
                ("SLURM_ARRAY_TASK_MAX", "10"),
            ]),
            None,
        )
        .unwrap();
        assert_eq!(
            s,
            Shard {
                index: 9,
                count: 10
            }
        );
        let (s, _) = Shard::from_env(
            env(&[
                ("SLURM_ARRAY_TASK_ID", "4"),
                ("SLURM_ARRAY_TASK_MIN", "0"),
                ("SLURM_ARRAY_TASK_MAX", "20"),
                ("SLURM_ARRAY_TASK_STEP", "2"),
            ]),
            None,
        )
        .unwrap();
        assert_eq!(
            s,
            Shard {
                index: 2,
                count: 11
            }
        );
        // A list such as --array=1,3,7 cannot be mapped onto shards.
        let e = Shard::from_env(
            env(&[
                ("SLURM_ARRAY_TASK_ID", "3"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
                ("SLURM_ARRAY_TASK_MIN", "1"),
                ("SLURM_ARRAY_TASK_MAX", "7"),
            ]),
            None,
        )
        .unwrap_err();
        assert!(e.message.contains("not a plain range"), "{e}");
        let e = Shard::from_env(env(&[("SLURM_ARRAY_TASK_ID", "3")]), None).unwrap_err();
        assert!(e.message.contains("--shard-count"), "{e}");
        let (s, _) = Shard::from_env(env(&[("SLURM_ARRAY_TASK_ID", "3")]), Some(5)).unwrap();
        assert_eq!(s, Shard { index: 3, count: 5 });
    }

    fn slurm(id: &str, min: &str, max: &str, count: &str) -> Vec<(&'static str, String)> {
        vec![
            ("SLURM_ARRAY_TASK_ID", id.to_string()),
            ("SLURM_ARRAY_TASK_MIN", min.to_string()),
            ("SLURM_ARRAY_TASK_MAX", max.to_string()),
            ("SLURM_ARRAY_TASK_COUNT", count.to_string()),
        ]
    }

    fn auto(vars: Vec<(&'static str, String)>, n: Option<usize>) -> Result<Shard, AutoShardError> {
        let pairs: Vec<(&str, &str)> = vars.iter().map(|(k, v)| (*k, v.as_str())).collect();
        Shard::from_env(env(&pairs), n).map(|(s, _)| s)
    }

    #[test]
    fn a_resubmitted_task_runs_its_own_shard_or_is_refused_with_the_shards_that_would() {
        // `sbatch --array=2` of a 1-3 array: Slurm says 2..2, one task.
        let e = auto(slurm("2", "2", "2", "1"), None).unwrap_err();
        assert!(
            e.message.contains("resubmit") && e.message.contains("--shard-count N"),
            "{e}"
        );
        // `sbatch --array=1` or `--array=0`: a one-task array is never read as the whole batch.
        assert!(auto(slurm("1", "1", "1", "1"), None).is_err());
        assert!(auto(slurm("0", "0", "0", "1"), None).is_err());
        // With the count: task 2 of an array that ends at 3 = N counts from 1...
        let e = auto(slurm("2", "2", "2", "1"), Some(3)).unwrap_err();
        assert_eq!(
            e.instead,
            [
                (
                    "if the array counts from 1 (--array=1-3)".to_string(),
                    Shard { index: 1, count: 3 }
                ),
                (
                    "if it counts from 0 (--array=0-2)".to_string(),
                    Shard { index: 2, count: 3 }
                )
            ]
        );
        assert!(e.to_string().contains("give --shard 2/3"), "{e}");
        // ... but the ids seen tell it when they reach N (from 1) or 0 (from 0).
        assert_eq!(
            auto(slurm("3", "3", "3", "1"), Some(3)).unwrap(),
            Shard { index: 2, count: 3 }
        );
        assert_eq!(
            auto(slurm("2", "2", "3", "2"), Some(3)).unwrap(),
            Shard { index: 1, count: 3 }
        );
        assert_eq!(
            auto(slurm("0", "0", "0", "1"), Some(3)).unwrap(),
            Shard { index: 0, count: 3 }
        );
        assert_eq!(
            auto(slurm("2", "0", "2", "2"), Some(3)).unwrap(),
            Shard { index: 2, count: 3 }
        );
        // The whole array with its count reads as before.
        assert_eq!(
            auto(slurm("2", "1", "3", "3"), Some(3)).unwrap(),
            Shard { index: 1, count: 3 }
        );
        assert_eq!(
            auto(slurm("2", "0", "2", "3"), Some(3)).unwrap(),
            Shard { index: 2, count: 3 }
        );
        // A task id beyond the count is no shard.
        let e = auto(slurm("5", "5", "5", "1"), Some(3)).unwrap_err();
        assert!(
            e.message.contains("no shard of 3") && e.instead.is_empty(),
            "{e}"
        );
    }

    #[test]
    fn kubernetes_indexed_jobs_need_a_count() {
        let e = Shard::from_env(env(&[("JOB_COMPLETION_INDEX", "2")]), None).unwrap_err();
        assert!(e.message.contains("APPLESIM_SHARD_COUNT"), "{e}");
        let (s, from) = Shard::from_env(
            env(&[("JOB_COMPLETION_INDEX", "2"), ("APPLESIM_SHARD_COUNT", "3")]),
            None,
        )
        .unwrap();
        assert_eq!(s, Shard { index: 2, count: 3 });
        assert!(from.contains("Kubernetes"), "{from}");
        let (s, _) = Shard::from_env(env(&[("JOB_COMPLETION_INDEX", "0")]), Some(4)).unwrap();
        assert_eq!(s, Shard { index: 0, count: 4 });
        assert!(Shard::from_env(env(&[("JOB_COMPLETION_INDEX", "4")]), Some(4)).is_err());
    }

    #[test]
    fn no_scheduler_is_a_clear_error() {
        let e = Shard::from_env(env(&[]), None).unwrap_err();
        assert!(
            e.message.contains("SLURM_ARRAY_TASK_ID") && e.message.contains("JOB_COMPLETION_INDEX"),
            "{e}"
        );
    }
}
