//! Fitting a damage model's coefficients to measured bruises (docs/damage.md section 8). Pure
//! functions: what the simulator says each drop did to the apple (its [`Hit`]) and what the lab
//! measured in, the coefficients, their standard errors and the residuals out.
//!
//! | model | bruise volumes | bruised yes/no |
//! |---|---|---|
//! | energy | BS and E_th, least squares on the volumes ([`fit_energy`]) | E_th only (the onset); BS is the preset's |
//! | pressure-area | p_c (and the depth ratio), least squares on the volumes ([`fit_pressure_area`]) | p_c only: the onset p0 > p_c |
//! | peak-force | F_th, the onset of the drops with a bruise (volume > 0) | F_th |
//!
//! Volumes are fitted by least squares; each coefficient's standard error is that of the fit's
//! Jacobian J at the optimum, sqrt(diag(s^2 (J^T J)^-1)) with s^2 = SSR / (n - p): it measures
//! the scatter of the measured bruises about the model, not the uncertainty of what the
//! simulation was given (modulus, restitution, mass), which moves every hit together. An onset
//! is fitted from yes/no outcomes ([`fit_onset`]): where the data separate (every unbruised
//! drop below every bruised one) the threshold is the midpoint of the gap, and the data bound it
//! to the gap and say no more; where they overlap, by maximum likelihood with a logistic onset
//! P(bruised) = 1 / (1 + exp(-(x - x50) / w)), the threshold x50 with its standard error from
//! the inverse Fisher information (the delta method).

use super::{model, DamageParams, Hit};
use crate::scenario::damage::{DamageModelName, DamageSpec};
use thiserror::Error;

/// What a lab measured of one drop's bruise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Measured {
    /// Bruise volume (mm^3; 0: no bruise).
    Volume(f64),
    /// Bruised or not (no size).
    Bruised(bool),
}

impl Measured {
    /// Whether the drop bruised (a volume above 0).
    pub fn bruised(&self) -> bool {
        match *self {
            Measured::Volume(v) => v > 0.0,
            Measured::Bruised(b) => b,
        }
    }

    /// The volume, if measured (mm^3).
    pub fn volume_mm3(&self) -> Option<f64> {
        match *self {
            Measured::Volume(v) => Some(v),
            Measured::Bruised(_) => None,
        }
    }
}

/// Why the coefficients could not be fitted.
#[derive(Debug, Error, PartialEq)]
pub enum FitError {
    /// No drop bruised.
    #[error("no drop bruised: the data put the {quantity} onset above the hardest drop ({largest}); add harder drops")]
    NoBruise {
        /// The onset's variable (`absorbed energy`, `peak centre pressure`, `peak force`).
        quantity: &'static str,
        /// The hardest drop's value of it, with its unit.
        largest: String,
    },
    /// Every drop bruised.
    #[error("every drop bruised: the data put the {quantity} onset below the gentlest drop ({smallest}); add gentler drops")]
    AllBruised {
        /// The onset's variable.
        quantity: &'static str,
        /// The gentlest drop's value of it, with its unit.
        smallest: String,
    },
    /// Too few drops of the kind the fit needs.
    #[error("{0}")]
    TooFew(String),
    /// The data run against the model.
    #[error("{0}")]
    Against(String),
}

/// How the coefficients were found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Least squares on the bruise volumes.
    LeastSquares,
    /// Yes/no data that separate: the threshold is the midpoint of the gap between the largest
    /// value without a bruise and the smallest with one.
    Separating {
        /// The largest value without a bruise.
        below: f64,
        /// The smallest value with one.
        above: f64,
    },
    /// Yes/no data that overlap: maximum likelihood with a logistic onset.
    Logistic {
        /// The logistic's width w (the 10-90 % span is 2 ln 9 w = 4.39 w).
        width: f64,
    },
}

/// One fitted coefficient.
#[derive(Debug, Clone, PartialEq)]
pub struct Coefficient {
    /// Its field in a damage entry (`bruise_susceptibility_mm3_j`, ...).
    pub field: &'static str,
    /// Its symbol in the docs (`BS`, `E_th`, `p_c`, `F_th`, `depth_ratio`).
    pub symbol: &'static str,
    /// The value, in the field's unit.
    pub value: f64,
    /// Its standard error, where the fit defines one (least squares with more drops than
    /// coefficients; a logistic onset).
    pub std_error: Option<f64>,
    /// The unit (`mm^3/J`, `J`, `Pa`, `N`, empty for a ratio).
    pub unit: &'static str,
}

/// One drop as the fitted model sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DropFit {
    /// The model's variable for an onset fit (absorbed energy J, peak centre pressure Pa or peak
    /// force N); the absorbed energy for an energy fit, the peak centre pressure for a
    /// pressure-area fit.
    pub x: f64,
    /// What was measured.
    pub measured: Measured,
    /// The volume the fitted model gives the hit (mm^3; volume fits).
    pub predicted_volume_mm3: Option<f64>,
    /// Whether the fitted model bruises the hit.
    pub predicted_bruised: bool,
    /// Measured less predicted volume (mm^3; volume fits).
    pub residual_mm3: Option<f64>,
    /// The fitted probability of a bruise (logistic onset fits).
    pub probability: Option<f64>,
}

