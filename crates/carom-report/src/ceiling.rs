//! The machine's own 2-thread ceilings and one-core speeds: the 1 → 2 thread speedups
//! of three loops that share no data between their threads, measured in the report's
//! run beside the parts of section 4.
//!
//! A parallel part of an engine cannot scale better than the machine lets the kind of
//! work it does scale. On this project's 2-core VM, in twelve runs of [`measure`] on
//! 2026-11-29 (in reports, the stepped bench's table and alone), the compute loop scaled
//! by 1.84–2.00× and the streaming loop by 1.44–1.73×; the random reads, the noisiest,
//! by 1.80–2.01× in nine of them and 0.78–1.39× in three run right after a build, while
//! the machine's load average was still above 1. Each loop here runs as two equal tasks,
//! one after the other on a pool of one thread and at once on a pool of two, in
//! alternating rounds; the ceiling is the median of the rounds' time ratios:
//!
//! * **compute**: a chain of square roots in registers, no memory traffic;
//! * **streaming memory**: each task reads and rewrites its own buffer, larger than the
//!   last-level cache, front to back;
//! * **random reads**: each task sums entries of its own table, larger than the cache,
//!   at indices from a linear congruential sequence that does not depend on what it
//!   reads (so the core can keep several misses in flight, as the engines' read-ahead
//!   does).
//!
//! The same runs give what one core does of each loop (square roots, bytes streamed and
//! random reads per second): a machine's speed on the day, to compare before comparing
//! two reports' timings (this VM's changes by a factor of up to three).

use std::hint::black_box;

use crate::error::ReportError;
use crate::model::Ceiling;
use crate::throughput::pool;
use crate::timing::{median, timed};

/// How much work each ceiling's loops do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CeilingSizes {
    /// Square roots per compute task.
    pub compute_steps: usize,
    /// `f64` entries of each task's streaming buffer and random-read table.
    pub buffer_len: usize,
    /// Reads per random-read task.
    pub random_reads: usize,
    /// Rounds of 1 and 2 threads; the median ratio is kept.
    pub rounds: usize,
}

impl CeilingSizes {
    /// 2.5–3.2 s on this project's VM (2026-11-29): buffers of 32 MiB (4 times its
    /// last-level cache).
    pub fn report() -> Self {
        Self {
            compute_steps: 4_000_000,
            buffer_len: 4 << 20,
            random_reads: 4_000_000,
            rounds: 5,
        }
    }

    /// Milliseconds, for tests of the machinery (figures meaningless).
    pub fn tiny() -> Self {
        Self {
            compute_steps: 10_000,
            buffer_len: 10_000,
            random_reads: 10_000,
            rounds: 1,
        }
    }
}

impl Ceiling {
    /// The three speedups as the report and the stepped bench print them: `compute
    /// 1.97×, streaming memory 1.72×, random reads 1.81×`.
    pub fn speedups(&self) -> String {
        format!(
            "compute {:.2}×, streaming memory {:.2}×, random reads {:.2}×",
            self.compute, self.streaming_memory, self.random_reads
        )
    }
}

/// Measures the three ceilings (see the [module documentation](self)), and what one
/// core does of each loop.
///
/// # Errors
/// A thread pool that cannot be built.
pub fn measure(sizes: &CeilingSizes) -> Result<Ceiling, ReportError> {
    let one = pool(1)?;
    let two = pool(2)?;
    let rounds = sizes.rounds;
    let mut buffers = [
        vec![1.0_f64; sizes.buffer_len],
        vec![1.0_f64; sizes.buffer_len],
    ];
    let steps = sizes.compute_steps;
    let (compute_1t, compute) = alternate(&one, &two, rounds, |p| {
        black_box(
            p.install(|| rayon::join(|| square_roots(0.0, steps), || square_roots(1.0, steps))),
        );
    });
    let (stream_1t, streaming_memory) = alternate(&one, &two, rounds, |p| {
        let [a, b] = &mut buffers;
        black_box(p.install(|| rayon::join(|| stream(a), || stream(b))));
    });
    let reads = sizes.random_reads;
    let (random_1t, random_reads) = alternate(&one, &two, rounds, |p| {
        let [a, b] = &buffers;
        black_box(p.install(|| rayon::join(|| random_sum(a, reads), || random_sum(b, reads))));
    });
    // Both tasks on one thread: twice each loop's work. A streaming pass reads and writes
    // each entry (16 bytes moved per `f64`), twice per task.
    let streamed = (2 * STREAM_PASSES * 16 * sizes.buffer_len) as f64;
    Ok(Ceiling {
        compute,
        streaming_memory,
        random_reads,
        one_core_square_roots_per_s: (2 * steps) as f64 / compute_1t,
        one_core_stream_bytes_per_s: streamed / stream_1t,
        one_core_random_reads_per_s: (2 * reads) as f64 / random_1t,
    })
}

