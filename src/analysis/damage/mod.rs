//! Fruit damage: what a run's hits do to each apple (docs/damage.md).
//!
//! Pure functions, contact figures in and bruises out, in the order they are applied:
//! [`model`] turns one hit of an apple (the energy it absorbed, its peak force and pressure,
//! its contact patch) into a bruise by the apple material's damage model; [`sites`] places the
//! hits on the apple's own surface and combines repeated hits at one site; [`grade`] grades the
//! apple by a standard's classes; [`geometry`] holds the bruise's shape. The run only feeds them
//! (`analysis::bruise` gathers each apple's hits from the contact events). [`fit`] goes the
//! other way: measured bruises of drop tests in, a model's coefficients out
//! (`applesim calibrate-bruise`, `analysis::calibrate_bruise`).

pub mod fit;
pub mod geometry;
pub mod grade;
pub mod model;
pub mod sites;

pub use model::{DamageParams, Hit, HitDamage, Model};
