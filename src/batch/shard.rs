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
    /// `--shard-count`) overrides the number of shards; without it Slurm's own variables give
    /// it, and for Kubernetes `APPLESIM_SHARD_COUNT` must. Returns the shard and a line saying
    /// where it came from.
    pub fn from_env(
        var: impl Fn(&str) -> Option<String>,
        count: Option<usize>,
    ) -> Result<(Shard, String), String> {
        let num = |name: &str| -> Result<Option<i64>, String> {
            match var(name) {
                None => Ok(None),
                Some(s) if s.trim().is_empty() => Ok(None),
                Some(s) => s
                    .trim()
                    .parse::<i64>()
                    .map(Some)
                    .map_err(|_| format!("--shard auto: {name}='{s}' is not an integer")),
            }
        };
        let env_count = match num(env::COUNT)? {
            Some(n) if n >= 1 => Some(n as usize),
            Some(n) => return Err(format!("--shard auto: {}={n} must be >= 1", env::COUNT)),
            None => None,
        };
        let count = count.or(env_count);
        if let Some(id) = num(env::SLURM_ID)? {
            let min = num(env::SLURM_MIN)?.unwrap_or(0);
            let step = num(env::SLURM_STEP)?.unwrap_or(1);
            if step < 1 {
                return Err(format!(
                    "--shard auto: {}={step} must be >= 1",
                    env::SLURM_STEP
                ));
            }
            let from_max = num(env::SLURM_MAX)?.map(|max| (max - min) / step + 1);
            let slurm_count = num(env::SLURM_COUNT)?;
            if let (Some(a), Some(b)) = (from_max, slurm_count) {
                if a != b {
                    return Err(format!(
                        "--shard auto: the Slurm array is not a plain range ({}={b} tasks, but MIN..MAX \
                         spans {a}): submit it as --array=0-N (or 1-N, with an optional :step and %limit)",
                        env::SLURM_COUNT
                    ));
                }
            }
            let n = match count.map(|c| c as i64).or(slurm_count).or(from_max) {
                Some(n) => n,
                None => {
                    return Err(format!(
                        "--shard auto: {} is set but neither {} nor {}: give --shard-count N",
                        env::SLURM_ID,
                        env::SLURM_COUNT,
                        env::SLURM_MAX
                    ))
                }
            };
            let off = id - min;
            if off < 0 || off % step != 0 || off / step >= n {
                return Err(format!(
                    "--shard auto: Slurm task {id} is not one of the {n} tasks {min}, {}, ... (step {step})",
                    min + step
                ));
            }
            let shard = Shard {
                index: (off / step) as usize,
                count: n as usize,
            };
            return Ok((shard, format!("Slurm array task {id} of {n}")));
        }
        if let Some(k) = num(env::K8S_INDEX)? {
            let Some(n) = count else {
                return Err(format!(
                    "--shard auto: {}={k} (Kubernetes indexed Job) but no shard count: give \
                     --shard-count N or set {} to the Job's completions",
                    env::K8S_INDEX,
                    env::COUNT
                ));
            };
            if k < 0 || k as usize >= n {
                return Err(format!(
                    "--shard auto: {}={k} must lie in 0..{n} (the shard count)",
                    env::K8S_INDEX
                ));
            }
            let shard = Shard {
                index: k as usize,
                count: n,
            };
            return Ok((shard, format!("Kubernetes completion index {k} of {n}")));
        }
        Err(format!(
            "--shard auto: neither {} (Slurm job array) nor {} (Kubernetes indexed Job) is set; \
             give --shard i/n",
            env::SLURM_ID,
            env::K8S_INDEX
        ))
    }

    /// Whether run `index` (0-based, expansion order) belongs to this shard.
    pub fn contains(&self, index: usize) -> bool {
        index % self.count == self.index
    }
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
        assert!(e.contains("not a plain range"), "{e}");
        let e = Shard::from_env(env(&[("SLURM_ARRAY_TASK_ID", "3")]), None).unwrap_err();
        assert!(e.contains("--shard-count"), "{e}");
        let (s, _) = Shard::from_env(env(&[("SLURM_ARRAY_TASK_ID", "3")]), Some(5)).unwrap();
        assert_eq!(s, Shard { index: 3, count: 5 });
    }

    #[test]
    fn kubernetes_indexed_jobs_need_a_count() {
        let e = Shard::from_env(env(&[("JOB_COMPLETION_INDEX", "2")]), None).unwrap_err();
        assert!(e.contains("APPLESIM_SHARD_COUNT"), "{e}");
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
            e.contains("SLURM_ARRAY_TASK_ID") && e.contains("JOB_COMPLETION_INDEX"),
            "{e}"
        );
    }
}
