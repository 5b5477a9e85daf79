//! ParaView output (issue 4 acceptance): every file of `scene.pvd` is read back by an
//! independent VTK reader (the `vtkio` crate) with the right number of points and arrays per
//! frame, the values of `bodies.csv`, and the surfaces' triangles.

use crate::common;
use applesim::analysis::bruise::BruiseReport;
use applesim::contact::Material;
use applesim::layer::SurfaceOptions;
use applesim::output::vtk::{self, SceneSurfaces};
use applesim::scenario::{self, Scenario, VtkSpec};
use common::*;
use rapier3d_f64::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use vtkio::model::{Attribute, DataSet, Piece, PolyDataPiece};

/// Point arrays of every apple frame: name and components.
const ARRAYS: [(&str, usize); 6] = [
    ("radius", 1),
    ("velocity", 3),
    ("angular_velocity", 3),
    ("contact_force", 3),
    ("bruise", 1),
    ("apple_id", 1),
];

fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn piece(path: &Path) -> PolyDataPiece {
    let vtk = vtkio::Vtk::import(path).unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
    let DataSet::PolyData { mut pieces, .. } = vtk.data else {
        panic!("{}: not PolyData", path.display());
    };
    assert_eq!(pieces.len(), 1);
    match pieces.remove(0) {
        Piece::Inline(p) => *p,
        _ => panic!("{}: piece not inline", path.display()),
    }
}

fn array(p: &PolyDataPiece, name: &str) -> (usize, Vec<f64>) {
    p.data
        .point
        .iter()
        .find_map(|a| match a {
            Attribute::DataArray(d) if d.name == name => Some((
                d.elem.num_comp() as usize,
                d.data.clone().cast_into::<f64>().unwrap(),
            )),
            _ => None,
        })
        .unwrap_or_else(|| panic!("no point array {name}"))
}

/// (timestep, part, file) of every DataSet of a .pvd, read with an XML parser.
fn pvd(path: &Path) -> Vec<(f64, u32, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    assert_eq!(doc.root_element().attribute("type"), Some("Collection"));
    doc.descendants()
        .filter(|n| n.has_tag_name("DataSet"))
        .map(|n| {
            (
                n.attribute("timestep").unwrap().parse().unwrap(),
                n.attribute("part").unwrap().parse().unwrap(),
                n.attribute("file").unwrap().to_string(),
            )
        })
        .collect()
}

/// How many files of the folder `dir` have names starting with `prefix`.
fn files_starting(dir: &Path, prefix: &str) -> usize {
    std::fs::read_dir(dir)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .starts_with(prefix)
        })
        .count()
}

fn drops() -> Scenario {
    drops_with_ke(None)
}

/// [`drops`], with eq. 12's ke set (the shipped drop is elastic).
fn drops_with_ke(ke: Option<f64>) -> Scenario {
    // Three apples dropped on steel under gravity at 0.5, 1.0 and 1.4 m/s; with ke = 0.09 the
    // last one absorbs about 0.095 J (91 % of 1/2 m v^2), over the default damage model's
    // 0.08 J threshold, and is bruised from its peak at t = 2.9 ms.
    let mut sc = shipped("scenarios/drop_on_steel.json");
    if ke.is_some() {
        sc.contact.ke = ke;
    }
    let a0 = sc.apples[0].clone();
    sc.apples.clear();
    for (k, v) in [0.5, 1.0, 1.4].into_iter().enumerate() {
        let mut a = a0.clone();
        a.name = format!("a{k}");
        a.position_m = [0.2 * k as f64, 0.0, 0.0401];
        a.velocity_m_s = [0.0, 0.0, -v];
        sc.apples.push(a);
    }
    sc.output.sample_interval_s = Some(1e-3);
    sc.output.vtk = Some(VtkSpec { interval_s: 0.005 });
    scenario::validate(&sc).unwrap();
    sc
}