/// Runs `run` on `one` and on `two` in turn for `rounds` rounds: the median seconds on
/// `one`, and the median of the rounds' ratios (seconds on `one` over seconds on `two`).
fn alternate(
    one: &rayon::ThreadPool,
    two: &rayon::ThreadPool,
    rounds: usize,
    mut run: impl FnMut(&rayon::ThreadPool),
) -> (f64, f64) {
    let (mut seconds, mut ratios) = (Vec::new(), Vec::new());
    for _ in 0..rounds.max(1) {
        let t1 = timed(|| run(one)).1.as_secs_f64();
        seconds.push(t1);
        ratios.push(t1 / timed(|| run(two)).1.as_secs_f64());
    }
    (median(&mut seconds), median(&mut ratios))
}

/// `steps` dependent square roots from `seed`.
fn square_roots(seed: f64, steps: usize) -> f64 {
    let mut x = seed + 2.0;
    let mut sum = 0.0;
    for _ in 0..steps {
        x = (x * 1.000_001 + 0.5).sqrt();
        sum += x;
    }
    sum
}

/// Passes of [`stream`] over its buffer.
const STREAM_PASSES: usize = 2;

/// Reads and rewrites `buffer` front to back, [`STREAM_PASSES`] times.
fn stream(buffer: &mut [f64]) -> f64 {
    let mut sum = 0.0;
    for _ in 0..STREAM_PASSES {
        for v in buffer.iter_mut() {
            *v = *v * 0.999_999 + 1e-6;
            sum += *v;
        }
    }
    sum
}

/// The sum of `reads` entries of `table` at indices of a linear congruential sequence
/// (Knuth's MMIX constants; the high bits index the table).
fn random_sum(table: &[f64], reads: usize) -> f64 {
    let len = table.len() as u64;
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut sum = 0.0;
    for _ in 0..reads {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        sum += table[((state >> 32) % len) as usize];
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_loops_compute_what_they_say() {
        // A square root chain from x: x ← sqrt(1.000001 x + 0.5), summed.
        let mut x = 2.0_f64;
        let mut sum = 0.0;
        for _ in 0..3 {
            x = (x * 1.000_001 + 0.5).sqrt();
            sum += x;
        }
        assert_eq!(square_roots(0.0, 3), sum);
        // Streaming twice over ones: each pass maps v to 0.999999 v + 1e-6, which keeps 1.
        let mut buffer = vec![1.0; 10];
        let s = stream(&mut buffer);
        assert!((s - 20.0).abs() < 1e-9, "{s}");
        // Random reads of a table of ones sum to the number of reads.
        assert_eq!(random_sum(&[1.0; 1000], 777), 777.0);
    }

    #[test]
    fn tiny_ceilings_are_positive_ratios() {
        let c = measure(&CeilingSizes::tiny()).expect("pools of 1 and 2 threads");
        for (name, s) in [
            ("compute", c.compute),
            ("streaming", c.streaming_memory),
            ("random", c.random_reads),
            ("square roots", c.one_core_square_roots_per_s),
            ("stream bytes", c.one_core_stream_bytes_per_s),
            ("random reads", c.one_core_random_reads_per_s),
        ] {
            assert!(s.is_finite() && s > 0.0, "{name}: {s}");
        }
    }
}
