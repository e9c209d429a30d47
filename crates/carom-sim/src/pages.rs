//! Large per-ball arrays backed by huge pages where the system allows it.
//!
//! The event-driven engine reads a few records of random balls at every event: at 1e5
//! balls its arrays (records, cells, calendar) span tens of megabytes: in 4 KiB pages,
//! thousands of translations, far more than the processor's address-translation cache
//! holds (its second level covers a few megabytes), so random reads there also walk the
//! page tables. Backed by 2 MiB pages the same arrays need a few dozen translations (the
//! gain measured, not the misses: this VM exposes no hardware counters). Linux hands out such pages for memory a program marks
//! with `madvise(MADV_HUGEPAGE)` (the kernel's transparent huge pages in their default
//! `madvise` mode; in `always` mode it does so anyway, in `never` mode not at all), and
//! only when the memory is first written after the mark. So the arrays here are
//! allocated, marked, and only then filled. Elsewhere (other systems and processors,
//! whose page sizes differ, or `never`) the mark is absent or ignored and nothing
//! changes: it is a hint, and changes no value.
//!
//! Measured on the 2D gas of 1e5 discs at area fraction 0.3: see
//! `docs/event-engine.md` ("Huge pages").

/// A vector of `n` values `fill(0..n)`, its memory marked for huge pages before it is
/// first written (see the module documentation).
pub(crate) fn filled<X>(n: usize, fill: impl FnMut(usize) -> X) -> Vec<X> {
    let mut v = with_capacity(n);
    v.extend((0..n).map(fill));
    v
}

/// An empty vector with room for `n` values, its memory marked for huge pages (fill it
/// before it grows).
pub(crate) fn with_capacity<X>(n: usize) -> Vec<X> {
    let mut v = Vec::with_capacity(n);
    advise_huge_pages(v.spare_capacity_mut());
    v
}

/// Marks the memory of `region` for huge pages (a no-op but on Linux on x86-64, whose
/// page sizes it assumes, and for regions too small to hold a huge page).
fn advise_huge_pages<X>(region: &mut [X]) {
    #[cfg(all(target_os = "linux", target_arch = "x86_64"))]
    {
        /// The x86-64 page sizes. Regions smaller than a huge page are left alone: none
        /// of their pages could be one.
        const HUGE_PAGE: usize = 2 << 20;
        const PAGE: usize = 4 << 10;
        let bytes = core::mem::size_of_val(region);
        if bytes < HUGE_PAGE {
            return;
        }
        let start = region.as_mut_ptr() as usize;
        // The pages the region lies on (a page it shares with other memory is only
        // marked, never changed).
        let first = start / PAGE * PAGE;
        let end = (start + bytes).div_ceil(PAGE) * PAGE;
        // SAFETY: `madvise` with `MADV_HUGEPAGE` only asks the kernel how to back the
        // pages of a mapping the process owns (`region` is live memory of this process,
        // rounded out to the pages it lies on); it changes no byte of their contents and
        // no protection, so no reference to them is invalidated. Its result is a hint's:
        // when the kernel declines (no huge page support), nothing changes.
        let _ =
            unsafe { libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE) };
    }
    #[cfg(not(all(target_os = "linux", target_arch = "x86_64")))]
    let _ = region;
}

#[cfg(test)]
mod tests {
    use super::filled;

    #[test]
    fn filled_holds_the_values_asked_for_at_every_size() {
        // Around the huge page's size in elements of 8 and 64 bytes: the mark must not
        // change what is written, or drop or add any element.
        for n in [0, 1, 262_143, 262_144, 262_145, 600_000] {
            let v = filled(n, |i| i as u64 * 3 + 1);
            assert_eq!(v.len(), n);
            assert!(v.iter().enumerate().all(|(i, &x)| x == i as u64 * 3 + 1));
        }
        let rows = filled(40_000, |i| [i as u64; 8]);
        assert!(
            rows.iter()
                .enumerate()
                .all(|(i, r)| r.iter().all(|&x| x == i as u64))
        );
    }
}