#[test]
fn run_frames_read_back_with_vtkio() {
    // Eq. 12's loss, e = sqrt(ke) = 0.3: the fastest apple is bruised.
    let sc = drops_with_ke(Some(0.09));
    let dir = tmp("vtk_run");
    let r = applesim::run::to_dir(&sc, &repo("scenarios"), &dir, &mut |_| {}).unwrap();
    let index = pvd(&dir.join("scene.pvd"));
    let frames: Vec<&(f64, u32, String)> = index.iter().filter(|d| d.1 == 0).collect();
    // 0.03 s at 5 ms: frames at 0, 5, ..., 30 ms.
    let times: Vec<f64> = frames.iter().map(|f| f.0).collect();
    println!("frame times {times:?}");
    assert_eq!(frames.len(), 7);
    for (k, t) in times.iter().enumerate() {
        assert!((t - 0.005 * k as f64).abs() < 1e-9, "{times:?}");
    }
    assert_eq!(r.metrics["vtk_frames"], 7.0);
    // bodies.csv, read independently, for the values.
    let mut rows: BTreeMap<String, Vec<Vec<f64>>> = BTreeMap::new();
    let mut rd = csv::Reader::from_path(dir.join("bodies.csv")).unwrap();
    for rec in rd.records() {
        let rec = rec.unwrap();
        rows.entry(rec[0].to_string())
            .or_default()
            .push((2..14).map(|i| rec[i].parse().unwrap()).collect());
    }
    let t_bruise = r
        .events
        .iter()
        .find(|e| e.impact.is_some_and(|i| i.a_absorbed_energy_j > 0.08))
        .map(|e| e.t_peak_s)
        .unwrap();
    assert_eq!(
        r.events
            .iter()
            .filter(|e| e.impact.is_some_and(|i| i.a_absorbed_energy_j > 0.08))
            .count(),
        1
    );
    for (t, _, file) in &frames {
        let p = piece(&dir.join(file));
        assert_eq!(p.num_points(), 3, "{file}");
        assert_eq!(p.verts.as_ref().unwrap().num_cells(), 3);
        assert_eq!(p.data.point.len(), ARRAYS.len(), "{file}");
        for (name, comps) in ARRAYS {
            let (c, v) = array(&p, name);
            assert_eq!((c, v.len()), (comps, 3 * comps), "{file} {name}");
        }
        let want = &rows[&t.to_string()];
        let pts = p.points.clone().cast_into::<f64>().unwrap();
        let vel = array(&p, "velocity").1;
        let force = array(&p, "contact_force").1;
        for (k, row) in want.iter().enumerate() {
            assert_eq!(&pts[3 * k..3 * k + 3], &row[0..3]);
            assert_eq!(&vel[3 * k..3 * k + 3], &row[3..6]);
            assert_eq!(&force[3 * k..3 * k + 3], &row[9..12]);
        }
        assert_eq!(array(&p, "radius").1, vec![0.04; 3]);
        assert_eq!(array(&p, "apple_id").1, vec![0.0, 1.0, 2.0]);
        let flag = if *t >= t_bruise { 1.0 } else { 0.0 };
        assert_eq!(array(&p, "bruise").1, vec![0.0, 0.0, flag], "t = {t}");
    }
    // The surfaces: the floor as one square patch (2 triangles) under the scene.
    let surf: Vec<&(f64, u32, String)> = index.iter().filter(|d| d.1 == 1).collect();
    assert_eq!(surf.len(), frames.len());
    let s = piece(&dir.join(&surf[0].2));
    assert_eq!(s.polys.as_ref().unwrap().num_cells(), 2);
    assert_eq!(s.num_points(), 4);
    let z = s.points.clone().cast_into::<f64>().unwrap();
    assert!(
        z.chunks(3).all(|p| p[2].abs() < 1e-12),
        "floor at z = 0: {z:?}"
    );
    let xs: Vec<f64> = z.chunks(3).map(|p| p[0]).collect();
    let (lo, hi) = xs
        .iter()
        .fold((f64::MAX, f64::MIN), |a, &x| (a.0.min(x), a.1.max(x)));
    assert!(
        lo < -0.04 && hi > 0.44,
        "patch spans the apples: {lo} .. {hi}"
    );
}

