//! The scene's surfaces for the viewer: rebuilt from the scenario as the run built them and
//! tessellated as the ParaView output draws them; planes cut to the scene's extent. A moving
//! part is tessellated at its rest pose and carried per frame by its body's motion, compiled
//! from the scenario as the run compiled it ([`Motion::of`] per unit, as `World` builds them).

use super::*;
use crate::world::motion::Motion;
use rapier3d_f64::math::Pose;

/// The surfaces of the scenario, tessellated at their rest poses; the bodies that carry the
/// moving ones, posed at each frame's time (`times`); the extent of the bounded surfaces over
/// the frames. A surface that cannot be rebuilt (a mesh file not found from `base`) is left out
/// with a note.
#[allow(clippy::type_complexity)]
pub(super) fn surfaces_of(
    sc: &Scenario,
    base: &Path,
    lo: Vec3,
    hi: Vec3,
    have_apples: bool,
    times: &[f64],
    notes: &mut Vec<String>,
) -> (Vec<SurfaceInfo>, Vec<MoverInfo>, Option<Vec3>, Option<Vec3>) {
    let mut items = Vec::new();
    // (name, kind, material, belt, the plane's point and normal, the body that carries it).
    let mut meta: Vec<(
        String,
        &'static str,
        String,
        Option<Belt>,
        Option<(Vec3, Vec3)>,
        Option<usize>,
    )> = Vec::new();
    // The moving bodies: the rigid move from the rest pose at each frame.
    let mut carried: Vec<(String, Vec<Pose>)> = Vec::new();
    let mut moving = Vec::new();
    for (k, s) in sc.surfaces.iter().enumerate() {
        let field = format!("surfaces[{k}]");
        let parts = match crate::world::surfaces::parts(s, &field, base) {
            Ok(p) => p,
            Err(e) => {
                notes.push(format!(
                    "surface '{}' is not drawn: {e}{}",
                    s.name(),
                    if matches!(s, SurfaceSpec::Mesh(_)) {
                        " (mesh files resolve against the scenario's folder: pass --assets DIR)"
                    } else {
                        ""
                    }
                ));
                continue;
            }
        };
        let kind = match s {
            SurfaceSpec::Plane(_) => "plane",
            SurfaceSpec::Box(_) => "box",
            SurfaceSpec::Conveyor(_) => "conveyor",
            SurfaceSpec::Chute(c) => match c.profile {
                crate::scenario::surfaces::ChuteProfile::Flat => "chute",
                crate::scenario::surfaces::ChuteProfile::Trough => "trough",
            },
            SurfaceSpec::Bin(_) => "bin",
            SurfaceSpec::Mesh(_) => "mesh",
            SurfaceSpec::Roller(_) => "roller",
            SurfaceSpec::RollerBed(_) => "roller_bed",
        };
        // One body per unit (a roller bed's rollers), as the world builds them.
        let units = s.units();
        let motions: Vec<Option<Motion>> = units.iter().map(Motion::of).collect();
        if motions.iter().flatten().any(|m| m.spin_axis().is_some()) {
            notes.push(format!(
                "roller '{}' turns about its own axis in the run: drawn without its turn (a cylinder looks the same turned)",
                s.name()
            ));
        }
        let bodies: Vec<Option<usize>> = units
            .iter()
            .zip(&motions)
            .map(|(u, m)| {
                let m = m.as_ref().filter(|m| m.displaces())?;
                carried.push((
                    u.name().to_string(),
                    times.iter().map(|&t| m.carry(t)).collect(),
                ));
                Some(carried.len() - 1)
            })
            .collect();
        if bodies.iter().any(Option::is_some) {
            moving.push(format!("'{}'", s.name()));
        }
        let belt = match s {
            SurfaceSpec::Conveyor(c) => rotation_of(&c.rotation, &field).ok().map(|rot| {
                let sign = if c.belt_velocity_m_s < 0.0 { -1.0 } else { 1.0 };
                let d = rot * Vec3::new(sign, 0.0, 0.0);
                let top =
                    crate::math::vec3(c.position_m) + rot * Vec3::new(0.0, 0.0, c.size_m[2] / 2.0);
                Belt {
                    direction: [d.x, d.y, d.z],
                    speed_m_s: c.belt_velocity_m_s.abs(),
                    top_centre_m: [top.x, top.y, top.z],
                    half_length_m: c.size_m[0] / 2.0,
                }
            }),
            _ => None,
        };
        let plane = match s {
            SurfaceSpec::Plane(p) => Some((
                crate::math::vec3(p.point_m),
                crate::math::vec3(p.normal).normalize(),
            )),
            _ => None,
        };
        let mut belt = belt;
        // A spec of one unit has one body for all its parts; a bed, one per roller (one part
        // each).
        debug_assert!(bodies.len() == 1 || bodies.len() == parts.len());
        for (j, p) in parts.into_iter().enumerate() {
            let body = bodies[if bodies.len() == 1 { 0 } else { j }];
            let material = p.material.clone();
            let name = p.name.clone();
            items.push((
                name.clone(),
                p.collider.shape.clone(),
                p.collider.position,
                p.shape.clone(),
            ));
            meta.push((name, kind, material, belt.take(), plane, body));
        }
    }
    if !moving.is_empty() {
        notes.push(format!(
            "moving surface(s) {} drawn at their pose of each frame (from their `motion`), moving in a straight line between frames",
            moving.join(", ")
        ));
    }
    let scene = SceneSurfaces::from_parts(items);
    // Bounded surfaces' extent first, so that a plane is cut to the whole scene.
    let (mut blo, mut bhi) = (None::<Vec3>, None::<Vec3>);
    let (probe, _) = scene.tessellate(lo, hi);
    for (m, info) in probe.iter().zip(&meta) {
        if info.4.is_some() || m.points.is_empty() {
            continue;
        }
        let (a, b) = m
            .points
            .iter()
            .fold((m.points[0], m.points[0]), |(a, b), &p| {
                (a.min(p), b.max(p))
            });
        // A moving one over every frame: its box's corners carried.
        let rest = [Pose::IDENTITY];
        let poses = info.5.map_or(&rest[..], |k| &carried[k].1[..]);
        for pose in poses {
            for k in 0..8 {
                let c = Vec3::new(
                    if k & 1 == 0 { a.x } else { b.x },
                    if k & 2 == 0 { a.y } else { b.y },
                    if k & 4 == 0 { a.z } else { b.z },
                );
                let p = pose.transform_point(c);
                blo = Some(blo.map_or(p, |x| x.min(p)));
                bhi = Some(bhi.map_or(p, |x| x.max(p)));
            }
        }
    }
    let (clo, chi) = match (have_apples, blo, bhi) {
        (true, Some(a), Some(b)) => (lo.min(a), hi.max(b)),
        (true, _, _) => (lo, hi),
        (false, Some(a), Some(b)) => (a, b),
        (false, _, _) => (Vec3::splat(-0.5), Vec3::splat(0.5)),
    };
    // A plane is cut to the scene: the rectangle its box (padded by a tenth) covers when
    // projected onto it (tessellate() draws a square twice the box's diagonal, for ParaView).
    let pad = (chi - clo) * 0.1 + Vec3::splat(0.02);
    let (clo, chi) = (clo - pad, chi + pad);
    let (meshes, warnings) = scene.tessellate(clo, chi);
    notes.extend(warnings);
    let surfaces = meshes
        .into_iter()
        .zip(meta)
        .map(|(m, (name, kind, material, belt, plane, mover))| {
            let m = match plane {
                Some((p0, n)) => plane_patch(p0, n, clo, chi),
                None => m,
            };
            let mut bytes = Vec::with_capacity(m.triangles.len() * 36);
            for t in &m.triangles {
                for &v in t {
                    let p = m.points[v as usize];
                    for x in [p.x, p.y, p.z] {
                        bytes.extend_from_slice(&(x as f32).to_le_bytes());
                    }
                }
            }
            SurfaceInfo {
                name,
                kind,
                material,
                triangles_b64: b64(&bytes),
                belt,
                mover,
            }
        })
        .collect();
    let movers = carried
        .into_iter()
        .map(|(name, poses)| {
            let mut bytes = Vec::with_capacity(poses.len() * 28);
            for p in &poses {
                let (t, q) = (p.translation, p.rotation);
                for x in [t.x, t.y, t.z, q.x, q.y, q.z, q.w] {
                    bytes.extend_from_slice(&(x as f32).to_le_bytes());
                }
            }
            MoverInfo {
                name,
                poses_b64: b64(&bytes),
            }
        })
        .collect();
    (surfaces, movers, blo, bhi)
}

