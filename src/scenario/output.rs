//! The settings of `output` that size a run's files: how numbers are printed
//! ([`Precision`]), which part of each contact's force curve is kept ([`ForceHistory`]), and the
//! sample interval of `bodies.csv` when the scenario leaves it out ([`Sampling`]).

use super::Scenario;
use serde::de::{self, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// How numbers are printed in the CSV files (`output.precision`): a number of significant
/// digits (default 9, README "Outputs") or `"full"` (every f64 reads back bit for bit).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    /// Rounded to this many significant digits (1 to 17).
    Digits(u8),
    /// The shortest form that round-trips the f64 (up to 17 digits).
    Full,
}

impl Default for Precision {
    fn default() -> Self {
        Precision::Digits(crate::output::number::DEFAULT_DIGITS)
    }
}

impl Precision {
    /// Whether this is the default (then omitted from the scenario as written).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

impl Serialize for Precision {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Precision::Digits(n) => s.serialize_u8(*n),
            Precision::Full => s.serialize_str("full"),
        }
    }
}

impl<'de> Deserialize<'de> for Precision {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        const WANT: &str = "\"full\" or a number of significant digits from 1 to 17 (default 9)";
        impl Visitor<'_> for V {
            type Value = Precision;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(WANT)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Precision, E> {
                match v {
                    "full" => Ok(Precision::Full),
                    _ => Err(E::custom(format!("'{v}' is not {WANT}"))),
                }
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Precision, E> {
                match v {
                    1..=17 => Ok(Precision::Digits(v as u8)),
                    _ => Err(E::custom(format!(
                        "{v} digits: give {WANT} (17 digits already round-trip every number)"
                    ))),
                }
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Precision, E> {
                match u64::try_from(v) {
                    Ok(u) => self.visit_u64(u),
                    Err(_) => Err(E::custom(format!("{v} digits: give {WANT}"))),
                }
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Precision, E> {
                if v.fract() == 0.0 && (1.0..=17.0).contains(&v) {
                    self.visit_u64(v as u64)
                } else {
                    Err(E::custom(format!("{v} digits: give {WANT}")))
                }
            }
        }
        d.deserialize_any(V)
    }
}

/// Which part of each contact's force curve (`forces.csv`, the pulse fits, the force chart and
/// the viewer's curves) a run keeps (`output.force_history`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ForceHistory {
    /// The impact pulse and as much again after it ([`crate::record::events::IMPACT_HISTORY_SPAN`]),
    /// not the resting time that follows (`true`, the default); nothing of a contact that starts
    /// at rest.
    #[default]
    Impact,
    /// The whole contact, decimated evenly to at most 4096 samples (`"full"`).
    Full,
    /// None (`false`): no `forces.csv` and no `pulse_fits.csv`.
    Off,
}

impl ForceHistory {
    /// Whether any force curve is kept.
    pub fn is_kept(self) -> bool {
        self != ForceHistory::Off
    }
}

impl From<bool> for ForceHistory {
    fn from(keep: bool) -> Self {
        if keep {
            ForceHistory::Impact
        } else {
            ForceHistory::Off
        }
    }
}

impl Serialize for ForceHistory {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            ForceHistory::Impact => s.serialize_str("impact"),
            ForceHistory::Full => s.serialize_str("full"),
            ForceHistory::Off => s.serialize_bool(false),
        }
    }
}

impl<'de> Deserialize<'de> for ForceHistory {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        const WANT: &str = "true or \"impact\" (each contact's impact pulse, the default), \"full\" (the whole contact) or false (none)";
        impl Visitor<'_> for V {
            type Value = ForceHistory;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(WANT)
            }
            fn visit_bool<E: de::Error>(self, v: bool) -> Result<ForceHistory, E> {
                Ok(v.into())
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<ForceHistory, E> {
                match v {
                    "impact" => Ok(ForceHistory::Impact),
                    "full" => Ok(ForceHistory::Full),
                    _ => Err(E::custom(format!("'{v}' is not {WANT}"))),
                }
            }
        }
        d.deserialize_any(V)
    }
}

/// Rows of `bodies.csv` (apples and free-turning rollers times samples) the default sample
/// interval keeps a run under: at most about 28 MB of `bodies.csv` at the 9-digit precision's
/// 183 bytes a row (measured on the bin fill), when every apple is there from start to end; a
/// source's apples, fed in over the run, write fewer (the bin fill 79 000 rows, 14.5 MB).
pub const DEFAULT_SAMPLE_ROWS: f64 = 150_000.0;

/// The shortest default sample interval (s): what a short run gets.
pub const MIN_DEFAULT_SAMPLE_INTERVAL_S: f64 = 1e-3;

