//! Moving parts: a surface with a prescribed motion (`motion`, or a roller's own turning) rides a
//! rapier kinematic position-based body. Before every step the driver gives each such body its
//! pose at the end of the step ([`super::World::advance`]); rapier derives the body's velocity
//! from the two poses (`RigidBodyPosition::interpolate_velocity`), so the velocity the layer reads
//! ([`crate::layer`]'s surface velocity field, at the contact point) is the prescribed one over
//! that step: exact for constant rates, the mean over the step between keyframes.
//!
//! The body's pose at time t is B(t) = T(d(t)) R_p(theta(t)) T(c) S(w t): the roller's own turn
//! S about its axis through the body origin c (a roller's centre, else the origin), then the
//! rotation R_p about the motion's axis through its point p, then the translation d. At t = 0
//! with every offset zero B is T(c): the colliders are attached at their scenario poses relative
//! to it. The body's colliders have no mass (density 0), so its centre of mass is its origin and
//! rapier's linear velocity is that of the origin.

use crate::math::{vec3, Vec3};
use crate::scenario::motion::{unit_axis, MotionSpec};
use crate::scenario::SurfaceSpec;
use rapier3d_f64::math::{Pose, Rotation};

/// A scalar profile: a constant rate, or keyframes with linear interpolation.
#[derive(Debug, Clone, PartialEq)]
enum Scalar {
    Rate(f64),
    Keys(Vec<(f64, f64)>),
}

/// A vector profile: a constant velocity, or keyframed offsets.
#[derive(Debug, Clone, PartialEq)]
enum Offset {
    Velocity(Vec3),
    Keys(Vec<(f64, Vec3)>),
}

/// Piecewise-linear interpolation of keyframes (held before the first and after the last), and
/// its slope (the right-hand slope at a keyframe).
fn lerp<T>(keys: &[(f64, T)], t: f64) -> (T, T)
where
    T: Copy
        + std::ops::Sub<Output = T>
        + std::ops::Add<Output = T>
        + std::ops::Mul<f64, Output = T>,
{
    let zero = keys[0].1 * 0.0;
    if t < keys[0].0 {
        return (keys[0].1, zero);
    }
    let i = keys.partition_point(|k| k.0 <= t);
    if i >= keys.len() {
        return (keys[keys.len() - 1].1, zero);
    }
    let (t0, x0) = keys[i - 1];
    let (t1, x1) = keys[i];
    let slope = (x1 - x0) * (1.0 / (t1 - t0));
    (x0 + slope * (t - t0), slope)
}

impl Scalar {
    fn at(&self, t: f64) -> (f64, f64) {
        match self {
            Scalar::Rate(w) => (w * t, *w),
            Scalar::Keys(k) => lerp(k, t),
        }
    }
}

impl Offset {
    fn at(&self, t: f64) -> (Vec3, Vec3) {
        match self {
            Offset::Velocity(v) => (*v * t, *v),
            Offset::Keys(k) => lerp(k, t),
        }
    }
}

/// The compiled motion of one surface spec (validated).
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// Body origin at t = 0 (a roller's centre).
    origin: Vec3,
    /// The roller's own turn: axis (world, at t = 0) and rate (rad/s).
    spin: Option<(Vec3, f64)>,
    /// Rotation about an axis through a point: axis, point, angle profile (rad).
    turn: Option<(Vec3, Vec3, Scalar)>,
    /// Translation profile.
    shift: Option<Offset>,
}

impl Motion {
    /// The motion of a surface spec, or `None` for a fixed surface (a roller at rate 0 without a
    /// `motion` is fixed).
    pub fn of(s: &SurfaceSpec) -> Option<Motion> {
        let (origin, spin) = match s {
            SurfaceSpec::Roller(r)
                if r.angular_velocity_rad_s != 0.0 || r.free_turning.is_some() =>
            {
                let axis = vec3(unit_axis("axis", r.axis).ok()?);
                (vec3(r.position_m), Some((axis, r.angular_velocity_rad_s)))
            }
            SurfaceSpec::Roller(r) => (vec3(r.position_m), None),
            _ => (Vec3::ZERO, None),
        };
        let m: Option<&MotionSpec> = s.motion();
        if spin.is_none() && m.is_none() {
            return None;
        }
        Some(Self::compile(origin, spin, m))
    }

    /// The motion of a source (`sources[k].motion`), or `None` for a fixed source: a body
    /// whose origin is the world's origin, so that its pose at time t is the rigid move that
    /// carries the source's points from where the scenario places them ([`Motion::spawn`]).
    pub fn of_source(m: Option<&MotionSpec>) -> Option<Motion> {
        m.map(|m| Self::compile(Vec3::ZERO, None, Some(m)))
    }

