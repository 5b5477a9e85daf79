//! Scene output for ParaView: VTK XML PolyData frames of the apples, the surfaces' geometry, and
//! a `scene.pvd` index (scenario `output.vtk`; user guide in docs/analysis.md, "ParaView").
//!
//! Files, in the run folder:
//! - `vtk/apples_NNNNNN.vtp`: one frame; points = apple centres (one vertex cell each), point
//!   arrays `radius` (m), `velocity` (m/s), `angular_velocity` (rad/s), `contact_force` (N),
//!   `bruise` (1 once the apple has a bruise, from the time of the peak force of the hit that
//!   made it), `apple_id` (index in the run's apple order: listed, generated,
//!   then fed-in apples; -1 if unknown). Every frame carries its own points, so the number of
//!   apples may change from frame to frame (sources feed apples in). A run with spheroidal
//!   apples (`bodies.csv` with the shape columns, issue 29) adds `diameter` and `height` (m),
//!   `orientation` (the unit quaternion w x y z of `bodies.csv`, the apple's frame to the
//!   world's), `axis` (the apple's own z axis in the world) and `shape_tensor` (9 components,
//!   the frame's active tensors): R diag(D, D, H) R^T, whose eigenvalues are the full extents
//!   along the principal axes, so that ParaView's Tensor Glyph filter with its default sphere
//!   (radius 0.5, scale factor 1) draws each apple as its oriented spheroid (a sphere of such a
//!   run as D I). A run of spheres writes none of these, byte for byte as before.
//! - `vtk/surfaces.vtp`: every fixed surface as triangles, cell array `surface_id` (index of
//!   the surface part in the layer: a bin's floor and walls are separate parts). Half-spaces
//!   become a square patch sized to the scene, boxes their box, meshes their triangles, balls a
//!   tessellated sphere, troughs their half-pipe; any other shape its bounding box, with a
//!   warning.
//! - `vtk/moving_NNNNNN.vtp`, only when a surface moves (a `motion`): the moving surfaces of
//!   frame NNNNNN, the same triangles posed at the frame's time by the motion their kinematic
//!   body follows in the run (`world::motion::Motion::pose`), with the same `surface_id`s; the
//!   fixed file then leaves them out. A roller is drawn without its own turn about its axis (it
//!   looks the same turned, and a free-turning roller's angle is not kept after the run), so a
//!   roller that only turns stays in the fixed file. LIGGGHTS users expect moving meshes this
//!   way, one file per dump.
//! - `scene.pvd`: the time series: per frame, part 0 the apples, part 1 the fixed surfaces and,
//!   when a surface moves, part 2 that frame's moving surfaces.
//!
//! Frames are taken from `bodies.csv` after the run (so they show exactly what it holds, and the
//! bruise flag can use the finished contacts): the frame interval is rounded up to a whole
//! number of `output.sample_interval_s`. Numbers are ASCII in Rust's shortest round-trip form,
//! so the same run gives byte-identical files.

use super::atomic;
use crate::analysis::bruise::BruiseReport;
use crate::layer::{SurfaceId, SurfaceShape};
use crate::math::Vec3;
use crate::scenario::Scenario;
use crate::world::motion::Motion;
use crate::world::World;
use rapier3d_f64::parry::math::Pose;
use rapier3d_f64::parry::shape::{Shape, SharedShape, TypedShape};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Folder of the frames inside the run folder.
pub const VTK_DIR: &str = "vtk";
/// Name of the index.
pub const PVD_FILE: &str = "scene.pvd";
/// Name of the surfaces file inside [`VTK_DIR`].
pub const SURFACES_FILE: &str = "surfaces.vtp";
/// Start of the names of the moving surfaces' files inside [`VTK_DIR`] (`moving_NNNNNN.vtp`).
pub const MOVING_PREFIX: &str = "moving_";
/// Start of the names of the apple frames inside [`VTK_DIR`] (`apples_NNNNNN.vtp`).
const APPLES_PREFIX: &str = "apples_";

