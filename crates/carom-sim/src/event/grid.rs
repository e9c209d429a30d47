//! Indexing a grid of cells: a cell's linear index and the `3^D` cells around it.
//!
//! Both ways the event-driven engine finds partners bin balls in a grid (`cells`: the
//! balls themselves, `neighbours`: the anchors of their lists) and read the cells around
//! a cell. Most cells are interior, and their neighbours sit at fixed offsets of the
//! linear index, computed once; only cells on the grid's edge take the general path
//! (wrapping on a periodic axis, dropping cells past a wall, listing a cell met twice
//! once). Both paths list the cells in the same order, offset by offset with the first
//! axis fastest, so the order in which partners are met (and with it which of two
//! simultaneous events is taken first) does not depend on the path.
//!
//! Measured before this module (3D gas, N = 4,000, callgrind): enumerating a rebuild's
//! 27 cells through the general path cost about 4,600 instructions of the rebuild's
//! 14,000.

/// The most cells around a cell (`3^D` for `D <= 3`).
pub(crate) const MAX_AROUND: usize = 27;

/// The shape of a grid of `counts[0] × … × counts[D−1]` cells, periodic or walled.
#[derive(Clone, Debug)]
pub(crate) struct GridIndex<const D: usize> {
    counts: [i64; D],
    periodic: bool,
    /// The linear-index offsets of the `3^D` cells around an interior cell.
    offsets: [i64; MAX_AROUND],
    /// Per face `2 · axis + upper`, the linear-index offsets of the `3^(D−1)` cells one
    /// step across that face from an interior cell (the slab a ball's neighbourhood gains
    /// when it crosses into the cell through the opposite face).
    slabs: [[i64; MAX_SLAB]; 6],
}

/// The most cells in a slab (`3^(D−1)` for `D <= 3`).
const MAX_SLAB: usize = 9;

impl<const D: usize> GridIndex<D> {
    /// A grid with `counts[k] >= 1` cells on axis `k`.
    pub(crate) fn new(counts: [i64; D], periodic: bool) -> Self {
        let mut offsets = [0; MAX_AROUND];
        for (offset, delta) in offsets.iter_mut().enumerate().take(Self::around_count()) {
            let mut rest = offset;
            let mut stride = 1i64;
            for count in counts {
                *delta += ((rest % 3) as i64 - 1) * stride;
                rest /= 3;
                stride *= count;
            }
        }
        let mut slabs = [[0; MAX_SLAB]; 6];
        for axis in 0..D {
            for (upper, step) in [(0, -1i64), (1, 1)] {
                for (slot, delta) in slabs[2 * axis + upper]
                    .iter_mut()
                    .enumerate()
                    .take(Self::slab_count())
                {
                    let (mut rest, mut stride) = (slot, 1i64);
                    for (k, count) in counts.iter().enumerate() {
                        let o = if k == axis {
                            step
                        } else {
                            let o = (rest % 3) as i64 - 1;
                            rest /= 3;
                            o
                        };
                        *delta += o * stride;
                        stride *= count;
                    }
                }
            }
        }
        Self {
            counts,
            periodic,
            offsets,
            slabs,
        }
    }

    /// `3^(D−1)`.
    #[inline]
    const fn slab_count() -> usize {
        3usize.pow(D as u32 - 1)
    }

    /// `3^D`.
    #[inline]
    const fn around_count() -> usize {
        3usize.pow(D as u32)
    }

    /// The number of cells per axis.
    #[inline]
    pub(crate) fn counts(&self) -> &[i64; D] {
        &self.counts
    }

    /// The number of cells.
    pub(crate) fn len(&self) -> usize {
        self.counts.iter().product::<i64>() as usize
    }

    /// The linear index of the cell with (in-grid) coordinates `c`, first axis fastest.
    #[inline]
    pub(crate) fn index(&self, c: [i64; D]) -> usize {
        let mut index = 0i64;
        for k in (0..D).rev() {
            index = index * self.counts[k] + c[k];
        }
        index as usize
    }

    /// `true` if no neighbour of cell `base` is past an edge of the grid.
    #[inline]
    pub(crate) fn is_interior(&self, base: [i64; D]) -> bool {
        (0..D).all(|k| base[k] >= 1 && base[k] + 2 <= self.counts[k])
    }

    /// `true` if points in the cells around the interior cell `base` are each other's
    /// minimum images as they are: every cell around it is inside the grid, so nothing
    /// wrapped them, and they are less than two cells apart on every axis, at most half
    /// a period when every axis has four cells or more.
    #[inline]
    pub(crate) fn needs_no_image(&self, base: [i64; D]) -> bool {
        self.is_interior(base) && self.counts.iter().all(|&n| n >= 4)
    }

