//! Surface specs become rapier colliders (one per wall for a bin) with the information the layer
//! needs: material, contact geometry, belt velocity, contact model.

use super::mesh;
use crate::layer::SurfaceShape;
use crate::math::{vec3, Vec3};
use crate::scenario::surfaces::{rotation_of, ChuteProfile, ContactModel, SurfaceSpec};
use crate::scenario::ScenarioError;
use rapier3d_f64::math::{Pose, Rotation};
use rapier3d_f64::prelude::*;
use std::path::Path;

/// Default plate thickness of chutes and bins (m).
pub const DEFAULT_THICKNESS_M: f64 = 0.01;

/// Facets of the collider that stands for a trough in rapier's broad phase (and in pictures);
/// the contact geometry itself is the exact cylinder.
pub const TROUGH_SEGMENTS: usize = 32;

/// One collider of a surface.
pub struct SurfacePart {
    /// Name in the results (`BIN/floor` for a bin's wall).
    pub name: String,
    /// Material name.
    pub material: String,
    /// The rapier collider.
    pub collider: ColliderBuilder,
    /// How the layer computes contacts with it.
    pub shape: SurfaceShape,
    /// Belt velocity in the collider's local frame (m/s).
    pub belt_local: Vec3,
    /// Contact model.
    pub model: ContactModel,
    /// The frame in which positions along the part are measured (transitions' `along_m`): +x
    /// runs along it from its start (a belt's upstream end, a chute's top end, a box's -x
    /// end). `None` for parts without a running direction (planes, bin walls, meshes).
    pub along: Option<Pose>,
    /// A pad bonded on it: its material's name and thickness (m).
    pub padding: Option<(String, f64)>,
    /// A free-turning roller: R^2 / I of its surface point (1/kg; see
    /// [`crate::layer::SurfaceOptions::turned_by_contacts`]).
    pub turned_by_contacts: Option<f64>,
}

fn part(name: &str, material: &str, collider: ColliderBuilder, model: ContactModel) -> SurfacePart {
    SurfacePart {
        name: name.to_string(),
        material: material.to_string(),
        shape: SurfaceShape::FromCollider,
        belt_local: Vec3::ZERO,
        along: None,
        collider,
        model,
        padding: None,
        turned_by_contacts: None,
    }
}

fn cuboid(size: [f64; 3], pose: Pose) -> ColliderBuilder {
    ColliderBuilder::cuboid(size[0] / 2.0, size[1] / 2.0, size[2] / 2.0).position(pose)
}

/// The colliders of one surface spec. `field` is its JSON path, `base_dir` resolves mesh files.
pub fn parts(
    s: &SurfaceSpec,
    field: &str,
    base_dir: &Path,
) -> Result<Vec<SurfacePart>, ScenarioError> {
    let mut parts = parts_without_padding(s, field, base_dir)?;
    if let Some(p) = s.padding() {
        for part in &mut parts {
            part.padding = Some((p.material.clone(), p.thickness_m));
        }
    }
    Ok(parts)
}

