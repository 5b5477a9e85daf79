//! Two measures of the traffic between two cores, for judging a two-thread timing
//! (docs/performance.md, "The VM's slow state, found" and "Eleventh session"):
//!
//! 1. the round trip of one cache line between two threads: on the 2-core VM it printed 43-128
//!    ns, and 383-614 ns in the spells in which a two-thread run of applesim is about as slow as
//!    one thread;
//! 2. a gather, the pattern of a parallel force pass: one thread writes one number on each of
//!    1000 cache lines (an apple's state), the other then reads 3000 of them at random (the two
//!    apples of each contact); against the same gather of lines the reading thread wrote itself.
//!    On the VM, in the slow spells the first took 22.7-38.8 us a pass (median 34.5) against
//!    8.7-11.0 us for the second; in the fast state 6.4-32.9 us (median 15.1) against 9.0 us.
//!
//! ```sh
//! cargo run --release --example core_latency
//! ```
//!
//! Both threads spin, so the scheduler keeps them on two cores. Prints the mean round trip in ns
//! and each gather's mean time per pass in us.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// The counter, on cache lines of its own.
#[repr(align(128))]
struct Line(AtomicU64);

/// One apple's line of state.
#[repr(align(64))]
#[derive(Default)]
struct Apple(AtomicU64);

const APPLES: usize = 1000;
const GATHERS: usize = 3000;
const PASSES: u64 = 2000;

fn round_trip() -> f64 {
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
    ns
}

/// Mean time per pass (us): the main thread writes every apple's line (of `written`, shared
/// with the reader, or of its own set), then the reader gathers `GATHERS` random lines of
/// `written` (when `shared`) or of a set it wrote itself.
fn gather(shared: bool) -> f64 {
    let mut seed = 12_345u64;
    let picks: Arc<Vec<usize>> = Arc::new(
        (0..GATHERS)
            .map(|_| {
                seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                (seed >> 33) as usize % APPLES
            })
            .collect(),
    );
    let written: Arc<Vec<Apple>> = Arc::new((0..APPLES).map(|_| Apple::default()).collect());
    let own_main: Vec<Apple> = (0..APPLES).map(|_| Apple::default()).collect();
    let turn = Arc::new(Line(AtomicU64::new(0)));
    let stop = Arc::new(AtomicBool::new(false));
    let reader = {
        let (written, picks, turn, stop) = (
            Arc::clone(&written),
            Arc::clone(&picks),
            Arc::clone(&turn),
            Arc::clone(&stop),
        );
        std::thread::spawn(move || {
            let own: Vec<Apple> = (0..APPLES).map(|_| Apple::default()).collect();
            let mut sum = 0u64;
            for pass in 0..PASSES {
                while turn.0.load(Ordering::Acquire) != 2 * pass + 1 {
                    if stop.load(Ordering::Relaxed) {
                        return sum;
                    }
                    std::hint::spin_loop();
                }
                let lines = if shared { &written[..] } else { &own[..] };
                if !shared {
                    for a in lines {
                        a.0.fetch_add(1, Ordering::Relaxed);
                    }
                }
                for &k in picks.iter() {
                    sum = sum.wrapping_add(lines[k].0.load(Ordering::Relaxed));
                }
                turn.0.store(2 * pass + 2, Ordering::Release);
            }
            sum
        })
    };
    let start = Instant::now();
    for pass in 0..PASSES {
        let lines = if shared { &written[..] } else { &own_main[..] };
        for a in lines {
            a.0.fetch_add(1, Ordering::Relaxed);
        }
        turn.0.store(2 * pass + 1, Ordering::Release);
        while turn.0.load(Ordering::Acquire) != 2 * pass + 2 {
            std::hint::spin_loop();
        }
    }
    let us = start.elapsed().as_secs_f64() * 1e6 / PASSES as f64;
    stop.store(true, Ordering::Relaxed);
    std::hint::black_box(reader.join().expect("the reader ends"));
    us
}

fn main() {
    let ns = round_trip();
    println!("round trip between two threads: {ns:.0} ns");
    let (shared, own) = (gather(true), gather(false));
    println!(
        "gather of {GATHERS} of {APPLES} lines: written by the other thread {shared:.1} us a pass, by the reader itself {own:.1} us"
    );
}
