//! The LIGGGHTS reference pile as shipped scenarios (issue 11): scenarios/bench/ holds the scene
//! of shared/bench/liggghts/README.md exactly, with the apples of gen.py (assets/piles/). A full
//! run takes minutes; here the scenarios are loaded and checked, and the 1000-apple pile is
//! stepped briefly.

use crate::common;
use applesim::record::series::NoSamples;
use applesim::scenario::{self, SurfaceSpec, TimeStep};
use applesim::sim::Simulation;
use common::repo;

#[derive(serde::Deserialize)]
struct FileApple {
    name: String,
    diameter_m: f64,
    position_m: [f64; 3],
}

/// (scenario, pile file, apples, box half-width W in m)
const PILES: [(&str, &str, usize, f64); 2] = [
    (
        "scenarios/bench/liggghts_pile_1000.json",
        "assets/piles/liggghts_1000.json",
        1000,
        0.25,
    ),
    (
        "scenarios/bench/liggghts_pile_8036.json",
        "assets/piles/liggghts_8036.json",
        8036,
        0.70,
    ),
];

#[test]
fn both_piles_load_with_the_reference_scene() {
    for (file, pile, n, w) in PILES {
        let sc = scenario::load(&repo(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        // The scene of shared/bench/liggghts/README.md and in.apple.
        assert_eq!(sc.duration_s, 5.0);
        assert_eq!(sc.time_step_s, TimeStep::Fixed(1e-4));
        assert_eq!(sc.gravity_m_s2, [0.0, 0.0, -9.81]);
        let apple = &sc.materials["apple"];
        assert_eq!(
            (
                apple.youngs_modulus_pa,
                apple.poisson_ratio,
                apple.density_kg_m3
            ),
            (Some(2.6e6), Some(0.18), Some(800.0))
        );
        let steel = &sc.materials["steel"];
        assert_eq!(
            (steel.youngs_modulus_pa, steel.poisson_ratio),
            (Some(2.0e11), Some(0.3))
        );
        assert_eq!(
            (sc.contact.friction, sc.contact.ke, sc.contact.lambda_s_m),
            (0.5, Some(0.09), Some(1000.0))
        );
        assert!(
            sc.pairs.is_empty(),
            "{file}: one set of coefficients for all pairs"
        );
        assert!(!sc.force_history().is_kept() && !sc.output.transitions.enabled);
        assert_eq!(sc.output.sample_interval_s, Some(0.1));
        assert_eq!(
            sc.model,
            Default::default(),
            "{file}: default model and sleeping"
        );

        // Five steel planes: the floor and four walls at +-W facing inwards, no lid.
        let planes: Vec<([f64; 3], [f64; 3])> = sc
            .surfaces
            .iter()
            .map(|s| match s {
                SurfaceSpec::Plane(p) => {
                    assert_eq!(p.material, "steel");
                    (p.point_m, p.normal)
                }
                _ => panic!("{file}: only planes expected"),
            })
            .collect();
        assert_eq!(
            planes,
            [
                ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
                ([-w, 0.0, 0.0], [1.0, 0.0, 0.0]),
                ([w, 0.0, 0.0], [-1.0, 0.0, 0.0]),
                ([0.0, -w, 0.0], [0.0, 1.0, 0.0]),
                ([0.0, w, 0.0], [0.0, -1.0, 0.0]),
            ]
        );

        // The apples are the pile file's, in its order, with the generator's prefix, inside the box.
        let listed: Vec<FileApple> =
            serde_json::from_slice(&std::fs::read(repo(pile)).unwrap()).unwrap();
        let apples = sc.initial_apples().unwrap();
        assert_eq!(apples.len(), n, "{file}");
        assert_eq!(listed.len(), n, "{pile}");
        for (a, l) in apples.iter().zip(&listed) {
            assert_eq!(a.name, format!("p-{}", l.name));
            assert_eq!((a.diameter_m, a.position_m), (l.diameter_m, l.position_m));
            assert!((0.072..=0.088).contains(&a.diameter_m), "{}", a.name);
            let r = a.diameter_m / 2.0;
            let [x, y, z] = a.position_m;
            assert!(
                x.abs() + r < w && y.abs() + r < w && z > r,
                "{} outside the box",
                a.name
            );
        }
        assert_eq!(apples[0].name, "p-p1");
        assert_eq!(apples[n - 1].name, format!("p-p{n}"));
    }
}

#[test]
fn the_1000_apple_pile_steps() {
    let file = repo(PILES[0].0);
    let sc = scenario::load(&file).unwrap();
    let mut sim = Simulation::new(&sc, file.parent().unwrap()).unwrap();
    let z0: Vec<f64> = sim.apple_states().iter().map(|s| s.position.z).collect();
    let steps = 100;
    for _ in 0..steps {
        sim.step(&mut NoSamples).unwrap();
    }
    assert_eq!(sim.steps_done(), steps);
    assert!((sim.time_s() - 0.01).abs() < 1e-12);
    let states = sim.apple_states();
    assert_eq!(states.len(), 1000);
    // The top apple (p1000, z = 4.05 m) falls freely: symplectic Euler from rest drops it by
    // g dt^2 n (n + 1) / 2 after n steps.
    let dt = 1e-4;
    let want = 9.81 * dt * dt * (steps * (steps + 1)) as f64 / 2.0;
    let fell = z0[999] - states[999].position.z;
    assert!(
        (fell - want).abs() < 1e-3 * want,
        "top apple fell {fell} m, free fall {want} m"
    );
    // Nothing has reached the floor or passed through it yet: the lowest layer is 6-14 mm up.
    assert!(states.iter().all(|s| s.position.z > 0.035));
}

/// Issue 30 item 3: the benchmark line's roller singulator (bench/make_line_1000.py) is a looped
/// bed: 35 rollers, each carried round the same closed path (a top run of 1.2 m from x 8.98 m at
/// z 0.80 m, 0.2 m down, back under it, up) at 0.32 m/s between every two keyframes, to one second
/// past the run's end; the line builds and steps.
#[test]
fn the_benchmark_line_has_a_looped_singulator() {
    let file = "scenarios/bench/line_1000.json";
    let sc = scenario::load(&repo(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
    let (x0, x1, top, bottom, v) = (8.98, 8.98 + 1.2, 0.80, 0.60, 0.32);
    let mut rollers = 0;
    for s in &sc.surfaces {
        let SurfaceSpec::Roller(r) = s else { continue };
        if !r.name.starts_with("singulator-") {
            continue;
        }
        rollers += 1;
        let keys = r
            .motion
            .as_ref()
            .and_then(|m| m.translation.as_ref())
            .and_then(|t| t.keyframes.as_ref())
            .unwrap_or_else(|| panic!("{}: keyframes", r.name));
        assert!(
            keys.last().unwrap().0 >= sc.duration_s + 1.0 - 1e-9,
            "{}",
            r.name
        );
        let at = |k: usize| {
            let (t, d) = keys[k];
            (t, r.position_m[0] + d[0], r.position_m[2] + d[2])
        };
        for k in 0..keys.len() {
            let (t, x, z) = at(k);
            // On the loop: the top or bottom run, or one of its two ends.
            let on_run = ((z - top).abs() < 1e-9 || (z - bottom).abs() < 1e-9)
                && (x0 - 1e-9..=x1 + 1e-9).contains(&x);
            let on_end = ((x - x0).abs() < 1e-9 || (x - x1).abs() < 1e-9)
                && (bottom - 1e-9..=top + 1e-9).contains(&z);
            assert!(on_run || on_end, "{} at {t} s: ({x}, {z})", r.name);
            if k > 0 {
                let (t0, xa, za) = at(k - 1);
                // Straight between corners, so the distance is the path's length.
                let speed = ((x - xa).powi(2) + (z - za).powi(2)).sqrt() / (t - t0);
                assert!(
                    (speed - v).abs() < 1e-6,
                    "{} {t0}-{t} s: {speed} m/s",
                    r.name
                );
            }
        }
    }
    assert_eq!(rollers, 35);
    let mut sim = Simulation::new(&sc, &repo("scenarios/bench")).expect("the line builds");
    for _ in 0..200 {
        sim.step(&mut NoSamples).expect("the line steps");
    }
}
