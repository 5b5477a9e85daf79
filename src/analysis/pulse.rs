//! The paper's force pulse (eqs. 13-15, physics.md section 7) fitted to each recorded impact.
//!
//! Eq. 13 describes an impact force curve by four numbers:
//!
//! ```text
//! P(t) = P_max (t / (tau t_k))^eps ((t_k - t) / (t_k (1 - tau)))^(eps (1 - tau) / tau),  0 < t < t_k
//! ```
//!
//! peaking at P_max at t = tau t_k and zero at 0 and t_k. Eq. 14 ties it to the impact:
//! m v0 (1 + e) = integral P dt = k_P P_max t_k, so eq. 15 predicts the peak force from quantities a
//! line designer can measure (contact time, restitution): P_max = m v0 (1 + e) / (k_P t_k).
//!
//! [`fit_events`] fits P_max, t_k, eps and tau to each impact's recorded force history by
//! nonlinear least squares (Levenberg-Marquardt, `levenberg-marquardt` crate) and reports, beside
//! them, k_P = impulse / (P_max t_k) and the eq. 15 prediction with the elastic Hertz
//! k_P = 0.5436 (physics.md section 4) next to the measured peak force.

use crate::contact::theory::{reduced_mass, ELASTIC_PULSE_COEFFICIENT};
use crate::record::events::{ContactEvent, Party};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DVector, Dyn, OMatrix, Owned, Vector4, U4};
use serde::Serialize;
use std::sync::Arc;

/// Fewest force samples an impact needs to be fitted (four parameters, and a curve to see).
pub const MIN_SAMPLES: usize = 8;

/// The eq. 13 pulse.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PulseShape {
    /// Peak force P_max (N).
    pub peak_force_n: f64,
    /// Pulse length t_k (s): the contact time of the curve.
    pub contact_time_s: f64,
    /// Rise exponent eps: about 2 for elastic impacts, below 1.5 for visco-elastic ones.
    pub eps: f64,
    /// Time of the peak as a fraction of t_k: 0.5 is symmetric.
    pub tau: f64,
}

impl PulseShape {
    /// Exponent of the falling side, eps (1 - tau) / tau.
    pub fn fall_exponent(&self) -> f64 {
        self.eps * (1.0 - self.tau) / self.tau
    }

    /// Force at time `t_s` after first touch (N); zero outside (0, t_k).
    pub fn force_n(&self, t_s: f64) -> f64 {
        let x = t_s / self.contact_time_s;
        if !(x > 0.0 && x < 1.0) {
            return 0.0;
        }
        let ln = self.eps * (x / self.tau).ln()
            + self.fall_exponent() * ((1.0 - x) / (1.0 - self.tau)).ln();
        self.peak_force_n * ln.exp()
    }

    /// integral P dt / (P_max t_k) of this curve: B(eps + 1, beta + 1) / (tau^eps (1 - tau)^beta)
    /// with beta the fall exponent (8/15 = 0.5333 for eps = 2, tau = 0.5).
    pub fn area_coefficient(&self) -> f64 {
        let (a, b) = (self.eps, self.fall_exponent());
        let ln_beta = libm::lgamma(a + 1.0) + libm::lgamma(b + 1.0) - libm::lgamma(a + b + 2.0);
        (ln_beta - a * self.tau.ln() - b * (1.0 - self.tau).ln()).exp()
    }
}

