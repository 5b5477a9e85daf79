//! Steps per second for the single-apple drop and for 1000 apples settling in a box
//! (issue 2). Run: `cargo bench --bench steps`; figures go to docs/benchmarks.md.
//!
//! The pile is the LIGGGHTS reference lattice of ../shared/bench/liggghts (5 x 5 x 40 apples,
//! 0.1 m apart, diameters 72-88 mm, 800 kg/m^3, E = 2.6 MPa, open steel box of half-width
//! 0.25 m), built here with its own random numbers; dt = 1e-4 s, friction 0.5, ke = 0.09 with
//! lambda = 1000 s/m (e = 0.3).

use applesim::record::series::NoSamples;
use applesim::scenario::{self, Scenario};
use applesim::sim::Simulation;
use serde_json::json;
use std::path::Path;
use std::time::Instant;

fn pile(n_layers: usize) -> Scenario {
    let mut seed = 1u64;
    let mut rnd = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut apples = Vec::new();
    for k in 0..n_layers {
        for j in 0..5 {
            for i in 0..5 {
                let d = 0.072 + 0.016 * rnd();
                let x = -0.25 + (i as f64 + 0.5) * 0.1 + (rnd() - 0.5) * 0.01;
                let y = -0.25 + (j as f64 + 0.5) * 0.1 + (rnd() - 0.5) * 0.01;
                let z = 0.05 + k as f64 * 0.1;
                apples.push(json!({"name": format!("p{}", apples.len() + 1), "material": "apple",
                    "diameter_m": d, "position_m": [x, y, z]}));
            }
        }
    }
    let wall = |name: &str, p: [f64; 3], n: [f64; 3]| {
        json!({"name": name, "type": "plane", "material": "steel", "point_m": p, "normal": n})
    };
    let v = json!({
        "duration_s": 5.0, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 0.1, "force_history": false},
        "materials": {
            "apple": {"youngs_modulus_pa": 2.6e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "steel": {"youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.3}},
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
        "apples": apples,
        "surfaces": [wall("floor", [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            wall("x-", [-0.25, 0.0, 0.0], [1.0, 0.0, 0.0]), wall("x+", [0.25, 0.0, 0.0], [-1.0, 0.0, 0.0]),
            wall("y-", [0.0, -0.25, 0.0], [0.0, 1.0, 0.0]), wall("y+", [0.0, 0.25, 0.0], [0.0, -1.0, 0.0])]
    });
    let sc = scenario::from_json(&v.to_string(), "pile").unwrap();
    scenario::validate(&sc).unwrap();
    sc
}

fn time_window(sim: &mut Simulation, steps: u64) -> f64 {
    let t0 = Instant::now();
    for _ in 0..steps {
        sim.step(&mut NoSamples).expect("stable run");
    }
    t0.elapsed().as_secs_f64()
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // Single apple drop at the shipped step, repeated to get a stable figure.
    let drop = scenario::load(&root.join("scenarios/drop_on_steel.json")).unwrap();
    let mut total = 0.0;
    let mut steps = 0u64;
    for _ in 0..20 {
        let mut sim = Simulation::new(&drop, root).unwrap();
        let n = sim.steps_total();
        total += time_window(&mut sim, n);
        steps += n;
    }
    println!("drop_on_steel: {steps} steps in {total:.3} s: {:.3e} steps/s", steps as f64 / total);

    let sc = pile(40);
    let n = sc.apples.len() as f64;
    let mut sim = Simulation::new(&sc, root).unwrap();
    let report = |name: &str, sim: &mut Simulation, steps: u64| {
        let t = time_window(sim, steps);
        let contacts = sim.world().layer.stats().contacts as f64 / n;
        println!(
            "pile {n} apples, {name}: {:.3} ms/step, {:.3e} apple-steps/s, {:.2} contacts/apple at the end",
            1e3 * t / steps as f64,
            n * steps as f64 / t,
            contacts
        );
        t
    };
    let mut wall = 0.0;
    wall += report("falling 0-0.5 s", &mut sim, 5000);
    wall += report("impact 0.5-1 s", &mut sim, 5000);
    wall += report("1-3 s", &mut sim, 20000);
    wall += report("settled 3-5 s", &mut sim, 20000);
    println!("pile whole 0-5 s: {wall:.2} s wall time");
}
