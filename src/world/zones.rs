//! Where in the line a point lies at a given time: inside a bin (its walls at their pose then),
//! over a part (a belt, a chute, a box, a roller bed, a mesh, a plane), or in the air. The line
//! audit counts an apple-apple hit at the part where its contact point lies
//! (`analysis::audit::points_of`), not at the surface an apple touched last: a hit among the
//! apples in a bin belongs to the bin, whatever chute the falling apple came down.
//!
//! Every zone keeps the pose of its part at t = 0 and, for a moving part, the motion that carries
//! it (`world::motion`): a lowered bin's inside is where the bin is at the moment of the hit.

use super::motion::Motion;
use super::World;
use crate::layer::SurfaceId;
use crate::math::Vec3;
use rapier3d_f64::math::Pose;

/// The shape of a zone, in its part's frame.
#[derive(Debug, Clone, PartialEq)]
enum Shape {
    /// A bin's inside: x, y within the inner length and width about the floor's centre, z from
    /// the floor's top face (the frame's origin) up to the walls' top.
    Bin {
        /// Inner length, width and wall height (m).
        inner_size_m: [f64; 3],
    },
    /// A part's box (its collider's local bounding box): the point is over the part when it lies
    /// above the box, within the reach, along the scene's up.
    Part {
        /// Centre of the box in the part's frame.
        centre: Vec3,
        /// Half extents.
        half: Vec3,
    },
    /// An infinite plane: the frame's origin on it, its +z the normal.
    Plane,
}

/// One zone.
#[derive(Debug, Clone, PartialEq)]
struct Zone {
    /// The part's name (a bin's, or a surface part's: `bed/3` for a roller of a bed).
    name: String,
    shape: Shape,
    /// The part's frame at t = 0 with every motion offset zero (world).
    frame: Pose,
    /// The motion that carries it, if it moves.
    motion: Option<Motion>,
}

impl Zone {
    fn frame_at(&self, t_s: f64) -> Pose {
        match &self.motion {
            Some(m) => m.carry(t_s) * self.frame,
            None => self.frame,
        }
    }
}

