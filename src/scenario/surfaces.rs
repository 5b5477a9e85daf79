//! Surfaces of a handling line: planes, boxes, belts, chutes, bins and meshes.
//!
//! Every placed surface has a `position_m` and an optional `rotation`, given either as an axis and
//! an angle in degrees, `{"axis": [0, 1, 0], "angle_deg": 10}`, or as Euler angles in degrees,
//! `{"euler_xyz_deg": [rx, ry, rz]}`: rotations about the fixed world x, then y, then z axes
//! (R = Rz Ry Rx).

use super::motion::MotionSpec;
use super::ranges::{self, num};
use super::{de, ScenarioError};
use crate::math::{vec3, Vec3};
use rapier3d_f64::math::Rotation;
use serde::de::value::SeqAccessDeserializer;
use serde::de::{Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};
use std::fmt;

/// How a surface's contacts with apples are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactModel {
    /// Our Hertz law with eq. 12 and friction (forces recorded).
    #[default]
    Hertz,
    /// rapier's own contact (restitution sqrt(ke), friction), where forces there do not matter.
    Rigid,
}

/// A rotation: axis + angle, or Euler angles (see the module documentation).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotationSpec {
    /// Rotation axis (any length > 0; normalised).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<[f64; 3]>,
    /// Angle about `axis` (degrees, right-hand rule).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle_deg: Option<f64>,
    /// Rotations about world x, then y, then z (degrees).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub euler_xyz_deg: Option<[f64; 3]>,
}

impl RotationSpec {
    /// The rotation, or an error naming `field`.
    pub fn to_rotation(&self, field: &str) -> Result<Rotation, ScenarioError> {
        match (self.axis, self.angle_deg, self.euler_xyz_deg) {
            (Some(axis), Some(angle), None) => {
                // Scaled by its largest component first, so that any finite non-zero axis
                // normalises (an axis of [1e200, 1e200, 0] would overflow to an infinite length).
                let m = axis.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let a = vec3(axis) / m;
                if !(m > 0.0 && m.is_finite() && a.is_finite()) {
                    return Err(ScenarioError::invalid(
                        format!("{field}.axis"),
                        format!(
                            "[{}, {}, {}]: need a finite non-zero axis",
                            num(axis[0]),
                            num(axis[1]),
                            num(axis[2])
                        ),
                    ));
                }
                ranges::ANGLE.check(&format!("{field}.angle_deg"), angle)?;
                Ok(Rotation::from_axis_angle(a.normalize(), angle.to_radians()))
            }
            (None, None, Some(e)) => {
                ranges::ANGLE.check_each(&format!("{field}.euler_xyz_deg"), e)?;
                let [rx, ry, rz] = e.map(f64::to_radians);
                Ok(Rotation::from_rotation_z(rz)
                    * Rotation::from_rotation_y(ry)
                    * Rotation::from_rotation_x(rx))
            }
            (None, None, None) => Ok(Rotation::IDENTITY),
            (Some(_), None, None) => Err(ScenarioError::invalid(
                format!("{field}.angle_deg"),
                "missing: an axis needs an angle_deg",
            )),
            (None, Some(_), None) => Err(ScenarioError::invalid(
                format!("{field}.axis"),
                "missing: angle_deg needs an axis",
            )),
            _ => Err(ScenarioError::invalid(
                format!("{field}.euler_xyz_deg"),
                "give either {\"axis\": [x, y, z], \"angle_deg\": a} or {\"euler_xyz_deg\": [rx, ry, rz]}, not both",
            )),
        }
    }
}

/// Converts an optional rotation (identity when absent).
pub fn rotation_of(r: &Option<RotationSpec>, field: &str) -> Result<Rotation, ScenarioError> {
    match r {
        Some(r) => r.to_rotation(&format!("{field}.rotation")),
        None => Ok(Rotation::IDENTITY),
    }
}

