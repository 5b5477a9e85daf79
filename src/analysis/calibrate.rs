//! Calibration of the eq. 12 coefficient ke against a measured coefficient of restitution.
//!
//! Without gravity and with lambda v0 >> 1 the restitution of one impact is sqrt(ke)
//! (physics.md section 3), but neither holds in practice: at moderate lambda v0 the unloading is
//! stiffer than ke times Hertz (e >= 0.477 for every ke at lambda v0 = 2), and gravity acting
//! through the long unloading (t_c ~ t_H / 2 (1 + 1/sqrt(ke))) takes speed off the rebound (ke =
//! 0.09, lambda = 1000 s/m, v0 = 1 m/s gives e = 0.23, not 0.3). So [`calibrate`] simulates the
//! impact with the simulator itself (the scenario's materials, the apple's size and mass, the
//! speed, lambda and, by default, gravity) and searches ke in [[`KE_MIN`], 1], along which the
//! restitution rises monotonically, until the simulated restitution matches the target.

use crate::contact::{material::effective_modulus, normal, theory};
use crate::layer::{LayerError, StepRequest};
use crate::math::vec3;
use crate::scenario::surfaces::{PaddingSpec, PlaneSpec};
use crate::scenario::{
    self, AppleSpec, ContactSpec, MaterialSpec, ModelSpec, OutputSpec, PairSpec, Scenario,
    ScenarioError, SurfaceSpec,
};
use crate::world::{self, BuildError, World};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use thiserror::Error;

/// Smallest ke searched. Its restitution stands for the ke -> 0 limit (sqrt(ke) = 0.01), and the
/// unloading it implies (t_H / 2 / sqrt(ke) = 50 t_H) is still quick to simulate.
pub const KE_MIN: f64 = 1e-4;

/// Default steps per elastic contact time: the peak force is then within about 0.001 % and the
/// restitution within 1e-4 of the converged value (physics.md section 10 for the error scaling).
pub const DEFAULT_STEPS_PER_IMPACT: f64 = 200.0;

/// Default cap on the time-step error of a simulated restitution under gravity. The separation
/// speed is the velocity of the last step in contact, which gravity changes by g dt per step, so
/// the restitution is only defined to g dt / v0 and moves in jumps of that size as ke changes the
/// number of steps in contact; the time step is capped at this x v0 / g.
pub const DEFAULT_RESTITUTION_RESOLUTION: f64 = 5e-5;

/// Errors of the calibration.
#[derive(Debug, Error)]
pub enum CalibrateError {
    /// A bad argument (it names the option or scenario field).
    #[error("{field}: {message}")]
    Input {
        /// Option or field.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// No ke in range gives the target restitution.
    #[error("e = {target} cannot be reached at v0 = {speed_m_s} m/s with lambda = {lambda_s_m} s/m{gravity}: {reason}")]
    Unreachable {
        /// Target restitution.
        target: f64,
        /// Impact speed (m/s).
        speed_m_s: f64,
        /// Eq. 12 rate constant (s/m).
        lambda_s_m: f64,
        /// ", under gravity of ... m/s^2" or empty.
        gravity: String,
        /// Why, and what would work.
        reason: String,
    },
    /// The impact scenario was refused.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The world could not be built.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// The simulated impact went wrong.
    #[error(transparent)]
    Layer(#[from] LayerError),
}

fn input(field: &str, message: impl Into<String>) -> CalibrateError {
    CalibrateError::Input {
        field: field.into(),
        message: message.into(),
    }
}

/// One apple hitting a flat surface square on: everything the impact depends on but ke and v0.
#[derive(Debug, Clone, PartialEq)]
pub struct ImpactSetup {
    /// The apple's material.
    pub apple: MaterialSpec,
    /// The surface's material.
    pub surface: MaterialSpec,
    /// Apple diameter (m).
    pub diameter_m: f64,
    /// Apple mass (kg).
    pub mass_kg: f64,
    /// Eq. 12 rate constant (s/m).
    pub lambda_s_m: f64,
    /// Gravity towards the surface (m/s^2); 0 for none.
    pub gravity_m_s2: f64,
    /// Time step = elastic contact time / this (or shorter, see `restitution_resolution`).
    pub steps_per_impact: f64,
    /// Under gravity the time step is also at most this x v0 / g: the restitution measured at a
    /// step is off by up to g dt / v0 ([`DEFAULT_RESTITUTION_RESOLUTION`]).
    pub restitution_resolution: f64,
    /// Names of the apple's and the surface's materials in the scenario (for messages).
    pub material_names: [String; 2],
}

/// Restitution, as the simulation measured it, of one impact.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Impact {
    /// ke used.
    pub ke: f64,
    /// Approach speed (m/s).
    pub speed_m_s: f64,
    /// Separation / approach speed; `None` when the apple did not lift off (gravity held it).
    pub restitution: Option<f64>,
    /// Peak force (N).
    pub peak_force_n: f64,
    /// Contact time (s); `None` without lift-off.
    pub contact_time_s: Option<f64>,
    /// Time step used (s).
    pub time_step_s: f64,
}

/// Result of [`calibrate`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Calibration {
    /// Target restitution.
    pub target: f64,
    /// ke found.
    pub ke: f64,
    /// Restitution the simulation gives with it.
    pub restitution: f64,
    /// The closed-form limit sqrt(ke) (no gravity, lambda v0 >> 1), for comparison.
    pub sqrt_ke: f64,
    /// lambda v0: the closed-form limit needs it >> 1 (physics.md section 3).
    pub lambda_v0: f64,
    /// The impact simulated with the ke found.
    pub impact: Impact,
    /// Impacts simulated in the search.
    pub simulations: usize,
}