/// The sample interval of a run and where it comes from (`summary.json` `sampling`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sampling {
    /// The interval (s), before rounding to whole steps.
    pub interval_s: f64,
    /// `scenario` (given as `output.sample_interval_s`) or `default`.
    pub set_by: &'static str,
    /// Why this interval.
    pub why: String,
}

/// The interval of `bodies.csv` for `sc`: `output.sample_interval_s` when given; otherwise the
/// smallest of 1, 2, 5 x 10^k s, at least 1 ms, for which the planned apples and free-turning
/// rollers times the samples stay within [`DEFAULT_SAMPLE_ROWS`] (a short run keeps 1 ms; the
/// 150-apple, 18 s bin fill gets 20 ms).
pub fn sampling(sc: &Scenario) -> Sampling {
    if let Some(s) = sc.output.sample_interval_s {
        return Sampling {
            interval_s: s,
            set_by: "scenario",
            why: "output.sample_interval_s".into(),
        };
    }
    let bodies = super::budget::planned_apples(sc) + super::budget::free_rollers(sc);
    let rows = |interval: f64| bodies * samples(sc.duration_s, interval);
    let mut k = -3;
    let interval = loop {
        // From the decimal text, so that 2e-2 is the double nearest 0.02, as a user writes it.
        let found = [1, 2, 5].iter().find_map(|m| {
            let x: f64 = format!("{m}e{k}").parse().unwrap_or(f64::MAX);
            (rows(x) <= DEFAULT_SAMPLE_ROWS || x >= sc.duration_s.max(1e-300) || k >= 300)
                .then_some(x)
        });
        if let Some(x) = found {
            break x;
        }
        k += 1;
    };
    let why = if interval == MIN_DEFAULT_SAMPLE_INTERVAL_S {
        format!(
            "default: 1 ms, the finest default ({} apples x {} samples is within {} rows of bodies.csv)",
            bodies,
            samples(sc.duration_s, interval),
            DEFAULT_SAMPLE_ROWS
        )
    } else {
        format!(
            "default for {} apples over {} s: the smallest 1-2-5 step of at least 1 ms that keeps apples x samples ({} x {}) within {} rows of bodies.csv (set output.sample_interval_s for another)",
            bodies,
            sc.duration_s,
            bodies,
            samples(sc.duration_s, interval),
            DEFAULT_SAMPLE_ROWS
        )
    };
    Sampling {
        interval_s: interval,
        set_by: "default",
        why,
    }
}

/// The planned apples up to which a run keeps its impacts' force histories by default
/// ([`force_history`]). A judgement, not a measured limit: a run of a few dozen apples is read
/// contact by contact (its force curves, the eq. 13 pulse fits); a larger one (a bin fill of
/// thousands of contacts) through its peaks and the damage, and its histories cost it most of
/// its writing: the 150-apple bin fill's `forces.csv` is 14 MB and its histories and fits add
/// about half again to its wall time (docs/performance.md, issue 31).
pub const DEFAULT_HISTORY_APPLES: f64 = 50.0;

/// Which force histories a run keeps and where that comes from (`summary.json` `force_history`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HistoryChoice {
    /// What is kept: `"impact"`, `"full"` or `false`.
    pub kept: ForceHistory,
    /// `scenario` (given as `output.force_history`) or `default`.
    pub set_by: &'static str,
    /// Why.
    pub why: String,
}

/// The force histories of `sc`: `output.force_history` when given; otherwise the impact pulses
/// of a run of at most [`DEFAULT_HISTORY_APPLES`] planned apples, none of a larger one.
pub fn force_history(sc: &Scenario) -> HistoryChoice {
    if let Some(kept) = sc.output.force_history {
        return HistoryChoice {
            kept,
            set_by: "scenario",
            why: "output.force_history".into(),
        };
    }
    let apples = super::budget::planned_apples(sc);
    if apples <= DEFAULT_HISTORY_APPLES {
        HistoryChoice {
            kept: ForceHistory::Impact,
            set_by: "default",
            why: format!(
                "default for {apples} apples: the impact pulses (a run of at most {DEFAULT_HISTORY_APPLES} apples keeps them; output.force_history: false for none)"
            ),
        }
    } else {
        HistoryChoice {
            kept: ForceHistory::Off,
            set_by: "default",
            why: format!(
                "default for {apples} apples: none (a run of more than {DEFAULT_HISTORY_APPLES} apples is read through its peaks and damage; output.force_history: true keeps the impact pulses)"
            ),
        }
    }
}