/// A fitted damage model.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// The model.
    pub model: DamageModelName,
    /// The fitted coefficients.
    pub coefficients: Vec<Coefficient>,
    /// How.
    pub method: Method,
    /// Each drop, in the order given.
    pub drops: Vec<DropFit>,
    /// Root mean square of the volume residuals (mm^3; volume fits).
    pub residual_rms_mm3: Option<f64>,
    /// Drops the fitted model calls the wrong way (bruised or not).
    pub misclassified: usize,
    /// Degrees of freedom of the residuals (drops less coefficients; volume fits).
    pub dof: usize,
    /// What the fit could not determine, in words (a threshold at a kink of the model, a
    /// coefficient at the end of its search range, too few informative drops).
    pub notes: Vec<String>,
    /// The damage entry of the fitted coefficients (the model and its coefficients only, with
    /// `depth_ratio` when fitted or given).
    pub spec: DamageSpec,
}

/// What a fit may be told beyond the data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// Bruise depth over the apple's deformation (pressure-area model; default the preset's).
    pub depth_ratio: f64,
    /// Whether `depth_ratio` was given (then written into the entry).
    pub depth_ratio_given: bool,
    /// Fit the depth ratio too (pressure-area model with volumes).
    pub fit_depth_ratio: bool,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            depth_ratio: crate::scenario::damage::DEPTH_RATIO.value,
            depth_ratio_given: false,
            fit_depth_ratio: false,
        }
    }
}

/// Fits `model` to the hits of the drops and what was measured of them (one each, in order).
/// Volumes fit the energy and pressure-area models by least squares; yes/no outcomes (or, for
/// the peak-force model, whether a volume is above 0) fit an onset threshold.
pub fn fit(
    model: DamageModelName,
    hits: &[Hit],
    measured: &[Measured],
    opts: FitOptions,
) -> Result<Fit, FitError> {
    assert_eq!(hits.len(), measured.len(), "one measurement per hit");
    let volumes: Option<Vec<f64>> = measured.iter().map(|m| m.volume_mm3()).collect();
    match (model, volumes) {
        (DamageModelName::Energy, Some(v)) => fit_energy(hits, &v),
        (DamageModelName::PressureArea, Some(v)) => fit_pressure_area(hits, &v, opts),
        _ => fit_onset_model(model, hits, measured, opts),
    }
}

/// The variable of a model's onset, its name and unit, for a hit.
fn onset_variable(model: DamageModelName, h: &Hit) -> f64 {
    match model {
        DamageModelName::Energy => h.absorbed_energy_j,
        DamageModelName::PressureArea => h.peak_pressure_pa,
        DamageModelName::PeakForce => h.peak_force_n,
    }
}

fn onset_names(model: DamageModelName) -> (&'static str, &'static str, &'static str, &'static str) {
    match model {
        DamageModelName::Energy => ("absorbed energy", "J", "threshold_energy_j", "E_th"),
        DamageModelName::PressureArea => {
            ("peak centre pressure", "Pa", "critical_pressure_pa", "p_c")
        }
        DamageModelName::PeakForce => ("peak force", "N", "peak_force_n", "F_th"),
    }
}

fn spec_of(model: DamageModelName, field: &str, value: f64, base: &DamageSpec) -> DamageSpec {
    let mut s = DamageSpec {
        model: Some(model),
        ..base.clone()
    };
    match field {
        "threshold_energy_j" => s.threshold_energy_j = Some(value),
        "critical_pressure_pa" => s.critical_pressure_pa = Some(value),
        "peak_force_n" => s.peak_force_n = Some(value),
        _ => unreachable!("an onset field"),
    }
    s
}

fn fit_onset_model(
    model: DamageModelName,
    hits: &[Hit],
    measured: &[Measured],
    opts: FitOptions,
) -> Result<Fit, FitError> {
    let (quantity, unit, field, symbol) = onset_names(model);
    let x: Vec<f64> = hits.iter().map(|h| onset_variable(model, h)).collect();
    let y: Vec<bool> = measured.iter().map(|m| m.bruised()).collect();
    let on = fit_onset(&x, &y, quantity, unit)?;
    let base = DamageSpec {
        depth_ratio: (model == DamageModelName::PressureArea && opts.depth_ratio_given)
            .then_some(opts.depth_ratio),
        ..DamageSpec::default()
    };
    let spec = spec_of(model, field, on.threshold, &base);
    let drops: Vec<DropFit> = x
        .iter()
        .zip(measured)
        .map(|(&x, &m)| DropFit {
            x,
            measured: m,
            predicted_volume_mm3: None,
            predicted_bruised: x > on.threshold,
            residual_mm3: None,
            probability: on.probability(x),
        })
        .collect();
    let misclassified = drops
        .iter()
        .filter(|d| d.predicted_bruised != d.measured.bruised())
        .count();
    Ok(Fit {
        model,
        coefficients: vec![Coefficient {
            field,
            symbol,
            value: on.threshold,
            std_error: on.std_error,
            unit,
        }],
        method: on.method,
        drops,
        residual_rms_mm3: None,
        misclassified,
        dof: hits.len().saturating_sub(1),
        notes: Vec::new(),
        spec,
    })
}

/// An onset threshold fitted to yes/no outcomes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Onset {
    /// The threshold: bruised above it.
    pub threshold: f64,
    /// Its standard error (logistic fits only; separating data bound it to the gap instead).
    pub std_error: Option<f64>,
    /// How it was found.
    pub method: Method,
}

