//! The files of a layout comparison (`applesim audit A B`): a run folder read back as the
//! comparison samples it ([`read_run`]: its fruit from `summary.json`, their impacts from
//! `apple_contacts.csv`), and the comparison written whole ([`write_comparison`]:
//! `compare.md` and `compare.csv`).

use super::atomic::{self, AtomicCsv};
use super::{APPLE_CONTACTS_CSV, APPLE_CONTACTS_HEADER};
use crate::analysis::compare::{AppleSample, Comparison, HitSample, RunSample, COMPARE_HEADER};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The comparison to read (`--out DIR`): the table printed by `applesim audit A B`.
pub const COMPARE_MD: &str = "compare.md";

/// The comparison's numbers for scripts ([`COMPARE_HEADER`]).
pub const COMPARE_CSV: &str = "compare.csv";

/// Errors reading a run folder for a comparison.
#[derive(Debug, thiserror::Error)]
pub enum RunReadError {
    /// A file is missing or cannot be read.
    #[error("{path}: {source}{hint}")]
    Read {
        /// The file.
        path: PathBuf,
        /// OS error.
        source: std::io::Error,
        /// What the folder should be.
        hint: &'static str,
    },
    /// `apple_contacts.csv` is not CSV.
    #[error("{path}: {source}")]
    Csv {
        /// The file.
        path: PathBuf,
        /// The CSV reader's error.
        source: csv::Error,
    },
    /// A file is not what this version of applesim writes.
    #[error("{path}: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

const NOT_A_RUN: &str =
    " (give a run folder written by `applesim run`, or a batch's runs/<id>; a folder of an applesim before the damage assessment: run it again)";

fn read(path: &Path) -> Result<Vec<u8>, RunReadError> {
    std::fs::read(path).map_err(|source| RunReadError::Read {
        path: path.to_path_buf(),
        source,
        hint: NOT_A_RUN,
    })
}

/// Reads the fruit of the run in folder `dir`: each apple of `summary.json`'s `apples[]` that
/// has a `grade` (a probe has none), downgraded when its grade is not the standard's best class
/// (`damage.grades[0]`), where `downgraded_by.transfer_point` says; its bruise volume; and its
/// impacts, the rows of `apple_contacts.csv` with a bruise site (peak g, transfer point, volume).
pub fn read_run(dir: &Path) -> Result<RunSample, RunReadError> {
    let sp = dir.join("summary.json");
    let bad = |path: &Path, message: String| RunReadError::Format {
        path: path.to_path_buf(),
        message,
    };
    let s: serde_json::Value =
        serde_json::from_slice(&read(&sp)?).map_err(|e| bad(&sp, format!("not JSON: {e}")))?;
    let best = s["damage"]["grades"][0].as_str().ok_or_else(|| {
        bad(
            &sp,
            "no `damage.grades`: written by an applesim before the damage assessment; run it again"
                .into(),
        )
    })?;
    let list = s["apples"]
        .as_array()
        .ok_or_else(|| bad(&sp, "no `apples` list".into()))?;
    let mut apples: Vec<AppleSample> = Vec::new();
    let mut index: BTreeMap<String, usize> = BTreeMap::new();
    for (k, a) in list.iter().enumerate() {
        let Some(grade) = a["grade"].as_str() else {
            continue;
        };
        let name = a["name"]
            .as_str()
            .ok_or_else(|| bad(&sp, format!("apples[{k}] has no `name`")))?;
        let downgraded_at = (grade != best).then(|| {
            a["downgraded_by"]["transfer_point"]
                .as_str()
                .unwrap_or("")
                .to_string()
        });
        let volume = &a["bruise_volume_mm3"];
        let bruise_volume_mm3 = match volume {
            serde_json::Value::Null => None,
            v => Some(v.as_f64().ok_or_else(|| {
                bad(
                    &sp,
                    format!("apples[{k}].bruise_volume_mm3 is {v}, not a number"),
                )
            })?),
        };
        index.insert(name.to_string(), apples.len());
        apples.push(AppleSample {
            apple: name.to_string(),
            downgraded_at,
            bruise_volume_mm3,
            hits: Vec::new(),
        });
    }

    // Plain or gzipped (`output.compress`), through the one opener of run files.
    let (cp, mut rd) =
        super::csv_file::reader(&dir.join(APPLE_CONTACTS_CSV)).map_err(|source| {
            RunReadError::Read {
                path: super::csv_file::locate(dir, APPLE_CONTACTS_CSV),
                source,
                hint: NOT_A_RUN,
            }
        })?;
    let csv_err = |source| RunReadError::Csv {
        path: cp.clone(),
        source,
    };
    let header: Vec<String> = rd
        .headers()
        .map_err(csv_err)?
        .iter()
        .map(String::from)
        .collect();
    if header != APPLE_CONTACTS_HEADER {
        return Err(bad(
            &cp,
            format!(
                "not an apple_contacts.csv of applesim {} (its header is {})",
                env!("CARGO_PKG_VERSION"),
                header.join(",")
            ),
        ));
    }
    let col = |name: &str| {
        APPLE_CONTACTS_HEADER
            .iter()
            .position(|h| *h == name)
            .expect("a column of the header")
    };
    let (c_apple, c_point, c_g, c_site, c_vol) = (
        col("apple"),
        col("transfer_point"),
        col("peak_g"),
        col("site"),
        col("volume_mm3"),
    );
    for (k, row) in rd.records().enumerate() {
        let row = row.map_err(csv_err)?;
        let cell = |i: usize| row.get(i).unwrap_or("");
        if cell(c_site).is_empty() {
            continue; // a contact that started at rest: no impact
        }
        let num = |i: usize| -> Result<Option<f64>, RunReadError> {
            let c = cell(i);
            if c.is_empty() {
                return Ok(None);
            }
            c.parse().map(Some).map_err(|_| {
                bad(
                    &cp,
                    format!(
                        "row {}, column {}: '{c}' is not a number",
                        k + 2,
                        APPLE_CONTACTS_HEADER[i]
                    ),
                )
            })
        };
        let peak_g = num(c_g)?.unwrap_or(f64::NAN);
        let volume_mm3 = num(c_vol)?;
        let name = cell(c_apple);
        let Some(&i) = index.get(name) else {
            return Err(bad(
                &cp,
                format!(
                    "row {}: apple '{name}' is not a fruit apple of {} (the files are of different runs)",
                    k + 2,
                    sp.display()
                ),
            ));
        };
        apples[i].hits.push(HitSample {
            transfer_point: cell(c_point).to_string(),
            peak_g,
            volume_mm3,
        });
    }
    Ok(RunSample { apples })
}

/// Writes `compare.md` (`markdown`, the table as printed) and `compare.csv` (the comparison's
/// numbers, [`COMPARE_HEADER`]) into folder `dir` (created if missing), each file whole.
pub fn write_comparison(dir: &Path, markdown: &str, c: &Comparison) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    atomic::write_file(&dir.join(COMPARE_MD), markdown.as_bytes())?;
    let mut w = AtomicCsv::create(&dir.join(COMPARE_CSV), &COMPARE_HEADER)?;
    for row in c.csv_rows() {
        w.write_record(&row)?;
    }
    w.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(name: &str, summary: &str, contacts: &[&str]) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("applesim-read-run-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("summary.json"), summary).unwrap();
        let mut csv = APPLE_CONTACTS_HEADER.join(",");
        for row in contacts {
            csv += "\n";
            csv += row;
        }
        std::fs::write(d.join(APPLE_CONTACTS_CSV), csv + "\n").unwrap();
        d
    }