/// Errors of the VTK output.
#[derive(Debug, thiserror::Error)]
pub enum VtkError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// File.
        path: PathBuf,
        /// OS error.
        source: std::io::Error,
    },
    /// `bodies.csv` could not be parsed.
    #[error("{path}: {message}")]
    Bodies {
        /// File.
        path: PathBuf,
        /// What was wrong.
        message: String,
    },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> VtkError + '_ {
    move |source| VtkError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// A triangle mesh in world coordinates.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertices (m).
    pub points: Vec<Vec3>,
    /// Triangles (indices into `points`).
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    fn push(&mut self, pose: &Pose, pts: &[Vec3], tris: &[[u32; 3]]) {
        let base = self.points.len() as u32;
        self.points
            .extend(pts.iter().map(|&p| pose.transform_point(p)));
        self.triangles
            .extend(tris.iter().map(|t| [t[0] + base, t[1] + base, t[2] + base]));
    }
}

/// What a surface looks like, captured from the world before the run.
#[derive(Clone)]
struct SurfaceItem {
    name: String,
    shape: SharedShape,
    pose: Pose,
    layer_shape: SurfaceShape,
    /// The motion of its body and its pose on the body, if it moves other than turning about
    /// its own axis ([`Motion::displaces`]).
    motion: Option<(Motion, Pose)>,
}

/// The surfaces of a world, captured at t = 0 (from `World::surface_colliders`) so that they can
/// be tessellated after the run, when the scene's extent is known.
#[derive(Clone, Default)]
pub struct SceneSurfaces {
    items: Vec<SurfaceItem>,
}

impl SceneSurfaces {
    /// Captures the surface colliders of `world` (scenario order).
    pub fn capture(world: &World) -> Self {
        let items = world
            .surface_colliders
            .iter()
            .enumerate()
            .filter_map(|(k, &ch)| {
                let co = world.physics.colliders.get(ch)?;
                let id = SurfaceId(k as u32);
                Some(SurfaceItem {
                    name: world.layer.surface_name(id).to_string(),
                    shape: co.shared_shape().clone(),
                    pose: *co.position(),
                    layer_shape: world.layer.surface_shape(id).clone(),
                    motion: world
                        .surface_motion(k)
                        .filter(|(m, _)| m.displaces())
                        .map(|(m, on_body)| (m.clone(), on_body)),
                })
            })
            .collect();
        Self { items }
    }

    /// Surfaces from their parts without a world: (name, collider shape, pose, contact shape)
    /// each. The viewer (`crate::view`) draws a finished run folder this way, from its
    /// `scenario.json`, long after the world is gone.
    pub fn from_parts(
        parts: impl IntoIterator<Item = (String, SharedShape, Pose, SurfaceShape)>,
    ) -> Self {
        Self {
            items: parts
                .into_iter()
                .map(|(name, shape, pose, layer_shape)| SurfaceItem {
                    name,
                    shape,
                    pose,
                    layer_shape,
                    motion: None,
                })
                .collect(),
        }
    }

    /// Number of surfaces.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether there is no surface.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Whether a surface moves (other than a roller turning about its own axis): then the
    /// moving ones get a file per frame.
    pub fn moves(&self) -> bool {
        self.items.iter().any(|s| s.motion.is_some())
    }

    /// One mesh per surface, as captured (t = 0); unbounded half-spaces are cut to a square
    /// patch centred under the scene box (`lo`, `hi`, m) and twice its diagonal wide. Warnings
    /// name the surfaces drawn as their bounding box.
    pub fn tessellate(&self, lo: Vec3, hi: Vec3) -> (Vec<Mesh>, Vec<String>) {
        let mut warnings = Vec::new();
        let meshes = self
            .items
            .iter()
            .map(|s| {
                let (m, w) = item_mesh(s, &s.pose, lo, hi);
                warnings.extend(w);
                m
            })
            .collect();
        (meshes, warnings)
    }

    /// The moving surfaces at time `t_s`, as (index of the surface, mesh): each posed by its
    /// body's motion at `t_s` without a roller's own turn. Their warnings are those of
    /// [`Self::tessellate`] (same shapes), so none are returned.
    fn moving_meshes(&self, t_s: f64, lo: Vec3, hi: Vec3) -> Vec<(usize, Mesh)> {
        self.items
            .iter()
            .enumerate()
            .filter_map(|(k, s)| {
                let (m, on_body) = s.motion.as_ref()?;
                Some((
                    k,
                    item_mesh(s, &(m.pose_spun(t_s, 0.0) * *on_body), lo, hi).0,
                ))
            })
            .collect()
    }
}