#[test]
fn frames_follow_a_changing_apple_count_and_surfaces_are_tessellated() {
    // bodies.csv with 2, 3 and 1 apples (one of them not in the scenario), written by hand: the
    // apple count may change from frame to frame (apples fed in later).
    let mut sc = drops();
    sc.output.sample_interval_s = Some(0.001);
    let dir = tmp("vtk_count");
    std::fs::create_dir_all(&dir).unwrap();
    let head =
        "time_s,apple,x_m,y_m,z_m,vx_m_s,vy_m_s,vz_m_s,wx_rad_s,wy_rad_s,wz_rad_s,fx_n,fy_n,fz_n\n";
    let row = |t: f64, a: &str| format!("{t},{a},1,2,3,0.1,0.2,0.3,4,5,6,7,8,9\n");
    let mut csv = String::from(head);
    for a in ["a0", "a1"] {
        csv += &row(0.0, a);
    }
    for a in ["a0", "a1", "late"] {
        csv += &row(0.001, a);
    }
    csv += &row(0.002, "a2");
    std::fs::write(dir.join("bodies.csv"), csv).unwrap();

    // A world with one surface of each drawable kind, plus a segment (drawn as its box).
    let mut w = applesim::world::build(&sc, Path::new(".")).unwrap();
    let mat = w
        .layer
        .add_material("steel2", Material::from_youngs(2e11, 0.3, None).unwrap());
    let tri_v = vec![
        Vector::new(0.0, 0.0, 0.0),
        Vector::new(1.0, 0.0, 0.0),
        Vector::new(0.0, 1.0, 0.0),
        Vector::new(1.0, 1.0, 0.2),
    ];
    let tri_i = vec![[0, 1, 2], [1, 3, 2]];
    let extra = [
        ("box", ColliderBuilder::cuboid(0.1, 0.2, 0.05)),
        ("ball", ColliderBuilder::ball(0.3)),
        ("mesh", ColliderBuilder::trimesh(tri_v, tri_i).unwrap()),
        ("rail", ColliderBuilder::capsule_z(0.5, 0.02)),
        (
            "wire",
            ColliderBuilder::segment(Vector::ZERO, Vector::new(0.0, 0.0, 1.0)),
        ),
    ];
    for (name, b) in extra {
        let ch = w
            .physics
            .colliders
            .insert(b.translation(Vector::new(2.0, 0.0, 0.0)));
        w.layer
            .add_surface(
                &mut w.physics.colliders,
                ch,
                SurfaceOptions::hertz(name, mat),
            )
            .unwrap();
        w.surface_colliders.push(ch);
    }
    let surfaces = SceneSurfaces::capture(&w);
    assert_eq!(surfaces.len(), 6);
    let order = ["a0", "a1", "a2"];
    let out = vtk::write_vtk(
        &dir,
        &sc,
        &surfaces,
        &BruiseReport::default(),
        &order,
        0.001,
    )
    .unwrap();
    println!("{:?}", out.warnings);
    assert!(out.warnings.iter().any(|m| m.contains("'late'")));
    assert!(out
        .warnings
        .iter()
        .any(|m| m.contains("'wire'") && m.contains("bounding box")));
    let index = pvd(&dir.join("scene.pvd"));
    let counts: Vec<usize> = index
        .iter()
        .filter(|d| d.1 == 0)
        .map(|d| piece(&dir.join(&d.2)).num_points())
        .collect();
    assert_eq!(counts, vec![2, 3, 1]);
    let second = piece(&dir.join(&index[2].2));
    assert_eq!(array(&second, "apple_id").1, vec![0.0, 1.0, -1.0]);
    let r = array(&second, "radius").1;
    assert!(r[0] == 0.04 && r[2].is_nan());
    // Triangles per surface, from the cell array surface_id: floor patch 2, box 12, ball as parry
    // tessellates it (32 x 16), mesh 2, capsule as parry tessellates it, segment's box 12.
    let s = piece(&dir.join(&index[1].2));
    let ids: Vec<f64> = s
        .data
        .cell
        .iter()
        .find_map(|a| match a {
            Attribute::DataArray(d) if d.name == "surface_id" => {
                Some(d.data.clone().cast_into::<f64>().unwrap())
            }
            _ => None,
        })
        .unwrap();
    let per: Vec<usize> = (0..6)
        .map(|k| ids.iter().filter(|&&i| i == k as f64).count())
        .collect();
    let ball = rapier3d_f64::parry::shape::Ball::new(0.3)
        .to_trimesh(32, 16)
        .1
        .len();
    let capsule = rapier3d_f64::parry::shape::Capsule::new_z(0.5, 0.02)
        .to_trimesh(32, 16)
        .1
        .len();
    println!("triangles per surface {per:?}");
    assert_eq!(per, vec![2, 12, ball, 2, capsule, 12]);
    assert_eq!(s.polys.as_ref().unwrap().num_cells(), ids.len());
    // The ball's vertices lie on its sphere around (2, 0, 0).
    let pts = s.points.clone().cast_into::<f64>().unwrap();
    let first_ball_vertex = 4 + 8;
    let p = &pts[3 * first_ball_vertex..3 * first_ball_vertex + 3];
    let d = ((p[0] - 2.0).powi(2) + p[1].powi(2) + p[2].powi(2)).sqrt();
    assert!((d - 0.3).abs() < 1e-12, "ball vertex at distance {d}");
}

