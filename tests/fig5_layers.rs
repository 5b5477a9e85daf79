//! Paper Fig. 5 (issue 3 acceptance): the bottom-layer apple's peak force on the plastic
//! container bottom grows with the number of layers above it, at both landing speeds.

mod common;
use common::*;

fn bottom_peak(file: &str) -> (f64, f64) {
    let sc = shipped(file);
    let (r, _) = run(&sc);
    // The middle apple of the bottom layer (3 x 3 grid: L-5) against the container floor.
    let e = r
        .events
        .iter()
        .filter(|e| &*e.a == "L-5" && &*e.b == "container/floor")
        .max_by(|a, b| a.peak_force_n.total_cmp(&b.peak_force_n))
        .expect("bottom apple hits the floor");
    (e.peak_force_n, e.duration_s.unwrap_or(f64::NAN))
}

#[test]
fn bottom_layer_force_grows_with_layers() {
    println!("| v0 (m/s) | layers | bottom apple peak force (N) | contact time (ms) |");
    for (v, speed) in [("025", 0.25), ("050", 0.5)] {
        let mut last = 0.0;
        for layers in 1..=3 {
            let (p, t) = bottom_peak(&format!("scenarios/paper/fig5_layers{layers}_v{v}.json"));
            println!("| {speed} | {layers} | {p:.2} | {:.2} |", t * 1e3);
            assert!(
                p > last,
                "v0 {speed}: {layers} layers give {p} N, not more than {last} N"
            );
            last = p;
        }
    }
}