impl ImpactSetup {
    /// The setup of a scenario's apple (`apple`, default the first) on a surface: the material of
    /// surface `surface` (default the first), or the material named `surface_material`. lambda is
    /// the one of that material pair (a `pairs` entry or `contact`); gravity its magnitude.
    pub fn from_scenario(
        sc: &Scenario,
        apple: Option<&str>,
        surface: Option<&str>,
        surface_material: Option<&str>,
    ) -> Result<Self, CalibrateError> {
        // The scenario's apples as the world would hold them (listed, then generated).
        let plan = world::roster::plan(sc)?;
        let a = match apple {
            Some(n) => plan
                .initial
                .iter()
                .map(|(a, _)| a)
                .find(|a| a.name == n)
                .ok_or_else(|| input("--apple", format!("no apple named '{n}' in the scenario")))?,
            None => plan
                .initial
                .first()
                .map(|(a, _)| a)
                .ok_or_else(|| input("apples", "the scenario has no apple to calibrate"))?,
        };
        let surface_mat = match (surface, surface_material) {
            (_, Some(m)) => m.to_string(),
            (name, None) => {
                let s = match name {
                    Some(n) => sc.surfaces.iter().find(|s| s.name() == n).ok_or_else(|| {
                        input(
                            "--surface",
                            format!("no surface named '{n}' in the scenario"),
                        )
                    })?,
                    None => sc.surfaces.first().ok_or_else(|| {
                        input(
                            "surfaces",
                            "the scenario has no surface: name a material with --surface-material",
                        )
                    })?,
                };
                // Every surface kind has a `material` field; reading it through serde keeps this
                // independent of the list of kinds.
                serde_json::to_value(s)
                    .ok()
                    .and_then(|v| v.get("material")?.as_str().map(String::from))
                    .ok_or_else(|| {
                        input(
                            "--surface",
                            format!(
                                "surface '{}' has no single material: name one with --surface-material",
                                s.name()
                            ),
                        )
                    })?
            }
        };
        let spec = |m: &str, field: &str| {
            sc.materials.get(m).cloned().ok_or_else(|| {
                input(
                    field,
                    format!(
                        "unknown material '{m}' (defined: {})",
                        sc.materials.keys().cloned().collect::<Vec<_>>().join(", ")
                    ),
                )
            })
        };
        let apple_spec = spec(&a.material, "--apple")?;
        let surface_spec = spec(&surface_mat, "--surface-material")?;
        if a.mass_kg.is_none() && apple_spec.density_kg_m3.is_none() {
            return Err(input(
                "--apple",
                format!(
                    "apple '{}' has neither mass_kg nor a material density",
                    a.name
                ),
            ));
        }
        let mass_kg = world::apple_mass(a, apple_spec.density_kg_m3);
        let law = sc.pair_law(&a.material, &surface_mat);
        if law.damping == crate::scenario::models::Damping::Viscoelastic {
            return Err(input(
                "contact.damping",
                "ke is calibrated for the eq. 12 damping; the viscoelastic model takes the restitution itself",
            ));
        }
        let lambda_s_m = law.lambda_s_m.unwrap_or(0.0);
        Ok(Self {
            apple: apple_spec,
            surface: surface_spec,
            diameter_m: a.diameter_m,
            mass_kg,
            lambda_s_m,
            gravity_m_s2: vec3(sc.gravity_m_s2).length(),
            steps_per_impact: DEFAULT_STEPS_PER_IMPACT,
            restitution_resolution: DEFAULT_RESTITUTION_RESOLUTION,
            material_names: [a.material.clone(), surface_mat],
        })
    }

