//! Time series of the apples, sampled by the driver at the scenario's output interval.

use crate::math::Vec3;
use crate::world::free_roller::RollerSample;
use std::sync::Arc;

/// The state of one apple at a sample time.
#[derive(Debug, Clone, PartialEq)]
pub struct AppleState {
    /// Apple index (scenario order).
    pub index: u32,
    /// Apple name.
    pub name: Arc<str>,
    /// Centre (m).
    pub position: Vec3,
    /// Centre velocity (m/s).
    pub velocity: Vec3,
    /// Angular velocity (rad/s).
    pub angular_velocity: Vec3,
    /// Total contact force acting at this pose (N).
    pub contact_force: Vec3,
    /// Slip speed of the contact the apple slides or rolls on (m/s; 0 when airborne), when the
    /// slip/roll detector runs ([`crate::sim::slip_roll`]).
    pub slip_speed: Option<f64>,
    /// Diameter (m): a spheroid's equatorial one.
    pub diameter_m: f64,
    /// Mass (kg).
    pub mass_kg: f64,
}

/// Receives the samples of a run (a CSV writer, an in-memory store, a plot, ...).
pub trait SampleSink {
    /// One sample of every apple at time `time_s`.
    fn sample(&mut self, time_s: f64, apples: &[AppleState]) -> std::io::Result<()>;

    /// The free-turning rollers' spins at the same sample time, right after [`Self::sample`];
    /// called only in a scene that has some. Ignored by default: only the run's files keep
    /// them (`rollers.csv`), the apples' sinks need not know about rollers.
    fn sample_rollers(&mut self, _time_s: f64, _rollers: &[RollerSample]) -> std::io::Result<()> {
        Ok(())
    }
}

/// Drops every sample.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoSamples;

impl SampleSink for NoSamples {
    fn sample(&mut self, _: f64, _: &[AppleState]) -> std::io::Result<()> {
        Ok(())
    }
}

/// Keeps every sample in memory (tests, analysis of small runs).
#[derive(Debug, Default, Clone)]
pub struct MemorySeries {
    /// (time, states) per sample.
    pub samples: Vec<(f64, Vec<AppleState>)>,
}

impl SampleSink for MemorySeries {
    fn sample(&mut self, time_s: f64, apples: &[AppleState]) -> std::io::Result<()> {
        self.samples.push((time_s, apples.to_vec()));
        Ok(())
    }
}

impl MemorySeries {
    /// The series of one apple: (time, state).
    pub fn of(&self, index: u32) -> Vec<(f64, &AppleState)> {
        self.samples
            .iter()
            .filter_map(|(t, v)| v.iter().find(|a| a.index == index).map(|a| (*t, a)))
            .collect()
    }
}
