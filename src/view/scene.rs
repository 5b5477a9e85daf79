//! The scene's surfaces for the viewer: rebuilt from the scenario as the run built them and
//! tessellated as the ParaView output draws them; planes cut to the scene's extent. A moving
//! part is tessellated at its rest pose and carried per frame by its body's motion, compiled
//! from the scenario as the run compiled it ([`Motion::of`] per unit, as `World` builds them).
//!
//! A roller is drawn with stripes along it (a two-tone band pattern, [`roller_stripes`]) so that
//! its own turn shows, and a powered roller's body is posed with its turn: w t at each frame's
//! time, [`Motion::pose`], through the same per-frame poses as every moving body. The page
//! interpolates a body's rotation between frames by the shorter way round (quaternion slerp),
//! which is the roller's true way only while it turns less than half a turn between frames: a
//! roller that turns more than [`MAX_TURN_PER_FRAME_RAD`] between two frames is drawn without
//! its turn and the page says so, rather than turning it the wrong way. A free-turning roller's
//! angle is the run's state ([`crate::world::free_roller`]), not a function of time: it is
//! posed with the angle the run recorded at each frame's sample (`rollers.csv`,
//! [`Motion::pose_spun`]), under the same limit on the turn between frames, taken from the
//! recorded angles. A run without `rollers.csv` (from before the file was written) draws its
//! free rollers without their turn, and the page says so.

use super::*;
use crate::world::motion::Motion;
use rapier3d_f64::math::Pose;

/// The largest turn of a roller about its own axis between two frames that the page draws
/// (rad): the quaternion slerp between frames takes the shorter way round, the true way for a
/// turn under half a turn (pi); a tenth of it is kept as margin, so that f32 poses and a turn
/// close to half a turn (which the eye cannot tell from its opposite anyway) are not drawn.
pub(super) const MAX_TURN_PER_FRAME_RAD: f64 = 0.9 * std::f64::consts::PI;

/// Number of stripes around a roller (half of them dark): with the 48 segments of its
/// tessellation, 6 segments a stripe.
const ROLLER_STRIPES: usize = 8;

/// What the page needs of one surface part besides its triangles.
struct PartMeta {
    name: String,
    kind: &'static str,
    material: String,
    belt: Option<Belt>,
    /// A plane's point and unit normal.
    plane: Option<(Vec3, Vec3)>,
    /// The index of the body that carries it, in `carried`.
    body: Option<usize>,
    /// A roller's pose (its axis is the pose's y axis), to stripe it.
    roller: Option<Pose>,
}

/// A moving body: its name; its pose per frame as drawn (with a powered roller's turn); its
/// move from the rest pose per frame without the turn (for the scene's extent: a roller is
/// round, and its turned bounding box would widen the scene); its origin at rest.
type Carried = (String, Vec<Pose>, Vec<Pose>, Vec3);

