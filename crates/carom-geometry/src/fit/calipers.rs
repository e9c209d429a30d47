//! The convex hull of a planar point set (monotone chain) and its minimum-area enclosing
//! rectangle (rotating calipers).

use carom_math::{InvalidValue, Problem, Real, Rotation, robust};
use nalgebra::{Matrix2, Vector2};

use crate::Obb;

use super::{obb_with_axes, reference};

/// `(a − o) × (b − o)`: positive when `o → a → b` turns counter-clockwise. The two
/// products are subtracted with Kahan's algorithm, so nearly collinear triples keep the
/// sign their rounded coordinate differences give.
#[inline]
fn turn<T: Real>(o: &Vector2<T>, a: &Vector2<T>, b: &Vector2<T>) -> T {
    let (u, v) = (a - o, b - o);
    robust::diff_of_products(u.x, v.y, u.y, v.x)
}

/// The convex hull in counter-clockwise order, starting at the lowest-x (then lowest-y)
/// point, without repeated or collinear points: one point for coincident input, two for
/// collinear input.
///
/// Andrew's monotone chain: sort the points by `(x, y)`, then build the lower and upper
/// chains, popping the last point while it does not make a strict left turn.
///
/// # Errors
/// `points` if empty; `points[k][i]` if a coordinate is not finite.
pub fn convex_hull<T: Real>(points: &[Vector2<T>]) -> Result<Vec<Vector2<T>>, InvalidValue> {
    crate::Aabb::from_points(points)?;
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| {
        (a.x, a.y)
            .partial_cmp(&(b.x, b.y))
            .unwrap_or(core::cmp::Ordering::Equal)
    });
    sorted.dedup();
    if sorted.len() < 3 {
        return Ok(sorted);
    }
    let mut hull: Vec<Vector2<T>> = Vec::with_capacity(2 * sorted.len());
    let chain = |hull: &mut Vec<Vector2<T>>, floor: usize, p: &Vector2<T>| {
        while hull.len() >= floor + 2
            && turn(&hull[hull.len() - 2], &hull[hull.len() - 1], p) <= T::zero()
        {
            hull.pop();
        }
        hull.push(*p);
    };
    for p in &sorted {
        chain(&mut hull, 0, p);
    }
    let lower_len = hull.len();
    for p in sorted.iter().rev().skip(1) {
        chain(&mut hull, lower_len - 1, p);
    }
    hull.pop(); // the first point again
    if hull.len() < 3 {
        // Every point was collinear: the hull is the segment between the extremes.
        hull = vec![sorted[0], sorted[sorted.len() - 1]];
    }
    Ok(hull)
}

/// The index after `i` on a closed polygon of `n` vertices.
#[inline]
fn next(i: usize, n: usize) -> usize {
    if i + 1 == n { 0 } else { i + 1 }
}

/// The minimum-area rectangle around a counter-clockwise convex polygon with at least
/// three vertices: the unit direction of its first axis.
///
/// Some minimum-area rectangle has a side on a hull edge (Freeman and Shapira, 1975), so
/// it suffices to try each edge direction `u` (with `v` its inward normal). For edge `i`,
/// the rectangle spans `[min u·p, max u·p] × [v·h_i, max v·p]`; the three extreme vertices
/// (max along `u`, max along `v`, min along `u`) only move forward around the hull as the
/// edge turns, so each is advanced from where it was (rotating calipers, Toussaint 1983):
/// `O(h)` for the whole sweep.
fn calipers_direction<T: Real>(hull: &[Vector2<T>]) -> Vector2<T> {
    let n = hull.len();
    let edge = |i: usize| (hull[next(i, n)] - hull[i]).normalize();
    let perp = |u: &Vector2<T>| Vector2::new(-u.y, u.x);
    let argmax = |f: &dyn Fn(&Vector2<T>) -> T| {
        (1..n).fold(0, |best, k| {
            if f(&hull[k]) > f(&hull[best]) {
                k
            } else {
                best
            }
        })
    };
    let advance = |mut k: usize, f: &dyn Fn(&Vector2<T>) -> T| {
        for _ in 0..n {
            if f(&hull[next(k, n)]) > f(&hull[k]) {
                k = next(k, n);
            } else {
                break;
            }
        }
        k
    };
    let u0 = edge(0);
    let (mut right, mut top, mut left) = (
        argmax(&|p| u0.dot(p)),
        argmax(&|p| perp(&u0).dot(p)),
        argmax(&|p| -u0.dot(p)),
    );
    let mut best = (T::INFINITY, u0);
    for i in 0..n {
        let u = edge(i);
        let v = perp(&u);
        right = advance(right, &|p| u.dot(p));
        top = advance(top, &|p| v.dot(p));
        left = advance(left, &|p| -u.dot(p));
        let width = u.dot(&(hull[right] - hull[left]));
        let height = v.dot(&(hull[top] - hull[i]));
        let area = width * height;
        if area < best.0 {
            best = (area, u);
        }
    }
    best.1
}