/// The fit of one impact.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PulseFit {
    /// Index of the contact in `contacts.csv` / `RunResult::events`.
    pub contact: usize,
    /// The apple.
    pub a: Arc<str>,
    /// The other body.
    pub b: Arc<str>,
    /// Force samples fitted (the two zero-force ends included).
    pub samples: usize,
    /// Fitted P_max (N).
    pub fit_peak_force_n: f64,
    /// Fitted t_k (s).
    pub fit_contact_time_s: f64,
    /// Fitted eps.
    pub fit_eps: f64,
    /// Fitted tau.
    pub fit_tau: f64,
    /// Root-mean-square residual of the fit (N).
    pub rms_residual_n: f64,
    /// Whether Levenberg-Marquardt reported convergence.
    pub converged: bool,
    /// k_P = impulse / (fitted P_max x fitted t_k): eq. 14 with the measured impulse.
    pub k_p: f64,
    /// integral of the fitted curve / (P_max t_k): the k_P the eq. 13 shape itself implies.
    pub k_p_shape: f64,
    /// impulse / (measured peak force x measured contact time): the k_P that makes eq. 15 exact
    /// for this impact (0.5436 for an elastic Hertz impact without gravity).
    pub k_p_measured: f64,
    /// Measured peak force (N).
    pub peak_force_n: f64,
    /// Measured contact time (s).
    pub contact_time_s: f64,
    /// Measured restitution.
    pub restitution: f64,
    /// Mass in eq. 14 (kg): the apple's, or m1 m2 / (m1 + m2) for two apples.
    pub effective_mass_kg: f64,
    /// Eq. 15: m v0 (1 + e) / (k_P t_k) with the measured approach speed, restitution and
    /// contact time and the elastic Hertz k_P = 0.5436 (N).
    pub eq15_peak_force_n: f64,
}

impl PulseFit {
    /// The fitted curve.
    pub fn shape(&self) -> PulseShape {
        PulseShape {
            peak_force_n: self.fit_peak_force_n,
            contact_time_s: self.fit_contact_time_s,
            eps: self.fit_eps,
            tau: self.fit_tau,
        }
    }
}

/// Least-squares problem in unconstrained parameters
/// x = (ln P_max, logit((t_k - lo) / (hi - lo)), ln eps, logit tau), so every trial point is a
/// valid pulse with t_k in (lo, hi).
struct Problem<'a> {
    t: &'a [f64],
    p: &'a [f64],
    t_k_range: (f64, f64),
    x: Vector4<f64>,
}

fn logistic(z: f64) -> f64 {
    1.0 / (1.0 + (-z).exp())
}

impl Problem<'_> {
    fn shape(&self) -> PulseShape {
        PulseShape {
            peak_force_n: self.x[0].exp(),
            contact_time_s: self.t_k_range.0
                + (self.t_k_range.1 - self.t_k_range.0) * logistic(self.x[1]),
            eps: self.x[2].exp(),
            tau: logistic(self.x[3]),
        }
    }
}

impl LeastSquaresProblem<f64, Dyn, U4> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, U4>;
    type ParameterStorage = Owned<f64, U4>;

    fn set_params(&mut self, x: &Vector4<f64>) {
        self.x = *x;
    }

    fn params(&self) -> Vector4<f64> {
        self.x
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let s = self.shape();
        let r = DVector::from_iterator(
            self.t.len(),
            self.t.iter().zip(self.p).map(|(&t, &p)| s.force_n(t) - p),
        );
        r.iter().all(|v| v.is_finite()).then_some(r)
    }

    fn jacobian(&self) -> Option<OMatrix<f64, Dyn, U4>> {
        // d ln P / d(ln P_max) = 1; t_k d ln P / d t_k = -eps + beta x / (1 - x), and
        // d t_k / d x1 = (hi - lo) s (1 - s) with s = logistic(x1);
        // d ln P / d(ln eps) = eps ln(x / tau) + beta ln((1 - x) / (1 - tau));
        // d ln P / d tau = -eps ln((1 - x) / (1 - tau)) / tau^2, and d tau / d logit = tau (1 - tau).
        let s = self.shape();
        let beta = s.fall_exponent();
        let sk = logistic(self.x[1]);
        let dtk = (self.t_k_range.1 - self.t_k_range.0) * sk * (1.0 - sk) / s.contact_time_s;
        let mut j = OMatrix::<f64, Dyn, U4>::zeros(self.t.len());
        for (i, &t) in self.t.iter().enumerate() {
            let p = s.force_n(t);
            if p == 0.0 {
                continue;
            }
            let x = t / s.contact_time_s;
            let l1 = (x / s.tau).ln();
            let l2 = ((1.0 - x) / (1.0 - s.tau)).ln();
            j[(i, 0)] = p;
            j[(i, 1)] = p * (-s.eps + beta * x / (1.0 - x)) * dtk;
            j[(i, 2)] = p * (s.eps * l1 + beta * l2);
            j[(i, 3)] = p * (-s.eps * l2 / (s.tau * s.tau)) * s.tau * (1.0 - s.tau);
        }
        j.iter().all(|v| v.is_finite()).then_some(j)
    }
}

