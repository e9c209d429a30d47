//! Contacts of a ball against any shape: normal, penetration depth and contact points.
//!
//! Every ball contact is the nearest boundary point of the other shape to the ball's
//! centre `c` ([`PointQuery::boundary_point_within`], with reach = the radius `r`): when
//! its signed distance `s` is at most `r`, the ball touches or penetrates, the depth is
//! `r − s`, and the normal is the shape's outward normal there. This covers a centre
//! outside the shape (normal along `c − q`), inside it (the face of least penetration)
//! and at another ball's centre (`+x`), with one formula.

use carom_math::{Real, Vector};

use crate::Ball;
use crate::query::PointQuery;

/// A ball touching or penetrating another shape.
///
/// `point_on_shape = point_on_ball + depth · normal`: moving the ball by `depth · normal`
/// brings its deepest point onto the other shape's surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact<T: Real, const D: usize> {
    /// Unit normal from the other shape towards the ball (the direction that separates
    /// the ball; the other shape's outward surface normal at `point_on_shape`).
    pub normal: Vector<T, D>,
    /// Penetration depth, `>= 0`; zero when the shapes just touch.
    pub depth: T,
    /// The ball's deepest point inside the other shape: `centre − radius · normal`.
    pub point_on_ball: Vector<T, D>,
    /// The point of the other shape's surface nearest to the ball's centre.
    pub point_on_shape: Vector<T, D>,
}

/// The contact of `ball` with `shape` (a [`Ball`], [`Aabb`](crate::Aabb),
/// [`Obb`](crate::Obb) or [`HalfSpace`](crate::HalfSpace)), or `None` if they are apart.
/// Touching shapes give a contact of depth 0.
///
/// The normal points from `shape` towards `ball`. A ball whose centre is inside a box is
/// pushed out through the face of least penetration (ties: lowest axis, then upper face);
/// two balls with coincident centres get the normal `+x`. No allocation; far balls are
/// rejected without a square root.
///
/// ```
/// use carom_geometry::{d2, query::contact};
/// use nalgebra::Vector2;
///
/// let ball: d2::Ball = d2::Ball::new(Vector2::new(0.0, 0.9), 1.0)?;
/// let floor = d2::HalfSpace::new(Vector2::new(0.0, 1.0), Vector2::new(0.0, 0.0))?;
/// let c = contact(&ball, &floor).expect("the ball sinks 0.1 into the floor");
/// assert_eq!(c.normal, Vector2::new(0.0, 1.0));
/// assert!((c.depth - 0.1).abs() < 1e-15);
/// # Ok::<(), carom_geometry::InvalidValue>(())
/// ```
#[inline]
pub fn contact<T: Real, const D: usize, S: PointQuery<T, D> + ?Sized>(
    ball: &Ball<T, D>,
    shape: &S,
) -> Option<Contact<T, D>> {
    let (c, r) = (ball.center(), ball.radius());
    let b = shape.boundary_point_within(&c, r)?;
    Some(Contact {
        normal: b.normal,
        depth: r - b.signed_distance,
        point_on_ball: c - b.normal * r,
        point_on_shape: b.point,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Aabb, HalfSpace, Obb};
    use approx::assert_relative_eq;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn ball_ball_contact_matches_the_closed_form() {
        let a = Ball::new(Vector3::new(0.0, 0.0, 0.0), 1.0).unwrap();
        let b = Ball::new(Vector3::new(0.0, 1.5, 0.0), 1.0).unwrap();
        let c = contact(&a, &b).unwrap();
        assert_eq!(c.normal, -Vector3::y());
        assert_eq!(c.depth, 0.5);
        assert_eq!(c.point_on_ball, Vector3::y());
        assert_eq!(c.point_on_shape, Vector3::new(0.0, 0.5, 0.0));
        let apart = b.translated(&Vector3::new(0.0, 0.5 + 1e-12, 0.0));
        assert!(contact(&a, &apart).is_none());
    }

    #[test]
    fn touching_is_a_contact_of_depth_zero() {
        let a = Ball::new(Vector2::new(0.0, 0.0), 1.0).unwrap();
        let b = Ball::new(Vector2::new(2.0, 0.0), 1.0).unwrap();
        assert_eq!(contact(&a, &b).unwrap().depth, 0.0);
        let wall = Aabb::new(Vector2::new(1.0, -5.0), Vector2::new(3.0, 5.0)).unwrap();
        let c = contact(&a, &wall).unwrap();
        assert_eq!((c.depth, c.normal), (0.0, -Vector2::x()));
    }

    #[test]
    fn coincident_centres_give_the_documented_x_normal() {
        let a = Ball::new(Vector3::new(5.0, 5.0, 5.0), 1.0).unwrap();
        let b = Ball::new(Vector3::new(5.0, 5.0, 5.0), 3.0).unwrap();
        let c = contact(&a, &b).unwrap();
        assert_eq!(c.normal, Vector3::x());
        assert_eq!(c.depth, 4.0);
        assert!(c.normal.iter().all(|x: &f64| x.is_finite()));
    }

    #[test]
    fn a_centre_inside_a_box_leaves_through_the_nearest_face() {
        let table = Aabb::new(Vector2::new(-2.0, -1.0), Vector2::new(2.0, 0.0)).unwrap();
        let ball = Ball::new(Vector2::new(1.0, -0.25), 0.5).unwrap();
        let c = contact(&ball, &table).unwrap();
        assert_eq!(c.normal, Vector2::y());
        assert_eq!(c.depth, 0.75);
        assert_eq!(c.point_on_shape, Vector2::new(1.0, 0.0));
        assert_relative_eq!(c.point_on_ball + c.normal * c.depth, c.point_on_shape);
    }

    #[test]
    fn ball_obb_contact_at_a_rotated_corner() {
        // A unit square turned 45°: its right corner is at (√2, 0).
        let o = Obb::<f64, 2>::from_angle(
            Vector2::zeros(),
            Vector2::new(1.0, 1.0),
            core::f64::consts::FRAC_PI_4,
        )
        .unwrap();
        let ball = Ball::new(Vector2::new(2.0, 0.0), 1.0).unwrap();
        let c = contact(&ball, &o).unwrap();
        assert_relative_eq!(c.normal, Vector2::x(), epsilon = 1e-15);
        assert_relative_eq!(c.depth, 1.0 - (2.0 - 2f64.sqrt()), epsilon = 1e-15);
    }

    #[test]
    fn ball_half_space_contact_with_a_slanted_floor() {
        let h = HalfSpace::new(Vector3::new(1.0, 1.0, 0.0), Vector3::zeros()).unwrap();
        let ball = Ball::new(Vector3::new(0.5, 0.5, 7.0), 1.0).unwrap();
        let c = contact(&ball, &h).unwrap();
        let s = 0.5f64.sqrt();
        assert_relative_eq!(c.normal, Vector3::new(s, s, 0.0), epsilon = 1e-15);
        assert_relative_eq!(c.depth, 1.0 - 2.0 * 0.5 * s, epsilon = 1e-15);
        assert_relative_eq!(
            c.point_on_shape,
            Vector3::new(0.0, 0.0, 7.0),
            epsilon = 1e-15
        );
    }
}