#[test]
fn rerun_with_fewer_frames_removes_stale_ones() {
    let mut sc = drops();
    let dir = tmp("vtk_rerun");
    applesim::run::to_dir(&sc, &repo("scenarios"), &dir, &mut |_| {}).unwrap();
    sc.output.vtk = Some(VtkSpec { interval_s: 0.01 });
    applesim::run::to_dir(&sc, &repo("scenarios"), &dir, &mut |_| {}).unwrap();
    let n = files_starting(&dir.join("vtk"), "apples_");
    assert_eq!(n, 4, "frames at 0, 10, 20, 30 ms only");
    assert_eq!(pvd(&dir.join("scene.pvd")).len(), 8);
}

#[test]
fn bad_interval_is_refused_with_the_field() {
    let mut sc = drops();
    sc.output.vtk = Some(VtkSpec { interval_s: 0.0 });
    let err = scenario::validate(&sc).unwrap_err().to_string();
    assert_eq!(
        err,
        "output.vtk.interval_s: 0 s is outside the range of fruit handling (1e-9 s <= t <= 1e5 s)"
    );
}

#[test]
fn analysis_files_are_byte_identical_across_runs() {
    // Determinism (project rule): the files of this feature, run twice.
    let sc = drops();
    let (a, b) = (tmp("det_a"), tmp("det_b"));
    for d in [&a, &b] {
        applesim::run::to_dir(&sc, &repo("scenarios"), d, &mut |_| {}).unwrap();
        applesim::output::plot::plot_runs(
            std::slice::from_ref(d),
            d,
            &applesim::output::plot::PlotOptions::default(),
        )
        .unwrap();
    }
    let mut files = vec![
        "forces.csv".to_string(),
        "pulse_fits.csv".into(),
        "apple_contacts.csv".into(),
        "bruises.csv".into(),
        "scene.pvd".into(),
        "force_time.svg".into(),
        "linear_velocity.svg".into(),
        "angular_velocity.svg".into(),
    ];
    for e in std::fs::read_dir(a.join("vtk")).unwrap() {
        files.push(format!("vtk/{}", e.unwrap().file_name().to_string_lossy()));
    }
    assert_eq!(files.len(), 8 + 8);
    for f in &files {
        let (x, y) = (
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
        );
        assert!(x == y, "{f} differs between two runs");
    }
}

#[test]
fn handling_line_with_fed_apples_and_bin() {
    // The shipped handling line (belt, trough chute, bin; apples fed in by a source at 4 per
    // second) for 1.5 s: the apple count grows from frame to frame, the surfaces are drawn.
    let mut sc = shipped("scenarios/handling_line.json");
    sc.duration_s = 1.5;
    sc.output.sample_interval_s = Some(0.01);
    sc.output.vtk = Some(VtkSpec { interval_s: 0.1 });
    let dir = tmp("vtk_line");
    let r = applesim::run::to_dir(&sc, &repo("scenarios"), &dir, &mut |_| {}).unwrap();
    let mut per_time: BTreeMap<String, usize> = BTreeMap::new();
    let mut rd = csv::Reader::from_path(dir.join("bodies.csv")).unwrap();
    for rec in rd.records() {
        *per_time.entry(rec.unwrap()[0].to_string()).or_default() += 1;
    }
    let index = pvd(&dir.join("scene.pvd"));
    let frames: Vec<&(f64, u32, String)> = index.iter().filter(|d| d.1 == 0).collect();
    let mut counts = Vec::new();
    for (t, _, file) in &frames {
        let p = piece(&dir.join(file));
        let n = p.num_points();
        assert_eq!(
            n,
            per_time.get(&t.to_string()).copied().unwrap_or(0),
            "t = {t}"
        );
        assert_eq!(p.data.point.len(), ARRAYS.len());
        for (name, comps) in ARRAYS {
            assert_eq!(array(&p, name).1.len(), n * comps, "{file} {name}");
        }
        // Fed-in apples have the source's sizes (mean 75 mm +- 5 mm).
        assert!(array(&p, "radius")
            .1
            .iter()
            .all(|&r| (0.035..=0.040).contains(&r)));
        counts.push(n);
    }
    println!("apples per frame {counts:?}");
    assert_eq!(frames.len(), 16);
    assert!(counts.windows(2).all(|w| w[0] <= w[1]) && counts[0] < *counts.last().unwrap());
    assert_eq!(*counts.last().unwrap(), r.apples.len());
    // Belt, chute and the bin's floor and four walls: one surface_id per part.
    let s = piece(&dir.join(&index[1].2));
    let ids: std::collections::BTreeSet<i64> = s
        .data
        .cell
        .iter()
        .find_map(|a| match a {
            Attribute::DataArray(d) if d.name == "surface_id" => {
                Some(d.data.clone().cast_into::<f64>().unwrap())
            }
            _ => None,
        })
        .unwrap()
        .into_iter()
        .map(|x| x as i64)
        .collect();
    println!(
        "surface parts {ids:?}, {} triangles",
        s.polys.as_ref().unwrap().num_cells()
    );
    assert_eq!(ids.len(), 7);
    assert!(
        r.warnings.iter().all(|w| !w.contains("bounding box")),
        "{:?}",
        r.warnings
    );
}

