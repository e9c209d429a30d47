//! The balls of the event-driven engine, stored lazily.
//!
//! Each ball keeps its centre, velocity and spin *at its own reference time* `tᵢ` (the
//! time of its last event), struct-of-arrays. Between events a ball flies on the
//! parabola `x(t) = xᵢ + vᵢ (t − tᵢ) + aᵢ (t − tᵢ)²/2` (a straight line without gravity), so
//! its state at any time is computed on demand and only written back ("synchronised")
//! when the ball takes part in an event (Lubachevsky's delayed states). A ball resting on
//! a surface flies with the tangential part of gravity only.
//!
//! Each ball also counts its collisions: an event predicted with partner `j` stores `j`'s
//! count, and is stale if `j` has collided since.

use carom_geometry::Border;
use carom_math::{Real, Space, Vector};
use nalgebra::Const;

use crate::engine::Angular;

/// What holds a resting ball.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Support {
    /// A border wall: axis and upper (`true`) or lower side.
    Wall { axis: usize, upper: bool },
    /// A face of box `k`: the box axis and side of the face.
    BoxFace { k: usize, axis: usize, upper: bool },
}

/// How a ball moves between events.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Mode {
    /// Ballistic flight under the world's gravity.
    Free,
    /// Resting on a support: the normal part of gravity is cancelled.
    Resting(Support),
    /// A member of stuck cluster `c`: its state follows the cluster.
    Stuck(usize),
}

/// The lazily advanced balls.
#[derive(Clone, Debug)]
pub(crate) struct Balls<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    pub(crate) pos: Vec<Vector<T, D>>,
    pub(crate) vel: Vec<Vector<T, D>>,
    pub(crate) spin: Vec<Angular<T, D>>,
    pub(crate) accel: Vec<Vector<T, D>>,
    pub(crate) t_ref: Vec<T>,
    pub(crate) radius: Vec<T>,
    pub(crate) mass: Vec<T>,
    /// The ball's own restitution override, if any.
    pub(crate) restitution: Vec<Option<T>>,
    pub(crate) count: Vec<u32>,
    /// When the ball last collided (for the collapse guard); −∞ if never.
    pub(crate) last_collision: Vec<T>,
    pub(crate) mode: Vec<Mode>,
}

impl<T: Real, const D: usize> Balls<T, D>
where
    Const<D>: Space<T, D>,
{
    pub(crate) fn len(&self) -> usize {
        self.pos.len()
    }

    /// The centre of ball `i` at time `t` (not wrapped into a periodic box).
    #[inline]
    pub(crate) fn position_at(&self, i: usize, t: T) -> Vector<T, D> {
        let s = t - self.t_ref[i];
        self.pos[i] + (self.vel[i] + self.accel[i] * (s * T::lit(0.5))) * s
    }

    /// The velocity of ball `i` at time `t`.
    #[inline]
    pub(crate) fn velocity_at(&self, i: usize, t: T) -> Vector<T, D> {
        self.vel[i] + self.accel[i] * (t - self.t_ref[i])
    }

    /// Writes ball `i`'s state at `t` back as its reference state, wrapping its centre
    /// into a periodic box.
    #[inline]
    pub(crate) fn sync(&mut self, i: usize, t: T, periodic: Option<&Border<T, D>>) {
        if self.t_ref[i] == t {
            return;
        }
        let p = self.position_at(i, t);
        self.vel[i] = self.velocity_at(i, t);
        self.pos[i] = match periodic {
            Some(b) => b.wrap(&p),
            None => p,
        };
        self.t_ref[i] = t;
    }
}
