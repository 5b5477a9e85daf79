//! applesim: how hard apples are hit in fruit-handling lines, before anything is built.
//!
//! The contact model is the 2019 paper "The dynamic simulation model of apples contact
//! interaction" (Rogatynskyi et al.) as corrected in `docs/physics.md`: Hertz normal force from
//! the overlap of the undeformed bodies, the eq. 12 energy loss with the dissipative sign, and
//! Amontons-Coulomb friction with its moments. Apples are rapier rigid bodies; a contact layer of
//! ours switches rapier's own response off for the pairs we model and applies our forces instead.
//!
//! A run flows through the modules in this order: a [`scenario`] file is validated and becomes
//! a [`world`] (rapier bodies and colliders, and the run's roster: every apple's name,
//! material, radius, mass and origin, resolved once); the [`layer`] applies the [`contact`] law to
//! it at the current poses every step; the driver in [`sim`] steps it, refuses a run that went
//! wrong and runs the slip/roll detector; what happened is kept in [`record`]s (contact events,
//! time series, transitions); [`analysis`] says what it means for the fruit (pulse fit, bruise
//! assessment) and [`output`] writes the run folder (summary, CSV, ParaView, charts); [`run`]
//! holds the order of those stages for one run, into a folder switched in whole. On top:
//! [`batch`] (sweeps, shards, merge), [`validate`] (the paper's figures), [`bench`](mod@bench) (the cost of
//! a run), [`view`] (a run folder as one HTML page) and the command line (a thin shell in `src/cli`).
//!
//! Code dependencies run one way, each module using only those listed before it: [`math`],
//! [`contact`] (pure functions), [`scenario`], [`record`] (plain data), [`layer`], [`world`],
//! [`sim`], [`analysis`], [`output`], [`run`], then the top. One arrow runs back: scenario validation
//! borrows the layer's cell grid ([`layer::grid`]) to find overlapping apples.
#![warn(missing_docs)]

pub mod analysis;
pub mod batch;
pub mod bench;
pub mod chart;
pub mod contact;
pub mod layer;
pub mod math;
pub mod output;
pub mod record;
pub mod run;
pub mod scenario;
pub mod sim;
pub mod validate;
pub mod view;
pub mod world;

/// The README's code blocks, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
