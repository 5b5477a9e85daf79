//! Layout helpers: components placed relative to each other instead of in absolute
//! coordinates, resolved once when a scenario is loaded (before validation and the world).
//!
//! A line designer thinks "the chute's top edge 10 mm past the belt's discharge end and 40 mm
//! below it; the bin under the chute's end": a surface's `place` puts one of its **ports** (a
//! named point: a conveyor's `feed` and `discharge` ends, a chute's `top` and `bottom` edges, a
//! box's `top`, `start`, `end`, a bin's `floor` and `rim`) at another surface's port, moved on
//! by `gap_m` along that surface's flow (horizontally), `side_m` to the left of it and `drop_m`
//! down (world z is up, the README's convention). A listed apple or a source can be put `on` a
//! surface at a distance along its flow from its upstream port, resting on its top face.
//!
//! The resolved positions are written into `position_m`, so `scenario.json` (the scenario as
//! run) holds both; a `position_m` given beside a `place` must agree with it.

use super::ranges::{self, num};
use super::surfaces::{ChuteProfile, RotationSpec, SurfaceSpec};
use super::{Scenario, ScenarioError};
use crate::math::{vec3, Vec3};
use rapier3d_f64::math::Rotation;
use serde::{Deserialize, Serialize};

/// Where a surface goes, relative to another surface (`surfaces[].place`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaceSpec {
    /// `SURFACE.PORT`: the port of another surface this surface's `anchor` is put at.
    pub at: String,
    /// This surface's port that goes there (default: its upstream port: a conveyor's `feed`, a
    /// chute's `top`, a box's `start`, a bin's `floor`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor: Option<String>,
    /// Horizontal distance beyond the port along the other surface's flow (m).
    #[serde(default)]
    pub gap_m: f64,
    /// Distance below the port (m; negative raises).
    #[serde(default)]
    pub drop_m: f64,
    /// Distance to the left of the other surface's flow, horizontally (m).
    #[serde(default)]
    pub side_m: f64,
}

/// Where a listed apple or a source starts, on a surface (`apples[].on`, `sources[].on`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OnSpec {
    /// The surface (a conveyor, chute or box).
    pub surface: String,
    /// Distance along the surface's flow from its upstream port, along the surface (m).
    #[serde(default)]
    pub along_m: f64,
    /// Distance to the left of the flow, across the surface (m).
    #[serde(default)]
    pub side_m: f64,
    /// Gap between the apple and the surface (m; default 1 mm: the apple is set down).
    #[serde(default = "default_clearance")]
    pub clearance_m: f64,
}

fn default_clearance() -> f64 {
    1e-3
}

/// The value of a `position_m` left out: resolved by a `place` or `on`, refused otherwise.
pub fn unset() -> [f64; 3] {
    [f64::NAN; 3]
}

fn is_unset(p: &[f64; 3]) -> bool {
    p.iter().all(|x| x.is_nan())
}