/// A surface. `type` selects the kind. (Read by hand, through the scenario's `de` module, so
/// that a mistake inside a surface names its exact field.)
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum SurfaceSpec {
    /// An infinite flat platform: the half-space below the plane through `point_m` with outward
    /// unit normal `normal`.
    Plane(PlaneSpec),
    /// A box: a platform, wall or machine part.
    Box(BoxSpec),
    /// A belt: a box whose top surface moves along its local +x axis.
    Conveyor(ConveyorSpec),
    /// A chute: an inclined flat plate or a half-pipe trough.
    Chute(ChuteSpec),
    /// An open container: a floor and four walls, each with its material.
    Bin(BinSpec),
    /// A triangle mesh from an OBJ or STL file.
    Mesh(MeshSpec),
    /// A cylinder turning about its own axis at a set rate (a powered roller), or freely.
    Roller(RollerSpec),
    /// A row of identical rollers at a pitch (a roller conveyor, a singulator's bed).
    RollerBed(RollerBedSpec),
}

impl<'de> Deserialize<'de> for SurfaceSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        const TYPES: &[&str] = &[
            "plane",
            "box",
            "conveyor",
            "chute",
            "bin",
            "mesh",
            "roller",
            "roller_bed",
        ];
        let (t, v) = de::tagged(d, TYPES)?;
        if let Some(why) = match t {
            "conveyor" => {
                Some("a belt's own material is its top layer: give the belt that material")
            }
            "bin" => Some("pad a bin's floor as a padded box or plane inside it"),
            "mesh" => Some("a mesh has no single face to bond a layer on"),
            "roller" | "roller_bed" => {
                Some("the thin-layer law is for a flat layer, not a roller's curved side")
            }
            _ => None,
        } {
            if v.get("padding").is_some() {
                return Err(serde::de::Error::custom(de::nested(
                    "padding",
                    &format!("padding is for planes, boxes and flat chutes, not a {t}: {why}"),
                )));
            }
        }
        Ok(match t {
            "plane" => SurfaceSpec::Plane(de::from_value(v)?),
            "box" => SurfaceSpec::Box(de::from_value(v)?),
            "conveyor" => SurfaceSpec::Conveyor(de::from_value(v)?),
            "chute" => SurfaceSpec::Chute(de::from_value(v)?),
            "bin" => SurfaceSpec::Bin(de::from_value(v)?),
            "roller" => SurfaceSpec::Roller(de::from_value(v)?),
            "roller_bed" => SurfaceSpec::RollerBed(de::from_value(v)?),
            _ => SurfaceSpec::Mesh(de::from_value(v)?),
        })
    }
}

