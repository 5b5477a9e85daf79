//! Steps a scenario to a time, then one window of simulated time through a function that is
//! never inlined, so that a profiler can look at that window alone (docs/performance.md):
//!
//! ```sh
//! cargo run --release --example profile_window -- scenarios/bench/liggghts_pile_1000.json 0.5 1
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect=profile_window::measured_step \
//!     target/release/examples/profile_window scenarios/bench/liggghts_pile_1000.json 0.6 0.61
//! perf record -g target/release/examples/profile_window scenarios/bench/liggghts_pile_1000.json 0.5 1
//! ```
//!
//! One rayon thread unless `THREADS` says otherwise. Prints the window's cost per step, apple-steps
//! per second, contacts and sleepers at its end; built with `--features stage-clocks`, also the
//! wall time per step of each stage (`layer::stage_clock`).

use applesim::record::series::NoSamples;
use applesim::scenario;
use applesim::sim::Simulation;
use std::path::Path;
use std::time::Instant;

/// One step of the window (the profilers' toggle).
#[inline(never)]
fn measured_step(sim: &mut Simulation) {
    sim.step(&mut NoSamples).expect("stable run");
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        eprintln!("usage: profile_window SCENARIO FROM_S TO_S");
        std::process::exit(2);
    }
    let path = Path::new(&args[1]);
    let from: f64 = args[2].parse().expect("FROM_S: a number of seconds");
    let to: f64 = args[3].parse().expect("TO_S: a number of seconds");
    let sc = scenario::load(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let base = path.parent().unwrap_or(Path::new("."));
    let threads: usize = std::env::var("THREADS").map_or(1, |s| s.parse().expect("THREADS"));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| {
        let mut sim = Simulation::new(&sc, base).expect("scenario builds");
        while sim.time_s() < from - 1e-9 && !sim.done() {
            sim.step(&mut NoSamples).expect("stable run");
        }
        applesim::layer::stage_clock::reset();
        let first = sim.steps_done();
        let clock = Instant::now();
        while sim.time_s() < to - 1e-9 && !sim.done() {
            measured_step(&mut sim);
        }
        let wall = clock.elapsed().as_secs_f64();
        let steps = (sim.steps_done() - first).max(1) as f64;
        let layer = &sim.world().layer;
        let n = layer.apple_count() as f64;
        let (contacts, apple_apple) = layer.contact_counts();
        println!(
            "{from}-{to} s: {} steps, {:.4} ms/step, {:.3e} apple-steps/s; at {to} s: {:.3} contacts/apple ({:.3} apple-apple), {} of {} apples asleep",
            steps,
            1e3 * wall / steps,
            n * steps / wall,
            contacts as f64 / n,
            apple_apple as f64 / n,
            layer.sleeping_count(),
            n
        );
        if applesim::layer::stage_clock::ENABLED {
            // The stage clocks (`--features stage-clocks`): us per step of the window.
            let per_step: Vec<String> = applesim::layer::stage_clock::totals_s()
                .iter()
                .map(|(s, t)| format!("{} {:.1}", s.name(), 1e6 * t / steps))
                .collect();
            println!("us per step: {}", per_step.join(", "));
        }
    });
}
