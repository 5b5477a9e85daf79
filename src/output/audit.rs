//! The line audit's files: `audit.csv` (written here, and read back by `applesim audit` to
//! compare layouts) and `audit.md` ([`Audit::markdown`]).

use super::atomic::AtomicCsv;
use crate::analysis::audit::{Audit, TransferPoint};
use std::path::Path;

/// Header of `audit.csv` (one row per transfer point, most damage first; `_p50`, `_p95`, `_max`
/// are the median, 95th percentile and largest over the apples hit there; fruit only).
pub const AUDIT_HEADER: [&str; 20] = [
    "transfer_point",
    "contacts",
    "impacts",
    "apples_hit_share",
    "peak_force_n_p50",
    "peak_force_n_p95",
    "peak_force_n_max",
    "peak_g_p50",
    "peak_g_p95",
    "peak_g_max",
    "velocity_change_m_s_p50",
    "velocity_change_m_s_p95",
    "velocity_change_m_s_max",
    "absorbed_energy_j_total",
    "absorbed_energy_j_max",
    "apples_bruised",
    "bruise_volume_mm3_p50",
    "bruise_volume_mm3_p95",
    "bruise_volume_mm3_total",
    "apples_downgraded",
];

/// The line audit as a table to read (`audit.md`, [`crate::analysis::audit::Audit::markdown`]).
pub const AUDIT_MD: &str = "audit.md";

/// Writes `audit.csv` (a figure without impacts to take it from is empty), numbers as `nf`
/// prints them.
pub fn write_audit(path: &Path, audit: &Audit, nf: super::NumberFormat) -> std::io::Result<()> {
    let mut w = AtomicCsv::create(path, &AUDIT_HEADER)?;
    let num = |x: f64| {
        if x.is_finite() {
            nf.num(x)
        } else {
            String::new()
        }
    };
    for t in &audit.points {
        let mut row = vec![
            t.point.clone(),
            t.contacts.to_string(),
            t.impacts.to_string(),
            num(t.apples_hit_share),
        ];
        for q in [t.peak_force_n, t.peak_g, t.velocity_change_m_s] {
            row.extend(q.map(num));
        }
        row.extend(t.absorbed_energy_j.map(num));
        row.push(t.apples_bruised.to_string());
        row.extend(t.bruise_volume_mm3.map(num));
        row.push(t.apples_downgraded.to_string());
        w.write_record(&row)?;
    }
    w.commit()
}

/// Errors reading an `audit.csv`.
#[derive(Debug, thiserror::Error)]
pub enum AuditReadError {
    /// The file could not be read, or is not CSV.
    #[error("{path}: {source}")]
    Csv {
        /// The file.
        path: std::path::PathBuf,
        /// The CSV reader's error.
        source: csv::Error,
    },
    /// The file is not an `audit.csv` of this version (header or a cell).
    #[error("{path}: {message}")]
    Format {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// Reads an `audit.csv` written by [`write_audit`] (an empty cell reads as NaN), plain or
/// gzipped (`audit.csv.gz`: `path` may name either, [`super::csv_file::open`]).
pub fn read_audit(path: &Path) -> Result<Audit, AuditReadError> {
    let (path, mut rd) = super::csv_file::reader(path).map_err(|e| AuditReadError::Csv {
        path: path.to_path_buf(),
        source: e.into(),
    })?;
    let path = path.as_path();
    let csv_err = |source| AuditReadError::Csv {
        path: path.to_path_buf(),
        source,
    };
    let format = |message: String| AuditReadError::Format {
        path: path.to_path_buf(),
        message,
    };
    let header: Vec<String> = rd
        .headers()
        .map_err(csv_err)?
        .iter()
        .map(String::from)
        .collect();
    if header != AUDIT_HEADER {
        return Err(format(format!(
            "not an audit.csv of applesim {} (its header is {})",
            env!("CARGO_PKG_VERSION"),
            header.join(",")
        )));
    }
    let mut points = Vec::new();
    for (k, row) in rd.records().enumerate() {
        let row = row.map_err(csv_err)?;
        let num = |i: usize| -> Result<f64, AuditReadError> {
            let cell = row.get(i).unwrap_or("");
            if cell.is_empty() {
                return Ok(f64::NAN);
            }
            cell.parse().map_err(|_| {
                format(format!(
                    "row {}, column {}: '{cell}' is not a number",
                    k + 2,
                    AUDIT_HEADER[i]
                ))
            })
        };
        let count = |i: usize| num(i).map(|x| if x.is_finite() { x as usize } else { 0 });
        points.push(TransferPoint {
            point: row.get(0).unwrap_or("").to_string(),
            contacts: count(1)?,
            impacts: count(2)?,
            apples_hit_share: num(3)?,
            peak_force_n: [num(4)?, num(5)?, num(6)?],
            peak_g: [num(7)?, num(8)?, num(9)?],
            velocity_change_m_s: [num(10)?, num(11)?, num(12)?],
            absorbed_energy_j: [num(13)?, num(14)?],
            apples_bruised: count(15)?,
            bruise_volume_mm3: [num(16)?, num(17)?, num(18)?],
            apples_downgraded: count(19)?,
        });
    }
    Ok(Audit { points })
}
