//! Piles: the free balls that touch each other at a step's start, found so that a large
//! one is held at once (`stack`'s [`Approach::Resting`](super::stack::Approach)) instead
//! of one contact at a time.
//!
//! Under gravity a ball resting on others closes on them at every step's start, and
//! answered one contact at a time a pile's contacts hold the pile again at each one:
//! once a hold has grouped its balls (`stack::Groups`), every contact of a grouped ball
//! holds the whole group again, and the group grows by one ball a contact. A 480-ball
//! pile made some 10,000 holds of 60 to 80 bodies a step, minutes a step. Held at the
//! step's start as one stack, its contacts leave the step's event loop nothing to
//! answer but what arrives from outside it.
//!
//! A pile here is a connected set of free balls, linked by pairs in resting contact at
//! the step's start, counted with their resting contacts with walls and boxes (the
//! contacts a hold takes in). A contact rests when it closes no faster than support
//! does (`support_speed`, twice what gravity adds in a step) and its gap is within
//! rounding of touching ([`touch_tolerance`]) or within what that speed closes in two
//! steps: a pile rests on gaps of nanometres to micrometres that gravity closes within
//! each step. A faster contact is an impact, answered in the step's event loop (a ball
//! landing on a held pile meets it as a surface, `Contacts::onto_pile`). Only piles of
//! more contacts than [`PILE_CONTACTS`] are held so: a smaller one is answered one
//! contact at a time as before, and its holds are the exact solves of `lcp`.

use carom_geometry::{Ball, Border};
use carom_math::{Real, Space};
use nalgebra::Const;

use super::balls::BallArrays;
use super::clusters::FREE;
use super::narrow::touch_tolerance;
use super::obstacles::BoxArrays;

/// Piles of more contacts than this are held at the step's start.
pub(super) const PILE_CONTACTS: usize = 64;

/// The piles of more than [`PILE_CONTACTS`] resting contacts at the start of a step of
/// length `h`, contacts closing no faster than `support_speed` (see the module
/// documentation), each pile as its balls in ascending order, the piles in the order of
/// their lowest ball.
///
/// `pairs` are the broad phase's pairs (`(i, j)` with `i < j`, indices from the number
/// of balls on boxes); only free balls take part.
pub(super) fn resting_piles<T: Real, const D: usize>(
    balls: &BallArrays<T, D>,
    boxes: &BoxArrays<T, D>,
    border: Option<&Border<T, D>>,
    periodic: Option<&Border<T, D>>,
    pairs: &[(u32, u32)],
    h: T,
    support_speed: T,
) -> Vec<Vec<usize>>
where
    Const<D>: Space<T, D>,
{
    let n = balls.len();
    let free = |i: usize| balls.cluster[i] == FREE;
    let reach = T::lit(2.0) * support_speed * h;
    // A resting contact: slow, and touching or within what support closes in two steps.
    let near = |i: usize, gap: T, closing: T| {
        closing <= support_speed
            && gap <= touch_tolerance(&balls.seg_x[i], balls.radius[i]).max(reach)
    };
    let mut root: Vec<u32> = (0..n as u32).collect();
    let mut contacts = vec![0_usize; n];
    for &(i, j) in pairs {
        let (i, j) = (i as usize, j as usize);
        // Box–box pairs too have both indices past the balls'.
        if i >= n || !free(i) {
            continue;
        }
        if j >= n {
            let k = j - n;
            let nearest = boxes.nearest(k, T::zero(), &balls.seg_x[i], periodic);
            if let Some((normal, d)) = nearest
                && near(
                    i,
                    d - balls.radius[i],
                    (balls.chord[i] - boxes.vel[k]).dot(&normal),
                )
            {
                contacts[i] += 1;
            }
            continue;
        }
        if !free(j) {
            continue;
        }
        let offset = balls.seg_x[j] - balls.seg_x[i];
        let offset = periodic.map_or(offset, |p| p.minimum_image(&offset));
        let distance = offset.norm();
        let gap = distance - balls.radius[i] - balls.radius[j];
        let closing = (balls.chord[i] - balls.chord[j]).dot(&offset) / distance;
        if distance > T::zero() && (near(i, gap, closing) || near(j, gap, closing)) {
            contacts[i] += 1;
            let (a, b) = (find(&mut root, i), find(&mut root, j));
            // The lower index is the root: the piles come out in a fixed order.
            root[a.max(b)] = a.min(b) as u32;
        }
    }
    if let Some(border) = border {
        for i in (0..n).filter(|&i| free(i)) {
            let gaps = border.wall_gaps(&Ball::new_unchecked(balls.seg_x[i], balls.radius[i]));
            let u = balls.chord[i];
            let walls = (gaps.iter().enumerate())
                .flat_map(|(axis, &(lo, hi))| [(lo, -u[axis]), (hi, u[axis])]);
            contacts[i] += walls
                .filter(|&(gap, closing)| near(i, gap, closing))
                .count();
        }
    }
    let mut total = vec![0_usize; n];
    for (i, &c) in contacts.iter().enumerate() {
        let r = find(&mut root, i);
        total[r] += c;
    }
    let mut piles: Vec<Vec<usize>> = Vec::new();
    let mut slot = vec![u32::MAX; n];
    for i in (0..n).filter(|&i| free(i)) {
        let r = find(&mut root, i);
        if total[r] <= PILE_CONTACTS {
            continue;
        }
        if slot[r] == u32::MAX {
            slot[r] = piles.len() as u32;
            piles.push(Vec::new());
        }
        piles[slot[r] as usize].push(i);
    }
    piles
}

/// The root of `i`'s set, halving the path on the way.
fn find(root: &mut [u32], mut i: usize) -> usize {
    while root[i] as usize != i {
        let parent = root[i] as usize;
        root[i] = root[parent];
        i = parent;
    }
    i
}