/// Samples of a run of `duration_s` at `interval_s`: one at every whole interval from 0, and the
/// end state (at most one more).
pub fn samples(duration_s: f64, interval_s: f64) -> f64 {
    (duration_s / interval_s).floor() + 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scenario(duration_s: f64, apples: u32, output: &str) -> Scenario {
        crate::scenario::from_json(
            &format!(
                r#"{{"duration_s": {duration_s}, "time_step_s": "adaptive", "gravity_m_s2": [0, 0, -9.81],
                "output": {{{output}}},
                "materials": {{"apple": {{"preset": "apple-paper"}}}},
                "contact": {{"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000}},
                "sources": [{{"name": "s", "material": "apple", "diameter_m": 0.075, "position_m": [0, 0, 1],
                  "rate_per_s": 10, "count": {apples}}}]}}"#
            ),
            "test",
        )
        .unwrap()
    }

    /// A short run keeps 1 ms; the 150-apple 18 s bin fill gets 20 ms (150 x 902 rows; 10 ms
    /// would be 150 x 1802); the interval given is kept; a run longer than any budget samples
    /// once at the start and once at the end.
    #[test]
    fn the_default_interval_follows_length_and_apples() {
        let s = sampling(&scenario(0.5, 1, ""));
        assert_eq!((s.interval_s, s.set_by), (1e-3, "default"));
        let s = sampling(&scenario(18.0, 150, ""));
        assert_eq!(s.interval_s, 0.02);
        assert!(s.why.contains("150 x 902"), "{}", s.why);
        let s = sampling(&scenario(18.0, 150, r#""sample_interval_s": 0.1"#));
        assert_eq!((s.interval_s, s.set_by), (0.1, "scenario"));
        let s = sampling(&scenario(1e4, 100_000, ""));
        assert!(s.interval_s >= 1e4, "{}", s.interval_s);
        assert_eq!(sampling(&scenario(100.0, 1, "")).interval_s, 1e-3);
        assert_eq!(sampling(&scenario(1000.0, 1, "")).interval_s, 1e-2);
    }

    #[test]
    fn force_histories_by_default_up_to_50_apples() {
        let h = force_history(&scenario(18.0, 50, ""));
        assert_eq!((h.kept, h.set_by), (ForceHistory::Impact, "default"));
        assert!(h.why.contains("50 apples"), "{}", h.why);
        let h = force_history(&scenario(18.0, 51, ""));
        assert_eq!((h.kept, h.set_by), (ForceHistory::Off, "default"));
        assert!(h.why.contains("output.force_history: true"), "{}", h.why);
        let h = force_history(&scenario(18.0, 150, r#""force_history": true"#));
        assert_eq!((h.kept, h.set_by), (ForceHistory::Impact, "scenario"));
        let h = force_history(&scenario(1.0, 1, r#""force_history": false"#));
        assert_eq!((h.kept, h.set_by), (ForceHistory::Off, "scenario"));
    }

    #[test]
    fn precision_and_force_history_read_as_documented() {
        let o = |s: &str| {
            crate::scenario::parse_one::<crate::scenario::OutputSpec>(s, "t")
                .map_err(|e| e.to_string())
        };
        assert_eq!(o("{}").unwrap().precision, Precision::Digits(9));
        assert_eq!(
            o(r#"{"precision": "full"}"#).unwrap().precision,
            Precision::Full
        );
        assert_eq!(
            o(r#"{"precision": 12}"#).unwrap().precision,
            Precision::Digits(12)
        );
        for bad in [
            r#"{"precision": 0}"#,
            r#"{"precision": 18}"#,
            r#"{"precision": "half"}"#,
            r#"{"precision": 9.5}"#,
        ] {
            let e = o(bad).unwrap_err();
            assert!(
                e.contains("precision") && e.contains("\"full\" or a number"),
                "{e}"
            );
        }
        assert_eq!(o("{}").unwrap().force_history, None);
        assert_eq!(
            o(r#"{"force_history": true}"#).unwrap().force_history,
            Some(ForceHistory::Impact)
        );
        assert_eq!(
            o(r#"{"force_history": "full"}"#).unwrap().force_history,
            Some(ForceHistory::Full)
        );
        assert_eq!(
            o(r#"{"force_history": false}"#).unwrap().force_history,
            Some(ForceHistory::Off)
        );
        let e = o(r#"{"force_history": "all"}"#).unwrap_err();
        assert!(e.contains("force_history") && e.contains("\"full\""), "{e}");
        let spec =
            o(r#"{"force_history": "full", "precision": "full", "compress": true}"#).unwrap();
        let back = serde_json::to_string(&spec).unwrap();
        assert_eq!(o(&back).unwrap(), spec, "{back}");
    }
}