/// A surface's frame for ports: position, orientation (with a chute's incline), the local
/// offsets of its ports, and its flow along local +x (or -x).
struct Frame {
    rotation: Rotation,
    /// (name, local offset from `position_m`)
    ports: Vec<(&'static str, Vec3)>,
    /// Flow direction, local.
    flow: Vec3,
    /// Outward normal of the face apples ride on, local.
    up: Vec3,
    /// Length of the face apples ride on, along the flow from the upstream port (m).
    length_m: f64,
    /// Half its width across the flow (m); `None` for a trough, whose apples ride on its
    /// bottom line.
    half_width_m: Option<f64>,
}

fn rotation(r: &Option<RotationSpec>, field: &str) -> Result<Rotation, ScenarioError> {
    match r {
        Some(r) => r.to_rotation(&format!("{field}.rotation")),
        None => Ok(Rotation::IDENTITY),
    }
}

/// The frame of a surface that has ports, its sizes range-checked first (a port of a belt
/// 1e308 m long is no place: the belt's `size_m` is the mistake, not the place's).
fn frame_of(s: &SurfaceSpec, field: &str) -> Result<Option<Frame>, ScenarioError> {
    let sizes = |name: &str, v: [f64; 3]| ranges::LENGTH.check_each(&format!("{field}.{name}"), v);
    let size = |name: &str, x: f64| ranges::LENGTH.check(&format!("{field}.{name}"), x);
    match s {
        SurfaceSpec::Conveyor(c) => sizes("size_m", c.size_m)?,
        SurfaceSpec::Box(b) => sizes("size_m", b.size_m)?,
        SurfaceSpec::Chute(c) => {
            size("length_m", c.length_m)?;
            ranges::INCLINE.check(&format!("{field}.incline_deg"), c.incline_deg)?;
            if let Some(w) = c.width_m {
                size("width_m", w)?;
            }
        }
        SurfaceSpec::Bin(b) => sizes("inner_size_m", b.inner_size_m)?,
        _ => {}
    }
    Ok(Some(match s {
        SurfaceSpec::Conveyor(c) => {
            let [l, _, t] = c.size_m;
            let sign = if c.belt_velocity_m_s < 0.0 { -1.0 } else { 1.0 };
            Frame {
                rotation: rotation(&c.rotation, field)?,
                ports: vec![
                    ("feed", Vec3::new(-sign * l / 2.0, 0.0, t / 2.0)),
                    ("discharge", Vec3::new(sign * l / 2.0, 0.0, t / 2.0)),
                ],
                flow: Vec3::new(sign, 0.0, 0.0),
                up: Vec3::Z,
                length_m: l,
                half_width_m: Some(c.size_m[1] / 2.0),
            }
        }
        SurfaceSpec::Box(b) => {
            let [l, _, h] = b.size_m;
            Frame {
                rotation: rotation(&b.rotation, field)?,
                ports: vec![
                    ("start", Vec3::new(-l / 2.0, 0.0, h / 2.0)),
                    ("top", Vec3::new(0.0, 0.0, h / 2.0)),
                    ("end", Vec3::new(l / 2.0, 0.0, h / 2.0)),
                ],
                flow: Vec3::X,
                up: Vec3::Z,
                length_m: l,
                half_width_m: Some(b.size_m[1] / 2.0),
            }
        }
        SurfaceSpec::Chute(c) => {
            // `position_m` is the centre of a flat chute's top face, of a trough's bottom line:
            // the line apples run along, in both cases (src/world/surfaces.rs).
            Frame {
                rotation: rotation(&c.rotation, field)?
                    * Rotation::from_rotation_y(c.incline_deg.to_radians()),
                ports: vec![
                    ("top", Vec3::new(-c.length_m / 2.0, 0.0, 0.0)),
                    ("bottom", Vec3::new(c.length_m / 2.0, 0.0, 0.0)),
                ],
                flow: Vec3::X,
                up: Vec3::Z,
                length_m: c.length_m,
                // A flat chute without its width is refused by validation, naming width_m.
                half_width_m: match c.profile {
                    ChuteProfile::Trough => None,
                    ChuteProfile::Flat => Some(c.width_m.map_or(f64::INFINITY, |w| w / 2.0)),
                },
            }
        }
        SurfaceSpec::Bin(b) => Frame {
            rotation: rotation(&b.rotation, field)?,
            ports: vec![
                ("floor", Vec3::ZERO),
                ("rim", Vec3::new(0.0, 0.0, b.inner_size_m[2])),
            ],
            flow: Vec3::X,
            up: Vec3::Z,
            length_m: b.inner_size_m[0],
            half_width_m: Some(b.inner_size_m[1] / 2.0),
        },
        SurfaceSpec::Plane(_)
        | SurfaceSpec::Mesh(_)
        | SurfaceSpec::Roller(_)
        | SurfaceSpec::RollerBed(_) => return Ok(None),
    }))
}

/// A surface's `place` and mutable `position_m`, if it can have one.
fn place_of(s: &mut SurfaceSpec) -> Option<(&Option<PlaceSpec>, &mut [f64; 3])> {
    match s {
        SurfaceSpec::Conveyor(c) => Some((&c.place, &mut c.position_m)),
        SurfaceSpec::Box(b) => Some((&b.place, &mut b.position_m)),
        SurfaceSpec::Chute(c) => Some((&c.place, &mut c.position_m)),
        SurfaceSpec::Bin(b) => Some((&b.place, &mut b.position_m)),
        SurfaceSpec::Plane(_)
        | SurfaceSpec::Mesh(_)
        | SurfaceSpec::Roller(_)
        | SurfaceSpec::RollerBed(_) => None,
    }
}

fn kind(s: &SurfaceSpec) -> &'static str {
    match s {
        SurfaceSpec::Plane(_) => "plane",
        SurfaceSpec::Box(_) => "box",
        SurfaceSpec::Conveyor(_) => "conveyor",
        SurfaceSpec::Chute(_) => "chute",
        SurfaceSpec::Bin(_) => "bin",
        SurfaceSpec::Mesh(_) => "mesh",
        SurfaceSpec::Roller(_) => "roller",
        SurfaceSpec::RollerBed(_) => "roller bed",
    }
}

