//! The contact law: pure functions of overlap, rates and materials, no rapier.
//!
//! Split like LAMMPS's GRANULAR package, each part small and unit-tested against closed forms:
//! [`material`] (eq. 2), [`normal`] (Hertz, eqs. 1 and 3), [`damping`] (eq. 12 with the
//! dissipative sign, its elastic-at-rest variant, viscoelastic Hertz), [`friction`] (eq. 11 with a
//! Mindlin stick spring, or LIGGGHTS's tangential history), [`rolling`] (rolling resistance),
//! [`geometry`] (overlaps, eq. 8) and [`theory`] (closed forms of physics.md). Like LAMMPS, the
//! sub-models are chosen per pair of materials ([`SubModels`]). [`evaluate`] combines them for
//! one contact; the rolling torque is computed beside it ([`rolling_torque`]).

pub mod damping;
pub mod elliptic;
pub mod friction;
pub mod geometry;
pub mod material;
pub mod normal;
pub mod padding;
pub mod rolling;
pub mod share;
pub mod spheroid;
pub mod theory;
pub mod twisting;

use crate::math::Vec3;
pub use damping::DampingModel;
pub use friction::TangentialModel;
pub use material::{Material, MaterialError};
pub use rolling::RollingModel;
pub use twisting::TwistingModel;

/// The sub-models of a pair of materials beyond friction, ke and lambda (docs/physics.md
/// section 11). The default is the paper's model: eq. 12, the Mindlin spring, no rolling
/// resistance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubModels {
    /// Normal energy loss.
    pub damping: DampingModel,
    /// Coefficient of restitution of [`DampingModel::Viscoelastic`] (and of the damping of
    /// [`TangentialModel::History`]); with the eq. 12 models the tangential damping takes
    /// e = sqrt(ke).
    pub restitution: f64,
    /// Tangential force.
    pub tangential: TangentialModel,
    /// Rolling resistance.
    pub rolling: RollingModel,
    /// Coefficient of rolling friction mu_r (the torque's lever over R*).
    pub rolling_friction: f64,
    /// Damping ratio eta_r of the elastic-plastic rolling spring (LIGGGHTS `epsd`'s
    /// `coefficientRollingViscousDamping`; 0 is `epsd2`).
    pub rolling_damping: f64,
    /// Twisting resistance (spin about the normal).
    pub twisting: TwistingModel,
}

impl Default for SubModels {
    fn default() -> Self {
        Self {
            damping: DampingModel::Eq12,
            restitution: f64::NAN,
            tangential: TangentialModel::Mindlin,
            rolling: RollingModel::None,
            rolling_friction: 0.0,
            rolling_damping: 0.0,
            twisting: TwistingModel::None,
        }
    }
}

/// Which parts of the law are on (the fidelity levels of the scenario, see `docs/accuracy.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LawParts {
    /// Eq. 12 energy loss; off means elastic Hertz whatever ke says.
    pub energy_loss: bool,
    /// Coulomb friction with the stick spring; off means frictionless.
    pub friction: bool,
    /// The eq. 9 shift of the contact point along the friction force ("full" fidelity).
    pub patch_shift: bool,
}

impl Default for LawParts {
    fn default() -> Self {
        Self {
            energy_loss: true,
            friction: true,
            patch_shift: false,
        }
    }
}

/// Constants of the law for one pair of materials (body 1 is the apple).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairLaw {
    /// Effective modulus E* (Pa).
    pub e_star_pa: f64,
    /// Effective shear modulus G* for the Mindlin spring (Pa).
    pub g_star_pa: f64,
    /// Body 1's share of the overlap, c1 / (c1 + c2).
    pub share1: f64,
    /// Body 1's share of the energy the contact dissipates ([`share`]): `share1` weighted by
    /// the two bodies' loss factors.
    pub energy_share1: f64,
    /// The loss factors of the two bodies ([`material::Material::loss_factor`]), each the
    /// pair's own 1 - e^2 where the material states none ([`share::pair_loss_factor`]).
    pub loss_factors: [f64; 2],
    /// The materials' own loss factors, as stated (`None`: not stated).
    pub stated_loss_factors: [Option<f64>; 2],
    /// Coulomb coefficient.
    pub friction: f64,
    /// Eq. 12 energy-loss coefficient ke in (0, 1]; 1 is elastic.
    pub ke: f64,
    /// Eq. 12 rate constant lambda (s/m).
    pub lambda_s_m: f64,
    /// Body 1's Poisson ratio (eq. 9 patch shift).
    pub nu1: f64,
    /// Body 1's shear modulus (eq. 9 patch shift), Pa.
    pub g1_pa: f64,
    /// The pair's sub-models.
    pub models: SubModels,
    /// LIGGGHTS's damping ratio beta = ln e / sqrt(ln^2 e + pi^2) of the pair's restitution (the
    /// viscoelastic and history dampings).
    pub beta: f64,
}

