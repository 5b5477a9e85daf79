//! What the layer refuses: registration mistakes, and runs that went wrong (physics.md section
//! 10: a run that went unstable is refused, never returned as a result).

use rapier3d_f64::geometry::ColliderHandle;
use thiserror::Error;

/// Errors of the layer: registration mistakes and runs that went wrong.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LayerError {
    /// The collider handle is not in the collider set.
    #[error("collider {0:?} is not in the collider set")]
    UnknownCollider(ColliderHandle),
    /// An apple collider must be a ball attached to a dynamic body.
    #[error("apple '{0}': its collider must be a ball attached to a dynamic rigid body")]
    NotABall(String),
    /// A collider-less apple body must be dynamic, with a mass, an inertia and a positive radius.
    #[error("apple '{0}': its rigid body must be dynamic, with a positive mass and inertia (set them with additional_mass_properties), and its radius positive")]
    NoMass(String),
    /// The collider (or body) is registered twice.
    #[error("collider of '{0}' is already registered with the layer")]
    Duplicate(String),
    /// A concave surface tighter than the apple: Hertz theory has no answer (K1 + K2 <= 0).
    #[error("apple '{apple}' (radius {apple_radius_m} m) cannot touch concave surface '{surface}' of radius {surface_radius_m} m: conforming contact (K1 + K2 <= 0) is outside Hertz theory; make the surface radius larger than the apple's")]
    Conforming {
        /// Apple name.
        apple: String,
        /// Surface name.
        surface: String,
        /// Apple radius.
        apple_radius_m: f64,
        /// Surface radius.
        surface_radius_m: f64,
    },
    /// A registered apple's rigid body is no longer in the body set (the caller removed it
    /// without telling the layer).
    #[error("apple '{apple}': its rigid body was removed from the body set (at t = {} s); remove apples only between runs", crate::math::secs(*time_s))]
    MissingBody {
        /// Apple name.
        apple: String,
        /// Simulated time.
        time_s: f64,
    },
    /// A body's state went non-finite.
    #[error("non-finite state of '{body}' at t = {} s: the run blew up (the time step is too large for the stiffest contact, or a force is unbounded)", crate::math::secs(*time_s))]
    NonFinite {
        /// Body name.
        body: String,
        /// Simulated time.
        time_s: f64,
    },
    /// The stability guard stopped the run.
    #[error("unstable at t = {} s, contact '{a}' - '{b}': {what}", crate::math::secs(*time_s))]
    Unstable {
        /// First body.
        a: String,
        /// Second body.
        b: String,
        /// Simulated time.
        time_s: f64,
        /// What was seen and what would work.
        what: String,
        /// A time step that would resolve this contact, when the cause is the step.
        suggested_dt_s: Option<f64>,
    },
}