impl Onset {
    /// The fitted probability of a bruise at `x` (logistic fits).
    pub fn probability(&self, x: f64) -> Option<f64> {
        match self.method {
            Method::Logistic { width } => Some(logistic((x - self.threshold) / width)),
            _ => None,
        }
    }
}

fn logistic(z: f64) -> f64 {
    1.0 / (1.0 + (-z).exp())
}

/// The onset threshold of outcomes `bruised` at values `x` (bruised above the threshold).
/// Separating data (every unbruised value below every bruised one, or equal at most): the
/// midpoint of the gap, [`Method::Separating`]. Overlapping data: maximum likelihood with a
/// logistic onset, [`Method::Logistic`], the threshold the 50 % point with its standard error
/// from the inverse Fisher information. `quantity` and `unit` name x in messages.
pub fn fit_onset(
    x: &[f64],
    bruised: &[bool],
    quantity: &'static str,
    unit: &'static str,
) -> Result<Onset, FitError> {
    let max_no = x
        .iter()
        .zip(bruised)
        .filter(|(_, &b)| !b)
        .map(|(&x, _)| x)
        .fold(f64::NEG_INFINITY, f64::max);
    let min_yes = x
        .iter()
        .zip(bruised)
        .filter(|(_, &b)| b)
        .map(|(&x, _)| x)
        .fold(f64::INFINITY, f64::min);
    let show = |v: f64| format!("{} {unit}", crate::math::human(v, 4, 1));
    if min_yes == f64::INFINITY {
        return Err(FitError::NoBruise {
            quantity,
            largest: show(max_no),
        });
    }
    if max_no == f64::NEG_INFINITY {
        return Err(FitError::AllBruised {
            quantity,
            smallest: show(min_yes),
        });
    }
    if max_no <= min_yes {
        return Ok(Onset {
            threshold: 0.5 * (max_no + min_yes),
            std_error: None,
            method: Method::Separating {
                below: max_no,
                above: min_yes,
            },
        });
    }
    logistic_onset(x, bruised, quantity)
}

/// Maximum likelihood of P(bruised | x) = 1 / (1 + exp(-(b0 + b1 z))), z = (x - m) / s (x
/// standardised), by Newton's method with step halving.
fn logistic_onset(x: &[f64], y: &[bool], quantity: &'static str) -> Result<Onset, FitError> {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let s = (x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / n).sqrt();
    let z: Vec<f64> = x.iter().map(|v| (v - m) / s).collect();
    let loglik = |b: [f64; 2]| -> f64 {
        z.iter()
            .zip(y)
            .map(|(&z, &y)| {
                let t = b[0] + b[1] * z;
                // log sigma(t) and log(1 - sigma(t)), stable for large |t|.
                let log1pexp = |u: f64| if u > 30.0 { u } else { u.exp().ln_1p() };
                if y {
                    -log1pexp(-t)
                } else {
                    -log1pexp(t)
                }
            })
            .sum()
    };
    let info = |b: [f64; 2]| -> ([f64; 2], [[f64; 2]; 2]) {
        let mut g = [0.0; 2];
        let mut h = [[0.0; 2]; 2];
        for (&z, &y) in z.iter().zip(y) {
            let p = logistic(b[0] + b[1] * z);
            let r = if y { 1.0 } else { 0.0 } - p;
            g[0] += r;
            g[1] += r * z;
            let w = p * (1.0 - p);
            h[0][0] += w;
            h[0][1] += w * z;
            h[1][1] += w * z * z;
        }
        h[1][0] = h[0][1];
        (g, h)
    };
    let inv = |h: [[f64; 2]; 2]| -> Option<[[f64; 2]; 2]> {
        let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
        (det.abs() > 1e-300 && det.is_finite()).then(|| {
            [
                [h[1][1] / det, -h[0][1] / det],
                [-h[1][0] / det, h[0][0] / det],
            ]
        })
    };
    let mut b = [0.0, 1.0];
    let mut l = loglik(b);
    let mut converged = false;
    for _ in 0..200 {
        let (g, h) = info(b);
        let Some(hi) = inv(h) else { break };
        let step = [
            hi[0][0] * g[0] + hi[0][1] * g[1],
            hi[1][0] * g[0] + hi[1][1] * g[1],
        ];
        let mut k = 1.0;
        let mut next = b;
        let mut ln = l;
        for _ in 0..60 {
            next = [b[0] + k * step[0], b[1] + k * step[1]];
            ln = loglik(next);
            if ln >= l - 1e-15 {
                break;
            }
            k *= 0.5;
        }
        let moved = (next[0] - b[0]).abs().max((next[1] - b[1]).abs());
        b = next;
        l = ln;
        if moved < 1e-12 {
            converged = true;
            break;
        }
    }
    if !converged || !b.iter().all(|v| v.is_finite()) {
        return Err(FitError::Against(format!(
            "the logistic onset of the {quantity} did not converge (the yes/no data barely overlap): check the outcomes"
        )));
    }
    if b[1] <= 0.0 {
        return Err(FitError::Against(format!(
            "bruises do not become more likely with the {quantity} in these data: no onset to fit"
        )));
    }
    let (_, h) = info(b);
    let cov = inv(h);
    let z50 = -b[0] / b[1];
    let se = cov.map(|c| {
        // d z50 / d b = (-1 / b1, b0 / b1^2).
        let g = [-1.0 / b[1], b[0] / (b[1] * b[1])];
        let var =
            g[0] * (c[0][0] * g[0] + c[0][1] * g[1]) + g[1] * (c[1][0] * g[0] + c[1][1] * g[1]);
        s * var.max(0.0).sqrt()
    });
    Ok(Onset {
        threshold: m + s * z50,
        std_error: se,
        method: Method::Logistic { width: s / b[1] },
    })
}

