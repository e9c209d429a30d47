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
    for pass in 0..3u32 {
        let shift = 32 + pass * RADIX_BITS;
        let digit = |e: u64| ((e >> shift) as usize) & (BUCKETS - 1);
        counts.fill(0);
        for &e in entries.iter() {
            counts[digit(e)] += 1;
        }
        if counts.contains(&entries.len()) {
            continue;
        }
        let mut sum = 0;
        for c in counts.iter_mut() {
            let here = *c;
            *c = sum;
            sum += here;
        }
        for &e in entries.iter() {
            let slot = &mut counts[digit(e)];
            scratch[*slot] = e;
            *slot += 1;
        }
        core::mem::swap(entries, scratch);
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
        let mut state = 99u64;
        for _ in 0..20_000 {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
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

    #[test]
    fn radix_and_insertion_sorts_agree_with_the_standard_sort() {
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as u32
        };
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
