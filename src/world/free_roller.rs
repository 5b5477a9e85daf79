//! Free-turning rollers: a roller that no motor drives turns from the friction torques the
//! apples put on it, against its own moment of inertia and its bearing friction.
//!
//! The roller's body stays a rapier kinematic body posed from its [`Motion`] every step, like
//! every moving part (one body per surface spec, the layer reading the surface velocity from
//! it); its spin is a state of its own, and this module is its one owner: [`FreeRoller`] holds
//! the rate and the angle, [`super::World::advance`] asks it to turn them before it poses the
//! body. Each step, with the reaction forces F_c the layer's force pass put on the roller at the
//! contact points c (the opposite of what it applied to the apples, [`crate::layer::ContactLayer::surface_reactions`]):
//!
//! ```text
//! I dw/dt = sum_c ((c - o) x F_c) . n  -  T_b sign(w)        (o the roller's centre, n its axis)
//! ```
//!
//! integrated like the apples (symplectic Euler: the rate from this step's torque, then the
//! angle from the new rate), so the pose it gives the body at the end of the step moves the
//! roller's surface at w x r over it, the velocity rapier derives and the layer reads at the
//! next step. The bearing torque T_b is Coulomb friction: it slows the roller, never turns it
//! back, and holds it at rest while the apples' torque stays below it.
//!
//! A free roller may be carried (a `motion.translation`) but not swung (validation refuses a
//! `motion.rotation`): the spin is integrated about the axis direction it was given.
//! docs/physics.md section 12.5.

use super::motion::Motion;
use crate::layer::SurfaceId;
use crate::math::Vec3;
use serde::Serialize;
use std::sync::Arc;

/// A free-turning roller's spin (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct FreeRoller {
    /// The roller's name.
    pub name: String,
    /// Its surface in the layer.
    pub surface: SurfaceId,
    /// The name as written in `rollers.csv` each sample (shared, not copied per row).
    label: Arc<str>,
    /// Its axis (unit, world).
    axis: Vec3,
    /// Its radius (m): the surface speed of `rollers.csv` is the rate times it.
    radius_m: f64,
    /// Moment of inertia about the axis (kg m^2).
    inertia_kg_m2: f64,
    /// Bearing friction torque (N m).
    bearing_torque_n_m: f64,
    /// The JSON path of its moment of inertia, for a refusal of its spin
    /// (`surfaces[k].free_turning.moment_of_inertia_kg_m2`).
    field: String,
    /// Rate about the axis over the last step (rad/s; right-hand rule about the axis).
    rate_rad_s: f64,
    /// Angle turned since the start (rad).
    angle_rad: f64,
}

/// A free-turning roller's spin at one output sample: a row of `rollers.csv`
/// ([`crate::output::RollersCsv`]). A copy of the [`FreeRoller`]'s state, taken by the driver
/// when it samples the apples, so that the file's angles and rates are the run's own, at the
/// same times as `bodies.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct RollerSample {
    /// The roller's name as the contacts name it (a bed's rollers `BED/k`).
    pub name: Arc<str>,
    /// The angle turned since the start (rad; right-hand rule about the axis).
    pub angle_rad: f64,
    /// Its rate about its axis over the step that ended at the sample (rad/s).
    pub spin_rad_s: f64,
    /// The speed of its surface, rate times radius (m/s; signed as the rate).
    pub surface_speed_m_s: f64,
}

/// A free-turning roller whose spin ran away ([`FreeRoller::runaway`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RollerRunaway {
    /// The JSON path of its moment of inertia.
    pub field: String,
    /// The roller's name.
    pub roller: String,
    /// Its rate (rad/s).
    pub spin_rad_s: f64,
    /// Its surface speed (m/s).
    pub surface_speed_m_s: f64,
    /// Its moment of inertia (kg m^2).
    pub inertia_kg_m2: f64,
}

/// A free-turning roller's state at the end of a run (`summary.json`, `free_rollers`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FreeRollerState {
    /// The roller's name.
    pub name: String,
    /// Its rate about its axis (rad/s).
    pub angular_velocity_rad_s: f64,
    /// The angle it turned since the start (rad).
    pub angle_turned_rad: f64,
}