impl PairLaw {
    /// Combines two materials with the pair's friction, ke and lambda.
    pub fn new(m1: &Material, m2: &Material, friction: f64, ke: f64, lambda_s_m: f64) -> Self {
        Self {
            e_star_pa: material::effective_modulus(m1, m2),
            g_star_pa: material::effective_shear_modulus(m1, m2),
            share1: material::indentation_share(m1, m2),
            energy_share1: f64::NAN,
            loss_factors: [f64::NAN; 2],
            stated_loss_factors: [m1.loss_factor, m2.loss_factor],
            friction,
            ke,
            lambda_s_m,
            nu1: m1.poisson_ratio,
            g1_pa: m1.shear_modulus_pa,
            models: SubModels::default(),
            beta: damping::beta_of_restitution(ke.sqrt()),
        }
        .with_loss_shares(ke.sqrt())
    }

    /// Resolves the loss factors and the energy share for the pair's nominal restitution `e`.
    fn with_loss_shares(mut self, e: f64) -> Self {
        let pair = share::pair_loss_factor(e);
        let [a, b] = self.stated_loss_factors;
        self.loss_factors = [a.unwrap_or(pair), b.unwrap_or(pair)];
        self.energy_share1 =
            share::loss_share(self.share1, self.loss_factors[0], self.loss_factors[1]);
        self
    }

    /// The same law with other sub-models.
    pub fn with_models(mut self, models: SubModels) -> Self {
        let e = match models.damping {
            DampingModel::Viscoelastic => models.restitution,
            _ if models.restitution.is_finite() => models.restitution,
            _ => self.ke.sqrt(),
        };
        self.beta = damping::beta_of_restitution(e);
        // The pair's nominal restitution: its loss as a whole (eq. 12: sqrt(ke), section 3).
        let nominal = match models.damping {
            DampingModel::Viscoelastic => models.restitution,
            _ => self.ke.sqrt(),
        };
        self.models = models;
        self.with_loss_shares(nominal)
    }
}

/// Constants of one contact: they depend only on the two bodies, so the layer computes them once
/// when the contact starts (a square root and a few divisions per contact and step saved).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactConstants {
    /// Effective radius R* (m).
    pub r_star_m: f64,
    /// sqrt(R*): the contact radius is a = sqrt(R*) sqrt(u).
    pub sqrt_r_star: f64,
    /// Hertz stiffness k = 4/3 E* sqrt(R*) (N/m^(3/2)).
    pub stiffness: f64,
    /// sqrt(R_a / R*): the radius of the circle of the contact's true area over the law's
    /// contact radius sqrt(R* u). 1 for a circular contact; for an elliptical one (an apple on a
    /// roller, [`elliptic`]) R* is the stiffness radius R_k and the area is pi a b = pi R_a u, so
    /// the reported area and pressure use this factor while the law keeps sqrt(R_k u).
    pub area_scale: f64,
    /// Normal effective mass of the contact (kg), for the bound on eq. 12's rate part.
    pub normal_mass_kg: f64,
    /// 1 / `normal_mass_kg`.
    pub inv_normal_mass: f64,
    /// Tangential effective mass of the contact (kg), for the friction dashpot.
    pub tangential_mass_kg: f64,
    /// Effective moment of inertia of the relative rolling, 1 / (1/I1 + 1/I2) with each body's
    /// moment about the contact point, I + m R^2 (kg m^2; 0 until set), for the rolling dashpot.
    pub rolling_inertia_kg_m2: f64,
    /// Effective moment of inertia of the relative spin about the centres, 1 / (1/I1 + 1/I2)
    /// (kg m^2; 0 until set), for the stopping bound of the constant rolling torque.
    pub spin_inertia_kg_m2: f64,
    /// The pad of a padded surface ([`padding`]); `None`: half-space Hertz. Boxed: every
    /// contact's slot holds these constants, few contacts are on a pad, and the pad's 144 bytes
    /// inline made a contact 800 bytes, the slab the force pass and detection stream each step.
    pub pad: Option<Box<padding::PadConstants>>,
}

