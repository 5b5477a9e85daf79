//! Issue 22's layout helpers (src/scenario/layout.rs): a surface placed at another's port, a
//! source or apple put on a surface, against the geometry written out by hand (the closed
//! forms of the ports: a conveyor's discharge end is its centre + (L/2, 0, T/2) in its frame, a
//! chute's top edge its reference point - (L/2) (cos t, 0, -sin t)), and the refusals.

use applesim::scenario::surfaces::SurfaceSpec;
use applesim::scenario::{self, Scenario};

/// A belt (1.5 m long, 0.04 m thick, top at 0.8 m, optionally turned by `heading` degrees about
/// z), a 1 m chute at 20 degrees and a bin; `chute`, `bin` and `source` are the JSON of their
/// placement fields.
fn scene(heading: f64, chute: &str, bin: &str, source: &str) -> String {
    format!(
        r#"{{
  "duration_s": 0.01, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -9.81],
  "materials": {{ "apple": {{ "preset": "apple-paper" }}, "steel": {{ "preset": "steel" }} }},
  "contact": {{ "friction": 0.5, "ke": 0.09, "lambda_s_m": 1000 }},
  "sources": [ {{ "name": "feed", "material": "apple", "diameter_m": {{ "mean_m": 0.075, "spread_m": 0.005 }},
                  {source} "rate_per_s": 1, "count": 1 }} ],
  "surfaces": [
    {{ "name": "belt", "type": "conveyor", "material": "steel", "size_m": [1.5, 0.3, 0.04],
       "position_m": [0, 0, 0.78], "rotation": {{ "axis": [0, 0, 1], "angle_deg": {heading} }},
       "belt_velocity_m_s": 0.5 }},
    {{ "name": "chute", "type": "chute", "profile": "flat", "material": "steel", "length_m": 1.0,
       "width_m": 0.3, "incline_deg": 20, "rotation": {{ "axis": [0, 0, 1], "angle_deg": {heading} }}, {chute} }},
    {{ "name": "bin", "type": "bin", "material": "steel", "inner_size_m": [0.5, 0.4, 0.35], {bin} }}
  ]
}}"#
    )
}

fn position(sc: &Scenario, name: &str) -> [f64; 3] {
    match sc.surfaces.iter().find(|s| s.name() == name).unwrap() {
        SurfaceSpec::Chute(c) => c.position_m,
        SurfaceSpec::Bin(b) => b.position_m,
        SurfaceSpec::Conveyor(c) => c.position_m,
        other => panic!("{other:?}"),
    }
}

fn close(what: &str, got: [f64; 3], want: [f64; 3]) {
    println!("{what}: {got:?} (hand geometry {want:?})");
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() <= 1e-12, "{what}: {got:?} against {want:?}");
    }
}

const PLACED_CHUTE: &str = r#""place": { "at": "belt.discharge", "gap_m": 0.01, "drop_m": 0.04 }"#;
const PLACED_BIN: &str = r#""place": { "at": "chute.bottom", "gap_m": 0.3, "drop_m": 0.418 }"#;
const SOURCE_ON_BELT: &str = r#""on": { "surface": "belt", "along_m": 0.15 },"#;

#[test]
fn a_chute_at_the_belt_end_and_a_bin_under_the_chute() {
    let sc =
        scenario::from_json(&scene(0.0, PLACED_CHUTE, PLACED_BIN, SOURCE_ON_BELT), "t").unwrap();
    scenario::validate(&sc).unwrap();
    let (c, s) = (20f64.to_radians().cos(), 20f64.to_radians().sin());
    // Discharge end (0.75, 0, 0.80); the chute's top edge 10 mm on and 40 mm down; its reference
    // point half its length down the slope from there.
    let top = [0.75 + 0.01, 0.0, 0.80 - 0.04];
    close(
        "chute",
        position(&sc, "chute"),
        [top[0] + 0.5 * c, 0.0, top[2] - 0.5 * s],
    );
    // The chute's lower edge, 0.3 m on, 0.418 m down: the bin's floor centre.
    let bottom = [top[0] + c, 0.0, top[2] - s];
    close(
        "bin",
        position(&sc, "bin"),
        [bottom[0] + 0.3, 0.0, bottom[2] - 0.418],
    );
    // The source 0.15 m along the belt from its feed end, its largest apple (80 mm) 1 mm above
    // the belt.
    close(
        "source",
        sc.sources[0].position_m,
        [-0.75 + 0.15, 0.0, 0.80 + 0.04 + 0.001],
    );
}

