//! Issue 29, build 1: the shape of an apple in the scenario. `apples[].height_m` and
//! `apples[].rotation`, a file's per-apple `height_m` and `rotation`, and the `aspect` that
//! generators and sources draw shapes from (with uniform random orientations); the refusals,
//! each naming its field; the mass and inertia that follow from the shape (closed forms written
//! here); and the world's spheroid body. No simulation runs: every test is parsing, generating
//! or building.

use crate::common;
use applesim::scenario::generators::{self, FileApples};
use applesim::scenario::{self, AppleSpec, GeneratorSpec, Scenario};
use applesim::world::{self, roster, Origin};
use common::*;
use rapier3d_f64::math::{Rotation, Vector};
use serde_json::{json, Value};
use std::f64::consts::PI;
use std::path::Path;

/// A plane of steel at z = 0, the apple material of density 800 kg/m^3, and `apples`.
fn scene(apples: Value) -> Value {
    json!({
        "duration_s": 0.01, "time_step_s": 1e-5, "gravity_m_s2": [0, 0, -9.81],
        "output": {"force_history": false},
        "materials": {
            "apple": {"shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "steel": {"shear_modulus_pa": 8.1e10, "poisson_ratio": 0.28}},
        "contact": {"friction": 0.3, "ke": 1.0, "lambda_s_m": 1000, "rolling": "none"},
        "apples": apples,
        "surfaces": [{"name": "floor", "type": "plane", "material": "steel",
            "point_m": [0, 0, 0], "normal": [0, 0, 1]}]
    })
}

fn parse(v: &Value) -> Result<Scenario, String> {
    scenario::from_json(&v.to_string(), "t").map_err(|e| e.to_string())
}

/// Parses and validates; the error as printed.
fn check(v: &Value) -> Result<Scenario, String> {
    let sc = parse(v)?;
    scenario::validate(&sc).map_err(|e| e.to_string())?;
    Ok(sc)
}

/// `check` must refuse, with a message starting with `field: `.
#[track_caller]
fn refused(v: &Value, field: &str) -> String {
    let e = check(v).expect_err("must be refused");
    println!("{e}");
    assert!(e.starts_with(&format!("{field}: ")), "{e}");
    e
}

/// The 80 mm x 72 mm apple of the issue, 0.1 m up.
fn oblate() -> Value {
    json!({"name": "a", "material": "apple", "diameter_m": 0.08, "height_m": 0.072,
        "position_m": [0, 0, 0.1]})
}

#[test]
fn height_and_rotation_are_read_and_a_sphere_is_the_default() {
    let mut a = oblate();
    a["rotation"] = json!({"axis": [1, 0, 0], "angle_deg": 90});
    let sphere = json!({"name": "s", "material": "apple", "diameter_m": 0.08,
        "position_m": [0.2, 0, 0.1]});
    let same = json!({"name": "h", "material": "apple", "diameter_m": 0.08, "height_m": 0.08,
        "rotation": {"euler_xyz_deg": [0, 30, 0]}, "position_m": [0.4, 0, 0.1]});
    let sc = check(&scene(json!([a, sphere, same]))).unwrap();
    let [a, s, h] = [&sc.apples[0], &sc.apples[1], &sc.apples[2]];
    assert_eq!(a.height_m, Some(0.072));
    assert!(a.is_spheroid());
    assert_eq!((a.spheroid().a, a.spheroid().c), (0.04, 0.036));
    let q = a.orientation("apples[0]").unwrap();
    assert!((q * Vector::Z - Vector::new(0.0, -1.0, 0.0)).length() < 1e-15);
    // Absent: a sphere, unturned; a height equal to the diameter is a sphere too.
    assert_eq!((s.height_m, s.rotation.clone()), (None, None));
    assert!(!s.is_spheroid() && !h.is_spheroid());
    assert_eq!(s.height(), 0.08);
    assert_eq!(s.orientation("apples[1]").unwrap(), Rotation::IDENTITY);
    // Written back as read, and a sphere's JSON without the new fields.
    let text = serde_json::to_string(&sc.apples[1]).unwrap();
    assert!(
        !text.contains("height_m") && !text.contains("rotation"),
        "{text}"
    );
    let back: AppleSpec = serde_json::from_str(&serde_json::to_string(a).unwrap()).unwrap();
    assert_eq!(&back, a);
}

#[test]
fn unknown_fields_stay_refused() {
    let mut a = oblate();
    a["heigth_m"] = json!(0.07);
    let e = parse(&scene(json!([a]))).unwrap_err();
    assert!(
        e.contains("apples[0].heigth_m") || e.contains("heigth_m"),
        "{e}"
    );
    let mut a = oblate();
    a["rotation"] = json!({"axis": [1, 0, 0], "angel_deg": 9});
    let e = parse(&scene(json!([a]))).unwrap_err();
    assert!(e.contains("apples[0].rotation"), "{e}");
    let mut v = grid(json!({"mean": 0.9, "sd": 0.05}), 1, 0);
    v["count"] = json!([1, 1, 1]);
    let e = serde_json::from_value::<GeneratorSpec>(v)
        .unwrap_err()
        .to_string();
    assert!(e.contains("sd"), "{e}");
}

#[test]
fn each_refusal_names_its_field() {
    let others: Vec<Value> = (0..3)
        .map(|k| {
            json!({"name": format!("s{k}"), "material": "apple", "diameter_m": 0.08,
                "position_m": [0.2 * (k + 1) as f64, 0, 0.1]})
        })
        .collect();
    let at3 = |height: Value| {
        let mut a = oblate();
        a["height_m"] = height;
        let mut list = others.clone();
        list.push(a);
        scene(Value::Array(list))
    };
    for h in [json!(0), json!(-0.07), json!(1e300)] {
        refused(&at3(h), "apples[3].height_m");
    }
    // The aspect's bounds, 0.5 and 2, themselves allowed.
    let e = refused(&at3(json!(0.0399)), "apples[3].height_m");
    assert!(e.contains("aspect") && e.contains("0.5 <= H/D <= 2"), "{e}");
    refused(&at3(json!(0.1601)), "apples[3].height_m");
    check(&at3(json!(0.04))).unwrap();
    check(&at3(json!(0.16))).unwrap();
    let mut a = oblate();
    a["rotation"] = json!({"axis": [0, 0, 0], "angle_deg": 10});
    refused(&scene(json!([a])), "apples[0].rotation.axis");
    let mut a = oblate();
    a["rotation"] = json!({"euler_xyz_deg": [0, 1e9, 0]});
    refused(&scene(json!([a])), "apples[0].rotation.euler_xyz_deg[1]");
    // A given mass over the spheroid's own volume: 1 kg in 80 x 72 mm is 4145 kg/m^3 (allowed),
    // 1e-4 kg is 0.41 kg/m^3 (refused).
    let mut a = oblate();
    a["mass_kg"] = json!(1e-4);
    let e = refused(&scene(json!([a])), "apples[0].mass_kg");
    assert!(e.contains("0.08 m by 0.072 m"), "{e}");

    // Generators and sources: the aspect and its distribution.
    refused(&with_grid(json!(2.5)), "generators[0].aspect");
    refused(
        &with_grid(json!({"mean": 0.3, "spread": 0.01})),
        "generators[0].aspect.mean",
    );
    refused(
        &with_grid(json!({"mean": 0.9, "spread": -0.1})),
        "generators[0].aspect.spread",
    );
    let e = refused(
        &with_grid(json!({"mean": 0.9, "spread": 0.2, "distribution": "normal"})),
        "generators[0].aspect.spread",
    );
    assert!(e.contains("gives aspects from"), "{e}");
    let mut v = scene(json!([]));
    v["sources"] = json!([{"name": "feed", "material": "apple", "diameter_m": 0.08,
        "aspect": 0.4, "position_m": [0, 0, 0.5], "rate_per_s": 10, "count": 3}]);
    refused(&v, "sources[0].aspect");

    // rapier has no spheroid: not where rapier itself touches apples.
    let mut v = scene(json!([oblate()]));
    v["fidelity"] = json!("rigid");
    let e = refused(&v, "apples[0].height_m");
    assert!(e.contains("rapier has no spheroid"), "{e}");
    let mut v = with_grid(json!(0.9));
    v["surfaces"][0]["contact_model"] = json!("rigid");
    refused(&v, "generators[0].aspect");
    // A sphere there is fine, a height equal to the diameter too.
    let mut a = oblate();
    a["height_m"] = json!(0.08);
    let mut v = scene(json!([a]));
    v["fidelity"] = json!("rigid");
    check(&v).unwrap();
}

#[test]
fn a_file_lists_heights_and_rotations() {
    use applesim::scenario::FileApple;
    let mut v = scene(json!([]));
    v["generators"] = json!([{"type": "file", "name": "p", "material": "apple",
        "file": "pile.json"}]);
    let sc0 = parse(&v).unwrap();
    let with = |apples: Vec<FileApple>| {
        let mut sc = sc0.clone();
        let GeneratorSpec::File(f) = &mut sc.generators[0] else {
            unreachable!()
        };
        f.loaded = Some(FileApples(std::sync::Arc::new(apples)));
        scenario::validate(&sc)
            .map(|_| sc)
            .map_err(|e| e.to_string())
    };
    // The file's format: the new fields optional, unknown ones refused.
    let list: Vec<FileApple> = serde_json::from_value(json!([
        {"name": "p1", "diameter_m": 0.08, "position_m": [0, 0, 0.1]},
        {"name": "p2", "diameter_m": 0.08, "height_m": 0.07,
         "rotation": {"axis": [0, 1, 0], "angle_deg": 90}, "position_m": [0.2, 0, 0.1]}
    ]))
    .unwrap();
    assert!(serde_json::from_value::<Vec<FileApple>>(
        json!([{"name": "p", "diameter_m": 0.08, "aspect": 1, "position_m": [0, 0, 0.1]}])
    )
    .is_err());
    let sc = with(list.clone()).unwrap();
    let apples = sc.initial_apples().unwrap();
    assert_eq!(apples[0].height_m, None);
    assert_eq!(apples[1].height_m, Some(0.07));
    assert_eq!(apples[1].rotation, list[1].rotation);
    let mut bad = list.clone();
    bad[1].height_m = Some(0.2);
    let e = with(bad).unwrap_err();
    assert!(
        e.starts_with("generators[0].file: pile.json[1].height_m: "),
        "{e}"
    );
    let mut bad = list;
    bad[1].rotation.as_mut().unwrap().angle_deg = None;
    let e = with(bad).unwrap_err();
    assert!(
        e.starts_with("generators[0].file: pile.json[1].rotation.angle_deg: "),
        "{e}"
    );
}

#[test]
fn mass_and_density_follow_the_shape() {
    let sc = check(&scene(json!([oblate()]))).unwrap();
    let a = &sc.apples[0];
    // Density 800 kg/m^3 times 4/3 pi a^2 c, a = 40 mm, c = 36 mm: 0.19302 kg.
    let want = 800.0 * 4.0 / 3.0 * PI * 0.04 * 0.04 * 0.036;
    let e = roster::entry(a, Some(800.0), Origin::Listed { index: 0 });
    assert_rel("spheroid mass", e.mass_kg, want, 1e-14);
    assert_eq!((e.radius_m, e.height_m), (0.04, Some(0.072)));
    assert_rel(
        "the sphere's mass times c / a",
        want,
        roster::sphere_mass(0.08, 800.0) * 0.9,
        1e-14,
    );
    // With mass_kg given, the mass is as given: the density is what the volume makes of it.
    let mut given = a.clone();
    given.mass_kg = Some(0.15);
    assert_eq!(roster::apple_mass(&given, Some(800.0)), 0.15);
    // A sphere, and a height equal to the diameter: the sphere's exact formula, no height.
    let mut sphere = a.clone();
    sphere.height_m = Some(0.08);
    let s = roster::entry(&sphere, Some(800.0), Origin::Listed { index: 0 });
    assert_eq!(s.mass_kg, roster::sphere_mass(0.08, 800.0));
    assert_eq!(s.height_m, None);
    // The roster's JSON of a sphere is unchanged: no height.
    let text = serde_json::to_string(&s).unwrap();
    assert!(!text.contains("height_m"), "{text}");
}

/// A grid generator of 20 x 10 x 10 apples of 80 mm, 0.2 m apart, with `aspect`.
fn grid(aspect: Value, seed: u64, n: u32) -> Value {
    let mut v = json!({"type": "grid", "name": "g", "material": "apple",
        "diameter_m": {"mean_m": 0.08, "spread_m": 0.005}, "count": [20, 10, n],
        "spacing_m": [0.2, 0.2, 0.2], "origin_m": [0, 0, 0.1], "jitter_m": 0.01, "seed": seed});
    if !aspect.is_null() {
        v["aspect"] = aspect;
    }
    v
}

fn expand(v: Value) -> Vec<AppleSpec> {
    let g: GeneratorSpec = serde_json::from_value(v).unwrap();
    generators::expand(&g, &[], "generators[0]").unwrap()
}

/// A scene with one 2 x 2 x 1 grid generator of `aspect`.
fn with_grid(aspect: Value) -> Value {
    let mut v = scene(json!([]));
    let mut g = grid(aspect, 0, 1);
    g["count"] = json!([2, 2, 1]);
    v["generators"] = json!([g]);
    v
}

#[test]
fn a_generator_draws_aspects_from_its_seed() {
    let law = json!({"mean": 0.9, "spread": 0.05, "distribution": "normal"});
    let a = expand(grid(law.clone(), 7, 10));
    let b = expand(grid(law.clone(), 7, 10));
    let c = expand(grid(law.clone(), 8, 10));
    let plain = expand(grid(Value::Null, 7, 10));
    assert_eq!(a.len(), 2000);
    assert_eq!(a, b, "same seed, same shapes");
    assert_ne!(
        a.iter().map(|x| x.height_m).collect::<Vec<_>>(),
        c.iter().map(|x| x.height_m).collect::<Vec<_>>()
    );
    // Sizes and places are drawn as without an aspect (the shapes come from another stream).
    for (x, p) in a.iter().zip(&plain) {
        assert_eq!((x.diameter_m, x.position_m), (p.diameter_m, p.position_m));
        assert_eq!((p.height_m, p.rotation.clone()), (None, None));
    }
    // The aspect: a normal of sd 0.05 clipped at 3 sd has sd 0.05 sqrt(1 - 6 phi(3) / (2 Phi(3)
    // - 1)) = 0.04933; over 2000 apples the mean is within 3 standard errors (3.3e-3) of 0.9,
    // the sd within 5 % (its standard error is 1.6 %), and none beyond 0.9 +- 0.15.
    let x: Vec<f64> = a
        .iter()
        .map(|s| s.height_m.unwrap() / s.diameter_m)
        .collect();
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let sd = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
    println!("aspect mean {mean}, sd {sd}");
    assert!((mean - 0.9).abs() < 3.0 * 0.04933 / n.sqrt(), "mean {mean}");
    assert_rel("aspect sd", sd, 0.04933, 0.05);
    assert!(x.iter().all(|v| (v - 0.9).abs() <= 0.15 + 1e-12));
    // An aspect of exactly 1: spheres, unturned, the apples of no aspect.
    assert_eq!(expand(grid(json!(1), 7, 10)), plain);
    // A fixed aspect: every height that times the diameter.
    let f = expand(grid(json!(0.85), 7, 1));
    assert!(f
        .iter()
        .all(|s| s.height_m == Some(s.diameter_m * 0.85) && s.rotation.is_some()));
}

#[test]
fn orientations_are_uniform_over_rotations() {
    // The apple's own axis R z over 2000 draws: each component of a uniform unit vector has mean
    // 0 and variance 1/3, its square mean 1/3 and variance E[z^4] - 1/9 = 1/5 - 1/9 = 4/45. The
    // means are within 3 standard errors.
    let apples = expand(grid(json!(0.85), 11, 10));
    let n = apples.len() as f64;
    let axes: Vec<Vector> = apples
        .iter()
        .map(|a| a.orientation("g").unwrap() * Vector::Z)
        .collect();
    for c in 0..3 {
        let m1 = axes.iter().map(|v| v[c]).sum::<f64>() / n;
        let m2 = axes.iter().map(|v| v[c] * v[c]).sum::<f64>() / n;
        println!("axis component {c}: mean {m1:.4}, mean square {m2:.4}");
        assert!(
            m1.abs() < 3.0 * (1.0 / 3.0 / n).sqrt(),
            "component {c}: mean {m1}"
        );
        assert!(
            (m2 - 1.0 / 3.0).abs() < 3.0 * (4.0 / 45.0 / n).sqrt(),
            "component {c}: mean square {m2}"
        );
    }
    // The angle of the rotation: a uniform rotation's has density (1 - cos t) / pi on [0, pi],
    // mean pi/2 + 2/pi and second moment pi^2/3 + 2 (so variance 0.4172); its mean over the
    // draws is within 3 standard errors.
    let angles: Vec<f64> = apples
        .iter()
        .map(|a| a.rotation.as_ref().unwrap().angle_deg.unwrap().to_radians())
        .collect();
    let mean = angles.iter().sum::<f64>() / n;
    let want = PI / 2.0 + 2.0 / PI;
    let var = PI * PI / 3.0 + 2.0 - want * want;
    println!("rotation angle: mean {mean:.4} (want {want:.4})");
    assert!(
        (mean - want).abs() < 3.0 * (var / n).sqrt(),
        "angle mean {mean} against {want}"
    );
    assert!(angles.iter().all(|t| (0.0..=PI + 1e-12).contains(t)));
}

#[test]
fn a_random_fill_and_a_source_draw_shapes() {
    let mut v = scene(json!([]));
    v["generators"] = json!([{"type": "random_fill", "name": "r", "material": "apple",
        "diameter_m": 0.07, "aspect": {"mean": 1.2, "spread": 0.1}, "count": 30,
        "region_min_m": [-0.2, -0.2, 0.0], "region_max_m": [0.2, 0.2, 0.4], "seed": 3}]);
    v["sources"] = json!([{"name": "feed", "material": "apple",
        "diameter_m": {"mean_m": 0.075, "spread_m": 0.005}, "aspect": 0.85,
        "position_m": [1, 0, 0.5], "jitter_m": 0.01, "rate_per_s": 10, "count": 5, "seed": 4}]);
    let sc = check(&v).unwrap();
    let fill = sc.initial_apples().unwrap();
    assert_eq!(fill.len(), 30);
    assert_eq!(fill, check(&v).unwrap().initial_apples().unwrap());
    for a in &fill {
        let x = a.height_m.unwrap() / a.diameter_m;
        assert!((1.1..=1.3).contains(&x), "{x}");
        // Whole apples inside the region, whatever their turn (their bounding balls).
        let r = a.bounding_radius_m();
        assert_eq!(r, 0.5 * a.height_m.unwrap());
        assert!(a.position_m[2] - r >= 0.0 && a.position_m[2] + r <= 0.4);
    }
    let fed = sc.sources[0].schedule(sc.gravity_m_s2);
    let mut plain = sc.sources[0].clone();
    plain.aspect = None;
    for ((_, a), (_, p)) in fed.iter().zip(plain.schedule(sc.gravity_m_s2)) {
        assert_eq!((a.diameter_m, a.position_m), (p.diameter_m, p.position_m));
        assert_eq!(a.height_m, Some(a.diameter_m * 0.85));
        assert!(a.rotation.is_some());
    }
}

#[test]
fn a_spheroid_is_placed_by_its_shape() {
    // Pole on pole: two 80 x 72 mm apples 72 mm apart along z touch (their bounding balls,
    // 80 mm across, would overlap by 8 mm); 70 mm apart they overlap by 2 mm.
    let stack = |gap: f64| {
        let mut b = oblate();
        b["name"] = json!("b");
        b["position_m"] = json!([0, 0, 0.1 + gap]);
        scene(json!([oblate(), b]))
    };
    check(&stack(0.072)).unwrap();
    let e = refused(&stack(0.070), "apples[1].position_m");
    assert!(e.contains("starts 2.0000 mm inside"), "{e}");
    // Turned on its side, the pole faces sideways: side by side 72 mm apart along x.
    let side = |angle: f64| {
        let mut a = oblate();
        a["rotation"] = json!({"axis": [0, 1, 0], "angle_deg": angle});
        let mut b = a.clone();
        b["name"] = json!("b");
        b["position_m"] = json!([0.0721, 0, 0.1]);
        scene(json!([a, b]))
    };
    check(&side(90.0)).unwrap();
    refused(&side(0.0), "apples[1].position_m");
    // Resting on its pole on the floor: the centre 36 mm up (the bounding ball would sink 4 mm).
    let on_floor = |z: f64| {
        let mut a = oblate();
        a["position_m"] = json!([0, 0, z]);
        scene(json!([a]))
    };
    let sc = check(&on_floor(0.036)).unwrap();
    world::build(&sc, Path::new(".")).expect("rests on its pole");
    let sc = check(&on_floor(0.034)).unwrap();
    let e = world::build(&sc, Path::new("."))
        .err()
        .expect("2 mm into the floor")
        .to_string();
    assert!(
        e.starts_with("apples[0].position_m: ")
            && e.contains("starts 2.0000 mm inside surface 'floor'"),
        "{e}"
    );
}

#[test]
fn a_spheroid_put_on_a_belt_rests_on_its_support_point() {
    // A belt whose top is at z = 0.8; the apple 1 mm above it: its centre 1 mm plus its
    // support distance along z, c = 36 mm upright, a = 40 mm on its side, and turned by t about
    // x, sqrt(a^2 sin^2 t + c^2 cos^2 t).
    let on = |rotation: Value| {
        let mut a = oblate();
        a.as_object_mut().unwrap().remove("position_m");
        a["on"] = json!({"surface": "belt", "along_m": 0.5});
        if !rotation.is_null() {
            a["rotation"] = rotation;
        }
        let mut v = scene(json!([a]));
        v["surfaces"] = json!([{"name": "belt", "type": "conveyor", "material": "steel",
            "size_m": [1.5, 0.3, 0.04], "position_m": [0, 0, 0.78], "belt_velocity_m_s": 0.5}]);
        check(&v).unwrap().apples[0].position_m[2]
    };
    let t = 30f64.to_radians();
    let tilted = (0.04f64.powi(2) * t.sin().powi(2) + 0.036f64.powi(2) * t.cos().powi(2)).sqrt();
    for (rotation, h) in [
        (Value::Null, 0.036),
        (json!({"axis": [1, 0, 0], "angle_deg": 90}), 0.04),
        (json!({"axis": [1, 0, 0], "angle_deg": 30}), tilted),
    ] {
        let z = on(rotation.clone());
        println!("{rotation}: centre at {z}, want {}", 0.801 + h);
        assert!((z - (0.801 + h)).abs() < 1e-14, "{rotation}: {z}");
    }
}

/// `got` and `want` are the same rotation: their unit quaternions equal (or opposite) to 1e-15
/// in every component (an angle from acos would lose half the digits).
#[track_caller]
fn same_turn(got: Rotation, want: Rotation) {
    let d = (got - want).length().min((got + want).length());
    assert!(d < 1e-15, "{got:?} against {want:?}: {d:e}");
}

#[test]
fn the_world_builds_a_spheroid_body() {
    let mut a = oblate();
    a["rotation"] = json!({"axis": [1, 2, 3], "angle_deg": 40});
    a["mass_kg"] = json!(0.2);
    let mut s = json!({"name": "s", "material": "apple", "diameter_m": 0.08,
        "position_m": [0.3, 0, 0.1]});
    let plain = s.clone();
    s["name"] = json!("t");
    s["position_m"] = json!([0.6, 0, 0.1]);
    s["rotation"] = json!({"euler_xyz_deg": [10, 20, 30]});
    let sc = check(&scene(json!([a, plain, s]))).unwrap();
    let mut w = world::build(&sc, Path::new(".")).unwrap();
    // rapier computes a body's mass properties in its first step; a step of length zero.
    w.refresh_pairs();
    let body = |k: usize| w.apple_body(k);
    // The spheroid: m (a^2 + c^2) / 5 about an equatorial axis, 2 m a^2 / 5 about its own.
    let (m, a2, c2) = (0.2, 0.04f64 * 0.04, 0.036f64 * 0.036);
    let rb = body(0);
    let inertia = rb.mass_properties().local_mprops.principal_inertia();
    assert_rel("mass", rb.mass(), m, 1e-14);
    assert_rel("I equatorial x", inertia.x, m * (a2 + c2) / 5.0, 1e-14);
    assert_rel("I equatorial y", inertia.y, m * (a2 + c2) / 5.0, 1e-14);
    assert_rel("I axial", inertia.z, 2.0 * m * a2 / 5.0, 1e-14);
    let want =
        Rotation::from_axis_angle(Vector::new(1.0, 2.0, 3.0).normalize(), 40f64.to_radians());
    same_turn(*rb.rotation(), want);
    assert_eq!(rb.translation(), Vector::new(0.0, 0.0, 0.1));
    assert!(rb.gyroscopic_forces_enabled());
    // The roster records the height; the layer bounds the spheroid by its largest radius.
    let roster = w.roster.apples();
    assert_eq!(
        (roster[0].radius_m, roster[0].height_m),
        (0.04, Some(0.072))
    );
    assert_eq!(w.layer.apple_radius(applesim::layer::AppleId(0)), 0.04);
    // A sphere: the ball's inertia, no gyroscopic forces, unturned unless a rotation is given.
    let mass = roster::sphere_mass(0.08, 800.0);
    for k in [1, 2] {
        let rb = body(k);
        // (rapier keeps the inverses: 1 / (1 / m) may differ from m in the last bit.)
        assert_rel("sphere mass", rb.mass(), mass, 1e-15);
        let i = rb.mass_properties().local_mprops.principal_inertia();
        for c in 0..3 {
            assert_rel("sphere inertia", i[c], 0.4 * mass * 0.04 * 0.04, 1e-15);
        }
        assert!(!rb.gyroscopic_forces_enabled());
        assert_eq!(roster[k].height_m, None);
    }
    assert_eq!(*body(1).rotation(), Rotation::IDENTITY);
    let e = [10f64, 20.0, 30.0].map(f64::to_radians);
    let want = Rotation::from_rotation_z(e[2])
        * Rotation::from_rotation_y(e[1])
        * Rotation::from_rotation_x(e[0]);
    same_turn(*body(2).rotation(), want);
}
