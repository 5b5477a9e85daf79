//! How a scenario trades speed for accuracy: the time-step policy, the accuracy target and the
//! fidelity level (docs/accuracy.md has the measured trade).

use serde::de::{self, Deserializer, Visitor};
use serde::ser::Serializer;
use serde::{Deserialize, Serialize};
use std::fmt;

/// `time_step_s`: a number (a fixed step, s), `"auto"` (a fixed step derived from the stiffest
/// contact the scene can produce and the accuracy target), or `"adaptive"` (a step chosen every
/// step from the contacts in progress and about to start, long in free flight, short in impacts).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeStep {
    /// A fixed step (s).
    Fixed(f64),
    /// A fixed step from the scene's stiffest possible contact.
    Auto,
    /// A step that follows the scene.
    Adaptive,
}

impl From<f64> for TimeStep {
    fn from(dt: f64) -> Self {
        TimeStep::Fixed(dt)
    }
}

impl Serialize for TimeStep {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            TimeStep::Fixed(dt) => s.serialize_f64(*dt),
            TimeStep::Auto => s.serialize_str("auto"),
            TimeStep::Adaptive => s.serialize_str("adaptive"),
        }
    }
}

impl<'de> Deserialize<'de> for TimeStep {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = TimeStep;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a time step in seconds, \"auto\" or \"adaptive\"")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<TimeStep, E> {
                Ok(TimeStep::Fixed(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<TimeStep, E> {
                Ok(TimeStep::Fixed(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<TimeStep, E> {
                Ok(TimeStep::Fixed(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<TimeStep, E> {
                match v {
                    "auto" => Ok(TimeStep::Auto),
                    "adaptive" => Ok(TimeStep::Adaptive),
                    _ => Err(E::invalid_value(
                        de::Unexpected::Str(v),
                        &"a number of seconds, \"auto\" or \"adaptive\"",
                    )),
                }
            }
        }
        d.deserialize_any(V)
    }
}

/// `accuracy`: steps per elastic contact time of the stiffest impact (physics.md section 10:
/// symplectic Euler errs on the peak force by 0.9 % at 10 steps, 0.2 % at 20, 0.05 % at 40).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Accuracy {
    /// 10 steps per contact: about 1 % on peak forces.
    Preview,
    /// 20 steps per contact: about 0.2 % on peak forces.
    #[default]
    Balanced,
    /// 50 steps per contact: about 0.03 % on peak forces.
    Precise,
    /// An explicit number of steps per contact (>= 5).
    Steps(f64),
}

impl Accuracy {
    /// Steps per contact time.
    pub fn steps_per_contact(&self) -> f64 {
        match *self {
            Accuracy::Preview => 10.0,
            Accuracy::Balanced => 20.0,
            Accuracy::Precise => 50.0,
            Accuracy::Steps(n) => n,
        }
    }
}

impl Serialize for Accuracy {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Accuracy::Preview => s.serialize_str("preview"),
            Accuracy::Balanced => s.serialize_str("balanced"),
            Accuracy::Precise => s.serialize_str("precise"),
            Accuracy::Steps(n) => s.serialize_f64(*n),
        }
    }
}

impl<'de> Deserialize<'de> for Accuracy {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Accuracy;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "\"preview\", \"balanced\", \"precise\" or a number of steps per contact",
                )
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Accuracy, E> {
                Ok(Accuracy::Steps(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Accuracy, E> {
                Ok(Accuracy::Steps(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Accuracy, E> {
                Ok(Accuracy::Steps(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Accuracy, E> {
                match v {
                    "preview" => Ok(Accuracy::Preview),
                    "balanced" => Ok(Accuracy::Balanced),
                    "precise" => Ok(Accuracy::Precise),
                    _ => Err(E::invalid_value(
                        de::Unexpected::Str(v),
                        &"\"preview\", \"balanced\", \"precise\" or a number",
                    )),
                }
            }
        }
        d.deserialize_any(V)
    }
}

/// `fidelity`: which parts of the contact model run. Each level says what it cannot tell you.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Fidelity {
    /// rapier's own contacts (restitution sqrt(ke), friction) at large steps: a quick kinematic
    /// preview of where apples go. No contact forces, contact times or pressures at all.
    #[serde(rename = "rigid")]
    Rigid,
    /// Elastic Hertz with friction: peak forces of first impacts, but no energy loss, so apples
    /// bounce for ever and later impacts, rest positions and restitution are wrong.
    #[serde(rename = "hertz")]
    Hertz,
    /// Hertz with the eq. 12 energy loss and Coulomb friction (the default): the paper's model.
    #[default]
    #[serde(rename = "hertz-damped")]
    HertzDamped,
    /// As `hertz-damped`, plus the eq. 9 shift of the contact patch along the friction force, which
    /// changes the friction moment arm (a small effect: 1e-4 on a slip-to-roll speed).
    #[serde(rename = "full")]
    Full,
}

impl Fidelity {
    /// What the level cannot tell (reported in the summary).
    pub fn limits(&self) -> &'static str {
        match self {
            Fidelity::Rigid => "rigid: rapier's own impulse contacts; no contact forces, contact times, pressures or bruise assessment, rebounds only approximate the eq. 12 restitution",
            Fidelity::Hertz => "hertz: elastic Hertz, no energy loss; first-impact peak forces only, apples never come to rest, restitution is 1",
            Fidelity::HertzDamped => "hertz-damped: the paper's model (Hertz, eq. 12, Coulomb friction); no rolling or twisting resistance, no contact-patch shift",
            Fidelity::Full => "full: the paper's model plus the eq. 9 contact-patch shift; no rolling or twisting resistance beyond that shift",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_forms() {
        let t: TimeStep = serde_json::from_str("1e-5").unwrap();
        assert_eq!(t, TimeStep::Fixed(1e-5));
        assert_eq!(
            serde_json::from_str::<TimeStep>("\"auto\"").unwrap(),
            TimeStep::Auto
        );
        assert!(serde_json::from_str::<TimeStep>("\"fast\"").is_err());
        let a: Accuracy = serde_json::from_str("\"precise\"").unwrap();
        assert_eq!(a.steps_per_contact(), 50.0);
        assert_eq!(
            serde_json::from_str::<Accuracy>("30").unwrap(),
            Accuracy::Steps(30.0)
        );
        let f: Fidelity = serde_json::from_str("\"hertz-damped\"").unwrap();
        assert_eq!(f, Fidelity::HertzDamped);
        assert_eq!(serde_json::to_string(&Fidelity::Full).unwrap(), "\"full\"");
        assert_eq!(
            serde_json::to_string(&TimeStep::Adaptive).unwrap(),
            "\"adaptive\""
        );
    }
}
