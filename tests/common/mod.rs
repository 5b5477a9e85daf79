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
