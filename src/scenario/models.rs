//! The contact sub-models a scenario chooses, per pair of materials like friction (`contact` for
//! every pair, `pairs[]` to override one): the normal damping, the tangential force and the
//! rolling resistance (docs/physics.md section 11). Names as users of DEM codes know them; each
//! maps onto a sub-model of [`crate::contact`].

use crate::contact::{DampingModel, RollingModel, TangentialModel, TwistingModel};
use serde::{Deserialize, Serialize};

/// `damping`: how the normal force loses energy.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Damping {
    /// The paper's eq. 12 (`ke`, `lambda_s_m`); a resting contact carries (1 + ke) / 2 of the
    /// Hertz force.
    #[default]
    #[serde(rename = "eq12")]
    Eq12,
    /// Eq. 12 whose resting contact carries the full Hertz force (the same restitution).
    #[serde(rename = "eq12-elastic-rest")]
    Eq12ElasticRest,
    /// Viscoelastic Hertz as LIGGGHTS `model hertz` / EDEM Hertz-Mindlin, from `restitution`.
    #[serde(rename = "viscoelastic")]
    Viscoelastic,
}

impl Damping {
    /// The contact law's sub-model.
    pub fn model(self) -> DampingModel {
        match self {
            Damping::Eq12 => DampingModel::Eq12,
            Damping::Eq12ElasticRest => DampingModel::Eq12ElasticRest,
            Damping::Viscoelastic => DampingModel::Viscoelastic,
        }
    }

    /// Whether it needs `ke` and `lambda_s_m`.
    pub fn uses_eq12(self) -> bool {
        self != Damping::Viscoelastic
    }
}

/// `tangential`: the friction force's model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Tangential {
    /// applesim's Mindlin stick spring, bounded dashpot, Coulomb cap.
    #[default]
    #[serde(rename = "mindlin")]
    Mindlin,
    /// LIGGGHTS `tangential history`.
    #[serde(rename = "history")]
    History,
}

impl Tangential {
    /// The contact law's sub-model.
    pub fn model(self) -> TangentialModel {
        match self {
            Tangential::Mindlin => TangentialModel::Mindlin,
            Tangential::History => TangentialModel::History,
        }
    }
}

/// `rolling`: the rolling-resistance model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Rolling {
    /// None (the paper's model: an apple rolls on a flat for ever).
    #[serde(rename = "none")]
    None,
    /// A constant torque mu_r R* F_n against the rolling (LIGGGHTS `cdt`, EDEM type A).
    #[serde(rename = "constant-torque")]
    ConstantTorque,
    /// A torsion spring capped at mu_r R* F_n (LIGGGHTS `epsd2`): the default, so that apples
    /// ride belts, heap in bins and rest on gentle slopes without rocking.
    #[default]
    #[serde(rename = "elastic-plastic")]
    ElasticPlastic,
}

impl Rolling {
    /// The contact law's sub-model.
    pub fn model(self) -> RollingModel {
        match self {
            Rolling::None => RollingModel::None,
            Rolling::ConstantTorque => RollingModel::ConstantTorque,
            Rolling::ElasticPlastic => RollingModel::ElasticPlastic,
        }
    }
}

/// `twisting`: the twisting-resistance model (spin about the contact normal).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Twisting {
    /// None (the paper's model, and LIGGGHTS's and EDEM's default): an apple spinning about the
    /// vertical on a floor spins for ever.
    #[default]
    #[serde(rename = "none")]
    None,
    /// Coulomb friction over the Hertz contact patch, (3 pi / 16) mu a F_n against the spin
    /// (docs/physics.md section 11.8).
    #[serde(rename = "coulomb")]
    Coulomb,
}

impl Twisting {
    /// The contact law's sub-model.
    pub fn model(self) -> TwistingModel {
        match self {
            Twisting::None => TwistingModel::None,
            Twisting::Coulomb => TwistingModel::Coulomb,
        }
    }
}

/// Default coefficient of rolling friction: 0.03, the apple-apple value of a DEM calibration of
/// 'Luli' apples (0.032), rounded; the same study gives 0.029 and 0.017 for apples on high and
/// super-high density foam (docs/physics.md section 11, docs/materials.md).
pub const DEFAULT_ROLLING_FRICTION: f64 = 0.03;

/// Default damping ratio of the elastic-plastic rolling spring: 1, a critically damped spring
/// (the dashpot of LIGGGHTS `epsd`, C_r = eta_r 2 sqrt(I_r k_r), Ai et al. 2011, Powder
/// Technology 206, 269-282): a resting apple does not rock. Measured on a settled 27-apple pile
/// (sleeping off): largest displacement over 2-4 s 0.36 um at eta_r = 0.3, 23 nm at 1; over 4-6 s
/// 85 nm and 0.04 nm (docs/physics.md section 11).
pub const DEFAULT_ROLLING_DAMPING: f64 = 1.0;