/// The minimum-area rectangle containing every point (2D).
///
/// The convex hull ([`convex_hull`]) of the points, taken relative to the centre of their
/// bounding box, is swept with rotating calipers; the rectangle's first axis lies along
/// the best hull edge. Ties go to the first edge of the hull in counter-clockwise order from
/// its lowest-x point. Coincident points give a zero-size box with the identity
/// rotation, collinear points a zero-width box along their line.
///
/// # Errors
/// `points` if empty; `points[k][i]` if a coordinate is not finite.
///
/// ```
/// use carom_geometry::fit::min_area_rect;
/// use nalgebra::Vector2;
///
/// // A diamond: the best rectangle is the square along its edges, of area 2 (not 4).
/// let pts = [
///     Vector2::new(1.0_f64, 0.0), Vector2::new(0.0, 1.0),
///     Vector2::new(-1.0, 0.0), Vector2::new(0.0, -1.0),
/// ];
/// let r = min_area_rect(&pts)?;
/// let area = 4.0 * r.half_extents().x * r.half_extents().y;
/// assert!((area - 2.0).abs() < 1e-12);
/// # Ok::<(), carom_geometry::InvalidValue>(())
/// ```
pub fn min_area_rect<T: Real>(points: &[Vector2<T>]) -> Result<Obb<T, 2>, InvalidValue> {
    let (_, origin) = reference(points)?;
    let local: Vec<_> = points.iter().map(|p| p - origin).collect();
    let hull = convex_hull(&local)?;
    let u = match hull.len() {
        0 => return Err(InvalidValue::new("points", Problem::Empty)),
        1 => Vector2::x(),
        2 => (hull[1] - hull[0]).normalize(),
        _ => calipers_direction(&hull),
    };
    let rotation = Rotation::from_matrix_unchecked(Matrix2::new(u.x, -u.y, u.y, u.x));
    obb_with_axes(points, rotation, &origin)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::PointQuery;
    use approx::assert_relative_eq;

    #[test]
    fn hull_of_a_square_with_inner_and_edge_points() {
        let pts = [
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            Vector2::new(0.5, 0.0), // on an edge
            Vector2::new(1.0, 1.0),
            Vector2::new(0.5, 0.5), // inside
            Vector2::new(0.0, 1.0),
            Vector2::new(1.0, 1.0), // repeated
        ];
        let h = convex_hull(&pts).unwrap();
        assert_eq!(
            h,
            vec![
                Vector2::new(0.0, 0.0),
                Vector2::new(1.0, 0.0),
                Vector2::new(1.0, 1.0),
                Vector2::new(0.0, 1.0)
            ]
        );
    }

    #[test]
    fn hull_of_degenerate_sets() {
        let one = [Vector2::new(2.0, 2.0); 3];
        assert_eq!(convex_hull(&one).unwrap(), vec![Vector2::new(2.0, 2.0)]);
        let line: Vec<_> = (0..5).map(|k| Vector2::new(f64::from(k), 1.0)).collect();
        assert_eq!(
            convex_hull(&line).unwrap(),
            vec![Vector2::new(0.0, 1.0), Vector2::new(4.0, 1.0)]
        );
    }

    #[test]
    fn min_area_rect_of_a_rotated_rectangle_is_that_rectangle() {
        let r = Rotation::<f64, 2>::new(0.3);
        let c = Vector2::new(-2.0, 7.0);
        let pts: Vec<_> = [
            (3.0, 1.0),
            (-3.0, 1.0),
            (-3.0, -1.0),
            (3.0, -1.0),
            (1.0, 0.5),
        ]
        .iter()
        .map(|&(x, y)| c + r * Vector2::new(x, y))
        .collect();
        let o = min_area_rect(&pts).unwrap();
        assert_relative_eq!(o.center(), c, epsilon = 1e-12);
        let h = o.half_extents();
        assert_relative_eq!(h.x.max(h.y), 3.0, epsilon = 1e-12);
        assert_relative_eq!(h.x.min(h.y), 1.0, epsilon = 1e-12);
        assert!(pts.iter().all(|p| o.contains_point(p)));
    }

    #[test]
    fn min_area_rect_of_degenerate_sets() {
        let same = [Vector2::new(1.0, -1.0); 2];
        let o = min_area_rect(&same).unwrap();
        assert_eq!((o.center(), o.half_extents()), (same[0], Vector2::zeros()));
        let line = [
            Vector2::new(0.0, 0.0),
            Vector2::new(3.0, 4.0),
            Vector2::new(1.5, 2.0),
        ];
        let o = min_area_rect(&line).unwrap();
        assert_relative_eq!(o.half_extents(), Vector2::new(2.5, 0.0), epsilon = 1e-15);
        assert_relative_eq!(o.axis(0), Vector2::new(0.6, 0.8), epsilon = 1e-15);
    }
}