/// t_k is searched within this fraction of the measured contact time on either side.
///
/// Without a bound the least-squares optimum of a strongly skewed pulse (eq. 12 at moderate
/// lambda v0) runs off to t_k -> infinity, tau -> 0, where eq. 13 degenerates into
/// t^eps exp(-c t): a good fit of the shape, but no longer a pulse of finite length t_k.
pub const CONTACT_TIME_RANGE: f64 = 0.25;

/// Fits eq. 13 to force samples `(t, P)` with t measured from first touch, t_k within
/// `t_k_range` (s). `guess` starts the search; a second start at eps = 1.2 (visco-elastic shapes)
/// is tried and the better kept. Returns the shape, the RMS residual and whether the solver
/// reported convergence.
pub fn fit_samples(
    t: &[f64],
    p: &[f64],
    guess: PulseShape,
    t_k_range: (f64, f64),
) -> Option<(PulseShape, f64, bool)> {
    let (lo, hi) = t_k_range;
    if t.len() != p.len() || t.len() < MIN_SAMPLES || !(lo > 0.0 && hi > lo) {
        return None;
    }
    let logit = |q: f64| (q / (1.0 - q)).ln();
    let start = |eps: f64| {
        let tau = guess.tau.clamp(0.05, 0.95);
        let q = ((guess.contact_time_s - lo) / (hi - lo)).clamp(0.01, 0.99);
        Vector4::new(guess.peak_force_n.ln(), logit(q), eps.ln(), logit(tau))
    };
    let mut best: Option<(PulseShape, f64, bool)> = None;
    for eps0 in [guess.eps, 1.2] {
        let problem = Problem {
            t,
            p,
            t_k_range,
            x: start(eps0),
        };
        let (solved, report) = LevenbergMarquardt::new().minimize(problem);
        let Some(r) = solved.residuals() else {
            continue;
        };
        let rms = (r.norm_squared() / t.len() as f64).sqrt();
        let shape = solved.shape();
        let ok = [
            shape.peak_force_n,
            shape.contact_time_s,
            shape.eps,
            shape.tau,
        ]
        .iter()
        .all(|v| v.is_finite());
        if ok && best.as_ref().is_none_or(|b| rms < b.1) {
            best = Some((shape, rms, report.termination.was_successful()));
        }
    }
    best
}

/// Fits every finished impact that has a force history (scenario `output.force_history`) and
/// started moving (a restitution); contacts that start at rest (an apple resting on a belt) have
/// no pulse to fit, and a contact whose history was kept over its impact only (the default
/// `output.force_history`, [`crate::record::events::HistorySpan::Impact`]) while it rested on
/// long after is not fitted: the fit spans touch to parting, and the history does not. `mass_kg` gives an apple's mass by name, for eq. 14's m; surfaces are
/// treated as immovable.
pub fn fit_events(
    events: &[ContactEvent],
    mass_kg: &(dyn Fn(&str) -> f64 + Sync),
) -> Vec<PulseFit> {
    // Each fit depends on its contact alone: fitted in parallel, collected in contact order (the
    // same fits, in the same order, at any thread count).
    use rayon::prelude::*;
    events
        .par_iter()
        .enumerate()
        .filter_map(|(k, e)| fit_event(k, e, mass_kg))
        .collect()
}

