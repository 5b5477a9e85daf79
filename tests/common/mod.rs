//! Helpers shared by the integration tests.
#![allow(dead_code)]

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