impl ContactConstants {
    /// The constants of a contact with effective radius `r_star_m` and effective masses.
    pub fn new(law: &PairLaw, r_star_m: f64, normal_mass_kg: f64, tangential_mass_kg: f64) -> Self {
        let sqrt_r_star = r_star_m.sqrt();
        Self {
            r_star_m,
            sqrt_r_star,
            stiffness: 4.0 / 3.0 * law.e_star_pa * sqrt_r_star,
            area_scale: 1.0,
            normal_mass_kg,
            inv_normal_mass: 1.0 / normal_mass_kg,
            tangential_mass_kg,
            rolling_inertia_kg_m2: 0.0,
            spin_inertia_kg_m2: 0.0,
            pad: None,
        }
    }
}

/// Kinematics of one contact at the current poses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactKinematics {
    /// Unit normal from body 2 towards body 1.
    pub normal: Vec3,
    /// Overlap u > 0 (m).
    pub overlap_m: f64,
    /// Velocity of body 1's surface point at the contact point minus body 2's (belt included), m/s.
    pub rel_velocity: Vec3,
    /// Whether the contact is resting: its impact is over (it is older than 1.2 times eq. 12's
    /// contact time at its approach speed). Only a resting contact gets the bound on eq. 12's rate part
    /// (see [`damping::hysteresis_force`]): an impact passes its turn once and keeps the paper's law.
    pub resting: bool,
    /// The free relative acceleration of the overlap, d(du/dt)/dt without this contact's force
    /// (m/s^2): gravity and the other contacts' loads (the layer takes it from the last step).
    /// The eq. 12 dampings average their factor over the coming step from the rate it will
    /// reach; without the support's share an apple at rest was predicted to unload and sank (20 %
    /// of its overlap in 0.1 s at dt 1e-4 s: tests/damping_models.rs).
    pub free_accel: f64,
    /// The largest gamma_t / m_t of LIGGGHTS's tangential dashpot (1/s): the bound
    /// ([`HISTORY_DASHPOT_BOUND`] by default) times 1 / (n dt), the rate that stops the contact's
    /// relative motion within one step shared among the n contacts of the busier of its apples.
    /// Infinite leaves the dashpot unbounded.
    pub history_damping_limit_1_s: f64,
}

/// What the law returns for one contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactResponse {
    /// Normal force P >= 0 (N).
    pub normal_force_n: f64,
    /// Total force on body 1 (normal + friction), N; body 2 gets the opposite.
    pub force_on_1: Vec3,
    /// Friction force on body 1 (N).
    pub friction_force: Vec3,
    /// Shift of the point of application from the geometric contact point (eq. 9), m.
    pub patch_shift: Vec3,
    /// Contact radius a = sqrt(R* u) of the law (m): the Mindlin spring's and the rolling
    /// spring's radius.
    pub contact_radius_m: f64,
    /// Radius of the circle of the true contact area (m): `contact_radius_m` for a circular
    /// contact, sqrt(a b) for an elliptical one (see [`ContactConstants::area_scale`]).
    pub area_radius_m: f64,
    /// Mean pressure P / (true contact area) (Pa): P / (pi a b) on an ellipse; the peak
    /// pressure is 1.5 times this for both shapes.
    pub mean_pressure_pa: f64,
    /// Overlap rate du/dt (m/s), > 0 while approaching.
    pub overlap_rate_m_s: f64,
    /// Tangential slip velocity s_t of body 1's surface point over body 2's (m/s); its length is
    /// the slip speed of physics.md section 5.
    pub slip_velocity: Vec3,
    /// Whether friction is at the Coulomb limit.
    pub sliding: bool,
    /// Elastic energy 2/5 k u^(5/2) of the overlap (J).
    pub elastic_energy_j: f64,
    /// The elastic (Hertz) part k u^(3/2) of the normal force (N); on a pad, the pad law's
    /// elastic force ([`padding`]).
    pub hertz_force_n: f64,
    /// On a pad: it has bottomed out ([`padding::PadConstants::elastic_force`]).
    pub pad_bottomed: bool,
}