/// Standard errors sqrt(diag(s^2 (J^T J)^-1)), s^2 = `ssr` / (n - p), of a least-squares fit
/// with Jacobian rows `j` (p = 1 or 2 columns); `None` where n <= p or J^T J is singular.
fn std_errors<const P: usize>(j: &[[f64; P]], ssr: f64) -> [Option<f64>; P] {
    let n = j.len();
    if n <= P {
        return [None; P];
    }
    let s2 = ssr / (n - P) as f64;
    let mut a = [[0.0; P]; P];
    for row in j {
        for r in 0..P {
            for c in 0..P {
                a[r][c] += row[r] * row[c];
            }
        }
    }
    let mut out = [None; P];
    match P {
        1 => {
            if a[0][0] > 0.0 {
                out[0] = Some((s2 / a[0][0]).sqrt());
            }
        }
        2 => {
            let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
            let scale = a[0][0] * a[1][1];
            if det > 1e-12 * scale && det.is_finite() {
                out[0] = Some((s2 * a[1][1] / det).sqrt());
                out[1] = Some((s2 * a[0][0] / det).sqrt());
            }
        }
        _ => unreachable!("one or two coefficients"),
    }
    out
}

/// The energy model V = BS max(0, E - E_th) fitted to volumes `v` (mm^3) of hits with absorbed
/// energies E by least squares, exactly: the model is linear in BS and, for E_th between two
/// consecutive energies (the bruised drops fixed), linear in (BS, BS E_th), so the minimum is
/// either the unconstrained regression V = BS E - BS E_th over the drops above the interval, if
/// its E_th falls inside the interval, or at an end of an interval (E_th = 0 or a drop's
/// energy), where BS is the regression through the origin. Every candidate is tried.
pub fn fit_energy(hits: &[Hit], v: &[f64]) -> Result<Fit, FitError> {
    let e: Vec<f64> = hits.iter().map(|h| h.absorbed_energy_j).collect();
    let bruised: Vec<f64> = e
        .iter()
        .zip(v)
        .filter(|(_, &v)| v > 0.0)
        .map(|(&e, _)| e)
        .collect();
    if bruised.is_empty() {
        let largest = e.iter().copied().fold(0.0, f64::max);
        return Err(FitError::NoBruise {
            quantity: "absorbed energy",
            largest: format!("{} J", crate::math::human(largest, 4, 1)),
        });
    }
    let distinct = bruised
        .iter()
        .any(|&x| (x - bruised[0]).abs() > 1e-12 * x.abs());
    if !distinct {
        return Err(FitError::TooFew(
            "the energy model's BS and E_th need bruises at two absorbed energies at least: add bruised drops at other heights (or fit the onset alone with bruised yes/no)".into(),
        ));
    }
    // SSR of E_th = t with BS the regression through the origin of V on (E - t)+.
    let at = |t: f64| -> Option<(f64, f64, f64)> {
        let (mut sxv, mut sxx) = (0.0, 0.0);
        for (&e, &v) in e.iter().zip(v) {
            let x = (e - t).max(0.0);
            sxv += x * v;
            sxx += x * x;
        }
        if sxx <= 0.0 {
            return None;
        }
        let bs = sxv / sxx;
        if bs <= 0.0 {
            return None;
        }
        let ssr = e
            .iter()
            .zip(v)
            .map(|(&e, &v)| {
                let r = v - bs * (e - t).max(0.0);
                r * r
            })
            .sum();
        Some((bs, t, ssr))
    };
    let mut ends: Vec<f64> = e.iter().copied().filter(|&x| x > 0.0).collect();
    ends.push(0.0);
    ends.sort_by(f64::total_cmp);
    ends.dedup();
    let mut best: Option<(f64, f64, f64)> = None;
    let mut consider = |c: Option<(f64, f64, f64)>| {
        if let Some(c) = c {
            if best.is_none_or(|b| c.2 < b.2) {
                best = Some(c);
            }
        }
    };
    for w in ends.windows(2) {
        let (lo, hi) = (w[0], w[1]);
        consider(at(lo));
        // The drops above the interval: a regression with intercept.
        let act: Vec<(f64, f64)> = e
            .iter()
            .zip(v)
            .filter(|(&e, _)| e > lo)
            .map(|(&e, &v)| (e, v))
            .collect();
        if act.len() >= 2 {
            let k = act.len() as f64;
            let me = act.iter().map(|p| p.0).sum::<f64>() / k;
            let mv = act.iter().map(|p| p.1).sum::<f64>() / k;
            let see: f64 = act.iter().map(|p| (p.0 - me) * (p.0 - me)).sum();
            let sev: f64 = act.iter().map(|p| (p.0 - me) * (p.1 - mv)).sum();
            if see > 0.0 {
                let bs = sev / see;
                let t = me - mv / bs;
                if bs > 0.0 && t > lo && t < hi {
                    consider(at(t));
                }
            }
        }
    }
    let Some((bs, t, ssr)) = best else {
        return Err(FitError::Against(
            "the bruise volumes do not grow with the absorbed energy: no positive susceptibility fits them".into(),
        ));
    };
    // A threshold at a drop's energy is a kink of the model: the SSR has no derivative in E_th
    // there, so E_th has no standard error; BS's is given with E_th held.
    let near = |x: f64, t: f64| (x - t).abs() <= 1e-9 * t.abs().max(1e-12);
    let (bs, t, ssr) = match e.iter().find(|&&x| near(x, t)) {
        // The regression's threshold a rounding error off a drop's energy: that energy, the
        // drop without a bruise, as the boundary candidate it equals.
        Some(&x) if x != t => at(x).unwrap_or((bs, t, ssr)),
        _ => (bs, t, ssr),
    };
    let kink = e.iter().any(|&x| near(x, t));
    let active = |e: f64| e > t && !near(e, t);
    let mut notes = Vec::new();
    let (se_bs, se_t) = if kink {
        notes.push(format!(
            "E_th sits at a drop's absorbed energy ({} J), a kink of the piecewise model: the data bound it from one side only and its standard error is not defined; BS's is given with E_th held",
            crate::math::human(t, 6, 0)
        ));
        let x: Vec<[f64; 1]> = e
            .iter()
            .map(|&e| [if active(e) { e - t } else { 0.0 }])
            .collect();
        // E_th was fitted too: n - 2 degrees of freedom.
        let n = x.len();
        let se = std_errors(&x, ssr)[0]
            .and_then(|se| (n > 2).then(|| se * ((n - 1) as f64 / (n - 2) as f64).sqrt()));
        (se, None)
    } else {
        let jac: Vec<[f64; 2]> = e
            .iter()
            .map(|&e| if active(e) { [e - t, -bs] } else { [0.0, 0.0] })
            .collect();
        let [a, b] = std_errors(&jac, ssr);
        (a, b)
    };
    let spec = DamageSpec {
        model: Some(DamageModelName::Energy),
        bruise_susceptibility_mm3_j: Some(bs),
        threshold_energy_j: Some(t),
        ..DamageSpec::default()
    };
    let params = DamageParams::of(Some(&spec));
    let mut f = volume_fit(
        DamageModelName::Energy,
        vec![
            Coefficient {
                field: "bruise_susceptibility_mm3_j",
                symbol: "BS",
                value: bs,
                std_error: se_bs,
                unit: "mm^3/J",
            },
            Coefficient {
                field: "threshold_energy_j",
                symbol: "E_th",
                value: t,
                std_error: se_t,
                unit: "J",
            },
        ],
        hits,
        v,
        &params,
        e.clone(),
        spec,
    );
    f.notes = notes;
    f.note_undetermined();
    Ok(f)
}