    /// Writes the cells around the (in-grid) cell `base`, itself included and each once,
    /// to the start of `around`; returns their number.
    #[inline]
    pub(crate) fn around(&self, base: [i64; D], around: &mut [usize; MAX_AROUND]) -> usize {
        let cells = Self::around_count();
        // An interior cell's neighbours are at fixed index offsets, all distinct.
        if self.is_interior(base) {
            let index = self.index(base) as i64;
            for (slot, delta) in around.iter_mut().zip(&self.offsets[..cells]) {
                *slot = (index + delta) as usize;
            }
            return cells;
        }
        self.around_edge(base, around)
    }

    /// Writes the cells one step across the face (`axis`, `upper`) of cell `base` and
    /// beside that (the `3^(D−1)` cells of the neighbourhood of `base` with that
    /// coordinate on `axis`), each once, to the start of `out`; returns their number. In
    /// the order of [`around`](Self::around), the other axes' offsets first axis fastest.
    #[inline]
    pub(crate) fn slab(
        &self,
        base: [i64; D],
        axis: usize,
        upper: bool,
        out: &mut [usize; MAX_AROUND],
    ) -> usize {
        if self.is_interior(base) {
            let index = self.index(base) as i64;
            let slab = &self.slabs[2 * axis + usize::from(upper)];
            for (slot, delta) in out.iter_mut().zip(&slab[..Self::slab_count()]) {
                *slot = (index + delta) as usize;
            }
            return Self::slab_count();
        }
        self.slab_edge(base, axis, upper, out)
    }

    /// [`slab`](Self::slab) for a cell on the grid's edge, out of line, as
    /// [`around_edge`](Self::around_edge) with `axis` held one step across the face.
    #[inline(never)]
    fn slab_edge(
        &self,
        base: [i64; D],
        axis: usize,
        upper: bool,
        out: &mut [usize; MAX_AROUND],
    ) -> usize {
        let mut values = [[0i64; 3]; D];
        let mut lens = [0usize; D];
        for k in 0..D {
            let n = self.counts[k];
            let steps: &[i64] = match (k == axis, upper) {
                (true, true) => &[1],
                (true, false) => &[-1],
                (false, _) => &[-1, 0, 1],
            };
            for &o in steps {
                let mut x = base[k] + o;
                if x < 0 || x >= n {
                    if !self.periodic {
                        continue;
                    }
                    x = x.rem_euclid(n);
                }
                if !values[k][..lens[k]].contains(&x) {
                    values[k][lens[k]] = x;
                    lens[k] += 1;
                }
            }
        }
        self.combinations(&values, &lens, out)
    }

    /// Every combination of the per-axis coordinates `values[k][..lens[k]]`, first axis
    /// fastest, as linear indices written to `out`; returns their number.
    fn combinations(
        &self,
        values: &[[i64; 3]; D],
        lens: &[usize; D],
        out: &mut [usize; MAX_AROUND],
    ) -> usize {
        let total: usize = lens.iter().product();
        for (slot, cell) in out.iter_mut().enumerate().take(total) {
            let mut rest = slot;
            let c: [i64; D] = core::array::from_fn(|k| {
                let x = values[k][rest % lens[k]];
                rest /= lens[k];
                x
            });
            *cell = self.index(c);
        }
        total
    }

    /// [`around`](Self::around) for a cell on the grid's edge, out of line: per axis the
    /// coordinates `x − 1, x, x + 1` that exist (wrapped on a periodic axis, dropped past
    /// a wall, each value once on an axis of one or two cells), then every combination,
    /// first axis fastest. That is the order of the offsets with later repeats dropped.
    #[inline(never)]
    fn around_edge(&self, base: [i64; D], around: &mut [usize; MAX_AROUND]) -> usize {
        let mut values = [[0i64; 3]; D];
        let mut lens = [0usize; D];
        for k in 0..D {
            let n = self.counts[k];
            for o in -1..=1 {
                let mut x = base[k] + o;
                if x < 0 || x >= n {
                    if !self.periodic {
                        continue;
                    }
                    x = x.rem_euclid(n);
                }
                if !values[k][..lens[k]].contains(&x) {
                    values[k][lens[k]] = x;
                    lens[k] += 1;
                }
            }
        }
        self.combinations(&values, &lens, around)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    /// The cells around `base` by brute force: every cell whose coordinates differ from
    /// `base` by at most one on each axis, directly or across a periodic face.
    fn brute<const D: usize>(grid: &GridIndex<D>, base: [i64; D]) -> BTreeSet<usize> {
        let mut out = BTreeSet::new();
        let total = grid.len();
        for index in 0..total {
            let mut rest = index as i64;
            let near = (0..D).all(|k| {
                let n = grid.counts[k];
                let x = rest % n;
                rest /= n;
                let d = (x - base[k]).abs();
                d <= 1 || (grid.periodic && d == n - 1)
            });
            if near {
                out.insert(index);
            }
        }
        out
    }

    /// The cells around `base` offset by offset, first axis fastest, each kept the first
    /// time it is met.
    fn by_offsets<const D: usize>(grid: &GridIndex<D>, base: [i64; D]) -> Vec<usize> {
        let mut out = Vec::new();
        'offsets: for offset in 0..3usize.pow(D as u32) {
            let mut rest = offset;
            let mut c = [0i64; D];
            for k in 0..D {
                let (n, mut x) = (grid.counts[k], base[k] + (rest % 3) as i64 - 1);
                rest /= 3;
                if x < 0 || x >= n {
                    if !grid.periodic {
                        continue 'offsets;
                    }
                    x = x.rem_euclid(n);
                }
                c[k] = x;
            }
            if !out.contains(&grid.index(c)) {
                out.push(grid.index(c));
            }
        }
        out
    }

