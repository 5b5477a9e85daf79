//! Material presets (docs/materials.md, `scenario::presets`): a named preset fills what the
//! scenario leaves out, the scenario's own numbers win, pair coefficients of two presets fill
//! their pair, a value no source gives is asked for by name, and the doc's tables are the code's.

use applesim::scenario::{self, models::Damping, presets};
use std::path::Path;

fn repo(p: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn drop_text() -> String {
    std::fs::read_to_string(repo("scenarios/drop_on_steel.json")).unwrap()
}

#[test]
fn a_preset_fills_the_material_and_runs_as_the_explicit_values() {
    let explicit = scenario::from_json(&drop_text(), "drop").unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&drop_text()).unwrap();
    v["materials"]["apple"] = serde_json::json!({"preset": "apple-paper"});
    v["materials"]["steel"] = serde_json::json!({"preset": "steel-paper"});
    let named = scenario::from_json(&v.to_string(), "drop").unwrap();
    let (a, s) = (&named.materials["apple"], &named.materials["steel"]);
    assert_eq!(
        (a.shear_modulus_pa, a.poisson_ratio, a.density_kg_m3),
        (Some(1.1e6), Some(0.18), Some(800.0))
    );
    assert_eq!(
        (s.shear_modulus_pa, s.poisson_ratio),
        (Some(8.1e10), Some(0.28))
    );
    // The drop on steel, by presets or by the numbers the paper gives: the same impact, bit for bit.
    let run = |sc: &scenario::Scenario| {
        scenario::validate(sc).unwrap();
        applesim::sim::run(
            sc,
            &repo("scenarios"),
            &mut applesim::record::series::NoSamples,
        )
        .unwrap()
    };
    let (x, y) = (run(&explicit), run(&named));
    assert_eq!(x.events.len(), 1);
    assert_eq!(
        x.events[0].peak_force_n.to_bits(),
        y.events[0].peak_force_n.to_bits()
    );
    assert_eq!(x.events[0].duration_s, y.events[0].duration_s);
}

#[test]
fn the_scenarios_own_numbers_override_a_preset() {
    let mut v: serde_json::Value = serde_json::from_str(&drop_text()).unwrap();
    v["materials"]["steel"] =
        serde_json::json!({"preset": "steel", "youngs_modulus_pa": 1.9e11, "density_kg_m3": 7800});
    let sc = scenario::from_json(&v.to_string(), "drop").unwrap();
    let s = &sc.materials["steel"];
    // Eurocode 3's nu = 0.3 kept; the modulus and density given win.
    assert_eq!(
        (
            s.youngs_modulus_pa,
            s.shear_modulus_pa,
            s.poisson_ratio,
            s.density_kg_m3
        ),
        (Some(1.9e11), None, Some(0.3), Some(7800.0))
    );
    // A shear modulus given replaces the preset's Young's modulus (one modulus per material).
    v["materials"]["steel"] = serde_json::json!({"preset": "steel", "shear_modulus_pa": 8e10});
    let sc = scenario::from_json(&v.to_string(), "drop").unwrap();
    assert_eq!(sc.materials["steel"].youngs_modulus_pa, None);
    scenario::validate(&sc).unwrap();
}

#[test]
fn pair_coefficients_of_two_presets_fill_their_pair() {
    let mut v: serde_json::Value = serde_json::from_str(&drop_text()).unwrap();
    v["materials"]["apple"] = serde_json::json!({"preset": "apple-luli", "shear_modulus_pa": 1.1e6,
        "poisson_ratio": 0.18, "density_kg_m3": 800});
    v["materials"]["pad"] = serde_json::json!({"preset": "foam-hd", "youngs_modulus_pa": 2e5,
        "poisson_ratio": 0.1});
    let sc = scenario::from_json(&v.to_string(), "drop").unwrap();
    scenario::validate(&sc).unwrap();
    // Luli calibration: apple on high-density foam e 0.47, mu 0.61, mu_r 0.0288; eq. 12 takes
    // ke = e^2 with lambda 1000 s/m (physics.md section 3: e -> sqrt(ke) for lambda v0 >> 1).
    let p = sc.pair_law("apple", "pad");
    assert_eq!(p.friction, 0.61);
    assert_eq!(p.rolling_friction, 0.0288);
    assert!((p.ke.unwrap() - 0.47 * 0.47).abs() < 1e-15);
    assert_eq!(p.lambda_s_m, Some(1000.0));
    let aa = sc.pair_law("apple", "apple");
    assert_eq!((aa.friction, aa.rolling_friction), (0.42, 0.032));
    assert!((aa.ke.unwrap() - 0.65 * 0.65).abs() < 1e-15);
    // With the viscoelastic damping the restitution itself; a pairs[] entry's own numbers win.
    v["contact"]["damping"] = serde_json::json!("viscoelastic");
    v["contact"]["restitution"] = serde_json::json!(0.3);
    v["pairs"] = serde_json::json!([{"materials": ["pad", "apple"], "friction": 0.5}]);
    let sc = scenario::from_json(&v.to_string(), "drop").unwrap();
    let p = sc.pair_law("apple", "pad");
    assert_eq!(p.damping, Damping::Viscoelastic);
    assert_eq!(
        (p.friction, p.restitution, p.rolling_friction),
        (0.5, Some(0.47), 0.0288)
    );
}

#[test]
fn what_no_source_gives_is_asked_for_by_name() {
    let mut v: serde_json::Value = serde_json::from_str(&drop_text()).unwrap();
    v["materials"]["steel"] = serde_json::json!({"preset": "wood-paper"});
    let sc = scenario::from_json(&v.to_string(), "drop").unwrap();
    let e = scenario::validate(&sc).unwrap_err().to_string();
    assert!(
        e.starts_with("materials.steel.poisson_ratio: missing")
            && e.contains("the preset 'wood-paper' does not give one"),
        "{e}"
    );
    v["materials"]["steel"] = serde_json::json!({"preset": "stainless"});
    let e = scenario::from_json(&v.to_string(), "drop")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("materials.steel.preset: unknown preset 'stainless' (known: apple-paper,"),
        "{e}"
    );
}

#[test]
fn docs_materials_holds_the_tables() {
    let doc = std::fs::read_to_string(repo("docs/materials.md")).unwrap();
    let table = presets::markdown();
    assert!(
        doc.contains(&table),
        "docs/materials.md is out of date; its tables should read:\n{table}"
    );
}
