//! The event calendar: one scheduled event per ball, ordered by time.
//!
//! The event-driven engine keeps at most one pending event per ball (its earliest
//! predicted event), so the calendar maps ball index → time and must support
//! "schedule or reschedule ball i at t", "cancel ball i" and "pop the earliest".
//!
//! It follows Paul (J. Comput. Phys. 221, 2007): time is cut into buckets of width `w`,
//! and `nb` consecutive buckets form a *cycle*. Events in the current bucket live in a
//! small binary min-heap; events in the rest of the cycle live in unsorted
//! doubly-linked lists (one per bucket, O(1) insert and remove); events beyond the cycle
//! live in an unsorted overflow list. Popping takes from the heap; when it runs dry the
//! cursor moves to the next non-empty bucket, whose list is heapified. When the cycle is
//! used up the next one starts and the overflow is redistributed — once per cycle, so
//! each event is looked at O(1) times per cycle. With `w` chosen so a bucket holds a few
//! events, scheduling and popping cost O(1) on average plus a heap of a handful of
//! entries, instead of O(log N) in one big heap.
//!
//! The heap holds `(time, ball)` entries, so its comparisons read no per-ball array, and
//! an event cancelled while in the heap is only forgotten (its ball's slot and time
//! change); its entry is dropped, dead, when it reaches the top. An entry is live when
//! its ball is in the heap at the entry's time: a ball cancelled and scheduled again at
//! the same time leaves two equal entries, either of which stands for it (they order
//! alike), and the other is dead once the ball leaves the heap. Every entry in the heap
//! lies in a bucket at or before the current one, so the heap is empty, dead entries
//! and all, before the cursor moves on; and when dead entries outnumber the live ones
//! the heap is rebuilt from the live ones, so a long stay in one bucket (a cascade of
//! events at one instant) cannot pile them up. Against a heap of ball indices that
//! moved each ball's heap position with it: see `docs/event-engine.md`.
//!
//! Each pop also reads one ball of the next bucket's list ahead (`read_ahead`), so that
//! emptying that bucket into the heap finds its links in the cache.
//!
//! Ties are broken by ball index, so the order of events is deterministic.

use carom_math::{Real, floor_to_i64};

use crate::pages::Array;

const NONE: u32 = u32::MAX;

/// Where a ball's event is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Slot {
    /// No event scheduled.
    Idle,
    /// In the heap (an entry at the ball's time is there).
    Heap,
    /// In the list of this bucket (index into `heads`).
    Bucket(u32),
    /// In the overflow list at this position.
    Overflow(u32),
}

/// A heap entry: a ball and its event time when it entered the heap.
#[derive(Clone, Copy, Debug)]
struct Entry<T: Real> {
    time: T,
    ball: u32,
}

impl<T: Real> Entry<T> {
    /// `true` if `self` comes before `other`: earlier time, then lower ball.
    #[inline]
    fn before(&self, other: &Self) -> bool {
        self.time < other.time || (self.time == other.time && self.ball < other.ball)
    }

    /// `true` if the heap entry stands for its ball's event: the ball is in the heap at
    /// the entry's time (`time` and `slot` are the calendar's per-ball arrays).
    #[inline]
    fn is_live(&self, time: &[T], slot: &[Slot]) -> bool {
        let ball = self.ball as usize;
        slot[ball] == Slot::Heap && time[ball] == self.time
    }
}

/// A calendar of at most one event per ball.
#[derive(Clone, Debug)]
pub struct Calendar<T: Real> {
    time: Array<T>,
    slot: Array<Slot>,
    next: Array<u32>,
    prev: Array<u32>,
    heads: Array<u32>,
    /// The current bucket's events, a binary min-heap ordered by (time, ball), dead
    /// entries included (see the module documentation).
    heap: Vec<Entry<T>>,
    /// The number of live entries in the heap.
    heap_live: usize,
    /// The ball whose successor in the next bucket's list is read ahead at the next pop
    /// (`NONE`: nothing to read ahead; see `read_ahead`).
    ahead: u32,
    overflow: Vec<u32>,
    /// The inverse of the bucket width.
    inv_width: T,
    /// Absolute index of the bucket the heap holds (bucket k spans `[k w, (k+1) w)`).
    current: i64,
    /// The first bucket after the current cycle: lists hold buckets in
    /// `(current, cycle_end)`, the overflow holds buckets `>= cycle_end`.
    cycle_end: i64,
    len: usize,
}

