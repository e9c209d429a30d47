//! Sort keys for the sweep: floats as order-preserving integers, a radix sort for
//! one-shot frames, and a bounded insertion sort for coherent ones.
//!
//! Terdiman's trick: an IEEE float's bits, with the sign bit flipped for positive
//! numbers and all bits flipped for negative ones, compare as unsigned integers in the
//! order of the floats. Keys are `f32`-sized (`u32`) for both precisions: an `f64`
//! bound is rounded outward to `f32` first (a minimum down, a maximum up), so a sweep
//! on the keys finds a superset of the true candidates and the exact test in `T` removes
//! the extra ones. `f32` input is keyed exactly.
//!
//! A sort entry is `key << 32 | index`, so sorting entries orders by key and breaks ties
//! by index: the sorted order is a function of the current keys alone, not of the
//! previous frame's order, which keeps the incremental path deterministic.
//!
//! On the rayon pool, long inputs are first split by their leading key bits into
//! partitions (a parallel histogram and a stable parallel scatter), then each partition
//! is radix-sorted on its remaining bits as its own task. Every pass is stable, so the
//! result is the sequential sort's, bit for bit, on any number of threads.

/// The order-preserving integer image of an `f32` (for non-NaN input).
#[inline]
fn ordered_bits(x: f32) -> u32 {
    let bits = x.to_bits();
    // Positive: flip the sign bit; negative: flip every bit (no branch).
    bits ^ ((bits.cast_signed() >> 31).cast_unsigned() | 0x8000_0000)
}

/// The key of a lower bound: the integer image of the largest `f32 <= x`.
///
/// `x as f32` rounds to nearest (to `±inf` beyond the `f32` range); when that went up,
/// the next `f32` down has the next lower image, since consecutive floats have
/// consecutive images (`-0.0` and `+0.0` included, which only makes the key one step
/// more conservative). No branch, no `next_down`.
#[inline]
pub(crate) fn key_down(x: f64) -> u32 {
    let f = x as f32;
    ordered_bits(f) - u32::from(f64::from(f) > x)
}

/// The key of an upper bound: the integer image of the smallest `f32 >= x` (see
/// [`key_down`]).
#[inline]
pub(crate) fn key_up(x: f64) -> u32 {
    let f = x as f32;
    ordered_bits(f) + u32::from(f64::from(f) < x)
}

/// The sort entry of index `id` with key `key`.
#[inline]
pub(crate) fn entry(key: u32, id: u32) -> u64 {
    u64::from(key) << 32 | u64::from(id)
}

/// The index of a sort entry.
#[inline]
pub(crate) fn entry_id(e: u64) -> u32 {
    e as u32
}

/// The key of a sort entry.
#[inline]
pub(crate) fn entry_key(e: u64) -> u32 {
    (e >> 32) as u32
}

const RADIX_BITS: u32 = 11;
const BUCKETS: usize = 1 << RADIX_BITS;

/// Stable LSD radix sort of `entries` by their key (the high 32 bits), in three passes
/// of 11 bits; a pass whose digits are all equal is skipped (Terdiman's check). If the
/// entries were in index order, the result is sorted by `(key, index)`. Short inputs
/// are sorted by comparison instead, with the same result.
pub(crate) fn radix_sort_by_key(
    entries: &mut Vec<u64>,
    scratch: &mut Vec<u64>,
    counts: &mut Vec<usize>,
) {
    // Below a few hundred entries the passes over 2048 buckets cost more than a
    // comparison sort of the whole entries, which gives the same (key, index) order
    // when the input is in index order.
    if entries.len() < 256 {
        entries.sort_unstable();
        return;
    }
    scratch.clear();
    scratch.resize(entries.len(), 0);
    counts.clear();
    counts.resize(BUCKETS, 0);
    let shifts = (0..3).map(|pass| pass * RADIX_BITS);
    if radix_passes(entries, scratch, counts, shifts) {
        core::mem::swap(entries, scratch);
    }
}