#[test]
fn a_turned_line_places_along_its_own_flow() {
    let sc =
        scenario::from_json(&scene(90.0, PLACED_CHUTE, PLACED_BIN, SOURCE_ON_BELT), "t").unwrap();
    let (c, s) = (20f64.to_radians().cos(), 20f64.to_radians().sin());
    // Turned 90 degrees about z: the belt runs along +y.
    let top = [0.0, 0.75 + 0.01, 0.80 - 0.04];
    close(
        "chute",
        position(&sc, "chute"),
        [0.0, top[1] + 0.5 * c, top[2] - 0.5 * s],
    );
    close(
        "bin",
        position(&sc, "bin"),
        [0.0, top[1] + c + 0.3, top[2] - s - 0.418],
    );
    close(
        "source",
        sc.sources[0].position_m,
        [0.0, -0.75 + 0.15, 0.841],
    );
}

/// The scenario as run (scenario.json) holds both the place and the resolved position: it loads
/// again to the same positions; a position that disagrees with its place is refused.
#[test]
fn the_scenario_as_run_loads_again_and_a_disagreeing_position_is_refused() {
    let sc =
        scenario::from_json(&scene(0.0, PLACED_CHUTE, PLACED_BIN, SOURCE_ON_BELT), "t").unwrap();
    let text = serde_json::to_string(&sc).unwrap();
    let again = scenario::from_json(&text, "again").unwrap();
    assert_eq!(position(&again, "chute"), position(&sc, "chute"));
    assert_eq!(position(&again, "bin"), position(&sc, "bin"));
    let both = format!(r#""position_m": [1.2, 0, 0.59], {PLACED_CHUTE}"#);
    let e = scenario::from_json(&scene(0.0, &both, PLACED_BIN, SOURCE_ON_BELT), "t")
        .unwrap_err()
        .to_string();
    println!("{e}");
    assert!(
        e.starts_with("surfaces[1].position_m: [1.2, 0, 0.59] disagrees with the place"),
        "{e}"
    );
}

#[test]
fn unknown_references_ports_and_circles_are_refused_by_name() {
    let cases = [
        (
            r#""place": { "at": "conveyor.discharge" }"#,
            PLACED_BIN,
            SOURCE_ON_BELT,
            "surfaces[1].place.at: no surface named 'conveyor' (surfaces: belt, chute, bin)",
        ),
        (
            r#""place": { "at": "belt.end" }"#,
            PLACED_BIN,
            SOURCE_ON_BELT,
            "surfaces[1].place.at: 'belt.end': a conveyor's ports are feed, discharge",
        ),
        (
            r#""place": { "at": "belt" }"#,
            PLACED_BIN,
            SOURCE_ON_BELT,
            "surfaces[1].place.at: 'belt': write SURFACE.PORT",
        ),
        (
            r#""place": { "at": "belt.discharge", "anchor": "middle" }"#,
            PLACED_BIN,
            SOURCE_ON_BELT,
            "surfaces[1].place.anchor: 'middle': a chute's ports are top, bottom",
        ),
        (
            r#""place": { "at": "bin.rim" }"#,
            PLACED_BIN,
            SOURCE_ON_BELT,
            "surfaces[1].place.at: the places of 'chute', 'bin' refer to each other in a circle",
        ),
        (
            r#""place": { "at": "chute.top" }"#,
            PLACED_BIN,
            SOURCE_ON_BELT,
            "surfaces[1].place.at: 'chute.top' places the surface relative to itself",
        ),
        (
            r#""incline_deg_extra": 0"#,
            PLACED_BIN,
            SOURCE_ON_BELT,
            "unknown field `incline_deg_extra`",
        ),
        (
            PLACED_CHUTE,
            r#""wall_thickness_m": 0.01"#,
            SOURCE_ON_BELT,
            "surfaces[2].position_m: missing: give the position, or a `place`",
        ),
        (
            PLACED_CHUTE,
            PLACED_BIN,
            r#""on": { "surface": "bin" },"#,
            "sources[0].on.surface: 'bin' is a bin: an apple can be put on a conveyor, a chute or a box",
        ),
        (
            PLACED_CHUTE,
            PLACED_BIN,
            r#""on": { "surface": "belts" },"#,
            "sources[0].on.surface: no surface named 'belts'",
        ),
        (
            PLACED_CHUTE,
            PLACED_BIN,
            "",
            "sources[0].position_m: missing: give the position, or `on` a surface",
        ),
    ];
    for (chute, bin, source, want) in cases {
        let e = scenario::from_json(&scene(0.0, chute, bin, source), "t")
            .map(|_| String::from("accepted"))
            .unwrap_or_else(|e| e.to_string());
        println!("{e}");
        assert!(e.contains(want), "{e}\nwanted: {want}");
    }
}