/// The bound of LIGGGHTS's `tangential history` dashpot, as a share of the damping m_t / (n dt)
/// that stops a contact's slip within one step when its apple's n contacts share it
/// ([`ContactKinematics::history_damping_limit_1_s`]): gamma_t dt / m_t <= 1.5 / n. The default
/// of `model.history_dashpot_bound` (`LayerConfig::history_dashpot_bound`), which may replace it
/// within (0, 2).
///
/// Why: LIGGGHTS integrates that dashpot explicitly, and it does not scale with the tangential
/// mass m_t (gamma_t = 2 sqrt(5/6) |beta| sqrt(k_t m*)). A sticking contact stepped as the layer
/// steps it is stable iff b < 2 and a + 2 b < 4, with a = k_t dt^2 / m_t and b = gamma_t dt / m_t
/// (docs/physics.md, "Stability of the spin"); LIGGGHTS's own 1000-apple pile jiggles at a fixed
/// 6e-4 s (docs/liggghts_models.md), and applesim's step control had to keep every resting
/// `history` contact under b = 0.6 (its former `damping_step`): on the same-model pile about
/// 4.5e-4 s, where the stick spring allows about 8e-4 s. Bounded, one contact at the step
/// control's resting steps (a <= (pi/4)^2 = 0.62, four steps per half period of the stick spring)
/// has a + 2 b <= 3.62: stable at every step the spring allows, and the step control takes those. Why 1.5 and not the 1 of the eq. 12
/// bound: above every contact of the reference runs at LIGGGHTS's dt 1e-4 s (the largest
/// gamma_t n dt / m_t over the four starts of the epsd2 pile and over the cdt pile is 1.27,
/// measured: docs/performance.md, "Tenth session"), so those runs are unchanged bit for bit. A
/// choice of this project, not a literature value.
pub const HISTORY_DASHPOT_BOUND: f64 = 1.5;

