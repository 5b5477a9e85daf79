//! Every kind of mistake a user makes in a scenario gives a clear message naming the field (or
//! the pair) and a non-zero exit, never a panic, and leaves no result files behind.
//! Runs the real `applesim` binary.

use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

fn base() -> Value {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/drop_on_steel.json"),
    )
    .unwrap();
    serde_json::from_str(&text).unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("applesim-bad-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs `applesim run` on `text`; asserts exit code 1 (an error, not a panic: 101), that stderr
/// mentions every `needles` string, and that no summary was written.
fn refused(name: &str, text: &str, needles: &[&str]) {
    refused_with_files(name, text, &[], needles)
}

/// Like [`refused`], with extra files written beside the scenario (meshes).
fn refused_with_files(name: &str, text: &str, files: &[(&str, &str)], needles: &[&str]) {
    let dir = tmp(name);
    for (f, content) in files {
        std::fs::write(dir.join(f), content).unwrap();
    }
    let file = dir.join("scenario.json");
    std::fs::write(&file, text).unwrap();
    let out = dir.join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args([
            "run",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    println!("{name}: {}", err.trim());
    assert_eq!(
        o.status.code(),
        Some(1),
        "{name}: exit {:?}, stderr {err}",
        o.status
    );
    assert!(err.starts_with("error: "), "{name}: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{name}: not one line: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "{name}: message lacks '{n}': {err}");
    }
    assert!(
        !out.join("summary.json").exists(),
        "{name}: a summary was written"
    );
    assert!(
        !out.join("bodies.csv").exists(),
        "{name}: bodies.csv was written"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

fn mutated(name: &str, f: impl FnOnce(&mut Value), needles: &[&str]) {
    let mut v = base();
    f(&mut v);
    refused(name, &serde_json::to_string_pretty(&v).unwrap(), needles);
}

#[test]
fn syntax_error() {
    refused("syntax", "{ \"duration_s\": 0.03, ", &["line"]);
}

#[test]
fn not_an_object() {
    refused("array", "[1, 2]", &["expected"]);
}

#[test]
fn missing_file() {
    let o = Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args(["run", "/nonexistent/scenario.json"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("/nonexistent/scenario.json"));
}

#[test]
fn missing_field() {
    mutated(
        "missing",
        |v| {
            v.as_object_mut().unwrap().remove("duration_s");
        },
        &["duration_s", "missing"],
    );
}

#[test]
fn unknown_field() {
    mutated(
        "unknown",
        |v| {
            v["materials"]["apple"]["shear_modulos_pa"] = json!(1e6);
        },
        &["materials.apple", "shear_modulos_pa"],
    );
}

#[test]
fn wrong_type() {
    mutated(
        "type",
        |v| v["apples"][0]["diameter_m"] = json!("eighty"),
        &["apples[0].diameter_m"],
    );
}

#[test]
fn negative_modulus() {
    mutated(
        "neg-modulus",
        |v| v["materials"]["apple"]["shear_modulus_pa"] = json!(-1.1e6),
        &["materials.apple.shear_modulus_pa", "-1.1e6 Pa"],
    );
}

#[test]
fn poisson_half() {
    mutated(
        "nu-half",
        |v| v["materials"]["steel"]["poisson_ratio"] = json!(0.5),
        &["materials.steel.poisson_ratio", "0.5"],
    );
}

#[test]
fn poisson_below_minus_one() {
    mutated(
        "nu-low",
        |v| v["materials"]["apple"]["poisson_ratio"] = json!(-1.2),
        &["materials.apple.poisson_ratio"],
    );
}

#[test]
fn both_moduli() {
    mutated(
        "both",
        |v| v["materials"]["apple"]["youngs_modulus_pa"] = json!(2.6e6),
        &["materials.apple", "both"],
    );
}

#[test]
fn no_modulus() {
    mutated(
        "none",
        |v| {
            v["materials"]["apple"]
                .as_object_mut()
                .unwrap()
                .remove("shear_modulus_pa");
        },
        &["materials.apple", "shear_modulus_pa or youngs_modulus_pa"],
    );
}

#[test]
fn negative_density() {
    mutated(
        "density",
        |v| v["materials"]["apple"]["density_kg_m3"] = json!(-800),
        &["materials.apple.density_kg_m3"],
    );
}

#[test]
fn no_mass_and_no_density() {
    mutated(
        "no-mass",
        |v| {
            v["materials"]["apple"]
                .as_object_mut()
                .unwrap()
                .remove("density_kg_m3");
            v["apples"][0].as_object_mut().unwrap().remove("mass_kg");
        },
        &["apples[0].mass_kg", "density"],
    );
}

#[test]
fn unknown_material() {
    mutated(
        "material",
        |v| v["apples"][0]["material"] = json!("pear"),
        &["apples[0].material", "pear"],
    );
}

#[test]
fn zero_diameter() {
    mutated(
        "diameter",
        |v| v["apples"][0]["diameter_m"] = json!(0.0),
        &["apples[0].diameter_m"],
    );
}

#[test]
fn negative_mass() {
    mutated(
        "mass",
        |v| v["apples"][0]["mass_kg"] = json!(-0.1),
        &["apples[0].mass_kg"],
    );
}

#[test]
fn duplicate_names() {
    mutated(
        "dup",
        |v| {
            let mut a = v["apples"][0].clone();
            a["position_m"] = json!([0.5, 0, 0.0401]);
            v["apples"].as_array_mut().unwrap().push(a);
        },
        &["apples[1].name", "a1", "twice"],
    );
}

#[test]
fn overlapping_apples() {
    mutated(
        "overlap",
        |v| {
            let mut a = v["apples"][0].clone();
            a["name"] = json!("a2");
            a["position_m"] = json!([0.07, 0, 0.0401]);
            v["apples"].as_array_mut().unwrap().push(a);
        },
        &["apples[1].position_m", "'a2'", "'a1'", "inside"],
    );
}

#[test]
fn apple_inside_surface() {
    mutated(
        "inside",
        |v| v["apples"][0]["position_m"] = json!([0, 0, 0.03]),
        &["apples[0].position_m", "'floor'", "inside"],
    );
}

#[test]
fn zero_normal() {
    mutated(
        "normal0",
        |v| v["surfaces"][0]["normal"] = json!([0, 0, 0]),
        &["surfaces[0].normal", "unit"],
    );
}

#[test]
fn non_unit_normal() {
    mutated(
        "normal2",
        |v| v["surfaces"][0]["normal"] = json!([0, 0, 2]),
        &["surfaces[0].normal", "length 2"],
    );
}

#[test]
fn unknown_surface_type() {
    mutated(
        "stype",
        |v| v["surfaces"][0]["type"] = json!("floor"),
        &["surfaces[0].type", "unknown variant"],
    );
}

#[test]
fn negative_time_step() {
    mutated("dt", |v| v["time_step_s"] = json!(-1e-5), &["time_step_s"]);
}

#[test]
fn zero_duration() {
    mutated("duration", |v| v["duration_s"] = json!(0), &["duration_s"]);
}

#[test]
fn ke_out_of_range() {
    mutated(
        "ke0",
        |v| v["contact"]["ke"] = json!(0.0),
        &["contact.ke", "(0 < ke <= 1)"],
    );
    mutated("ke2", |v| v["contact"]["ke"] = json!(1.5), &["contact.ke"]);
}

/// `model.history_dashpot_bound` lies in (0, 2): at 2 LIGGGHTS's explicit tangential dashpot
/// overshoots and grows (src/contact `HISTORY_DASHPOT_BOUND`).
#[test]
fn history_dashpot_bound_out_of_range() {
    for (name, b) in [("hdb0", 0.0), ("hdb2", 2.0), ("hdb-1", -1.0)] {
        mutated(
            name,
            |v| v["model"] = json!({"history_dashpot_bound": b}),
            &["model.history_dashpot_bound", "(0 < b < 2)"],
        );
    }
}

#[test]
fn negative_friction() {
    mutated(
        "mu",
        |v| v["contact"]["friction"] = json!(-0.3),
        &["contact.friction"],
    );
}

#[test]
fn negative_lambda() {
    mutated(
        "lambda",
        |v| v["contact"]["lambda_s_m"] = json!(-10),
        &["contact.lambda_s_m"],
    );
}

#[test]
fn pair_with_unknown_material() {
    mutated(
        "pair",
        |v| v["pairs"] = json!([{ "materials": ["apple", "rubber"], "friction": 0.5 }]),
        &["pairs[0].materials[1]", "rubber"],
    );
}

#[test]
fn pair_given_twice() {
    mutated(
        "pair2",
        |v| {
            v["pairs"] = json!([
        { "materials": ["apple", "steel"], "friction": 0.5 },
        { "materials": ["steel", "apple"], "ke": 0.5 }])
        },
        &["pairs[1].materials", "twice"],
    );
}

#[test]
fn zero_sample_interval() {
    mutated(
        "sample",
        |v| v["output"]["sample_interval_s"] = json!(0),
        &["output.sample_interval_s"],
    );
}

#[test]
fn unstable_time_step_names_the_pair_and_a_step_that_works() {
    // 1.4 m/s on steel lasts 5.6 ms: dt = 1e-3 resolves it in 5.6 steps.
    mutated(
        "unstable",
        |v| v["time_step_s"] = json!(1e-3),
        &["'a1'", "'floor'", "time_step_s <="],
    );
}

// Geometry mistakes (issue 3).

fn with_surface(name: &str, surface: Value, needles: &[&str]) {
    mutated(
        name,
        |v| v["surfaces"].as_array_mut().unwrap().push(surface),
        needles,
    );
}

#[test]
fn missing_mesh_file() {
    with_surface(
        "mesh-missing",
        json!({"name": "tray", "type": "mesh", "material": "steel",
        "file": "no_such_tray.obj", "position_m": [0, 0, -1]}),
        &["surfaces[1].file", "no_such_tray.obj", "not found"],
    );
}

#[test]
fn empty_mesh() {
    let mut v = base();
    v["surfaces"]
        .as_array_mut()
        .unwrap()
        .push(json!({"name": "tray", "type": "mesh",
        "material": "steel", "file": "empty.obj", "position_m": [0, 0, -1]}));
    refused_with_files(
        "mesh-empty",
        &v.to_string(),
        &[("empty.obj", "# nothing here\n")],
        &["surfaces[1].file", "empty.obj", "no triangle"],
    );
}

#[test]
fn mesh_of_unknown_format() {
    let mut v = base();
    v["surfaces"]
        .as_array_mut()
        .unwrap()
        .push(json!({"name": "tray", "type": "mesh",
        "material": "steel", "file": "tray.ply", "position_m": [0, 0, -1]}));
    refused_with_files(
        "mesh-ply",
        &v.to_string(),
        &[("tray.ply", "ply\n")],
        &["surfaces[1].file", "unknown mesh format"],
    );
}

#[test]
fn zero_size_box() {
    with_surface(
        "box0",
        json!({"name": "wall", "type": "box", "material": "steel",
        "size_m": [0.1, 0.0, 0.3], "position_m": [1, 0, 0.15]}),
        &["surfaces[1].size_m[1]"],
    );
}

#[test]
fn rotation_with_zero_axis() {
    with_surface(
        "rot0",
        json!({"name": "wall", "type": "box", "material": "steel",
        "size_m": [0.1, 0.1, 0.3], "position_m": [1, 0, 0.15],
        "rotation": {"axis": [0, 0, 0], "angle_deg": 30}}),
        &["surfaces[1].rotation.axis"],
    );
}

#[test]
fn rotation_given_twice() {
    with_surface(
        "rot2",
        json!({"name": "wall", "type": "box", "material": "steel",
        "size_m": [0.1, 0.1, 0.3], "position_m": [1, 0, 0.15],
        "rotation": {"axis": [0, 0, 1], "angle_deg": 30, "euler_xyz_deg": [0, 0, 30]}}),
        &["surfaces[1].rotation", "either"],
    );
}

#[test]
fn flat_chute_without_width() {
    with_surface(
        "chute-w",
        json!({"name": "c", "type": "chute", "profile": "flat", "material": "steel",
        "length_m": 1.0, "incline_deg": 20, "position_m": [1, 0, 0.5]}),
        &["surfaces[1].width_m"],
    );
}

#[test]
fn trough_tighter_than_the_apple() {
    // An apple of radius 40 mm cannot lie in a trough of radius 30 mm: conforming contact.
    with_surface(
        "trough",
        json!({"name": "t", "type": "chute", "profile": "trough", "material": "steel",
        "length_m": 1.0, "radius_m": 0.03, "position_m": [1, 0, 0.5]}),
        &["'a1'", "'t'", "conforming"],
    );
}

#[test]
fn bin_wall_with_unknown_material() {
    with_surface(
        "binmat",
        json!({"name": "b", "type": "bin", "material": "steel",
        "wall_materials": {"floor": "foam"}, "inner_size_m": [0.4, 0.4, 0.3], "position_m": [2, 0, 0]}),
        &["surfaces[1].wall_materials.floor", "foam"],
    );
}

#[test]
fn overlapping_generated_apples() {
    mutated(
        "gen-overlap",
        |v| {
            v["generators"] = json!([{"type": "grid", "name": "g", "material": "apple",
        "diameter_m": 0.08, "count": [2, 1, 1], "spacing_m": [0.07, 0.1, 0.1], "origin_m": [1, 1, 0.5]}])
        },
        &["generators", "'g-2'", "'g-1'", "inside"],
    );
}

#[test]
fn random_fill_that_cannot_fit() {
    // 18 apples are 60 % of the region: more than random placement reaches (about 38 %).
    mutated(
        "gen-full",
        |v| {
            v["generators"] = json!([{"type": "random_fill", "name": "r", "material": "apple",
        "diameter_m": 0.08, "count": 18, "region_min_m": [1, 1, 0.0], "region_max_m": [1.2, 1.2, 0.2], "seed": 1}])
        },
        &["generators[0].count", "placed only"],
    );
    // 50 apples are more than any random packing of it holds: refused before any attempt.
    mutated(
        "gen-overfull",
        |v| {
            v["generators"] = json!([{"type": "random_fill", "name": "r", "material": "apple",
        "diameter_m": 0.08, "count": 50, "region_min_m": [1, 1, 0.0], "region_max_m": [1.2, 1.2, 0.2], "seed": 1}])
        },
        &["generators[0].count", "0.0134 m^3", "random packing"],
    );
}

#[test]
fn source_with_zero_rate() {
    mutated(
        "src-rate",
        |v| {
            v["sources"] = json!([{"name": "s", "material": "apple", "diameter_m": 0.08,
        "position_m": [1, 1, 1], "rate_per_s": 0, "count": 3}])
        },
        &["sources[0].rate_per_s"],
    );
}

#[test]
fn generated_name_clash() {
    mutated(
        "gen-name",
        |v| {
            v["apples"][0]["name"] = json!("g-1");
            v["generators"] = json!([{"type": "grid", "name": "g", "material": "apple",
            "diameter_m": 0.08, "count": [1, 1, 1], "spacing_m": [0.1, 0.1, 0.1], "origin_m": [1, 1, 0.5]}]);
        },
        &["generators", "'g-1'", "already used"],
    );
}

// Apples read from a file (issue 11): the file is user input too; every mistake in it names
// `generators[0].file` and, where it is about one entry, the entry.

/// The base scenario with a `file` generator reading `pile.json` (written beside it with
/// `content`, unless `None`).
fn file_generator(name: &str, content: Option<&str>, needles: &[&str]) {
    let mut v = base();
    v["generators"] =
        json!([{"type": "file", "name": "p", "material": "apple", "file": "pile.json"}]);
    let files: Vec<(&str, &str)> = content.map(|c| ("pile.json", c)).into_iter().collect();
    refused_with_files(name, &v.to_string(), &files, needles);
}

#[test]
fn file_generator_missing_file() {
    file_generator(
        "file-missing",
        None,
        &["generators[0].file", "pile.json", "cannot read"],
    );
}

#[test]
fn file_generator_unreadable_json() {
    file_generator(
        "file-syntax",
        Some("[{\"name\": \"a\", \"diameter_m\": 0.08,"),
        &["generators[0].file", "pile.json", "line 1"],
    );
}

#[test]
fn file_generator_not_a_list() {
    file_generator(
        "file-object",
        Some("{\"name\": \"a\"}"),
        &["generators[0].file", "expected a sequence"],
    );
}

#[test]
fn file_generator_entry_missing_a_field() {
    file_generator(
        "file-field",
        Some(
            r#"[{"name": "a", "diameter_m": 0.08, "position_m": [1, 1, 0.5]}, {"name": "b", "position_m": [2, 1, 0.5]}]"#,
        ),
        &["generators[0].file", "[1].diameter_m", "missing"],
    );
}

#[test]
fn file_generator_entry_with_unknown_field() {
    file_generator(
        "file-unknown",
        Some(r#"[{"name": "a", "diameter_m": 0.08, "position_m": [1, 1, 0.5], "mass_kg": 0.2}]"#),
        &["generators[0].file", "[0]", "unknown field `mass_kg`"],
    );
}

#[test]
fn file_generator_zero_diameter() {
    file_generator(
        "file-diameter",
        Some(
            r#"[{"name": "a", "diameter_m": 0.08, "position_m": [1, 1, 0.5]}, {"name": "b", "diameter_m": 0, "position_m": [2, 1, 0.5]}]"#,
        ),
        &[
            "generators[0].file",
            "pile.json[1].diameter_m",
            "outside the range of fruit handling (0.001 m <= D <= 1 m)",
            "'b'",
        ],
    );
}

#[test]
fn file_generator_position_out_of_range() {
    // JSON has no NaN or infinity: a number too large for f64 is the way a file holds one.
    file_generator(
        "file-position",
        Some(r#"[{"name": "a", "diameter_m": 0.08, "position_m": [1, 1e999, 0.5]}]"#),
        &["generators[0].file", "[0].position_m", "out of range"],
    );
}

#[test]
fn file_generator_empty_list() {
    file_generator(
        "file-empty",
        Some("[]"),
        &["generators[0].file", "lists no apple"],
    );
}

#[test]
fn file_generator_duplicate_names() {
    file_generator(
        "file-dup",
        Some(
            r#"[{"name": "a", "diameter_m": 0.08, "position_m": [1, 1, 0.5]}, {"name": "a", "diameter_m": 0.08, "position_m": [2, 1, 0.5]}]"#,
        ),
        &["generators[0].file", "pile.json[1].name", "'a'", "twice"],
    );
}

#[test]
fn file_generator_overlapping_apples() {
    // The same check and message as for any generated apples.
    file_generator(
        "file-overlap",
        Some(
            r#"[{"name": "a", "diameter_m": 0.08, "position_m": [1, 1, 0.5]}, {"name": "b", "diameter_m": 0.08, "position_m": [1.07, 1, 0.5]}]"#,
        ),
        &["generators", "'p-b'", "'p-a'", "inside"],
    );
}

// Physical ranges (issue 18): every number outside the range of fruit handling is refused with
// the field, the value and the range (scenario::ranges, README "Ranges and mistakes").

#[test]
fn speed_out_of_range() {
    mutated(
        "range-speed",
        |v| v["apples"][0]["velocity_m_s"] = json!([0, 0, -1e200]),
        &["error: apples[0].velocity_m_s: 1e200 m/s is outside the range of fruit handling (|v| <= 100 m/s)"],
    );
}

#[test]
fn gravity_out_of_range() {
    mutated(
        "range-gravity",
        |v| v["gravity_m_s2"] = json!([0, 0, -1e200]),
        &["gravity_m_s2: 1e200 m/s^2", "(|g| <= 1000 m/s^2)"],
    );
}

#[test]
fn position_out_of_range() {
    mutated(
        "range-position",
        |v| v["apples"][0]["position_m"] = json!([0, 0, 1e308]),
        &["apples[0].position_m[2]: 1e308 m", "(|x| <= 10000 m)"],
    );
}

#[test]
fn mesh_scale_out_of_range() {
    with_surface(
        "range-scale",
        json!({"name": "tray", "type": "mesh", "material": "steel",
        "file": "tray.obj", "scale": 1e308, "position_m": [0, 0, -1]}),
        &["surfaces[1].scale: 1e308", "(1e-6 <= s <= 1e6)"],
    );
    with_surface(
        "range-scale3",
        json!({"name": "tray", "type": "mesh", "material": "steel",
        "file": "tray.obj", "scale": [1, 1e308, 1], "position_m": [0, 0, -1]}),
        &["surfaces[1].scale[1]: 1e308", "(1e-6 <= s <= 1e6)"],
    );
}

#[test]
fn diameter_out_of_range() {
    // Once blamed on rapier's additional_mass_properties.
    mutated(
        "range-diameter",
        |v| v["apples"][0]["diameter_m"] = json!(1e308),
        &["apples[0].diameter_m: 1e308 m", "(0.001 m <= D <= 1 m)"],
    );
}

#[test]
fn modulus_out_of_range() {
    // Once blamed on the time step.
    mutated(
        "range-modulus",
        |v| v["materials"]["apple"]["shear_modulus_pa"] = json!(5e-324),
        &[
            "materials.apple.shear_modulus_pa: 5e-324 Pa",
            "(1000 Pa <= modulus <= 1e13 Pa)",
        ],
    );
}

#[test]
fn belt_speed_out_of_range() {
    // Once blamed on the time step.
    with_surface(
        "range-belt",
        json!({"name": "belt", "type": "conveyor", "material": "steel",
        "size_m": [1, 0.3, 0.04], "position_m": [2, 0, 0.5], "belt_velocity_m_s": 1e308}),
        &[
            "surfaces[1].belt_velocity_m_s: 1e308 m/s",
            "(|v| <= 100 m/s)",
        ],
    );
}

#[test]
fn steps_out_of_range() {
    // Refused before the run instead of after hours (issue 18, item 3).
    mutated(
        "range-duration",
        |v| v["duration_s"] = json!(1e9),
        &["duration_s: 1e9 s", "(1e-9 s <= t <= 1e5 s)"],
    );
    mutated(
        "range-dt",
        |v| v["time_step_s"] = json!(1e-300),
        &["time_step_s: 1e-300 s", "(1e-9 s <= dt <= 1 s)"],
    );
    mutated(
        "range-accuracy",
        |v| {
            v["time_step_s"] = json!("auto");
            v["accuracy"] = json!(1e9);
        },
        &["accuracy: 1e9", "(5 <= n <= 10000)"],
    );
}

#[test]
fn apple_count_out_of_range() {
    // A source of 1e9 apples once allocated 152 GB.
    mutated(
        "range-count",
        |v| {
            v["sources"] = json!([{"name": "s", "material": "apple", "diameter_m": 0.08,
            "position_m": [1, 1, 1], "rate_per_s": 4, "count": 1000000000u64}])
        },
        &["sources[0].count: 1e9 apples", "(0 <= N <= 1e6)"],
    );
}

#[test]
fn mass_and_diameter_make_an_impossible_density() {
    mutated(
        "range-density",
        |v| v["apples"][0]["mass_kg"] = json!(1.07e-4),
        &[
            "apples[0].mass_kg",
            "density of 0.399 kg/m^3",
            "(1 kg/m^3 <= rho <= 1e5 kg/m^3)",
        ],
    );
}

#[test]
fn poisson_ratio_that_makes_the_other_modulus_absurd() {
    mutated(
        "range-nu",
        |v| {
            v["materials"]["steel"] =
                json!({"youngs_modulus_pa": 2e11, "poisson_ratio": -0.999999999})
        },
        &["materials.steel.poisson_ratio", "shear modulus G = 1e20 Pa"],
    );
}

// The file itself (issue 18, item 2).

#[test]
fn trailing_content_is_refused() {
    let text = serde_json::to_string_pretty(&base()).unwrap();
    let lines = text.lines().count();
    refused(
        "trailing-scenario",
        &format!("{text}\n{text}"),
        &[
            ".: more text after the end of the JSON document",
            &format!("line {}", lines + 1),
            "a file holds one scenario",
        ],
    );
    refused(
        "trailing-comma",
        &format!("{text},"),
        &["more text after the end"],
    );
}

#[test]
fn byte_order_mark_is_accepted() {
    let dir = tmp("bom");
    let file = dir.join("scenario.json");
    let text = serde_json::to_string_pretty(&base()).unwrap();
    std::fs::write(&file, format!("\u{feff}{text}")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args([
            "run",
            file.to_str().unwrap(),
            "--out",
            dir.join("out").to_str().unwrap(),
            "-q",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.join("out/summary.json").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

// Exact paths (issue 18, item 5): inside surfaces, generators and the number-or-object forms.

#[test]
fn exact_path_inside_a_surface() {
    mutated(
        "path-normal",
        |v| v["surfaces"][0]["normal"] = json!([0, "0", 1]),
        &["surfaces[0].normal[1]: invalid type: string \"0\", expected f64"],
    );
    mutated(
        "path-surface-missing",
        |v| {
            v["surfaces"][0].as_object_mut().unwrap().remove("point_m");
        },
        &["surfaces[0].point_m: missing"],
    );
    mutated(
        "path-surface-type",
        |v| {
            v["surfaces"][0].as_object_mut().unwrap().remove("type");
        },
        &["surfaces[0].type: missing", "`plane`"],
    );
    mutated(
        "path-surface-unknown",
        |v| v["surfaces"][0]["colour"] = json!("grey"),
        &["surfaces[0].colour: unknown field `colour`"],
    );
}

#[test]
fn exact_path_inside_a_generator_and_a_distribution() {
    mutated(
        "path-generator",
        |v| {
            v["generators"] = json!([{"type": "grid", "name": "g", "material": "apple",
            "diameter_m": {"mean_m": 0.08, "spread_m": "0.01"}, "count": [1, 1, 1],
            "spacing_m": [0.1, 0.1, 0.1], "origin_m": [1, 1, 0.5]}])
        },
        &["generators[0].diameter_m.spread_m: invalid type: string \"0.01\", expected f64"],
    );
    mutated(
        "path-generator-count",
        |v| {
            v["generators"] = json!([{"type": "grid", "name": "g", "material": "apple",
            "diameter_m": 0.08, "count": [1, -1, 1],
            "spacing_m": [0.1, 0.1, 0.1], "origin_m": [1, 1, 0.5]}])
        },
        &["generators[0].count[1]: invalid value: integer `-1`"],
    );
    mutated(
        "path-source-diameter",
        |v| {
            v["sources"] = json!([{"name": "s", "material": "apple", "diameter_m": "80 mm",
            "position_m": [1, 1, 1], "rate_per_s": 4, "count": 3}])
        },
        &["sources[0].diameter_m: invalid type: string \"80 mm\", expected a diameter in metres"],
    );
}

#[test]
fn exact_path_of_a_mesh_scale() {
    with_surface(
        "path-scale",
        json!({"name": "tray", "type": "mesh", "material": "steel",
        "file": "tray.obj", "scale": [1, "2", 1], "position_m": [0, 0, -1]}),
        &["surfaces[1].scale[1]: invalid type: string \"2\", expected f64"],
    );
}

#[test]
fn exact_path_of_a_syntax_error() {
    let text = serde_json::to_string_pretty(&base())
        .unwrap()
        .replace("\"time_step_s\": 1e-5", "\"time_step_s\": 0x10")
        .replace("\"time_step_s\": 0.00001", "\"time_step_s\": 0x10");
    assert!(text.contains("0x10"));
    refused("path-syntax", &text, &["time_step_s: expected `,` or `}`"]);
    let text = serde_json::to_string_pretty(&base()).unwrap();
    let cut = text.find("\"normal\"").unwrap() + 14;
    refused(
        "path-eof",
        &text[..cut],
        &["surfaces[0].normal", "EOF while parsing"],
    );
}

#[test]
fn an_object_given_as_an_array_is_refused() {
    // serde's structs also read their fields from an array, in order: this was friction 0.3,
    // ke 1, lambda 1000, accepted in silence.
    mutated(
        "object-array",
        |v| v["contact"] = json!([0.3, 1, 1000]),
        &["contact: invalid type: sequence, expected an object {friction, ke, lambda_s_m, damping, restitution, tangential, rolling, rolling_friction, rolling_damping, twisting}"],
    );
}

#[test]
fn a_name_on_two_lines_is_refused_on_one() {
    mutated(
        "name-newline",
        |v| v["apples"][0]["name"] = json!("a\nb"),
        &["apples[0].name: 'a\\nb' holds a control character"],
    );
}

#[test]
fn two_generators_with_one_name() {
    mutated(
        "gen-prefix",
        |v| {
            let g = json!({"type": "grid", "name": "g", "material": "apple",
            "diameter_m": 0.08, "count": [1, 1, 1], "spacing_m": [0.1, 0.1, 0.1], "origin_m": [1, 1, 0.5]});
            let mut h = g.clone();
            h["origin_m"] = json!([2, 2, 0.5]);
            v["generators"] = json!([g, h]);
        },
        &[
            "generators[1].name",
            "'g' is already the name of generators[0]",
        ],
    );
}

#[test]
fn a_material_given_twice() {
    // A JSON object may repeat a key; a map would keep the last one in silence.
    let text = serde_json::to_string_pretty(&base()).unwrap().replacen(
        "\"materials\": {",
        "\"materials\": {\"steel\": {\"shear_modulus_pa\": 1e6, \"poisson_ratio\": 0.3},",
        1,
    );
    refused(
        "material-twice",
        &text,
        &["materials.steel: 'steel' is defined twice"],
    );
}

#[test]
fn a_field_given_twice() {
    let text = serde_json::to_string_pretty(&base()).unwrap().replacen(
        "\"ke\": 1.0,",
        "\"ke\": 1.0, \"ke\": 0.5,",
        1,
    );
    refused("field-twice", &text, &["contact.ke: given twice"]);
    // Inside a surface too (read through a buffer that once kept the last one).
    let text = serde_json::to_string_pretty(&base()).unwrap().replacen(
        "\"type\": \"plane\"",
        "\"type\": \"plane\", \"type\": \"box\"",
        1,
    );
    refused(
        "surface-field-twice",
        &text,
        &["surfaces[0].type: given twice"],
    );
}

/// Issue 18: runs that would never end are refused before they start, with the step estimate:
/// by the ranges (duration 1e9 s, a step of 1e-300 s, 1e9 steps per contact), and within the
/// ranges by the up-front step budget (1e4 s in steps of 1e-5 s is 1e9 steps; 1000 s at `auto`
/// with 1e4 steps per contact, 1.8e9) before anything is stepped.
#[test]
fn endless_runs_are_refused_up_front_with_the_step_estimate() {
    mutated(
        "duration_1e9",
        |v| v["duration_s"] = json!(1e9),
        &[
            "duration_s:",
            "about 1.000e14 steps",
            "model.max_steps = 200000000",
        ],
    );
    mutated(
        "step_1e-300",
        |v| v["time_step_s"] = json!(1e-300),
        &["time_step_s:", "about 3.000e298 steps"],
    );
    mutated(
        "accuracy_1e9",
        |v| {
            v["time_step_s"] = json!("auto");
            v["accuracy"] = json!(1e9);
        },
        &["accuracy:", "about 1.000e9 steps"],
    );
    mutated(
        "duration_1e4",
        |v| {
            v["duration_s"] = json!(1e4);
            v["output"]["sample_interval_s"] = json!(1.0);
        },
        &[
            "duration_s:",
            "about 1.000e9 steps",
            "refused before it starts",
        ],
    );
    mutated(
        "auto_1e4_per_contact",
        |v| {
            v["duration_s"] = json!(1000);
            v["output"]["sample_interval_s"] = json!(1.0);
            v["time_step_s"] = json!("auto");
            v["accuracy"] = json!(1e4);
        },
        &[
            "accuracy:",
            "steps per contact make the `auto` step",
            "refused before it starts",
        ],
    );
    mutated(
        "source_2e5_with_histories",
        |v| {
            v["sources"] = json!([{ "name": "feed", "material": "apple", "diameter_m": 0.08,
                "position_m": [0, 0, 1], "velocity_m_s": [0, 0, 0], "rate_per_s": 1e4,
                "start_s": 0, "count": 200000, "seed": 1 }]);
            // Whole histories (64 KiB an apple): the default impact ones cost half.
            v["output"]["force_history"] = json!("full");
        },
        &["sources:", "GiB of memory", "model.max_memory_mb"],
    );
    mutated(
        "sample_interval_1e-9",
        |v| v["output"]["sample_interval_s"] = json!(1e-9),
        &[
            "output.sample_interval_s:",
            "MB in 5 files (bodies.csv 5700 MB",
            "model.max_output_mb",
        ],
    );
}

/// A small line for the layout mistakes of issue 28: a belt (1.2 m long, 0.3 m wide, top at
/// 0.8 m), a flat chute placed at its discharge end, a trough, and an apple and a source `on`
/// the belt. `f` changes it before it is written.
fn line_with(f: impl FnOnce(&mut Value)) -> String {
    let mut v = json!({
        "duration_s": 0.01, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -9.81],
        "materials": { "apple": { "preset": "apple-paper" }, "steel": { "preset": "steel" } },
        "contact": { "friction": 0.5, "ke": 0.09, "lambda_s_m": 1000 },
        "apples": [{ "name": "a1", "material": "apple", "diameter_m": 0.075,
                     "on": { "surface": "belt", "along_m": 0.2 } }],
        "sources": [{ "name": "feed", "material": "apple", "diameter_m": 0.075,
                      "on": { "surface": "belt", "along_m": 0.6 }, "rate_per_s": 1, "count": 1 }],
        "surfaces": [
            { "name": "belt", "type": "conveyor", "material": "steel", "size_m": [1.2, 0.3, 0.04],
              "position_m": [0, 0, 0.78], "belt_velocity_m_s": 0.5 },
            { "name": "chute", "type": "chute", "profile": "flat", "material": "steel",
              "length_m": 1.0, "width_m": 0.3, "incline_deg": 20,
              "place": { "at": "belt.discharge", "gap_m": 0.01, "drop_m": 0.04 } },
            { "name": "trough", "type": "chute", "profile": "trough", "material": "steel",
              "length_m": 1.0, "radius_m": 0.1, "incline_deg": 10, "position_m": [0, 2, 0.5] }
        ]
    });
    f(&mut v);
    serde_json::to_string_pretty(&v).unwrap()
}

/// Issue 28, "Messages that blame a field the file does not have" and "Also": each mistake is
/// refused before the run, naming the field as the user wrote it.
#[test]
fn line_layout_mistakes_name_the_field_as_written() {
    type Case = (&'static str, Box<dyn FnOnce(&mut Value)>, Vec<&'static str>);
    let cases: Vec<Case> = vec![
        (
            "place_gap_1e308",
            Box::new(|v| v["surfaces"][1]["place"]["gap_m"] = json!(1e308)),
            vec!["error: surfaces[1].place.gap_m: 1e308 m is outside the range of fruit handling (|d| <= 10000 m)"],
        ),
        (
            "place_drop_1e5",
            Box::new(|v| v["surfaces"][1]["place"]["drop_m"] = json!(1e5)),
            vec!["error: surfaces[1].place.drop_m: 1e5 m is outside the range"],
        ),
        (
            "place_sum_out_of_range",
            Box::new(|v| {
                v["surfaces"][0]["position_m"] = json!([9000, 0, 0.78]);
                v["surfaces"][1]["place"]["gap_m"] = json!(5000);
            }),
            vec!["error: surfaces[1].place: 'belt.discharge' with gap_m 5000", "outside the range of fruit handling"],
        ),
        (
            "on_along_1e9",
            Box::new(|v| v["sources"][0]["on"]["along_m"] = json!(1e9)),
            vec!["error: sources[0].on.along_m: 1e9 m is off surface 'belt': along_m runs from 0 (its upstream end, the feed port) to 1.2 m"],
        ),
        (
            "on_along_negative",
            Box::new(|v| v["apples"][0]["on"]["along_m"] = json!(-5)),
            vec!["error: apples[0].on.along_m: -5 m is off surface 'belt'"],
        ),
        (
            "on_side_5",
            Box::new(|v| v["apples"][0]["on"]["side_m"] = json!(5)),
            vec!["error: apples[0].on.side_m: 5 m is off surface 'belt': its face is 0.3 m wide, side_m runs from -0.15 to 0.15 m"],
        ),
        (
            "on_clearance_negative",
            Box::new(|v| v["apples"][0]["on"]["clearance_m"] = json!(-0.01)),
            vec!["error: apples[0].on.clearance_m: -0.01 m is outside the range", "a negative clearance starts the apple inside the surface"],
        ),
        (
            "trough_tighter_than_fed_apples",
            Box::new(|v| {
                v["sources"][0]["diameter_m"] = json!({"mean_m": 0.15, "spread_m": 0.06});
                v["sources"][0]["on"] = json!({"surface": "trough", "along_m": 0.1});
            }),
            vec!["error: surfaces[2].radius_m: the trough 'trough' of radius 0.1 m is tighter than the apples of sources[0] ('feed'), radius up to 0.105 m"],
        ),
        (
            "random_fill_inverted",
            Box::new(|v| {
                v["generators"] = json!([{ "type": "random_fill", "name": "g", "material": "apple",
                    "diameter_m": 0.07, "count": 5, "region_min_m": [0, 3, 1],
                    "region_max_m": [1, 4, 0], "seed": 1, "velocity_m_s": [0, 0, 0] }]);
            }),
            vec!["error: generators[0].region_max_m[2]: 0 m is not above region_min_m[2] = 1 m"],
        ),
        (
            "on_a_trough_side",
            Box::new(|v| v["apples"][0]["on"] = json!({"surface": "trough", "side_m": 0.02})),
            vec!["error: apples[0].on.side_m: 0.02 m: on the trough 'trough' an apple rests on its bottom line, side_m must be 0"],
        ),
        (
            "long_name_shortened",
            Box::new(|v| v["surfaces"][1]["place"]["at"] = json!(format!("{}.discharge", "b".repeat(100_000)))),
            // The quoted name is one word of 100,002 characters (quotes included): its first
            // and last 40 are kept.
            vec![Box::leak(
                format!(
                    "error: surfaces[1].place.at: no surface named '{b}...(100002 characters)...{b}' (surfaces: belt, chute, trough)",
                    b = "b".repeat(39)
                )
                .into_boxed_str(),
            )],
        ),
    ];
    for (name, f, needles) in cases {
        let text = line_with(f);
        refused(name, &text, &needles);
    }
}

/// Issue 28: a surface named "belt.a" can be a place target (`"at": "belt.a.discharge"`: the
/// port follows the last dot), and the line it starts runs.
#[test]
fn a_surface_name_with_a_dot_is_a_place_target() {
    let text = line_with(|v| {
        v["surfaces"][0]["name"] = json!("belt.a");
        v["surfaces"][1]["place"]["at"] = json!("belt.a.discharge");
        v["apples"][0]["on"]["surface"] = json!("belt.a");
        v["sources"][0]["on"]["surface"] = json!("belt.a");
    });
    let sc = applesim::scenario::from_json(&text, "dots").unwrap();
    applesim::scenario::validate(&sc).unwrap();
    let plain = applesim::scenario::from_json(&line_with(|_| {}), "plain").unwrap();
    match (&sc.surfaces[1], &plain.surfaces[1]) {
        (applesim::scenario::SurfaceSpec::Chute(a), applesim::scenario::SurfaceSpec::Chute(b)) => {
            assert_eq!(a.position_m, b.position_m)
        }
        _ => unreachable!(),
    }
}

/// Issue 28, "Also": a write failing with EFBIG (a file size limit, SIGXFSZ ignored) while the
/// run streams bodies.csv names the file in the result folder, not "writing samples".
#[test]
fn a_write_failing_with_efbig_names_the_folder() {
    let dir = tmp("efbig");
    let mut v = base();
    v["duration_s"] = json!(0.05);
    v["output"]["sample_interval_s"] = json!(1e-5);
    let file = dir.join("scenario.json");
    std::fs::write(&file, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let out = dir.join("out");
    // 64 blocks of 512 bytes: bodies.csv outgrows it within the run.
    let cmd = format!(
        "trap '' XFSZ; ulimit -f 64; exec '{}' run '{}' --out '{}' --quiet",
        env!("CARGO_BIN_EXE_applesim"),
        file.display(),
        out.display()
    );
    let o = Command::new("sh").args(["-c", &cmd]).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    println!("{}", err.trim());
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!("writing {}", out.join("bodies.csv").display())),
        "{err}"
    );
    assert!(err.contains("File too large"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
