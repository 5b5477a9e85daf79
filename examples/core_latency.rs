//! The round trip of one cache line between two threads, for judging a two-thread timing
//! (docs/performance.md, "The VM's slow state, found"): on the 2-core VM it printed 43-128 ns,
//! and 383-452 ns in the spells in which a two-thread run of applesim is about as slow as one
//! thread.
//!
//! ```sh
//! cargo run --release --example core_latency
//! ```
//!
//! Two threads hand a counter back and forth 200 000 times; both spin, so the scheduler keeps
//! them on two cores. Prints the mean round trip in ns.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// The counter, on cache lines of its own.
#[repr(align(128))]
struct Line(AtomicU64);

fn main() {
    const ROUNDS: u64 = 200_000;
    let line = Arc::new(Line(AtomicU64::new(0)));
    let other = Arc::clone(&line);
    let echo = std::thread::spawn(move || {
        for i in 0..ROUNDS {
            while other.0.load(Ordering::Acquire) != 2 * i + 1 {
                std::hint::spin_loop();
            }
            other.0.store(2 * i + 2, Ordering::Release);
        }
    });
    let start = Instant::now();
    for i in 0..ROUNDS {
        line.0.store(2 * i + 1, Ordering::Release);
        while line.0.load(Ordering::Acquire) != 2 * i + 2 {
            std::hint::spin_loop();
        }
    }
    let ns = start.elapsed().as_secs_f64() * 1e9 / ROUNDS as f64;
    echo.join().expect("the echo thread ends");
    println!("round trip between two threads: {ns:.0} ns");
}