/// The fit's drops and residuals, the volumes predicted by the run's own model
/// ([`model::evaluate`]).
fn volume_fit(
    model_name: DamageModelName,
    coefficients: Vec<Coefficient>,
    hits: &[Hit],
    v: &[f64],
    params: &DamageParams,
    x: Vec<f64>,
    spec: DamageSpec,
) -> Fit {
    let drops: Vec<DropFit> = hits
        .iter()
        .zip(v)
        .zip(x)
        .map(|((h, &v), x)| {
            let d = model::evaluate(params, h);
            let p = d.volume_mm3.unwrap_or(0.0);
            DropFit {
                x,
                measured: Measured::Volume(v),
                predicted_volume_mm3: Some(p),
                predicted_bruised: d.bruised,
                residual_mm3: Some(v - p),
                probability: None,
            }
        })
        .collect();
    let n = drops.len();
    let ssr: f64 = drops
        .iter()
        .map(|d| d.residual_mm3.unwrap_or(0.0).powi(2))
        .sum();
    let misclassified = drops
        .iter()
        .filter(|d| d.predicted_bruised != d.measured.bruised())
        .count();
    let p = coefficients.len();
    Fit {
        model: model_name,
        coefficients,
        method: Method::LeastSquares,
        drops,
        residual_rms_mm3: Some((ssr / n as f64).sqrt()),
        misclassified,
        dof: n.saturating_sub(p),
        notes: Vec::new(),
        spec,
    }
}

/// One drop of a pressure-area fit: the contact radius a (mm), the peak centre pressure p0 (Pa)
/// and the apple's deformation delta (mm).
#[derive(Debug, Clone, Copy)]
struct Patch {
    a_mm: f64,
    p0: f64,
    delta_mm: f64,
}

impl Patch {
    /// d^2 (mm^2) of the part of the patch above `pc`: 4 a^2 (1 - (pc/p0)^2), 0 below.
    fn d2(&self, pc: f64) -> f64 {
        if self.p0 <= pc {
            0.0
        } else {
            let r = pc / self.p0;
            4.0 * self.a_mm * self.a_mm * (1.0 - r * r)
        }
    }

    /// The cap volume pi h (3 d^2 + 4 h^2) / 24 of depth h = k delta (0 without a bruise), as
    /// [`model::evaluate`] gives it.
    fn volume(&self, pc: f64, k: f64) -> f64 {
        let d2 = self.d2(pc);
        if d2 <= 0.0 {
            return 0.0;
        }
        let h = k * self.delta_mm;
        std::f64::consts::PI * h * (3.0 * d2 + 4.0 * h * h) / 24.0
    }

