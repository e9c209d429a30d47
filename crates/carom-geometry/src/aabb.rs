//! The axis-aligned box: the broad phase's bounding volume and a static shape.

use carom_math::{InvalidValue, Problem, Real, Vector, ensure_finite_vector, ensure_non_negative};

/// An axis-aligned box `[min, max]` (a rectangle in 2D).
///
/// Invariants (checked by [`Aabb::new`]): both corners finite, `min[i] <= max[i]`.
/// Zero-size boxes (points, segments, faces) are valid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb<T: Real, const D: usize> {
    min: Vector<T, D>,
    max: Vector<T, D>,
}

impl<T: Real, const D: usize> Aabb<T, D> {
    /// The box with corners `min` and `max`.
    ///
    /// # Errors
    /// `min[i]` / `max[i]` if not finite; `min[i]` with [`Problem::Inverted`] if
    /// `min[i] > max[i]`.
    pub fn new(min: Vector<T, D>, max: Vector<T, D>) -> Result<Self, InvalidValue> {
        ensure_finite_vector("min", &min)?;
        ensure_finite_vector("max", &max)?;
        if let Some(i) = (0..D).find(|&i| min[i] > max[i]) {
            return Err(InvalidValue::new(
                format!("min[{i}]"),
                Problem::Inverted {
                    min: min[i].to_f64(),
                    max: max[i].to_f64(),
                },
            ));
        }
        Ok(Self { min, max })
    }

    /// The box centred at `center` with half extents `half_extents` (each `>= 0`).
    ///
    /// # Errors
    /// `center[i]` if not finite; `half_extents[i]` if not finite or negative.
    pub fn from_center_half_extents(
        center: Vector<T, D>,
        half_extents: Vector<T, D>,
    ) -> Result<Self, InvalidValue> {
        ensure_finite_vector("center", &center)?;
        for i in 0..D {
            ensure_non_negative("half_extents", half_extents[i])
                .map_err(|e| InvalidValue::new(format!("half_extents[{i}]"), e.problem))?;
        }
        Ok(Self::new_unchecked(
            center - half_extents,
            center + half_extents,
        ))
    }

    /// A box from corners the caller has already validated (hot paths).
    #[inline]
    pub fn new_unchecked(min: Vector<T, D>, max: Vector<T, D>) -> Self {
        debug_assert!((0..D).all(|i| min[i] <= max[i] && min[i].finite() && max[i].finite()));
        Self { min, max }
    }

    /// The smallest box containing every point, or [`Problem::Empty`] for no points.
    ///
    /// # Errors
    /// `points` if empty; `points[k][i]` if a coordinate is not finite.
    pub fn from_points(points: &[Vector<T, D>]) -> Result<Self, InvalidValue> {
        let (first, rest) = points
            .split_first()
            .ok_or(InvalidValue::new("points", Problem::Empty))?;
        let check = |k: usize, p: &Vector<T, D>| {
            ensure_finite_vector("p", p)
                .map_err(|e| InvalidValue::new(format!("points[{k}]{}", &e.field[1..]), e.problem))
        };
        check(0, first)?;
        let (mut lo, mut hi) = (*first, *first);
        for (k, p) in rest.iter().enumerate() {
            check(k + 1, p)?;
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        Ok(Self { min: lo, max: hi })
    }

    /// The lower corner.
    #[inline]
    pub fn min(&self) -> Vector<T, D> {
        self.min
    }

    /// The upper corner.
    #[inline]
    pub fn max(&self) -> Vector<T, D> {
        self.max
    }

    /// `max − min`.
    #[inline]
    pub fn extents(&self) -> Vector<T, D> {
        self.max - self.min
    }

    /// `true` if `p` is inside or on the boundary.
    #[inline]
    pub fn contains_point(&self, p: &Vector<T, D>) -> bool {
        (0..D).all(|i| self.min[i] <= p[i] && p[i] <= self.max[i])
    }

    /// The box moved by `offset`.
    #[inline]
    #[must_use]
    pub fn translated(&self, offset: &Vector<T, D>) -> Self {
        Self {
            min: self.min + offset,
            max: self.max + offset,
        }
    }

    /// The corners, `2^D` of them; corner `k` takes `max[i]` where bit `i` of `k` is set.
    pub fn corners(&self) -> impl Iterator<Item = Vector<T, D>> + '_ {
        (0..1usize << D).map(move |k| {
            Vector::<T, D>::from_fn(|i, _| {
                if k >> i & 1 == 1 {
                    self.max[i]
                } else {
                    self.min[i]
                }
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn rejects_inverted_and_non_finite_corners_naming_the_component() {
        let e = Aabb::new(Vector2::new(0.0, 1.0), Vector2::new(1.0, 0.0)).unwrap_err();
        assert_eq!(e.field, "min[1]");
        assert_eq!(e.to_string(), "min[1]: lower bound 1 exceeds upper bound 0");
        assert_eq!(
            Aabb::new(Vector2::new(f64::NAN, 0.0), Vector2::new(1.0, 1.0))
                .unwrap_err()
                .field,
            "min[0]"
        );
        let e = Aabb::from_center_half_extents(Vector3::zeros(), Vector3::new(1.0, -1.0, 0.0))
            .unwrap_err();
        assert_eq!(e.field, "half_extents[1]");
    }

    #[test]
    fn zero_size_boxes_are_valid() {
        let p = Aabb::new(Vector3::new(1.0, 2.0, 3.0), Vector3::new(1.0, 2.0, 3.0)).unwrap();
        assert!(p.contains_point(&Vector3::new(1.0, 2.0, 3.0)));
        assert_eq!(p.corners().count(), 8);
    }

    #[test]
    fn from_points_is_the_componentwise_hull() {
        let pts = [
            Vector2::new(1.0, 5.0),
            Vector2::new(-2.0, 0.5),
            Vector2::new(0.0, 7.0),
        ];
        let a = Aabb::from_points(&pts).unwrap();
        assert_eq!(a.min(), Vector2::new(-2.0, 0.5));
        assert_eq!(a.max(), Vector2::new(1.0, 7.0));
        assert_eq!(
            Aabb::<f64, 2>::from_points(&[]).unwrap_err().problem,
            Problem::Empty
        );
        let bad = [Vector2::new(0.0, 0.0), Vector2::new(0.0, f64::INFINITY)];
        assert_eq!(Aabb::from_points(&bad).unwrap_err().field, "points[1][1]");
    }

    #[test]
    fn corners_enumerate_every_combination() {
        let a = Aabb::new(Vector2::new(0.0, 0.0), Vector2::new(1.0, 2.0)).unwrap();
        let c: Vec<_> = a.corners().collect();
        assert_eq!(
            c,
            vec![
                Vector2::new(0.0, 0.0),
                Vector2::new(1.0, 0.0),
                Vector2::new(0.0, 2.0),
                Vector2::new(1.0, 2.0)
            ]
        );
    }
}