    /// Elastic Hertz contact time of the impact at `v0` (physics.md section 4).
    pub fn elastic_contact_time_s(&self, v0: f64) -> Result<f64, CalibrateError> {
        let m1 = scenario::validate::material("apple", &self.apple)?;
        let m2 = scenario::validate::material("surface", &self.surface)?;
        let r = self.diameter_m / 2.0;
        let k = normal::stiffness(effective_modulus(&m1, &m2), r);
        Ok(theory::elastic_impact(self.mass_kg, v0, k, r).contact_time_s)
    }

    fn check(&self, v0: f64) -> Result<(), CalibrateError> {
        let pos = |field: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(input(field, format!("{v} must be a finite number > 0")))
            }
        };
        pos("speed_m_s", v0)?;
        pos("diameter_m", self.diameter_m)?;
        pos("mass_kg", self.mass_kg)?;
        pos("steps_per_impact", self.steps_per_impact)?;
        pos("restitution_resolution", self.restitution_resolution)?;
        if !(self.lambda_s_m.is_finite() && self.lambda_s_m >= 0.0) {
            return Err(input(
                "lambda_s_m",
                format!("{} must be >= 0", self.lambda_s_m),
            ));
        }
        if !(self.gravity_m_s2.is_finite() && self.gravity_m_s2 >= 0.0) {
            return Err(input(
                "gravity_m_s2",
                format!("{} must be >= 0", self.gravity_m_s2),
            ));
        }
        Ok(())
    }

    /// The one-impact scenario of ke `ke` (the paper's eq. 12 with this setup's lambda): the
    /// apple touching a plane at z = 0, moving down at `v0`.
    fn scenario(&self, ke: f64, v0: f64, dt: f64, duration: f64) -> Scenario {
        OneImpact {
            materials: BTreeMap::from([
                ("apple".to_string(), self.apple.clone()),
                ("surface".to_string(), self.surface.clone()),
            ]),
            contact: ContactSpec::paper(0.0, ke, self.lambda_s_m),
            pairs: Vec::new(),
            apple_material: "apple".into(),
            surface_name: "surface".into(),
            surface_material: "surface".into(),
            padding: None,
            diameter_m: self.diameter_m,
            mass_kg: self.mass_kg,
            gravity_m_s2: self.gravity_m_s2,
        }
        .scenario(v0, dt, duration)
    }

    fn gravity_note(&self) -> String {
        if self.gravity_m_s2 > 0.0 {
            format!(", under gravity of {} m/s^2", self.gravity_m_s2)
        } else {
            String::new()
        }
    }
}

