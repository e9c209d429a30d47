//! Telling a free ball **wedged** between contacts that keep answering each other at one
//! instant, so that the engine solves them together instead.
//!
//! Contacts are answered one at a time. A ball pressed between two others, or between a
//! ball and a wall, is answered by one contact, which sends it into the other, which sends
//! it back, and so on. Without friction the approach shrinks geometrically and the chain
//! ends within rounding; with friction a driving body (a heavy ball spinning against a
//! light one on a wall) feeds every round a little tangential velocity that the next
//! contact turns into a new approach, and the chain settles at a fixed approach instead
//! of shrinking: fuzzed scenes ran the event budget out, a million contacts per step, all
//! within 1e-11 s. A ball with more than [`WEDGE_CONTACTS`] contacts within
//! [`Repeats::note`]'s tolerance of one instant is held as a stack (see `stack`): all its
//! touching contacts at once, with the free balls it touches and theirs, restitution 0
//! with friction, which leaves none of them approaching. The same holds a light ball
//! squeezed between heavy ones (a 1 mg ball between two 1 kg balls and a floor), which
//! one contact at a time passes on a millionth of the push per contact.
//!
//! Contacts that answer each other need not fall within one instant of the step: far
//! from the origin a squeeze answers them as far apart as its bodies take to move by the
//! resolution of their coordinates (a ball pressed by a moving box into a corner 5e4 m
//! from the origin met its three surfaces in turn every 1.2e-12 s, never 256 within
//! `1e-9 h`, and sank 13 mm into the box over a few steps). So a ball is wedged too when
//! more than [`WEDGE_CONTACTS`] contacts follow each other, each within a *link* of the
//! one before: the instant, or the time its contact's bodies take to move by that
//! resolution, whichever is longer.
//!
//! No impulse frees a ball **crushed** by a kinematic box against the border, a static
//! box or another kinematic box when the surfaces close on it from every side it could
//! leave by (a box coming down parallel to the floor, or into a corner): the contacts
//! come back however they are answered. A ball past [`CRUSH_CONTACTS`] contacts at one
//! instant ends the run with an error naming it, as the event engine does for a cascade
//! that does not end, instead of spending the event budget (a million contacts, tens of
//! seconds) on every step. A box closing on a ball at a slant squeezes it out sideways
//! (the wedge's hold finds that), which is no crush.

use carom_math::Real;

use crate::prefetch::prefetch;

/// Contacts of one ball at one instant beyond which it is wedged. Elastic chains end in
/// far fewer: a column of `k` balls settles in `k(k+1)/2` contacts, `k` for each ball.
pub(crate) const WEDGE_CONTACTS: u32 = 256;

/// Contacts of one ball at one instant beyond which it is crushed: 64 times the wedge
/// limit, so that a wedge is held many times first.
pub(crate) const CRUSH_CONTACTS: u32 = 64 * WEDGE_CONTACTS;

/// What a ball's contacts at one instant say about it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Repeat {
    /// No more than [`WEDGE_CONTACTS`]: answered one at a time.
    Free,
    /// Wedged: to be held with all its contacts at once.
    Wedged,
    /// Crushed: no impulse frees it.
    Crushed,
}

/// One ball's record in [`Repeats`]: the instant its recent contacts cluster around and
/// how many it had there, and the time of its last contact and how many it has had in a
/// chain, each within a link (`note`'s `link`) of the one before. One record per ball
/// (not one array per field) so that a contact reads one cache line of each ball, which
/// the event loop prefetches ([`Repeats::prefetch`]).
#[derive(Clone, Copy, Debug, Default)]
struct Record<T> {
    anchor: T,
    last: T,
    count: u32,
    chain: u32,
}

/// Per ball, the instant its recent contacts cluster around and how many it had there.
#[derive(Clone, Debug, Default)]
pub(crate) struct Repeats<T> {
    records: Vec<Record<T>>,
    /// The balls with a non-zero count (to forget in [`Self::clear`]).
    noted: Vec<u32>,
}

impl<T: Real> Repeats<T> {
    /// No contacts yet, for `n` balls.
    pub(crate) fn new(n: usize) -> Self {
        Self {
            records: vec![Record::default(); n],
            noted: Vec::new(),
        }
    }