/// The mesh of one surface at `pose`, and a warning if it is drawn as its bounding box.
fn item_mesh(s: &SurfaceItem, pose: &Pose, lo: Vec3, hi: Vec3) -> (Mesh, Option<String>) {
    let mut m = Mesh::default();
    if let SurfaceShape::Trough {
        radius_m,
        half_length_m,
        half_angle_rad,
    } = s.layer_shape
    {
        trough(&mut m, pose, radius_m, half_length_m, half_angle_rad);
    } else if !shape_mesh(&mut m, pose, s.shape.as_ref(), lo, hi) {
        let warning = format!(
            "vtk: surface '{}' has a shape the VTK output does not draw ({:?}); it is shown as its bounding box",
            s.name,
            s.shape.shape_type()
        );
        m = Mesh::default();
        let aabb = s.shape.compute_aabb(pose);
        let (p, t) = aabb.to_trimesh();
        m.push(&Pose::IDENTITY, &p, &t);
        return (m, Some(warning));
    }
    (m, None)
}

/// Appends the triangles of `shape` at `pose`; false for a shape it cannot draw.
fn shape_mesh(m: &mut Mesh, pose: &Pose, shape: &dyn Shape, lo: Vec3, hi: Vec3) -> bool {
    match shape.as_typed_shape() {
        TypedShape::HalfSpace(h) => {
            let n = (pose.rotation * h.normal).normalize();
            let p0 = pose.translation;
            let centre = 0.5 * (lo + hi);
            let c = centre - (centre - p0).dot(n) * n;
            let half = (hi - lo).length().max(0.1);
            let u = n.any_orthonormal_vector();
            let v = n.cross(u);
            let pts = [
                c - half * u - half * v,
                c + half * u - half * v,
                c + half * u + half * v,
                c - half * u + half * v,
            ];
            m.push(&Pose::IDENTITY, &pts, &[[0, 1, 2], [0, 2, 3]]);
        }
        TypedShape::Cuboid(c) => {
            let (p, t) = c.to_trimesh();
            m.push(pose, &p, &t);
        }
        TypedShape::RoundCuboid(c) => {
            let (p, t) = c.inner_shape.to_trimesh();
            m.push(pose, &p, &t);
        }
        TypedShape::Ball(b) => {
            let (p, t) = b.to_trimesh(32, 16);
            m.push(pose, &p, &t);
        }
        TypedShape::Capsule(c) => {
            let (p, t) = c.to_trimesh(32, 16);
            m.push(pose, &p, &t);
        }
        TypedShape::Cylinder(c) => {
            let (p, t) = c.to_trimesh(48);
            m.push(pose, &p, &t);
        }
        TypedShape::RoundCylinder(c) => {
            let (p, t) = c.inner_shape.to_trimesh(48);
            m.push(pose, &p, &t);
        }
        TypedShape::Cone(c) => {
            let (p, t) = c.to_trimesh(48);
            m.push(pose, &p, &t);
        }
        TypedShape::RoundCone(c) => {
            let (p, t) = c.inner_shape.to_trimesh(48);
            m.push(pose, &p, &t);
        }
        TypedShape::Triangle(t) => m.push(pose, &[t.a, t.b, t.c], &[[0, 1, 2]]),
        TypedShape::RoundTriangle(t) => {
            let t = &t.inner_shape;
            m.push(pose, &[t.a, t.b, t.c], &[[0, 1, 2]]);
        }
        TypedShape::TriMesh(t) => m.push(pose, t.vertices(), t.indices()),
        TypedShape::ConvexPolyhedron(c) => {
            let (p, t) = c.to_trimesh();
            m.push(pose, &p, &t);
        }
        TypedShape::RoundConvexPolyhedron(c) => {
            let (p, t) = c.inner_shape.to_trimesh();
            m.push(pose, &p, &t);
        }
        TypedShape::HeightField(h) => {
            let (p, t) = h.to_trimesh();
            m.push(pose, &p, &t);
        }
        TypedShape::Compound(c) => {
            for (local, sub) in c.shapes() {
                if !shape_mesh(m, &(*pose * *local), sub.as_ref(), lo, hi) {
                    return false;
                }
            }
        }
        _ => return false,
    }
    true
}