    /// dV/dpc and dV/dk.
    fn gradient(&self, pc: f64, k: f64) -> [f64; 2] {
        let d2 = self.d2(pc);
        if d2 <= 0.0 {
            return [0.0, 0.0];
        }
        let h = k * self.delta_mm;
        let pi = std::f64::consts::PI;
        [
            -pi * h * self.a_mm * self.a_mm * pc / (self.p0 * self.p0),
            pi / 8.0 * self.delta_mm * (d2 + 4.0 * h * h),
        ]
    }
}

/// Minimises `f` over [lo, hi] (in ln x) by a scan of `n` points and a golden-section search
/// between the best point's neighbours; returns (x, f(x)).
fn minimise_log(lo: f64, hi: f64, n: usize, f: impl Fn(f64) -> f64) -> (f64, f64) {
    let (a, b) = (lo.ln(), hi.ln());
    let at = |i: usize| a + (b - a) * i as f64 / (n - 1) as f64;
    let mut best = (0usize, f64::INFINITY);
    for i in 0..n {
        let y = f(at(i).exp());
        if y < best.1 {
            best = (i, y);
        }
    }
    let (mut l, mut r) = (at(best.0.saturating_sub(1)), at((best.0 + 1).min(n - 1)));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = r - g * (r - l);
    let mut d = l + g * (r - l);
    let (mut fc, mut fd) = (f(c.exp()), f(d.exp()));
    for _ in 0..200 {
        if (r - l).abs() < 1e-13 {
            break;
        }
        if fc < fd {
            r = d;
            d = c;
            fd = fc;
            c = r - g * (r - l);
            fc = f(c.exp());
        } else {
            l = c;
            c = d;
            fc = fd;
            d = l + g * (r - l);
            fd = f(d.exp());
        }
    }
    let x = 0.5 * (l + r);
    let (x, y) = (x.exp(), f(x.exp()));
    if y <= best.1 {
        (x, y)
    } else {
        (at(best.0).exp(), best.1)
    }
}

/// The pressure-area model fitted to volumes `v` (mm^3): the critical pressure p_c (and, with
/// `opts.fit_depth_ratio`, the depth ratio) by least squares. The volume of a hit is the cap of
/// the patch above p_c, pi h (3 d^2 + 4 h^2) / 24 with d^2 = 4 a^2 (1 - (p_c/p0)^2) and h the
/// depth ratio times the apple's deformation; p_c is searched over [1e-4 min p0, max p0] (a
/// scan in ln p_c, then a golden-section search), the depth ratio for each p_c likewise over
/// its range [0.01, 100].
pub fn fit_pressure_area(hits: &[Hit], v: &[f64], opts: FitOptions) -> Result<Fit, FitError> {
    let patches: Vec<Patch> = hits
        .iter()
        .map(|h| Patch {
            a_mm: 1e3 * h.contact_radius_m,
            p0: h.peak_pressure_pa,
            delta_mm: 1e3 * h.indentation_m,
        })
        .collect();
    let need = if opts.fit_depth_ratio { 2 } else { 1 };
    let bruised = v.iter().filter(|&&v| v > 0.0).count();
    if bruised < need {
        return Err(if bruised == 0 {
            let largest = patches.iter().map(|p| p.p0).fold(0.0, f64::max);
            FitError::NoBruise {
                quantity: "peak centre pressure",
                largest: format!("{} MPa", crate::math::human(largest * 1e-6, 4, 1)),
            }
        } else {
            FitError::TooFew("fitting the depth ratio too needs two bruised drops at least".into())
        });
    }
    let ssr = |pc: f64, k: f64| -> f64 {
        patches
            .iter()
            .zip(v)
            .map(|(p, &v)| (v - p.volume(pc, k)).powi(2))
            .sum()
    };
    let best_k = |pc: f64| -> (f64, f64) {
        if opts.fit_depth_ratio {
            minimise_log(0.01, 100.0, 200, |k| ssr(pc, k))
        } else {
            (opts.depth_ratio, ssr(pc, opts.depth_ratio))
        }
    };
    let p_min = patches.iter().map(|p| p.p0).fold(f64::INFINITY, f64::min);
    let p_max = patches.iter().map(|p| p.p0).fold(0.0, f64::max);
    if !(p_min > 0.0 && p_max > p_min * 1e-4) {
        return Err(FitError::Against(
            "no drop has a contact pressure: nothing to fit".into(),
        ));
    }
    let p_lo = 1e-4 * p_min;
    let (pc, _) = minimise_log(p_lo, p_max, 600, |pc| best_k(pc).1);
    let (k, s) = best_k(pc);
    let mut notes = Vec::new();
    let pc_at_end = pc <= p_lo * (1.0 + 1e-6);
    if pc_at_end {
        notes.push(format!(
            "p_c ran to the low end of its search ({} Pa, 1e-4 of the smallest peak pressure): the data want the whole contact patch bruised, and p_c has no standard error",
            crate::math::human(p_lo, 4, 0)
        ));
    }
    let k_at_end = opts.fit_depth_ratio && (k <= 0.01 * (1.0 + 1e-6) || k >= 100.0 * (1.0 - 1e-6));
    if k_at_end {
        notes.push(format!(
            "the depth ratio ran to the end of its range [0.01, 100] ({}): it has no standard error",
            crate::math::human(k, 4, 2)
        ));
    }
    let coefficients = if opts.fit_depth_ratio {
        let jac: Vec<[f64; 2]> = patches.iter().map(|p| p.gradient(pc, k)).collect();
        let [se_pc, se_k] = std_errors(&jac, s);
        let (se_pc, se_k) = (se_pc.filter(|_| !pc_at_end), se_k.filter(|_| !k_at_end));
        vec![
            Coefficient {
                field: "critical_pressure_pa",
                symbol: "p_c",
                value: pc,
                std_error: se_pc,
                unit: "Pa",
            },
            Coefficient {
                field: "depth_ratio",
                symbol: "depth_ratio",
                value: k,
                std_error: se_k,
                unit: "",
            },
        ]
    } else {
        let jac: Vec<[f64; 1]> = patches.iter().map(|p| [p.gradient(pc, k)[0]]).collect();
        let [se_pc] = std_errors(&jac, s);
        let se_pc = se_pc.filter(|_| !pc_at_end);
        vec![Coefficient {
            field: "critical_pressure_pa",
            symbol: "p_c",
            value: pc,
            std_error: se_pc,
            unit: "Pa",
        }]
    };
    let spec = DamageSpec {
        model: Some(DamageModelName::PressureArea),
        critical_pressure_pa: Some(pc),
        depth_ratio: (opts.fit_depth_ratio || opts.depth_ratio_given).then_some(k),
        ..DamageSpec::default()
    };
    let params = DamageParams::of(Some(&DamageSpec {
        depth_ratio: Some(k),
        ..spec.clone()
    }));
    let x = patches.iter().map(|p| p.p0).collect();
    let mut f = volume_fit(
        DamageModelName::PressureArea,
        coefficients,
        hits,
        v,
        &params,
        x,
        spec,
    );
    f.notes = notes;
    f.note_undetermined();
    Ok(f)
}