impl<T: Real> Calendar<T> {
    /// An empty calendar for `balls` balls, with `buckets` buckets of width `width`
    /// starting at time `start`. `width` must be positive and finite; `buckets >= 1`.
    pub fn new(balls: usize, buckets: usize, width: T, start: T) -> Self {
        assert!(
            width > T::zero() && width.finite(),
            "bucket width must be positive and finite"
        );
        assert!(balls < NONE as usize, "at most 2^32 − 2 balls");
        let buckets = buckets.max(1);
        let mut c = Self {
            time: Array::filled(balls, |_| T::INFINITY),
            slot: Array::filled(balls, |_| Slot::Idle),
            next: Array::filled(balls, |_| NONE),
            prev: Array::filled(balls, |_| NONE),
            heads: Array::filled(buckets, |_| NONE),
            heap: Vec::with_capacity(64),
            heap_live: 0,
            ahead: NONE,
            overflow: Vec::new(),
            inv_width: T::one() / width,
            current: 0,
            cycle_end: 0,
            len: 0,
        };
        c.current = c.bucket_of(start);
        c.cycle_end = c.current.saturating_add(buckets as i64);
        c
    }

    /// A bucket width and count for `balls` balls whose events are spread over about
    /// `horizon` (e.g. the mean time between a ball's events): about eight events per
    /// bucket, buckets spanning a few horizons.
    pub fn sized_for(balls: usize, horizon: T, start: T) -> Self {
        let n = T::from_count(balls.max(1));
        let width = if horizon > T::zero() && horizon.finite() {
            horizon * T::lit(8.0) / n
        } else {
            T::one()
        };
        let buckets = (balls / 2).next_power_of_two().clamp(16, 1 << 20);
        Self::new(balls, buckets, width.max(T::MIN_POSITIVE), start)
    }

    /// The number of scheduled events.
    pub fn len(&self) -> usize {
        self.len
    }

    /// `true` if nothing is scheduled.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The time of `ball`'s event, or infinity.
    pub fn time_of(&self, ball: usize) -> T {
        self.time[ball]
    }

    fn bucket_of(&self, t: T) -> i64 {
        // Saturating: times far beyond the range land in the overflow list.
        floor_to_i64(t * self.inv_width)
    }

    /// Schedules `ball` at time `t`, replacing its previous event. An infinite `t` cancels.
    pub fn schedule(&mut self, ball: usize, t: T) {
        self.cancel(ball);
        if t == T::INFINITY {
            return;
        }
        debug_assert!(t.finite(), "event times are finite or +infinity");
        self.time[ball] = t;
        self.len += 1;
        self.place(ball as u32);
    }

    /// Removes `ball`'s event, if any.
    pub fn cancel(&mut self, ball: usize) {
        match self.slot[ball] {
            Slot::Idle => return,
            // Its entry stays in the heap, dead, until it reaches the top.
            Slot::Heap => self.heap_live -= 1,
            Slot::Bucket(b) => self.list_remove(ball as u32, b as usize),
            Slot::Overflow(pos) => {
                let pos = pos as usize;
                self.overflow.swap_remove(pos);
                if let Some(&moved) = self.overflow.get(pos) {
                    self.slot[moved as usize] = Slot::Overflow(pos as u32);
                }
            }
        }
        self.slot[ball] = Slot::Idle;
        self.time[ball] = T::INFINITY;
        self.len -= 1;
    }

    /// The earliest event `(ball, time)` without removing it.
    pub fn peek(&mut self) -> Option<(usize, T)> {
        loop {
            while let Some(&top) = self.heap.first() {
                if self.is_live(&top) {
                    return Some((top.ball as usize, top.time));
                }
                self.heap_pop();
            }
            if self.len == 0 {
                return None;
            }
            self.refill();
        }
    }