/// One apple striking a flat square on, the flat's face at z = 0: the single-impact scenario
/// [`simulate_impact`] (ke against a restitution) and `applesim calibrate-bruise`
/// ([`super::calibrate_bruise`], a drop test's hit) simulate. The materials keep the names they
/// have in the user's file, so the pair's contact law (`contact`, a `pairs` entry, the material
/// presets' pair coefficients) and each material's loss factor apply as in the user's scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct OneImpact {
    /// The materials (at least the apple's, the flat's and its pad's).
    pub materials: BTreeMap<String, MaterialSpec>,
    /// Contact coefficients of every pair without a `pairs` entry.
    pub contact: ContactSpec,
    /// Per-pair overrides.
    pub pairs: Vec<PairSpec>,
    /// The apple's material (a key of `materials`).
    pub apple_material: String,
    /// The flat's name (in the simulation's messages).
    pub surface_name: String,
    /// The flat's material (a key of `materials`); the substrate when padded.
    pub surface_material: String,
    /// A pad bonded on the flat (docs/physics.md section 13).
    pub padding: Option<PaddingSpec>,
    /// Apple diameter (m).
    pub diameter_m: f64,
    /// Apple mass (kg).
    pub mass_kg: f64,
    /// Gravity towards the flat (m/s^2); 0 for none.
    pub gravity_m_s2: f64,
}

impl OneImpact {
    /// The scenario: the apple touching the flat (no overlap), moving down at `v0` (m/s), stepped
    /// at the fixed step `dt` for `duration` (s); no force histories, no slip/roll detection.
    pub fn scenario(&self, v0: f64, dt: f64, duration: f64) -> Scenario {
        let r = self.diameter_m / 2.0;
        let mut output = OutputSpec {
            force_history: Some(crate::scenario::ForceHistory::Off),
            ..OutputSpec::default()
        };
        output.transitions.enabled = false;
        Scenario {
            description: Some("applesim: one impact on a flat".into()),
            grading: None,
            duration_s: duration,
            time_step_s: dt.into(),
            accuracy: None,
            max_time_step_s: None,
            fidelity: Default::default(),
            gravity_m_s2: [0.0, 0.0, -self.gravity_m_s2],
            output,
            materials: self.materials.clone(),
            contact: self.contact,
            pairs: self.pairs.clone(),
            model: ModelSpec::default(),
            apples: vec![AppleSpec {
                name: "apple".into(),
                material: self.apple_material.clone(),
                diameter_m: self.diameter_m,
                height_m: None,
                rotation: None,
                mass_kg: Some(self.mass_kg),
                position_m: [0.0, 0.0, r],
                velocity_m_s: [0.0, 0.0, -v0],
                angular_velocity_rad_s: [0.0; 3],
                probe: None,
                on: None,
            }],
            generators: Vec::new(),
            sources: Vec::new(),
            surfaces: vec![SurfaceSpec::Plane(PlaneSpec {
                name: self.surface_name.clone(),
                material: self.surface_material.clone(),
                point_m: [0.0; 3],
                normal: [0.0, 0.0, 1.0],
                contact_model: Default::default(),
                motion: None,
                padding: self.padding.clone(),
            })],
        }
    }

