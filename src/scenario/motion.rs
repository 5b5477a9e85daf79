//! Prescribed motion of a surface (issue 22): a translation, a rotation about an axis through a
//! point, or both, each at a constant rate or by keyframes (linear interpolation between them).
//!
//! ```json
//! "motion": {
//!   "translation": {"keyframes": [[0, [0, 0, 0]], [0.5, [0, 0, 0]], [0.6, [0.02, 0, 0]]]},
//!   "rotation": {"axis": [0, 1, 0], "point_m": [0, 0, 0.1], "angular_velocity_rad_s": 2}
//! }
//! ```
//!
//! A translation is a constant `velocity_m_s`, or `keyframes` `[[t_s, [x_m, y_m, z_m]], ...]`: the
//! surface's offset from where the scenario places it at each time (held before the first
//! keyframe and after the last). A rotation turns the surface about `axis` (right-hand rule)
//! through `point_m` at `angular_velocity_rad_s`, or by `keyframes` `[[t_s, angle_deg], ...]`
//! (the angle turned from the scenario's placement). With both, the surface is turned first, then
//! shifted. The world carries such a surface on a rapier kinematic body (see `world::motion`).
//! A source takes the same motion (issue 31): its apples appear where it carries the source at
//! their spawn time, with its velocity there (`world::motion::Motion::spawn`).

use super::ranges::{self, num};
use super::ScenarioError;
use serde::{Deserialize, Serialize};

/// The prescribed motion of a surface or a source.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionSpec {
    /// Translation of the surface.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub translation: Option<TranslationSpec>,
    /// Rotation of the surface about a fixed axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<TurnSpec>,
}

/// A translation: a constant velocity or a keyframed offset.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TranslationSpec {
    /// Constant velocity (m/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity_m_s: Option<[f64; 3]>,
    /// Offsets from the placement at given times: `[t_s, [x_m, y_m, z_m]]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub keyframes: Option<Vec<(f64, [f64; 3])>>,
}

/// A rotation about a fixed axis through a point: a constant rate or a keyframed angle.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TurnSpec {
    /// Axis direction (any length > 0; normalised; right-hand rule).
    pub axis: [f64; 3],
    /// A point of the axis (m).
    pub point_m: [f64; 3],
    /// Constant rate (rad/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angular_velocity_rad_s: Option<f64>,
    /// Angle turned from the placement at given times: `[t_s, angle_deg]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub keyframes: Option<Vec<(f64, f64)>>,
}

/// A finite non-zero axis, normalised, or an error naming `field`.
pub fn unit_axis(field: &str, axis: [f64; 3]) -> Result<[f64; 3], ScenarioError> {
    // Scaled by the largest component first so that any finite axis normalises.
    let m = axis.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let a = axis.map(|x| x / m);
    let len = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(m > 0.0 && m.is_finite() && len.is_finite()) {
        return Err(ScenarioError::invalid(
            field,
            format!(
                "[{}, {}, {}]: a rotation axis needs a finite non-zero length",
                num(axis[0]),
                num(axis[1]),
                num(axis[2])
            ),
        ));
    }
    Ok(a.map(|x| x / len))
}

/// Checks keyframe times: each in the time range and after the one before.
fn check_times<T>(f: &str, keys: &[(f64, T)]) -> Result<(), ScenarioError> {
    if keys.is_empty() {
        return Err(ScenarioError::invalid(
            f,
            "empty: give at least one [t_s, value] keyframe",
        ));
    }
    for (i, k) in keys.iter().enumerate() {
        ranges::TIME.check(&format!("{f}[{i}][0]"), k.0)?;
        if i > 0 && k.0 <= keys[i - 1].0 {
            return Err(ScenarioError::invalid(
                format!("{f}[{i}][0]"),
                format!(
                    "t = {} s is not after the keyframe before it (t = {} s): keyframe times must increase",
                    num(k.0),
                    num(keys[i - 1].0)
                ),
            ));
        }
    }
    Ok(())
}

