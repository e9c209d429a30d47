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
//!
//! An **elastic squeeze** is no wedge, however many contacts it takes at one instant: a
//! light ball of mass `m` between a wall and a ball of mass `M` closing on it is pumped
//! by every contact and sends the heavy ball back after about `π √(M/m)` of them, with
//! the energy kept (Galperin's billiard: in the coordinates `√m x` and `√M X` each
//! elastic contact is a mirror reflection off one side of a wedge of angle
//! `θ = atan √(m/M)`, and a path meets the sides of such a wedge `⌈π/θ⌉ − 1` times).
//! Near the turn the contacts crowd into one instant (1 g pumped by 1e5 kg at 1e5 m/s
//! from 0.08 m off the wall: its speed times the gap is about kept, so it reaches about
//! 1e9 m/s in a gap of about 2e-5 m, and the contacts come about 3e-14 s apart), and a
//! hold at the wedge limit of 256 took the heavy ball's energy
//! (5e14 J to 0.43 J). So a ball's limit is [`wedge_limit`] of the largest mass ratio
//! among its elastic ball contacts (pair restitution 1) since its count began: an
//! inelastic squeeze ends only in the hold (a collapse), whose answer it is, and takes
//! [`WEDGE_CONTACTS`] as before. The limit is `4 √(M/m)`, at least
//! [`WEDGE_CONTACTS`] and at most [`MAX_WEDGE_CONTACTS`] (a ratio of 2.7e8; beyond it a
//! squeeze is still held with restitution 0, and loses its energy). The crush limit
//! moves with it, [`CRUSH_CONTACTS`] − [`WEDGE_CONTACTS`] contacts beyond.

use carom_math::Real;

use crate::prefetch::prefetch;

/// Contacts of one ball at one instant beyond which it is wedged. Elastic chains end in
/// far fewer: a column of `k` balls settles in `k(k+1)/2` contacts, `k` for each ball.
pub(crate) const WEDGE_CONTACTS: u32 = 256;

/// Contacts of one ball at one instant beyond which it is crushed: 64 times the wedge
/// limit, so that a wedge is held many times first.
pub(crate) const CRUSH_CONTACTS: u32 = 64 * WEDGE_CONTACTS;

/// Contacts per square root of the mass ratio allowed before a ball is wedged: an
/// elastic squeeze takes `π` (see the [module documentation](self)), and this leaves it a
/// quarter more.
const CONTACTS_PER_ROOT_OF_MASS_RATIO: f64 = 4.0;

/// The most contacts of one ball at one instant before it is wedged, whatever the mass
/// ratio: an elastic squeeze of a ratio up to `(MAX_WEDGE_CONTACTS / 4)²`, 2.7e8, runs
/// to its end. It bounds what one squeeze costs its step: Galperin's 31,415 contacts
/// (a ratio of 1e8) took 0.04 to 0.08 s of `carom run`'s wall time on this project's VM.
pub(crate) const MAX_WEDGE_CONTACTS: u32 = 65_536;

/// The wedge limit for a contact between balls whose masses differ by `ratio` (the
/// heavier's over the lighter's, at least 1): `4 √ratio` contacts, clamped to
/// [`WEDGE_CONTACTS`] and [`MAX_WEDGE_CONTACTS`].
pub(crate) fn wedge_limit(ratio: f64) -> u32 {
    let pumped = CONTACTS_PER_ROOT_OF_MASS_RATIO * ratio.sqrt();
    if pumped >= f64::from(MAX_WEDGE_CONTACTS) {
        MAX_WEDGE_CONTACTS
    } else if pumped > f64::from(WEDGE_CONTACTS) {
        pumped.ceil() as u32
    } else {
        // Also a NaN ratio (no ball has one: masses are positive and finite).
        WEDGE_CONTACTS
    }
}

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
    /// The wedge limit of the contacts since the count or the chain began (the larger
    /// of theirs).
    limit: u32,
}

impl<T> Record<T> {
    /// Contacts at one instant beyond which the ball is crushed.
    fn crush_limit(&self) -> u32 {
        self.limit.saturating_add(CRUSH_CONTACTS - WEDGE_CONTACTS)
    }
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

    /// Notes a contact of ball `i` at in-step time `s` whose wedge limit is `limit` (see
    /// [`wedge_limit`]) and tells what its contacts within `tolerance` of the first of
    /// them say (a contact further away starts a new instant), and its chain of contacts
    /// each within `link` of the one before: a chain longer than the limit wedges it
    /// too. The limit is the largest of the contacts since the count or the chain began.
    pub(crate) fn note(&mut self, i: usize, s: T, tolerance: T, link: T, limit: u32) -> Repeat {
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
        record.limit = if record.count == 1 && record.chain == 1 {
            limit
        } else {
            record.limit.max(limit)
        };
        match (record.count, record.chain) {
            (c, _) if c > record.crush_limit() => Repeat::Crushed,
            (c, k) if c > record.limit || k > record.limit => Repeat::Wedged,
            _ => Repeat::Free,
        }
    }

