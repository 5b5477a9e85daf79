//! The scene's surfaces for the viewer: rebuilt from the scenario as the run built them and
//! tessellated as the ParaView output draws them; planes cut to the scene's extent.

use super::*;

/// The surfaces of the scenario, tessellated; the extent of the bounded ones. A surface that
/// cannot be rebuilt (a mesh file not found from `base`) is left out with a note.
#[allow(clippy::type_complexity)]
pub(super) fn surfaces_of(
    sc: &Scenario,
    base: &Path,
    lo: Vec3,
    hi: Vec3,
    have_apples: bool,
    notes: &mut Vec<String>,
) -> (Vec<SurfaceInfo>, Option<Vec3>, Option<Vec3>) {
    let mut items = Vec::new();
    // (name, kind, material, belt, the plane's point and normal).
    let mut meta: Vec<(
        String,
        &'static str,
        String,
        Option<Belt>,
        Option<(Vec3, Vec3)>,
    )> = Vec::new();
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
        if s.motion().is_some() {
            notes.push(format!(
                "surface '{}' moves in the run (its `motion`): it is drawn where it starts",
                s.name()
            ));
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
        for p in parts {
            let material = p.material.clone();
            let name = p.name.clone();
            items.push((
                name.clone(),
                p.collider.shape.clone(),
                p.collider.position,
                p.shape.clone(),
            ));
            meta.push((name, kind, material, belt.take(), plane));
        }
    }
    let scene = SceneSurfaces::from_parts(items);
    // Bounded surfaces' extent first, so that a plane is cut to the whole scene.
    let (mut blo, mut bhi) = (None::<Vec3>, None::<Vec3>);
    let (probe, _) = scene.tessellate(lo, hi);
    for (m, info) in probe.iter().zip(&meta) {
        if info.4.is_some() {
            continue;
        }
        for &p in &m.points {
            blo = Some(blo.map_or(p, |x| x.min(p)));
            bhi = Some(bhi.map_or(p, |x| x.max(p)));
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
        .map(|(m, (name, kind, material, belt, plane))| {
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
            }
        })
        .collect();
    (surfaces, blo, bhi)
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