/// The inner face of a trough (layer `SurfaceShape::Trough`): axis along local x, bottom line
/// at local -z, `half_angle` on each side of it.
fn trough(m: &mut Mesh, pose: &Pose, rs: f64, half_len: f64, half_angle: f64) {
    let n = 48u32;
    let mut pts = Vec::with_capacity(2 * (n as usize + 1));
    for i in 0..=n {
        let phi = -half_angle + 2.0 * half_angle * i as f64 / n as f64;
        let (y, z) = (rs * phi.sin(), -rs * phi.cos());
        pts.push(Vec3::new(-half_len, y, z));
        pts.push(Vec3::new(half_len, y, z));
    }
    let tris: Vec<[u32; 3]> = (0..n)
        .flat_map(|i| {
            let a = 2 * i;
            [[a, a + 1, a + 3], [a, a + 3, a + 2]]
        })
        .collect();
    m.push(pose, &pts, &tris);
}

/// What [`write_vtk`] wrote.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VtkSummary {
    /// (time s, file relative to the run folder) of every apple frame.
    pub frames: Vec<(f64, String)>,
    /// Things the user should know (shapes drawn as boxes, frame interval rounded, ...).
    pub warnings: Vec<String>,
}

fn xml_header(out: &mut String) {
    out.push_str("<?xml version=\"1.0\"?>\n");
}

fn data_array<I, T>(out: &mut String, ty: &str, name: Option<&str>, comps: usize, values: I)
where
    I: IntoIterator<Item = T>,
    T: std::fmt::Display,
{
    let _ = write!(out, "        <DataArray type=\"{ty}\"");
    if let Some(n) = name {
        let _ = write!(out, " Name=\"{n}\"");
    }
    if comps > 1 {
        let _ = write!(out, " NumberOfComponents=\"{comps}\"");
    }
    out.push_str(" format=\"ascii\">\n         ");
    for (i, v) in values.into_iter().enumerate() {
        if i > 0 && i % 12 == 0 {
            out.push_str("\n         ");
        }
        let _ = write!(out, " {v}");
    }
    out.push_str("\n        </DataArray>\n");
}

/// One apple in a frame.
struct FrameApple {
    id: i64,
    radius: f64,
    p: [f64; 3],
    v: [f64; 3],
    w: [f64; 3],
    f: [f64; 3],
    bruise: u8,
    /// The shape, in a run with spheroids.
    shape: Option<FrameShape>,
}

/// An apple's shape in a frame of a run with spheroids (`bodies.csv`'s shape columns).
struct FrameShape {
    /// Equatorial diameter D (m).
    diameter: f64,
    /// Height H along its own z axis (m).
    height: f64,
    /// Orientation, w x y z, as `bodies.csv` prints it.
    q: [f64; 4],
}

impl FrameShape {
    /// The apple's own z axis in the world: R e_z of the normalised quaternion (`bodies.csv`
    /// prints it to a few digits, so its norm is 1 only to that precision).
    fn axis(&self) -> [f64; 3] {
        let n = self.q.iter().map(|x| x * x).sum::<f64>().sqrt();
        let [w, x, y, z] = self.q.map(|c| c / n);
        [
            2.0 * (x * z + w * y),
            2.0 * (y * z - w * x),
            1.0 - 2.0 * (x * x + y * y),
        ]
    }

    /// R diag(D, D, H) R^T = D I + (H - D) k k^T with k the axis, row by row: the tensor that
    /// a Tensor Glyph of a sphere of radius 0.5 turns into the apple (its eigenvalues D, D, H
    /// scale the sphere along its eigenvectors, the equator's and the axis).
    fn tensor(&self) -> [f64; 9] {
        let k = self.axis();
        let (d, dh) = (self.diameter, self.height - self.diameter);
        let mut t = [0.0; 9];
        for i in 0..3 {
            for j in 0..3 {
                t[3 * i + j] = dh * k[i] * k[j] + if i == j { d } else { 0.0 };
            }
        }
        t
    }
}