impl SurfaceSpec {
    /// The fields that put the surface where it is (for messages about something that meets
    /// it: a refusal between a surface and an apple names both).
    pub fn placing_fields(&self) -> &'static str {
        match self {
            SurfaceSpec::Plane(_) => "point_m, normal",
            SurfaceSpec::Box(_) | SurfaceSpec::Conveyor(_) => "position_m, size_m, rotation, place",
            SurfaceSpec::Chute(_) => {
                "position_m, length_m, width_m, radius_m, incline_deg, thickness_m, rotation, place"
            }
            SurfaceSpec::Bin(_) => "position_m, inner_size_m, wall_thickness_m, rotation, place",
            SurfaceSpec::Mesh(_) => "file, position_m, scale, rotation",
            SurfaceSpec::Roller(_) => "position_m, radius_m, length_m, axis",
            SurfaceSpec::RollerBed(_) => {
                "position_m, radius_m, length_m, axis, pitch_direction, pitch_m, count"
            }
        }
    }

    /// The surface's name.
    pub fn name(&self) -> &str {
        match self {
            SurfaceSpec::Plane(s) => &s.name,
            SurfaceSpec::Box(s) => &s.name,
            SurfaceSpec::Conveyor(s) => &s.name,
            SurfaceSpec::Chute(s) => &s.name,
            SurfaceSpec::Bin(s) => &s.name,
            SurfaceSpec::Mesh(s) => &s.name,
            SurfaceSpec::Roller(s) => &s.name,
            SurfaceSpec::RollerBed(s) => &s.name,
        }
    }

    /// The contact model.
    pub fn contact_model(&self) -> ContactModel {
        match self {
            SurfaceSpec::Plane(s) => s.contact_model,
            SurfaceSpec::Box(s) => s.contact_model,
            SurfaceSpec::Conveyor(s) => s.contact_model,
            SurfaceSpec::Chute(s) => s.contact_model,
            SurfaceSpec::Bin(s) => s.contact_model,
            SurfaceSpec::Mesh(s) => s.contact_model,
            SurfaceSpec::Roller(s) => s.contact_model,
            SurfaceSpec::RollerBed(s) => s.contact_model,
        }
    }

    /// The pad bonded on it, if any.
    pub fn padding(&self) -> Option<&PaddingSpec> {
        match self {
            SurfaceSpec::Plane(p) => p.padding.as_ref(),
            SurfaceSpec::Box(b) => b.padding.as_ref(),
            SurfaceSpec::Chute(c) => c.padding.as_ref(),
            _ => None,
        }
    }

    /// The prescribed motion, if any.
    pub fn motion(&self) -> Option<&MotionSpec> {
        match self {
            SurfaceSpec::Plane(s) => s.motion.as_ref(),
            SurfaceSpec::Box(s) => s.motion.as_ref(),
            SurfaceSpec::Conveyor(s) => s.motion.as_ref(),
            SurfaceSpec::Chute(s) => s.motion.as_ref(),
            SurfaceSpec::Bin(s) => s.motion.as_ref(),
            SurfaceSpec::Mesh(s) => s.motion.as_ref(),
            SurfaceSpec::Roller(s) => s.motion.as_ref(),
            SurfaceSpec::RollerBed(s) => s.motion.as_ref(),
        }
    }

    /// Whether the surface feeds energy into the scene: a running belt, a turning roller or a
    /// prescribed motion (the energy guard is off for such scenes).
    pub fn is_moving(&self) -> bool {
        self.motion().is_some()
            || match self {
                SurfaceSpec::Conveyor(c) => c.belt_velocity_m_s != 0.0,
                SurfaceSpec::Roller(r) => {
                    r.angular_velocity_rad_s != 0.0 || r.free_turning.is_some()
                }
                SurfaceSpec::RollerBed(b) => {
                    b.angular_velocity_rad_s != 0.0 || b.free_turning.is_some()
                }
                _ => false,
            }
    }

    /// The surface specs the world builds, one moving body each: a roller bed's rollers
    /// ([`RollerBedSpec::rollers`]), else the spec itself.
    pub fn units(&self) -> Vec<SurfaceSpec> {
        match self {
            SurfaceSpec::RollerBed(b) => b.rollers().into_iter().map(SurfaceSpec::Roller).collect(),
            s => vec![s.clone()],
        }
    }
}

/// A layer of foam or rubber of `material`, `thickness_m` thick, bonded on a plane, a box or a
/// flat chute (docs/physics.md section 13).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PaddingSpec {
    /// The pad's material (its modulus and Poisson ratio enter the thin-layer law).
    pub material: String,
    /// The pad's thickness h (m).
    pub thickness_m: f64,
}

/// An infinite plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneSpec {
    /// Unique name.
    pub name: String,
    /// Material name.
    pub material: String,
    /// A point of the plane (m).
    pub point_m: [f64; 3],
    /// Outward unit normal (towards the apples).
    pub normal: [f64; 3],
    /// Contact model.
    #[serde(default)]
    pub contact_model: ContactModel,
    /// Prescribed motion (see [`super::motion`]); the surface is fixed without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionSpec>,
    /// A pad bonded on the surface (docs/physics.md section 13): `material` is then the
    /// substrate under it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub padding: Option<PaddingSpec>,
}

/// A box.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    /// Unique name.
    pub name: String,
    /// Material name.
    pub material: String,
    /// Full edge lengths along the local x, y, z axes (m).
    pub size_m: [f64; 3],
    /// Centre (m).
    #[serde(default = "super::layout::unset")]
    pub position_m: [f64; 3],
    /// Orientation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<RotationSpec>,
    /// Contact model.
    #[serde(default)]
    pub contact_model: ContactModel,
    /// Placed relative to another surface (resolved into `position_m` when loaded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub place: Option<super::layout::PlaceSpec>,
    /// Prescribed motion (see [`super::motion`]); the surface is fixed without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionSpec>,
    /// A pad bonded on the surface (docs/physics.md section 13): `material` is then the
    /// substrate under it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub padding: Option<PaddingSpec>,
}