/// The rectangle of the plane through `p0` with unit normal `n` that the box [lo, hi] covers
/// when projected onto it, as two triangles.
pub(super) fn plane_patch(p0: Vec3, n: Vec3, lo: Vec3, hi: Vec3) -> crate::output::vtk::Mesh {
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let (mut a0, mut a1, mut b0, mut b1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for k in 0..8 {
        let c = Vec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        );
        let d = c - p0;
        a0 = a0.min(d.dot(u));
        a1 = a1.max(d.dot(u));
        b0 = b0.min(d.dot(v));
        b1 = b1.max(d.dot(v));
    }
    crate::output::vtk::Mesh {
        points: vec![
            p0 + a0 * u + b0 * v,
            p0 + a1 * u + b0 * v,
            p0 + a1 * u + b1 * v,
            p0 + a0 * u + b1 * v,
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// RFC 4648 base64 back to bytes.
    fn unb64(s: &str) -> Vec<u8> {
        const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let v: Vec<u32> = s
            .bytes()
            .filter(|&c| c != b'=')
            .map(|c| A.iter().position(|&a| a == c).unwrap() as u32)
            .collect();
        let mut out = Vec::new();
        for c in v.chunks(4) {
            let n = c
                .iter()
                .enumerate()
                .fold(0, |n, (k, &x)| n | x << (18 - 6 * k));
            out.extend_from_slice(&n.to_be_bytes()[1..c.len()]);
        }
        out
    }

    /// A roller bed carried by a `motion` is one body per roller, as the world builds it: each
    /// roller's part has its own mover, posed per frame by the translation (its own turn left
    /// out, and said); a roller that only turns has none.
    #[test]
    fn a_carried_roller_bed_has_a_body_per_roller_and_a_turning_roller_none() {
        let sc: Scenario = crate::scenario::from_json(
            r#"{"duration_s": 1, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -9.81],
                "materials": {"steel": {"youngs_modulus_pa": 2e11, "poisson_ratio": 0.28}},
                "contact": {"friction": 0.3, "ke": 0.09, "lambda_s_m": 1000},
                "surfaces": [
                  {"type": "roller_bed", "name": "bed", "material": "steel", "radius_m": 0.03,
                   "length_m": 0.4, "position_m": [0, 0, 0], "axis": [0, 1, 0], "pitch_m": 0.08,
                   "pitch_direction": [1, 0, 0], "count": 3, "angular_velocity_rad_s": 5,
                   "motion": {"translation": {"velocity_m_s": [0.5, 0, 0]}}},
                  {"type": "roller", "name": "spin", "material": "steel", "radius_m": 0.03,
                   "length_m": 0.4, "position_m": [0, 1, 0], "axis": [0, 1, 0],
                   "angular_velocity_rad_s": 5}
                ]}"#,
            "test",
        )
        .unwrap();
        let mut notes = Vec::new();
        let (surfaces, movers, _, _) = surfaces_of(
            &sc,
            Path::new("."),
            Vec3::ZERO,
            Vec3::ONE,
            false,
            &[0.0, 0.2],
            &mut notes,
        );
        let bodies: Vec<Option<usize>> = surfaces.iter().map(|s| s.mover).collect();
        assert_eq!(bodies, [Some(0), Some(1), Some(2), None]);
        assert_eq!(movers.len(), 3);
        for m in &movers {
            // Frame 1 (t = 0.2 s): 0.1 m along x, not turned.
            let f: Vec<f32> = unb64(&m.poses_b64)
                .chunks(4)
                .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
                .collect();
            assert_eq!(f[..7], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
            assert_eq!(f[7..], [0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        }
        let notes = notes.join("\n");
        assert!(
            notes.contains("roller 'bed' turns about its own axis"),
            "{notes}"
        );
        assert!(
            notes.contains("roller 'spin' turns about its own axis"),
            "{notes}"
        );
        assert!(notes.contains("moving surface(s) 'bed' drawn"), "{notes}");
        assert!(!notes.contains("'spin' drawn"), "{notes}");
    }
}
