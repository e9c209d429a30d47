//! The border: the axis-aligned container balls bounce inside or wrap around.
//!
//! A reflecting border has `2·D` walls, the lower and upper face on each axis; a ball of
//! radius `r` inside it has its centre in `[min + r, max − r]`. A periodic border
//! identifies opposite faces: positions wrap into `[min, max)` and separations use the
//! minimum image. Whether a border reflects or wraps is the engine's choice; this type
//! gives the geometry both need.

use carom_math::{InvalidValue, Problem, Real, Vector};

use crate::{Aabb, Ball};

/// An axis-aligned container of positive size on every axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Border<T: Real, const D: usize> {
    bounds: Aabb<T, D>,
}

impl<T: Real, const D: usize> Border<T, D> {
    /// The container `[min, max]`.
    ///
    /// # Errors
    /// `min[i]` / `max[i]` if not finite; `min[i]` if `min[i] >= max[i]` (a container has
    /// room on every axis).
    pub fn new(min: Vector<T, D>, max: Vector<T, D>) -> Result<Self, InvalidValue> {
        let bounds = Aabb::new(min, max)?;
        if let Some(i) = (0..D).find(|&i| min[i] >= max[i]) {
            return Err(InvalidValue::new(
                format!("min[{i}]"),
                Problem::Inverted {
                    min: min[i].to_f64(),
                    max: max[i].to_f64(),
                },
            ));
        }
        if let Some(i) = (0..D).find(|&i| !(max[i] - min[i]).finite()) {
            return Err(InvalidValue::new(
                format!("max[{i}]"),
                Problem::NotFinite((max[i] - min[i]).to_f64()),
            ));
        }
        Ok(Self { bounds })
    }

    /// The container as a box.
    #[inline]
    pub fn bounds(&self) -> &Aabb<T, D> {
        &self.bounds
    }

    /// The lower corner.
    #[inline]
    pub fn min(&self) -> Vector<T, D> {
        self.bounds.min()
    }

    /// The upper corner.
    #[inline]
    pub fn max(&self) -> Vector<T, D> {
        self.bounds.max()
    }

    /// The edge lengths `max − min` (the periods of a periodic border).
    #[inline]
    pub fn extents(&self) -> Vector<T, D> {
        self.bounds.extents()
    }

    /// `true` if the whole ball is inside (touching a wall counts as inside).
    pub fn contains_ball(&self, ball: &Ball<T, D>) -> bool {
        self.wall_gaps(ball)
            .iter()
            .all(|&(lo, hi)| lo >= T::zero() && hi >= T::zero())
    }

    /// Per axis, the gaps from the ball's surface to the lower and the upper wall:
    /// `(c − r − min, max − c − r)`. A negative gap is a penetration (or, for a ball
    /// outside, how far outside it is).
    pub fn wall_gaps(&self, ball: &Ball<T, D>) -> [(T, T); D] {
        let (c, r) = (ball.center(), ball.radius());
        let (lo, hi) = (self.min(), self.max());
        core::array::from_fn(|i| (c[i] - r - lo[i], hi[i] - c[i] - r))
    }

    /// The smallest wall gap and the wall it belongs to: `(gap, axis, upper)`.
    pub fn nearest_wall(&self, ball: &Ball<T, D>) -> (T, usize, bool) {
        let gaps = self.wall_gaps(ball);
        let mut best = (gaps[0].0, 0, false);
        for (i, &(lo, hi)) in gaps.iter().enumerate() {
            if lo < best.0 {
                best = (lo, i, false);
            }
            if hi < best.0 {
                best = (hi, i, true);
            }
        }
        best
    }

    /// The periodic image of `p` in `[min, max)` on every axis.
    ///
    /// A point at most one period outside (a ball that just crossed a face) is shifted by
    /// one period with a comparison; only points farther away use the general
    /// `floor` formula.
    #[inline]
    pub fn wrap(&self, p: &Vector<T, D>) -> Vector<T, D> {
        let (lo, hi, len) = (self.min(), self.max(), self.extents());
        Vector::<T, D>::from_fn(|i, _| {
            let x = p[i];
            let near = if x < lo[i] {
                x + len[i]
            } else if x >= hi[i] {
                x - len[i]
            } else {
                return x;
            };
            if near >= lo[i] && near < hi[i] {
                return near;
            }
            let u = (x - lo[i]) / len[i];
            let mut y = lo[i] + (u - u.floor()) * len[i];
            // Rounding can land exactly on the upper face; that point is the lower face.
            if y >= hi[i] {
                y = lo[i];
            }
            y
        })
    }

    /// The minimum image of the separation `delta` in a periodic border: each
    /// component shifted by a whole number of periods into `[−L/2, L/2]` (see
    /// [`Period::minimum_image`]).
    #[inline]
    pub fn minimum_image(&self, delta: &Vector<T, D>) -> Vector<T, D> {
        self.period().minimum_image(delta)
    }