    /// Forgets every contact (at the start of a step).
    pub(crate) fn clear(&mut self) {
        for &i in &self.noted {
            let record = &mut self.records[i as usize];
            record.count = 0;
            record.chain = 0;
        }
        self.noted.clear();
    }

    /// Prefetches ball `i`'s record (see `prefetch`).
    pub(crate) fn prefetch(&self, i: usize) {
        prefetch(&self.records[i]);
    }

    /// Notes a contact of ball `i` at in-step time `s` and tells what its contacts within
    /// `tolerance` of the first of them say (a contact further away starts a new
    /// instant), and its chain of contacts each within `link` of the one before: a chain
    /// longer than [`WEDGE_CONTACTS`] wedges it too.
    pub(crate) fn note(&mut self, i: usize, s: T, tolerance: T, link: T) -> Repeat {
        let record = &mut self.records[i];
        let fresh = record.count == 0;
        if fresh {
            self.noted.push(i as u32);
        }
        if fresh || (s - record.anchor).abs() > tolerance {
            record.anchor = s;
            record.count = 1;
        } else {
            record.count = record.count.saturating_add(1);
        }
        if fresh || (s - record.last).abs() > link {
            record.chain = 1;
        } else {
            record.chain = record.chain.saturating_add(1);
        }
        record.last = s;
        match (record.count, record.chain) {
            (c, _) if c > CRUSH_CONTACTS => Repeat::Crushed,
            (c, k) if c > WEDGE_CONTACTS || k > WEDGE_CONTACTS => Repeat::Wedged,
            _ => Repeat::Free,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ball_is_wedged_then_crushed_after_the_limits_of_contacts_at_one_instant() {
        let mut r = Repeats::<f64>::new(2);
        for k in 0..WEDGE_CONTACTS {
            let s = 0.5 + f64::from(k) * 1e-15;
            assert_eq!(r.note(0, s, 1e-9, 1e-9), Repeat::Free, "contact {k}");
        }
        for k in WEDGE_CONTACTS..CRUSH_CONTACTS {
            let s = 0.5 + f64::from(k) * 1e-15;
            assert_eq!(r.note(0, s, 1e-9, 1e-9), Repeat::Wedged, "contact {k}");
        }
        assert_eq!(r.note(0, 0.5 + 1e-12, 1e-9, 1e-9), Repeat::Crushed);
        // The other ball has its own count.
        assert_eq!(r.note(1, 0.5, 1e-9, 1e-9), Repeat::Free);
    }

    #[test]
    fn contacts_at_separate_instants_and_a_new_step_start_afresh() {
        let mut r = Repeats::<f64>::new(1);
        // A ball rattling between walls: many contacts, each one instant apart.
        for k in 0..2 * CRUSH_CONTACTS {
            assert_eq!(r.note(0, f64::from(k) * 1e-6, 1e-9, 1e-9), Repeat::Free);
        }
        for _ in 0..WEDGE_CONTACTS {
            r.note(0, 0.25, 1e-9, 1e-9);
        }
        r.clear();
        assert_eq!(r.note(0, 0.25, 1e-9, 1e-9), Repeat::Free);
    }

    #[test]
    fn a_chain_of_contacts_each_within_a_link_of_the_last_wedges_the_ball() {
        // Contacts 1.2e-12 apart, never two within an instant of 1e-12 of the first of
        // them: free one at a time, wedged once the chain's links (1e-10) hold them.
        let mut separate = Repeats::<f64>::new(1);
        let mut chained = Repeats::<f64>::new(1);
        for k in 0..4 * WEDGE_CONTACTS {
            let s = 0.5 + f64::from(k) * 1.2e-12;
            assert_eq!(
                separate.note(0, s, 1e-12, 1e-12),
                Repeat::Free,
                "contact {k}"
            );
            let expected = if k < WEDGE_CONTACTS {
                Repeat::Free
            } else {
                Repeat::Wedged
            };
            assert_eq!(chained.note(0, s, 1e-12, 1e-10), expected, "contact {k}");
        }
        // A chain never crushes on its own: that takes contacts at one instant.
        assert_eq!(chained.note(0, 0.5 + 1e-6, 1e-12, 1e-3), Repeat::Wedged);
    }
}