/// A conveyor belt.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConveyorSpec {
    /// Unique name.
    pub name: String,
    /// Material of the belt surface.
    pub material: String,
    /// Full edge lengths (m): length along local x, width along y, thickness along z.
    pub size_m: [f64; 3],
    /// Centre (m).
    #[serde(default = "super::layout::unset")]
    pub position_m: [f64; 3],
    /// Orientation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<RotationSpec>,
    /// Belt speed along the belt's local +x axis (m/s; negative runs the other way). It enters
    /// the friction slip velocity; the belt itself stays in place.
    pub belt_velocity_m_s: f64,
    /// Contact model.
    #[serde(default)]
    pub contact_model: ContactModel,
    /// Placed relative to another surface (resolved into `position_m` when loaded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub place: Option<super::layout::PlaceSpec>,
    /// Prescribed motion (see [`super::motion`]); the surface is fixed without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionSpec>,
}

/// Cross-section of a chute.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChuteProfile {
    /// A flat plate.
    Flat,
    /// A half-pipe (concave cylinder), curvature -1/R_s across.
    Trough,
}

/// A chute: in its local frame the sliding surface runs along +x (downhill once inclined), the
/// width along y, up is +z; `position_m` is the centre of the surface's top (flat) or of its
/// bottom line (trough).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChuteSpec {
    /// Unique name.
    pub name: String,
    /// Material name.
    pub material: String,
    /// `flat` or `trough`.
    pub profile: ChuteProfile,
    /// Length along the slope (m).
    pub length_m: f64,
    /// Width of a flat chute (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width_m: Option<f64>,
    /// Inner radius of a trough (m); must exceed the apples' radius.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_m: Option<f64>,
    /// Angular half-width of a trough from its bottom line (degrees, default 90: a half pipe).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_angle_deg: Option<f64>,
    /// Plate thickness (m, default 0.01).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness_m: Option<f64>,
    /// Slope: the surface descends along its local +x by this angle (degrees, default 0).
    #[serde(default)]
    pub incline_deg: f64,
    /// Reference point (m).
    #[serde(default = "super::layout::unset")]
    pub position_m: [f64; 3],
    /// Orientation applied after the incline (e.g. a heading about z).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<RotationSpec>,
    /// Contact model.
    #[serde(default)]
    pub contact_model: ContactModel,
    /// Placed relative to another surface (resolved into `position_m` when loaded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub place: Option<super::layout::PlaceSpec>,
    /// Prescribed motion (see [`super::motion`]); the surface is fixed without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionSpec>,
    /// A pad bonded on the surface (docs/physics.md section 13): `material` is then the
    /// substrate under it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub padding: Option<PaddingSpec>,
}

/// Per-wall materials of a bin; absent walls use the bin's `material`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BinMaterials {
    /// Floor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub floor: Option<String>,
    /// Wall at local -x.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x_min: Option<String>,
    /// Wall at local +x.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x_max: Option<String>,
    /// Wall at local -y.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y_min: Option<String>,
    /// Wall at local +y.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y_max: Option<String>,
}

/// An open bin. Its five walls are separate surfaces named `NAME/floor`, `NAME/x_min`,
/// `NAME/x_max`, `NAME/y_min`, `NAME/y_max` in the results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BinSpec {
    /// Unique name.
    pub name: String,
    /// Material of every wall without its own.
    pub material: String,
    /// Per-wall materials.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_materials: Option<BinMaterials>,
    /// Inside length (x), width (y) and wall height (z) (m).
    pub inner_size_m: [f64; 3],
    /// Wall and floor thickness (m, default 0.01).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_thickness_m: Option<f64>,
    /// Centre of the floor's inside (top) face (m).
    #[serde(default = "super::layout::unset")]
    pub position_m: [f64; 3],
    /// Orientation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<RotationSpec>,
    /// Contact model.
    #[serde(default)]
    pub contact_model: ContactModel,
    /// Placed relative to another surface (resolved into `position_m` when loaded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub place: Option<super::layout::PlaceSpec>,
    /// Prescribed motion (see [`super::motion`]); the surface is fixed without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionSpec>,
}

