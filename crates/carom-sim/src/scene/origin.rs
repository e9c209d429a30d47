//! Moving a scene's origin into its middle, exactly, so that an engine computes in
//! coordinates as fine as the scene's size allows and not as coarse as its distance
//! from the origin.
//!
//! A floating-point position `x` is resolved to about `ε|x|`. A scene built 5e4 m from
//! the origin has, in `f32`, a unit of 3.9e-3 m however small it is, and an engine that
//! adds displacements to such positions drops every one below half a unit: a ball at
//! 0.17 m/s with steps of 0.01 s never moves, and a moving box runs into it
//! (docs/stepped.md). Measured from the scene's middle the same ball sits within metres
//! of the origin, where the unit is 1e-7 m.
//!
//! The move must not change the scene. Sterbenz's lemma: for floating-point `a`, `b`
//! with `b/2 <= a <= 2b`, `a − b` is exact. On an axis whose coordinates all lie in
//! `[lo, hi]` with `0 < lo` and `hi <= 2 lo` (or the mirror image below zero), take any
//! `o` in `[lo, hi]`; then `o/2 <= hi/2 <= lo <= x` and `x <= hi <= 2 lo <= 2o` for every
//! coordinate `x`, so `x − o` is exact. Every centre, every box centre and both border
//! faces move by `−o` without rounding, and every difference between them is the same
//! number as before. An axis whose coordinates do not meet the condition (the scene
//! reaches zero, or spans more than a factor of 2 in distance from it) keeps its origin:
//! there the move could round, and the coordinates are already as fine as the scene's
//! size allows within a factor of 2.
//!
//! Only positions move. Velocities, gravity, radii, box shapes and orientations are
//! the same in both frames; an engine adds `o` back to every position it reports.

use carom_math::{Real, Vector};

use super::{BorderSpec, Scene};

impl<T: Real, const D: usize> Scene<T, D> {
    /// The scene with its origin moved, exactly, to `o` ([`Scene::middle`]): every ball
    /// and box centre and the border are moved by `−o`. The simulation of the moved
    /// scene, with `o` added to its positions, is the simulation of `self` computed in
    /// finer coordinates (see the module documentation).
    #[must_use]
    pub fn recentred(&self) -> (Self, Vector<T, D>) {
        let o = self.middle();
        if o == Vector::<T, D>::zeros() {
            return (self.clone(), o);
        }
        let mut moved = self.clone();
        for b in &mut moved.balls {
            b.pos -= o;
        }
        for b in &mut moved.boxes {
            b.shape = b.shape.translated(&-o);
        }
        if let Some(BorderSpec { border, .. }) = &mut moved.world.border {
            *border = carom_geometry::Border::new(border.min() - o, border.max() - o)
                .expect("an exact translation keeps the border valid");
        }
        (moved, o)
    }

    /// The origin [`Scene::recentred`] moves to: on each axis the middle of the span of
    /// every ball, box and the border where the span lies on one side of zero within a
    /// factor of 2 (`0 < lo`, `hi <= 2 lo`, or the mirror image), `0` elsewhere.
    pub fn middle(&self) -> Vector<T, D> {
        let mut lo = Vector::<T, D>::repeat(T::INFINITY);
        let mut hi = Vector::<T, D>::repeat(-T::INFINITY);
        let mut cover = |a: Vector<T, D>, b: Vector<T, D>| {
            lo = lo.inf(&a);
            hi = hi.sup(&b);
        };
        for b in &self.balls {
            let r = Vector::repeat(b.radius);
            cover(b.pos - r, b.pos + r);
        }
        for b in &self.boxes {
            let aabb = b.shape.aabb();
            cover(aabb.min(), aabb.max());
        }
        if let Some(b) = &self.world.border {
            cover(b.border.min(), b.border.max());
        }
        let two = T::lit(2.0);
        Vector::from_fn(|k, _| {
            let (lo, hi) = (lo[k], hi[k]);
            let one_sided = lo <= hi
                && ((lo > T::zero() && hi <= two * lo) || (hi < T::zero() && lo >= two * hi));
            if one_sided {
                (lo * T::lit(0.5) + hi * T::lit(0.5)).max(lo).min(hi)
            } else {
                T::zero()
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use carom_geometry::{Border, Obb};
    use nalgebra::{Vector2, Vector3};

    use super::*;
    use crate::scene::{BallSpec, BoxSpec};

    fn far_scene(at: f32) -> Scene<f32, 2> {
        let mut s = Scene::default();
        s.world.border = Some(BorderSpec {
            border: Border::new(Vector2::new(at - 3.0, 1.0), Vector2::new(at + 4.0, 9.0)).unwrap(),
            restitution: 1.0,
            periodic: false,
        });
        s.balls.push(BallSpec::new(
            Vector2::new(at + 0.123_456, 2.5),
            Vector2::new(0.17, 0.0),
            0.1,
            1.0,
        ));
        s.boxes.push(BoxSpec {
            shape: Obb::from_angle(Vector2::new(at - 1.0, 5.0), Vector2::new(0.5, 0.25), 0.3)
                .unwrap(),
            vel: Vector2::new(0.0, -1.0),
            restitution: 0.5,
        });
        s
    }

    #[test]
    fn a_scene_far_from_the_origin_moves_exactly_and_back() {
        for at in [-5e4_f32, 1e3, 3.0e7] {
            let scene = far_scene(at);
            let (moved, o) = scene.recentred();
            // x: the scene lies on one side within a factor of 2; y: [1, 9] does not.
            assert!(o[0] != 0.0 && (o[0] - at).abs() <= 4.0, "at {at}: {o}");
            assert_eq!(o[1], 0.0, "at {at}");
            // Moving back gives every coordinate bit for bit, so nothing was rounded.
            assert_eq!(moved.balls[0].pos + o, scene.balls[0].pos, "at {at}");
            assert_eq!(
                moved.boxes[0].shape.center() + o,
                scene.boxes[0].shape.center()
            );
            let (b, mb) = (
                scene.world.border.unwrap().border,
                moved.world.border.unwrap().border,
            );
            assert_eq!(mb.min() + o, b.min(), "at {at}");
            assert_eq!(mb.max() + o, b.max(), "at {at}");
            // The ball's gap to the wall is the same number in both frames.
            assert_eq!(
                moved.balls[0].pos[0] - mb.min()[0],
                scene.balls[0].pos[0] - b.min()[0]
            );
            moved.validate().unwrap();
        }
    }

    #[test]
    fn a_scene_around_the_origin_or_spread_away_from_it_stays() {
        let mut s = Scene::<f64, 3>::default();
        s.balls.push(BallSpec::new(
            Vector3::new(-1.0, 10.0, 5.0),
            Vector3::zeros(),
            0.5,
            1.0,
        ));
        s.balls.push(BallSpec::new(
            Vector3::new(1.0, 30.0, 6.0),
            Vector3::zeros(),
            0.5,
            1.0,
        ));
        // x reaches zero, y spans 9.5..30.5 (more than a factor 2); z 4.5..6.5 moves.
        let (moved, o) = s.recentred();
        assert_eq!((o[0], o[1]), (0.0, 0.0));
        assert_eq!(o[2], 5.5);
        assert_eq!(moved.balls[1].pos, Vector3::new(1.0, 30.0, 0.5));
        let empty = Scene::<f64, 2>::default();
        assert_eq!(empty.recentred().1, Vector2::zeros());
    }
}
