//! Apple-surface contact geometry at the current poses.
//!
//! The layer lists the surfaces near each apple when it rebuilds its pair lists (the colliders'
//! bounding boxes, then this module's geometry with the skin as margin); this module computes the
//! overlap, normal and surface curvature of each contact from the collider's pose *now*, never
//! from rapier's manifolds, which describe the previous pose (rapier-notes.md, "one-step lag"). Planes, spheres, boxes and troughs are analytic; triangle meshes are queried
//! triangle by triangle through their BVH; any other convex shape goes through parry's `contact`.

use crate::contact::spheroid::{self, Spheroid, Tangent2};
use crate::math::Vec3;
use rapier3d_f64::geometry::Collider;
use rapier3d_f64::math::Rotation;
use rapier3d_f64::parry::bounding_volume::Aabb;
use rapier3d_f64::parry::math::Pose;
use rapier3d_f64::parry::query;
use rapier3d_f64::parry::shape::{Ball, TriMesh};

/// How the layer computes contacts with a surface collider.
#[derive(Debug, Clone, PartialEq)]
pub enum SurfaceShape {
    /// Read the collider's own shape: half-space (plane), ball (convex sphere, K = 1/R), cuboid
    /// (box, flat faces; edges and corners treated as flat), triangle mesh (flat triangles), or
    /// any other convex shape through parry (flat).
    FromCollider,
    /// A concave half-pipe (trough) in the collider's local frame: axis along local x from
    /// -half_length to +half_length, inner radius `radius_m`, open towards local +z, spanning
    /// `half_angle_rad` on each side of the bottom line (pi/2 for a half pipe). Curvature
    /// K = -1/R_s across the trough (physics.md section 2 treats a trough like a cup of the same
    /// radius: the more conforming, higher-force choice). The collider's own shape is only used
    /// by rapier to find the pair.
    Trough {
        /// Inner radius R_s (m).
        radius_m: f64,
        /// Half length along local x (m).
        half_length_m: f64,
        /// Angular half-width from the bottom line (rad).
        half_angle_rad: f64,
    },
}

/// One apple-surface contact (or near-contact, overlap may be <= 0) at the current poses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceHit {
    /// Unit normal from the surface towards the apple centre (world).
    pub normal: Vec3,
    /// Overlap u (m); <= 0 means apart by -u.
    pub overlap_m: f64,
    /// Surface curvature K2 at the contact (1/m): 0 flat, > 0 convex, < 0 concave.
    pub curvature_1_m: f64,
}

/// Normals closer than this (cos 30 deg) belong to one contact on a mesh (see [`mesh_hits`]).
pub const MESH_MERGE_COS: f64 = 0.866_025_403_784_438_6;

/// Appends the hits of an apple (centre, radius) with a surface, keeping those with overlap
/// > -margin. Several hits are possible only for meshes (an apple in a V or a corner).
pub fn surface_hits(
    shape: &SurfaceShape,
    collider: &Collider,
    centre: Vec3,
    radius: f64,
    margin: f64,
    out: &mut Vec<SurfaceHit>,
) {
    surface_hits_raw(shape, collider, centre, radius, margin, true, out)
}