    /// Up to `k` of the next events' balls, the earliest first, the others in no
    /// particular order: the top of the heap of the current bucket (with `k = 3` it holds
    /// the next two entries, when the bucket has them; an entry may be dead). For
    /// prefetching their data.
    pub fn upcoming(&self, k: usize) -> impl Iterator<Item = usize> + '_ {
        self.heap[..self.heap.len().min(k)]
            .iter()
            .map(|e| e.ball as usize)
    }

    /// Removes and returns the earliest event `(ball, time)`; ties go to the lower ball.
    pub fn pop(&mut self) -> Option<(usize, T)> {
        let (ball, t) = self.peek()?;
        self.heap_pop();
        self.cancel(ball);
        self.read_ahead();
        Some((ball, t))
    }

    /// `true` if the heap entry `entry` stands for its ball's event: the ball is in the
    /// heap at the entry's time.
    #[inline]
    fn is_live(&self, entry: &Entry<T>) -> bool {
        entry.is_live(&self.time, &self.slot)
    }

    /// Puts a ball whose time is set into the heap, a bucket or the overflow list.
    fn place(&mut self, ball: u32) {
        let k = self.bucket_of(self.time[ball as usize]);
        if k <= self.current {
            self.heap_push(ball);
        } else if k < self.cycle_end {
            self.list_push(ball, k.rem_euclid(self.heads.len() as i64) as usize);
        } else {
            self.slot[ball as usize] = Slot::Overflow(self.overflow.len() as u32);
            self.overflow.push(ball);
        }
    }

    /// Moves the cursor forward until the heap holds the earliest events (called with
    /// the heap empty and events scheduled).
    ///
    /// Invariant: heap events are in buckets `<= current`, list events in
    /// `(current, cycle_end)`, overflow events in `>= cycle_end`.
    fn refill(&mut self) {
        debug_assert!(self.heap.is_empty() && self.len > 0);
        let nb = self.heads.len() as i64;
        loop {
            let mut k = self.current + 1;
            while k < self.cycle_end {
                let b = k.rem_euclid(nb) as usize;
                if self.heads[b] != NONE {
                    self.current = k;
                    self.drain_bucket_into_heap(b);
                    // Start reading ahead the next bucket's list.
                    self.ahead = if k + 1 < self.cycle_end {
                        self.heads[(k + 1).rem_euclid(nb) as usize]
                    } else {
                        NONE
                    };
                    return;
                }
                k += 1;
            }
            // The cycle is used up: the next one starts at the earliest overflow event
            // (skipping empty cycles), and the overflow is redistributed once.
            let earliest = self
                .overflow
                .iter()
                .map(|&b| self.time[b as usize])
                .fold(T::INFINITY, T::min);
            debug_assert!(
                earliest < T::INFINITY,
                "events are counted but none is stored"
            );
            self.current = self.bucket_of(earliest).max(self.cycle_end);
            self.cycle_end = self.current.saturating_add(nb);
            self.redistribute_overflow();
            if !self.heap.is_empty() {
                return;
            }
        }
    }

    /// One step along the next bucket's list: asks for the links, time and slot of the
    /// ball after `ahead` to be brought into the cache, and moves `ahead` on to it.
    ///
    /// Emptying a bucket into the heap follows its list from ball to ball, each step a
    /// read of a random ball's link that waits for the one before (4 % of the 2D gas's
    /// profile samples at 1e5 balls, on that read). A bucket holds about as many events as it takes pops to empty
    /// the one before, so one step per pop has the next bucket's list in the cache when
    /// the heap runs dry. The list may change meanwhile (a ball inserted at its head was
    /// just written; one removed has no successor, which ends the walk; one moved to
    /// another list leads the walk there): it is only a hint, and changes nothing.
    #[inline]
    fn read_ahead(&mut self) {
        if self.ahead == NONE {
            return;
        }
        let ball = self.ahead as usize;
        crate::prefetch::prefetch(&self.time[ball]);
        crate::prefetch::prefetch(&self.slot[ball]);
        self.ahead = self.next[ball];
        if self.ahead != NONE {
            crate::prefetch::prefetch(&self.next[self.ahead as usize]);
        }
    }

    fn drain_bucket_into_heap(&mut self, b: usize) {
        let mut ball = self.heads[b];
        self.heads[b] = NONE;
        while ball != NONE {
            let next = self.next[ball as usize];
            self.next[ball as usize] = NONE;
            self.prev[ball as usize] = NONE;
            self.heap_push(ball);
            ball = next;
        }
    }

    /// Places every overflow event again relative to the current cycle.
    fn redistribute_overflow(&mut self) {
        let pending = std::mem::take(&mut self.overflow);
        for &ball in &pending {
            self.place(ball);
        }
        // Keep the allocation when every event left the overflow.
        if self.overflow.is_empty() {
            self.overflow = pending;
            self.overflow.clear();
        }
    }

    fn list_push(&mut self, ball: u32, b: usize) {
        let head = self.heads[b];
        self.next[ball as usize] = head;
        self.prev[ball as usize] = NONE;
        if head != NONE {
            self.prev[head as usize] = ball;
        }
        self.heads[b] = ball;
        self.slot[ball as usize] = Slot::Bucket(b as u32);
    }

    fn list_remove(&mut self, ball: u32, b: usize) {
        let (p, n) = (self.prev[ball as usize], self.next[ball as usize]);
        if p == NONE {
            self.heads[b] = n;
        } else {
            self.next[p as usize] = n;
        }
        if n != NONE {
            self.prev[n as usize] = p;
        }
        self.next[ball as usize] = NONE;
        self.prev[ball as usize] = NONE;
    }

    /// Puts `ball`, whose time is set, into the heap; rebuilds the heap from its live
    /// entries, one per ball, when the others outnumber them.
    fn heap_push(&mut self, ball: u32) {
        self.slot[ball as usize] = Slot::Heap;
        self.heap_live += 1;
        if self.heap.len() >= 2 * self.heap_live + 16 {
            let (time, slot) = (&self.time, &self.slot);
            self.heap.retain(|e| e.is_live(time, slot));
            // A sorted array is a heap.
            self.heap.sort_unstable_by(|a, b| {
                if a.before(b) {
                    core::cmp::Ordering::Less
                } else if b.before(a) {
                    core::cmp::Ordering::Greater
                } else {
                    core::cmp::Ordering::Equal
                }
            });
            // A ball rescheduled at the time it had leaves equal entries, all live; they
            // lie side by side once sorted, and one stands for the ball. Kept, they made
            // every push of a cascade at one instant rebuild a heap that only grew: a
            // fuzzed scene's pinned ball (23 balls) crawled at 15,000 events a second,
            // 96 % of it in this rebuild.
            self.heap.dedup_by_key(|e| e.ball);
        }
        let entry = Entry {
            time: self.time[ball as usize],
            ball,
        };
        // Sift up: move parents down until the entry's place is found.
        let mut pos = self.heap.len();
        self.heap.push(entry);
        while pos > 0 {
            let parent = (pos - 1) / 2;
            if !entry.before(&self.heap[parent]) {
                break;
            }
            self.heap[pos] = self.heap[parent];
            pos = parent;
        }
        self.heap[pos] = entry;
    }

    /// Removes the heap's top entry.
    fn heap_pop(&mut self) {
        let Some(last) = self.heap.pop() else {
            return;
        };
        let n = self.heap.len();
        if n == 0 {
            return;
        }
        // Sift the last entry down from the top: move the earlier child up.
        let mut pos = 0;
        loop {
            let l = 2 * pos + 1;
            if l >= n {
                break;
            }
            let child = if l + 1 < n && self.heap[l + 1].before(&self.heap[l]) {
                l + 1
            } else {
                l
            };
            if !self.heap[child].before(&last) {
                break;
            }
            self.heap[pos] = self.heap[child];
            pos = child;
        }
        self.heap[pos] = last;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::collections::BTreeSet;

    /// The oracle: an ordered set of (time bits, ball) with a map ball → time.
    #[derive(Default)]
    struct Oracle {
        set: BTreeSet<(u64, usize)>,
        time: std::collections::HashMap<usize, f64>,
    }

    impl Oracle {
        fn key(t: f64) -> u64 {
            // Non-negative finite times order like their bit patterns.
            t.to_bits()
        }
        fn schedule(&mut self, ball: usize, t: f64) {
            self.cancel(ball);
            if t.is_finite() {
                self.set.insert((Self::key(t), ball));
                self.time.insert(ball, t);
            }
        }
        fn cancel(&mut self, ball: usize) {
            if let Some(t) = self.time.remove(&ball) {
                self.set.remove(&(Self::key(t), ball));
            }
        }
        fn pop(&mut self) -> Option<(usize, f64)> {
            let &(k, ball) = self.set.iter().next()?;
            self.set.remove(&(k, ball));
            self.time.remove(&ball);
            Some((ball, f64::from_bits(k)))
        }
    }

    #[derive(Clone, Debug)]
    enum Op {
        Schedule(usize, f64),
        Cancel(usize),
        Pop,
    }

    fn ops() -> impl Strategy<Value = Vec<Op>> {
        let op = prop_oneof![
            4 => (0..40usize, 0.0..5.0f64).prop_map(|(b, dt)| Op::Schedule(b, dt)),
            // far in the future: exercises the overflow list
            1 => (0..40usize, 5.0..1e6f64).prop_map(|(b, dt)| Op::Schedule(b, dt)),
            // coincident times: exercises tie-breaking
            1 => (0..40usize).prop_map(|b| Op::Schedule(b, 0.0)),
            1 => (0..40usize).prop_map(Op::Cancel),
            3 => Just(Op::Pop),
        ];
        proptest::collection::vec(op, 1..400)
    }

    proptest! {
        #[test]
        fn pops_in_the_same_order_as_an_ordered_set(ops in ops(), width in 0.001..2.0f64, buckets in 1..64usize) {
            let mut cal = Calendar::<f64>::new(40, buckets, width, 0.0);
            let mut oracle = Oracle::default();
            let mut now = 0.0f64;
            for op in ops {
                match op {
                    // Events are never scheduled before the current time.
                    Op::Schedule(b, dt) => { cal.schedule(b, now + dt); oracle.schedule(b, now + dt); }
                    Op::Cancel(b) => { cal.cancel(b); oracle.cancel(b); }
                    Op::Pop => {
                        let got = cal.pop();
                        prop_assert_eq!(got, oracle.pop());
                        if let Some((_, t)) = got { now = t; }
                    }
                }
                prop_assert_eq!(cal.len(), oracle.set.len());
            }
            while let Some(e) = cal.pop() {
                prop_assert_eq!(Some(e), oracle.pop());
            }
            prop_assert!(oracle.pop().is_none());
        }
    }

    #[test]
    fn upcoming_starts_with_the_next_event_and_holds_the_one_after() {
        // Five events in one bucket (width 1): after a peek fills the heap, the top three
        // hold the earliest first and the second earliest among the others.
        let mut c = Calendar::<f64>::new(6, 4, 1.0, 0.0);
        for (ball, t) in [(0, 0.5), (1, 0.1), (2, 0.3), (3, 0.2), (4, 0.9)] {
            c.schedule(ball, t);
        }
        assert_eq!(c.peek(), Some((1, 0.1)));
        let top: Vec<usize> = c.upcoming(3).collect();
        assert_eq!(top[0], 1);
        assert!(
            top[1..].contains(&3),
            "the second event (ball 3) in {top:?}"
        );
        assert_eq!(c.upcoming(10).count(), 5);
        c.pop();
        assert!(c.upcoming(1).eq([3]));
    }

    #[test]
    fn rescheduling_within_the_current_bucket_does_not_pile_up_dead_entries() {
        // Ball 1 keeps the heap's bucket open; ball 0 is rescheduled a thousand times
        // within it, later each time (a cascade at one instant does this). Each
        // rescheduling leaves a dead entry below the top; the heap is rebuilt from its
        // live entries before they outnumber them much.
        let mut c = Calendar::<f64>::new(3, 4, 1.0, 0.0);
        c.schedule(1, 0.1);
        c.schedule(2, 0.2);
        assert_eq!(c.peek(), Some((1, 0.1)));
        for k in 0..1000 {
            c.schedule(0, 0.5 + 1e-6 * f64::from(k));
            assert!(c.heap.len() <= 2 * 3 + 16, "{} entries", c.heap.len());
        }
        assert_eq!(c.pop(), Some((1, 0.1)));
        assert_eq!(c.pop(), Some((2, 0.2)));
        assert_eq!(c.pop(), Some((0, 0.5 + 1e-6 * 999.0)));
        assert_eq!(c.pop(), None);
    }

    #[test]
    fn rescheduling_at_the_same_instant_keeps_the_heap_small() {
        // A cascade at one instant: every event at the same time, each ball rescheduled
        // at that time again and again. Each rescheduling leaves an entry equal to the
        // new one (both live); the heap keeps one per ball at its rebuilds.
        let mut c = Calendar::<f64>::new(3, 4, 1.0, 0.0);
        for ball in 0..3 {
            c.schedule(ball, 0.5);
        }
        assert_eq!(c.peek(), Some((0, 0.5)));
        for k in 0..3000 {
            c.schedule(k % 3, 0.5);
            assert!(c.heap.len() <= 2 * 3 + 16, "{} entries", c.heap.len());
        }
        // Each ball pops once, in index order, then the calendar is empty.
        assert_eq!(c.pop(), Some((0, 0.5)));
        assert_eq!(c.pop(), Some((1, 0.5)));
        assert_eq!(c.pop(), Some((2, 0.5)));
        assert_eq!(c.pop(), None);
    }

    #[test]
    fn rescheduling_replaces_and_infinity_cancels() {
        let mut c = Calendar::<f32>::sized_for(3, 1.0, 0.0);
        c.schedule(0, 2.0);
        c.schedule(1, 1.0);
        c.schedule(0, 0.5);
        c.schedule(2, 3.0);
        c.schedule(2, f32::INFINITY);
        assert_eq!(c.len(), 2);
        assert_eq!(c.pop(), Some((0, 0.5)));
        assert_eq!(c.pop(), Some((1, 1.0)));
        assert_eq!(c.pop(), None);
    }

    #[test]
    fn an_overflow_event_comes_before_a_later_bucket_once_the_window_reaches_it() {
        // 4 buckets of width 1. Ball 0 at t = 5.5 starts in the overflow (bucket 5 >= 0 + 4).
        // After popping t = 2.5, the window is (2, 6): ball 0 must pop before ball 1 at 5.9,
        // which was scheduled into a bucket list after the cursor moved.
        let mut c = Calendar::<f64>::new(3, 4, 1.0, 0.0);
        c.schedule(0, 5.5);
        c.schedule(2, 2.5);
        assert_eq!(c.pop(), Some((2, 2.5)));
        c.schedule(1, 5.9);
        assert_eq!(c.pop(), Some((0, 5.5)));
        assert_eq!(c.pop(), Some((1, 5.9)));
    }

    #[test]
    fn huge_times_wait_in_the_overflow_and_come_back_in_order() {
        let mut c = Calendar::<f64>::new(4, 8, 1e-3, 0.0);
        c.schedule(3, 1e300);
        c.schedule(2, 1e9);
        c.schedule(1, 0.0105);
        c.schedule(0, 1e9);
        assert_eq!(c.pop(), Some((1, 0.0105)));
        assert_eq!(c.pop(), Some((0, 1e9)));
        assert_eq!(c.pop(), Some((2, 1e9)));
        assert_eq!(c.pop(), Some((3, 1e300)));
        assert!(c.is_empty());
    }
}
