//! Mesh contacts merged on neighbouring triangles (README "Surfaces", `mesh`: "near-parallel
//! hits (within 30 degrees) on neighbouring triangles count as one contact"; docs/design.md,
//! Meshes: "a flat floor made of triangles pushes once ... matches the plane to the last digit,
//! on the diagonal too, while an apple in a V between two walls gets two contacts").
//!
//! - assets/floor_two_triangles.{obj,stl}: drops on the shared diagonal, on a shared corner
//!   vertex and inside one triangle give one contact each, bit-identical to the same drop on a
//!   plane (peak force, contact time, overlap, rebound).
//! - triangles are two-sided: the same from below;
//! - a valley of two flat faces (each two triangles) whose normals are 28 degrees apart gives one
//!   contact; 32 degrees apart, two; a V of two 45 degree walls, two.

use crate::common;
use applesim::record::events::ContactEvent;
use applesim::scenario::{self, Scenario};
use common::*;
use serde_json::{json, Value};
use std::path::PathBuf;

const R: f64 = 0.04;

fn drop(
    surfaces: Value,
    pos: [f64; 3],
    vel: [f64; 3],
    base: &std::path::Path,
) -> Vec<ContactEvent> {
    let v = json!({
        "duration_s": 0.02, "time_step_s": 1e-5, "gravity_m_s2": [0, 0, 0],
        "output": {"sample_interval_s": 1e-3, "force_history": false},
        "materials": {
            "apple": {"shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "steel": {"shear_modulus_pa": 8.1e10, "poisson_ratio": 0.28}},
        "contact": {"friction": 0.3, "ke": 1.0, "lambda_s_m": 1000},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 2.0 * R, "mass_kg": 0.107,
                    "position_m": pos, "velocity_m_s": vel}],
        "surfaces": surfaces
    });
    let sc: Scenario = scenario::from_json(&v.to_string(), "mesh").unwrap();
    scenario::validate(&sc).unwrap();
    let mut series = applesim::record::series::MemorySeries::default();
    applesim::sim::run(&sc, base, &mut series)
        .unwrap_or_else(|e| panic!("run failed: {e}"))
        .events
}

/// The fields of an event that a merged contact must reproduce exactly.
fn bits(e: &ContactEvent) -> [u64; 5] {
    [
        e.peak_force_n.to_bits(),
        e.duration_s.unwrap().to_bits(),
        e.max_overlap_m.to_bits(),
        e.separation_speed_m_s.unwrap().to_bits(),
        e.impulse_n_s.to_bits(),
    ]
}

/// Triangles are two-sided (README): an apple rising into the floor from below is pushed back
/// down as by a plane facing down.
#[test]
fn triangles_are_two_sided() {
    let plane = json!([{"name": "floor", "type": "plane", "material": "steel",
        "point_m": [0, 0, 0], "normal": [0, 0, -1]}]);
    let pos = [0.3, -0.2, -R - 1e-4];
    let p = drop(plane, pos, [0.0, 0.0, 1.0], &repo("scenarios"));
    let mesh = json!([{"name": "floor", "type": "mesh", "material": "steel",
        "file": "../assets/floor_two_triangles.obj"}]);
    let m = drop(mesh, pos, [0.0, 0.0, 1.0], &repo("scenarios"));
    assert_eq!((m.len(), p.len()), (1, 1));
    assert_eq!(bits(&m[0]), bits(&p[0]));
}

#[test]
fn two_triangle_floor_pushes_once_like_the_plane() {
    let plane = json!([{"name": "floor", "type": "plane", "material": "steel",
        "point_m": [0, 0, 0], "normal": [0, 0, 1]}]);
    // On the shared diagonal, on a corner vertex shared by both triangles, inside one triangle.
    for xy in [[0.0, 0.0], [0.25, 0.25], [1.0, 1.0], [0.3, -0.2]] {
        let pos = [xy[0], xy[1], R + 1e-4];
        let p = drop(plane.clone(), pos, [0.0, 0.0, -1.0], &repo("scenarios"));
        assert_eq!(p.len(), 1);
        for file in [
            "../assets/floor_two_triangles.obj",
            "../assets/floor_two_triangles.stl",
        ] {
            let mesh =
                json!([{"name": "floor", "type": "mesh", "material": "steel", "file": file}]);
            let m = drop(mesh, pos, [0.0, 0.0, -1.0], &repo("scenarios"));
            assert_eq!(m.len(), 1, "{file} at {xy:?}: {} contacts", m.len());
            println!(
                "{file} at {xy:?}: {} N, {} s against the plane's {} N, {} s",
                m[0].peak_force_n,
                m[0].duration_s.unwrap(),
                p[0].peak_force_n,
                p[0].duration_s.unwrap()
            );
            assert_eq!(
                bits(&m[0]),
                bits(&p[0]),
                "{file} at {xy:?}: not the plane's to the bit"
            );
        }
    }
}

/// Writes an OBJ valley along y: two flat faces meeting at the line x = 0, z = 0, each rising
/// at `half_deg` from the horizontal (their normals are 2 half_deg apart), 1 m wide each way.
fn valley(dir: &std::path::Path, half_deg: f64) -> PathBuf {
    let (s, c) = (half_deg.to_radians().sin(), half_deg.to_radians().cos());
    let text = format!(
        "v 0 -1 0\nv 0 1 0\nv {c} 1 {s}\nv {c} -1 {s}\nv {mc} -1 {s}\nv {mc} 1 {s}\n\
         f 1 4 3\nf 1 3 2\nf 1 2 6\nf 1 6 5\n",
        mc = -c
    );
    let p = dir.join(format!("valley_{half_deg}.obj"));
    std::fs::write(&p, text).unwrap();
    p
}

/// Contacts of an apple dropped at 1 m/s onto the bottom line of a valley of normals
/// `2 half_deg` apart.
fn valley_contacts(half_deg: f64) -> Vec<ContactEvent> {
    let dir = std::env::temp_dir().join(format!("applesim-mesh-merge-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = valley(&dir, half_deg);
    let mesh = json!([{"name": "valley", "type": "mesh", "material": "steel",
        "file": file.file_name().unwrap().to_str().unwrap()}]);
    // Touching both faces at once: the centre R / cos(half) above the bottom line, plus a gap.
    let z = R / half_deg.to_radians().cos() + 1e-4;
    let e = drop(mesh, [0.0, 0.0, z], [0.0, 0.0, -1.0], &dir);
    for x in &e {
        println!(
            "valley of {:.0} degrees: {} - {} at {} s, {} N",
            2.0 * half_deg,
            x.a,
            x.b,
            x.t_start_s,
            x.peak_force_n
        );
    }
    e
}

#[test]
fn near_parallel_faces_merge_and_a_v_gives_two_contacts() {
    // Normals 28 degrees apart: within 30, one contact.
    assert_eq!(valley_contacts(14.0).len(), 1);
    // 32 degrees apart: two contacts, touching at the same instant, equal by symmetry.
    let two = valley_contacts(16.0);
    assert_eq!(two.len(), 2);
    assert_eq!(two[0].t_start_s, two[1].t_start_s);
    assert_rel(
        "the two faces' peak forces",
        two[0].peak_force_n,
        two[1].peak_force_n,
        1e-9,
    );
    // A V of two 45 degree walls (normals 90 degrees apart): two contacts.
    assert_eq!(valley_contacts(45.0).len(), 2);
}