/// [`surface_hits`], with `fill_cylinder` false leaving a cylinder's side hits with a NaN
/// curvature (a spheroid's contact computes its own, [`spheroid_hits`]).
fn surface_hits_raw(
    shape: &SurfaceShape,
    collider: &Collider,
    centre: Vec3,
    radius: f64,
    margin: f64,
    fill_cylinder: bool,
    out: &mut Vec<SurfaceHit>,
) {
    let pose = collider.position();
    match shape {
        SurfaceShape::Trough {
            radius_m,
            half_length_m,
            half_angle_rad,
        } => {
            if let Some(h) = trough_hit(
                pose,
                centre,
                radius,
                *radius_m,
                *half_length_m,
                *half_angle_rad,
            ) {
                if h.overlap_m > -margin {
                    out.push(h);
                }
            }
        }
        SurfaceShape::FromCollider => {
            let s = collider.shape();
            if let Some(hs) = s.as_halfspace() {
                let n = pose.rotation * hs.normal;
                let u = radius - (centre - pose.translation).dot(n);
                if u > -margin {
                    out.push(SurfaceHit {
                        normal: n,
                        overlap_m: u,
                        curvature_1_m: 0.0,
                    });
                }
            } else if let Some(b) = s.as_ball() {
                let d = centre - pose.translation;
                let dist = d.length();
                let u = radius + b.radius - dist;
                if dist > 0.0 && u > -margin {
                    out.push(SurfaceHit {
                        normal: d / dist,
                        overlap_m: u,
                        curvature_1_m: 1.0 / b.radius,
                    });
                }
            } else if let Some(c) = s.as_cuboid() {
                if let Some(h) = cuboid_hit(pose, c.half_extents, centre, radius) {
                    if h.overlap_m > -margin {
                        out.push(h);
                    }
                }
            } else if let Some(cy) = s.as_cylinder() {
                let mut h = cylinder_hit(pose, cy.half_height, cy.radius, centre, radius);
                if h.overlap_m > -margin {
                    if h.curvature_1_m.is_nan() && fill_cylinder {
                        // On the side (computed only for hits kept: it solves for the ellipse).
                        h.curvature_1_m = crate::contact::elliptic::cylinder_equivalent_curvature(
                            radius, cy.radius,
                        );
                    }
                    out.push(h);
                }
            } else if let Some(m) = s.as_trimesh() {
                mesh_hits(pose, m, centre, radius, margin, out);
            } else {
                let ball = Ball::new(radius);
                let ball_pose = Pose::from_translation(centre);
                if let Ok(Some(c)) = query::contact(&ball_pose, &ball, pose, s, margin) {
                    out.push(SurfaceHit {
                        normal: -c.normal1,
                        overlap_m: -c.dist,
                        curvature_1_m: 0.0,
                    });
                }
            }
        }
    }
}

/// Whether a sphere centred at `centre` lies over one face of a box surface, at least `inset`
/// inside that face's edges (and not inside the box): there [`surface_hits`] finds that face
/// alone, at an overlap that depends only on the distance to the face's plane, so a sphere
/// carried along the face keeps its hit (an apple riding a belt, `super::sleep`). False for any
/// other shape.
pub fn over_a_box_face(
    shape: &SurfaceShape,
    collider: &Collider,
    centre: Vec3,
    inset: f64,
) -> bool {
    if !matches!(shape, SurfaceShape::FromCollider) {
        return false;
    }
    let Some(c) = collider.shape().as_cuboid() else {
        return false;
    };
    let p = collider.position().inverse_transform_point(centre);
    let h = c.half_extents;
    let outside = [p.x.abs() > h.x, p.y.abs() > h.y, p.z.abs() > h.z];
    let inside_by = [h.x - p.x.abs(), h.y - p.y.abs(), h.z - p.z.abs()];
    outside.iter().filter(|&&o| o).count() == 1
        && (0..3).all(|i| outside[i] || inside_by[i] >= inset)
}

/// How long a sphere centred at `centre`, carried at `velocity`, stays over a box surface's face
/// with its centre at least `inset` inside the face's edges ([`over_a_box_face`] holding
/// throughout) (s); `None` when it is not over a face now, or moves off the face's plane. A
/// rider's detection skips the query until then (the box is fixed: a running belt's body).
pub fn time_over_a_box_face(
    shape: &SurfaceShape,
    collider: &Collider,
    centre: Vec3,
    velocity: Vec3,
    inset: f64,
) -> Option<f64> {
    if !over_a_box_face(shape, collider, centre, inset) {
        return None;
    }
    let half = collider.shape().as_cuboid()?.half_extents;
    let pose = collider.position();
    let p = pose.inverse_transform_point(centre);
    let v = pose.rotation.inverse() * velocity;
    let mut t = f64::INFINITY;
    for i in 0..3 {
        let (p, v, h) = (p[i], v[i], half[i]);
        if p.abs() > h {
            // The face's axis: the centre stays at its height above the face, or the test fails.
            if v != 0.0 {
                return None;
            }
        } else if v != 0.0 {
            t = t.min((h - inset - p * v.signum()) / v.abs());
        }
    }
    Some(t)
}

