//! Large per-ball arrays backed by huge pages where the system allows it.
//!
//! The event-driven engine reads a few records of random balls at every event: at 1e5
//! balls its arrays (records, cells, calendar, pending events) span tens of megabytes: in
//! 4 KiB pages, thousands of translations, far more than the processor's
//! address-translation cache holds (its second level covers a few megabytes), so random
//! reads there also walk the page tables. Backed by 2 MiB pages the same arrays need a
//! few dozen translations (the gain is measured, the misses are not: this VM exposes no
//! hardware counters).
//!
//! Linux hands out such pages for memory a program marks with `madvise(MADV_HUGEPAGE)`
//! (the kernel's transparent huge pages in their default `madvise` mode; in `always`
//! mode it does so anyway, in `never` mode not at all), and only for a 2 MiB-aligned
//! stretch of marked memory that nothing has written yet. An ordinary allocation lies
//! anywhere in the allocator's heap, beside other memory already written, so only the
//! aligned stretches wholly inside it could become huge pages (of a 6 MB array, two or
//! three of them; of a 1 MB one, none). So a large [`Array`] takes memory of its own:
//! 2 MiB-aligned, its length rounded up to whole huge pages, marked, and only then
//! filled. Elsewhere (other systems and processors, whose page sizes differ, or
//! `never`) arrays are ordinary allocations: it is a hint, and changes no value.
//!
//! Measured on the 2D gas of 1e5 discs at area fraction 0.3: see
//! `docs/event-engine.md` ("Huge pages").

use core::alloc::Layout;
use core::marker::PhantomData;
use core::ptr::NonNull;

/// The x86-64 huge page.
const HUGE_PAGE: usize = 2 << 20;

/// Arrays of at least this many bytes get huge pages of their own (on Linux x86-64):
/// a quarter of a huge page, so that rounding one up at most quadruples its memory.
/// Smaller arrays stay ordinary allocations: giving huge pages to those from 64 KiB
/// too measured level on the 2D gas at 1e5 balls (docs/event-engine.md, eleventh
/// session), for up to 2 MiB more memory each.
const LARGE: usize = HUGE_PAGE / 4;

/// A fixed-length array whose memory, when large, lies on huge pages of its own (see
/// the module documentation). It reads and writes as a slice.
pub(crate) struct Array<X> {
    start: NonNull<X>,
    /// The number of values written (all of them once built).
    len: usize,
    /// How the memory was allocated (size 0: nothing was).
    layout: Layout,
    _owns: PhantomData<X>,
}

// SAFETY: an `Array` owns its values as a `Vec` does; sending or sharing it sends or
// shares them.
unsafe impl<X: Send> Send for Array<X> {}
// SAFETY: as above.
unsafe impl<X: Sync> Sync for Array<X> {}

impl<X> Array<X> {
    /// The array of `n` values `fill(0..n)`.
    pub(crate) fn filled(n: usize, mut fill: impl FnMut(usize) -> X) -> Self {
        let layout = layout_for::<X>(n);
        let start = if layout.size() == 0 {
            NonNull::dangling()
        } else {
            // SAFETY: the layout's size is not zero.
            let raw = unsafe { std::alloc::alloc(layout) };
            let Some(start) = NonNull::new(raw.cast::<X>()) else {
                std::alloc::handle_alloc_error(layout)
            };
            if layout.align() >= HUGE_PAGE {
                advise_huge_pages(raw, layout.size());
            }
            start
        };
        // Counted as they are written: if `fill` panics, `drop` drops those written and
        // frees the memory.
        let mut array = Self {
            start,
            len: 0,
            layout,
            _owns: PhantomData,
        };
        for i in 0..n {
            let x = fill(i);
            // SAFETY: `i < n`, inside the allocation (`layout_for` holds `n` values);
            // the slot is unwritten.
            unsafe { array.start.as_ptr().add(i).write(x) };
            array.len = i + 1;
        }
        array
    }
}

/// The allocation for `n` values of `X`: a plain array, or, when large on Linux x86-64,
/// whole huge pages aligned to one.
fn layout_for<X>(n: usize) -> Layout {
    let plain = Layout::array::<X>(n).expect("an array larger than the address space");
    if cfg!(all(target_os = "linux", target_arch = "x86_64")) && plain.size() >= LARGE {
        Layout::from_size_align(
            plain.size().next_multiple_of(HUGE_PAGE),
            HUGE_PAGE.max(plain.align()),
        )
        .expect("an array larger than the address space")
    } else {
        plain
    }
}

impl<X> core::ops::Deref for Array<X> {
    type Target = [X];
    #[inline]
    fn deref(&self) -> &[X] {
        // SAFETY: the first `len` values are written and owned by the array.
        unsafe { core::slice::from_raw_parts(self.start.as_ptr(), self.len) }
    }
}

