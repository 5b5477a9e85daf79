//! What the layer reports: contacts that ended, each evaluated contact's slip (for the slip/roll
//! detector), and the figures of the last step.

use super::clock::StepLimit;
use crate::math::Vec3;
use crate::record::events::{ContactEvent, Party};

/// The slip of one contact at one step (an apple-apple contact gives one sample for each of its
/// apples).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlipSample {
    /// The apple.
    pub apple: u32,
    /// What it touches.
    pub other: Party,
    /// Tangential slip speed of the apple's surface point over the other surface at the contact
    /// point, belt velocity included (m/s): |s_t| of physics.md section 5.
    pub slip_m_s: f64,
    /// Normal force (N).
    pub normal_force_n: f64,
    /// Contact point (m, world).
    pub point: Vec3,
}

/// Per-step figures of the layer.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepStats {
    /// Contacts with overlap this step.
    pub contacts: usize,
    /// Apple-apple contacts.
    pub apple_apple_contacts: usize,
    /// Candidate apple-apple pairs in the neighbour list.
    pub apple_candidates: usize,
    /// Elastic energy stored in the contacts, sum of 2/5 k u^(5/2) (J).
    pub elastic_energy_j: f64,
    /// Largest overlap over the smaller radius.
    pub max_overlap_ratio: f64,
    /// With [`super::LayerConfig::step_control`]: the longest next step that resolves every
    /// contact in progress or about to start (s); infinite when nothing limits it.
    pub dt_limit_s: f64,
    /// What set `dt_limit_s`.
    pub dt_limit_reason: StepLimit,
    /// The step chosen was the layer's limit (`dt_limit_s`, landed on the end), not the
    /// driver's request (a fixed step, the largest step, the growth cap).
    pub dt_set_by_limit: bool,
}

impl StepStats {
    /// Figures of a step that has not found anything yet.
    pub(super) fn fresh() -> Self {
        Self {
            dt_limit_s: f64::INFINITY,
            ..Self::default()
        }
    }

    /// Lowers the step limit to `dt` for the reason `why`, if it is shorter.
    #[inline]
    pub(super) fn limit(&mut self, dt: f64, why: StepLimit) {
        if dt < self.dt_limit_s {
            self.dt_limit_s = dt;
            self.dt_limit_reason = why;
        }
    }
}

/// A pad that bottomed out under an apple (docs/physics.md section 13): once per contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PadBottom {
    /// The apple.
    pub apple: u32,
    /// The padded surface.
    pub surface: u32,
    /// When (s).
    pub time_s: f64,
    /// Which limit it reached, and the pad's compression there
    /// ([`crate::contact::padding::PadConstants::limit_at`]).
    pub limit: (crate::contact::padding::PadLimit, f64),
}

/// The layer's outputs.
#[derive(Debug, Default)]
pub(super) struct Outputs {
    /// Pads that bottomed out, in the order they did (taken by the driver).
    pub pad_bottoms: Vec<PadBottom>,
    /// Contacts that ended, in the order they ended.
    pub finished: Vec<ContactEvent>,
    /// The slip of every contact evaluated at the last force pass (with `record_slips`).
    pub slips: Vec<SlipSample>,
    /// Figures of the last step.
    pub stats: StepStats,
}