#[test]
fn trough_chute_is_drawn_as_its_half_pipe() {
    let mut sc = drops();
    sc.surfaces.push(
        serde_json::from_value(serde_json::json!({
            "type": "chute", "name": "trough", "material": "steel", "profile": "trough",
            "length_m": 0.4, "radius_m": 0.1, "position_m": [3.0, 0.0, 0.5]
        }))
        .unwrap(),
    );
    scenario::validate(&sc).unwrap();
    let w = applesim::world::build(&sc, Path::new(".")).unwrap();
    let surfaces = SceneSurfaces::capture(&w);
    let (meshes, warnings) = surfaces.tessellate(Vector::ZERO, Vector::ONE);
    assert!(warnings.is_empty(), "{warnings:?}");
    let m = &meshes[1];
    // 48 strips of 2 triangles across the half pipe, both ends of each generator line.
    assert_eq!((m.points.len(), m.triangles.len()), (98, 96));
    // Every vertex lies on the circle of radius 0.1 m through the two rims and the bottom line
    // (half pipe: the rims' midpoint is the axis).
    let axis = 0.5 * (m.points[0] + m.points[96]);
    for p in &m.points {
        let d = ((p.y - axis.y).powi(2) + (p.z - axis.z).powi(2)).sqrt();
        assert!(
            (d - 0.1).abs() < 1e-9,
            "vertex {p:?} at {d} m from the axis"
        );
        assert!((p.x - 3.0).abs() <= 0.2 + 1e-9);
    }
    let bottom = m.points.iter().map(|p| p.z).fold(f64::MAX, f64::min);
    assert!((axis.z - bottom - 0.1).abs() < 1e-9, "opens upwards");
}

/// Cell array `name` of a surfaces file, as numbers.
fn cell_array(p: &PolyDataPiece, name: &str) -> Vec<f64> {
    p.data
        .cell
        .iter()
        .find_map(|a| match a {
            Attribute::DataArray(d) if d.name == name => {
                Some(d.data.clone().cast_into::<f64>().unwrap())
            }
            _ => None,
        })
        .unwrap_or_else(|| panic!("no cell array {name}"))
}

/// The moving box of [`moving_box_is_drawn_per_frame_at_its_motion_offset`]: centre, size, and
/// the keyframes of its offset (m), held after the last.
const BOX_CENTRE: [f64; 3] = [1.0, 0.0, 0.05];
const BOX_SIZE: [f64; 3] = [0.1, 0.08, 0.1];
const BOX_KEYS: [(f64, [f64; 3]); 2] = [(0.0, [0.0; 3]), (0.02, [0.01, -0.004, 0.006])];

/// The box's offset at `t`, interpolated here (not by the crate): linear between the two keys,
/// held after the last.
fn box_offset(t: f64) -> [f64; 3] {
    let (t0, a) = BOX_KEYS[0];
    let (t1, b) = BOX_KEYS[1];
    let f = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
    [0, 1, 2].map(|i| a[i] + f * (b[i] - a[i]))
}