/// A triangle mesh.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// Unique name.
    pub name: String,
    /// Material name.
    pub material: String,
    /// OBJ or STL file, relative to the scenario's folder.
    pub file: String,
    /// Scale factor applied to the file's coordinates (one number, or per axis).
    #[serde(default)]
    pub scale: Scale,
    /// Position of the mesh origin (m).
    #[serde(default)]
    pub position_m: [f64; 3],
    /// Orientation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<RotationSpec>,
    /// Contact model.
    #[serde(default)]
    pub contact_model: ContactModel,
    /// Prescribed motion (see [`super::motion`]); the surface is fixed without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionSpec>,
}

/// A roller: a cylinder of `radius_m` and `length_m` centred on `position_m`, its axis along
/// `axis`, turning about it at `angular_velocity_rad_s` (right-hand rule about `axis`). Powered
/// (the default): no load changes its rate. With `free_turning` no motor drives it: it starts at
/// `angular_velocity_rad_s` and turns from the friction torques the apples put on it, against
/// its own moment of inertia and its bearing friction (`world::free_roller`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RollerSpec {
    /// Unique name.
    pub name: String,
    /// Material of the roller's surface.
    pub material: String,
    /// Radius (m).
    pub radius_m: f64,
    /// Length along the axis (m).
    pub length_m: f64,
    /// Centre (m).
    pub position_m: [f64; 3],
    /// Axis direction (any length > 0; normalised).
    pub axis: [f64; 3],
    /// Rate of turn about `axis` (rad/s; default 0); a free-turning roller's initial rate.
    #[serde(default)]
    pub angular_velocity_rad_s: f64,
    /// Contact model.
    #[serde(default)]
    pub contact_model: ContactModel,
    /// Prescribed motion of the whole roller (see [`super::motion`]), besides its own turning.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionSpec>,
    /// No motor: the roller turns freely on its bearings (absent: powered).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_turning: Option<FreeTurningSpec>,
}

/// A roller that no motor drives: what turns it is the apples' friction, against its own
/// inertia and its bearings. A packhouse engineer reads the inertia off the roller's drawing:
/// a steel tube of mass m, outer radius R and inner radius R_i has I = m (R^2 + R_i^2) / 2 (a
/// solid shaft m R^2 / 2); shafts and end caps add theirs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FreeTurningSpec {
    /// Moment of inertia of everything that turns with the roller, about its axis (kg m^2).
    pub moment_of_inertia_kg_m2: f64,
    /// Friction torque of its bearings (N m; default 0): a constant torque against the turning
    /// (Coulomb), holding the roller at rest below it.
    #[serde(default)]
    pub bearing_torque_n_m: f64,
}

/// A roller bed: `count` identical rollers (radius, length, axis, material, turning) whose
/// centres lie on a line along `pitch_direction`, `pitch_m` apart, the first at `position_m`.
/// They are the surfaces `NAME/0` .. `NAME/N-1` in the results (contacts.csv, transitions); the
/// line audit counts them as one transfer point, `NAME`. All turn alike: powered at
/// `angular_velocity_rad_s`, or each freely with the same `free_turning` (each its own spin).
/// A `motion` carries the whole bed (each roller rides its own copy of it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RollerBedSpec {
    /// Unique name (its rollers are `NAME/0`, `NAME/1`, ...).
    pub name: String,
    /// Material of the rollers' surface.
    pub material: String,
    /// Radius of each roller (m).
    pub radius_m: f64,
    /// Length of each roller along its axis (m).
    pub length_m: f64,
    /// Centre of the first roller, `NAME/0` (m).
    pub position_m: [f64; 3],
    /// The rollers' axis direction (any length > 0; normalised).
    pub axis: [f64; 3],
    /// From one roller's centre to the next (any length > 0; normalised; at right angles to
    /// `axis`).
    pub pitch_direction: [f64; 3],
    /// Number of rollers (>= 1).
    pub count: u32,
    /// Distance between neighbouring rollers' axes (m; at least a diameter: they may not
    /// overlap).
    pub pitch_m: f64,
    /// Rate of turn of every roller about `axis` (rad/s; default 0).
    #[serde(default)]
    pub angular_velocity_rad_s: f64,
    /// Contact model.
    #[serde(default)]
    pub contact_model: ContactModel,
    /// Prescribed motion of the whole bed (see [`super::motion`]), besides the rollers' turning.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionSpec>,
    /// Every roller turns freely on its bearings with these (absent: powered).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_turning: Option<FreeTurningSpec>,
}

