//! World building: a validated scenario becomes rapier bodies and colliders, registered with a
//! [`ContactLayer`].
//!
//! Integration settings follow rapier-notes.md: `num_solver_iterations = 1` makes rapier's step
//! exact symplectic Euler (the default 4 weights the force term by (N+1)/(2N) and gains energy);
//! CCD is off (contacts are resolved by the force law over many steps, never by CCD clamping);
//! apples never sleep in rapier's sense (forces are reset and re-added every step).

use crate::contact::Material;
use crate::layer::{
    Coefficients, ContactLayer, Guard, LayerConfig, LayerError, MaterialId, SurfaceOptions,
    SurfaceShape,
};
use crate::math::{vec3, Vec3};
use crate::scenario::{self, ContactModel, Scenario, ScenarioError, SurfaceSpec};
use rapier3d_f64::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;
use thiserror::Error;

/// Largest initial overlap of an apple with a surface, as a fraction of its radius: an apple may
/// be placed at its resting sag (about 0.3 % of R for the paper's apple), not deeper.
pub const MAX_INITIAL_SURFACE_OVERLAP_RATIO: f64 = 0.01;

/// Samples of force history kept per contact when the scenario asks for histories.
pub const FORCE_HISTORY_CAP: usize = 4096;

/// Errors while building the world.
#[derive(Debug, Error)]
pub enum BuildError {
    /// A scenario mistake found while building (it names the field).
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// A layer registration error.
    #[error(transparent)]
    Layer(#[from] LayerError),
}

/// The rapier world plus our layer, ready to step.
pub struct World {
    /// rapier's sets, pipeline and parameters.
    pub physics: PhysicsWorld,
    /// The contact layer.
    pub layer: ContactLayer,
    /// Rigid body of each apple, in scenario order.
    pub apple_bodies: Vec<RigidBodyHandle>,
    /// Collider of each surface, in scenario order.
    pub surface_colliders: Vec<ColliderHandle>,
}

/// Mass of a solid sphere of the given diameter and density.
pub fn sphere_mass(diameter_m: f64, density: f64) -> f64 {
    let r = diameter_m / 2.0;
    density * 4.0 / 3.0 * std::f64::consts::PI * r * r * r
}

/// Builds the world of a validated scenario. `_base_dir` is where relative asset paths (meshes)
/// are resolved.
pub fn build(sc: &Scenario, _base_dir: &Path) -> Result<World, BuildError> {
    let mut physics = PhysicsWorld::new();
    physics.gravity = vec3(sc.gravity_m_s2);
    let ip = &mut physics.integration_parameters;
    ip.dt = sc.time_step_s;
    ip.num_solver_iterations = 1;
    ip.max_ccd_substeps = 0;

    let config = LayerConfig {
        force_history_cap: if sc.output.force_history {
            FORCE_HISTORY_CAP
        } else {
            0
        },
        guard: Guard {
            max_overlap_ratio: sc.model.max_overlap_ratio,
            min_steps_per_impact: sc.model.min_steps_per_impact,
        },
        ..LayerConfig::default()
    };
    let mut layer = ContactLayer::new(config);
    let mut mat_ids: BTreeMap<&str, (MaterialId, Material)> = BTreeMap::new();
    for (name, spec) in &sc.materials {
        let m = scenario::validate::material(name, spec)?;
        mat_ids.insert(name.as_str(), (layer.add_material(name, m), m));
    }
    layer.set_default_coefficients(sc.contact.friction, sc.contact.ke, sc.contact.lambda_s_m);
    for p in &sc.pairs {
        let a = mat_ids[p.materials[0].as_str()].0;
        let b = mat_ids[p.materials[1].as_str()].0;
        layer.set_pair_coefficients(
            a,
            b,
            Coefficients {
                friction: p.friction.unwrap_or(sc.contact.friction),
                ke: p.ke.unwrap_or(sc.contact.ke),
                lambda_s_m: p.lambda_s_m.unwrap_or(sc.contact.lambda_s_m),
            },
        );
    }

    let mut apple_bodies = Vec::with_capacity(sc.apples.len());
    for a in &sc.apples {
        let (mid, m) = mat_ids[a.material.as_str()];
        let mass = a
            .mass_kg
            .unwrap_or_else(|| sphere_mass(a.diameter_m, m.density_kg_m3.unwrap_or(0.0)));
        let (bh, ch) = physics.insert(
            RigidBodyBuilder::dynamic()
                .translation(vec3(a.position_m))
                .linvel(vec3(a.velocity_m_s))
                .angvel(vec3(a.angular_velocity_rad_s))
                .can_sleep(false),
            ColliderBuilder::ball(a.diameter_m / 2.0)
                .mass(mass)
                .friction(0.0)
                .restitution(0.0),
        );
        layer.add_apple(&mut physics.colliders, ch, mid, &a.name)?;
        apple_bodies.push(bh);
    }

    let mut surface_colliders = Vec::with_capacity(sc.surfaces.len());
    for s in &sc.surfaces {
        let (collider, material, model, shape, belt) = match s {
            SurfaceSpec::Plane(p) => (
                ColliderBuilder::new(SharedShape::halfspace(vec3(p.normal)))
                    .translation(vec3(p.point_m)),
                p.material.as_str(),
                p.contact_model,
                SurfaceShape::FromCollider,
                Vec3::ZERO,
            ),
        };
        let (mid, _) = mat_ids[material];
        let rigid = model == ContactModel::Rigid;
        let mut collider = collider;
        if rigid {
            // rapier's own response: friction and restitution of the apple-surface pair.
            let apple_mat = sc.apples.first().map(|a| mat_ids[a.material.as_str()].0);
            let c = apple_mat
                .map(|am| layer.coefficients(am, mid))
                .unwrap_or(Coefficients {
                    friction: sc.contact.friction,
                    ke: sc.contact.ke,
                    lambda_s_m: sc.contact.lambda_s_m,
                });
            collider = collider
                .friction(c.friction)
                .restitution(c.ke.sqrt())
                .friction_combine_rule(CoefficientCombineRule::Max)
                .restitution_combine_rule(CoefficientCombineRule::Max);
        }
        let ch = physics.colliders.insert(collider);
        layer.add_surface(
            &mut physics.colliders,
            ch,
            SurfaceOptions {
                name: s.name().to_string(),
                material: mid,
                shape,
                belt_velocity_local: belt,
                rigid,
            },
        )?;
        surface_colliders.push(ch);
    }
    layer.check_conformity()?;
    check_initial_surface_overlaps(sc, &physics, &layer, &surface_colliders)?;

    // A step of length zero runs rapier's collision detection only, so the pairs touching at
    // t = 0 are known before the first force pass.
    let dt = physics.integration_parameters.dt;
    physics.integration_parameters.dt = 0.0;
    physics.step_with_events(layer.hooks(), &());
    physics.integration_parameters.dt = dt;

    Ok(World {
        physics,
        layer,
        apple_bodies,
        surface_colliders,
    })
}

fn check_initial_surface_overlaps(
    sc: &Scenario,
    physics: &PhysicsWorld,
    layer: &ContactLayer,
    surfaces: &[ColliderHandle],
) -> Result<(), ScenarioError> {
    let mut hits = Vec::new();
    for (k, a) in sc.apples.iter().enumerate() {
        let r = a.diameter_m / 2.0;
        for (s, &ch) in surfaces.iter().enumerate() {
            let Some(co) = physics.colliders.get(ch) else {
                continue;
            };
            hits.clear();
            let shape = layer_surface_shape(layer, s);
            crate::layer::surface::surface_hits(&shape, co, vec3(a.position_m), r, 0.0, &mut hits);
            if let Some(h) = hits
                .iter()
                .find(|h| h.overlap_m > MAX_INITIAL_SURFACE_OVERLAP_RATIO * r)
            {
                return Err(ScenarioError::invalid(
                    format!("apples[{k}].position_m"),
                    format!(
                        "apple '{}' starts {:.4} mm inside surface '{}' (more than {} % of its radius): place it on or above the surface",
                        a.name,
                        h.overlap_m * 1e3,
                        sc.surfaces[s].name(),
                        MAX_INITIAL_SURFACE_OVERLAP_RATIO * 100.0
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn layer_surface_shape(layer: &ContactLayer, s: usize) -> SurfaceShape {
    layer.surface_shape(crate::layer::SurfaceId(s as u32)).clone()
}