/// Where a point lies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Location<'a> {
    /// Inside the bin of this name: between its walls, up to the walls' top.
    InBin(&'a str),
    /// Above the inside of the bin of this name, within the reach (on a heap over the rim).
    OverBin(&'a str),
    /// Over the part of this name (a surface part's name), within the reach.
    Over(&'a str),
    /// Over nothing within the reach.
    Air,
}

/// The zones of a scene.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Zones {
    zones: Vec<Zone>,
    /// Against gravity (unit); `None` without gravity (nothing is over anything then).
    up: Option<Vec3>,
}

impl Zones {
    /// The zones of a built world: its bins, and every surface part that is not a bin's wall.
    pub fn of(world: &World) -> Self {
        let mut zones: Vec<Zone> = world
            .bins
            .iter()
            .map(|b| Zone {
                name: b.name.clone(),
                shape: Shape::Bin {
                    inner_size_m: b.inner_size_m,
                },
                frame: b.frame,
                motion: b.motion.clone(),
            })
            .collect();
        let walls: Vec<String> = world.bins.iter().map(|b| format!("{}/", b.name)).collect();
        for (k, &ch) in world.surface_colliders.iter().enumerate() {
            let name = world.layer.surface_name(SurfaceId(k as u32));
            if walls.iter().any(|w| name.starts_with(w.as_str())) {
                continue;
            }
            let Some(co) = world.physics.colliders.get(ch) else {
                continue;
            };
            let (frame, motion) = match world.surface_motion(k) {
                Some((m, on_body)) => (m.rest_pose() * on_body, Some(m.clone())),
                None => (*co.position(), None),
            };
            let shape = if co.shape().as_halfspace().is_some() {
                Shape::Plane
            } else {
                let b = co.shape().compute_local_aabb();
                Shape::Part {
                    centre: (b.mins + b.maxs) * 0.5,
                    half: (b.maxs - b.mins) * 0.5,
                }
            };
            let frame = match (&shape, co.shape().as_halfspace()) {
                // The plane's frame: origin on it, +z its normal.
                (Shape::Plane, Some(h)) => {
                    let n = frame.rotation * h.normal;
                    Pose::from_parts(
                        frame.translation,
                        rapier3d_f64::math::Rotation::from_rotation_arc(Vec3::Z, n),
                    )
                }
                _ => frame,
            };
            zones.push(Zone {
                name: name.to_string(),
                shape,
                frame,
                motion,
            });
        }
        let g = world.physics.gravity;
        Zones {
            zones,
            up: (g.length() > 0.0).then(|| -g / g.length()),
        }
    }

    /// Whether `name` is one of the scene's bins.
    pub fn is_bin(&self, name: &str) -> bool {
        self.zones
            .iter()
            .any(|z| z.name == name && matches!(z.shape, Shape::Bin { .. }))
    }

    /// Where the point `p` lies at time `t_s`: inside a bin first (between its walls), else over
    /// the part nearest below it within `reach_m` (a bin's inside counts, on the heap above its
    /// walls), else in the air.
    pub fn locate(&self, p: Vec3, t_s: f64, reach_m: f64) -> Location<'_> {
        for z in &self.zones {
            if let Shape::Bin { inner_size_m } = z.shape {
                let q = z.frame_at(t_s).inverse_transform_point(p);
                let [lx, ly, h] = inner_size_m;
                if q.x.abs() <= lx / 2.0 && q.y.abs() <= ly / 2.0 && q.z >= 0.0 && q.z <= h {
                    return Location::InBin(&z.name);
                }
            }
        }
        let Some(up) = self.up else {
            return Location::Air;
        };
        // The part nearest below: the smallest height above it.
        let mut best: Option<(f64, &Zone)> = None;
        for z in &self.zones {
            let pose = z.frame_at(t_s);
            let height = match &z.shape {
                Shape::Bin { inner_size_m } => {
                    let q = pose.inverse_transform_point(p);
                    let [lx, ly, h] = *inner_size_m;
                    (q.x.abs() <= lx / 2.0 && q.y.abs() <= ly / 2.0 && q.z > h)
                        .then(|| (q.z - h).max(0.0))
                        .filter(|&d| d <= reach_m)
                }
                Shape::Plane => {
                    let n = pose.rotation * Vec3::Z;
                    let d = (p - pose.translation).dot(n);
                    // Above the plane within the reach, measured along the plane's normal.
                    (n.dot(up) > 0.0 && (0.0..=reach_m).contains(&d)).then_some(d)
                }
                Shape::Part { centre, half } => {
                    let q = pose.inverse_transform_point(p) - *centre;
                    let down = pose.rotation.inverse() * -up;
                    segment_entry(q, down, *half, reach_m)
                }
            };
            if let Some(h) = height {
                if best.is_none_or(|(b, _)| h < b) {
                    best = Some((h, z));
                }
            }
        }
        match best {
            Some((_, z)) if matches!(z.shape, Shape::Bin { .. }) => Location::OverBin(&z.name),
            Some((_, z)) => Location::Over(&z.name),
            None => Location::Air,
        }
    }
}

/// How far along the unit direction `d` the segment from `q` of length `len` enters the box of
/// half extents `half` centred at the origin (0 when `q` is inside), or `None` if it misses it
/// (the slab method).
fn segment_entry(q: Vec3, d: Vec3, half: Vec3, len: f64) -> Option<f64> {
    let (mut t0, mut t1) = (0.0f64, len);
    for (o, v, e) in [(q.x, d.x, half.x), (q.y, d.y, half.y), (q.z, d.z, half.z)] {
        if v.abs() < 1e-15 {
            if o.abs() > e {
                return None;
            }
        } else {
            let (a, b) = ((-e - o) / v, (e - o) / v);
            let (a, b) = if a < b { (a, b) } else { (b, a) };
            t0 = t0.max(a);
            t1 = t1.min(b);
            if t0 > t1 {
                return None;
            }
        }
    }
    Some(t0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_enter_boxes_where_they_should() {
        let half = Vec3::new(1.0, 1.0, 0.5);
        let down = Vec3::new(0.0, 0.0, -1.0);
        // 0.3 above the top face: entered after 0.3.
        let t = segment_entry(Vec3::new(0.0, 0.0, 0.8), down, half, 1.0).unwrap();
        assert!((t - 0.3).abs() < 1e-12);
        // Out of reach, beside the box, inside it.
        assert_eq!(
            segment_entry(Vec3::new(0.0, 0.0, 2.0), down, half, 1.0),
            None
        );
        assert_eq!(
            segment_entry(Vec3::new(1.5, 0.0, 0.8), down, half, 1.0),
            None
        );
        assert_eq!(
            segment_entry(Vec3::new(0.5, 0.5, 0.0), down, half, 1.0),
            Some(0.0)
        );
    }
}
