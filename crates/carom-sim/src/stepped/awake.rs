//! Keeping the rayon pool's other threads awake through a sequential section, so that
//! the parallel region after it starts on all threads at once.
//!
//! A rayon worker that finds no work spins for a few dozen rounds and then sleeps; the
//! next parallel region has to wake it, and on this project's 2-core VM the wake-up
//! costs tens of microseconds, during which the calling thread does the region's work
//! alone. The step's in-step event loop (0.55 of the 1.93 ms of a 2-thread step at 1e5
//! balls, timed before the prefetch) is long enough for the other thread to fall asleep
//! every step. [`hold_pool`] runs such
//! a section on the calling thread while one task per other thread waits for it to end,
//! yielding its core to the OS scheduler on every round (so a busy machine loses nothing
//! to the wait) but never sleeping. On the 1e5-ball gas of `docs/stepped.md` this took
//! the 2-thread integration from 0.38 to 0.355 ms per step (see "Where the second
//! thread's time goes" there).
//!
//! The section must not use the pool itself: its tasks would queue behind the waiting
//! ones. Nothing computed depends on it, so results stay bit-identical.

use std::sync::atomic::{AtomicBool, Ordering};

/// Runs `section` on this thread; when `parallel`, the pool's other threads wait for
/// its end awake (see the [module documentation](self)). `section` must not start
/// parallel work.
pub(crate) fn hold_pool<R>(parallel: bool, section: impl FnOnce() -> R) -> R {
    if !parallel || rayon::current_num_threads() < 2 {
        return section();
    }
    let done = AtomicBool::new(false);
    let here = rayon::current_thread_index();
    rayon::in_place_scope(|scope| {
        for _ in 1..rayon::current_num_threads() {
            scope.spawn(|_| {
                // A waiting task this thread picks up itself (at the scope's end) has
                // nothing to wait for.
                if rayon::current_thread_index() == here {
                    return;
                }
                while !done.load(Ordering::Acquire) {
                    std::thread::yield_now();
                }
            });
        }
        let result = section();
        done.store(true, Ordering::Release);
        result
    })
}