    /// A validated motion spec on a body with origin `origin` and a roller's own turn `spin`.
    fn compile(origin: Vec3, spin: Option<(Vec3, f64)>, m: Option<&MotionSpec>) -> Motion {
        let turn = m.and_then(|m| m.rotation.as_ref()).and_then(|r| {
            let axis = vec3(unit_axis("axis", r.axis).ok()?);
            let profile = match (&r.angular_velocity_rad_s, &r.keyframes) {
                (Some(w), _) => Scalar::Rate(*w),
                (None, Some(k)) => {
                    Scalar::Keys(k.iter().map(|&(t, a)| (t, a.to_radians())).collect())
                }
                _ => return None,
            };
            Some((axis, vec3(r.point_m), profile))
        });
        let shift = m.and_then(|m| m.translation.as_ref()).and_then(|t| {
            Some(match (&t.velocity_m_s, &t.keyframes) {
                (Some(v), _) => Offset::Velocity(vec3(*v)),
                (None, Some(k)) => Offset::Keys(k.iter().map(|&(t, x)| (t, vec3(x))).collect()),
                _ => return None,
            })
        });
        Motion {
            origin,
            spin,
            turn,
            shift,
        }
    }

    /// Where a point placed at `p_rest` (where the scenario puts it) on a body with this motion
    /// is at `t_s`, and the velocity it has there when it moves at `v_rest` relative to the body
    /// as placed: `carry(t) p_rest`, and `v_rest` turned with the body plus the body's velocity
    /// at that point, v(t) + w(t) x (p - origin(t)) (right-hand slopes at keyframes, as
    /// [`Motion::velocity`]). A moving source's apple appears so (issue 31): a fill head lowered
    /// at 13 mm/s drops its apples with 13 mm/s more, a turning arm throws them with its tip's
    /// speed. A roller's own turn is left out (a roller is round; sources have none).
    pub fn spawn(&self, t_s: f64, p_rest: Vec3, v_rest: Vec3) -> (Vec3, Vec3) {
        let carry = self.carry(t_s);
        let p = carry.transform_point(p_rest);
        let (lin, ang) = self.velocity(t_s);
        let origin = self.pose(t_s).translation;
        (p, carry.rotation * v_rest + lin + ang.cross(p - origin))
    }

    /// The body's pose at t = 0 with every offset zero: where the colliders are attached.
    pub fn rest_pose(&self) -> Pose {
        Pose::from_translation(self.origin)
    }

    /// The body's pose at time `t_s`.
    pub fn pose(&self, t_s: f64) -> Pose {
        let angle = self.spin.map_or(0.0, |(_, w)| w * t_s);
        self.pose_spun(t_s, angle)
    }

    /// The body's pose at time `t_s` with the roller turned by `spin_angle` (rad) about its own
    /// axis: a free-turning roller's angle is its own state ([`super::free_roller`]), not w t.
    pub fn pose_spun(&self, t_s: f64, spin_angle: f64) -> Pose {
        let mut pose = Pose::from_translation(self.origin);
        if let Some((axis, _)) = self.spin {
            pose *= Pose::from_rotation(Rotation::from_axis_angle(axis, spin_angle));
        }
        if let Some((axis, point, profile)) = &self.turn {
            let (angle, _) = profile.at(t_s);
            let r = Pose::from_translation(*point)
                * Pose::from_rotation(Rotation::from_axis_angle(*axis, angle))
                * Pose::from_translation(-*point);
            pose = r * pose;
        }
        if let Some(shift) = &self.shift {
            let (d, _) = shift.at(t_s);
            pose = Pose::from_translation(d) * pose;
        }
        pose
    }

    /// The rigid move that takes a part from where the scenario puts it (the rest pose) to where
    /// its body carries it at `t_s`, without a roller's own turn: `pose_spun(t_s, 0) *
    /// rest_pose()^-1`, the same for every part of the body. The viewer ([`crate::view`]) takes
    /// the scene's extent over the frames with it (a roller is round: its turn does not widen it).
    pub fn carry(&self, t_s: f64) -> Pose {
        self.pose_spun(t_s, 0.0) * self.rest_pose().inverse()
    }

    /// Velocity of the body's origin and its angular velocity at `t_s` (right-hand slopes at
    /// keyframes): the velocity the body starts with, before rapier derives it from the poses.
    pub fn velocity(&self, t_s: f64) -> (Vec3, Vec3) {
        let pose = self.pose(t_s);
        let mut lin = Vec3::ZERO;
        let mut ang = Vec3::ZERO;
        if let Some((axis, w)) = self.spin {
            // The spin axis turned by the motion's rotation.
            let turned = match &self.turn {
                Some((a, _, p)) => Rotation::from_axis_angle(*a, p.at(t_s).0) * axis,
                None => axis,
            };
            ang += turned * w;
        }
        let d = self.shift.as_ref().map_or(Vec3::ZERO, |s| s.at(t_s).0);
        if let Some((axis, point, profile)) = &self.turn {
            let w = *axis * profile.at(t_s).1;
            ang += w;
            lin += w.cross(pose.translation - (*point + d));
        }
        if let Some(shift) = &self.shift {
            lin += shift.at(t_s).1;
        }
        (lin, ang)
    }