/// Validates a motion (`f` is its JSON path, `surfaces[k].motion` or `sources[k].motion`: one
/// check for both).
pub fn validate(f: &str, m: &MotionSpec) -> Result<(), ScenarioError> {
    if m.translation.is_none() && m.rotation.is_none() {
        return Err(ScenarioError::invalid(
            f,
            "empty: give a translation, a rotation or both",
        ));
    }
    if let Some(t) = &m.translation {
        let f = format!("{f}.translation");
        match (&t.velocity_m_s, &t.keyframes) {
            (Some(v), None) => ranges::SPEED.check_norm(&format!("{f}.velocity_m_s"), *v)?,
            (None, Some(keys)) => {
                let f = format!("{f}.keyframes");
                check_times(&f, keys)?;
                for (i, k) in keys.iter().enumerate() {
                    ranges::POSITION.check_each(&format!("{f}[{i}][1]"), k.1)?;
                }
                for i in 1..keys.len() {
                    let (t0, x0) = keys[i - 1];
                    let (t1, x1) = keys[i];
                    let d = (0..3).map(|c| (x1[c] - x0[c]).powi(2)).sum::<f64>().sqrt();
                    let v = d / (t1 - t0);
                    if !ranges::SPEED.contains(v) {
                        return Err(ScenarioError::invalid(
                            format!("{f}[{i}]"),
                            format!(
                                "moving {} m in {} s from the keyframe before is {} m/s, outside the range of fruit handling ({}): the profile jumps",
                                ranges::num3(d),
                                num(t1 - t0),
                                ranges::num3(v),
                                ranges::SPEED.describe()
                            ),
                        ));
                    }
                }
            }
            (None, None) => {
                return Err(ScenarioError::invalid(
                    f,
                    "missing: give velocity_m_s or keyframes, exactly one",
                ))
            }
            _ => {
                return Err(ScenarioError::invalid(
                    format!("{f}.velocity_m_s"),
                    "give either velocity_m_s or keyframes, exactly one",
                ))
            }
        }
    }
    if let Some(r) = &m.rotation {
        let f = format!("{f}.rotation");
        unit_axis(&format!("{f}.axis"), r.axis)?;
        ranges::POSITION.check_each(&format!("{f}.point_m"), r.point_m)?;
        match (r.angular_velocity_rad_s, &r.keyframes) {
            (Some(w), None) => {
                ranges::ANGULAR_SPEED.check_abs(&format!("{f}.angular_velocity_rad_s"), w)?
            }
            (None, Some(keys)) => {
                let f = format!("{f}.keyframes");
                check_times(&f, keys)?;
                for (i, k) in keys.iter().enumerate() {
                    ranges::TURN.check_abs(&format!("{f}[{i}][1]"), k.1)?;
                }
                for i in 1..keys.len() {
                    let (t0, a0) = keys[i - 1];
                    let (t1, a1) = keys[i];
                    let w = (a1 - a0).to_radians().abs() / (t1 - t0);
                    if !ranges::ANGULAR_SPEED.contains(w) {
                        return Err(ScenarioError::invalid(
                            format!("{f}[{i}]"),
                            format!(
                                "turning {} deg in {} s from the keyframe before is {} rad/s, outside the range of fruit handling ({}): the profile jumps",
                                ranges::num3(a1 - a0),
                                num(t1 - t0),
                                ranges::num3(w),
                                ranges::ANGULAR_SPEED.describe()
                            ),
                        ));
                    }
                }
            }
            (None, None) => {
                return Err(ScenarioError::invalid(
                    f,
                    "missing: give angular_velocity_rad_s or keyframes, exactly one",
                ))
            }
            _ => {
                return Err(ScenarioError::invalid(
                    format!("{f}.angular_velocity_rad_s"),
                    "give either angular_velocity_rad_s or keyframes, exactly one",
                ))
            }
        }
    }
    Ok(())
}