/// One frame of apples; `shaped`: the run has spheroids (the shape arrays are written, an apple
/// without a shape as a sphere of its radius).
fn apples_vtp(apples: &[FrameApple], shaped: bool) -> String {
    let n = apples.len();
    let mut s = String::with_capacity(256 + n * 400);
    xml_header(&mut s);
    s.push_str(
        "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <PolyData>\n",
    );
    let _ = writeln!(
        s,
        "    <Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{n}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">"
    );
    s.push_str(if shaped {
        "      <PointData Scalars=\"radius\" Vectors=\"velocity\" Tensors=\"shape_tensor\">\n"
    } else {
        "      <PointData Scalars=\"radius\" Vectors=\"velocity\">\n"
    });
    data_array(
        &mut s,
        "Float64",
        Some("radius"),
        1,
        apples.iter().map(|a| a.radius),
    );
    for (name, get) in [
        (
            "velocity",
            (|a: &FrameApple| a.v) as fn(&FrameApple) -> [f64; 3],
        ),
        ("angular_velocity", |a| a.w),
        ("contact_force", |a| a.f),
    ] {
        data_array(
            &mut s,
            "Float64",
            Some(name),
            3,
            apples.iter().flat_map(get),
        );
    }
    data_array(
        &mut s,
        "UInt8",
        Some("bruise"),
        1,
        apples.iter().map(|a| a.bruise),
    );
    data_array(
        &mut s,
        "Int64",
        Some("apple_id"),
        1,
        apples.iter().map(|a| a.id),
    );
    if shaped {
        shape_arrays(&mut s, apples);
    }
    s.push_str("      </PointData>\n      <Points>\n");
    data_array(
        &mut s,
        "Float64",
        Some("points"),
        3,
        apples.iter().flat_map(|a| a.p),
    );
    s.push_str("      </Points>\n      <Verts>\n");
    data_array(&mut s, "Int64", Some("connectivity"), 1, 0..n as i64);
    data_array(&mut s, "Int64", Some("offsets"), 1, 1..=n as i64);
    s.push_str("      </Verts>\n    </Piece>\n  </PolyData>\n</VTKFile>\n");
    s
}

/// The point arrays of the apples' shapes (module docs); an apple without a shape (its radius
/// unknown, or a file without the shape columns) has NaN there.
fn shape_arrays(s: &mut String, apples: &[FrameApple]) {
    let shape = |a: &FrameApple| {
        a.shape.as_ref().map_or(
            (
                f64::NAN,
                f64::NAN,
                [f64::NAN; 4],
                [f64::NAN; 3],
                [f64::NAN; 9],
            ),
            |sh| (sh.diameter, sh.height, sh.q, sh.axis(), sh.tensor()),
        )
    };
    data_array(
        s,
        "Float64",
        Some("diameter"),
        1,
        apples.iter().map(|a| shape(a).0),
    );
    data_array(
        s,
        "Float64",
        Some("height"),
        1,
        apples.iter().map(|a| shape(a).1),
    );
    data_array(
        s,
        "Float64",
        Some("orientation"),
        4,
        apples.iter().flat_map(|a| shape(a).2),
    );
    data_array(
        s,
        "Float64",
        Some("axis"),
        3,
        apples.iter().flat_map(|a| shape(a).3),
    );
    data_array(
        s,
        "Float64",
        Some("shape_tensor"),
        9,
        apples.iter().flat_map(|a| shape(a).4),
    );
}

