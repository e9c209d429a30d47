//! What a query returns: a status, the signed time, the unit normal and the contact point.
//!
//! Never a bare float. Conventions shared by every query:
//!
//! * `time` is the signed offset from now: `>= 0` for [`Direction::Forward`], `<= 0` for
//!   [`Direction::Backward`](crate::Direction::Backward).
//! * `normal` is the unit contact normal at that time, pointing **from the first body to
//!   the second** (from a ball into the wall, from ball 1 to ball 2), the convention of
//!   `carom-response`'s `Contact` (normal from `a` to `b`).
//! * `point` is the contact point at that time, on the surface of the second body (the
//!   midpoint of the overlap for two balls).
//!
//! [`Direction::Forward`]: crate::Direction::Forward

use carom_math::{Real, Vector};

/// How a query ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Status {
    /// The bodies first touch at `time`, approaching (in the window's direction).
    Hit,
    /// At time 0 the bodies already touch or overlap and approach: the event is
    /// immediate (`time` is 0). Approaching means the gap decreases: a negative normal
    /// rate, or a zero normal rate with an acceleration that pushes them deeper (a ball
    /// set down on a floor under gravity, or sunk in a wall and falling further out, is
    /// caught). Touching with zero normal rate and no such acceleration (resting contact
    /// whose pressing the engine cancels) is not reported.
    AlreadyTouching,
    /// No contact within the window, or only receding or resting contacts. `time` is
    /// `±∞`, `normal` and `point` are zero. (A pair that starts overlapping and receding
    /// but turns back before it is apart is a [`Status::Hit`] at the turn.)
    NoHit,
    /// An iterative method (conservative advancement) ran out of steps, or an
    /// intermediate value overflowed. `time` is the signed time up to which the absence
    /// of contact is proven (0 if nothing is proven); `normal` and `point` are zero.
    NotConverged,
}

/// The result of a time-of-impact query, with the feature `F` that was hit
/// (`()` for two balls, a [`Wall`], a [`BoxFeature`], a cluster ball index, ...).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Toi<T: Real, const D: usize, F = ()> {
    /// How the query ended.
    pub status: Status,
    /// The signed time of the event (see the module conventions).
    pub time: T,
    /// The unit normal from the first body to the second at `time`.
    pub normal: Vector<T, D>,
    /// The contact point at `time`.
    pub point: Vector<T, D>,
    /// Which part of the bodies touches.
    pub feature: F,
}

impl<T: Real, const D: usize, F> Toi<T, D, F> {
    /// `Some(time)` for [`Status::Hit`] and [`Status::AlreadyTouching`].
    #[inline]
    pub fn hit_time(&self) -> Option<T> {
        matches!(self.status, Status::Hit | Status::AlreadyTouching).then_some(self.time)
    }

    /// `true` for [`Status::Hit`] and [`Status::AlreadyTouching`].
    #[inline]
    pub fn is_hit(&self) -> bool {
        self.hit_time().is_some()
    }

    pub(crate) fn no_hit(sign: T, feature: F) -> Self {
        Self {
            status: Status::NoHit,
            time: T::INFINITY * sign,
            normal: Vector::zeros(),
            point: Vector::zeros(),
            feature,
        }
    }

    pub(crate) fn not_converged(time: T, feature: F) -> Self {
        Self {
            status: Status::NotConverged,
            time,
            normal: Vector::zeros(),
            point: Vector::zeros(),
            feature,
        }
    }
}

/// One side of an axis or a plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// The lower side (`x < level`, or inside a half-space).
    Lower,
    /// The upper side (`x > level`, or the free side of a half-space).
    Upper,
}

/// A wall of a [`Border`](carom_geometry::Border): the lower or upper face on an axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Wall {
    /// The axis the wall is perpendicular to (0 = x, 1 = y, 2 = z).
    pub axis: usize,
    /// The lower (`min`) or upper (`max`) wall.
    pub side: Side,
}

/// Which feature of a box the ball touches: the closest point of the box lies on a
/// face, an edge (3D), or a corner.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BoxFeature {
    /// The ball's centre is inside the box itself (deep overlap at time 0).
    Inside,
    /// A face: the centre is outside the box's slab on one axis.
    Face,
    /// An edge (3D only): outside on two axes.
    Edge,
    /// A corner: outside on every axis.
    Corner,
}

impl BoxFeature {
    /// The feature of a `D`-dimensional box whose closest point is outside the slabs of
    /// `outside` axes.
    pub(crate) fn from_outside_axes(outside: usize, dimension: usize) -> Self {
        match outside {
            0 => BoxFeature::Inside,
            1 if dimension > 1 => BoxFeature::Face,
            n if n == dimension => BoxFeature::Corner,
            _ => BoxFeature::Edge,
        }
    }
}

/// When a point crosses a plane or a level (periodic cell faces): the first time its
/// centre moves to the other side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing<T: Real> {
    /// [`Status::Hit`] for a crossing, [`Status::NoHit`] for none within the window,
    /// [`Status::NotConverged`] if an intermediate value overflowed.
    pub status: Status,
    /// The signed crossing time (`±∞` for none).
    pub time: T,
    /// The side the centre moves into.
    pub to: Side,
}
