//! Short lists of ball indices, one cache-aligned row each: the neighbour lists' storage
//! (a ball's partners) and that of their grid (a cell's balls).
//!
//! A prediction reads one ball's whole list, and a list rebuild edits the lists of a
//! dozen partners and reads those of `3^D` cells, each at a random place in memory.
//! Stored as one `Vec` per list, every list costs two dependent cache misses (the
//! vector's header, then its data). Here a list's length and its first `W` ids share one
//! row aligned to the cache line: one miss per list (with `W = 31`, 128 bytes: the length
//! and the first 15 ids share the first line, and the hardware's adjacent-line prefetch
//! brings the second). Lists longer than a row (a large ball among small ones, a crowded
//! cell) continue in a vector of their own, allocated only for those.
//!
//! Measured on the 2D gas of 1e5 balls at area fraction 0.3 (`event_throughput`, `perf
//! annotate`): with a `Vec` per neighbour list, the rebuild's search of its old partners'
//! lists and their headers were about 60 % of the rebuild's samples, and the two reads of
//! a list 27 % of the prediction's. The rows for neighbour lists gained 5–7 %; for the
//! grid's cells (linked lists through the balls before) they measured level and are kept
//! because they are simpler (see `docs/event-engine.md`).

use crate::pages::Array;
use crate::prefetch::prefetch;

/// Rows aligned to the cache line (64 bytes): a row is read with one miss.
#[derive(Clone, Copy, Debug)]
#[repr(align(64))]
pub(crate) struct Line;

/// Rows aligned to 16 bytes, for rows of 3 ids read several at a time from one line
/// (the cells of a grid row, next to each other in memory).
#[derive(Clone, Copy, Debug)]
#[repr(align(16))]
pub(crate) struct Quarter;

/// A list's length and its first `W` ids, aligned as `A`.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
struct Row<const W: usize, A> {
    align: [A; 0],
    len: u32,
    ids: [u32; W],
}

/// `n` lists of ids, the first `W` of each in its row, rows aligned as `A` (see the
/// module documentation).
#[derive(Clone, Debug)]
pub(crate) struct IdRows<const W: usize, A = Line> {
    rows: Array<Row<W, A>>,
    /// The ids beyond the row, per list (empty, never allocated, for most).
    spill: Vec<Vec<u32>>,
}

impl<const W: usize, A: Copy> IdRows<W, A> {
    /// `n` empty lists.
    pub(crate) fn new(n: usize) -> Self {
        Self {
            rows: Array::filled(n, |_| Row {
                align: [],
                len: 0,
                ids: [0; W],
            }),
            spill: vec![Vec::new(); n],
        }
    }

    /// The number of lists.
    pub(crate) fn count(&self) -> usize {
        self.rows.len()
    }

    /// The length of list `i`.
    #[inline]
    pub(crate) fn len(&self, i: usize) -> usize {
        self.rows[i].len as usize
    }

