//! docs/accuracy.md's two `applesim tradeoff` tables (the Fig. 1 drop and the handling line) are
//! what the command writes now: every cell but the wall times (a measurement of the machine).
//!
//! The cells are errors of each rung against the command's own 200-steps-per-contact reference
//! run; for the handling line they are differences between chaotic piles, with no closed form.
//! They are committed golden values, regression pins, not validation: the doc's table, compared
//! digit for digit with tradeoff.md; beside the handling line's, a physical check of its rungs.
//! (The independent checks of the same policies are tests/stepping.rs, tests/damped_accuracy.rs
//! and tests/handling_line.rs.)

use crate::common;
use common::*;

/// The table rows of `text` (lines starting with `|`, header and rule skipped), each as its
/// cells with the wall-time column (index 4 of the split, the 4th cell) removed.
fn rows(text: &str) -> Vec<Vec<String>> {
    text.lines()
        .filter(|l| l.starts_with('|') && !l.starts_with("| rung") && !l.starts_with("|---"))
        .map(|l| {
            let mut cells: Vec<String> = l.split('|').map(|c| c.trim().to_string()).collect();
            cells.remove(4);
            cells
        })
        .collect()
}

/// The doc's section between `from` and the next chart.
fn doc_table(from: &str) -> Vec<Vec<String>> {
    let doc = std::fs::read_to_string(repo("docs/accuracy.md")).unwrap();
    let start = doc
        .find(from)
        .unwrap_or_else(|| panic!("no '{from}' in accuracy.md"));
    let end = start + doc[start..].find("![error against wall time").unwrap();
    rows(&doc[start..end])
}

fn tradeoff(scenario: &str, name: &str) -> Vec<Vec<String>> {
    let out = std::env::temp_dir().join(format!("applesim-tradeoff-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args(["tradeoff", scenario, "--out"])
        .arg(&out)
        .current_dir(repo(""))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["tradeoff.csv", "tradeoff.md", "tradeoff.svg"] {
        assert!(out.join(f).exists(), "no {f}");
    }
    let t = rows(&std::fs::read_to_string(out.join("tradeoff.md")).unwrap());
    let _ = std::fs::remove_dir_all(&out);
    t
}

fn compare(doc: Vec<Vec<String>>, got: Vec<Vec<String>>) {
    assert_eq!(doc.len(), got.len(), "rungs");
    assert!(doc.len() >= 14);
    for (d, g) in doc.iter().zip(&got) {
        assert_eq!(
            d, g,
            "docs/accuracy.md (left) against tradeoff.md now (right)"
        );
    }
}

#[test]
fn drop_table_is_current() {
    compare(
        doc_table("### Fig. 1 drop"),
        tradeoff("scenarios/drop_on_steel.json", "drop"),
    );
}

/// The handling line's table is a regression pin, not validation (the pile in the bin is
/// chaotic). Beside it, the physical check docs/accuracy.md reads from it: every damped rung
/// (`hertz-damped`, `full`, the scenario's own step) is a pile as valid as the reference's, its
/// distributions within the pile's chaos (measured on this run: median peak-force error at most
/// 12.979 %, median first surface contact time 10.166 %, restitution 0.3085, median final height
/// 0.631 R; checked under 15 %, 15 %, 0.5 and 1 R), the precise rung no closer than that; the
/// `hertz` rungs (no eq. 12 loss) are not: their apples bounce instead of resting, so their first
/// surface contacts end after an impact's few milliseconds instead of the reference's seconds
/// of rest (median contact-time error at least 99.5 %, checked over 90 %), their restitutions
/// are off by at least 0.896 (over 0.85) and their median peak force by at least 58 % (over
/// 20 %). One realisation of a chaotic pile: the damped rungs' median peak error scatters 10-13 %
/// over slightly perturbed feed speeds (the `hertz-damped, auto, precise` rung 10.2-12.5 % over
/// six perturbed feeds, riding on or off; 12.979 % on this run), so its bound is 15 % (10 % until
/// that scatter was measured); the undamped `hertz` rungs are at 49 % and more. The bounds
/// before issue 31 (5 % and 0.15 for the damped rungs, 40 % for the hertz ones) were those of
/// the piles then, and the equally valid piles of the adaptive rungs since (steps no longer land
/// on the samples) fall outside them.
#[test]
fn handling_line_table_is_current() {
    let got = tradeoff("scenarios/handling_line.json", "line");
    // Cells: rung, step, steps, peak max / median, contact times max / median, restitution,
    // heights max / median (the wall time removed).
    let pair = |c: &str| -> (f64, f64) {
        let (a, b) = c.split_once(" / ").unwrap();
        (a.parse().unwrap(), b.parse().unwrap())
    };
    for row in &got {
        let rung = row[1].as_str();
        if rung.starts_with("rigid") {
            continue;
        }
        let (_, peak_median) = pair(&row[4]);
        let (_, time_median) = pair(&row[5]);
        let restitution: f64 = row[6].parse().unwrap();
        let (_, height_median) = pair(&row[7]);
        println!("{rung}: peak median {peak_median} %, contact time median {time_median} %, restitution {restitution}, height median {height_median} R");
        if rung.starts_with("hertz,") {
            assert!(
                time_median > 90.0 && restitution > 0.85 && peak_median > 20.0,
                "{rung}: {row:?}"
            );
        } else {
            assert!(
                peak_median < 15.0
                    && time_median < 15.0
                    && restitution < 0.5
                    && height_median < 1.0,
                "{rung}: {row:?}"
            );
        }
    }
    compare(doc_table("### Handling line"), got);
}
