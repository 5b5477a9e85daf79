//! The files of a virtual instrumented sphere (`apples[].probe`): its accelerometer trace and
//! its impact table, as the real device's software exports them (time, acceleration in g;
//! per impact peak g and velocity change), plus the transfer point of each impact, which a real
//! device leaves to the person who watched it pass.

use super::atomic::AtomicCsv;
use crate::record::events::{ContactEvent, Party};
use crate::sim::ProbeRecord;
use std::path::{Path, PathBuf};

/// Header of `probe_NAME_trace.csv`.
pub const TRACE_HEADER: [&str; 2] = ["t_s", "acceleration_g"];

/// Header of `probe_NAME_impacts.csv`.
pub const IMPACTS_HEADER: [&str; 9] = [
    "impact",
    "t_trigger_s",
    "t_start_s",
    "t_end_s",
    "duration_s",
    "peak_g",
    "t_peak_s",
    "velocity_change_m_s",
    "transfer_point",
];

/// The file name stem of a probe: `probe_NAME`, with every character of the apple's name but
/// letters, digits, `-` and `_` replaced by `_` (a name may hold `/` or spaces); see
/// [`crate::record::probe::file_stem`].
pub fn stem(apple: &str) -> String {
    crate::record::probe::file_stem(apple)
}

/// The transfer point of each of the probe's impacts: that of the probe's contact whose impact
/// peaked within the impact's pulse with the largest force (`points` from
/// [`crate::analysis::audit::points_of`]); failing that (a pulse of contacts that started at
/// rest, or of several small ones), that of the contact open at the pulse's peak with the
/// largest peak force; empty if none was.
pub fn transfer_points(p: &ProbeRecord, events: &[ContactEvent], points: &[String]) -> Vec<String> {
    let period = 1.0 / p.spec.sample_rate_hz;
    p.impacts
        .iter()
        .map(|i| {
            let mine = || {
                events
                    .iter()
                    .zip(points)
                    .filter(|(e, _)| e.a_index == p.index || e.b_party == Party::Apple(p.index))
            };
            mine()
                .filter_map(|(e, pt)| e.impact.map(|x| (x, pt)))
                .filter(|(x, _)| {
                    x.t_peak_s >= i.t_start_s - period && x.t_peak_s <= i.t_end_s + period
                })
                .max_by(|a, b| a.0.peak_force_n.total_cmp(&b.0.peak_force_n))
                .map(|(_, pt)| pt.clone())
                .or_else(|| {
                    mine()
                        .filter(|(e, _)| {
                            e.t_start_s <= i.t_peak_s && e.t_end_s.is_none_or(|t| t >= i.t_peak_s)
                        })
                        .max_by(|a, b| a.0.peak_force_n.total_cmp(&b.0.peak_force_n))
                        .map(|(_, pt)| pt.clone())
                })
                .unwrap_or_default()
        })
        .collect()
}

/// Writes the probe's two files into `dir` in format `csv`; returns their paths.
pub fn write_probe(
    dir: &Path,
    p: &ProbeRecord,
    events: &[ContactEvent],
    points: &[String],
    csv: &super::CsvFormat,
) -> Result<[PathBuf; 2], (PathBuf, std::io::Error)> {
    let stem = stem(&p.apple);
    let nf = csv.numbers;
    let trace = csv.path(dir, &format!("{stem}_trace.csv"));
    let at = |path: &Path| {
        let path = path.to_path_buf();
        move |e: std::io::Error| (path.clone(), e)
    };
    let write_trace = || -> std::io::Result<()> {
        let mut w = AtomicCsv::create(&trace, &TRACE_HEADER)?;
        for &(t, g) in &p.trace {
            w.write_record([nf.num(t), nf.num(g)])?;
        }
        w.commit()
    };
    write_trace().map_err(at(&trace))?;
    let impacts = csv.path(dir, &format!("{stem}_impacts.csv"));
    let pts = transfer_points(p, events, points);
    let write_impacts = || -> std::io::Result<()> {
        let mut w = AtomicCsv::create(&impacts, &IMPACTS_HEADER)?;
        for (k, (i, pt)) in p.impacts.iter().zip(&pts).enumerate() {
            w.write_record([
                (k + 1).to_string(),
                nf.num(i.t_trigger_s),
                nf.num(i.t_start_s),
                nf.num(i.t_end_s),
                nf.num(i.t_end_s - i.t_start_s),
                nf.num(i.peak_g),
                nf.num(i.t_peak_s),
                nf.num(i.velocity_change_m_s),
                pt.clone(),
            ])?;
        }
        w.commit()
    };
    write_impacts().map_err(at(&impacts))?;
    Ok([trace, impacts])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_make_safe_file_names() {
        assert_eq!(stem("is-1"), "probe_is-1");
        assert_eq!(stem("bin/ball 2"), "probe_bin_ball_2");
    }
}