fn cuboid_hit(pose: &Pose, half: Vec3, centre: Vec3, radius: f64) -> Option<SurfaceHit> {
    let p = pose.inverse_transform_point(centre);
    let q = p.clamp(-half, half);
    let d = p - q;
    let dist = d.length();
    if dist > 0.0 {
        return Some(SurfaceHit {
            normal: pose.rotation * (d / dist),
            overlap_m: radius - dist,
            curvature_1_m: 0.0,
        });
    }
    // Centre inside the box: leave through the nearest face.
    let depth = half - p.abs();
    let (axis, dep) = if depth.x <= depth.y && depth.x <= depth.z {
        (Vec3::X * p.x.signum(), depth.x)
    } else if depth.y <= depth.z {
        (Vec3::Y * p.y.signum(), depth.y)
    } else {
        (Vec3::Z * p.z.signum(), depth.z)
    };
    Some(SurfaceHit {
        normal: pose.rotation * axis,
        overlap_m: radius + dep,
        curvature_1_m: 0.0,
    })
}

/// An apple on a cylinder (a roller; rapier's cylinder has its axis along local y). On the
/// curved side the contact is elliptical Hertz (curvature 1/r across the axis, 0 along it): the
/// hit carries the equivalent curvature whose effective radius is the exact elliptic law's
/// stiffness radius ([`crate::contact::elliptic`]). The flat ends are flat; the rims count as flat
/// (like a box's edges). A side hit is returned with a NaN curvature, filled in by
/// [`surface_hits`] for the hits it keeps.
pub fn cylinder_hit(
    pose: &Pose,
    half_height: f64,
    r_cyl: f64,
    centre: Vec3,
    radius: f64,
) -> SurfaceHit {
    let p = pose.inverse_transform_point(centre);
    let radial = Vec3::new(p.x, 0.0, p.z);
    let rho = radial.length();
    let beyond_end = p.y.abs() - half_height;
    let outside_side = rho - r_cyl;
    let side = |rho: f64| {
        let n = if rho > 0.0 { radial / rho } else { Vec3::X };
        SurfaceHit {
            normal: pose.rotation * n,
            overlap_m: radius - (rho - r_cyl),
            curvature_1_m: f64::NAN,
        }
    };
    let end = || SurfaceHit {
        normal: pose.rotation * (Vec3::Y * p.y.signum()),
        overlap_m: radius - beyond_end,
        curvature_1_m: 0.0,
    };
    if beyond_end <= 0.0 && outside_side >= 0.0 {
        return side(rho);
    }
    if beyond_end > 0.0 && outside_side < 0.0 {
        return end();
    }
    if beyond_end > 0.0 {
        // Beyond the rim: the closest point is on the edge circle.
        let q = Vec3::new(0.0, half_height * p.y.signum(), 0.0) + radial * (r_cyl / rho);
        let d = p - q;
        let dist = d.length();
        return SurfaceHit {
            normal: pose.rotation * (d / dist),
            overlap_m: radius - dist,
            curvature_1_m: 0.0,
        };
    }
    // Centre inside the cylinder: leave through the nearer of the side and the end.
    if -outside_side <= -beyond_end {
        side(rho)
    } else {
        end()
    }
}

fn trough_hit(
    pose: &Pose,
    centre: Vec3,
    radius: f64,
    rs: f64,
    half_length: f64,
    half_angle: f64,
) -> Option<SurfaceHit> {
    let p = pose.inverse_transform_point(centre);
    if p.x.abs() > half_length {
        return None;
    }
    let perp = Vec3::new(0.0, p.y, p.z);
    let rho = perp.length();
    if rho == 0.0 || rho >= rs {
        return None;
    }
    // Angle from the bottom line (local -z).
    let phi = p.y.atan2(-p.z);
    if phi.abs() > half_angle {
        return None;
    }
    Some(SurfaceHit {
        normal: pose.rotation * (-perp / rho),
        overlap_m: radius - (rs - rho),
        curvature_1_m: -1.0 / rs,
    })
}

