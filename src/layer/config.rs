//! The layer's settings, fixed when it is built: which parts of the law are on, the stability
//! guard, sleeping, step control, and the registration options of a surface.

use crate::contact::{LawParts, SubModels};
use crate::math::Vec3;
use rapier3d_f64::geometry::Group;

use super::registry::MaterialId;
use super::surface::SurfaceShape;

/// Limits beyond which the layer refuses to go on (physics.md section 10).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Guard {
    /// Largest overlap as a fraction of the smaller radius (Hertz needs u << R).
    pub max_overlap_ratio: f64,
    /// Fewest steps an impact may be resolved in: the Hertz contact time at the approach speed
    /// over dt. 10 steps give about 1 % error in the peak force (physics.md section 10).
    pub min_steps_per_impact: f64,
}

impl Default for Guard {
    fn default() -> Self {
        Self {
            max_overlap_ratio: 0.5,
            min_steps_per_impact: 10.0,
        }
    }
}

/// When apples at rest stop being simulated, and what wakes them.
///
/// An awake apple counts as *still* when |v| and |w| R are both below `speed_m_s`; it falls
/// asleep after `time_s` of stillness during which it touched something, its net force (contacts
/// and gravity, [`LayerConfig::gravity`]), averaged over the last quarter of `time_s`, could not
/// change its speed by `speed_m_s` within `time_s`, and it touched no apple that was not still
/// and no moving surface (a belt, a moving body). The force is averaged because an apple held in
/// a pile vibrates at its contacts' frequencies while its mean force is nil. A sleeper is not
/// integrated (rapier's sleeping) and its contacts with other sleepers and fixed surfaces are
/// frozen, not evaluated. It wakes when a contact with an awake apple starts or ends, or when the
/// overlap of such a contact moves by more than `wake_overlap_ratio` of its value at the time of
/// sleeping (the neighbour pushes harder or lets go). Waking cascades: a woken apple that moves
/// shifts its own contacts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SleepConfig {
    /// Whether apples may sleep at all.
    pub enabled: bool,
    /// Stillness threshold (m/s).
    pub speed_m_s: f64,
    /// Stillness time before sleeping (s).
    pub time_s: f64,
    /// Relative change of a contact's overlap that wakes a sleeper.
    pub wake_overlap_ratio: f64,
    /// Apples at rest on a running belt ride it (the layer's `sleep` module): still in the belt's
    /// frame by the same rule, touching nothing but the belt, they are carried at the belt's
    /// velocity (a kinematic body in rapier) and their contact is frozen, until anything else
    /// comes near, the belt's surface under them changes, or the belt ends.
    pub carried: bool,
}

impl Default for SleepConfig {
    fn default() -> Self {
        Self {
            enabled: true,
            speed_m_s: 0.005,
            time_s: 0.2,
            wake_overlap_ratio: 0.05,
            carried: true,
        }
    }
}

/// Adaptive stepping: every force pass also computes the longest next step that resolves the
/// contacts in progress and those about to start with `steps_per_contact` steps (see
/// [`super::StepStats::dt_limit_s`]), and chooses the step it applies the forces for under the
/// driver's request ([`super::StepRequest`]):
///
/// - a contact in progress at overlap u, that started at approach speed v_a: the elastic contact
///   time of an impact reaching max(u, u_max(v_a)), over N (for a resting contact that is the time
///   scale of its normal oscillation, so resting contacts allow long steps);
/// - a pair closing at speed v_c with gap g: g / v_c + t_H(v_c) / N (it may touch within the
///   step, but not go deeper than one resolved step);
/// - no awake apple may move more than `max_displacement_m` (the pair-finding margins).
///
/// With variable steps the velocity kick of pose k must span (h_k-1 + h_k) / 2, the time between
/// the staggered velocities (leapfrog with variable steps); rapier kicks by F h_k, so the layer
/// scales every force by (h_k-1 + h_k) / (2 h_k) and adds gravity's share ([`LayerConfig::gravity`]).
/// Without it, a step change during an impact creates or destroys energy (measured: +2 % at the
/// first step change of a 1.4 m/s drop).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepControl {
    /// Steps per elastic contact time.
    pub steps_per_contact: f64,
    /// Largest displacement of an apple in one step allowed by rapier's pair finding (m); the
    /// layer also keeps it within half its own grid skin.
    pub max_displacement_m: f64,
}