    /// A row of apple_contacts.csv: apple, transfer point, peak g, site, volume.
    fn row(apple: &str, point: &str, g: &str, site: &str, volume: &str) -> String {
        format!("0,{apple},x,{point},0,0,0 0 0,1,1,0.1,0.1,1,{g},1,true,{site},{volume},g,,,,")
    }

    #[test]
    fn a_run_is_read_as_its_fruit_and_their_impacts_probes_left_out() {
        let summary = r#"{"damage": {"grades": ["best", "worse"]}, "apples": [
            {"name": "a", "grade": "worse", "bruise_volume_mm3": 12.5,
             "downgraded_by": {"transfer_point": "plate"}},
            {"name": "b", "grade": "best", "bruise_volume_mm3": 0},
            {"name": "probe"}]}"#;
        let rows = [
            row("a", "plate", "80", "0", "12.5"),
            row("a", "belt", "3", "", ""),
            row("b", "plate", "20", "0", "0"),
        ];
        let d = folder(
            "ok",
            summary,
            &rows.iter().map(String::as_str).collect::<Vec<_>>(),
        );
        let r = read_run(&d).unwrap();
        assert_eq!(r.apples.len(), 2, "the probe is not fruit");
        assert_eq!(r.apples[0].downgraded_at.as_deref(), Some("plate"));
        assert_eq!(
            r.apples[0].hits.len(),
            1,
            "a contact from rest is no impact"
        );
        assert_eq!(r.apples[0].hits[0].peak_g, 80.0);
        assert_eq!(r.apples[1].downgraded_at, None);
        // A row of an apple the summary does not have: the files are of different runs.
        let stray = [row("probe", "plate", "9", "0", "1")];
        let d = folder(
            "stray",
            summary,
            &stray.iter().map(String::as_str).collect::<Vec<_>>(),
        );
        let e = read_run(&d).unwrap_err().to_string();
        assert!(
            e.contains("apple_contacts.csv: row 2: apple 'probe'"),
            "{e}"
        );
        // Not a run: the missing file is named.
        let e = read_run(&d.join("nothing")).unwrap_err().to_string();
        assert!(
            e.contains("summary.json") && e.contains("give a run folder"),
            "{e}"
        );
        let d = folder("old", r#"{"apples": []}"#, &[]);
        let e = read_run(&d).unwrap_err().to_string();
        assert!(e.contains("no `damage.grades`"), "{e}");
    }
}