fn parts_without_padding(
    s: &SurfaceSpec,
    field: &str,
    base_dir: &Path,
) -> Result<Vec<SurfacePart>, ScenarioError> {
    Ok(match s {
        SurfaceSpec::Plane(p) => vec![part(
            &p.name,
            &p.material,
            ColliderBuilder::new(SharedShape::halfspace(vec3(p.normal)))
                .translation(vec3(p.point_m)),
            p.contact_model,
        )],
        SurfaceSpec::Box(b) => {
            let pose = Pose::from_parts(vec3(b.position_m), rotation_of(&b.rotation, field)?);
            let mut p = part(
                &b.name,
                &b.material,
                cuboid(b.size_m, pose),
                b.contact_model,
            );
            p.along = Some(pose * Pose::from_translation(Vec3::new(-b.size_m[0] / 2.0, 0.0, 0.0)));
            vec![p]
        }
        SurfaceSpec::Conveyor(b) => {
            let pose = Pose::from_parts(vec3(b.position_m), rotation_of(&b.rotation, field)?);
            let mut p = part(
                &b.name,
                &b.material,
                cuboid(b.size_m, pose),
                b.contact_model,
            );
            p.belt_local = Vec3::new(b.belt_velocity_m_s, 0.0, 0.0);
            // Along the belt's travel from its upstream end.
            let half = b.size_m[0] / 2.0;
            p.along = Some(if b.belt_velocity_m_s < 0.0 {
                pose * Pose::from_parts(
                    Vec3::new(half, 0.0, 0.0),
                    Rotation::from_rotation_z(std::f64::consts::PI),
                )
            } else {
                pose * Pose::from_translation(Vec3::new(-half, 0.0, 0.0))
            });
            vec![p]
        }
        SurfaceSpec::Chute(c) => {
            let frame = Pose::from_parts(
                vec3(c.position_m),
                rotation_of(&c.rotation, field)?
                    * Rotation::from_rotation_y(c.incline_deg.to_radians()),
            );
            let t = c.thickness_m.unwrap_or(DEFAULT_THICKNESS_M);
            // Along the slope from the top end.
            let along = frame * Pose::from_translation(Vec3::new(-c.length_m / 2.0, 0.0, 0.0));
            let mut parts = match c.profile {
                ChuteProfile::Flat => {
                    let w = c.width_m.unwrap_or(0.0);
                    let pose = frame * Pose::from_translation(Vec3::new(0.0, 0.0, -t / 2.0));
                    vec![part(
                        &c.name,
                        &c.material,
                        cuboid([c.length_m, w, t], pose),
                        c.contact_model,
                    )]
                }
                ChuteProfile::Trough => {
                    let rs = c.radius_m.unwrap_or(0.0);
                    let half_angle = c.half_angle_deg.unwrap_or(90.0).to_radians();
                    let half_length = c.length_m / 2.0;
                    // The trough's local frame has its axis along x through the origin.
                    let pose = frame * Pose::from_translation(Vec3::new(0.0, 0.0, rs));
                    let (verts, tris) = trough_mesh(rs, half_length, half_angle, TROUGH_SEGMENTS);
                    let collider = ColliderBuilder::trimesh(verts, tris)
                        .map_err(|e| ScenarioError::invalid(field, format!("trough mesh: {e}")))?
                        .position(pose);
                    let mut p = part(&c.name, &c.material, collider, c.contact_model);
                    p.shape = SurfaceShape::Trough {
                        radius_m: rs,
                        half_length_m: half_length,
                        half_angle_rad: half_angle,
                    };
                    vec![p]
                }
            };
            parts[0].along = Some(along);
            parts
        }
        SurfaceSpec::Bin(b) => {
            let frame = Pose::from_parts(vec3(b.position_m), rotation_of(&b.rotation, field)?);
            let t = b.wall_thickness_m.unwrap_or(DEFAULT_THICKNESS_M);
            let [lx, ly, h] = b.inner_size_m;
            let w = b.wall_materials.clone().unwrap_or_default();
            let mat = |m: &Option<String>| m.clone().unwrap_or_else(|| b.material.clone());
            let walls = [
                (
                    "floor",
                    mat(&w.floor),
                    [lx + 2.0 * t, ly + 2.0 * t, t],
                    Vec3::new(0.0, 0.0, -t / 2.0),
                ),
                (
                    "x_min",
                    mat(&w.x_min),
                    [t, ly + 2.0 * t, h],
                    Vec3::new(-(lx + t) / 2.0, 0.0, h / 2.0),
                ),
                (
                    "x_max",
                    mat(&w.x_max),
                    [t, ly + 2.0 * t, h],
                    Vec3::new((lx + t) / 2.0, 0.0, h / 2.0),
                ),
                (
                    "y_min",
                    mat(&w.y_min),
                    [lx, t, h],
                    Vec3::new(0.0, -(ly + t) / 2.0, h / 2.0),
                ),
                (
                    "y_max",
                    mat(&w.y_max),
                    [lx, t, h],
                    Vec3::new(0.0, (ly + t) / 2.0, h / 2.0),
                ),
            ];
            walls
                .into_iter()
                .map(|(wall, m, size, c)| {
                    let pose = frame * Pose::from_translation(c);
                    part(
                        &format!("{}/{wall}", b.name),
                        &m,
                        cuboid(size, pose),
                        b.contact_model,
                    )
                })
                .collect()
        }
        SurfaceSpec::Mesh(m) => {
            let path = base_dir.join(&m.file);
            let (verts, tris) = mesh::load(&path)
                .map_err(|e| ScenarioError::invalid(format!("{field}.file"), e))?;
            let scale = m.scale.vector();
            let verts: Vec<Vec3> = verts.into_iter().map(|v| v * scale).collect();
            let pose = Pose::from_parts(vec3(m.position_m), rotation_of(&m.rotation, field)?);
            // The scaled mesh must lie in the scene's range like every position (a scale of 1e6
            // on a 1 km mesh would put it beyond any apple).
            for v in &verts {
                let w = pose.transform_point(*v);
                for x in [w.x, w.y, w.z] {
                    if !crate::scenario::ranges::POSITION.contains(x.abs()) {
                        return Err(ScenarioError::invalid(
                            format!("{field}.scale"),
                            format!(
                                "the scaled mesh of '{}' reaches {x:e} m, outside the range of fruit handling ({}): check scale and the mesh's units",
                                path.display(),
                                crate::scenario::ranges::POSITION.describe()
                            ),
                        ));
                    }
                }
            }
            let collider = ColliderBuilder::trimesh(verts, tris)
                .map_err(|e| {
                    ScenarioError::invalid(
                        format!("{field}.file"),
                        format!("'{}': {e}", path.display()),
                    )
                })?
                .position(pose);
            vec![part(&m.name, &m.material, collider, m.contact_model)]
        }
        SurfaceSpec::RollerBed(b) => {
            let mut parts = Vec::new();
            for r in b.rollers() {
                parts.extend(parts_without_padding(
                    &SurfaceSpec::Roller(r),
                    field,
                    base_dir,
                )?);
            }
            parts
        }
        SurfaceSpec::Roller(r) => {
            let axis = vec3(crate::scenario::motion::unit_axis(
                &format!("{field}.axis"),
                r.axis,
            )?);
            // rapier's cylinder has its axis along local y.
            let pose = Pose::from_parts(
                vec3(r.position_m),
                Rotation::from_rotation_arc(Vec3::Y, axis),
            );
            let collider = ColliderBuilder::cylinder(r.length_m / 2.0, r.radius_m).position(pose);
            let mut p = part(&r.name, &r.material, collider, r.contact_model);
            p.turned_by_contacts = r
                .free_turning
                .as_ref()
                .map(|f| r.radius_m * r.radius_m / f.moment_of_inertia_kg_m2);
            vec![p]
        }
    })
}

/// Inner surface of a trough of radius `rs` about the x axis, open towards +z.
pub fn trough_mesh(
    rs: f64,
    half_length: f64,
    half_angle: f64,
    segments: usize,
) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut verts = Vec::new();
    for k in 0..=segments {
        let phi = -half_angle + 2.0 * half_angle * k as f64 / segments as f64;
        let (y, z) = (rs * phi.sin(), -rs * phi.cos());
        verts.push(Vec3::new(-half_length, y, z));
        verts.push(Vec3::new(half_length, y, z));
    }
    let mut tris = Vec::new();
    for k in 0..segments as u32 {
        let (a, b, c, d) = (2 * k, 2 * k + 1, 2 * k + 2, 2 * k + 3);
        tris.push([a, c, b]);
        tris.push([b, c, d]);
    }
    (verts, tris)
}