/// Settings of the layer.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerConfig {
    /// Which parts of the contact law are on.
    pub parts: LawParts,
    /// Bound of the rate-dependent forces as a fraction of the velocity-kill rate m_eff / dt,
    /// shared among an apple's contacts: the tangential dashpot (see [`crate::contact::friction`])
    /// and the rate part of eq. 12 (see [`crate::contact::damping::hysteresis_force`]). 0.5
    /// removes at most half the relative velocity per step, which keeps explicit stepping stable.
    pub tangential_relaxation: f64,
    /// Bound of LIGGGHTS's `tangential history` dashpot: gamma_t dt / m_t <= this / n for an
    /// apple with n contacts ([`crate::contact::HISTORY_DASHPOT_BOUND`], the default, says why).
    pub history_dashpot_bound: f64,
    /// Verlet skin of the apple-apple list as a fraction of the largest apple radius.
    pub grid_skin_ratio: f64,
    /// Samples of force history kept per contact (0: none); long contacts are decimated.
    pub force_history_cap: usize,
    /// Which part of each contact the force history covers (default the whole contact).
    pub force_history_span: crate::record::events::HistorySpan,
    /// Stability guard.
    pub guard: Guard,
    /// The collision group that marks apples; apple-apple pairs are excluded from rapier with it.
    pub apple_group: Group,
    /// Sleeping of apples at rest.
    pub sleep: SleepConfig,
    /// Gravity (m/s^2): the sleep rule checks that an apple's net force is small, and adaptive
    /// steps add its share of the leapfrog kick (see [`StepControl`]).
    pub gravity: Vec3,
    /// `true` leaves every contact to rapier (the `rigid` fidelity): the layer only keeps names.
    pub passive: bool,
    /// Step control for adaptive stepping (`None`: the driver's step is taken as it is).
    pub step_control: Option<StepControl>,
    /// Keep each step's slip of every evaluated contact ([`super::ContactLayer::slips`]) for the
    /// slip/roll detector (`sim::slip_roll`).
    pub record_slips: bool,
}

impl Default for LayerConfig {
    fn default() -> Self {
        Self {
            parts: LawParts::default(),
            tangential_relaxation: 0.5,
            history_dashpot_bound: crate::contact::HISTORY_DASHPOT_BOUND,
            grid_skin_ratio: 0.25,
            force_history_cap: 0,
            force_history_span: Default::default(),
            guard: Guard::default(),
            apple_group: Group::GROUP_32,
            sleep: SleepConfig::default(),
            gravity: Vec3::ZERO,
            passive: false,
            step_control: None,
            record_slips: false,
        }
    }
}

/// Registration options of a surface.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceOptions {
    /// Name used in records.
    pub name: String,
    /// Material.
    pub material: MaterialId,
    /// Geometry source.
    pub shape: SurfaceShape,
    /// Belt velocity in the collider's local frame (m/s): enters the friction slip; the
    /// collider itself does not move.
    pub belt_velocity_local: Vec3,
    /// Whether rapier's own contact handles this surface (no forces recorded).
    pub rigid: bool,
    /// A pad bonded on the surface (docs/physics.md section 13); `material` is then the
    /// substrate's.
    pub padding: Option<Padding>,
    /// A surface turned by its contacts (a free-turning roller), with the inverse mass of its
    /// surface point in the turning direction, R^2 / I (1/kg): the layer keeps the reaction
    /// forces on it for its owner to integrate ([`super::ContactLayer::surface_reactions`]) and
    /// counts that mass in its contacts' tangential effective mass (the friction dashpot's bound
    /// must stop the relative slip of the apple and the roller, not of the apple alone).
    pub turned_by_contacts: Option<f64>,
}

/// A pad of finite thickness bonded on a surface (see [`crate::contact::padding`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Padding {
    /// The pad's material.
    pub material: MaterialId,
    /// Its thickness (m).
    pub thickness_m: f64,
}

impl SurfaceOptions {
    /// A Hertz surface with the collider's own shape.
    pub fn hertz(name: &str, material: MaterialId) -> Self {
        Self {
            name: name.to_string(),
            material,
            shape: SurfaceShape::FromCollider,
            belt_velocity_local: Vec3::ZERO,
            rigid: false,
            padding: None,
            turned_by_contacts: None,
        }
    }
}

/// Contact coefficients of a pair of materials.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// Coulomb friction.
    pub friction: f64,
    /// Eq. 12 ke.
    pub ke: f64,
    /// Eq. 12 lambda (s/m).
    pub lambda_s_m: f64,
    /// Damping, tangential and rolling sub-models and their coefficients (default: the paper's).
    pub models: SubModels,
}

impl Coefficients {
    /// The paper's model with these friction, ke and lambda.
    pub fn paper(friction: f64, ke: f64, lambda_s_m: f64) -> Self {
        Self {
            friction,
            ke,
            lambda_s_m,
            models: SubModels::default(),
        }
    }
}