fn port_names(f: &Frame) -> String {
    f.ports.iter().map(|p| p.0).collect::<Vec<_>>().join(", ")
}

/// The horizontal unit vector of `v` (world z up), or x if `v` is vertical.
fn horizontal(v: Vec3) -> Vec3 {
    let h = Vec3::new(v.x, v.y, 0.0);
    if h.length() > 1e-12 {
        h.normalize()
    } else {
        Vec3::X
    }
}

/// A placed position, or the one given: a `position_m` beside a `place` must agree with it.
fn settle(pos: &mut [f64; 3], want: Vec3, field: &str) -> Result<(), ScenarioError> {
    let w = [want.x, want.y, want.z];
    if is_unset(pos) {
        *pos = w;
        return Ok(());
    }
    let close = pos
        .iter()
        .zip(w)
        .all(|(a, b)| (a - b).abs() <= 1e-9 * (1.0 + b.abs()));
    if close {
        // Keep the digits the user wrote.
        Ok(())
    } else {
        Err(ScenarioError::invalid(
            format!("{field}.position_m"),
            format!(
                "[{}, {}, {}] disagrees with the place it is given, [{}, {}, {}]: leave position_m out, or the place",
                pos[0], pos[1], pos[2], w[0], w[1], w[2]
            ),
        ))
    }
}

/// Resolves every `place` and `on` of the scenario into `position_m`, and refuses a
/// `position_m` left out without one, naming the field.
pub fn resolve(sc: &mut Scenario) -> Result<(), ScenarioError> {
    resolve_surfaces(&mut sc.surfaces)?;
    // The sizes first: an apple set `on` a surface sits its radius above it, so a diameter out of
    // range is named as itself, not as the place it would put the apple.
    for (k, a) in sc.apples.iter_mut().enumerate() {
        let field = format!("apples[{k}]");
        if a.on.is_some() {
            ranges::DIAMETER.check(&format!("{field}.diameter_m"), a.diameter_m)?;
        }
        if a.on.is_some() && a.is_spheroid() {
            // A spheroid rests on the point of it lowest along the face's normal: its centre
            // stands its support distance above the face (exact on a flat face; in a trough, the
            // same height above its bottom line).
            super::validate::shape(&field, a.diameter_m, a.height_m)?;
            let turned = a.orientation(&field)?;
            let shape = a.spheroid();
            let support = |up: Vec3| shape.point_with_normal(&turned, -up).support_m;
            put_on(
                &sc.surfaces,
                &a.on.clone(),
                &mut a.position_m,
                support,
                &field,
            )?;
            continue;
        }
        let r = 0.5 * a.diameter_m;
        put_on(
            &sc.surfaces,
            &a.on.clone(),
            &mut a.position_m,
            |_| r,
            &field,
        )?;
    }
    for (k, s) in sc.sources.iter_mut().enumerate() {
        let field = format!("sources[{k}]");
        if s.on.is_some() {
            s.diameter_m.validate(&format!("{field}.diameter_m"))?;
            if let Some(a) = &s.aspect {
                a.validate(&format!("{field}.aspect"))?;
            }
        }
        // Its apples are turned at random: the largest just clears the face however it turns.
        let r = 0.5
            * super::generators::AspectSpec::bounding_diameter_m(
                s.aspect.as_ref(),
                s.diameter_m.max_m(),
            );
        put_on(
            &sc.surfaces,
            &s.on.clone(),
            &mut s.position_m,
            |_| r,
            &field,
        )?;
    }
    Ok(())
}