/// Surfaces as triangles, each with its `surface_id` (its index in the layer, also when only
/// some of them are in the file).
fn surfaces_vtp(meshes: &[(usize, &Mesh)]) -> String {
    let np: usize = meshes.iter().map(|(_, m)| m.points.len()).sum();
    let nt: usize = meshes.iter().map(|(_, m)| m.triangles.len()).sum();
    let mut s = String::with_capacity(256 + np * 60 + nt * 40);
    xml_header(&mut s);
    s.push_str(
        "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <PolyData>\n",
    );
    let _ = writeln!(
        s,
        "    <Piece NumberOfPoints=\"{np}\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"{nt}\">"
    );
    s.push_str("      <CellData Scalars=\"surface_id\">\n");
    data_array(
        &mut s,
        "Int64",
        Some("surface_id"),
        1,
        meshes
            .iter()
            .flat_map(|&(k, m)| std::iter::repeat_n(k as i64, m.triangles.len())),
    );
    s.push_str("      </CellData>\n      <Points>\n");
    data_array(
        &mut s,
        "Float64",
        Some("points"),
        3,
        meshes
            .iter()
            .flat_map(|(_, m)| m.points.iter().flat_map(|p| [p.x, p.y, p.z])),
    );
    s.push_str("      </Points>\n      <Polys>\n");
    let mut conn = Vec::with_capacity(3 * nt);
    let mut base = 0i64;
    for (_, m) in meshes {
        for t in &m.triangles {
            conn.extend(t.iter().map(|&i| base + i as i64));
        }
        base += m.points.len() as i64;
    }
    data_array(&mut s, "Int64", Some("connectivity"), 1, conn);
    data_array(
        &mut s,
        "Int64",
        Some("offsets"),
        1,
        (1..=nt as i64).map(|k| 3 * k),
    );
    s.push_str("      </Polys>\n    </Piece>\n  </PolyData>\n</VTKFile>\n");
    s
}

/// File of frame `k`'s moving surfaces, relative to the run folder.
fn moving_file(k: usize) -> String {
    format!("{VTK_DIR}/{MOVING_PREFIX}{k:06}.vtp")
}