#[test]
fn moving_box_is_drawn_per_frame_at_its_motion_offset() {
    // The drops of `drops()` beside a box raised and shifted by translation keyframes: the box
    // gets a file per frame, posed by its motion; the floor stays in the fixed file.
    let mut sc = drops();
    sc.surfaces.push(
        serde_json::from_value(serde_json::json!({
            "name": "lift", "type": "box", "material": "steel",
            "size_m": BOX_SIZE, "position_m": BOX_CENTRE,
            "motion": {"translation": {"keyframes": BOX_KEYS}}
        }))
        .unwrap(),
    );
    scenario::validate(&sc).unwrap();
    let dir = tmp("vtk_moving");
    applesim::run::into_dir(&sc, &repo("scenarios"), &dir, &mut |_| {}).unwrap();
    let index = pvd(&dir.join("scene.pvd"));
    let parts = |part: u32| -> Vec<(f64, String)> {
        index
            .iter()
            .filter(|d| d.1 == part)
            .map(|d| (d.0, d.2.clone()))
            .collect()
    };
    let (apples, fixed, moving) = (parts(0), parts(1), parts(2));
    assert_eq!(index.len(), 3 * 7, "three parts per frame, 7 frames");
    for (k, ((ta, _), (tm, fm))) in apples.iter().zip(&moving).enumerate() {
        assert_eq!(ta, tm);
        assert_eq!(fm, &format!("vtk/moving_{k:06}.vtp"));
    }
    assert!(fixed.iter().all(|f| f.1 == "vtk/surfaces.vtp"));
    // The fixed file: the floor alone (its square patch), surface_id 0.
    let s = piece(&dir.join("vtk/surfaces.vtp"));
    assert_eq!(
        (s.num_points(), cell_array(&s, "surface_id")),
        (4, vec![0.0; 2])
    );
    // The box's corners at rest, from the scenario.
    let corners: Vec<[f64; 3]> = (0..8)
        .map(|c| [0, 1, 2].map(|i| BOX_CENTRE[i] + BOX_SIZE[i] / 2.0 * [-1.0, 1.0][(c >> i) & 1]))
        .collect();
    let mut worst = 0.0f64;
    for (t, f) in &moving {
        let p = piece(&dir.join(f));
        // The box alone: 12 triangles of surface 1 (the floor is not in it).
        assert_eq!(cell_array(&p, "surface_id"), vec![1.0; 12], "{f}");
        assert_eq!(p.num_points(), 8, "{f}");
        let pts = p.points.clone().cast_into::<f64>().unwrap();
        let d = box_offset(*t);
        // Every vertex is a corner moved by the offset, and every corner is drawn.
        for want in &corners {
            let e = pts
                .chunks(3)
                .map(|q| {
                    (0..3)
                        .map(|i| (q[i] - want[i] - d[i]).abs())
                        .fold(0.0, f64::max)
                })
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(e);
        }
        assert_eq!(pts.len() / 3, corners.len(), "{f}: one vertex per corner");
    }
    println!("largest vertex error against the prescribed offset: {worst:e} m");
    assert!(worst < 1e-9, "{worst}");
    // The last frames are past the last keyframe: the box held at its final offset.
    assert!(moving.last().unwrap().0 > BOX_KEYS[1].0);
    // The same folder rerun without the motion: the moving files are gone, the index is back to
    // two parts per frame.
    applesim::run::into_dir(&drops(), &repo("scenarios"), &dir, &mut |_| {}).unwrap();
    let left = files_starting(&dir.join("vtk"), "moving_");
    assert_eq!(left, 0);
    assert!(pvd(&dir.join("scene.pvd")).iter().all(|d| d.1 < 2));
}

/// `drops()`'s floor, as the build before moving surfaces were drawn per frame wrote it (its
/// `applesim run` of the same scenario, byte for byte).
const FLOOR_VTP: &str = r#"<?xml version="1.0"?>
<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">
  <PolyData>
    <Piece NumberOfPoints="4" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="2">
      <CellData Scalars="surface_id">
        <DataArray type="Int64" Name="surface_id" format="ascii">
          0 0
        </DataArray>
      </CellData>
      <Points>
        <DataArray type="Float64" Name="points" NumberOfComponents="3" format="ascii">
          0.6993989020187892 -0.4993989020187891 0 0.6993989020187892 0.4993989020187891 0 -0.2993989020187891 0.4993989020187891 0 -0.2993989020187891 -0.4993989020187891 0
        </DataArray>
      </Points>
      <Polys>
        <DataArray type="Int64" Name="connectivity" format="ascii">
          0 1 2 0 2 3
        </DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">
          3 6
        </DataArray>
      </Polys>
    </Piece>
  </PolyData>
</VTKFile>
"#;

