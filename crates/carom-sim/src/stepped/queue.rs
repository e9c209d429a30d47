//! The contacts of a window in the order the event loop answers them, and a look at the
//! contacts a few places ahead.
//!
//! A window's contacts are nearly all known at its start (on the 1e5-ball gas of
//! `docs/stepped.md`, 426 predicted per step against 3 found by re-predictions), so they
//! are sorted once, earliest last, and popped from the end; the few contacts found while
//! the window runs go to a binary heap, and each pop takes the earlier of the two heads.
//! Both follow the total order of `Event::key_cmp`, so the sequence is the one a
//! single heap would give. Being sorted, the first predictions can be read ahead
//! ([`EventQueue::ahead`]): the event loop prefetches what the next three contacts will
//! read while it answers the current one (`prefetch`; measured in `docs/stepped.md`).

use std::collections::BinaryHeap;

use carom_math::Real;

use super::narrow::{Event, Pending};

/// The queue of a window (see the [module documentation](self)).
pub(crate) struct EventQueue<T: Real, const D: usize> {
    /// The window's first predictions, sorted latest first: the next one is the last.
    sorted: Vec<Pending<T, D>>,
    /// The contacts predicted while the window runs.
    found: BinaryHeap<Pending<T, D>>,
}

impl<T: Real, const D: usize> EventQueue<T, D> {
    /// An empty queue.
    pub(crate) fn new() -> Self {
        Self {
            sorted: Vec::new(),
            found: BinaryHeap::new(),
        }
    }

    /// Forgets every contact.
    pub(crate) fn clear(&mut self) {
        self.sorted.clear();
        self.found.clear();
    }

    /// Starts a window whose first predictions are `events` (the queue is emptied first).
    pub(crate) fn start(&mut self, events: impl IntoIterator<Item = Event<T, D>>) {
        self.clear();
        self.sorted.extend(events.into_iter().map(Pending));
        // `Pending` orders the earliest contact greatest: ascending puts it last.
        self.sorted.sort_unstable();
    }

    /// Adds contacts predicted while the window runs.
    pub(crate) fn push(&mut self, events: &[Event<T, D>]) {
        self.found.extend(events.iter().map(|&e| Pending(e)));
    }

    /// Takes the earliest contact.
    pub(crate) fn pop(&mut self) -> Option<Event<T, D>> {
        let from_found = match (self.sorted.last(), self.found.peek()) {
            (Some(first), Some(found)) => found > first,
            (None, found) => found.is_some(),
            (Some(_), None) => false,
        };
        let next = if from_found {
            self.found.pop()
        } else {
            self.sorted.pop()
        };
        next.map(|Pending(e)| e)
    }

    /// The first prediction `k` places after the next one among the first predictions
    /// (contacts found during the window are not counted), if there is one.
    pub(crate) fn ahead(&self, k: usize) -> Option<&Event<T, D>> {
        let at = self.sorted.len().checked_sub(k + 1)?;
        Some(&self.sorted[at].0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::SplitMix64;

    /// The queue pops exactly what one binary heap given the same contacts at the same
    /// moments pops: first predictions at the start, contacts found in batches between
    /// pops (some earlier than contacts still waiting), with equal times and contacts
    /// in one simultaneity window among them.
    #[test]
    fn pops_what_one_heap_pops() {
        let mut rng = SplitMix64::new(17);
        let event = |rng: &mut SplitMix64| {
            let ball = (rng.next_u64() % 50) as u32;
            // Times on a coarse grid (ties) and within one window of each other.
            let time = (rng.next_u64() % 64) as f64 / 64.0 + (rng.next_u64() % 2) as f64 * 1e-9;
            Event::<f64, 2>::between(ball, ball + 1, time, 1e-6)
        };
        for round in 0..40 {
            let first: Vec<Event<f64, 2>> = (0..round * 5).map(|_| event(&mut rng)).collect();
            let mut queue = EventQueue::new();
            queue.start(first.iter().copied());
            let mut heap: BinaryHeap<Pending<f64, 2>> = first.iter().map(|&e| Pending(e)).collect();
            let mut pops = 0;
            loop {
                if pops % 3 == 0 && pops < 60 {
                    let batch: Vec<Event<f64, 2>> =
                        (0..rng.next_u64() % 4).map(|_| event(&mut rng)).collect();
                    queue.push(&batch);
                    heap.extend(batch.iter().map(|&e| Pending(e)));
                }
                let (got, want) = (queue.pop(), heap.pop().map(|Pending(e)| e));
                match (got, want) {
                    (Some(a), Some(b)) => {
                        assert!(
                            Pending(a) == Pending(b),
                            "round {round}, pop {pops}: {a:?} against {b:?}"
                        );
                    }
                    (None, None) => break,
                    (a, b) => panic!("round {round}, pop {pops}: {a:?} against {b:?}"),
                }
                pops += 1;
            }
        }
    }

    /// `ahead(k)` names the first prediction `k` places after the next pop.
    #[test]
    fn looks_ahead_among_the_first_predictions() {
        let times = [0.5, 0.1, 0.3, 0.2];
        let mut queue = EventQueue::new();
        queue.start(
            times
                .iter()
                .enumerate()
                .map(|(k, &t)| Event::<f64, 2>::between(k as u32, 9, t, 1e-6)),
        );
        assert_eq!(queue.ahead(0).map(|e| e.time), Some(0.1));
        assert_eq!(queue.ahead(2).map(|e| e.time), Some(0.3));
        assert!(queue.ahead(4).is_none());
        assert_eq!(queue.pop().map(|e| e.time), Some(0.1));
        assert_eq!(queue.ahead(0).map(|e| e.time), Some(0.2));
    }
}