    /// The elastic Hertz impact (peak force, contact time; physics.md section 4) of the apple on
    /// a half-space of material `other` (a key of `materials`) at `v0`: on the flat's own
    /// material it is the stiffest contact of the impact (a pad only softens it), whose contact
    /// time sets the time step.
    pub fn elastic(&self, other: &str, v0: f64) -> Result<theory::ElasticImpact, CalibrateError> {
        let spec = |m: &str| {
            self.materials.get(m).ok_or_else(|| {
                input(
                    "materials",
                    format!(
                        "unknown material '{m}' (defined: {})",
                        self.materials
                            .keys()
                            .cloned()
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                )
            })
        };
        let m1 = scenario::validate::material(&self.apple_material, spec(&self.apple_material)?)?;
        let m2 = scenario::validate::material(other, spec(other)?)?;
        let r = self.diameter_m / 2.0;
        let k = normal::stiffness(effective_modulus(&m1, &m2), r);
        Ok(theory::elastic_impact(self.mass_kg, v0, k, r))
    }
}

/// Validates `sc`, builds its world and steps it at `dt` (the layer may shorten a step; the
/// step taken is passed on) until `done`, called after each step's forces with the world, the
/// step taken and the step's index, gives a value; `None` after `max_steps` steps without one.
/// The stepping loop of every one-impact simulation ([`simulate_impact`],
/// `calibrate_bruise::simulate_drop`).
pub fn step_until<T>(
    sc: &Scenario,
    dt: f64,
    max_steps: u64,
    mut done: impl FnMut(&mut World, f64, u64) -> Option<T>,
) -> Result<Option<T>, CalibrateError> {
    scenario::validate(sc)?;
    let mut w = world::build(sc, Path::new("."))?;
    for step in 0..=max_steps {
        let t = step as f64 * dt;
        let taken = w.force_pass(&StepRequest::fixed(t, dt))?;
        if let Some(v) = done(&mut w, taken, step) {
            return Ok(Some(v));
        }
        w.advance(taken);
    }
    Ok(None)
}

/// Simulates one impact at `v0` with coefficient `ke` and reports its restitution.
///
/// The run stops at separation; or, under gravity, as soon as the apple turns back down while
/// still in contact: it then cannot lift off (at the turning point the force is below m g, so
/// the energy stored, less than m g u, cannot lift it over the overlap u), and the restitution is
/// `None`. A safety limit of 8 times the slowest unloading without gravity ends any other case.
pub fn simulate_impact(setup: &ImpactSetup, ke: f64, v0: f64) -> Result<Impact, CalibrateError> {
    setup.check(v0)?;
    if !(ke > 0.0 && ke <= 1.0) {
        return Err(input("ke", format!("{ke} must lie in (0, 1]")));
    }
    let t_h = setup.elastic_contact_time_s(v0)?;
    let mut dt = t_h / setup.steps_per_impact;
    if setup.gravity_m_s2 > 0.0 {
        dt = dt.min(setup.restitution_resolution * v0 / setup.gravity_m_s2);
    }
    let t_max = 4.0 * t_h * (1.0 + 1.0 / ke.sqrt());
    let sc = setup.scenario(ke, v0, dt, t_max);
    let max_steps = (t_max / dt).ceil() as u64;
    let mut rising = false;
    let found = step_until(&sc, dt, max_steps, |w, dt, step| {
        if let Some(e) = w.layer.finished_events().first() {
            return Some(Impact {
                ke,
                speed_m_s: v0,
                restitution: e.restitution,
                peak_force_n: e.peak_force_n,
                contact_time_s: e.duration_s,
                time_step_s: dt,
            });
        }
        let vz = w.apple_body(0).linvel().z;
        let turned_back = rising && vz <= 0.0;
        rising |= vz > 0.0;
        (turned_back || step >= max_steps).then(|| Impact {
            ke,
            speed_m_s: v0,
            restitution: None,
            peak_force_n: w
                .layer
                .open_events()
                .first()
                .map_or(0.0, |e| e.peak_force_n),
            contact_time_s: None,
            time_step_s: dt,
        })
    })?;
    // The closure answers at the last step at the latest.
    found.ok_or_else(|| input("duration", "the impact was not simulated"))
}

fn restitution_or_zero(i: &Impact) -> f64 {
    i.restitution.unwrap_or(0.0)
}

/// Finds ke so that the simulated impact at `v0` rebounds with restitution `target` (within
/// `tolerance`, e.g. 1e-4), or says why no ke in [[`KE_MIN`], 1] can.
///
/// The search brackets the target between ke = KE_MIN and ke = 1 and narrows the bracket by
/// regula falsi in sqrt(ke) with the Illinois modification (e is close to linear in sqrt(ke)),
/// falling back to bisection; no lift-off counts as e = 0, which keeps e(ke) monotonic.
pub fn calibrate(
    setup: &ImpactSetup,
    target: f64,
    v0: f64,
    tolerance: f64,
) -> Result<Calibration, CalibrateError> {
    if !(target > 0.0 && target < 1.0) {
        return Err(input(
            "target e",
            format!("{target} must lie in (0, 1): 1 is elastic (ke = 1), 0 no rebound"),
        ));
    }
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return Err(input("tolerance", format!("{tolerance} must be > 0")));
    }
    setup.check(v0)?;
    let mut fine = setup.clone();
    fine.restitution_resolution = fine.restitution_resolution.min(0.5 * tolerance);
    let setup = &fine;
    let unreachable = |reason: String| CalibrateError::Unreachable {
        target,
        speed_m_s: v0,
        lambda_s_m: setup.lambda_s_m,
        gravity: setup.gravity_note(),
        reason,
    };
    let lambda_v0 = setup.lambda_s_m * v0;
    let runs = std::cell::Cell::new(0usize);
    let sim = |ke: f64| {
        runs.set(runs.get() + 1);
        simulate_impact(setup, ke, v0)
    };
    let hi = sim(1.0)?;
    let Some(e_hi) = hi.restitution else {
        return Err(unreachable(
            "the apple does not lift off even with ke = 1 (elastic): gravity holds it".into(),
        ));
    };
    if target > e_hi {
        return Err(unreachable(format!(
            "ke = 1 (elastic) gives the largest restitution, e = {e_hi:.4}"
        )));
    }
    let lo = sim(KE_MIN)?;
    let e_lo = restitution_or_zero(&lo);
    if target < e_lo {
        let reason = format!(
            "at lambda v0 = {lambda_v0:.3} the eq. 12 unloading force never drops to ke times Hertz \
             (the factor (1 + ke + (1 - ke) tanh(lambda du/dt)) / 2 stays near (1 + ke) / 2 while \
             lambda |du/dt| is small), so even ke = {KE_MIN:e} rebounds with e = {e_lo:.4}, above the \
             target (physics.md section 3: e >= 0.477 for every ke at lambda v0 = 2 without gravity). \
             Raise lambda so that lambda v0 >> 1: with lambda v0 >= 100 e -> sqrt(ke), here lambda >= {:.0} s/m",
            100.0 / v0
        );
        return Err(unreachable(reason));
    }
    let done = |i: &Impact| (restitution_or_zero(i) - target).abs() <= tolerance;
    let mut best = if (e_hi - target).abs() < (e_lo - target).abs() {
        hi
    } else {
        lo
    };
    // Bracket in s = sqrt(ke): f(s) = e(s) - target, f(lo) <= 0 <= f(hi).
    let (mut s_lo, mut f_lo) = (KE_MIN.sqrt(), e_lo - target);
    let (mut s_hi, mut f_hi) = (1.0, e_hi - target);
    let mut side = 0i8;
    while !done(&best) {
        if s_hi - s_lo < 1e-12 || runs.get() >= 100 {
            return Err(unreachable(format!(
                "the search stalled at ke = {:.6e} with e = {:.5}: the simulated restitution jumps \
                 there by more than the tolerance {tolerance} (a change of one step in contact); \
                 loosen the tolerance or shorten the time step (--steps-per-impact)",
                best.ke,
                restitution_or_zero(&best)
            )));
        }
        let mut s = (s_lo * f_hi - s_hi * f_lo) / (f_hi - f_lo);
        if !(s > s_lo && s < s_hi) {
            s = 0.5 * (s_lo + s_hi);
        }
        let i = sim(s * s)?;
        let f = restitution_or_zero(&i) - target;
        if (f.abs()) < (restitution_or_zero(&best) - target).abs() {
            best = i;
        }
        if f > 0.0 {
            s_hi = s;
            f_hi = f;
            if side == 1 {
                f_lo *= 0.5;
            }
            side = 1;
        } else {
            s_lo = s;
            f_lo = f;
            if side == -1 {
                f_hi *= 0.5;
            }
            side = -1;
        }
    }
    Ok(Calibration {
        target,
        ke: best.ke,
        restitution: restitution_or_zero(&best),
        sqrt_ke: best.ke.sqrt(),
        lambda_v0,
        impact: best,
        simulations: runs.get(),
    })
}

/// The restitution of coefficient `ke` at each speed of `speeds_m_s` (the inverse of
/// [`calibrate`]).
pub fn restitution_table(
    setup: &ImpactSetup,
    ke: f64,
    speeds_m_s: &[f64],
) -> Result<Vec<Impact>, CalibrateError> {
    speeds_m_s
        .iter()
        .map(|&v| simulate_impact(setup, ke, v))
        .collect()
}