/// The fit of contact `k` ([`fit_events`]), if it has one.
fn fit_event(
    k: usize,
    e: &ContactEvent,
    mass_kg: &(dyn Fn(&str) -> f64 + Sync),
) -> Option<PulseFit> {
    {
        let (Some(h), Some(duration), Some(restitution)) =
            (&e.history, e.duration_s, e.restitution)
        else {
            return None;
        };
        if h.len() + 2 < MIN_SAMPLES
            || duration.is_nan()
            || duration <= 0.0
            || e.history_cut_s.is_some()
        {
            return None;
        }
        // The touch and parting instants are measured points of zero force.
        let mut t = Vec::with_capacity(h.len() + 2);
        let mut p = Vec::with_capacity(h.len() + 2);
        t.push(0.0);
        p.push(0.0);
        for &(ts, f) in h {
            t.push(ts - e.t_start_s);
            p.push(f);
        }
        t.push(duration);
        p.push(0.0);
        let guess = PulseShape {
            peak_force_n: e.peak_force_n.max(f64::MIN_POSITIVE),
            contact_time_s: duration,
            eps: 2.0,
            tau: (e.t_peak_s - e.t_start_s) / duration,
        };
        let range = (
            duration * (1.0 - CONTACT_TIME_RANGE),
            duration * (1.0 + CONTACT_TIME_RANGE),
        );
        let (shape, rms, converged) = fit_samples(&t, &p, guess, range)?;
        let m = match e.b_party {
            Party::Apple(_) => reduced_mass(mass_kg(&e.a), mass_kg(&e.b)),
            Party::Surface(_) => mass_kg(&e.a),
        };
        Some(PulseFit {
            contact: k,
            a: e.a.clone(),
            b: e.b.clone(),
            samples: t.len(),
            fit_peak_force_n: shape.peak_force_n,
            fit_contact_time_s: shape.contact_time_s,
            fit_eps: shape.eps,
            fit_tau: shape.tau,
            rms_residual_n: rms,
            converged,
            k_p: e.impulse_n_s / (shape.peak_force_n * shape.contact_time_s),
            k_p_shape: shape.area_coefficient(),
            k_p_measured: e.impulse_n_s / (e.peak_force_n * duration),
            peak_force_n: e.peak_force_n,
            contact_time_s: duration,
            restitution,
            effective_mass_kg: m,
            eq15_peak_force_n: m * e.approach_speed_m_s * (1.0 + restitution)
                / (ELASTIC_PULSE_COEFFICIENT * duration),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_coefficient_of_the_symmetric_square_pulse_is_8_15() {
        let s = PulseShape {
            peak_force_n: 1.0,
            contact_time_s: 1.0,
            eps: 2.0,
            tau: 0.5,
        };
        assert!((s.area_coefficient() - 8.0 / 15.0).abs() < 1e-12);
        // Peak value at tau t_k.
        assert!((s.force_n(0.5) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn area_coefficient_matches_quadrature_for_a_skewed_pulse() {
        let s = PulseShape {
            peak_force_n: 3.0,
            contact_time_s: 2.0,
            eps: 1.3,
            tau: 0.3,
        };
        let n = 200_000;
        let h = s.contact_time_s / n as f64;
        let sum: f64 = (0..n).map(|i| s.force_n((i as f64 + 0.5) * h)).sum::<f64>() * h;
        let want = sum / (s.peak_force_n * s.contact_time_s);
        assert!(
            (s.area_coefficient() - want).abs() < 1e-6,
            "{} vs {want}",
            s.area_coefficient()
        );
    }

    #[test]
    fn recovers_a_synthetic_pulse() {
        let truth = PulseShape {
            peak_force_n: 50.0,
            contact_time_s: 0.006,
            eps: 1.4,
            tau: 0.35,
        };
        let t: Vec<f64> = (0..=300).map(|i| i as f64 * 0.006 / 300.0).collect();
        let p: Vec<f64> = t.iter().map(|&t| truth.force_n(t)).collect();
        let guess = PulseShape {
            peak_force_n: 45.0,
            contact_time_s: 0.0065,
            eps: 2.0,
            tau: 0.5,
        };
        let (s, rms, ok) = fit_samples(&t, &p, guess, (0.004, 0.009)).unwrap();
        assert!(ok);
        assert!(rms < 1e-6, "rms {rms}");
        assert!(
            (s.eps - 1.4).abs() < 1e-6 && (s.tau - 0.35).abs() < 1e-6,
            "{s:?}"
        );
    }
}
