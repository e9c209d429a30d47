//! What the balls bounce off: the border (reflecting or periodic) and the boxes (static,
//! kinematic at constant velocity, or driven by a velocity set from Rust each step).
//!
//! A box does not rotate. Within a step it moves at its velocity for the step, so at
//! in-step time `s` it is its step-start box translated by `vel · s`. Its centre at
//! the end of the step is recomputed from the time its velocity was last set (`k·dt`
//! style, no running sum), so a box at constant velocity does not drift.

use carom_geometry::{Aabb, Border, Obb};
use carom_math::{Real, Vector};

use crate::scene::BoxSpec;

/// The boxes, struct of arrays.
#[derive(Clone, Debug)]
pub(crate) struct BoxArrays<T: Real, const D: usize> {
    /// Each box at the start of the current step.
    pub(crate) shape: Vec<Obb<T, D>>,
    /// Velocity during the current step (internal orientation: negated in a backward run).
    pub(crate) vel: Vec<Vector<T, D>>,
    /// Ball–box restitution.
    pub(crate) restitution: Vec<T>,
    /// Where each box's current motion started: centre and internal time.
    anchor: Vec<(Vector<T, D>, T)>,
}

impl<T: Real, const D: usize> BoxArrays<T, D> {
    /// The boxes of a scene; `sign` orients their velocities (−1 in a backward run).
    pub(crate) fn new(specs: &[BoxSpec<T, D>], sign: T) -> Self {
        Self {
            shape: specs.iter().map(|b| b.shape).collect(),
            vel: specs.iter().map(|b| b.vel * sign).collect(),
            restitution: specs.iter().map(|b| b.restitution).collect(),
            anchor: specs
                .iter()
                .map(|b| (b.shape.center(), T::zero()))
                .collect(),
        }
    }

    /// The number of boxes.
    pub(crate) fn len(&self) -> usize {
        self.shape.len()
    }

    /// Box `k` at in-step time `s`.
    pub(crate) fn at(&self, k: usize, s: T) -> Obb<T, D> {
        self.shape[k].translated(&(self.vel[k] * s))
    }

    /// From `x` towards the nearest point of box `k` at in-step time `s` (of its periodic
    /// image nearest `x` in a `periodic` border): the unit direction and the distance;
    /// `None` when `x` is inside the box.
    pub(crate) fn nearest(
        &self,
        k: usize,
        s: T,
        x: &Vector<T, D>,
        periodic: Option<&Border<T, D>>,
    ) -> Option<(Vector<T, D>, T)> {
        let obb = self.at(k, s);
        let shift = periodic.map_or_else(Vector::zeros, |border| {
            border.minimum_image(&(obb.center() - x)) - (obb.center() - x)
        });
        // In the box's frame, as the time of impact takes it (carom-toi's `ball_obb`):
        // at a face the offset to the nearest point has one non-zero coordinate, and the
        // normal is the face's axis exactly, not the direction between two points each
        // rounded to the world coordinates' resolution (known only to `ρ / r`: a 23 g ball
        // sliding at 3,000 m/s along a box 1,000 m out, held along such a normal, was
        // found approaching along the time of impact's at 5.7e-8 m/s, 16,384 times).
        let local = obb.to_local(&(x - shift));
        let half = obb.half_extents();
        let offset = local.inf(&half).sup(&-half) - local;
        let d = offset.norm();
        (d > T::zero()).then(|| (obb.vector_to_world(&(offset / d)), d))
    }

    /// The box swept by box `k` over the in-step times `[a, b]`.
    pub(crate) fn swept(&self, k: usize, a: T, b: T) -> Aabb<T, D> {
        let (p, q) = (self.at(k, a).aabb(), self.at(k, b).aabb());
        Aabb::new_unchecked(p.min().inf(&q.min()), p.max().sup(&q.max()))
    }

    /// Whether any box moves.
    pub(crate) fn any_moving(&self) -> bool {
        self.vel.iter().any(|v| *v != Vector::<T, D>::zeros())
    }

    /// Sets the velocity of box `k` from internal time `now` on.
    pub(crate) fn set_velocity(&mut self, k: usize, vel: Vector<T, D>, now: T) {
        self.anchor[k] = (self.shape[k].center(), now);
        self.vel[k] = vel;
    }

    /// Moves every box to internal time `now` (the end of a step), wrapping centres into
    /// a periodic `border` if given.
    pub(crate) fn advance(&mut self, now: T, periodic: Option<&Border<T, D>>) {
        for k in 0..self.shape.len() {
            let (origin, since) = self.anchor[k];
            let mut center = origin + self.vel[k] * (now - since);
            if let Some(border) = periodic {
                let wrapped = border.wrap(&center);
                if wrapped != center {
                    self.anchor[k] = (origin + (wrapped - center), since);
                    center = wrapped;
                }
            }
            let shift = center - self.shape[k].center();
            self.shape[k] = self.shape[k].translated(&shift);
        }
    }
}

/// The offsets of the periodic images of a cell to try: every combination of
/// `−1, 0, +1` periods per axis (`3^D`), the home cell first.
pub(crate) fn image_offsets<T: Real, const D: usize>(
    border: &Border<T, D>,
) -> impl Iterator<Item = Vector<T, D>> + '_ {
    let count = 3usize.pow(D as u32);
    let period = border.extents();
    (0..count).map(move |code| {
        // code 0 is the home cell: digit 0 ↦ 0, 1 ↦ +1, 2 ↦ −1.
        let mut rest = code;
        Vector::<T, D>::from_fn(|k, _| {
            let digit = rest % 3;
            rest /= 3;
            match digit {
                0 => T::zero(),
                1 => period[k],
                _ => -period[k],
            }
        })
    })
}