    /// Contacts at one instant beyond which ball `i` is crushed now.
    pub(crate) fn crush_limit(&self, i: usize) -> u32 {
        self.records[i].crush_limit()
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
            assert_eq!(
                r.note(0, s, 1e-9, 1e-9, WEDGE_CONTACTS),
                Repeat::Free,
                "contact {k}"
            );
        }
        for k in WEDGE_CONTACTS..CRUSH_CONTACTS {
            let s = 0.5 + f64::from(k) * 1e-15;
            assert_eq!(
                r.note(0, s, 1e-9, 1e-9, WEDGE_CONTACTS),
                Repeat::Wedged,
                "contact {k}"
            );
        }
        assert_eq!(
            r.note(0, 0.5 + 1e-12, 1e-9, 1e-9, WEDGE_CONTACTS),
            Repeat::Crushed
        );
        // The other ball has its own count.
        assert_eq!(r.note(1, 0.5, 1e-9, 1e-9, WEDGE_CONTACTS), Repeat::Free);
    }

    #[test]
    fn the_wedge_limit_grows_with_the_square_root_of_the_mass_ratio_within_its_bounds() {
        assert_eq!(wedge_limit(1.0), WEDGE_CONTACTS);
        assert_eq!(wedge_limit(4096.0), WEDGE_CONTACTS);
        assert_eq!(wedge_limit(1e6), 4000);
        // Galperin's 31,415 contacts at a ratio of 1e8 fit, with a quarter to spare.
        assert_eq!(wedge_limit(1e8), 40_000);
        assert_eq!(wedge_limit(1e12), MAX_WEDGE_CONTACTS);
        assert_eq!(wedge_limit(f64::INFINITY), MAX_WEDGE_CONTACTS);
        assert_eq!(wedge_limit(f64::NAN), WEDGE_CONTACTS);
    }

    #[test]
    fn a_raised_limit_lasts_while_the_contacts_crowd_and_moves_the_crush_limit_with_it() {
        let mut r = Repeats::<f64>::new(1);
        let limit = 4000;
        // Its first contact raises the limit; the wall contacts between keep it.
        for k in 0..limit {
            let (s, own) = (
                0.5 + f64::from(k) * 1e-15,
                [limit, WEDGE_CONTACTS][k as usize % 2],
            );
            assert_eq!(r.note(0, s, 1e-9, 1e-9, own), Repeat::Free, "contact {k}");
        }
        assert_eq!(r.note(0, 0.5, 1e-9, 1e-9, WEDGE_CONTACTS), Repeat::Wedged);
        assert_eq!(r.crush_limit(0), limit + CRUSH_CONTACTS - WEDGE_CONTACTS);
        for _ in limit + 1..r.crush_limit(0) {
            assert_eq!(r.note(0, 0.5, 1e-9, 1e-9, WEDGE_CONTACTS), Repeat::Wedged);
        }
        assert_eq!(r.note(0, 0.5, 1e-9, 1e-9, WEDGE_CONTACTS), Repeat::Crushed);
        // A contact at another instant, beyond the chain's link, starts with its own limit.
        assert_eq!(r.note(0, 0.75, 1e-9, 1e-9, WEDGE_CONTACTS), Repeat::Free);
        for _ in 1..WEDGE_CONTACTS {
            r.note(0, 0.75, 1e-9, 1e-9, WEDGE_CONTACTS);
        }
        assert_eq!(r.note(0, 0.75, 1e-9, 1e-9, WEDGE_CONTACTS), Repeat::Wedged);
    }

    #[test]
    fn contacts_at_separate_instants_and_a_new_step_start_afresh() {
        let mut r = Repeats::<f64>::new(1);
        // A ball rattling between walls: many contacts, each one instant apart.
        for k in 0..2 * CRUSH_CONTACTS {
            assert_eq!(
                r.note(0, f64::from(k) * 1e-6, 1e-9, 1e-9, WEDGE_CONTACTS),
                Repeat::Free
            );
        }
        for _ in 0..WEDGE_CONTACTS {
            r.note(0, 0.25, 1e-9, 1e-9, WEDGE_CONTACTS);
        }
        r.clear();
        assert_eq!(r.note(0, 0.25, 1e-9, 1e-9, WEDGE_CONTACTS), Repeat::Free);
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
                separate.note(0, s, 1e-12, 1e-12, WEDGE_CONTACTS),
                Repeat::Free,
                "contact {k}"
            );
            let expected = if k < WEDGE_CONTACTS {
                Repeat::Free
            } else {
                Repeat::Wedged
            };
            assert_eq!(
                chained.note(0, s, 1e-12, 1e-10, WEDGE_CONTACTS),
                expected,
                "contact {k}"
            );
        }
        // A chain never crushes on its own: that takes contacts at one instant.
        assert_eq!(
            chained.note(0, 0.5 + 1e-6, 1e-12, 1e-3, WEDGE_CONTACTS),
            Repeat::Wedged
        );
    }
}
