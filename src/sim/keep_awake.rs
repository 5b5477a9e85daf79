//! Keeps the pool's other threads polling for work while a run steps (issue 30 item 2).
//!
//! Why: a step of a large scene opens four or five short parallel regions (reading the bodies,
//! the contact law, the hand-off of forces, rapier's body sets, the neighbour scan) between
//! serial parts (detection, the load sums). An idle rayon worker goes to sleep within
//! microseconds, and waking it for the next region took 24-37 us on the 2-core VM
//! (docs/performance.md, "rapier's step split over body sets"): in a step of 0.28 ms that delay is
//! a large part of what a region can gain. A poller is a job that runs on another worker for as
//! long as the run steps, taking every job the stepping thread puts up for grabs
//! (`rayon::yield_now`), so the worker never sleeps between regions.
//!
//! It changes no result (only which thread runs a job; every parallel part of a step gives the
//! same bits for any thread count). It costs a busy core while the run steps, so the driver runs
//! pollers only after steps with at least [`MIN_CONTACTS`] contacts in a split scene (more than
//! one thread and at least [`crate::world::APPLE_SETS_MIN_APPLES`] apples), and a poller that
//! finds nothing to do for [`MAX_IDLE`] ends (the driver paused, or the run ended without dropping
//! its driver); the next step starts another. On the 2-core VM, while the pollers run, the
//! stepping thread's serial stages are sometimes slower too, by up to 1.6x for seconds or minutes
//! at a time (the VM's "slow state", docs/performance.md): in those spells a cache line's round
//! trip between the two cores takes about 400 ns instead of about 100 ns (the host's placement of
//! the VM's cores; `examples/core_latency.rs`), and a single two-thread timing there is not to
//! be trusted.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The fewest contacts in a step (`StepStats::contacts`) for the next to keep the pool's threads
/// polling: about where a step's parallel regions begin (256 contacts, 256 awake apples). Both
/// measured scenes are faster with pollers: the eq. 12 pile's impact phase (about 2 500 to 3 000
/// contacts) and the 1000-apple line's late steps (about 1 300 evaluated: 0.33 against 0.29 ms a
/// step on two threads, docs/performance.md). It was 2 000 while the line seemed slower with
/// them (21 s against 15-16 s), a measurement the VM's slow state explains. A tuned figure, not
/// a derived one.
pub const MIN_CONTACTS: usize = 500;

/// How long a poller spins with nothing to do before it ends.
pub const MAX_IDLE: Duration = Duration::from_millis(20);

/// The pollers of one run: stopped when dropped.
#[derive(Debug, Default)]
pub struct KeepAwake {
    stop: Arc<AtomicBool>,
    /// Pollers running now.
    running: Arc<AtomicUsize>,
}

impl KeepAwake {
    /// Makes sure every other thread of the current rayon pool polls for work, starting the
    /// pollers that are missing. Call it at every step from the stepping thread.
    pub fn ensure(&self) {
        let threads = rayon::current_num_threads();
        if threads < 2 {
            return;
        }
        let me = rayon::current_thread_index();
        let wanted = threads - usize::from(me.is_some());
        while self.running.load(Ordering::Acquire) < wanted {
            self.running.fetch_add(1, Ordering::AcqRel);
            let stop = Arc::clone(&self.stop);
            let running = Arc::clone(&self.running);
            rayon::spawn(move || {
                // The stepping thread itself may take the job while it waits for a region's
                // other half: it must not poll (it would never return to its step).
                if rayon::current_thread_index() != me {
                    poll(&stop);
                }
                running.fetch_sub(1, Ordering::AcqRel);
            });
        }
    }
}

impl KeepAwake {
    /// Stops the pollers (the step has too little parallel work to pay for a spinning core);
    /// [`Self::ensure`] starts new ones.
    pub fn release(&mut self) {
        if self.running.load(Ordering::Acquire) > 0 {
            self.stop.store(true, Ordering::Release);
            self.stop = Arc::new(AtomicBool::new(false));
        }
    }
}

impl Drop for KeepAwake {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
    }
}

/// Runs the pool's pending jobs until `stop`, or until nothing came for [`MAX_IDLE`].
fn poll(stop: &AtomicBool) {
    let mut idle_since: Option<Instant> = None;
    let mut spins = 0u32;
    while !stop.load(Ordering::Acquire) {
        if rayon::yield_now() == Some(rayon::Yield::Executed) {
            idle_since = None;
            continue;
        }
        std::hint::spin_loop();
        spins = spins.wrapping_add(1);
        if spins % 256 == 0 {
            let since = *idle_since.get_or_insert_with(Instant::now);
            if since.elapsed() > MAX_IDLE {
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// In a pool of two threads, a poller starts on the other worker, runs the jobs the
    /// stepping thread puts up (a join's other half), and ends when its owner is dropped.
    #[test]
    fn a_poller_runs_the_other_half_and_ends_with_its_owner() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let running = pool.install(|| {
            let k = KeepAwake::default();
            k.ensure();
            let t0 = Instant::now();
            while k.running.load(Ordering::Acquire) != 1 && t0.elapsed() < Duration::from_secs(5) {
                std::hint::spin_loop();
            }
            let me = rayon::current_thread_index();
            let (a, b) = rayon::join(
                || {
                    // The stepping thread is busy long enough for the poller to take `b`.
                    std::thread::sleep(Duration::from_millis(20));
                    rayon::current_thread_index()
                },
                rayon::current_thread_index,
            );
            assert_eq!(a, me);
            assert!(
                b.is_some() && b != me,
                "the other half ran on the other thread"
            );
            let running = Arc::clone(&k.running);
            drop(k);
            running
        });
        let t0 = Instant::now();
        while running.load(Ordering::Acquire) != 0 && t0.elapsed() < Duration::from_secs(5) {
            std::thread::sleep(Duration::from_millis(1));
        }
        assert_eq!(running.load(Ordering::Acquire), 0, "the poller ended");
    }

    /// One thread: nothing to start.
    #[test]
    fn one_thread_starts_no_poller() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        pool.install(|| {
            let k = KeepAwake::default();
            k.ensure();
            assert_eq!(k.running.load(Ordering::Acquire), 0);
        });
    }
}