impl Fit {
    /// Adds a note when the data leave a coefficient without a standard error although drops
    /// remain beyond the coefficients: fewer informative drops than coefficients (J^T J
    /// singular), the fit then one of many that fit as well.
    fn note_undetermined(&mut self) {
        if self.dof == 0 {
            self.notes.push(format!(
                "{} drops for {} coefficients: the fit is exact and the coefficients have no standard errors; add drops",
                self.drops.len(),
                self.coefficients.len()
            ));
        } else if self.notes.is_empty() && self.coefficients.iter().any(|c| c.std_error.is_none()) {
            self.notes.push(
                "too few drops inform the coefficients (J^T J is singular: fewer bruised drops that constrain them than coefficients): other values fit as well, and they have no standard errors; add bruised drops".into(),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(e: f64) -> Hit {
        Hit {
            absorbed_energy_j: e,
            peak_force_n: 400.0 * e,
            peak_pressure_pa: 2e5 + 1e6 * e,
            contact_radius_m: 5e-3 + 0.01 * e,
            indentation_m: 1e-3 + 0.004 * e,
            stored_share: 1.0,
        }
    }

    #[test]
    fn energy_fit_recovers_exact_coefficients_and_the_threshold_from_unbruised_drops() {
        let e = [0.02, 0.04, 0.06, 0.1, 0.15, 0.2, 0.3];
        let hits: Vec<Hit> = e.iter().map(|&e| hit(e)).collect();
        let v: Vec<f64> = e.iter().map(|&e| 5000.0 * (e - 0.05f64).max(0.0)).collect();
        let f = fit_energy(&hits, &v).unwrap();
        assert!((f.coefficients[0].value / 5000.0 - 1.0).abs() < 1e-12);
        assert!((f.coefficients[1].value / 0.05 - 1.0).abs() < 1e-12);
        assert!(f.residual_rms_mm3.unwrap() < 1e-9);
        assert_eq!(f.misclassified, 0);
        assert_eq!(f.dof, 5);
    }

    #[test]
    fn energy_fit_is_the_least_squares_minimum_and_its_errors_match_the_jacobian() {
        // Scattered volumes: no (BS, E_th) on a fine grid around the fit does better.
        let e = [0.03, 0.05, 0.08, 0.12, 0.16, 0.22, 0.3];
        let noise = [0.0, 20.0, -35.0, 40.0, -25.0, 30.0, -15.0];
        let hits: Vec<Hit> = e.iter().map(|&e| hit(e)).collect();
        let v: Vec<f64> = e
            .iter()
            .zip(noise)
            .map(|(&e, n)| (4000.0 * (e - 0.06f64).max(0.0) + n).max(0.0))
            .collect();
        let f = fit_energy(&hits, &v).unwrap();
        let (bs, t) = (f.coefficients[0].value, f.coefficients[1].value);
        let ssr = |bs: f64, t: f64| -> f64 {
            e.iter()
                .zip(&v)
                .map(|(&e, &v)| (v - bs * (e - t).max(0.0)).powi(2))
                .sum()
        };
        let best = ssr(bs, t);
        for i in -20..=20 {
            for j in -20..=20 {
                let s = ssr(bs * (1.0 + 0.002 * i as f64), t + 0.0005 * j as f64);
                assert!(s >= best - 1e-9, "{i} {j}: {s} < {best}");
            }
        }
        assert!((f.residual_rms_mm3.unwrap() - (best / 7.0).sqrt()).abs() < 1e-9);
        // The standard errors of the linear model at the fitted threshold (the active drops
        // fixed): sigma^2 (X^T X)^-1 with X = [E - t, -BS].
        let act: Vec<f64> = e.iter().copied().filter(|&x| x > t).collect();
        let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
        for x in &act {
            a += (x - t) * (x - t);
            b += -(x - t) * bs;
            c += bs * bs;
        }
        let det = a * c - b * b;
        let s2 = best / 5.0;
        let se_bs = (s2 * c / det).sqrt();
        let se_t = (s2 * a / det).sqrt();
        assert!((f.coefficients[0].std_error.unwrap() / se_bs - 1.0).abs() < 1e-9);
        assert!((f.coefficients[1].std_error.unwrap() / se_t - 1.0).abs() < 1e-9);
    }

    #[test]
    fn pressure_area_fit_recovers_the_critical_pressure_and_depth_ratio() {
        let e = [0.02, 0.05, 0.08, 0.12, 0.2, 0.3];
        let hits: Vec<Hit> = e.iter().map(|&e| hit(e)).collect();
        let truth = DamageParams::of(Some(&DamageSpec {
            model: Some(DamageModelName::PressureArea),
            critical_pressure_pa: Some(2.9e5),
            depth_ratio: Some(3.0),
            ..Default::default()
        }));
        let v: Vec<f64> = hits
            .iter()
            .map(|h| model::evaluate(&truth, h).volume_mm3.unwrap())
            .collect();
        assert_eq!(v[0], 0.0);
        let opts = FitOptions {
            fit_depth_ratio: true,
            ..FitOptions::default()
        };
        let f = fit_pressure_area(&hits, &v, opts).unwrap();
        assert!(
            (f.coefficients[0].value / 2.9e5 - 1.0).abs() < 1e-8,
            "{:?}",
            f.coefficients
        );
        assert!((f.coefficients[1].value / 3.0 - 1.0).abs() < 1e-8);
        // With the depth ratio fixed at the truth, p_c alone.
        let opts = FitOptions {
            depth_ratio: 3.0,
            depth_ratio_given: true,
            fit_depth_ratio: false,
        };
        let f = fit_pressure_area(&hits, &v, opts).unwrap();
        assert!((f.coefficients[0].value / 2.9e5 - 1.0).abs() < 1e-8);
        assert_eq!(f.spec.depth_ratio, Some(3.0));
    }

    #[test]
    fn separating_onsets_take_the_midpoint_and_overlapping_ones_the_logistic() {
        let on = fit_onset(
            &[10.0, 22.0, 50.0, 70.0],
            &[false, false, true, true],
            "f",
            "N",
        )
        .unwrap();
        assert_eq!(on.threshold, 36.0);
        assert_eq!(
            on.method,
            Method::Separating {
                below: 22.0,
                above: 50.0
            }
        );
        // Symmetric overlapping data: the 50 % point is the centre, by symmetry.
        let x = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0];
        let y = [false, false, true, false, true, false, true, true];
        let on = fit_onset(&x, &y, "f", "N").unwrap();
        assert!((on.threshold - 4.5).abs() < 1e-9, "{on:?}");
        assert!(on.std_error.unwrap() > 0.0);
        // The score vanishes at the fit: sum (y - p) = 0 and sum (y - p) x = 0.
        let p: Vec<f64> = x.iter().map(|&x| on.probability(x).unwrap()).collect();
        let g0: f64 = y.iter().zip(&p).map(|(&y, p)| y as u8 as f64 - p).sum();
        let g1: f64 = y
            .iter()
            .zip(&p)
            .zip(&x)
            .map(|((&y, p), x)| (y as u8 as f64 - p) * x)
            .sum();
        assert!(g0.abs() < 1e-9 && g1.abs() < 1e-9, "{g0} {g1}");
        assert!(matches!(
            fit_onset(&[1.0, 2.0], &[true, true], "peak force", "N"),
            Err(FitError::AllBruised { .. })
        ));
        assert!(matches!(
            fit_onset(&[1.0, 2.0], &[false, false], "peak force", "N"),
            Err(FitError::NoBruise { .. })
        ));
    }

    #[test]
    fn yes_no_data_fit_the_onset_only() {
        let e = [0.02, 0.04, 0.06, 0.1];
        let hits: Vec<Hit> = e.iter().map(|&e| hit(e)).collect();
        let m: Vec<Measured> = [false, false, true, true]
            .iter()
            .map(|&b| Measured::Bruised(b))
            .collect();
        let f = fit(DamageModelName::Energy, &hits, &m, FitOptions::default()).unwrap();
        assert_eq!(f.coefficients.len(), 1);
        assert_eq!(f.coefficients[0].field, "threshold_energy_j");
        assert!((f.coefficients[0].value - 0.05).abs() < 1e-15);
        assert_eq!(f.spec.bruise_susceptibility_mm3_j, None);
        // Volumes fit a peak-force onset by whether they are above 0.
        let m: Vec<Measured> = [0.0, 0.0, 30.0, 90.0]
            .iter()
            .map(|&v| Measured::Volume(v))
            .collect();
        let f = fit(DamageModelName::PeakForce, &hits, &m, FitOptions::default()).unwrap();
        assert!((f.coefficients[0].value - 20.0).abs() < 1e-12);
    }
}