impl FreeRoller {
    /// A free roller on `surface` of the motion `m` (its spin axis and initial rate), with its
    /// radius, inertia and bearing torque (validated); `field` is the JSON path of its moment of
    /// inertia, named if its spin runs away ([`Self::runaway`]).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: &str,
        field: &str,
        surface: SurfaceId,
        m: &Motion,
        radius_m: f64,
        rate_rad_s: f64,
        inertia_kg_m2: f64,
        bearing_torque_n_m: f64,
    ) -> Self {
        Self {
            name: name.to_string(),
            label: Arc::from(name),
            surface,
            axis: m.spin_axis().unwrap_or(Vec3::X),
            radius_m,
            inertia_kg_m2,
            bearing_torque_n_m,
            field: field.to_string(),
            rate_rad_s,
            angle_rad: 0.0,
        }
    }

    /// Whether its spin ran away: a rate that is not finite, or a surface speed beyond the speed
    /// range of fruit handling (100 m/s; no apple of a valid scene turns a roller that fast).
    /// The explicit update of a roller too light for the step rings and grows without bound
    /// (docs/physics.md 12.5); the run is refused then rather than finished with it.
    pub fn runaway(&self) -> Option<RollerRunaway> {
        let speed = (self.rate_rad_s * self.radius_m).abs();
        (!(self.rate_rad_s.is_finite() && crate::scenario::ranges::SPEED.contains(speed))).then(
            || RollerRunaway {
                field: self.field.clone(),
                roller: self.name.clone(),
                spin_rad_s: self.rate_rad_s,
                surface_speed_m_s: speed,
                inertia_kg_m2: self.inertia_kg_m2,
            },
        )
    }

    /// The angle turned since the start (rad): the pose's spin angle.
    pub fn angle_rad(&self) -> f64 {
        self.angle_rad
    }

    /// Its state for the summary.
    pub fn state(&self) -> FreeRollerState {
        FreeRollerState {
            name: self.name.clone(),
            angular_velocity_rad_s: self.rate_rad_s,
            angle_turned_rad: self.angle_rad,
        }
    }

    /// Its spin now, for `rollers.csv` (see [`RollerSample`]).
    pub fn sample(&self) -> RollerSample {
        RollerSample {
            name: self.label.clone(),
            angle_rad: self.angle_rad,
            spin_rad_s: self.rate_rad_s,
            surface_speed_m_s: self.rate_rad_s * self.radius_m,
        }
    }

    /// The torque about the axis through `centre` of this roller's reactions (N m).
    pub fn torque_n_m(&self, reactions: &[(SurfaceId, Vec3, Vec3)], centre: Vec3) -> f64 {
        reactions
            .iter()
            .filter(|r| r.0 == self.surface)
            .map(|&(_, f, p)| (p - centre).cross(f).dot(self.axis))
            .sum()
    }

    /// One step of `dt_s` under the apples' torque `torque_n_m` (symplectic Euler: the rate,
    /// then the angle from the new rate), with the bearing's Coulomb torque against the turning.
    pub fn turn(&mut self, torque_n_m: f64, dt_s: f64) {
        let (w, tb, i) = (self.rate_rad_s, self.bearing_torque_n_m, self.inertia_kg_m2);
        self.rate_rad_s = if w != 0.0 {
            let next = w + (torque_n_m - tb * w.signum()) * dt_s / i;
            // The bearing stops the roller; it does not turn it back.
            if next * w < 0.0 && torque_n_m.abs() <= tb {
                0.0
            } else {
                next
            }
        } else if torque_n_m.abs() > tb {
            (torque_n_m - tb * torque_n_m.signum()) * dt_s / i
        } else {
            0.0
        };
        self.angle_rad += self.rate_rad_s * dt_s;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn roller(i: f64, tb: f64, w0: f64) -> FreeRoller {
        FreeRoller {
            name: "r".into(),
            label: Arc::from("r"),
            surface: SurfaceId(0),
            axis: Vec3::X,
            radius_m: 0.03,
            inertia_kg_m2: i,
            bearing_torque_n_m: tb,
            field: "surfaces[0].free_turning.moment_of_inertia_kg_m2".into(),
            rate_rad_s: w0,
            angle_rad: 0.0,
        }
    }

    #[test]
    fn the_bearing_stops_the_roller_and_holds_it() {
        let mut r = roller(2e-3, 1e-3, 1.0);
        // Decelerates at T/I = 0.5 rad/s^2: at rest after 2 s, then stays there.
        for _ in 0..1000 {
            r.turn(0.0, 1e-3);
        }
        assert!((r.rate_rad_s - 0.5).abs() < 1e-12);
        for _ in 0..2000 {
            r.turn(0.0, 1e-3);
        }
        assert_eq!(r.rate_rad_s, 0.0);
        // A torque below the bearing's does not start it; above, it does by the excess.
        r.turn(0.9e-3, 1e-3);
        assert_eq!(r.rate_rad_s, 0.0);
        r.turn(3e-3, 1e-3);
        assert!((r.rate_rad_s - 1e-3).abs() < 1e-15);
    }

    #[test]
    fn torque_about_the_axis_from_reactions() {
        let r = roller(1.0, 0.0, 0.0);
        let c = Vec3::new(0.0, 0.0, 1.0);
        // A force +y at the top (z = 1.03) of a roller about x through c: torque -0.03 F.
        let reactions = [
            (
                SurfaceId(0),
                Vec3::new(0.0, 2.0, 0.0),
                Vec3::new(0.0, 0.0, 1.03),
            ),
            (
                SurfaceId(1),
                Vec3::new(0.0, 5.0, 0.0),
                Vec3::new(0.0, 0.0, 1.03),
            ),
        ];
        assert!((r.torque_n_m(&reactions, c) + 0.06).abs() < 1e-12);
    }
}