    /// The ids in list `i`, in no particular order.
    #[inline]
    pub(crate) fn of(&self, i: usize) -> impl Iterator<Item = u32> + '_ {
        let row = &self.rows[i];
        let in_row = (row.len as usize).min(W);
        let spilled: &[u32] = if row.len as usize > W {
            &self.spill[i]
        } else {
            &[]
        };
        row.ids[..in_row].iter().chain(spilled).copied()
    }

    /// Appends the ids in list `i` to `out`, in the order of [`Self::of`]. The whole row
    /// is copied and the copy cut to the list's length, so that a list's length does not
    /// decide a branch (a loop over a short list's ids ends at an unpredictable place).
    #[inline]
    pub(crate) fn append_to(&self, i: usize, out: &mut Vec<u32>) {
        let row = &self.rows[i];
        let start = out.len();
        let len = row.len as usize;
        out.extend_from_slice(&row.ids);
        out.truncate(start + len.min(W));
        if len > W {
            out.extend_from_slice(&self.spill[i]);
        }
    }

    /// The `k`-th id of list `i` (`k` below its length).
    #[inline]
    pub(crate) fn get(&self, i: usize, k: usize) -> u32 {
        if k < W {
            self.rows[i].ids[k]
        } else {
            self.spill[i][k - W]
        }
    }

    /// Adds `j` to list `i`.
    #[inline]
    pub(crate) fn push(&mut self, i: usize, j: u32) {
        let row = &mut self.rows[i];
        let len = row.len as usize;
        if len < W {
            row.ids[len] = j;
        } else {
            self.spill[i].push(j);
        }
        row.len += 1;
    }

    /// Removes `j` from list `i`, if it is there (the last id takes its place).
    pub(crate) fn remove(&mut self, i: usize, j: u32) {
        let row = &mut self.rows[i];
        let len = row.len as usize;
        let in_row = len.min(W);
        if let Some(k) = row.ids[..in_row].iter().position(|&x| x == j) {
            let last = if len > W {
                self.spill[i]
                    .pop()
                    .expect("a long list has spilled partners")
            } else {
                row.ids[len - 1]
            };
            row.ids[k] = last;
            row.len -= 1;
        } else if len > W
            && let Some(k) = self.spill[i].iter().position(|&x| x == j)
        {
            self.spill[i].swap_remove(k);
            row.len -= 1;
        }
    }

    /// For symmetric lists (`j` on list `i` exactly when `i` is on list `j`): removes `i`
    /// from the lists of all the ids on its list, and empties list `i`.
    pub(crate) fn unlink(&mut self, i: usize) {
        let len = self.len(i);
        // Each partner's row is a miss of its own: asked for all at once, they arrive
        // together instead of one after the other.
        for k in 0..len {
            self.prefetch(self.get(i, k) as usize);
        }
        for k in 0..len {
            let j = self.get(i, k);
            debug_assert_ne!(j as usize, i, "a ball is not its own partner");
            self.remove(j as usize, i as u32);
        }
        self.clear(i);
    }

    /// Asks for list `i`'s row to be brought into the cache (see `crate::prefetch`).
    #[inline]
    pub(crate) fn prefetch(&self, i: usize) {
        prefetch(&self.rows[i]);
    }

    /// Empties list `i`.
    pub(crate) fn clear(&mut self, i: usize) {
        // The spill is read only past the row: not touched (a miss) otherwise.
        if self.rows[i].len as usize > W {
            self.spill[i].clear();
        }
        self.rows[i].len = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::SplitMix64;
    use std::collections::BTreeSet;

    #[test]
    fn rows_hold_the_same_set_as_a_btreeset_through_pushes_and_removals_past_the_row() {
        // Lists grow well past a row (spilling) and shrink back, with removals from the
        // row, from the spill and of absent partners.
        let n = 4;
        let mut rows = IdRows::<31>::new(n);
        let mut oracle = vec![BTreeSet::new(); n];
        let mut g = SplitMix64::new(7);
        let mut longest = 0;
        for step in 0..20_000 {
            let i = (g.next_u64() % n as u64) as usize;
            let j = (g.next_u64() % 90) as u32;
            // Grow for a while, then shrink, then grow again.
            let grow = (step / 2_000) % 2 == 0;
            if grow && g.next_f64() < 0.8 {
                if oracle[i].insert(j) {
                    rows.push(i, j);
                }
            } else {
                oracle[i].remove(&j);
                rows.remove(i, j);
            }
            longest = longest.max(oracle[i].len());
            if step % 97 == 0 {
                for (k, expected) in oracle.iter().enumerate() {
                    let got: BTreeSet<u32> = rows.of(k).collect();
                    assert_eq!(&got, expected, "list {k} at step {step}");
                    assert_eq!(rows.len(k), expected.len());
                    assert_eq!(rows.of(k).count(), expected.len(), "no duplicates");
                }
            }
        }
        assert!(longest > 31, "the test reached the spill");
        let mut appended = vec![7];
        for k in 0..n {
            rows.append_to(k, &mut appended);
        }
        let listed: Vec<u32> = core::iter::once(7)
            .chain((0..n).flat_map(|k| rows.of(k)))
            .collect();
        assert_eq!(
            appended, listed,
            "append_to copies each list as `of` lists it"
        );
        rows.clear(1);
        assert_eq!(rows.of(1).count(), 0);
    }

    #[test]
    fn unlinking_a_ball_removes_it_from_every_partner_including_spilled_ones() {
        // Ball 0 partners 40 balls (past its row); each of them also partners 0 and 1.
        let mut rows = IdRows::<31>::new(42);
        for j in 2..42u32 {
            for (a, b) in [(0, j), (1, j)] {
                rows.push(a, b);
                rows.push(b as usize, a as u32);
            }
        }
        rows.unlink(0);
        assert_eq!(rows.len(0), 0);
        for j in 2..42 {
            assert_eq!(rows.of(j).collect::<Vec<_>>(), [1], "ball {j}");
        }
        assert_eq!(rows.len(1), 40);
    }

    #[test]
    fn rows_of_15_and_31_ids_are_one_and_two_cache_lines_aligned_to_one() {
        assert_eq!(core::mem::size_of::<Row<31, Line>>(), 128);
        assert_eq!(core::mem::size_of::<Row<15, Line>>(), 64);
        assert_eq!(core::mem::align_of::<Row<15, Line>>(), 64);
        // Four rows of 3 ids share a line.
        assert_eq!(core::mem::size_of::<Row<3, Quarter>>(), 16);
        assert_eq!(core::mem::align_of::<Row<3, Quarter>>(), 16);
    }
}
