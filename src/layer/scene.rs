//! The surfaces as the layer sees them this step: each surface's pose and motion, read from
//! rapier once per step (the few surfaces, not every contact, go to rapier's sets), and what
//! changed since the last step (a moved or removed surface wakes the sleepers near it).

use super::registry::SurfaceEntry;
use super::surface::{self, SurfaceHit, SurfaceShape};
use crate::math::Vec3;
use rapier3d_f64::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d_f64::geometry::ColliderSet;
use rapier3d_f64::math::Pose;

/// One surface this step.
#[derive(Debug, Clone)]
pub(super) struct SurfaceNow {
    /// The collider still exists.
    pub exists: bool,
    /// Its pose at the last step (change detection).
    pub pose: Pose,
    /// Its pose at the last rebuild of the candidate lists (how far it may have moved since).
    pub pose_at_build: Pose,
    /// Radius of a sphere around the collider's origin containing its shape (m; infinite for a
    /// half-space): bounds how far a rotation moves its points.
    pub extent_m: f64,
    /// Moved or removed since the last step: wakes the sleepers near it.
    pub changed: bool,
    /// A cylinder: turning about its own axis (a powered roller) moves its material, not its
    /// shape, so that alone neither wakes sleepers nor rebuilds the candidate lists.
    pub axisymmetric: bool,
    /// A cylinder's radius (m): its side contacts are elliptical (their true area is set from
    /// it, see `kernel`).
    pub cylinder_radius_m: Option<f64>,
    /// The parent body is not fixed, or the surface is a running belt: apples on it stay awake.
    pub moving: bool,
    /// Velocity field of the parent body: linear velocity, angular velocity, centre of mass.
    pub lin: Vec3,
    pub ang: Vec3,
    pub com: Vec3,
    /// Inverse mass of a dynamic parent (0 for fixed or kinematic ones).
    pub inv_mass: f64,
    /// A dynamic parent receives the reaction forces.
    pub dynamic_body: Option<RigidBodyHandle>,
    /// Belt velocity in world axes (m/s).
    pub belt: Vec3,
    /// A plane (a half-space collider with the collider's own shape): its world normal and
    /// n . point, so that its contacts need no shape dispatch.
    pub plane: Option<(Vec3, f64)>,
}

/// What a look at one surface found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Seen {
    /// Nothing changed that matters to the candidate lists.
    Same,
    /// It moved or vanished since the last step (sleepers near it must wake).
    Changed,
}

impl SurfaceNow {
    pub fn new() -> Self {
        Self {
            exists: false,
            pose: Pose::IDENTITY,
            pose_at_build: Pose::IDENTITY,
            extent_m: f64::INFINITY,
            changed: false,
            axisymmetric: false,
            cylinder_radius_m: None,
            moving: false,
            lin: Vec3::ZERO,
            ang: Vec3::ZERO,
            com: Vec3::ZERO,
            inv_mass: 0.0,
            dynamic_body: None,
            belt: Vec3::ZERO,
            plane: None,
        }
    }

    /// Velocity of the surface's material point at `p` (belt excluded).
    #[inline]
    pub fn velocity_at(&self, p: Vec3) -> Vec3 {
        self.lin + self.ang.cross(p - self.com)
    }

    /// A running belt on a body that does not move: the one velocity of its material everywhere
    /// (an apple at rest on it may ride it, `super::sleep`); `None` for any other surface.
    #[inline]
    pub fn running_belt(&self) -> Option<Vec3> {
        (self.belt != Vec3::ZERO && self.lin == Vec3::ZERO && self.ang == Vec3::ZERO)
            .then_some(self.belt)
    }

    /// Whether it still carries a rider at `velocity`: it exists, did not change this step, and
    /// runs as a belt at that velocity.
    pub fn carries(&self, velocity: Vec3) -> bool {
        self.exists && !self.changed && self.running_belt() == Some(velocity)
    }