/// Puts the centre at `pos` `on` a surface: `radius(up)` above its face, `up` the face's
/// outward normal (world).
fn put_on(
    surfaces: &[SurfaceSpec],
    on: &Option<OnSpec>,
    pos: &mut [f64; 3],
    radius: impl Fn(Vec3) -> f64,
    field: &str,
) -> Result<(), ScenarioError> {
    let Some(on) = on else {
        if is_unset(pos) {
            return Err(ScenarioError::invalid(
                format!("{field}.position_m"),
                "missing: give the position, or `on` a surface",
            ));
        }
        return Ok(());
    };
    let names: Vec<&str> = surfaces.iter().map(|s| s.name()).collect();
    let (k, s) = surfaces
        .iter()
        .enumerate()
        .find(|(_, s)| s.name() == on.surface)
        .ok_or_else(|| {
            ScenarioError::invalid(
                format!("{field}.on.surface"),
                format!(
                    "no surface named '{}' (surfaces: {})",
                    on.surface,
                    names.join(", ")
                ),
            )
        })?;
    let sf = format!("surfaces[{k}]");
    let frame = frame_of(s, &sf)?
        .filter(|_| !matches!(s, SurfaceSpec::Bin(_)))
        .ok_or_else(|| {
            ScenarioError::invalid(
                format!("{field}.on.surface"),
                format!(
                    "'{}' is a {}: an apple can be put on a conveyor, a chute or a box",
                    on.surface,
                    kind(s)
                ),
            )
        })?;
    let origin = surface_position(s);
    if is_unset(&origin) {
        return Err(ScenarioError::invalid(
            format!("{sf}.position_m"),
            "missing: give the position, or a `place`",
        ));
    }
    ranges::POSITION.check_each(&format!("{sf}.position_m"), origin)?;
    // The apple's centre must be over the face it is put on: off it, the apple would start in
    // mid-air beside the surface (or inside its side), wherever the scenario meant it to ride.
    let length = frame.length_m;
    if !(0.0..=length).contains(&on.along_m) {
        return Err(ScenarioError::invalid(
            format!("{field}.on.along_m"),
            format!(
                "{} m is off surface '{}': along_m runs from 0 (its upstream end, the {} port) to {} m (its length)",
                num(on.along_m),
                on.surface,
                frame.ports[0].0,
                num(length)
            ),
        ));
    }
    match frame.half_width_m {
        Some(hw) if on.side_m.abs() > hw => {
            return Err(ScenarioError::invalid(
                format!("{field}.on.side_m"),
                format!(
                    "{} m is off surface '{}': its face is {} m wide, side_m runs from -{} to {} m",
                    num(on.side_m),
                    on.surface,
                    num(2.0 * hw),
                    num(hw),
                    num(hw)
                ),
            ));
        }
        None if on.side_m != 0.0 => {
            return Err(ScenarioError::invalid(
                format!("{field}.on.side_m"),
                format!(
                    "{} m: on the trough '{}' an apple rests on its bottom line, side_m must be 0",
                    num(on.side_m),
                    on.surface
                ),
            ));
        }
        _ => {}
    }
    ranges::CLEARANCE
        .check(&format!("{field}.on.clearance_m"), on.clearance_m)
        .map_err(|e| match e {
            ScenarioError::Invalid { field, message } if on.clearance_m < 0.0 => {
                ScenarioError::invalid(
                    field,
                    format!("{message}: a negative clearance starts the apple inside the surface"),
                )
            }
            e => e,
        })?;
    let start = frame.ports[0].1;
    let side = frame.up.cross(frame.flow);
    let radius = radius(frame.rotation * frame.up);
    let local =
        start + frame.flow * on.along_m + side * on.side_m + frame.up * (radius + on.clearance_m);
    let want = vec3(origin) + frame.rotation * local;
    if !in_range(want) {
        return Err(ScenarioError::invalid(
            format!("{field}.on.clearance_m"),
            format!(
                "{} m above surface '{}' puts the apple at {}, outside the range of fruit handling ({})",
                num(on.clearance_m),
                on.surface,
                show(want),
                ranges::POSITION.describe()
            ),
        ));
    }
    settle(pos, want, field)
}

