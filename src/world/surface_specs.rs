//! Surface specs into the world: each spec's moving body (a kinematic body for a moving part),
//! its colliders registered with the layer, and the free-turning rollers' spin
//! ([`super::free_roller`]). A roller bed is built as its rollers, one body each
//! ([`crate::scenario::SurfaceSpec::units`]).

use super::surfaces::{self, SurfacePart};
use super::{free_roller, motion, BuildError, World, HERTZ_SURFACE_GROUP};
use crate::layer::{SurfaceId, SurfaceOptions};
use crate::scenario::{self, ContactModel, Scenario};
use rapier3d_f64::prelude::*;
use std::path::Path;

impl World {
    /// Builds every surface of the scenario, in order.
    pub(super) fn add_surface_specs(
        &mut self,
        sc: &Scenario,
        base_dir: &Path,
    ) -> Result<(), BuildError> {
        // An apple material for rigid surfaces' coefficients: the first apple's, or any source's.
        let apple_material = sc
            .apples
            .first()
            .map(|a| a.material.clone())
            .or_else(|| sc.sources.first().map(|s| s.material.clone()));
        for (k, spec) in sc.surfaces.iter().enumerate() {
            let field = format!("surfaces[{k}]");
            for s in &spec.units() {
                self.add_unit(s, &field, base_dir, apple_material.as_deref())?;
            }
        }
        Ok(())
    }

    /// One surface spec that rides one body (a bed's roller, or any other spec).
    fn add_unit(
        &mut self,
        s: &scenario::SurfaceSpec,
        field: &str,
        base_dir: &Path,
        apple_material: Option<&str>,
    ) -> Result<(), BuildError> {
        {
            // A moving part rides a kinematic body placed at its pose at t = 0 (its colliders are
            // attached relative to the rest pose, where the scenario puts them, and follow it),
            // moving at its initial velocity (rapier derives the velocity from the poses only
            // once it steps). Placed at the rest pose instead, a part whose profile starts
            // displaced (a bin filler's bin, keyframed 0.2 m up at t = 0) jumped there in the
            // first step: tests/moving_parts.rs, `a_part_starts_at_its_pose_at_time_zero`.
            let mover = motion::Motion::of(s).map(|m| {
                let (lin, ang) = m.velocity(0.0);
                let body = RigidBodyBuilder::kinematic_position_based()
                    .pose(m.pose(0.0))
                    .linvel(lin)
                    .angvel(ang)
                    .build();
                (self.physics.bodies.insert(body), m)
            });
            for part in surfaces::parts(s, field, base_dir)? {
                let parent = mover.as_ref().map(|(b, m)| (*b, m.rest_pose()));
                self.add_surface(part, apple_material, parent)?;
            }
            if let Some((b, m)) = mover {
                // The farthest point of its colliders from the body's origin.
                let origin = m.pose(0.0).translation;
                let reach = self.physics.bodies[b]
                    .colliders()
                    .iter()
                    .filter_map(|&c| self.physics.colliders.get(c))
                    .map(|c| {
                        let bs = c.shape().compute_local_bounding_sphere();
                        (c.position() * bs.center - origin).length() + bs.radius
                    })
                    .filter(|r| r.is_finite())
                    .fold(0.0, f64::max);
                self.moving_speed_m_s = self.moving_speed_m_s.max(m.max_speed_m_s(reach));
                let free = match s {
                    scenario::SurfaceSpec::Roller(r) => r.free_turning.as_ref().map(|f| {
                        // Its one part is the last surface registered.
                        let id = SurfaceId(self.surface_colliders.len() as u32 - 1);
                        self.free_rollers.push(free_roller::FreeRoller::new(
                            &r.name,
                            &format!("{field}.free_turning.moment_of_inertia_kg_m2"),
                            id,
                            &m,
                            r.radius_m,
                            r.angular_velocity_rad_s,
                            f.moment_of_inertia_kg_m2,
                            f.bearing_torque_n_m,
                        ));
                        self.free_rollers.len() - 1
                    }),
                    _ => None,
                };
                self.movers.push((b, m, free));
            }
        }
        Ok(())
    }

    fn add_surface(
        &mut self,
        part: SurfacePart,
        apple_material: Option<&str>,
        parent: Option<(RigidBodyHandle, rapier3d_f64::math::Pose)>,
    ) -> Result<(), BuildError> {
        let (mid, _) = self.materials[&part.material];
        let rigid = part.model == ContactModel::Rigid || self.layer.config().passive;
        let mut collider = part.collider;
        let along = part.along;
        if rigid {
            // rapier's own response: friction and restitution of the apple-surface pair.
            let c = match apple_material {
                Some(am) => self.layer.coefficients(self.materials[am].0, mid),
                None => self.layer.coefficients(mid, mid),
            };
            collider = collider
                .friction(c.friction)
                .restitution(c.ke.sqrt())
                .friction_combine_rule(CoefficientCombineRule::Max)
                .restitution_combine_rule(CoefficientCombineRule::Max);
        }
        if !rigid {
            // Out of the way of the apple colliders of scenes that have them (the layer owns
            // these contacts), and out of rapier's broad phase altogether: nothing of rapier's
            // touches it (its parts are fixed or kinematic, the apples' balls skip its group), so
            // the box rapier would refresh for it at every step of a moving part bought nothing
            // (a roller's: six support points, 5 % of the 1000-apple line's busy steps). rapier
            // still poses a disabled collider with its body, and the layer reads its shape and
            // pose as before.
            collider = collider
                .collision_groups(InteractionGroups::new(
                    HERTZ_SURFACE_GROUP,
                    Group::ALL,
                    InteractionTestMode::And,
                ))
                .enabled(false);
        }
        let ch = match parent {
            Some((body, rest)) => {
                // Attached at its scenario pose relative to the body's rest pose, massless (the
                // body's centre of mass stays at its origin).
                let at = rest.inverse() * collider.position;
                collider = collider.position(at).density(0.0);
                let set = &mut self.physics;
                set.colliders
                    .insert_with_parent(collider, body, &mut set.bodies)
            }
            None => self.physics.colliders.insert(collider),
        };
        self.layer.add_surface(
            &mut self.physics.colliders,
            ch,
            SurfaceOptions {
                name: part.name,
                material: mid,
                shape: part.shape,
                belt_velocity_local: part.belt_local,
                rigid,
                padding: part.padding.as_ref().map(|(m, h)| crate::layer::Padding {
                    material: self.materials[m.as_str()].0,
                    thickness_m: *h,
                }),
                turned_by_contacts: part.turned_by_contacts,
            },
        )?;
        self.surface_colliders.push(ch);
        self.surface_frames.push(along);
        Ok(())
    }
}
