//! Bounding volumes fitted to point sets.
//!
//! | volume | function | cost | quality |
//! |---|---|---|---|
//! | AABB | [`Aabb::from_points`] | one pass | exact |
//! | sphere, fast | [`ritter_sphere`] | three passes | at most ~5–20% larger than minimal |
//! | sphere, exact | [`minimal_sphere`] (Welzl, move-to-front) | expected linear | minimal |
//! | OBB | [`pca_obb`] (covariance eigenvectors) | two passes + a D×D eigenproblem | good for elongated sets |
//! | rectangle (2D) | [`min_area_rect`] (rotating calipers on the hull) | `n log n` | minimal area |
//! | hull (2D) | [`convex_hull`] (monotone chain) | `n log n` | exact up to orientation rounding |
//!
//! Every function rejects an empty set ([`Problem::Empty`](carom_math::Problem::Empty),
//! field `points`) and non-finite coordinates (field `points[k][i]`). Every fitted volume
//! contains every input point *as its own containment test computes it*
//! ([`BoundingSphere::contains_point`], [`PointQuery::contains_point`]): the final size is
//! measured from the final centre and axes over all points, so no rounding in the fit can
//! leave a point outside. Points far from the origin are fitted relative to the centre
//! of their bounding box, which keeps the precision of their relative positions.
//! Fitting allocates (a copy of the points for Welzl, the hull); the queries do not.
//!
//! [`PointQuery::contains_point`]: crate::query::PointQuery::contains_point
//! [`BoundingSphere::contains_point`]: crate::BoundingSphere::contains_point

mod calipers;
mod pca;
mod sphere;

pub use calipers::{convex_hull, min_area_rect};
pub use pca::pca_obb;
pub use sphere::{minimal_sphere, ritter_sphere};

use carom_math::{InvalidValue, Real, Rotation, Vector};

use crate::{Aabb, BoundingVolume, Obb};

/// The validated points' bounding box and its centre, the reference every fit subtracts.
fn reference<T: Real, const D: usize>(
    points: &[Vector<T, D>],
) -> Result<(Aabb<T, D>, Vector<T, D>), InvalidValue> {
    let bounds = Aabb::from_points(points)?;
    Ok((bounds, bounds.center()))
}

/// The oriented box with the given axes (columns of `rotation`) around all points: the
/// extents along each axis give the centre, then the half extents are the largest
/// `|Rᵀ (p − c)|` over the points, computed exactly as [`Obb::to_local`] computes it, so
/// every point passes the box's own containment test.
fn obb_with_axes<T: Real, const D: usize>(
    points: &[Vector<T, D>],
    rotation: Rotation<T, D>,
    reference: &Vector<T, D>,
) -> Result<Obb<T, D>, InvalidValue> {
    let mut lo = Vector::<T, D>::repeat(T::INFINITY);
    let mut hi = Vector::<T, D>::repeat(-T::INFINITY);
    for p in points {
        let local = rotation.inverse_transform_vector(&(p - reference));
        lo = lo.inf(&local);
        hi = hi.sup(&local);
    }
    let center = reference + rotation * ((lo + hi) * T::lit(0.5));
    let mut half = Vector::<T, D>::zeros();
    for p in points {
        half = half.sup(&rotation.inverse_transform_vector(&(p - center)).abs());
    }
    Obb::new(center, half, rotation)
}

#[cfg(test)]
mod tests {
    use super::*;
    use carom_math::Problem;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn every_fit_names_the_bad_point_and_rejects_empty_sets() {
        let bad = [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, f64::NAN, 0.0),
        ];
        assert_eq!(ritter_sphere(&bad).unwrap_err().field, "points[1][1]");
        assert_eq!(minimal_sphere(&bad).unwrap_err().field, "points[1][1]");
        assert_eq!(pca_obb(&bad).unwrap_err().field, "points[1][1]");
        let bad2 = [Vector2::new(f64::INFINITY, 0.0)];
        assert_eq!(min_area_rect(&bad2).unwrap_err().field, "points[0][0]");
        assert_eq!(convex_hull(&bad2).unwrap_err().field, "points[0][0]");
        let empty: [Vector2<f32>; 0] = [];
        assert_eq!(ritter_sphere(&empty).unwrap_err().problem, Problem::Empty);
        assert_eq!(minimal_sphere(&empty).unwrap_err().problem, Problem::Empty);
        assert_eq!(pca_obb(&empty).unwrap_err().problem, Problem::Empty);
        assert_eq!(min_area_rect(&empty).unwrap_err().problem, Problem::Empty);
        assert_eq!(convex_hull(&empty).unwrap_err().field, "points");
    }
}
