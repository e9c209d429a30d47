//! Asking the CPU to bring a value into the cache before it is read.
//!
//! Both engines' event loops are bound by cache misses on the data of the balls each event
//! touches (their state, their partner lists, the partners' states), which are scattered
//! over memory many times the size of the caches at 1e5 balls. Each loop knows which
//! balls come next (the stepped engine's `queue`, the event engine's calendar), so it
//! prefetches their data while it answers the current event. A prefetch is only a hint:
//! it reads nothing into the program, cannot fault, and changes no result. On targets
//! without a prefetch instruction in `core::arch` it does nothing.

/// Asks for the cache line holding `x` (a no-op where the target has no prefetch).
#[inline]
pub(crate) fn prefetch<X>(x: &X) {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let address: *const X = x;
        // SAFETY: `_mm_prefetch` needs SSE, which every x86_64 CPU has; a prefetch never
        // faults and does not access the memory as far as the program is concerned, and
        // `address` comes from a live reference anyway.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(address.cast::<i8>()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}