/// Contacts with a triangle mesh: the closest point of every triangle near the apple, then
/// merged so that one smooth region gives one contact: hits whose closest points coincide
/// (a shared edge or vertex) are one, and hits whose normals lie within 30 degrees of a deeper
/// hit are dropped (a flat floor split into triangles, or a finely tessellated curve, must not
/// push twice). Triangles are treated as flat (K = 0) and two-sided.
pub fn mesh_hits(
    pose: &Pose,
    mesh: &TriMesh,
    centre: Vec3,
    radius: f64,
    margin: f64,
    out: &mut Vec<SurfaceHit>,
) {
    let p = pose.inverse_transform_point(centre);
    let reach = radius + margin.max(0.0);
    let aabb = Aabb::new(p - Vec3::splat(reach), p + Vec3::splat(reach));
    let mut local: Vec<(f64, Vec3)> = Vec::new();
    for tri_id in mesh.bvh().intersect_aabb(&aabb) {
        let tri = mesh.triangle(tri_id);
        let q = closest_point_on_triangle(p, tri.a, tri.b, tri.c);
        let d = p - q;
        let dist = d.length();
        let u = radius - dist;
        if u <= -margin {
            continue;
        }
        let n = if dist > 1e-12 * radius {
            d / dist
        } else {
            match tri.normal() {
                Some(n) => n,
                None => continue,
            }
        };
        local.push((u, n));
    }
    // Deepest first; ties broken by the normal's components for a fixed order.
    local.sort_by(|a, b| {
        b.0.total_cmp(&a.0)
            .then(a.1.x.total_cmp(&b.1.x))
            .then(a.1.y.total_cmp(&b.1.y))
            .then(a.1.z.total_cmp(&b.1.z))
    });
    let first = out.len();
    for (u, n) in local {
        let nw = pose.rotation * n;
        if out[first..]
            .iter()
            .any(|h| h.normal.dot(nw) > MESH_MERGE_COS)
        {
            continue;
        }
        out.push(SurfaceHit {
            normal: nw,
            overlap_m: u,
            curvature_1_m: 0.0,
        });
    }
}

/// Buffers [`spheroid_hits`] reuses from call to call.
#[derive(Debug, Clone, Default)]
pub struct SpheroidScratch {
    starts: Vec<SurfaceHit>,
    probe: Vec<SurfaceHit>,
}

/// What a spheroid's contact with a surface adds to its [`SurfaceHit`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapedHit {
    /// The apple's surface point deepest into the surface, from its centre (m, world): the
    /// contact point before the deformation's share is added.
    pub arm: Vec3,
    /// The elliptic law's stiffness radius R_k (m); NaN when the contact conforms (Hertz does
    /// not apply).
    pub r_star_m: f64,
    /// The elliptic law's area radius R_a (m).
    pub area_radius_m: f64,
}