#[test]
fn without_motion_the_files_are_as_before() {
    // No surface moves: no moving files, the one surfaces file as before, and the index with
    // the apples and the surfaces per frame, in the form it had.
    let sc = drops();
    let dir = tmp("vtk_fixed");
    applesim::run::to_dir(&sc, &repo("scenarios"), &dir, &mut |_| {}).unwrap();
    let mut names: Vec<String> = std::fs::read_dir(dir.join("vtk"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut want: Vec<String> = (0..7).map(|k| format!("apples_{k:06}.vtp")).collect();
    want.push("surfaces.vtp".into());
    assert_eq!(names, want);
    assert_eq!(
        std::fs::read_to_string(dir.join("vtk/surfaces.vtp")).unwrap(),
        FLOOR_VTP
    );
    let mut index = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (k, t) in ["0", "0.005", "0.01", "0.015", "0.02", "0.025", "0.03"]
        .iter()
        .enumerate()
    {
        index.push_str(&format!(
            "    <DataSet timestep=\"{t}\" group=\"\" part=\"0\" file=\"vtk/apples_{k:06}.vtp\"/>\n    <DataSet timestep=\"{t}\" group=\"\" part=\"1\" file=\"vtk/surfaces.vtp\"/>\n"
        ));
    }
    index.push_str("  </Collection>\n</VTKFile>\n");
    assert_eq!(
        std::fs::read_to_string(dir.join("scene.pvd")).unwrap(),
        index
    );
}

/// The point arrays a frame of a run with spheroids adds after [`ARRAYS`] (issue 29).
const SHAPE_ARRAYS: [(&str, usize); 5] = [
    ("diameter", 1),
    ("height", 1),
    ("orientation", 4),
    ("axis", 3),
    ("shape_tensor", 9),
];

/// A run with spheroids (issue 29): every frame holds the shape arrays, equal to bodies.csv's
/// shape columns, and `shape_tensor` is the frame's active tensor R diag(D, D, H) R^T, which
/// ParaView's Tensor Glyph turns into the apple: its axis is an eigenvector of eigenvalue H and
/// every direction across it one of eigenvalue D (within 1e-15 m of the quaternion as printed).
/// At t = 0 the orientations are the scenario's and the arrays are the closed forms of those
/// turns (bodies.csv prints 9 digits: within 1e-9):
/// - an oblate apple (80 x 60 mm) turned 90 degrees about x: orientation (cos 45, sin 45, 0, 0),
///   axis (0, -1, 0), tensor diag(D, H, D);
/// - an elongated one (60 x 90 mm) turned 30 degrees about y: (cos 15, 0, sin 15, 0), axis
///   (sin 30, 0, cos 30), tensor D I + (H - D) k k^T: xx = D + (H - D)/4, zz = D + 3 (H - D)/4,
///   xz = (H - D) sqrt(3)/4;
/// - a sphere of the same run (70 mm): the identity, axis z, tensor D I.
#[test]
fn spheroids_carry_their_shape_for_tensor_glyphs() {
    let mut sc = drops();
    sc.apples = serde_json::from_value(serde_json::json!([
        { "name": "oblate", "material": "apple", "diameter_m": 0.08, "height_m": 0.06,
          "rotation": { "axis": [1, 0, 0], "angle_deg": 90 }, "position_m": [0, 0, 0.0401] },
        { "name": "long", "material": "apple", "diameter_m": 0.06, "height_m": 0.09,
          "rotation": { "axis": [0, 1, 0], "angle_deg": 30 }, "position_m": [0.2, 0, 0.1] },
        { "name": "ball", "material": "apple", "diameter_m": 0.07, "position_m": [0.4, 0, 0.1] }
    ]))
    .unwrap();
    scenario::validate(&sc).unwrap();
    let dir = tmp("vtk_spheroids");
    applesim::run::to_dir(&sc, &repo("scenarios"), &dir, &mut |_| {}).unwrap();

    // bodies.csv's shape columns, read independently: per time, per row, D, H, qw, qx, qy, qz.
    let mut rows: BTreeMap<String, Vec<[f64; 6]>> = BTreeMap::new();
    let mut rd = csv::Reader::from_path(dir.join("bodies.csv")).unwrap();
    let h = rd.headers().unwrap().clone();
    let col = |n: &str| h.iter().position(|x| x == n).unwrap();
    let cols = ["diameter_m", "height_m", "qw", "qx", "qy", "qz"].map(col);
    for rec in rd.records() {
        let rec = rec.unwrap();
        rows.entry(rec[0].to_string())
            .or_default()
            .push(cols.map(|c| rec[c].parse().unwrap()));
    }

    let frames: Vec<(f64, u32, String)> = pvd(&dir.join("scene.pvd"))
        .into_iter()
        .filter(|d| d.1 == 0)
        .collect();
    assert_eq!(frames.len(), 7);
    for (t, _, file) in &frames {
        let text = std::fs::read_to_string(dir.join(file)).unwrap();
        assert!(
            text.contains(
                "<PointData Scalars=\"radius\" Vectors=\"velocity\" Tensors=\"shape_tensor\">"
            ),
            "{file}: shape_tensor is not the active tensor"
        );
        let p = piece(&dir.join(file));
        assert_eq!(p.data.point.len(), ARRAYS.len() + SHAPE_ARRAYS.len());
        for (name, comps) in ARRAYS.iter().chain(&SHAPE_ARRAYS) {
            let (c, v) = array(&p, name);
            assert_eq!((c, v.len()), (*comps, 3 * comps), "{file} {name}");
        }
        let want = &rows[&t.to_string()];
        let (d, hh, q) = (
            array(&p, "diameter").1,
            array(&p, "height").1,
            array(&p, "orientation").1,
        );
        let (axis, tensor) = (array(&p, "axis").1, array(&p, "shape_tensor").1);
        for (k, row) in want.iter().enumerate() {
            assert_eq!([d[k], hh[k]], [row[0], row[1]], "{file} apple {k}");
            assert_eq!(&q[4 * k..4 * k + 4], &row[2..6], "{file} apple {k}");
            let ax = &axis[3 * k..3 * k + 3];
            let tt = &tensor[9 * k..9 * k + 9];
            let n = ax.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!((n - 1.0).abs() < 1e-15, "{file} apple {k}: |axis| = {n}");
            // T k = H k, and T u = D u for u across the axis (u = k x e, e the world axis
            // least along k).
            let mul = |v: [f64; 3]| [0, 1, 2].map(|i| (0..3).map(|j| tt[3 * i + j] * v[j]).sum());
            let e = if ax[0].abs() < 0.5 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            };
            let u = [
                ax[1] * e[2] - ax[2] * e[1],
                ax[2] * e[0] - ax[0] * e[2],
                ax[0] * e[1] - ax[1] * e[0],
            ];
            let (tk, tu): ([f64; 3], [f64; 3]) = (mul([ax[0], ax[1], ax[2]]), mul(u));
            for i in 0..3 {
                assert!(
                    (tk[i] - row[1] * ax[i]).abs() < 1e-15,
                    "{file} {k}: T k {tk:?}"
                );
                assert!(
                    (tu[i] - row[0] * u[i]).abs() < 1e-15,
                    "{file} {k}: T u {tu:?}"
                );
                for j in 0..3 {
                    assert_eq!(tt[3 * i + j], tt[3 * j + i], "{file} {k}: not symmetric");
                }
            }
        }
    }

    // t = 0: the closed forms of the scenario's turns.
    let p = piece(&dir.join(&frames[0].2));
    let (q, axis, tensor) = (
        array(&p, "orientation").1,
        array(&p, "axis").1,
        array(&p, "shape_tensor").1,
    );
    let (c45, s45) = (0.25 * std::f64::consts::PI).sin_cos();
    let (s15, c15) = (std::f64::consts::PI / 12.0).sin_cos();
    let r3 = 3f64.sqrt();
    let (dl, hl) = (0.06, 0.09);
    let want_q = [
        [s45, c45, 0.0, 0.0],
        [c15, 0.0, s15, 0.0],
        [1.0, 0.0, 0.0, 0.0],
    ];
    let want_axis = [[0.0, -1.0, 0.0], [0.5, 0.0, r3 / 2.0], [0.0, 0.0, 1.0]];
    let want_t = [
        [0.08, 0.0, 0.0, 0.0, 0.06, 0.0, 0.0, 0.0, 0.08],
        [
            dl + (hl - dl) / 4.0,
            0.0,
            (hl - dl) * r3 / 4.0,
            0.0,
            dl,
            0.0,
            (hl - dl) * r3 / 4.0,
            0.0,
            dl + 3.0 * (hl - dl) / 4.0,
        ],
        [0.07, 0.0, 0.0, 0.0, 0.07, 0.0, 0.0, 0.0, 0.07],
    ];
    let mut worst = 0.0f64;
    for k in 0..3 {
        for (got, want) in [
            (&q[4 * k..4 * k + 4], &want_q[k][..]),
            (&axis[3 * k..3 * k + 3], &want_axis[k][..]),
            (&tensor[9 * k..9 * k + 9], &want_t[k][..]),
        ] {
            for (g, w) in got.iter().zip(want) {
                worst = worst.max((g - w).abs());
                assert!(
                    (g - w).abs() < 1e-9,
                    "apple {k}: {got:?}, closed form {want:?}"
                );
            }
        }
    }
    println!("t = 0: largest difference from the closed forms {worst:e}");
}

/// A run of spheres writes its apple frames as before issue 29: no shape array, no active
/// tensor (the drop's 7 frames were also compared by hand, byte for byte, with the files of the
/// binary before the shape arrays were added).
#[test]
fn spheres_have_no_shape_arrays() {
    let sc = drops();
    let dir = tmp("vtk_spheres_no_shape");
    applesim::run::to_dir(&sc, &repo("scenarios"), &dir, &mut |_| {}).unwrap();
    let text = std::fs::read_to_string(dir.join("vtk/apples_000000.vtp")).unwrap();
    assert!(text.contains("<PointData Scalars=\"radius\" Vectors=\"velocity\">\n"));
    for name in SHAPE_ARRAYS.map(|a| a.0) {
        assert!(!text.contains(&format!("Name=\"{name}\"")), "{name}");
    }
}
