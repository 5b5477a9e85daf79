//! Generators and sources (issue 3): stable names, seeds, size distributions, feeding.

use crate::common;
use applesim::scenario::{self, Scenario};
use common::*;
use serde_json::json;
use std::process::Command;

fn fill(seed: u64) -> Scenario {
    let v = json!({
        "duration_s": 0.05, "time_step_s": 5e-5, "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 0.005, "force_history": false},
        "materials": {
            "apple": {"shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "plastic": {"shear_modulus_pa": 1.0e9, "poisson_ratio": 0.3}},
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
        "generators": [{"type": "random_fill", "name": "r", "material": "apple",
            "diameter_m": {"mean_m": 0.075, "spread_m": 0.006, "distribution": "normal"},
            "count": 40, "region_min_m": [-0.2, -0.2, 0.0], "region_max_m": [0.2, 0.2, 0.4], "seed": seed}],
        "surfaces": [{"name": "bin", "type": "bin", "material": "plastic",
            "inner_size_m": [0.4, 0.4, 0.4], "position_m": [0, 0, 0]}]
    });
    scenario::from_json(&v.to_string(), "fill").unwrap()
}

#[test]
fn random_fill_is_seeded_and_named() {
    let a = fill(1).initial_apples().unwrap();
    let b = fill(1).initial_apples().unwrap();
    let c = fill(2).initial_apples().unwrap();
    assert_eq!(a.len(), 40);
    assert_eq!(a, b, "same seed, same fill");
    assert_ne!(a, c, "another seed, another fill");
    let names: Vec<_> = a.iter().map(|x| x.name.as_str()).collect();
    assert_eq!(names[0], "r-1");
    assert_eq!(names[39], "r-40");
    scenario::validate(&fill(1)).expect("no overlap by construction");
    // Normal sizes are clipped at 3 standard deviations.
    assert!(a
        .iter()
        .all(|x| (x.diameter_m - 0.075).abs() <= 3.0 * 0.006 + 1e-15));
}

#[test]
fn size_distribution_has_the_asked_mean_and_spread() {
    let v = json!({"type": "grid", "name": "g", "material": "apple",
        "diameter_m": {"mean_m": 0.08, "spread_m": 0.008}, "count": [20, 20, 5],
        "spacing_m": [0.1, 0.1, 0.1], "origin_m": [0, 0, 0.05], "seed": 3});
    let g: applesim::scenario::GeneratorSpec = serde_json::from_value(v).unwrap();
    let apples = applesim::scenario::generators::expand(&g, &[], "g").unwrap();
    let d: Vec<f64> = apples.iter().map(|a| a.diameter_m).collect();
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    let sd = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / d.len() as f64).sqrt();
    // Uniform on mean +- 8 mm: standard deviation 8 / sqrt(3) = 4.62 mm. 2000 samples: the mean is
    // within 0.3 mm (about 3 standard errors), the deviation within 5 %.
    assert!((mean - 0.08).abs() < 3e-4, "mean {mean}");
    assert_rel("uniform spread", sd, 0.008 / 3f64.sqrt(), 0.05);
    assert!(d.iter().all(|&x| (0.072..=0.088).contains(&x)));
}

/// `applesim run SCENARIO --out OUT -q`, from `cwd` if given; asserts success.
fn applesim_run(scenario: &std::path::Path, out: &std::path::Path, cwd: Option<&std::path::Path>) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_applesim"));
    if let Some(d) = cwd {
        cmd.current_dir(d);
    }
    let o = cmd
        .args([
            "run",
            scenario.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "-q",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn run_cli(sc: &Scenario, dir: &std::path::Path) -> Vec<u8> {
    std::fs::create_dir_all(dir).unwrap();
    let f = dir.join("s.json");
    std::fs::write(&f, serde_json::to_string(sc).unwrap()).unwrap();
    let out = dir.join("out");
    applesim_run(&f, &out, None);
    let mut bytes = std::fs::read(out.join("bodies.csv")).unwrap();
    bytes.extend(std::fs::read(out.join("contacts.csv")).unwrap());
    bytes
}

#[test]
fn same_seed_gives_byte_identical_results() {
    let base = std::env::temp_dir().join(format!("applesim-seed-{}", std::process::id()));
    let a = run_cli(&fill(5), &base.join("a"));
    let b = run_cli(&fill(5), &base.join("b"));
    let c = run_cli(&fill(6), &base.join("c"));
    assert!(a == b, "same seed: results differ");
    assert!(a != c, "different seed: same results");
    let _ = std::fs::remove_dir_all(&base);
}

#[test]
fn source_feeds_apples_at_its_rate_with_stable_names() {
    let v = json!({
        "duration_s": 1.0, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 0.01, "force_history": false},
        "materials": {
            "apple": {"shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "steel": {"shear_modulus_pa": 8.1e10, "poisson_ratio": 0.28}},
        "contact": {"friction": 0.3, "ke": 0.09, "lambda_s_m": 1000},
        "sources": [{"name": "s", "material": "apple", "diameter_m": 0.08,
            "position_m": [0, 0, 0.3], "velocity_m_s": [0.5, 0, 0], "rate_per_s": 5, "count": 4, "start_s": 0.1}],
        "surfaces": [{"name": "floor", "type": "plane", "material": "steel", "point_m": [0, 0, 0], "normal": [0, 0, 1]}]
    });
    let sc = scenario::from_json(&v.to_string(), "src").unwrap();
    let (r, series) = run(&sc);
    let names: Vec<_> = r.apples.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["s-1", "s-2", "s-3", "s-4"]);
    // Apple k appears at 0.1 + k / 5 s: count the apples present in each sample.
    for (t, states) in &series.samples {
        let expect = (0..4).filter(|k| 0.1 + *k as f64 / 5.0 <= t + 1e-9).count();
        assert_eq!(states.len(), expect, "at t = {t}");
    }
}

#[test]
fn rigid_surfaces_use_rapiers_contact_and_record_nothing() {
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.contact.ke = Some(0.25);
    sc.duration_s = 0.2;
    let mut v = serde_json::to_value(&sc).unwrap();
    v["surfaces"][0]["contact_model"] = json!("rigid");
    let sc: Scenario = serde_json::from_value(v).unwrap();
    let (r, series) = run(&sc);
    assert!(
        r.events.is_empty(),
        "no Hertz contact recorded on a rigid surface"
    );
    // It still bounces (rapier's restitution): the apple goes up again after landing.
    let s = series.of(0);
    assert!(s.iter().any(|(_, a)| a.velocity.z > 0.1), "no bounce");
    assert!(
        s.iter().all(|(_, a)| a.position.z > 0.03),
        "fell through the floor"
    );
}

/// A pile written to a file (name, diameter, position each), as the LIGGGHTS reference's gen.py
/// writes it: numbers chosen not to be round in binary.
const PILE: &str = r#"[
  {"name": "p1", "diameter_m": 0.074150, "position_m": [-0.196526, -0.197362, 0.05]},
  {"name": "p2", "diameter_m": 0.076081, "position_m": [-0.100046, -0.200505, 0.05]},
  {"name": "q7", "diameter_m": 0.082425, "position_m": [0.002887, -0.204061, 0.15]}
]"#;

fn pile_scenario(file: &str) -> serde_json::Value {
    json!({
        "duration_s": 0.02, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 0.01, "force_history": false},
        "materials": {
            "apple": {"youngs_modulus_pa": 2.6e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "steel": {"youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.3}},
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
        "apples": [{"name": "first", "material": "apple", "diameter_m": 0.08, "position_m": [1, 1, 0.05]}],
        "generators": [{"type": "file", "name": "f", "material": "apple", "file": file,
            "velocity_m_s": [0.1, 0, 0]}],
        "surfaces": [{"name": "floor", "type": "plane", "material": "steel", "point_m": [0, 0, 0], "normal": [0, 0, 1]}]
    })
}

#[test]
fn file_generator_reads_names_diameters_and_positions_exactly() {
    let dir = std::env::temp_dir().join(format!("applesim-file-gen-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("piles")).unwrap();
    std::fs::write(dir.join("piles/p.json"), PILE).unwrap();
    let path = dir.join("s.json");
    std::fs::write(&path, pile_scenario("piles/p.json").to_string()).unwrap();

    // Relative to the scenario's folder, whatever the working directory.
    let sc = scenario::load(&path).unwrap();
    let apples = sc.initial_apples().unwrap();
    let want: Vec<(&str, f64, [f64; 3])> = vec![
        ("first", 0.08, [1.0, 1.0, 0.05]),
        ("f-p1", 0.074150, [-0.196526, -0.197362, 0.05]),
        ("f-p2", 0.076081, [-0.100046, -0.200505, 0.05]),
        ("f-q7", 0.082425, [0.002887, -0.204061, 0.15]),
    ];
    assert_eq!(apples.len(), want.len());
    for (a, (name, d, p)) in apples.iter().zip(&want) {
        assert_eq!(a.name, *name);
        // Exactly the file's numbers: the same decimal text parses to the same f64.
        assert_eq!(a.diameter_m, *d, "{name}");
        assert_eq!(a.position_m, *p, "{name}");
        assert_eq!(a.material, "apple");
        assert_eq!(a.mass_kg, None);
    }
    assert_eq!(apples[1].velocity_m_s, [0.1, 0.0, 0.0]);
    assert_eq!(apples[0].velocity_m_s, [0.0, 0.0, 0.0]);

    // mass_kg applies to every apple of the file.
    let mut v = pile_scenario("piles/p.json");
    v["generators"][0]["mass_kg"] = json!(0.2);
    std::fs::write(&path, v.to_string()).unwrap();
    let sc = scenario::load(&path).unwrap();
    let apples = sc.initial_apples().unwrap();
    assert!(apples[1..].iter().all(|a| a.mass_kg == Some(0.2)));

    // Parsed without its folder, the file is not read: validation says so instead of guessing
    // a directory; read_files with the folder makes it whole.
    let mut sc = scenario::from_json(&v.to_string(), "s").unwrap();
    let e = scenario::validate(&sc).unwrap_err().to_string();
    assert!(
        e.contains("generators[0].file") && e.contains("has not been read"),
        "{e}"
    );
    sc.read_files(&dir).unwrap();
    scenario::validate(&sc).unwrap();
    assert_eq!(sc.initial_apples().unwrap().len(), 4);

    // Through the CLI from another working directory: the run has the file's apples.
    let out = dir.join("out");
    applesim_run(&path, &out, Some(&std::env::temp_dir()));
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    let names: Vec<&str> = summary["apples"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["first", "f-p1", "f-p2", "f-q7"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn file_generator_values_are_validated() {
    // The file's values are checked by validate (the format by read_files): a list set in code
    // with a non-finite position or a non-positive diameter is refused with the entry named.
    use applesim::scenario::generators::FileApples;
    use applesim::scenario::{FileApple, GeneratorSpec};
    let v = pile_scenario("unused.json");
    let with = |apples: Vec<FileApple>| {
        let mut sc = scenario::from_json(&v.to_string(), "s").unwrap();
        let GeneratorSpec::File(f) = &mut sc.generators[0] else {
            unreachable!()
        };
        f.loaded = Some(FileApples(std::sync::Arc::new(apples)));
        scenario::validate(&sc).map_err(|e| e.to_string())
    };
    let apple = |name: &str, d: f64, p: [f64; 3]| FileApple {
        name: name.into(),
        diameter_m: d,
        height_m: None,
        rotation: None,
        position_m: p,
    };
    let e = with(vec![apple("a", 0.08, [0.0, 0.0, f64::NAN])]).unwrap_err();
    assert!(
        e.contains("generators[0].file: unused.json[0].position_m"),
        "{e}"
    );
    let e = with(vec![
        apple("a", 0.08, [0.0, 0.0, 0.1]),
        apple("b", -0.08, [0.5, 0.0, 0.1]),
    ])
    .unwrap_err();
    assert!(e.contains("unused.json[1].diameter_m: -0.08"), "{e}");
    assert!(with(vec![apple("a", 0.08, [0.0, 0.0, 0.1])]).is_ok());
}

/// README, Many apples: a source's apple k appears at start_s + k / rate_per_s; if its spot is
/// still taken it waits (a warning says so). Here apples of 80 mm leave at 0.5 m/s, every 0.1 s:
/// the second waits until the first has moved a diameter, 0.16 s.
#[test]
fn a_fed_apple_waits_for_its_spot() {
    let v = json!({
        "duration_s": 0.3, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, 0],
        "output": {"sample_interval_s": 1e-3, "force_history": false},
        "materials": {"apple": {"shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800}},
        "contact": {"friction": 0.3, "ke": 0.09, "lambda_s_m": 1000},
        "sources": [{"name": "feed", "material": "apple", "diameter_m": 0.08, "position_m": [0, 0, 0],
            "jitter_m": 0.0, "velocity_m_s": [0.5, 0, 0], "rate_per_s": 10, "start_s": 0.0,
            "count": 2, "seed": 1}]
    });
    let sc = applesim::scenario::from_json(&v.to_string(), "wait").unwrap();
    let (r, s) = run(&sc);
    let first = s
        .of(1)
        .first()
        .map(|(t, _)| *t)
        .expect("the second apple is fed in");
    println!(
        "second apple appears at {first} s; warnings {:?}",
        r.warnings
    );
    assert!(
        (0.16 - 1e-3..=0.16 + 2e-3).contains(&first),
        "appears at {first} s, not 0.16 s"
    );
    assert!(
        r.warnings
            .iter()
            .any(|w| w.starts_with("source 'feed': 1 apple waited, ")
                && w.contains("for apple 'feed-1' to clear the spot")),
        "{:?}",
        r.warnings
    );
}