/// Stable LSD passes over `src` by the 11-bit key digits starting at the bits `shifts`
/// (a pass whose digits are all equal is skipped), each from one buffer into the other;
/// `true` if the sorted entries ended in `dst`. `counts` has [`BUCKETS`] entries.
fn radix_passes(
    src: &mut [u64],
    dst: &mut [u64],
    counts: &mut [usize],
    shifts: impl Iterator<Item = u32>,
) -> bool {
    let (mut src, mut dst) = (src, dst);
    let mut in_dst = false;
    for shift in shifts {
        let digit = |e: u64| ((e >> (32 + shift)) as usize) & (BUCKETS - 1);
        counts.fill(0);
        for &e in src.iter() {
            counts[digit(e)] += 1;
        }
        if counts.contains(&src.len()) {
            continue;
        }
        let mut sum = 0;
        for c in counts.iter_mut() {
            (*c, sum) = (sum, sum + *c);
        }
        for &e in src.iter() {
            let slot = &mut counts[digit(e)];
            dst[*slot] = e;
            *slot += 1;
        }
        core::mem::swap(&mut src, &mut dst);
        in_dst = !in_dst;
    }
    in_dst
}

/// Below this many entries the parallel sort stays on the calling thread.
#[cfg(feature = "parallel")]
const PARALLEL_MIN: usize = 1 << 15;

/// The parallel sort's partitions: the top `PARTITION_BITS` of the used key bits.
#[cfg(feature = "parallel")]
const PARTITION_BITS: u32 = 6;
#[cfg(feature = "parallel")]
const PARTITIONS: usize = 1 << PARTITION_BITS;

/// [`radix_sort_by_key`], on the rayon pool when `parallel` and the input is long; the
/// result is the same.
#[cfg_attr(not(feature = "parallel"), allow(unused_variables))]
pub(crate) fn sort_by_key(
    entries: &mut Vec<u64>,
    scratch: &mut Vec<u64>,
    counts: &mut Vec<usize>,
    parallel: bool,
) {
    #[cfg(feature = "parallel")]
    if parallel && entries.len() >= PARALLEL_MIN && rayon::current_num_threads() > 1 {
        par_radix_sort_by_key(entries, scratch);
        return;
    }
    radix_sort_by_key(entries, scratch, counts);
}

/// The parallel sort (see the [module documentation](self)): an MSD split into
/// [`PARTITIONS`] by the leading used key bits, then an LSD sort of each partition.
#[cfg(feature = "parallel")]
fn par_radix_sort_by_key(entries: &mut [u64], scratch: &mut Vec<u64>) {
    use rayon::prelude::*;
    let n = entries.len();
    let top = entries.par_iter().map(|&e| entry_key(e)).max().unwrap_or(0);
    // The keys below `shift` are sorted within a partition; the bits above pick it.
    let used = u32::BITS - top.leading_zeros();
    let shift = used.saturating_sub(PARTITION_BITS);
    let part = |e: u64| (entry_key(e) >> shift) as usize;

    // Per-chunk histograms, then each (partition, chunk) gets its slot in `scratch`:
    // partitions in order, and within one the chunks in order, so the scatter is stable.
    let len = n.div_ceil(crate::parallel_chunks());
    let histograms: Vec<[usize; PARTITIONS]> = entries
        .par_chunks(len)
        .map(|chunk| {
            let mut h = [0; PARTITIONS];
            for &e in chunk {
                h[part(e)] += 1;
            }
            h
        })
        .collect();
    scratch.clear();
    scratch.resize(n, 0);
    let mut slots: Vec<Vec<&mut [u64]>> = histograms
        .iter()
        .map(|_| Vec::with_capacity(PARTITIONS))
        .collect();
    let mut partition_len = [0; PARTITIONS];
    let mut rest = scratch.as_mut_slice();
    for (p, size) in partition_len.iter_mut().enumerate() {
        for (h, chunk_slots) in histograms.iter().zip(&mut slots) {
            let (slot, tail) = core::mem::take(&mut rest).split_at_mut(h[p]);
            chunk_slots.push(slot);
            rest = tail;
            *size += h[p];
        }
    }
    entries
        .par_chunks(len)
        .zip(slots.into_par_iter())
        .for_each(|(chunk, mut out)| {
            let mut next = [0; PARTITIONS];
            for &e in chunk {
                let p = part(e);
                out[p][next[p]] = e;
                next[p] += 1;
            }
        });

    // Each partition sorted on its low `shift` key bits, the result back in `entries`.
    let mut pieces = Vec::with_capacity(PARTITIONS);
    let (mut from, mut to) = (scratch.as_mut_slice(), entries);
    for size in partition_len {
        let (a, rest_from) = core::mem::take(&mut from).split_at_mut(size);
        let (b, rest_to) = core::mem::take(&mut to).split_at_mut(size);
        pieces.push((a, b));
        (from, to) = (rest_from, rest_to);
    }
    pieces
        .into_par_iter()
        .with_max_len(1)
        .for_each(|(part, out)| sort_low_bits(part, out, shift));
}