/// The index; `moving`: whether each frame has a file of moving surfaces (part 2).
fn pvd(frames: &[(f64, String)], moving: bool) -> String {
    let mut s = String::new();
    xml_header(&mut s);
    s.push_str("<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n");
    for (k, (t, f)) in frames.iter().enumerate() {
        let _ = writeln!(
            s,
            "    <DataSet timestep=\"{t}\" group=\"\" part=\"0\" file=\"{f}\"/>"
        );
        let _ = writeln!(
            s,
            "    <DataSet timestep=\"{t}\" group=\"\" part=\"1\" file=\"{VTK_DIR}/{SURFACES_FILE}\"/>"
        );
        if moving {
            let _ = writeln!(
                s,
                "    <DataSet timestep=\"{t}\" group=\"\" part=\"2\" file=\"{}\"/>",
                moving_file(k)
            );
        }
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    s
}

/// Where the shape columns of a run with spheroids are in `bodies.csv`: `diameter_m`, and
/// `height_m` followed by `qw qx qy qz` ([`super::BODIES_SHAPE_HEADER`]).
#[derive(Debug, Clone, Copy)]
struct ShapeCols {
    diameter: usize,
    height: usize,
}

impl ShapeCols {
    /// The shape columns of `header`, if it has them all.
    fn of(header: &csv::StringRecord) -> Option<Self> {
        let at = |name: &str| header.iter().position(|h| h == name);
        let height = at(super::BODIES_SHAPE_HEADER[0])?;
        let follow = header
            .iter()
            .skip(height)
            .take(super::BODIES_SHAPE_HEADER.len())
            .eq(super::BODIES_SHAPE_HEADER.iter().copied());
        Some(Self {
            diameter: at("diameter_m")?,
            height: follow.then_some(height)?,
        })
    }
}

/// Reads `bodies.csv` (or `bodies.csv.gz`) sample by sample: (time, rows, its shape columns
/// when the run had spheroids) in file order.
fn for_each_sample(
    path: &Path,
    mut f: impl FnMut(f64, &[csv::StringRecord], Option<ShapeCols>) -> Result<(), VtkError>,
) -> Result<(), VtkError> {
    let bad = |message: String| VtkError::Bodies {
        path: path.to_path_buf(),
        message,
    };
    let (_, mut rd) = super::csv_file::reader(path).map_err(|e| bad(e.to_string()))?;
    let header = rd.headers().map_err(|e| bad(e.to_string()))?.clone();
    // The first 14 columns (files written before `slip_m_s` was added are read too).
    if header.len() < 14
        || header
            .iter()
            .take(14)
            .ne(super::BODIES_HEADER[..14].iter().copied())
    {
        return Err(bad(format!("unexpected header {:?}", header)));
    }
    let shape = ShapeCols::of(&header);
    let mut rows: Vec<csv::StringRecord> = Vec::new();
    let mut t_cur = f64::NAN;
    for rec in rd.records() {
        let rec = rec.map_err(|e| bad(e.to_string()))?;
        let t: f64 = rec[0]
            .parse()
            .map_err(|_| bad(format!("bad time_s '{}'", &rec[0])))?;
        if t != t_cur && !rows.is_empty() {
            f(t_cur, &rows, shape)?;
            rows.clear();
        }
        t_cur = t;
        rows.push(rec);
    }
    if !rows.is_empty() {
        f(t_cur, &rows, shape)?;
    }
    Ok(())
}

/// Writes the ParaView output of a finished run whose `bodies.csv` is in `dir`: frames every
/// `interval_s` (rounded up to whole samples of `sample_interval_s`), the surfaces captured
/// before the run (the fixed ones once, the moving ones posed per frame), and the `scene.pvd`
/// index. `apple_order` lists the run's apples in layer
/// order (their `apple_id`); radii come from the scenario's apples, generators and sources.
/// Frames of an earlier run in the same folder beyond the new last frame are removed, so the
/// folder holds one run.
pub fn write_vtk(
    dir: &Path,
    sc: &Scenario,
    surfaces: &SceneSurfaces,
    bruise: &BruiseReport,
    apple_order: &[&str],
    interval_s: f64,
) -> Result<VtkSummary, VtkError> {
    let vdir = dir.join(VTK_DIR);
    std::fs::create_dir_all(&vdir).map_err(io(&vdir))?;
    let mut summary = VtkSummary::default();
    let sample = sc.sample_interval_s();
    if interval_s < sample * (1.0 - 1e-9) {
        summary.warnings.push(format!(
            "output.vtk.interval_s = {interval_s} s is shorter than output.sample_interval_s = {sample} s: one frame per sample"
        ));
    }
    // Radii of every apple the run can hold (listed, generated, fed in), by name.
    let radii: BTreeMap<String, f64> = crate::world::roster::plan(sc)
        .map(|p| {
            p.initial
                .into_iter()
                .map(|(a, _)| a)
                .chain(p.feeds.into_iter().map(|(_, _, a)| a))
                .map(|a| (a.name, a.diameter_m / 2.0))
                .collect()
        })
        .unwrap_or_default();
    let ids: BTreeMap<&str, i64> = apple_order
        .iter()
        .enumerate()
        .map(|(k, n)| (*n, k as i64))
        .collect();
    let mut lo = Vec3::splat(f64::INFINITY);
    let mut hi = Vec3::splat(f64::NEG_INFINITY);
    let mut next_due = 0.0f64;
    let mut unknown: Vec<String> = Vec::new();
    let bodies = super::csv_file::locate(dir, "bodies.csv");
    let parse = |r: &csv::StringRecord, i: usize| -> Result<f64, VtkError> {
        let name = super::BODIES_HEADER
            .iter()
            .chain(&super::BODIES_SHAPE_HEADER)
            .nth(i)
            .copied()
            .unwrap_or("?");
        r.get(i)
            .and_then(|x| x.parse().ok())
            .ok_or_else(|| VtkError::Bodies {
                path: bodies.clone(),
                message: format!("bad number '{}' in column {name}", r.get(i).unwrap_or("")),
            })
    };
    for_each_sample(&bodies, |t, rows, shape_cols| {
        if t + 1e-9 * interval_s < next_due {
            return Ok(());
        }
        next_due = ((t / interval_s + 1e-9).floor() + 1.0) * interval_s;
        let mut apples = Vec::with_capacity(rows.len());
        for r in rows {
            let v3 = |i: usize| -> Result<[f64; 3], VtkError> {
                Ok([parse(r, i)?, parse(r, i + 1)?, parse(r, i + 2)?])
            };
            let id = ids.get(&r[1]).copied().unwrap_or(-1);
            let radius = match radii.get(&r[1]) {
                Some(&r) => r,
                None => {
                    if !unknown.iter().any(|u| u == &r[1]) {
                        unknown.push(r[1].to_string());
                    }
                    f64::NAN
                }
            };
            let shape = match shape_cols {
                Some(sc) => Some(FrameShape {
                    diameter: parse(r, sc.diameter)?,
                    height: parse(r, sc.height)?,
                    q: [
                        parse(r, sc.height + 1)?,
                        parse(r, sc.height + 2)?,
                        parse(r, sc.height + 3)?,
                        parse(r, sc.height + 4)?,
                    ],
                }),
                None => None,
            };
            let p = v3(2)?;
            let c = Vec3::from_array(p);
            // A spheroid reaches out to its larger semi-axis.
            let rr = match &shape {
                Some(sh) => 0.5 * sh.diameter.max(sh.height),
                None if radius.is_finite() => radius,
                None => 0.0,
            };
            lo = lo.min(c - Vec3::splat(rr));
            hi = hi.max(c + Vec3::splat(rr));
            apples.push(FrameApple {
                id,
                radius,
                p,
                v: v3(5)?,
                w: v3(8)?,
                f: v3(11)?,
                bruise: u8::from(bruise.bruised_by(&r[1], t)),
                shape,
            });
        }
        let rel = format!("{VTK_DIR}/{APPLES_PREFIX}{:06}.vtp", summary.frames.len());
        let path = dir.join(&rel);
        atomic::write_file(&path, apples_vtp(&apples, shape_cols.is_some()).as_bytes())
            .map_err(io(&path))?;
        summary.frames.push((t, rel));
        Ok(())
    })?;
    for u in unknown {
        summary.warnings.push(format!(
            "vtk: apple '{u}' of bodies.csv is not in the scenario: its radius is unknown (NaN)"
        ));
    }
    if !(lo.is_finite() && hi.is_finite()) {
        lo = Vec3::splat(-0.5);
        hi = Vec3::splat(0.5);
    }
    let (meshes, warnings) = surfaces.tessellate(lo, hi);
    summary.warnings.extend(warnings);
    let fixed: Vec<(usize, &Mesh)> = meshes
        .iter()
        .enumerate()
        .filter(|(k, _)| surfaces.items[*k].motion.is_none())
        .collect();
    let spath = vdir.join(SURFACES_FILE);
    atomic::write_file(&spath, surfaces_vtp(&fixed).as_bytes()).map_err(io(&spath))?;
    let moving = surfaces.moves();
    if moving {
        for (k, (t, _)) in summary.frames.iter().enumerate() {
            let posed = surfaces.moving_meshes(*t, lo, hi);
            let refs: Vec<(usize, &Mesh)> = posed.iter().map(|(k, m)| (*k, m)).collect();
            let path = dir.join(moving_file(k));
            atomic::write_file(&path, surfaces_vtp(&refs).as_bytes()).map_err(io(&path))?;
        }
    }
    let n = summary.frames.len();
    remove_stale_frames(&vdir, APPLES_PREFIX, n)?;
    // A run without moving surfaces leaves none of an earlier run's.
    remove_stale_frames(&vdir, MOVING_PREFIX, if moving { n } else { 0 })?;
    let ppath = dir.join(PVD_FILE);
    atomic::write_file(&ppath, pvd(&summary.frames, moving).as_bytes()).map_err(io(&ppath))?;
    Ok(summary)
}

/// Removes `PREFIXNNNNNN.vtp` with NNNNNN >= `count` (left by a longer earlier run).
fn remove_stale_frames(vdir: &Path, prefix: &str, count: usize) -> Result<(), VtkError> {
    for entry in std::fs::read_dir(vdir).map_err(io(vdir))? {
        let entry = entry.map_err(io(vdir))?;
        let name = entry.file_name();
        let name = name.to_string_lossy();
        let Some(num) = name
            .strip_prefix(prefix)
            .and_then(|n| n.strip_suffix(".vtp"))
        else {
            continue;
        };
        if num.parse::<usize>().is_ok_and(|k| k >= count) {
            let p = entry.path();
            std::fs::remove_file(&p).map_err(io(&p))?;
        }
    }
    Ok(())
}
