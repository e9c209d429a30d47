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
use crate::pages::Array;

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

/// What a prediction reads of each partner, in one record: its reference state and its
/// radius. Aligned to the cache line, the record of an `f64` ball is one line in 2D and
/// in 3D (48 and 64 bytes), so a partner's first read is one cache miss where separate
/// arrays cost one each (see `docs/event-engine.md` for the measured gain).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Motion<T: Real, const D: usize> {
    /// The centre at the reference time.
    pub(crate) pos: Vector<T, D>,
    /// The velocity at the reference time.
    pub(crate) vel: Vector<T, D>,
    /// The reference time: the time of the ball's last event.
    pub(crate) t_ref: T,
    pub(crate) radius: T,
}

/// What a collision's response reads and writes of a ball besides its motion, in one
/// record (one cache line for `f64` in 2D and 3D): where these were four arrays, a
/// collision cost a miss in each for both balls (see `docs/event-engine.md`).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Props<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    pub(crate) mass: T,
    /// The ball's own restitution override, if any.
    pub(crate) restitution: Option<T>,
    /// When the ball last collided (for the collapse guard); −∞ if never.
    pub(crate) last_collision: T,
    pub(crate) spin: Angular<T, D>,
}

/// The lazily advanced balls.
#[derive(Clone, Debug)]
pub(crate) struct Balls<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    pub(crate) motion: Array<Motion<T, D>>,
    pub(crate) props: Array<Props<T, D>>,
    /// The acceleration of each ball (read only when `accelerated`).
    pub(crate) accel: Array<Vector<T, D>>,
    /// `false` in a world without gravity, where every acceleration is zero: states are
    /// advanced without reading `accel`.
    pub(crate) accelerated: bool,
    pub(crate) count: Array<u32>,
    pub(crate) mode: Array<Mode>,
}

impl<T: Real, const D: usize> Balls<T, D>
where
    Const<D>: Space<T, D>,
{
    pub(crate) fn len(&self) -> usize {
        self.motion.len()
    }

    /// The acceleration of ball `i`.
    #[inline]
    pub(crate) fn accel(&self, i: usize) -> Vector<T, D> {
        if self.accelerated {
            self.accel[i]
        } else {
            Vector::zeros()
        }
    }

    /// The centre of ball `i` at time `t` (not wrapped into a periodic box).
    #[inline]
    pub(crate) fn position_at(&self, i: usize, t: T) -> Vector<T, D> {
        let m = &self.motion[i];
        let s = t - m.t_ref;
        if self.accelerated {
            m.pos + (m.vel + self.accel[i] * (s * T::lit(0.5))) * s
        } else {
            m.pos + m.vel * s
        }
    }

    /// The velocity of ball `i` at time `t`.
    #[inline]
    pub(crate) fn velocity_at(&self, i: usize, t: T) -> Vector<T, D> {
        let m = &self.motion[i];
        if self.accelerated {
            m.vel + self.accel[i] * (t - m.t_ref)
        } else {
            m.vel
        }
    }

    /// Writes ball `i`'s state at `t` back as its reference state, wrapping its centre
    /// into a periodic box.
    #[inline]
    pub(crate) fn sync(&mut self, i: usize, t: T, periodic: Option<&Border<T, D>>) {
        if self.motion[i].t_ref == t {
            return;
        }
        let p = self.position_at(i, t);
        let v = self.velocity_at(i, t);
        let m = &mut self.motion[i];
        m.vel = v;
        m.pos = match periodic {
            Some(b) => b.wrap(&p),
            None => p,
        };
        m.t_ref = t;
    }
}

#[cfg(test)]
mod tests {
    use super::{Motion, Props};

    #[test]
    fn a_balls_records_are_one_cache_line_each_for_f64_in_2d_and_3d() {
        for size in [
            core::mem::size_of::<Motion<f64, 2>>(),
            core::mem::size_of::<Motion<f64, 3>>(),
            core::mem::size_of::<Props<f64, 2>>(),
            core::mem::size_of::<Props<f64, 3>>(),
        ] {
            assert_eq!(size, 64);
        }
        assert_eq!(core::mem::align_of::<Motion<f64, 2>>(), 64);
        assert_eq!(core::mem::align_of::<Props<f64, 3>>(), 64);
    }
}
