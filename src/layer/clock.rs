//! The step clock: what the driver asks for the coming step ([`StepRequest`]), the rules that
//! bound a step (growth, landing), and the layer's memory of the steps taken.
//!
//! The step travels as one value: the driver builds a request every step (its time, the step it
//! allows, the step it took last, the instant it must land on), the layer answers with the step
//! it applied the forces for. Each rule is written here once and used by both: the driver's cap
//! ([`StepRequest::adaptive`]) and the layer's look-ahead for contacts about to start
//! ([`growth_cap`]) follow the same growth rule, and the step is landed on output samples and the
//! end by the same formula ([`land`]).

/// What the driver asks of the layer for the coming step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepRequest {
    /// Time of the current poses (s).
    pub time_s: f64,
    /// The step: with a fixed step, the one to take; with step control, the longest the driver
    /// allows now (already landed, see [`StepRequest::adaptive`]) (s).
    pub dt_s: f64,
    /// The longest step the driver ever takes (s): how far ahead to look for contacts about to
    /// start (with step control; the layer looks at most [`growth_cap`] ahead).
    pub max_dt_s: f64,
    /// The step taken last (s); `None` before the first.
    pub last_dt_s: Option<f64>,
    /// Time left to an instant the step must land on exactly (the end of the run), if
    /// any: the chosen step is shortened to divide it evenly, never leaving a sliver.
    pub land_in_s: Option<f64>,
}

impl StepRequest {
    /// A fixed step `dt_s` from the poses at `time_s` (the step before was the same).
    pub fn fixed(time_s: f64, dt_s: f64) -> Self {
        Self {
            time_s,
            dt_s,
            max_dt_s: dt_s,
            last_dt_s: Some(dt_s),
            land_in_s: None,
        }
    }

    /// A step chosen by the layer's step control, at most `max_dt_s`, at most twice the last
    /// ([`growth_cap`]; the first at most `first_dt_s`), landing exactly on the instant
    /// `land_in_s` ahead if it is positive.
    pub fn adaptive(
        time_s: f64,
        max_dt_s: f64,
        last_dt_s: Option<f64>,
        first_dt_s: f64,
        land_in_s: f64,
    ) -> Self {
        let land_in_s = (land_in_s > 0.0).then_some(land_in_s);
        Self {
            time_s,
            dt_s: land(growth_cap(max_dt_s, last_dt_s, first_dt_s), land_in_s),
            max_dt_s,
            last_dt_s,
            land_in_s,
        }
    }

    /// The step to take when the contacts allow at most `limit_s`: the request's step, shortened
    /// to the limit and landed.
    pub fn choose(&self, limit_s: f64) -> f64 {
        land(self.dt_s.min(limit_s), self.land_in_s)
    }

    /// The step that led to the current poses: the last one, or (at the first) this one.
    pub fn back_s(&self) -> f64 {
        self.last_dt_s.unwrap_or(self.dt_s)
    }

    /// How far ahead a contact may start within the coming step (with step control).
    pub fn horizon_s(&self) -> f64 {
        growth_cap(self.max_dt_s, self.last_dt_s, self.max_dt_s)
    }
}

/// The growth rule of variable steps: at most `max_s`, and at most twice the last step (the
/// first: at most `first_s`). A step may shrink at once (an impact begins) but only grow
/// gradually, so that a contact about to start is seen at most two steps ahead.
pub fn growth_cap(max_s: f64, last_s: Option<f64>, first_s: f64) -> f64 {
    match last_s {
        Some(last) => max_s.min(2.0 * last),
        None => first_s.min(max_s),
    }
}

/// `dt` shortened so that whole steps land exactly on the instant `left` ahead (no sliver).
pub fn land(dt: f64, left: Option<f64>) -> f64 {
    match left {
        Some(left) => left / (left / dt).ceil(),
        None => dt,
    }
}

/// What limited an adaptive step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, PartialOrd, Ord)]
pub enum StepLimit {
    /// Nothing in the layer: the driver's cap (largest step, output samples, end).
    #[default]
    None,
    /// An impact in progress.
    Impact,
    /// A resting contact's normal oscillation.
    Resting,
    /// A pair about to touch.
    Approaching,
    /// The pair-finding margins (an apple moving fast).
    Motion,
}

/// The layer's memory of the steps.
#[derive(Debug, Default)]
pub(super) struct StepClock {
    /// Time of the current poses (s).
    pub time_s: f64,
    /// The step that led to the current poses (touch and parting instants are interpolated
    /// within it).
    pub dt_back: f64,
    /// How far ahead contacts may start within the coming step (s; step control only).
    pub horizon_s: f64,
    /// Per apple: not stepped yet (its first kick spans half a step, see `frame::Loads`).
    pub first_step: Vec<bool>,
    /// Steps begun so far (riders' lazy carries count them, `ContactStore::carry_later`).
    pub steps: u64,
}

impl StepClock {
    /// Takes the request of the coming step.
    pub fn begin(&mut self, request: &StepRequest) {
        self.time_s = request.time_s;
        self.steps += 1;
        self.dt_back = request.back_s();
        self.horizon_s = request.horizon_s();
    }
}
