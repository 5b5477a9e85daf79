//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod elliptic;
pub mod ode;

use applesim::record::series::MemorySeries;
use applesim::scenario::{self, Scenario};
use applesim::sim::{self, RunResult};
use std::path::{Path, PathBuf};

/// Path of a file under the repository root.
pub fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// Loads (and validates) a shipped scenario.
pub fn shipped(rel: &str) -> Scenario {
    scenario::load(&repo(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// Runs a scenario in memory and returns the result and the full time series.
pub fn run(sc: &Scenario) -> (RunResult, MemorySeries) {
    scenario::validate(sc).unwrap_or_else(|e| panic!("invalid test scenario: {e}"));
    let mut series = MemorySeries::default();
    let r =
        sim::run(sc, &repo("scenarios"), &mut series).unwrap_or_else(|e| panic!("run failed: {e}"));
    (r, series)
}

/// Relative error.
pub fn rel(got: f64, want: f64) -> f64 {
    (got - want).abs() / want.abs()
}

/// Asserts a relative error within `tol`, printing both numbers.
#[track_caller]
pub fn assert_rel(what: &str, got: f64, want: f64, tol: f64) {
    let e = rel(got, want);
    println!(
        "{what}: got {got:.8e}, closed form {want:.8e}, error {:.5} %",
        100.0 * e
    );
    assert!(
        e <= tol,
        "{what}: got {got}, want {want} (error {:.4} % > {:.4} %)",
        100.0 * e,
        100.0 * tol
    );
}

/// Asserts |got - want| <= tol |want|, printing both numbers and naming the reference kind
/// ("closed form", "RK4", "golden value").
#[track_caller]
pub fn assert_ref(what: &str, got: f64, want: f64, tol: f64, kind: &str) {
    let e = rel(got, want);
    println!(
        "{what}: got {got:.8e}, {kind} {want:.8e}, error {:+.5} % (tolerance {:.5} %)",
        100.0 * (got - want) / want.abs(),
        100.0 * tol
    );
    assert!(
        e <= tol,
        "{what}: got {got}, {kind} {want} (error {:.5} % > {:.5} %)",
        100.0 * e,
        100.0 * tol
    );
}

/// The paper's apple (G 1 MPa, nu 0.18) and steel plate (G 8.1e10 Pa, nu 0.28) as (shear
/// modulus in Pa, Poisson's ratio): the materials of the moving-part and roller tests.
pub const PAPER_APPLE: (f64, f64) = (1.0e6, 0.18);
/// See [`PAPER_APPLE`].
pub const PAPER_STEEL: (f64, f64) = (8.1e10, 0.28);

/// [`PAPER_APPLE`] (800 kg/m^3) and [`PAPER_STEEL`] as a scenario's `materials`, named `apple`
/// and `steel`.
pub fn apple_and_steel() -> serde_json::Value {
    serde_json::json!({
        "apple": {"shear_modulus_pa": PAPER_APPLE.0, "poisson_ratio": PAPER_APPLE.1,
                  "density_kg_m3": 800},
        "steel": {"shear_modulus_pa": PAPER_STEEL.0, "poisson_ratio": PAPER_STEEL.1}})
}

/// E* of two materials given as (shear modulus in Pa, Poisson's ratio): physics.md section 2,
/// 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 with E = 2 G (1 + nu).
pub fn e_star_of(a: (f64, f64), b: (f64, f64)) -> f64 {
    let e = |(g, nu): (f64, f64)| 2.0 * g * (1.0 + nu);
    1.0 / ((1.0 - a.1 * a.1) / e(a) + (1.0 - b.1 * b.1) / e(b))
}

/// Runs `applesim run` on the scenario `v` written into a fresh folder under the system's
/// temporary folder, through `sh -c` with `limits` before it (e.g. `ulimit -v 400000;`), and
/// returns (exit code, standard error, seconds, the run folder). The folder is left for the
/// caller to look into and remove.
pub fn run_cli(
    name: &str,
    v: &serde_json::Value,
    limits: &str,
) -> (Option<i32>, String, f64, PathBuf) {
    let dir = std::env::temp_dir().join(format!("applesim-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("scenario.json");
    std::fs::write(&file, serde_json::to_string_pretty(v).unwrap()).unwrap();
    let out = dir.join("out");
    let cmd = format!(
        "{limits} exec '{}' run '{}' --out '{}' --quiet",
        env!("CARGO_BIN_EXE_applesim"),
        file.display(),
        out.display()
    );
    let start = std::time::Instant::now();
    let o = std::process::Command::new("sh")
        .args(["-c", &cmd])
        .output()
        .unwrap();
    let secs = start.elapsed().as_secs_f64();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    println!(
        "{name}: exit {:?} in {secs:.2} s: {}",
        o.status.code(),
        err.trim()
    );
    (o.status.code(), err, secs, dir)
}

/// Asserts that `applesim run` refuses `v` with exit 1, one `error: FIELD: ...` line holding
/// every one of `needles`, within `max_s` seconds, and writes no output folder; returns the line.
#[track_caller]
pub fn refused_cli(
    name: &str,
    v: &serde_json::Value,
    limits: &str,
    field: &str,
    needles: &[&str],
    max_s: f64,
) -> String {
    let (code, err, secs, dir) = run_cli(name, v, limits);
    assert_eq!(code, Some(1), "{name}: exit {code:?}: {err}");
    let lines: Vec<&str> = err.trim_end().lines().collect();
    assert_eq!(lines.len(), 1, "{name}: not one line: {err}");
    assert!(
        lines[0].starts_with(&format!("error: {field}: ")),
        "{name}: the line does not lead with {field}: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "{name}: message lacks '{n}': {err}");
    }
    assert!(
        secs <= max_s,
        "{name}: refused after {secs:.2} s (limit {max_s} s)"
    );
    assert!(
        !dir.join("out").exists(),
        "{name}: an output folder was written"
    );
    let _ = std::fs::remove_dir_all(&dir);
    lines[0].to_string()
}