/// Evaluates the full law for one contact. `xi` is the contact's stored tangential displacement;
/// `kill_rate` (1/s) is the fraction of the "velocity-kill" rate 1 / dt that bounds the
/// rate-dependent forces of this contact, per kg of its effective mass: the tangential dashpot
/// (see [`friction`]) and the rate part of eq. 12 (see [`damping::hysteresis_force`]). The layer
/// passes `relaxation / dt` with its relaxation shared among the apple's contacts.
#[inline]
pub fn evaluate(
    law: &PairLaw,
    parts: LawParts,
    k: &ContactConstants,
    kin: &ContactKinematics,
    xi: &mut Vec3,
    kill_rate: f64,
    dt_s: f64,
) -> ContactResponse {
    let n = kin.normal;
    let u = kin.overlap_m.max(0.0);
    let v_n = kin.rel_velocity.dot(n);
    let du_dt = -v_n;
    // sqrt(u) serves the Hertz force k u^(3/2), the contact radius sqrt(R*) sqrt(u) and the energy.
    let (mut elastic, sqrt_u) = normal::hertz_force_and_root(k.stiffness, u);
    let mut pad_bottomed = false;
    if let Some(pad) = &k.pad {
        // The pad law's elastic force; the damping models multiply it as they do Hertz's.
        (elastic, pad_bottomed) = pad.elastic_force(u);
    }
    let a = k.sqrt_r_star * sqrt_u;
    let p = if parts.energy_loss {
        // The normal bound uses twice the tangential share: it stops the relative normal motion
        // within one step (the friction dashpot within two), still stable shared among contacts.
        let kill = if kin.resting {
            2.0 * kill_rate * k.normal_mass_kg
        } else {
            f64::INFINITY
        };
        match law.models.damping {
            DampingModel::Eq12 => {
                // The rate at the end of the step, from the contact's own mean force (the static
                // part of eq. 12) decelerating the approach: the factor is averaged over the step.
                let decel = 0.5 * (1.0 + law.ke) * elastic * k.inv_normal_mass;
                let du_dt_next = du_dt + (kin.free_accel - decel) * dt_s;
                damping::hysteresis_force(elastic, law.ke, law.lambda_s_m, du_dt, du_dt_next, kill)
            }
            DampingModel::Eq12ElasticRest => {
                let du_dt_next = du_dt + (kin.free_accel - elastic * k.inv_normal_mass) * dt_s;
                damping::elastic_rest_force(
                    elastic,
                    law.ke,
                    law.lambda_s_m,
                    du_dt,
                    du_dt_next,
                    kill,
                )
            }
            DampingModel::Viscoelastic => {
                let c =
                    damping::viscoelastic_coefficient(law.beta, law.e_star_pa, a, k.normal_mass_kg);
                damping::viscoelastic_force(elastic, c, du_dt)
            }
        }
    } else {
        elastic
    };
    let slip_t = kin.rel_velocity - n * v_n;
    let mut friction_force = Vec3::ZERO;
    let mut sliding = false;
    let mut shift = Vec3::ZERO;
    if parts.friction && law.friction > 0.0 {
        let stiffness_n_m = friction::mindlin_stiffness(law.g_star_pa, a);
        let t = match law.models.tangential {
            TangentialModel::Mindlin => {
                *xi = friction::project_history(*xi, n);
                let params = friction::TangentialParams {
                    mu: law.friction,
                    stiffness_n_m,
                    damping_n_s_m: kill_rate * k.tangential_mass_kg,
                };
                friction::tangential_force(&params, p, slip_t, xi, dt_s)
            }
            TangentialModel::History => {
                // LIGGGHTS's dashpot, bounded where explicit stepping cannot carry it (see
                // `HISTORY_DASHPOT_BOUND`).
                let gamma_t = (-2.0
                    * damping::SQRT_FIVE_SIXTHS
                    * law.beta
                    * (stiffness_n_m * k.normal_mass_kg).sqrt())
                .min(kin.history_damping_limit_1_s * k.tangential_mass_kg);
                friction::history_force(
                    law.friction,
                    stiffness_n_m,
                    gamma_t,
                    p,
                    slip_t,
                    n,
                    xi,
                    dt_s,
                )
            }
        };
        friction_force = t.force;
        sliding = t.sliding;
        if parts.patch_shift && a > 0.0 {
            // Eq. 9: the pressure centre moves by delta = F_t nu1 / (4 a G1) along F_t.
            shift = friction_force * (law.nu1 / (4.0 * a * law.g1_pa));
        }
    } else {
        *xi = Vec3::ZERO;
    }
    ContactResponse {
        normal_force_n: p,
        force_on_1: n * p + friction_force,
        friction_force,
        patch_shift: shift,
        contact_radius_m: a,
        area_radius_m: a * k.area_scale,
        mean_pressure_pa: normal::mean_pressure(p, a * k.area_scale),
        overlap_rate_m_s: du_dt,
        slip_velocity: slip_t,
        sliding,
        elastic_energy_j: 0.4 * elastic * u,
        hertz_force_n: elastic,
        pad_bottomed,
    }
}