/// The surfaces of the scenario, tessellated at their rest poses; the bodies that carry the
/// moving ones, posed at each frame's time (`times`); the extent of the bounded surfaces over
/// the frames. A surface that cannot be rebuilt (a mesh file not found from `base`) is left out
/// with a note.
/// `spins` holds the free-turning rollers' recorded angles at the frames, if the run wrote them.
/// `lo`, `hi` bound the apples' centres, `apple_radius_m` is the largest apple's radius: a plane
/// is cut to reach at least three of it beyond the apples (a lone apple stands on a plate of
/// four diameters, not on a patch its own size).
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
pub(super) fn surfaces_of(
    sc: &Scenario,
    base: &Path,
    lo: Vec3,
    hi: Vec3,
    have_apples: bool,
    apple_radius_m: f64,
    times: &[f64],
    spins: Option<&RollerAngles>,
    notes: &mut Vec<String>,
) -> (Vec<SurfaceInfo>, Vec<MoverInfo>, Option<Vec3>, Option<Vec3>) {
    let mut items = Vec::new();
    let mut meta: Vec<PartMeta> = Vec::new();
    let mut carried: Vec<Carried> = Vec::new();
    let mut moving = Vec::new();
    let mut turning = Vec::new();
    let mut turning_free = Vec::new();
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
        let turn = roller_turn(s, times, spins);
        match turn {
            RollerTurn::None | RollerTurn::Drawn | RollerTurn::Recorded => {}
            RollerTurn::TooFast(per_frame) => notes.push(format!(
                "roller '{}' turns {per_frame:.2} rad about its own axis between two frames, more than the page can draw the right way round ({MAX_TURN_PER_FRAME_RAD:.2} rad, nine tenths of half a turn): drawn without its turn; a smaller output.sample_interval_s (or a larger --max-frames, up to the samples) shows it",
                s.name()
            )),
            RollerTurn::RecordedTooFast(per_frame) => notes.push(format!(
                "roller '{}' turns freely and, by the angles of rollers.csv, {per_frame:.2} rad about its own axis between two frames, more than the page can draw the right way round ({MAX_TURN_PER_FRAME_RAD:.2} rad, nine tenths of half a turn): drawn without its turn; a larger --max-frames (up to the samples) or a smaller output.sample_interval_s shows it",
                s.name()
            )),
            RollerTurn::Free => notes.push(format!(
                "roller '{}' turns freely in the run, and the run folder has no rollers.csv (its angle per sample; runs of applesim before it was written have none): drawn without its turn (its final rate and angle are in summary.json, free_rollers)",
                s.name()
            )),
        }
        let bodies: Vec<Option<usize>> = units
            .iter()
            .zip(&motions)
            .map(|(u, m)| {
                let m = m.as_ref()?;
                // A free roller's recorded angle per frame (read_rollers checked it has one).
                let angles = match turn {
                    RollerTurn::Recorded => spins.and_then(|sp| sp.get(u.name())),
                    _ => None,
                }
                .filter(|a| a.len() == times.len());
                let turned =
                    (turn == RollerTurn::Drawn || angles.is_some()) && m.spin_axis().is_some();
                if !(m.displaces() || turned) {
                    return None;
                }
                let place: Vec<Pose> = times.iter().map(|&t| m.carry(t)).collect();
                let drawn = times
                    .iter()
                    .enumerate()
                    .map(|(f, &t)| match angles {
                        Some(a) if turned => m.pose_spun(t, a[f]),
                        _ if turned => m.pose(t),
                        _ => m.pose_spun(t, 0.0),
                    })
                    .collect();
                carried.push((
                    u.name().to_string(),
                    drawn,
                    place,
                    m.rest_pose().translation,
                ));
                Some(carried.len() - 1)
            })
            .collect();
        if motions.iter().flatten().any(Motion::displaces) {
            moving.push(format!("'{}'", s.name()));
        }
        match turn {
            RollerTurn::Drawn => turning.push(format!("'{}'", s.name())),
            RollerTurn::Recorded => turning_free.push(format!("'{}'", s.name())),
            _ => {}
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
            meta.push(PartMeta {
                name,
                kind,
                material,
                belt: belt.take(),
                plane,
                body,
                roller: matches!(s, SurfaceSpec::Roller(_) | SurfaceSpec::RollerBed(_))
                    .then_some(p.collider.position),
            });
        }
    }
    if !moving.is_empty() {
        notes.push(format!(
            "moving surface(s) {} drawn at their pose of each frame (from their `motion`), moving in a straight line between frames",
            moving.join(", ")
        ));
    }
    if !turning.is_empty() {
        let gap = max_gap(times);
        notes.push(format!(
            "roller(s) {} drawn turning about their own axes (w t at each frame's time; the stripes show the turn), by the shorter way round between frames ({} frames, at most {gap:.3} s apart)",
            turning.join(", "),
            times.len()
        ));
    }
    if !turning_free.is_empty() {
        let gap = max_gap(times);
        notes.push(format!(
            "free-turning roller(s) {} drawn turning about their own axes at the angles rollers.csv recorded at each frame's time (the stripes show the turn), by the shorter way round between frames ({} frames, at most {gap:.3} s apart)",
            turning_free.join(", "),
            times.len()
        ));
    }
    let scene = SceneSurfaces::from_parts(items);
    // Bounded surfaces' extent first, so that a plane is cut to the whole scene.
    let (mut blo, mut bhi) = (None::<Vec3>, None::<Vec3>);
    let (probe, _) = scene.tessellate(lo, hi);
    for (m, info) in probe.iter().zip(&meta) {
        if info.plane.is_some() || m.points.is_empty() {
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
        let poses = info.body.map_or(&rest[..], |k| &carried[k].2[..]);
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
    let (alo, ahi) = (
        lo - Vec3::splat(apple_radius_m),
        hi + Vec3::splat(apple_radius_m),
    );
    let (clo, chi) = match (have_apples, blo, bhi) {
        (true, Some(a), Some(b)) => (alo.min(a), ahi.max(b)),
        (true, _, _) => (alo, ahi),
        (false, Some(a), Some(b)) => (a, b),
        (false, _, _) => (Vec3::splat(-0.5), Vec3::splat(0.5)),
    };
    // A plane is cut to the scene: the rectangle its box (padded by a tenth, and by at least
    // three apple radii or 2 cm) covers when projected onto it (tessellate() draws a square
    // twice the box's diagonal, for ParaView).
    let pad = (chi - clo) * 0.1 + Vec3::splat((3.0 * apple_radius_m).max(0.02));
    let (clo, chi) = (clo - pad, chi + pad);
    let (meshes, warnings) = scene.tessellate(clo, chi);
    notes.extend(warnings);
    let surfaces = meshes
        .into_iter()
        .zip(meta)
        .map(|(m, info)| {
            let m = match info.plane {
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
                name: info.name,
                kind: info.kind,
                material: info.material,
                triangles_b64: b64(&bytes),
                stripes_b64: info.roller.map(|pose| b64(&roller_stripes(&m, &pose))),
                belt: info.belt,
                mover: info.body,
            }
        })
        .collect();
    let movers = carried
        .into_iter()
        .map(|(name, poses, _, origin)| {
            let mut bytes = Vec::with_capacity(poses.len() * 28);
            for p in &poses {
                let (t, q) = (p.translation, p.rotation);
                for x in [t.x, t.y, t.z, q.x, q.y, q.z, q.w] {
                    bytes.extend_from_slice(&(x as f32).to_le_bytes());
                }
            }
            MoverInfo {
                name,
                origin_m: [origin.x, origin.y, origin.z],
                poses_b64: b64(&bytes),
                poses,
            }
        })
        .collect();
    (surfaces, movers, blo, bhi)
}

/// How a roller spec's own turn is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
enum RollerTurn {
    /// Not a roller, or one that does not turn.
    None,
    /// Powered: posed with its turn w t at each frame.
    Drawn,
    /// Powered, but turning this much (rad) between two frames: more than
    /// [`MAX_TURN_PER_FRAME_RAD`].
    TooFast(f64),
    /// Free-turning, and the run recorded no angle per sample (no `rollers.csv`).
    Free,
    /// Free-turning: posed with its angle recorded at each frame (`rollers.csv`).
    Recorded,
    /// Free-turning, but a roller of it turned this much (rad) between two frames by its
    /// recorded angles: more than [`MAX_TURN_PER_FRAME_RAD`].
    RecordedTooFast(f64),
}

/// How the rollers of `s` (a roller, or a bed's rollers: powered ones all turning alike, free
/// ones each at its recorded angles in `spins`) are drawn turning over the frames at `times`.
fn roller_turn(s: &SurfaceSpec, times: &[f64], spins: Option<&RollerAngles>) -> RollerTurn {
    let (w, free) = match s {
        SurfaceSpec::Roller(r) => (r.angular_velocity_rad_s, r.free_turning.is_some()),
        SurfaceSpec::RollerBed(b) => (b.angular_velocity_rad_s, b.free_turning.is_some()),
        _ => return RollerTurn::None,
    };
    if free {
        // The largest recorded step between two frames of any of its rollers.
        let mut per_frame = 0.0f64;
        for u in s.units() {
            let Some(a) = spins.and_then(|sp| sp.get(u.name())) else {
                return RollerTurn::Free;
            };
            per_frame = a
                .windows(2)
                .map(|w| (w[1] - w[0]).abs())
                .fold(per_frame, f64::max);
        }
        return if per_frame > MAX_TURN_PER_FRAME_RAD {
            RollerTurn::RecordedTooFast(per_frame)
        } else {
            RollerTurn::Recorded
        };
    }
    if w == 0.0 || !w.is_finite() {
        return RollerTurn::None;
    }
    let per_frame = w.abs() * max_gap(times);
    if per_frame > MAX_TURN_PER_FRAME_RAD {
        RollerTurn::TooFast(per_frame)
    } else {
        RollerTurn::Drawn
    }
}

/// The longest time between two consecutive frames (s; 0 for one frame).
fn max_gap(times: &[f64]) -> f64 {
    times.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max)
}