/// Stable LSD sort of `part` by the key bits below `bits` (11 at a time, a pass whose
/// digits are all equal skipped); the sorted entries end in `out`, `part` is scratch.
#[cfg(feature = "parallel")]
fn sort_low_bits(part: &mut [u64], out: &mut [u64], bits: u32) {
    if part.len() < 256 {
        // Fewer entries than buckets: a stable comparison sort by key is cheaper.
        part.sort_by_key(|&e| entry_key(e));
        out.copy_from_slice(part);
        return;
    }
    let mut counts = [0usize; BUCKETS];
    let shifts = (0..bits).step_by(RADIX_BITS as usize);
    if !radix_passes(part, out, &mut counts, shifts) {
        // The last pass wrote `part` (or none ran).
        out.copy_from_slice(part);
    }
}

/// Insertion sort that gives up after `budget` element moves: `true` if `entries` is
/// now sorted, `false` if the frame was not coherent enough (the slice is then a
/// permutation of its input, partly sorted).
pub(crate) fn insertion_sort_bounded(entries: &mut [u64], budget: usize) -> bool {
    let mut moves = 0usize;
    for i in 1..entries.len() {
        let x = entries[i];
        let mut j = i;
        while j > 0 && entries[j - 1] > x {
            entries[j] = entries[j - 1];
            j -= 1;
        }
        entries[j] = x;
        moves += i - j;
        if moves > budget {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::SplitMix64;

    #[test]
    fn keys_preserve_order_and_round_outward() {
        let xs = [
            -1e300,
            -3.5,
            -1e-30,
            -0.0,
            0.0,
            1e-30,
            0.1,
            1.0,
            1e6 + 0.3,
            1e300,
        ];
        for w in xs.windows(2) {
            assert!(key_down(w[0]) <= key_down(w[1]));
            assert!(key_up(w[0]) <= key_up(w[1]));
        }
        for &x in &xs {
            assert!(key_down(x) <= key_up(x));
        }
        // 0.1 is not an f32: its keys straddle it.
        assert!(key_down(0.1) < key_up(0.1));
        assert_eq!(key_down(0.5), key_up(0.5));
        // Beyond the f32 range the upper key is +inf's and still below the sentinel.
        assert!(key_up(1e300) < u32::MAX);
    }

    #[test]
    fn keys_are_the_images_of_the_nearest_f32_bounds() {
        // The reference: round, then step with next_down / next_up when the rounding
        // went the wrong way.
        let reference = |x: f64| {
            let f = x as f32;
            let down = if f64::from(f) > x { f.next_down() } else { f };
            let up = if f64::from(f) < x { f.next_up() } else { f };
            (ordered_bits(down), ordered_bits(up))
        };
        let mut xs = vec![
            0.0,
            -0.0,
            1e-320,
            -1e-320,
            f64::from(f32::MIN_POSITIVE) * 0.5,
            f64::from(f32::MAX),
            f64::from(f32::MAX) * 1.0000001,
            -f64::from(f32::MAX) * 1.0000001,
            1e300,
            -1e300,
            f64::MAX,
            f64::MIN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut rng = SplitMix64::new(99);
        for _ in 0..20_000 {
            let state = rng.next_u64();
            let x = f64::from_bits(state);
            if !x.is_nan() {
                xs.push(x);
            }
            xs.push(((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2e3);
        }
        for x in xs {
            let (down, up) = reference(x);
            // -0.0 and +0.0 are the same number: the branch-free key may pick either.
            let zero = |k: u32| k == ordered_bits(0.0) || k == ordered_bits(-0.0);
            let same = |a: u32, b: u32| a == b || (zero(a) && zero(b));
            assert!(same(key_down(x), down), "key_down({x:e})");
            assert!(same(key_up(x), up), "key_up({x:e})");
        }
    }

    /// The parallel sort equals the sequential radix sort (a stable sort by key) on any
    /// pool, for keys spanning a few values, a narrow range (one partition per key
    /// group), a grid-like range and the whole of `u32`, with the indices in order and
    /// shuffled (stability, not the index tie-break, is what both sorts share).
    #[cfg(feature = "parallel")]
    #[test]
    fn the_parallel_sort_is_the_sequential_one_on_any_pool() {
        let mut rng = SplitMix64::new(777);
        let mut next = || (rng.next_u64() >> 32) as u32;
        for (n, range) in [
            (PARALLEL_MIN, 1u32),
            (PARALLEL_MIN + 5, 40),
            (70_000, 5_000),
            (120_000, 400_000),
            (50_000, u32::MAX),
        ] {
            let keys: Vec<u32> = (0..n).map(|_| next() % range.max(1)).collect();
            let in_order: Vec<u64> = (0..n as u32).map(|i| entry(keys[i as usize], i)).collect();
            let shuffled: Vec<u64> = (0..n as u32)
                .map(|i| entry(keys[i as usize], next()))
                .collect();
            for input in [in_order, shuffled] {
                let mut expected = input.clone();
                expected.sort_by_key(|&e| entry_key(e));
                let (mut scratch, mut counts) = (Vec::new(), Vec::new());
                let mut sequential = input.clone();
                sort_by_key(&mut sequential, &mut scratch, &mut counts, false);
                assert_eq!(sequential, expected, "sequential, n = {n}, range {range}");
                for threads in [1, 2, 3] {
                    let pool = rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()
                        .expect("a pool");
                    let mut sorted = input.clone();
                    pool.install(|| sort_by_key(&mut sorted, &mut scratch, &mut counts, true));
                    assert_eq!(
                        sorted, expected,
                        "{threads} threads, n = {n}, range {range}"
                    );
                }
            }
        }
    }

    #[test]
    fn radix_and_insertion_sorts_agree_with_the_standard_sort() {
        let mut rng = SplitMix64::new(12345);
        let mut next = || (rng.next_u64() >> 32) as u32;
        let mut entries: Vec<u64> = (0..5000).map(|i| entry(next() % 700, i)).collect();
        let mut expected = entries.clone();
        expected.sort_unstable();
        let (mut scratch, mut counts) = (Vec::new(), Vec::new());
        let mut radix = entries.clone();
        radix_sort_by_key(&mut radix, &mut scratch, &mut counts);
        assert_eq!(radix, expected);
        assert!(!insertion_sort_bounded(&mut entries.clone(), 100));
        assert!(insertion_sort_bounded(&mut entries, usize::MAX));
        assert_eq!(entries, expected);
    }
}