/// The rolling-resistance torque on body 1 of a contact (see [`rolling`]); body 2 gets the
/// opposite. `rel_angular_velocity` is w1 - w2, `resp` the contact's response this step, `spring`
/// the contact's stored `epsd2` torque, `kill_rate` the share of 1/dt that bounds the `cdt` torque
/// (as for the friction dashpot).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn rolling_torque(
    law: &PairLaw,
    k: &ContactConstants,
    n: Vec3,
    rel_angular_velocity: Vec3,
    resp: &ContactResponse,
    spring: &mut Vec3,
    kill_rate: f64,
    dt_s: f64,
) -> Vec3 {
    let mu_r = law.models.rolling_friction;
    let w_t = rolling::rolling_velocity(rel_angular_velocity, n);
    match law.models.rolling {
        RollingModel::None => Vec3::ZERO,
        // The load (the whole normal force): with viscoelastic damping at rest it is the Hertz
        // force LIGGGHTS uses; with eq. 12 the Hertz part alone is 2 / (1 + ke) times the load.
        // The stopping bound turns the apple about its centre within a step: its moment there.
        RollingModel::ConstantTorque => rolling::constant_torque(
            mu_r,
            k.r_star_m,
            resp.normal_force_n,
            w_t,
            kill_rate * k.spin_inertia_kg_m2,
        ),
        RollingModel::ElasticPlastic => {
            // k_r = k_t R*^2 with k_t = 8 G* a (LIGGGHTS epsd2); the dashpot of epsd (its
            // coefficient on the moment about the contact point, as LIGGGHTS), bounded by the
            // velocity-kill rate for explicit stepping. The bound is on the moment about the
            // centres: within one step a couple turns the apple about its centre, and on
            // I + m R^2 the bound reversed the rolling by 1.75 times itself every step, so a
            // settled pile rattled and never slept (tests/rolling_damping_bound.rs).
            let k_r = friction::mindlin_stiffness(law.g_star_pa, resp.contact_radius_m)
                * k.r_star_m
                * k.r_star_m;
            let i_r = k.rolling_inertia_kg_m2;
            let c_r = (law.models.rolling_damping * 2.0 * (i_r * k_r).sqrt())
                .min(kill_rate * k.spin_inertia_kg_m2);
            rolling::elastic_plastic(
                mu_r,
                k.r_star_m,
                resp.normal_force_n,
                k_r,
                c_r,
                w_t,
                n,
                spring,
                dt_s,
            )
        }
    }
}