impl RollerBedSpec {
    /// The bed's rollers, `NAME/0` first at `position_m`, each the next `pitch_m` further along
    /// `pitch_direction` (normalised; a zero direction leaves them all at `position_m`, which
    /// validation refuses).
    pub fn rollers(&self) -> Vec<RollerSpec> {
        (0..self.count).map(|i| self.roller(i)).collect()
    }

    /// The bed's roller `i` (`NAME/i`), built alone: validation checks a bed's fields on its
    /// first and last rollers without expanding the others.
    pub fn roller(&self, i: u32) -> RollerSpec {
        let d = vec3(self.pitch_direction);
        let step = if d.length() > 0.0 {
            d.normalize() * self.pitch_m
        } else {
            Vec3::ZERO
        };
        let c = vec3(self.position_m) + step * f64::from(i);
        RollerSpec {
            name: format!("{}/{i}", self.name),
            material: self.material.clone(),
            radius_m: self.radius_m,
            length_m: self.length_m,
            position_m: [c.x, c.y, c.z],
            axis: self.axis,
            angular_velocity_rad_s: self.angular_velocity_rad_s,
            contact_model: self.contact_model,
            motion: self.motion.clone(),
            free_turning: self.free_turning.clone(),
        }
    }
}

/// A uniform or per-axis scale.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Scale {
    /// The same factor on every axis.
    Uniform(f64),
    /// One factor per axis.
    PerAxis([f64; 3]),
}

impl<'de> Deserialize<'de> for Scale {
    // By hand rather than `untagged`, which buffers the value and loses the path of a bad
    // factor (`scale[1]`).
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Scale;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a scale factor or [sx, sy, sz]")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Scale, E> {
                Ok(Scale::Uniform(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Scale, E> {
                Ok(Scale::Uniform(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Scale, E> {
                Ok(Scale::Uniform(v as f64))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Scale, A::Error> {
                <[f64; 3]>::deserialize(SeqAccessDeserializer::new(seq)).map(Scale::PerAxis)
            }
        }
        d.deserialize_any(V)
    }
}

impl Default for Scale {
    fn default() -> Self {
        Scale::Uniform(1.0)
    }
}

impl Scale {
    /// As a vector.
    pub fn vector(&self) -> Vec3 {
        match *self {
            Scale::Uniform(s) => Vec3::splat(s),
            Scale::PerAxis(a) => vec3(a),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euler_and_axis_angle_agree() {
        let a = RotationSpec {
            axis: Some([0.0, 1.0, 0.0]),
            angle_deg: Some(30.0),
            euler_xyz_deg: None,
        }
        .to_rotation("r")
        .unwrap();
        let b = RotationSpec {
            axis: None,
            angle_deg: None,
            euler_xyz_deg: Some([0.0, 30.0, 0.0]),
        }
        .to_rotation("r")
        .unwrap();
        let v = Vec3::new(1.0, 0.0, 0.0);
        assert!((a * v - b * v).length() < 1e-12);
        // Right-hand rule about y: +x tips down towards -z.
        assert!((a * v).z < 0.0);
        assert!(RotationSpec {
            axis: Some([0.0, 0.0, 0.0]),
            angle_deg: Some(30.0),
            euler_xyz_deg: None
        }
        .to_rotation("r")
        .is_err());
    }
}