    /// Whether the motion carries the part anywhere (a rotation or a translation), not only turns
    /// a roller about its own axis: a roller that only turns keeps its place and, being round,
    /// its look, so the ParaView output draws it with the fixed surfaces ([`crate::output::vtk`]).
    pub fn displaces(&self) -> bool {
        self.turn.is_some() || self.shift.is_some()
    }

    /// The roller's own axis at t = 0 (world), if it turns about one.
    pub fn spin_axis(&self) -> Option<Vec3> {
        self.spin.map(|(a, _)| a)
    }

    /// The largest speed of a point within `reach` of the body's origin over the whole profile
    /// (m/s): bounds the approach speed of a moving part for the time step.
    pub fn max_speed_m_s(&self, reach: f64) -> f64 {
        let max_rate = |p: &Scalar| match p {
            Scalar::Rate(w) => w.abs(),
            Scalar::Keys(k) => k
                .windows(2)
                .map(|w| ((w[1].1 - w[0].1) / (w[1].0 - w[0].0)).abs())
                .fold(0.0, f64::max),
        };
        let mut v = 0.0;
        if let Some((_, w)) = self.spin {
            v += w.abs() * reach;
        }
        if let Some((_, point, p)) = &self.turn {
            v += max_rate(p) * ((self.origin - *point).length() + reach);
        }
        if let Some(s) = &self.shift {
            v += match s {
                Offset::Velocity(u) => u.length(),
                Offset::Keys(k) => k
                    .windows(2)
                    .map(|w| (w[1].1 - w[0].1).length() / (w[1].0 - w[0].0))
                    .fold(0.0, f64::max),
            };
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn roller(json: &str) -> SurfaceSpec {
        serde_json::from_str(json).unwrap()
    }

    #[test]
    fn keyframes_interpolate_and_hold() {
        let k = vec![(1.0, 0.0), (2.0, 4.0), (4.0, 0.0)];
        assert_eq!(lerp(&k, 0.5), (0.0, 0.0));
        assert_eq!(lerp(&k, 1.5), (2.0, 4.0));
        assert_eq!(lerp(&k, 2.0), (4.0, -2.0));
        assert_eq!(lerp(&k, 3.0), (2.0, -2.0));
        assert_eq!(lerp(&k, 5.0), (0.0, 0.0));
    }

    #[test]
    fn a_roller_turns_in_place_and_a_swing_moves_its_origin() {
        let s = roller(
            r#"{"type": "roller", "name": "r", "material": "m", "radius_m": 0.03, "length_m": 0.5,
                "position_m": [1, 2, 3], "axis": [1, 0, 0], "angular_velocity_rad_s": 10}"#,
        );
        let m = Motion::of(&s).unwrap();
        let p = m.pose(0.1);
        assert_eq!(p.translation, Vec3::new(1.0, 2.0, 3.0));
        assert!(
            (p.rotation * Vec3::Y - Vec3::new(0.0, 1.0f64.cos(), 1.0f64.sin())).length() < 1e-15
        );
        let (lin, ang) = m.velocity(0.1);
        assert_eq!(lin, Vec3::ZERO);
        assert_eq!(ang, Vec3::new(10.0, 0.0, 0.0));
        let s = roller(
            r#"{"type": "box", "name": "b", "material": "m", "size_m": [1, 1, 1],
                "position_m": [0, 0, 0],
                "motion": {"rotation": {"axis": [0, 0, 2], "point_m": [1, 0, 0],
                                        "angular_velocity_rad_s": 2},
                           "translation": {"velocity_m_s": [0, 0, 1]}}}"#,
        );
        let m = Motion::of(&s).unwrap();
        // The origin swings about (1, 0, 0) at 2 rad/s and rises at 1 m/s.
        let t = 0.25;
        let p = m.pose(t);
        let want = Vec3::new(1.0 - (2.0 * t).cos(), -(2.0 * t).sin(), t);
        assert!((p.translation - want).length() < 1e-15);
        let (lin, ang) = m.velocity(t);
        assert!((ang - Vec3::new(0.0, 0.0, 2.0)).length() < 1e-15);
        let want_v = Vec3::new(2.0 * (2.0 * t).sin(), -2.0 * (2.0 * t).cos(), 1.0);
        assert!((lin - want_v).length() < 1e-14);
    }
}