impl<X> core::ops::DerefMut for Array<X> {
    #[inline]
    fn deref_mut(&mut self) -> &mut [X] {
        // SAFETY: as in `deref`, and `&mut self` is the only access.
        unsafe { core::slice::from_raw_parts_mut(self.start.as_ptr(), self.len) }
    }
}

impl<X> Drop for Array<X> {
    fn drop(&mut self) {
        // SAFETY: the first `len` values are written and dropped once, here; the memory
        // was allocated with `layout` when its size is not zero.
        unsafe {
            core::ptr::drop_in_place(core::ptr::slice_from_raw_parts_mut(
                self.start.as_ptr(),
                self.len,
            ));
            if self.layout.size() != 0 {
                std::alloc::dealloc(self.start.as_ptr().cast(), self.layout);
            }
        }
    }
}

impl<X: Clone> Clone for Array<X> {
    fn clone(&self) -> Self {
        Self::filled(self.len, |i| self[i].clone())
    }
}

impl<X: core::fmt::Debug> core::fmt::Debug for Array<X> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

/// Marks `bytes` bytes at `start`, whole huge pages of the process's own, for huge
/// pages (a no-op but on Linux x86-64).
fn advise_huge_pages(start: *mut u8, bytes: usize) {
    #[cfg(all(target_os = "linux", target_arch = "x86_64"))]
    {
        // SAFETY: `madvise` with `MADV_HUGEPAGE` only tells the kernel how to back pages
        // of a mapping the process owns (`start..start + bytes` is a live allocation of
        // this process, page-aligned and whole pages); it changes no byte and no
        // protection. Its result is a hint's: when the kernel declines (no huge page
        // support), nothing changes.
        let _ = unsafe { libc::madvise(start.cast(), bytes, libc::MADV_HUGEPAGE) };
    }
    #[cfg(not(all(target_os = "linux", target_arch = "x86_64")))]
    let _ = (start, bytes);
}

#[cfg(test)]
mod tests {
    use super::{Array, HUGE_PAGE, LARGE};
    use std::rc::Rc;

    #[test]
    fn filled_holds_the_values_asked_for_at_every_size() {
        // Around the threshold and the huge page's size in values of 8 and 64 bytes: the
        // allocation must not change what is written, or drop or add any value.
        for n in [
            0,
            1,
            LARGE / 8 - 1,
            LARGE / 8,
            262_143,
            262_144,
            262_145,
            600_000,
        ] {
            let mut v = Array::filled(n, |i| i as u64 * 3 + 1);
            assert_eq!(v.len(), n);
            assert!(v.iter().enumerate().all(|(i, &x)| x == i as u64 * 3 + 1));
            v.iter_mut().for_each(|x| *x += 1);
            let copy = v.clone();
            assert!(copy.iter().enumerate().all(|(i, &x)| x == i as u64 * 3 + 2));
        }
        let rows = Array::filled(40_000, |i| [i as u64; 8]);
        assert!(
            rows.iter()
                .enumerate()
                .all(|(i, r)| r.iter().all(|&x| x == i as u64))
        );
        assert_eq!(Array::filled(5, |_| ()).len(), 5);
    }

    #[test]
    fn large_arrays_take_whole_huge_pages_small_ones_an_ordinary_allocation() {
        let small = Array::filled(LARGE / 8 - 1, |i| i as u64);
        assert_eq!(small.layout.size(), LARGE - 8);
        assert_eq!(small.layout.align(), align_of::<u64>());
        let large = Array::filled(LARGE / 8 + 1, |i| i as u64);
        let larger = Array::filled(HUGE_PAGE / 8 + 1, |i| i as u64);
        if cfg!(all(target_os = "linux", target_arch = "x86_64")) {
            for (array, pages) in [(&large, 1), (&larger, 2)] {
                assert_eq!(array.as_ptr() as usize % HUGE_PAGE, 0);
                assert_eq!(array.layout.size(), pages * HUGE_PAGE);
            }
        } else {
            assert_eq!(large.layout.size(), LARGE + 8);
        }
    }

    #[test]
    fn every_value_is_dropped_once_also_when_filling_panics() {
        let token = Rc::new(());
        let full = Array::filled(100, |_| Rc::clone(&token));
        assert_eq!(Rc::strong_count(&token), 101);
        let copy = full.clone();
        drop(full);
        assert_eq!(Rc::strong_count(&token), 101);
        drop(copy);
        assert_eq!(Rc::strong_count(&token), 1);
        let failed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            Array::filled(10, |i| {
                assert!(i < 7, "the eighth value fails");
                Rc::clone(&token)
            })
        }));
        assert!(failed.is_err());
        assert_eq!(Rc::strong_count(&token), 1);
    }
}