    /// The periods of the border taken as periodic, for many minimum images.
    #[inline]
    pub fn period(&self) -> Period<T, D> {
        let length = self.extents();
        Period {
            length,
            half: length * T::lit(0.5),
        }
    }
}

/// The periods of a periodic border and their halves: what a minimum image reads,
/// computed once ([`Border::period`]) for code that takes many.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Period<T: Real, const D: usize> {
    length: Vector<T, D>,
    half: Vector<T, D>,
}

impl<T: Real, const D: usize> Period<T, D> {
    /// The periods (the border's edge lengths).
    #[inline]
    pub fn length(&self) -> &Vector<T, D> {
        &self.length
    }

    /// The minimum image of the separation `delta`: each component shifted by a whole
    /// number of periods into `[−L/2, L/2]`.
    ///
    /// Separations of points inside the box are within one period, and are shifted with
    /// a comparison; only larger ones use `round`.
    #[inline]
    pub fn minimum_image(&self, delta: &Vector<T, D>) -> Vector<T, D> {
        Vector::<T, D>::from_fn(|i, _| {
            let (d, l, h) = (delta[i], self.length[i], self.half[i]);
            // For d > L/2, d − L > −L/2 always; it is the image if also d − L <= L/2.
            if d > h {
                if d - l <= h {
                    d - l
                } else {
                    d - l * (d / l).round()
                }
            } else if d < -h {
                if d + l >= -h {
                    d + l
                } else {
                    d - l * (d / l).round()
                }
            } else {
                d
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    fn play_area() -> Border<f64, 2> {
        Border::new(Vector2::new(-2.0, -1.0), Vector2::new(2.0, 1.0)).unwrap()
    }

    #[test]
    fn wall_gaps_and_containment() {
        let b = play_area();
        let ball = Ball::new(Vector2::new(1.5, 0.0), 0.5).unwrap();
        assert_eq!(b.wall_gaps(&ball), [(3.0, 0.0), (0.5, 0.5)]);
        assert!(b.contains_ball(&ball), "touching the wall is inside");
        assert_eq!(b.nearest_wall(&ball), (0.0, 0, true));
        let out = Ball::new(Vector2::new(1.8, 0.0), 0.5).unwrap();
        assert!(!b.contains_ball(&out));
    }

    #[test]
    fn a_border_needs_room_on_every_axis() {
        assert_eq!(
            Border::new(Vector2::new(0.0, 0.0), Vector2::new(1.0, 0.0))
                .unwrap_err()
                .field,
            "min[1]"
        );
        assert_eq!(
            Border::new(Vector2::new(-f64::MAX, 0.0), Vector2::new(f64::MAX, 1.0))
                .unwrap_err()
                .field,
            "max[0]"
        );
    }

    #[test]
    fn wrap_lands_in_the_half_open_box() {
        let b = Border::new(Vector3::new(0.0, 0.0, -1.0), Vector3::new(1.0, 2.0, 1.0)).unwrap();
        let w = b.wrap(&Vector3::new(1.25, -0.5, 3.0));
        assert!((w - Vector3::new(0.25, 1.5, -1.0)).norm() < 1e-15);
        assert_eq!(
            b.wrap(&Vector3::new(1.0, 2.0, 1.0)),
            Vector3::new(0.0, 0.0, -1.0)
        );
        // Just below the lower face by less than an ulp of the period.
        let w = b.wrap(&Vector3::new(-1e-17, 0.0, 0.0));
        assert!(w.x >= 0.0 && w.x < 1.0);
    }

    #[test]
    fn wrap_and_minimum_image_agree_with_the_floor_and_round_formulas() {
        let b = Border::new(Vector2::new(-1.5, 0.0), Vector2::new(2.5, 0.75)).unwrap();
        let len = b.extents();
        let mut x = -13.37_f64;
        while x < 13.0 {
            let p = Vector2::new(x, x * 0.61);
            let w = b.wrap(&p);
            for i in 0..2 {
                let u = (p[i] - b.min()[i]) / len[i];
                let reference = b.min()[i] + (u - u.floor()) * len[i];
                assert!(
                    (w[i] - reference).abs() < 1e-12 || (w[i] - reference).abs() > len[i] - 1e-12,
                    "{x}"
                );
                assert!(w[i] >= b.min()[i] && w[i] < b.max()[i]);
                let d = b.minimum_image(&p)[i];
                assert!(
                    (d - (p[i] - len[i] * (p[i] / len[i]).round())).abs() < 1e-12,
                    "{x}"
                );
            }
            x += 0.0173;
        }
    }

    #[test]
    fn minimum_image_is_the_shortest_periodic_separation() {
        let b = play_area();
        assert_eq!(
            b.minimum_image(&Vector2::new(3.5, -1.5)),
            Vector2::new(-0.5, 0.5)
        );
        assert_eq!(
            b.minimum_image(&Vector2::new(0.25, 0.75)),
            Vector2::new(0.25, 0.75)
        );
    }
}