/// The hits of a spheroidal apple (centre, orientation `rot`, shape `sph`) with a surface, with
/// overlap > -margin, and what each adds ([`ShapedHit`], in `extra`, index for index).
///
/// Every surface kind is handled by the sphere code ([`surface_hits`]) through osculating
/// spheres: for a normal estimate n (surface to apple), the apple's point with outward normal -n
/// is p = centre + s(-n) ([`Spheroid::point_with_normal`]); a sphere of radius rho (the
/// spheroid's mean radius of curvature there) tangent to the spheroid at p, centred at
/// p + rho n, is queried, and its hit's normal is the next estimate. At the fixed point the
/// surface point nearest the sphere's centre lies on the line through p along n, and the surface
/// normal there is n: a common normal, with the sphere's overlap the spheroid's depth at p. On a
/// flat (plane, box face, triangle) one iteration is exact; on a curved surface each iteration
/// shrinks the normal's error by about |rho - R| / (rho + R_s) (docs/shape.md section 3). The
/// first estimates are the hits of the bounding sphere (a superset: the spheroid lies inside it).
///
/// The relative curvature adds the spheroid's two principal curvatures at p to the surface's:
/// isotropic (plane, box, triangle: 0; ball: 1/R; trough: -1/R, the cup of the sphere code), or
/// a cylinder's side: 1/r across its axis, 0 along it.
#[allow(clippy::too_many_arguments)]
pub fn spheroid_hits(
    shape: &SurfaceShape,
    collider: &Collider,
    centre: Vec3,
    rot: &Rotation,
    sph: &Spheroid,
    margin: f64,
    out: &mut Vec<SurfaceHit>,
    extra: &mut Vec<ShapedHit>,
    scratch: &mut SpheroidScratch,
) {
    let SpheroidScratch { starts, probe } = scratch;
    starts.clear();
    surface_hits_raw(
        shape,
        collider,
        centre,
        sph.bounding_radius(),
        margin,
        false,
        starts,
    );
    let first = out.len();
    for &h0 in starts.iter() {
        let mut n = h0.normal;
        let mut hit = None;
        for _ in 0..spheroid::MAX_ITERATIONS {
            let sp = sph.point_with_normal(rot, -n);
            let rho = 2.0 / (1.0 / sp.r_meridian_m + 1.0 / sp.r_parallel_m);
            probe.clear();
            surface_hits_raw(
                shape,
                collider,
                centre + sp.offset + n * rho,
                rho,
                margin + rho,
                false,
                probe,
            );
            let Some(best) = probe
                .iter()
                .copied()
                .max_by(|a, b| a.normal.dot(n).total_cmp(&b.normal.dot(n)))
            else {
                hit = None;
                break;
            };
            let moved = (best.normal - n).length();
            n = best.normal;
            hit = Some(best);
            if moved <= spheroid::NORMAL_TOLERANCE {
                break;
            }
        }
        let Some(hit) = hit else { continue };
        if hit.overlap_m <= -margin
            || out[first..]
                .iter()
                .any(|h| h.normal.dot(hit.normal) > MESH_MERGE_COS)
        {
            continue;
        }
        let sp = sph.point_with_normal(rot, -hit.normal);
        let (e1, e2) = spheroid::tangent_basis(hit.normal);
        let surface = if hit.curvature_1_m.is_nan() {
            // A cylinder's side (rapier's cylinders have their axis along local y).
            let r_cyl = collider
                .shape()
                .as_cylinder()
                .map_or(f64::INFINITY, |c| c.radius);
            let axis = collider.position().rotation * Vec3::Y;
            Tangent2::principal(0.0, axis, 1.0 / r_cyl, e1, e2)
        } else {
            Tangent2::iso(hit.curvature_1_m)
        };
        let (r_star_m, area_radius_m) = spheroid::hertz_radii(&(sp.curvature(e1, e2) + surface))
            .unwrap_or((f64::NAN, f64::NAN));
        out.push(hit);
        extra.push(ShapedHit {
            arm: sp.offset,
            r_star_m,
            area_radius_m,
        });
    }
}

/// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
pub fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    a + ab * v + ac * w
}

#[cfg(test)]
mod tests {
    use super::*;
    use rapier3d_f64::geometry::ColliderBuilder;