/// One byte per triangle of a roller's mesh `m` (at its rest pose `pose`, axis along the
/// pose's y): 1 for a triangle of a dark stripe, 0 for a light one. The side is cut into
/// [`ROLLER_STRIPES`] bands along the axis, alternately dark and light, by the angle of each
/// triangle's centroid about the axis from the pose's x axis (where the tessellation's first
/// segment starts, so that the bands' edges fall on segment edges); the end caps (triangles
/// facing along the axis, fanned from a rim point rather than the centre) are light.
pub(super) fn roller_stripes(m: &crate::output::vtk::Mesh, pose: &Pose) -> Vec<u8> {
    let (c, axis) = (pose.translation, pose.rotation * Vec3::Y);
    let (u, v) = (pose.rotation * Vec3::X, pose.rotation * Vec3::Z);
    let band = std::f64::consts::TAU / ROLLER_STRIPES as f64;
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, d] = t.map(|k| m.points[k as usize]);
            let n = (b - a).cross(d - a).normalize_or_zero();
            if n.dot(axis).abs() > 0.5 {
                return 0;
            }
            let r = (a + b + d) / 3.0 - c;
            let angle = r.dot(v).atan2(r.dot(u)).rem_euclid(std::f64::consts::TAU);
            ((angle / band) as usize % 2) as u8
        })
        .collect()
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

    /// Frame poses of a mover, as f32: per frame translation x y z, quaternion x y z w.
    fn poses(m: &MoverInfo) -> Vec<[f32; 7]> {
        unb64(&m.poses_b64)
            .chunks(28)
            .map(|p| {
                std::array::from_fn(|k| f32::from_le_bytes(p[4 * k..4 * k + 4].try_into().unwrap()))
            })
            .collect()
    }

    /// A scenario of steel surfaces only: `surfaces`, the JSON of its surfaces list's items.
    fn steel_scene(surfaces: &str) -> Scenario {
        crate::scenario::from_json(
            &format!(
                r#"{{"duration_s": 1, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -9.81],
                "materials": {{"steel": {{"youngs_modulus_pa": 2e11, "poisson_ratio": 0.28}}}},
                "contact": {{"friction": 0.3, "ke": 0.09, "lambda_s_m": 1000}},
                "surfaces": [{surfaces}]}}"#
            ),
            "test",
        )
        .unwrap()
    }

    /// A roller bed carried by a `motion` is one body per roller, as the world builds it: each
    /// roller's part has its own mover, its origin the roller's centre, posed per frame by the
    /// translation and its own turn w t about its axis; a powered roller that only turns has a
    /// mover too, turning in place. A free-turning roller (angle not recorded) and one turning more than
    /// [`MAX_TURN_PER_FRAME_RAD`] between frames have none, and the notes say why. Every roller
    /// is striped: half of its side's triangles dark, its caps light.
    #[test]
    fn a_roller_bed_has_a_body_per_roller_and_powered_rollers_turn() {
        let sc = steel_scene(
            r#"
                  {"type": "roller_bed", "name": "bed", "material": "steel", "radius_m": 0.03,
                   "length_m": 0.4, "position_m": [0, 0, 0], "axis": [0, 1, 0], "pitch_m": 0.08,
                   "pitch_direction": [1, 0, 0], "count": 3, "angular_velocity_rad_s": 5,
                   "motion": {"translation": {"velocity_m_s": [0.5, 0, 0]}}},
                  {"type": "roller", "name": "spin", "material": "steel", "radius_m": 0.03,
                   "length_m": 0.4, "position_m": [0, 1, 0], "axis": [0, 1, 0],
                   "angular_velocity_rad_s": 5},
                  {"type": "roller", "name": "fast", "material": "steel", "radius_m": 0.03,
                   "length_m": 0.4, "position_m": [0, 2, 0], "axis": [0, 1, 0],
                   "angular_velocity_rad_s": 15},
                  {"type": "roller", "name": "free", "material": "steel", "radius_m": 0.03,
                   "length_m": 0.4, "position_m": [0, 3, 0], "axis": [0, 1, 0],
                   "free_turning": {"moment_of_inertia_kg_m2": 1e-3}}
                "#,
        );
        let mut notes = Vec::new();
        let (surfaces, movers, _, _) = surfaces_of(
            &sc,
            Path::new("."),
            Vec3::ZERO,
            Vec3::ONE,
            false,
            0.0,
            &[0.0, 0.2],
            None,
            &mut notes,
        );
        let bodies: Vec<Option<usize>> = surfaces.iter().map(|s| s.mover).collect();
        assert_eq!(bodies, [Some(0), Some(1), Some(2), Some(3), None, None]);
        assert_eq!(movers.len(), 4);
        // Each body's origin is its roller's centre c, where its pose puts it at t = 0; at
        // frame 1 (t = 0.2 s) turned 1 rad about y, and the bed's 0.1 m along x: T(c + d) R.
        let q = rapier3d_f64::math::Rotation::from_axis_angle(Vec3::Y, 1.0);
        let centres = [(0.0, 0.1), (0.08, 0.1), (0.16, 0.1), (0.0, 0.0)];
        for (m, &(x, d)) in movers.iter().zip(&centres) {
            let f = poses(m);
            let c = Vec3::new(x, if d == 0.0 { 1.0 } else { 0.0 }, 0.0);
            assert_eq!(m.origin_m, [c.x, c.y, c.z]);
            assert_eq!(f[0], [c.x as f32, c.y as f32, 0.0, 0.0, 0.0, 0.0, 1.0]);
            let p = c + Vec3::new(d, 0.0, 0.0);
            let want = [p.x, p.y, p.z, q.x, q.y, q.z, q.w];
            for k in 0..7 {
                assert!(
                    (f[1][k] as f64 - want[k]).abs() < 1e-7,
                    "{}: {:?} vs {want:?}",
                    m.name,
                    f[1]
                );
            }
        }
        for s in &surfaces {
            let st = unb64(s.stripes_b64.as_ref().unwrap());
            // 48 segments: 96 side triangles, 2 x 46 cap triangles.
            assert_eq!(st.len(), 96 + 92, "{}", s.name);
            assert_eq!(st.iter().filter(|&&x| x == 1).count(), 48, "{}", s.name);
        }
        let notes = notes.join("\n");
        assert!(
            notes.contains("roller(s) 'bed', 'spin' drawn turning about their own axes"),
            "{notes}"
        );
        assert!(
            notes.contains("roller 'fast' turns 3.00 rad about its own axis between two frames"),
            "{notes}"
        );
        assert!(notes.contains("roller 'free' turns freely"), "{notes}");
        assert!(notes.contains("moving surface(s) 'bed' drawn"), "{notes}");
        assert!(!notes.contains("a cylinder looks the same"), "{notes}");
    }

    /// Free-turning rollers with recorded angles (rollers.csv's, here given directly): one whose
    /// angle steps stay under [`MAX_TURN_PER_FRAME_RAD`] gets a mover posed at the recorded
    /// angle of each frame; one that turns 3 rad between two frames (more than the page can
    /// draw the right way round) gets none, and the note gives its largest step.
    #[test]
    fn free_rollers_are_posed_at_their_recorded_angles_unless_too_fast() {
        let sc = steel_scene(
            r#"
                  {"type": "roller", "name": "slow", "material": "steel", "radius_m": 0.03,
                   "length_m": 0.4, "position_m": [0, 0, 0], "axis": [0, 1, 0],
                   "free_turning": {"moment_of_inertia_kg_m2": 1e-3}},
                  {"type": "roller", "name": "quick", "material": "steel", "radius_m": 0.03,
                   "length_m": 0.4, "position_m": [0, 1, 0], "axis": [0, 1, 0],
                   "free_turning": {"moment_of_inertia_kg_m2": 1e-3}}
                "#,
        );
        let spins: RollerAngles = [
            ("slow".to_string(), vec![0.0, 0.5, 1.25]),
            ("quick".to_string(), vec![0.0, 1.0, 4.0]),
        ]
        .into_iter()
        .collect();
        let mut notes = Vec::new();
        let (surfaces, movers, _, _) = surfaces_of(
            &sc,
            Path::new("."),
            Vec3::ZERO,
            Vec3::ONE,
            false,
            0.0,
            &[0.0, 0.1, 0.2],
            Some(&spins),
            &mut notes,
        );
        let bodies: Vec<Option<usize>> = surfaces.iter().map(|s| s.mover).collect();
        assert_eq!(bodies, [Some(0), None]);
        assert_eq!(movers.len(), 1);
        let f = poses(&movers[0]);
        for (k, &angle) in [0.0f64, 0.5, 1.25].iter().enumerate() {
            let q = rapier3d_f64::math::Rotation::from_axis_angle(Vec3::Y, angle);
            let want = [0.0, 0.0, 0.0, q.x, q.y, q.z, q.w];
            for j in 0..7 {
                assert!(
                    (f[k][j] as f64 - want[j]).abs() < 1e-7,
                    "frame {k}: {:?} vs {want:?}",
                    f[k]
                );
            }
        }
        let notes = notes.join("\n");
        assert!(
            notes.contains("roller 'quick' turns freely and, by the angles of rollers.csv, 3.00 rad about its own axis between two frames"),
            "{notes}"
        );
        assert!(!notes.contains("roller 'slow' turns freely and"), "{notes}");
    }
}