    /// Reads the surface's pose and motion. Returns what changed and whether the candidate lists
    /// must be rebuilt (it appeared, vanished, or moved by more than `half_skin` since the last
    /// rebuild).
    pub fn observe(
        &mut self,
        surf: &SurfaceEntry,
        bodies: &RigidBodySet,
        colliders: &ColliderSet,
        half_skin: f64,
    ) -> (Seen, bool) {
        self.changed = false;
        let mut rebuild = false;
        let Some(co) = colliders.get(surf.collider) else {
            if self.exists {
                self.exists = false;
                self.changed = true;
                return (Seen::Changed, true);
            }
            return (Seen::Same, false);
        };
        let pose = *co.position();
        if !self.exists {
            self.exists = true;
            self.pose = pose;
            self.pose_at_build = pose;
            let bs = co.shape().compute_local_bounding_sphere();
            let extent = bs.center.length() + bs.radius;
            self.extent_m = if extent.is_finite() && extent < 1e12 {
                extent
            } else {
                f64::INFINITY
            };
            self.cylinder_radius_m = co.shape().as_cylinder().map(|c| c.radius);
            self.axisymmetric = self.cylinder_radius_m.is_some();
            rebuild = true;
        } else if pose != self.pose {
            // A roller spinning in place: the same shape (to rounding: its pose is recomputed
            // from the time every step).
            let spun_only = self.axisymmetric
                && moved_by(&self.pose, &pose, self.extent_m, true) <= 1e-12 * self.extent_m;
            self.pose = pose;
            self.changed = !spun_only;
            if moved_by(&self.pose_at_build, &pose, self.extent_m, self.axisymmetric) > half_skin {
                rebuild = true;
            }
        }
        let parent = co.parent().and_then(|p| bodies.get(p).map(|rb| (p, rb)));
        match parent {
            Some((p, rb)) if !rb.is_fixed() => {
                self.moving = true;
                self.lin = rb.linvel();
                self.ang = rb.angvel();
                self.com = rb.center_of_mass();
                self.inv_mass = if rb.is_dynamic() && rb.mass() > 0.0 {
                    1.0 / rb.mass()
                } else {
                    0.0
                };
                self.dynamic_body = rb.is_dynamic().then_some(p);
            }
            _ => {
                self.moving = false;
                self.lin = Vec3::ZERO;
                self.ang = Vec3::ZERO;
                self.com = Vec3::ZERO;
                self.inv_mass = 0.0;
                self.dynamic_body = None;
            }
        }
        self.belt = pose.rotation * surf.belt_local;
        self.plane = match (&surf.shape, co.shape().as_halfspace()) {
            (SurfaceShape::FromCollider, Some(hs)) => {
                let n = pose.rotation * hs.normal;
                Some((n, n.dot(pose.translation)))
            }
            _ => None,
        };
        if surf.belt_local != Vec3::ZERO {
            self.moving = true;
        }
        let seen = if self.changed {
            Seen::Changed
        } else {
            Seen::Same
        };
        (seen, rebuild)
    }

    /// The fastest any point of its shape moves (m/s): its body's velocity and the turn of its
    /// shape (a cylinder's spin about its own axis moves its material, not its shape; a
    /// half-space counts its translation only). 0 for a fixed surface (a belt moves its material
    /// only).
    pub fn shape_speed_m_s(&self) -> f64 {
        if !self.exists || (self.lin == Vec3::ZERO && self.ang == Vec3::ZERO) {
            return 0.0;
        }
        let ang = if self.axisymmetric {
            let axis = self.pose.rotation * Vec3::Y;
            self.ang - axis * self.ang.dot(axis)
        } else {
            self.ang
        };
        let reach = (self.pose.translation - self.com).length() + self.extent_m;
        let turn = if reach.is_finite() {
            ang.length() * reach
        } else {
            0.0
        };
        self.lin.length() + turn
    }

    /// The hits of an apple (centre, radius) with this surface, keeping those whose overlap
    /// exceeds -margin (see [`surface::surface_hits`]); planes without the shape dispatch
    /// ([`crate::contact::geometry::sphere_plane`]).
    pub fn hits(
        &self,
        surf: &SurfaceEntry,
        colliders: &ColliderSet,
        centre: Vec3,
        radius: f64,
        margin: f64,
        out: &mut Vec<SurfaceHit>,
    ) {
        if let Some((n, d)) = self.plane {
            let u = crate::contact::geometry::sphere_plane(centre, radius, n, d);
            if u > -margin {
                out.push(SurfaceHit {
                    normal: n,
                    overlap_m: u,
                    curvature_1_m: 0.0,
                });
            }
        } else if let Some(co) = colliders.get(surf.collider) {
            surface::surface_hits(&surf.shape, co, centre, radius, margin, out);
        }
    }
}

/// Largest displacement of a point of a shape within `extent` of its origin when its pose goes
/// from `a` to `b` (m). For a shape symmetric about its local y axis (a cylinder) only the turn
/// of that axis counts.
fn moved_by(a: &Pose, b: &Pose, extent: f64, axisymmetric: bool) -> f64 {
    let shift = (b.translation - a.translation).length();
    let angle = if axisymmetric {
        let (ya, yb) = (a.rotation * Vec3::Y, b.rotation * Vec3::Y);
        // atan2 of |cross| and dot: accurate for small angles, unlike acos.
        ya.cross(yb).length().atan2(ya.dot(yb))
    } else {
        a.rotation.angle_between(b.rotation)
    };
    if angle == 0.0 {
        shift
    } else {
        shift + angle * extent
    }
}
