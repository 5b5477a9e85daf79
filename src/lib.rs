//! applesim: how hard apples are hit in fruit-handling lines, before anything is built.
//!
//! The contact model is the 2019 paper "The dynamic simulation model of apples contact
//! interaction" (Rogatynskyi et al.) as corrected in `docs/physics.md`: Hertz normal force from
//! the overlap of the undeformed bodies, the eq. 12 energy loss with the dissipative sign, and
//! Amontons-Coulomb friction with its moments. Apples are rapier rigid bodies; a contact layer of
//! ours switches rapier's own response off for the pairs we model and applies our forces instead.
//!
//! The modules follow the data flow:
//! [`scenario`] (serde types, validation) -> [`world`] (rapier bodies and colliders) ->
//! [`contact`] (the law, pure functions) -> [`layer`] (pair finding, hooks, forces) ->
//! [`sim`] (stepping, stability guard) -> [`record`] (contact events, time series, slip/roll
//! transitions) -> [`output`] (summary, CSV, charts, ParaView) -> [`analysis`] (pulse fit,
//! bruise assessment, ke calibration); [`validate`] runs the paper's figures against it;
//! [`bench`] measures the cost of a run.
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
pub mod scenario;
pub mod sim;
pub mod validate;
pub mod world;

/// The README's code blocks, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