/// The twisting torque on body 1 of a contact (see [`twisting`]); body 2 gets the opposite.
/// `rel_angular_velocity` is w1 - w2, `resp` the contact's response this step, `kill_rate` the
/// share of 1/dt that bounds the torque (as for the friction dashpot): the spin stops within a
/// step at most, about the centres (the moment `spin_inertia_kg_m2`). The patch is the true
/// contact area's circle (sqrt(a b) on a roller's ellipse, the same radius on a circle).
#[inline]
pub fn twisting_torque(
    law: &PairLaw,
    k: &ContactConstants,
    n: Vec3,
    rel_angular_velocity: Vec3,
    resp: &ContactResponse,
    kill_rate: f64,
) -> Vec3 {
    match law.models.twisting {
        TwistingModel::None => Vec3::ZERO,
        TwistingModel::Coulomb => twisting::coulomb_torque(
            twisting::coulomb_limit(law.friction, resp.area_radius_m, resp.normal_force_n),
            rel_angular_velocity,
            n,
            kill_rate * k.spin_inertia_kg_m2,
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fig1_law() -> PairLaw {
        let apple = Material::from_shear(1.1e6, 0.18, Some(800.0)).unwrap();
        let steel = Material::from_shear(8.1e10, 0.28, None).unwrap();
        PairLaw::new(&apple, &steel, 0.3, 0.09, 1000.0)
    }

    fn kin(u: f64, vel: Vec3) -> ContactKinematics {
        ContactKinematics {
            normal: Vec3::Z,
            overlap_m: u,
            rel_velocity: vel,
            resting: false,
            free_accel: 0.0,
            history_damping_limit_1_s: f64::INFINITY,
        }
    }

    fn consts(law: &PairLaw) -> ContactConstants {
        ContactConstants::new(law, 0.04, 0.107, 0.03)
    }

    #[test]
    fn loading_is_hertz_unloading_is_ke_hertz() {
        let law = fig1_law();
        let mut xi = Vec3::ZERO;
        let load = evaluate(
            &law,
            LawParts::default(),
            &consts(&law),
            &kin(1e-3, Vec3::new(0.0, 0.0, -1.0)),
            &mut xi,
            0.5 / 1e-5,
            1e-5,
        );
        let k = normal::stiffness(law.e_star_pa, 0.04);
        assert!((load.normal_force_n - k * 1e-3f64.powf(1.5)).abs() < 1e-9);
        let unload = evaluate(
            &law,
            LawParts::default(),
            &consts(&law),
            &kin(1e-3, Vec3::new(0.0, 0.0, 1.0)),
            &mut xi,
            0.5 / 1e-5,
            1e-5,
        );
        assert!((unload.normal_force_n / load.normal_force_n - 0.09).abs() < 1e-9);
        assert!(unload.normal_force_n >= 0.0);
    }

    #[test]
    fn friction_caps_at_mu_p_and_opposes_slip() {
        let law = fig1_law();
        let mut xi = Vec3::ZERO;
        let r = evaluate(
            &law,
            LawParts::default(),
            &consts(&law),
            &kin(1e-3, Vec3::new(1.0, 0.0, 0.0)),
            &mut xi,
            0.5 / 1e-5,
            1e-5,
        );
        assert!(r.sliding);
        assert!((r.friction_force.length() - 0.3 * r.normal_force_n).abs() < 1e-9);
        assert!(r.friction_force.x < 0.0);
        let off = evaluate(
            &law,
            LawParts {
                friction: false,
                ..LawParts::default()
            },
            &consts(&law),
            &kin(1e-3, Vec3::new(1.0, 0.0, 0.0)),
            &mut xi,
            0.5 / 1e-5,
            1e-5,
        );
        assert_eq!(off.friction_force, Vec3::ZERO);
    }

    #[test]
    fn patch_shift_follows_eq9() {
        // An elastic contact (energy loss off, so P = k u^(3/2) exactly) sliding at 1 m/s: the
        // shift is delta = F_t nu1 / (4 a G1) along F_t (physics.md section 5), here computed
        // from the materials and the overlap alone, not from the response: E = 2 G (1 + nu),
        // 1/E* = sum (1 - nu^2) / E, k = 4/3 E* sqrt(R*), a = sqrt(R* u), F_t = mu P.
        let law = fig1_law();
        let mut xi = Vec3::ZERO;
        let parts = LawParts {
            patch_shift: true,
            energy_loss: false,
            ..LawParts::default()
        };
        let u = 1e-3;
        let r = evaluate(
            &law,
            parts,
            &consts(&law),
            &kin(u, Vec3::new(1.0, 0.0, 0.0)),
            &mut xi,
            0.5 / 1e-5,
            1e-5,
        );
        let c = |g: f64, nu: f64| (1.0 - nu * nu) / (2.0 * g * (1.0 + nu));
        let e_star = 1.0 / (c(1.1e6, 0.18) + c(8.1e10, 0.28));
        let p = 4.0 / 3.0 * e_star * 0.04f64.sqrt() * u.powf(1.5);
        let a = (0.04 * u).sqrt();
        let delta = 0.3 * p * 0.18 / (4.0 * a * 1.1e6);
        // 0.3 * 22.6 N * 0.18 / (4 * 6.32 mm * 1.1 MPa) = 43.9 um, against the motion.
        assert!((delta - 4.39e-5).abs() < 0.01e-5, "delta {delta}");
        assert!(
            (r.patch_shift.x + delta).abs() < 1e-12 * delta.max(1.0),
            "{:?} against {delta}",
            r.patch_shift
        );
        assert_eq!((r.patch_shift.y, r.patch_shift.z), (0.0, 0.0));
        // Without the `full` level's patch shift there is none.
        let plain = evaluate(
            &law,
            LawParts {
                energy_loss: false,
                ..LawParts::default()
            },
            &consts(&law),
            &kin(u, Vec3::new(1.0, 0.0, 0.0)),
            &mut xi,
            0.5 / 1e-5,
            1e-5,
        );
        assert_eq!(plain.patch_shift, Vec3::ZERO);
    }

    /// The largest root magnitude of lambda^2 - (2 - a - b) lambda + (1 - b) = 0: the growth per
    /// step of a stick spring and dashpot integrated as the layer does (history xi += s dt, then
    /// F = -k_t xi - gamma s, then symplectic Euler s += F dt / m_t), a = k_t dt^2 / m_t,
    /// b = gamma dt / m_t (docs/physics.md, "Stability of the spin": its characteristic polynomial).
    fn stick_growth(a: f64, b: f64) -> f64 {
        let (p, q) = (2.0 - a - b, 1.0 - b);
        let disc = p * p - 4.0 * q;
        if disc >= 0.0 {
            ((p.abs() + disc.sqrt()) / 2.0).max(((p.abs() - disc.sqrt()) / 2.0).abs())
        } else {
            q.sqrt()
        }
    }

    /// LIGGGHTS's `tangential history` dashpot, bounded at `HISTORY_DASHPOT_BOUND` m_t / (n dt):
    /// at a step where the explicit dashpot alone removes 2.5 times the slip per step, the slip
    /// grows by the closed form's factor unbounded and decays by it bounded (1.5 times); at a
    /// step under the bound the force is LIGGGHTS's, bit for bit. The dashpot's rate against the
    /// stick spring's grows as sqrt(m_n / m_t): a light tangential mass (a twentieth of the
    /// normal one) puts its limit inside the spring's (omega_t dt = 0.85 here, a = 0.73).
    #[test]
    fn the_history_dashpot_is_bounded_where_explicit_stepping_overshoots() {
        let apple = Material::from_shear(1.1e6, 0.18, Some(800.0)).unwrap();
        let steel = Material::from_shear(8.1e10, 0.28, None).unwrap();
        // mu 1e9: the contact sticks throughout (the dashpot acts only below the Coulomb cap).
        let law = PairLaw::new(&apple, &steel, 1e9, 1.0, 0.0).with_models(SubModels {
            damping: DampingModel::Viscoelastic,
            restitution: 0.3,
            tangential: TangentialModel::History,
            ..SubModels::default()
        });
        let (m_n, m_t, u): (f64, f64, f64) = (0.214, 0.0107, 1e-3);
        let k = ContactConstants::new(&law, 0.04, m_n, m_t);
        let k_t = friction::mindlin_stiffness(law.g_star_pa, k.sqrt_r_star * u.sqrt());
        let gamma = -2.0 * damping::SQRT_FIVE_SIXTHS * law.beta * (k_t * m_n).sqrt();
        // Slip history over `steps` of `dt` from a slip speed of 1 um/s, its dashpot's gamma_t /
        // m_t at most `limit`: the last two slip speeds.
        let run = |dt: f64, limit: f64, steps: usize| {
            let (mut xi, mut v, mut last) = (Vec3::ZERO, 1e-6, 0.0);
            for _ in 0..steps {
                let kin = ContactKinematics {
                    history_damping_limit_1_s: limit,
                    ..kin(u, Vec3::new(v, 0.0, 0.0))
                };
                let r = evaluate(&law, LawParts::default(), &k, &kin, &mut xi, 0.5 / dt, dt);
                assert!(!r.sliding);
                last = v;
                v += r.friction_force.x * dt / m_t;
            }
            (last, v)
        };
        let dt = 2.5 * m_t / gamma;
        let a = k_t * dt * dt / m_t;
        assert!((a - 0.73).abs() < 0.01, "omega_t^2 dt^2 {a}");
        // Unbounded: the explicit dashpot overshoots, |root| 1.987 per step.
        let (before, after) = run(dt, f64::INFINITY, 40);
        let want = stick_growth(a, 2.5);
        assert!((want - 1.987).abs() < 1e-3, "{want}");
        assert!(
            ((after / before).abs() / want - 1.0).abs() < 1e-9,
            "{} against {want}",
            after / before
        );
        // Bounded at 1.5 m_t / dt: decays by the closed form's factor, 0.833 per step.
        // (One contact, n = 1: the layer's limit HISTORY_DASHPOT_BOUND * (1 / (1 dt)).)
        let (before, after) = run(dt, HISTORY_DASHPOT_BOUND * (1.0 / dt), 200);
        let want = stick_growth(a, HISTORY_DASHPOT_BOUND);
        assert!((want - 0.833).abs() < 1e-3, "{want}");
        assert!(
            ((after / before).abs() / want - 1.0).abs() < 1e-9,
            "{} against {want}",
            after / before
        );
        // Under the bound (b = 1 < 1.5): LIGGGHTS's dashpot, the same bits bounded or not.
        let small = m_t / gamma;
        assert_eq!(
            run(small, HISTORY_DASHPOT_BOUND * (1.0 / small), 50),
            run(small, f64::INFINITY, 50)
        );
    }
}
