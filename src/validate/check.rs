//! One check of the validation: a number of ours against a reference or a limit, with its
//! tolerance and verdict, as one row of the report's tables.

use serde::Serialize;

/// How a number is shown in the report. Values are kept in SI units; the unit only formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Unit {
    /// Newtons.
    Newton,
    /// Seconds, shown in milliseconds.
    Millisecond,
    /// Seconds.
    Second,
    /// Metres per second.
    MetrePerSecond,
    /// A fraction, shown in percent.
    Percent,
    /// A plain number.
    Plain,
}

impl Unit {
    /// `value` (SI) as the report shows it, with its unit.
    pub fn show(self, value: f64) -> String {
        if !value.is_finite() {
            return "-".into();
        }
        match self {
            Unit::Newton => format!("{value:.2} N"),
            Unit::Millisecond => format!("{:.3} ms", value * 1e3),
            Unit::Second => format!("{value:.4} s"),
            Unit::MetrePerSecond => format!("{value:.4} m/s"),
            Unit::Percent => format!("{:+.2} %", value * 100.0),
            Unit::Plain => format!("{value:.4}"),
        }
    }
}

/// What makes a check pass: a relative error against a reference (closed forms, the reference
/// integration, the paper's numbers), or a bound for what the paper states only as a trend or
/// a limit ("less than 0.1 s").
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Criterion {
    /// |ours / reference - 1| <= tolerance.
    Relative {
        /// Largest relative error allowed.
        tolerance: f64,
    },
    /// ours < limit.
    Below {
        /// Exclusive upper limit (SI, in the check's unit).
        limit: f64,
    },
    /// ours > limit.
    Above {
        /// Exclusive lower limit (SI, in the check's unit).
        limit: f64,
    },
    /// ours >= limit.
    AtLeast {
        /// Inclusive lower limit.
        limit: f64,
    },
}

/// One check: a row of a report table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Check {
    /// Stable key, `figN/what/case` (tests look checks up by it).
    pub key: String,
    /// What is compared, in words.
    pub what: String,
    /// Our value (SI).
    pub ours: f64,
    /// The reference value (SI), for relative checks.
    pub reference: Option<f64>,
    /// Where the reference or the limit comes from.
    pub source: String,
    /// How values are shown.
    pub unit: Unit,
    /// The criterion.
    pub criterion: Criterion,
    /// Whether it holds.
    pub pass: bool,
}

impl Check {
    /// A relative comparison with a reference value: |ours / reference - 1| <= `tolerance`.
    pub fn relative(
        key: impl Into<String>,
        what: impl Into<String>,
        ours: f64,
        reference: f64,
        source: impl Into<String>,
        unit: Unit,
        tolerance: f64,
    ) -> Check {
        let pass = ((ours / reference) - 1.0).abs() <= tolerance;
        Check {
            key: key.into(),
            what: what.into(),
            ours,
            reference: Some(reference),
            source: source.into(),
            unit,
            criterion: Criterion::Relative { tolerance },
            pass,
        }
    }

    /// A bound on our value. A [`Criterion::Relative`] has no reference here ([`Check::relative`]
    /// takes one), so given to this function it fails rather than passing unchecked.
    pub fn bound(
        key: impl Into<String>,
        what: impl Into<String>,
        ours: f64,
        source: impl Into<String>,
        unit: Unit,
        criterion: Criterion,
    ) -> Check {
        let pass = match criterion {
            Criterion::Relative { .. } => false,
            Criterion::Below { limit } => ours < limit,
            Criterion::Above { limit } => ours > limit,
            Criterion::AtLeast { limit } => ours >= limit,
        };
        Check {
            key: key.into(),
            what: what.into(),
            ours,
            reference: None,
            source: source.into(),
            unit,
            criterion,
            pass,
        }
    }

    /// A check that could not be evaluated (its runs failed): always a failure.
    pub fn missing(
        key: impl Into<String>,
        what: impl Into<String>,
        why: impl Into<String>,
    ) -> Check {
        Check {
            key: key.into(),
            what: what.into(),
            ours: f64::NAN,
            reference: None,
            source: why.into(),
            unit: Unit::Plain,
            criterion: Criterion::AtLeast { limit: 0.0 },
            pass: false,
        }
    }

    /// Relative error ours / reference - 1, for relative checks.
    pub fn error(&self) -> Option<f64> {
        self.reference.map(|r| self.ours / r - 1.0)
    }

    /// The tolerance or limit as the report shows it, so a reader sees what each row was held to.
    pub fn tolerance_text(&self) -> String {
        match self.criterion {
            Criterion::Relative { tolerance } => format!("± {} %", trim(tolerance * 100.0)),
            Criterion::Below { limit } => format!("< {}", self.unit.show(limit)),
            Criterion::Above { limit } => format!("> {}", self.unit.show(limit)),
            Criterion::AtLeast { limit } => format!(">= {}", self.unit.show(limit)),
        }
    }

    /// `PASS` or `FAIL`.
    pub fn verdict(&self) -> &'static str {
        if self.pass {
            "PASS"
        } else {
            "FAIL"
        }
    }
}

/// A number without trailing zeros (0.5, 4, 0.25).
fn trim(x: f64) -> String {
    let s = format!("{x:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verdicts_and_texts() {
        let c = Check::relative("k", "w", 11.18, 11.5, "paper", Unit::Newton, 0.04);
        assert!(c.pass);
        assert_eq!(c.tolerance_text(), "± 4 %");
        assert!((c.error().unwrap() + 0.027826).abs() < 1e-6);
        let c = Check::relative("k", "w", 10.0, 11.5, "paper", Unit::Newton, 0.04);
        assert!(!c.pass);
        let c = Check::bound(
            "k",
            "w",
            0.0978,
            "paper",
            Unit::Second,
            Criterion::Below { limit: 0.1 },
        );
        assert!(c.pass);
        assert_eq!(c.tolerance_text(), "< 0.1000 s");
        let c = Check::bound(
            "k",
            "w",
            0.0,
            "",
            Unit::Percent,
            Criterion::Above { limit: 0.0 },
        );
        assert!(!c.pass);
        assert!(!Check::missing("k", "w", "run failed").pass);
        assert_eq!(Unit::Millisecond.show(8.66e-3), "8.660 ms");
        assert_eq!(Unit::Percent.show(-0.2171), "-21.71 %");
    }
}