    #[test]
    fn two_triangle_floor_gives_one_hit_even_on_the_diagonal() {
        let verts = vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ];
        let col = ColliderBuilder::trimesh(verts, vec![[0, 1, 2], [0, 2, 3]])
            .unwrap()
            .build();
        for centre in [Vec3::new(0.0, 0.0, 0.039), Vec3::new(0.3, -0.2, 0.039)] {
            let mut hits = Vec::new();
            surface_hits(
                &SurfaceShape::FromCollider,
                &col,
                centre,
                0.04,
                0.0,
                &mut hits,
            );
            assert_eq!(hits.len(), 1, "{hits:?}");
            assert!((hits[0].overlap_m - 0.001).abs() < 1e-12);
            assert!((hits[0].normal - Vec3::Z).length() < 1e-12);
        }
    }

    /// A riding sphere is left unqueried only over one face of a box, at least the inset inside
    /// its edges, where the full query gives that face alone at an overlap set by the height.
    #[test]
    fn over_a_box_face_only_well_inside_its_edges() {
        let b = ColliderBuilder::cuboid(0.5, 0.15, 0.02)
            .translation(Vec3::new(0.0, 0.0, -0.02))
            .build();
        let over = |x: f64, y: f64, z: f64| {
            over_a_box_face(&SurfaceShape::FromCollider, &b, Vec3::new(x, y, z), 1e-3)
        };
        assert!(over(0.0, 0.0, 0.0399));
        assert!(over(0.498, 0.148, 0.0399));
        assert!(!over(0.4995, 0.0, 0.0399), "within the inset of an edge");
        assert!(!over(0.51, 0.0, 0.0399), "past the end");
        assert!(!over(0.51, 0.16, 0.0399), "over a corner");
        assert!(!over(0.0, 0.0, -0.02), "inside the box");
        // Where it holds, the full query finds the face alone, the overlap the same to the bit.
        let mut first = None;
        for x in [-0.45, 0.0, 0.3, 0.498] {
            let mut hits = Vec::new();
            surface_hits(
                &SurfaceShape::FromCollider,
                &b,
                Vec3::new(x, 0.1, 0.0399),
                0.04,
                0.01,
                &mut hits,
            );
            assert_eq!(hits.len(), 1, "{hits:?}");
            assert!((hits[0].overlap_m - 1e-4).abs() < 1e-15);
            assert_eq!(*first.get_or_insert(hits[0].overlap_m), hits[0].overlap_m);
        }
        let ball = ColliderBuilder::ball(0.5).build();
        assert!(!over_a_box_face(
            &SurfaceShape::FromCollider,
            &ball,
            Vec3::new(0.0, 0.0, 0.6),
            1e-3
        ));
    }

    /// The time a rider stays over the face is the time its centre takes to come within the
    /// inset of the face's edge it moves toward (a turned box included): over_a_box_face holds
    /// just before it and fails just after.
    #[test]
    fn time_over_a_box_face_ends_at_the_inset() {
        let turn = Rotation::from_rotation_z(0.3);
        let b = ColliderBuilder::cuboid(0.5, 0.15, 0.02)
            .position(Pose::from_parts(Vec3::new(1.0, 2.0, -0.02), turn))
            .build();
        let shape = SurfaceShape::FromCollider;
        // 0.2 m from the belt's centre along its length, 0.05 m across, moving at 0.4 m/s along
        // and 0.1 m/s across (in the belt's frame).
        let at = |local: Vec3| b.position().transform_point(local);
        let v = turn * Vec3::new(0.4, 0.1, 0.0);
        let c0 = at(Vec3::new(0.2, 0.05, 0.0599));
        let t = time_over_a_box_face(&shape, &b, c0, v, 1e-3).unwrap();
        // Along: (0.5 - 0.001 - 0.2) / 0.4 = 0.7475 s; across: (0.15 - 0.001 - 0.05) / 0.1 = 0.99 s.
        assert!((t - 0.7475).abs() < 1e-12, "{t}");
        assert!(over_a_box_face(&shape, &b, c0 + v * (t - 1e-9), 1e-3));
        assert!(!over_a_box_face(&shape, &b, c0 + v * (t + 1e-9), 1e-3));
        // Still: forever; moving off the face's plane, or not over a face: none.
        assert_eq!(
            time_over_a_box_face(&shape, &b, c0, Vec3::ZERO, 1e-3),
            Some(f64::INFINITY)
        );
        assert_eq!(
            time_over_a_box_face(&shape, &b, c0, Vec3::Z * 0.1, 1e-3),
            None
        );
        let edge = at(Vec3::new(0.4995, 0.0, 0.0599));
        assert_eq!(time_over_a_box_face(&shape, &b, edge, v, 1e-3), None);
    }

    #[test]
    fn box_and_trough() {
        let b = ColliderBuilder::cuboid(0.5, 0.5, 0.1).build();
        let mut hits = Vec::new();
        surface_hits(
            &SurfaceShape::FromCollider,
            &b,
            Vec3::new(0.1, 0.0, 0.139),
            0.04,
            0.0,
            &mut hits,
        );
        assert!((hits[0].overlap_m - 0.001).abs() < 1e-12);
        let t = ColliderBuilder::ball(0.1).build();
        let shape = SurfaceShape::Trough {
            radius_m: 0.1,
            half_length_m: 1.0,
            half_angle_rad: std::f64::consts::FRAC_PI_2,
        };
        let mut th = Vec::new();
        surface_hits(&shape, &t, Vec3::new(0.0, 0.0, -0.061), 0.04, 0.0, &mut th);
        assert!((th[0].overlap_m - 0.001).abs() < 1e-12);
        assert!((th[0].normal - Vec3::Z).length() < 1e-12);
        assert_eq!(th[0].curvature_1_m, -10.0);
    }

    #[test]
    fn cylinder_side_end_and_rim() {
        // A roller of radius 30 mm, 0.4 m long, axis along world x (local y turned onto x).
        let pose = Pose::from_parts(
            Vec3::new(0.0, 0.0, 0.1),
            rapier3d_f64::math::Rotation::from_rotation_arc(Vec3::Y, Vec3::X),
        );
        let col = ColliderBuilder::cylinder(0.2, 0.03).position(pose).build();
        let r = 0.037;
        let mut hits = Vec::new();
        // Above the side, 1 mm deep.
        surface_hits(
            &SurfaceShape::FromCollider,
            &col,
            Vec3::new(0.05, 0.0, 0.1 + 0.03 + r - 0.001),
            r,
            0.0,
            &mut hits,
        );
        assert_eq!(hits.len(), 1);
        assert!((hits[0].overlap_m - 0.001).abs() < 1e-12);
        assert!((hits[0].normal - Vec3::Z).length() < 1e-12);
        let r_star =
            crate::contact::normal::effective_radius(1.0 / r, hits[0].curvature_1_m).unwrap();
        let exact = crate::contact::elliptic::sphere_on_cylinder(r, 0.03).stiffness_radius_m;
        assert!((r_star - exact).abs() < 1e-15);
        // Beyond the +x end, on the axis: flat end.
        hits.clear();
        surface_hits(
            &SurfaceShape::FromCollider,
            &col,
            Vec3::new(0.2 + r - 0.002, 0.0, 0.1),
            r,
            0.0,
            &mut hits,
        );
        assert!((hits[0].overlap_m - 0.002).abs() < 1e-12);
        assert!((hits[0].normal - Vec3::X).length() < 1e-12);
        assert_eq!(hits[0].curvature_1_m, 0.0);
        // Off the rim at 45 degrees.
        hits.clear();
        let c = Vec3::new(0.2, 0.0, 0.13) + Vec3::new(1.0, 0.0, 1.0).normalize() * 0.036;
        surface_hits(&SurfaceShape::FromCollider, &col, c, r, 0.0, &mut hits);
        assert!((hits[0].overlap_m - 0.001).abs() < 1e-12);
        assert_eq!(hits[0].curvature_1_m, 0.0);
    }

    /// Every surface kind, at contacts on faces, edges, corners and curved sides: the spheroid
    /// code with a = c gives the sphere code's normal, overlap and effective radius (to 1e-12;
    /// the operations differ, so not to the bit).
    #[test]
    fn a_round_spheroid_is_the_sphere() {
        use rapier3d_f64::math::Pose;
        let r = 0.04;
        let sph = Spheroid::new(r, r);
        let rot = Rotation::from_scaled_axis(Vec3::new(0.3, -0.5, 0.9));
        let tilt = Pose::from_parts(
            Vec3::new(0.01, -0.02, 0.005),
            Rotation::from_scaled_axis(Vec3::new(0.2, 0.1, -0.4)),
        );
        let mesh = ColliderBuilder::trimesh(
            vec![
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.3),
            ],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let trough = SurfaceShape::Trough {
            radius_m: 0.1,
            half_length_m: 0.5,
            half_angle_rad: 1.2,
        };
        let cases: Vec<(&str, SurfaceShape, rapier3d_f64::geometry::Collider, Vec3)> = vec![
            (
                "plane",
                SurfaceShape::FromCollider,
                ColliderBuilder::new(rapier3d_f64::geometry::SharedShape::halfspace(Vec3::Z))
                    .position(tilt)
                    .build(),
                Vec3::new(0.02, 0.0, 0.04),
            ),
            (
                "ball",
                SurfaceShape::FromCollider,
                ColliderBuilder::ball(0.05).build(),
                Vec3::new(0.03, 0.05, 0.06),
            ),
            (
                "box face",
                SurfaceShape::FromCollider,
                ColliderBuilder::cuboid(0.2, 0.2, 0.1)
                    .position(tilt)
                    .build(),
                Vec3::new(0.05, 0.03, 0.138),
            ),
            (
                "box edge",
                SurfaceShape::FromCollider,
                ColliderBuilder::cuboid(0.2, 0.2, 0.1).build(),
                Vec3::new(0.225, 0.0, 0.125),
            ),
            (
                "box corner",
                SurfaceShape::FromCollider,
                ColliderBuilder::cuboid(0.2, 0.2, 0.1).build(),
                Vec3::new(0.22, 0.22, 0.12),
            ),
            (
                "cylinder side",
                SurfaceShape::FromCollider,
                ColliderBuilder::cylinder(0.3, 0.03).position(tilt).build(),
                Vec3::new(0.02, 0.1, 0.075),
            ),
            (
                "cylinder end",
                SurfaceShape::FromCollider,
                ColliderBuilder::cylinder(0.3, 0.03).build(),
                Vec3::new(0.01, 0.339, 0.0),
            ),
            (
                "trough",
                trough,
                ColliderBuilder::cuboid(0.5, 0.1, 0.1).build(),
                Vec3::new(0.1, 0.03, -0.055),
            ),
            (
                "mesh",
                SurfaceShape::FromCollider,
                mesh.build(),
                // 39 mm above the triangle's plane at (0.1, -0.1, 0.135).
                Vec3::new(0.1, -0.1, 0.135) + Vec3::new(0.0, -0.6, 4.0).normalize() * 0.039,
            ),
            (
                "capsule (parry)",
                SurfaceShape::FromCollider,
                ColliderBuilder::capsule_x(0.2, 0.02).build(),
                Vec3::new(0.05, 0.0, 0.059),
            ),
        ];
        for (what, shape, col, centre) in cases {
            let (mut a, mut b, mut extra) = (Vec::new(), Vec::new(), Vec::new());
            surface_hits(&shape, &col, centre, r, 0.01, &mut a);
            spheroid_hits(
                &shape,
                &col,
                centre,
                &rot,
                &sph,
                0.01,
                &mut b,
                &mut extra,
                &mut SpheroidScratch::default(),
            );
            assert_eq!(a.len(), 1, "{what}: {a:?}");
            assert_eq!(b.len(), 1, "{what}: {b:?}");
            let (ha, hb) = (a[0], b[0]);
            assert!(
                (ha.normal - hb.normal).length() < 1e-12,
                "{what}: {ha:?} {hb:?}"
            );
            assert!(
                (ha.overlap_m - hb.overlap_m).abs() < 1e-12 * r,
                "{what}: {ha:?} {hb:?}"
            );
            assert!(ha.overlap_m > 0.0, "{what}: {ha:?}");
            let r_star =
                crate::contact::normal::effective_radius(1.0 / r, ha.curvature_1_m).unwrap();
            assert!(
                (extra[0].r_star_m / r_star - 1.0).abs() < 1e-12,
                "{what}: {} {r_star}",
                extra[0].r_star_m
            );
            assert!(
                (extra[0].arm + ha.normal * r).length() < 1e-12 * r,
                "{what}"
            );
        }
    }
}