    fn check<const D: usize>(counts: [i64; D], periodic: bool) {
        let grid = GridIndex::new(counts, periodic);
        let mut base = [0i64; D];
        loop {
            let mut around = [0; MAX_AROUND];
            let count = grid.around(base, &mut around);
            let listed: BTreeSet<usize> = around[..count].iter().copied().collect();
            assert_eq!(
                listed.len(),
                count,
                "{counts:?} {base:?}: a cell listed twice"
            );
            assert_eq!(
                listed,
                brute(&grid, base),
                "{counts:?} periodic {periodic} {base:?}"
            );
            // Both paths list the cells in the order of the offsets (first axis fastest),
            // later repeats dropped.
            assert_eq!(
                &around[..count],
                &by_offsets(&grid, base)[..],
                "order at {base:?}"
            );
            // Next base, first axis fastest.
            let mut k = 0;
            loop {
                if k == D {
                    return;
                }
                base[k] += 1;
                if base[k] < counts[k] {
                    break;
                }
                base[k] = 0;
                k += 1;
            }
        }
    }

    /// The slab across face (`axis`, `upper`) of `base`, offset by offset as the cells
    /// code enumerated it before this module.
    fn slab_by_offsets<const D: usize>(
        grid: &GridIndex<D>,
        base: [i64; D],
        axis: usize,
        upper: bool,
    ) -> Vec<usize> {
        let mut out = Vec::new();
        'offsets: for offset in 0..3usize.pow(D as u32 - 1) {
            let mut rest = offset;
            let mut c = [0i64; D];
            for k in 0..D {
                let o = if k == axis {
                    if upper { 1 } else { -1 }
                } else {
                    let o = (rest % 3) as i64 - 1;
                    rest /= 3;
                    o
                };
                let (n, mut x) = (grid.counts[k], base[k] + o);
                if x < 0 || x >= n {
                    if !grid.periodic {
                        continue 'offsets;
                    }
                    x = x.rem_euclid(n);
                }
                c[k] = x;
            }
            if !out.contains(&grid.index(c)) {
                out.push(grid.index(c));
            }
        }
        out
    }

    #[test]
    fn the_slab_across_each_face_of_every_cell_is_listed_each_once_in_one_order() {
        fn each<const D: usize>(counts: [i64; D], periodic: bool) {
            let grid = GridIndex::new(counts, periodic);
            let total = grid.len();
            for index in 0..total {
                let mut rest = index as i64;
                let base: [i64; D] = core::array::from_fn(|k| {
                    let x = rest % counts[k];
                    rest /= counts[k];
                    x
                });
                for axis in 0..D {
                    for upper in [false, true] {
                        let mut out = [0; MAX_AROUND];
                        let n = grid.slab(base, axis, upper, &mut out);
                        assert_eq!(
                            &out[..n],
                            &slab_by_offsets(&grid, base, axis, upper)[..],
                            "{counts:?} periodic {periodic} {base:?} axis {axis} upper {upper}"
                        );
                    }
                }
            }
        }
        for periodic in [false, true] {
            each([5, 4], periodic);
            each([2, 7], periodic);
            each([4, 3, 5], periodic);
            each([1, 2, 6], periodic);
        }
    }

    #[test]
    fn the_cells_around_every_cell_are_its_neighbours_each_once_in_one_order() {
        for periodic in [false, true] {
            check([5, 4], periodic);
            check([1, 7], periodic);
            check([2, 3], periodic);
            check([4, 3, 5], periodic);
            check([2, 1, 6], periodic);
        }
    }
}