/// Whether every coordinate of `p` is in the position range.
fn in_range(p: Vec3) -> bool {
    [p.x, p.y, p.z]
        .iter()
        .all(|x| ranges::POSITION.contains(x.abs()))
}

/// A point as messages write it.
fn show(p: Vec3) -> String {
    format!(
        "[{}, {}, {}] m",
        ranges::num3(p.x),
        ranges::num3(p.y),
        ranges::num3(p.z)
    )
}

fn surface_position(s: &SurfaceSpec) -> [f64; 3] {
    match s {
        SurfaceSpec::Conveyor(c) => c.position_m,
        SurfaceSpec::Box(b) => b.position_m,
        SurfaceSpec::Chute(c) => c.position_m,
        SurfaceSpec::Bin(b) => b.position_m,
        SurfaceSpec::Plane(p) => p.point_m,
        SurfaceSpec::Mesh(m) => m.position_m,
        SurfaceSpec::Roller(r) => r.position_m,
        SurfaceSpec::RollerBed(b) => b.position_m,
    }
}

fn resolve_surfaces(surfaces: &mut [SurfaceSpec]) -> Result<(), ScenarioError> {
    let n = surfaces.len();
    let names: Vec<String> = surfaces.iter().map(|s| s.name().to_string()).collect();
    // Which surfaces wait for a place: (index, reference index, port).
    let mut pending: Vec<usize> = Vec::new();
    for k in 0..n {
        let field = format!("surfaces[{k}]");
        let Some((place, pos)) = place_of(&mut surfaces[k]) else {
            continue;
        };
        match place {
            Some(p) => {
                // Ports have no dots, names may: the port follows the last one.
                let (target, port) = p.at.rsplit_once('.').ok_or_else(|| {
                    ScenarioError::invalid(
                        format!("{field}.place.at"),
                        format!("'{}': write SURFACE.PORT, e.g. \"belt.discharge\"", p.at),
                    )
                })?;
                if !names.iter().any(|x| x == target) {
                    return Err(ScenarioError::invalid(
                        format!("{field}.place.at"),
                        format!(
                            "no surface named '{target}' (surfaces: {})",
                            names.join(", ")
                        ),
                    ));
                }
                if target == names[k] {
                    return Err(ScenarioError::invalid(
                        format!("{field}.place.at"),
                        format!("'{}' places the surface relative to itself", p.at),
                    ));
                }
                let _ = port;
                for (name, x) in [
                    ("gap_m", p.gap_m),
                    ("drop_m", p.drop_m),
                    ("side_m", p.side_m),
                ] {
                    ranges::OFFSET.check(&format!("{field}.place.{name}"), x)?;
                }
                pending.push(k);
            }
            None if is_unset(pos) => {
                return Err(ScenarioError::invalid(
                    format!("{field}.position_m"),
                    "missing: give the position, or a `place`",
                ))
            }
            None => {}
        }
    }
    // Resolve in rounds: a surface is placed once the one it refers to is.
    while !pending.is_empty() {
        let mut progressed = false;
        let mut left = Vec::new();
        for &k in &pending {
            let p = match place_of(&mut surfaces[k]) {
                Some((Some(p), _)) => p.clone(),
                _ => unreachable!("pending surfaces have a place"),
            };
            let (target, port) = p.at.rsplit_once('.').expect("checked above");
            let t = names
                .iter()
                .position(|x| x == target)
                .expect("checked above");
            if pending.contains(&t) && left_or_pending(&left, &pending, t, k) {
                left.push(k);
                continue;
            }
            let field = format!("surfaces[{k}]");
            let tf = format!("surfaces[{t}]");
            let ref_frame = frame_of(&surfaces[t], &tf)?.ok_or_else(|| {
                ScenarioError::invalid(
                    format!("{field}.place.at"),
                    format!(
                        "'{target}' is a {}: it has no ports (place relative to a conveyor, chute, box or bin)",
                        kind(&surfaces[t])
                    ),
                )
            })?;
            let local = ref_frame
                .ports
                .iter()
                .find(|x| x.0 == port)
                .map(|x| x.1)
                .ok_or_else(|| {
                    ScenarioError::invalid(
                        format!("{field}.place.at"),
                        format!(
                            "'{}': a {}'s ports are {}",
                            p.at,
                            kind(&surfaces[t]),
                            port_names(&ref_frame)
                        ),
                    )
                })?;
            let origin = surface_position(&surfaces[t]);
            ranges::POSITION.check_each(&format!("{tf}.position_m"), origin)?;
            let origin = vec3(origin);
            let point = origin + ref_frame.rotation * local;
            let flow = horizontal(ref_frame.rotation * ref_frame.flow);
            let left_dir = Vec3::Z.cross(flow);
            let target_point = point + flow * p.gap_m + left_dir * p.side_m - Vec3::Z * p.drop_m;
            let own = frame_of(&surfaces[k], &field)?.expect("placeable surfaces have frames");
            let anchor = p.anchor.as_deref().unwrap_or(own.ports[0].0);
            let offset = own
                .ports
                .iter()
                .find(|x| x.0 == anchor)
                .map(|x| x.1)
                .ok_or_else(|| {
                    ScenarioError::invalid(
                        format!("{field}.place.anchor"),
                        format!(
                            "'{anchor}': a {}'s ports are {}",
                            kind(&surfaces[k]),
                            port_names(&own)
                        ),
                    )
                })?;
            let want = target_point - own.rotation * offset;
            if !in_range(want) {
                return Err(ScenarioError::invalid(
                    format!("{field}.place"),
                    format!(
                        "'{}' with gap_m {}, drop_m {} and side_m {} puts the surface at {}, outside the range of fruit handling ({})",
                        p.at,
                        num(p.gap_m),
                        num(p.drop_m),
                        num(p.side_m),
                        show(want),
                        ranges::POSITION.describe()
                    ),
                ));
            }
            let (_, pos) = place_of(&mut surfaces[k]).expect("placeable");
            settle(pos, want, &field)?;
            progressed = true;
        }
        if !progressed {
            let cycle: Vec<String> = left.iter().map(|&k| format!("'{}'", names[k])).collect();
            return Err(ScenarioError::invalid(
                format!("surfaces[{}].place.at", left[0]),
                format!(
                    "the places of {} refer to each other in a circle: fix one of them in position_m",
                    cycle.join(", ")
                ),
            ));
        }
        pending = left;
    }
    Ok(())
}

/// Whether surface `t`, referred to by `k`, is still unplaced in this round.
fn left_or_pending(left: &[usize], pending: &[usize], t: usize, k: usize) -> bool {
    // Pending surfaces earlier in this round have been placed unless they were left; later ones
    // (and `k` itself) have not been handled yet.
    let pos_t = pending.iter().position(|&x| x == t);
    let pos_k = pending.iter().position(|&x| x == k);
    match (pos_t, pos_k) {
        (Some(a), Some(b)) if a < b => left.contains(&t),
        _ => true,
    }
}
