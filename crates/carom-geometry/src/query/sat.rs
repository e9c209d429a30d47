//! The separating-axis test (SAT) for two boxes: an overlap test and the signed gap along
//! the best separating axis. The method and its treatment of parallel edges are
//! documented on [`separation`].

use core::ops::ControlFlow;

use carom_math::{Real, Rotation, Space, Vector};
use nalgebra::{Const, SMatrix};

use crate::Obb;
use crate::query::point::first_axis;

/// The best separating axis of two boxes and the signed gap along it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Separation<T: Real, const D: usize> {
    /// Unit axis pointing from the second box towards the first (moving the first box by
    /// `−distance · axis` makes them just touch along this axis).
    pub axis: Vector<T, D>,
    /// The signed gap along `axis`: positive when the boxes are apart (a lower bound on
    /// their distance, exact when the closest features are faces along the axis),
    /// negative when they overlap, and then minus the penetration depth (the length of
    /// the shortest separating translation; exact up to the `O(√ε · size)` of skipped
    /// near-parallel edge axes).
    pub distance: T,
}

/// Box B seen from box A's frame: everything a box–box test needs.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RelativeBoxes<T: Real, const D: usize> {
    /// A's half extents.
    pub(crate) ha: Vector<T, D>,
    /// B's half extents.
    pub(crate) hb: Vector<T, D>,
    /// B's axes in A's frame (columns): `R_Aᵀ R_B`.
    pub(crate) r: SMatrix<T, D, D>,
    /// B's centre minus A's centre, in A's frame.
    pub(crate) t: Vector<T, D>,
}

/// The slack added to `|R_ij|` in the overlap test, in units of the machine epsilon.
const OVERLAP_SLACK_ULPS: f64 = 16.0;

impl<T: Real, const D: usize> RelativeBoxes<T, D> {
    /// B relative to A, where a missing rotation means axis-aligned (no product computed).
    #[inline]
    pub(crate) fn new(
        (ca, ha, ra): (Vector<T, D>, Vector<T, D>, Option<&Rotation<T, D>>),
        (cb, hb, rb): (Vector<T, D>, Vector<T, D>, Option<&Rotation<T, D>>),
    ) -> Self {
        let d = cb - ca;
        let (r, t) = match (ra, rb) {
            (None, None) => (SMatrix::identity(), d),
            (None, Some(rb)) => (*rb.matrix(), d),
            (Some(ra), None) => (ra.matrix().transpose(), ra.inverse_transform_vector(&d)),
            (Some(ra), Some(rb)) => (
                ra.matrix().tr_mul(rb.matrix()),
                ra.inverse_transform_vector(&d),
            ),
        };
        Self { ha, hb, r, t }
    }

    /// Two oriented boxes.
    #[inline]
    pub(crate) fn of_obbs(a: &Obb<T, D>, b: &Obb<T, D>) -> Self {
        Self::new(
            (a.center(), a.half_extents(), Some(a.rotation())),
            (b.center(), b.half_extents(), Some(b.rotation())),
        )
    }

    /// `r_A` and `r_B` along `l` (in A's frame), each `|·|` term grown by `slack`.
    #[inline]
    fn projected_radii(&self, l: &Vector<T, D>, slack: T) -> (T, T) {
        let rb_l = self.r.tr_mul(l);
        let mut ra = T::zero();
        let mut rb = T::zero();
        for k in 0..D {
            ra += self.ha[k] * (l[k].abs() + slack);
            rb += self.hb[k] * (rb_l[k].abs() + slack);
        }
        (ra, rb)
    }

    /// Visits every candidate axis `l` (in A's frame) with `t · l` and the sum of the
    /// projected radii `r_A + r_B` (each `|·|` term grown by `slack`), until `visit`
    /// breaks: A's face axes, B's face axes (`unit` is `true` for these), then the edge
    /// crosses from [`Space::edge_axes`] (not normalised, `unit` is `false`).
    fn visit_axes(
        &self,
        slack: T,
        mut visit: impl FnMut(&Vector<T, D>, bool, T, T) -> ControlFlow<()>,
    ) -> ControlFlow<()>
    where
        Const<D>: Space<T, D>,
    {
        let abs_r = self.r.abs().add_scalar(slack);
        // A's face axes: L = e_i, r_A = hA_i, r_B = Σ_k hB_k |R_ik|.
        for i in 0..D {
            let l = Vector::<T, D>::from_fn(|k, _| if k == i { T::one() } else { T::zero() });
            let reach = self.ha[i] + abs_r.row(i).transpose().dot(&self.hb);
            visit(&l, true, self.t[i], reach)?;
        }
        // B's face axes: L = R e_j, r_A = Σ_k hA_k |R_kj|, r_B = hB_j.
        for j in 0..D {
            let l = self.r.column(j).into_owned();
            let reach = abs_r.column(j).dot(&self.ha) + self.hb[j];
            visit(&l, true, l.dot(&self.t), reach)?;
        }
        let mut axes = [Vector::<T, D>::zeros(); 9];
        let n = <Const<D> as Space<T, D>>::edge_axes(
            &Rotation::identity(),
            &Rotation::from_matrix_unchecked(self.r),
            &mut axes,
        );
        for l in &axes[..n] {
            let (ra, rb) = self.projected_radii(l, slack);
            visit(l, false, self.t.dot(l), ra + rb)?;
        }
        ControlFlow::Continue(())
    }

    /// `true` if the boxes overlap or touch (or are closer than `16 ulp · Σ h` across
    /// near-parallel edges; see [`separation`]). Stops at the first separating axis.
    pub(crate) fn overlap(&self) -> bool
    where
        Const<D>: Space<T, D>,
    {
        let slack = T::lit(OVERLAP_SLACK_ULPS) * T::EPSILON;
        self.visit_axes(slack, |_, _, along, reach| {
            if along.abs() > reach {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
        .is_continue()
    }

    /// The axis (in A's frame, unit, from B towards A) of largest signed gap, and the gap.
    /// Edge axes shorter than `√ε` are skipped; the others are normalised only when they
    /// beat the best so far.
    pub(crate) fn separation(&self) -> (Vector<T, D>, T)
    where
        Const<D>: Space<T, D>,
    {
        let min_len = T::EPSILON.sqrt();
        let mut best = (first_axis(), -T::INFINITY);
        let _ = self.visit_axes(T::zero(), |l, unit, along, reach| {
            let len = if unit { T::one() } else { l.norm() };
            if len >= min_len {
                let gap = (along.abs() - reach) / len;
                if gap > best.1 {
                    let l = if unit { *l } else { l / len };
                    best = (if along > T::zero() { -l } else { l }, gap);
                }
            }
            ControlFlow::Continue(())
        });
        best
    }
}

/// The best separating axis of two oriented boxes (SAT over 4 axes in 2D, 15 in 3D) and
/// the signed gap along it: positive apart, minus the penetration depth when overlapping.
/// For axis-aligned boxes, convert with [`Obb::from_aabb`].
///
/// Ties between axes go to the first in the order: A's faces, B's faces, edge crosses
/// (lowest index first); an axis along which the centres do not differ points along
/// `+axis`.
///
/// Two convex polytopes are disjoint exactly when their projections on some axis are
/// disjoint, and it suffices to try the face normals of both and, in 3D, the cross
/// products of an edge direction of each: `D + D` face axes plus 9 edge axes in 3D
/// (4 axes in 2D, 15 in 3D). On an axis `L` the boxes project to intervals of radii
/// `r_A = Σ hA_k |a_k · L|`, `r_B = Σ hB_k |b_k · L|` around the projected centres, and
/// they are separated along `L` when `|t · L| > r_A + r_B` (`t` = centre of B − centre of A).
///
/// Everything is computed in A's frame (Gottschalk's OBBTree form, as in Ericson,
/// *Real-Time Collision Detection* §4.4.1): A's axes are the unit vectors, B's axes are the
/// columns of `R = R_Aᵀ R_B`, and `t` is expressed in A's frame. The 3D edge axes come
/// from [`Space::edge_axes`] (none in 2D).
///
/// # Parallel edges
///
/// When an edge of A is parallel to an edge of B, their cross product is zero and so are
/// both sides of the test, and rounding noise in `R` (a few ulp) can make `|t · L|` exceed
/// `r_A + r_B` and report a false separation. Two remedies, used for two jobs:
///
/// * **The box–box [`Overlap`](super::Overlap) test adds a slack `ε = 16 ulp` to every
///   `|R_ij|`** (Ericson's fix): each projected radius grows by `ε Σ h`, a length
///   relative to the box sizes, which dominates the noise of a near-zero axis (whose `|t · L|` is at most a few ulp times
///   `|t|`, and `|t| <= Σ hA + Σ hB` for boxes that could touch). A zero axis can then never
///   separate, and no axis is normalised, so the test stays branch-light. The price is that
///   boxes closer than `ε Σ h` may be reported as overlapping: the test errs towards
///   contact, never towards a missed one.
/// * **The signed separation skips edge axes shorter than `√ε`** (relative to unit axes):
///   it must normalise each axis to compare gaps, and a near-zero axis amplifies rounding
///   by `1/|L|`. Skipping loses little: as the edges become parallel the gap along their
///   cross product tends to a gap along a face axis (the problem reduces to 2D in the plane
///   across the edges, where face normals suffice), so the skipped axis changes the answer
///   by `O(|L| · size)`. With the cut at `√ε` both errors are `O(√ε · size)`.
///
/// ```
/// use carom_geometry::{d2, query::separation};
/// use nalgebra::Vector2;
///
/// let a = d2::Obb::from_angle(Vector2::new(0.0, 0.0), Vector2::new(1.0, 1.0), 0.0)?;
/// let b = d2::Obb::from_angle(Vector2::new(1.5, 0.0), Vector2::new(1.0, 1.0), 0.0)?;
/// let s = separation(&a, &b);
/// assert_eq!(s.distance, -0.5); // they overlap by 0.5 along x
/// assert_eq!(s.axis, Vector2::new(-1.0, 0.0)); // from b towards a
/// # Ok::<(), carom_geometry::InvalidValue>(())
/// ```
pub fn separation<T: Real, const D: usize>(a: &Obb<T, D>, b: &Obb<T, D>) -> Separation<T, D>
where
    Const<D>: Space<T, D>,
{
    let (axis, distance) = RelativeBoxes::of_obbs(a, b).separation();
    Separation {
        axis: a.vector_to_world(&axis),
        distance,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Vector2, Vector3};

    fn cube(c: Vector3<f64>, h: f64, rot: Vector3<f64>) -> Obb<f64, 3> {
        Obb::from_axis_angle(c, Vector3::repeat(h), rot).unwrap()
    }

    #[test]
    fn face_separation_in_2d_and_3d() {
        let a = Obb::<f64, 2>::from_angle(Vector2::zeros(), Vector2::new(1.0, 2.0), 0.0).unwrap();
        let b =
            Obb::<f64, 2>::from_angle(Vector2::new(0.0, 5.0), Vector2::new(1.0, 2.0), 0.0).unwrap();
        let s = separation(&a, &b);
        assert_eq!((s.axis, s.distance), (-Vector2::y(), 1.0));
        assert!(!RelativeBoxes::of_obbs(&a, &b).overlap());
        let c = cube(Vector3::new(0.0, 0.0, 1.5), 1.0, Vector3::zeros());
        let d = cube(Vector3::zeros(), 1.0, Vector3::zeros());
        let s = separation(&c, &d);
        assert_eq!((s.axis, s.distance), (Vector3::z(), -0.5));
    }

    #[test]
    fn edge_edge_separation_in_3d() {
        // Two unit cubes, each turned 45° about a different axis so that an edge of each
        // faces the other: A's edge along z at x = √2, B's edge along y at x = d − √2.
        let q = core::f64::consts::FRAC_PI_4;
        let a = cube(Vector3::zeros(), 1.0, Vector3::new(0.0, 0.0, q));
        let gap = 0.25;
        let d = 2.0 * 2f64.sqrt() + gap;
        let b = cube(Vector3::new(d, 0.0, 0.0), 1.0, Vector3::new(0.0, q, 0.0));
        let s = separation(&a, &b);
        assert_relative_eq!(s.distance, gap, epsilon = 1e-12);
        assert_relative_eq!(s.axis, -Vector3::x(), epsilon = 1e-12);
        assert!(!RelativeBoxes::of_obbs(&a, &b).overlap());
        let b = b.translated(&Vector3::new(-2.0 * gap, 0.0, 0.0));
        let s = separation(&a, &b);
        assert_relative_eq!(s.distance, -gap, epsilon = 1e-12);
        assert!(RelativeBoxes::of_obbs(&a, &b).overlap());
    }

    #[test]
    fn parallel_edges_never_separate_touching_or_overlapping_boxes() {
        // Identical rotations make the nine edge crosses of parallel pairs zero up to
        // rounding; the boxes overlap by 2e-9 of their size along A's x axis, or touch.
        let rot = Vector3::new(0.3, -1.1, 0.7);
        for (scale, offset) in [(1.0, 0.0), (1e-6, 0.0), (1e3, 0.0), (1.0, 1e6)] {
            let a = cube(Vector3::repeat(offset), scale, rot);
            if offset == 0.0 {
                // Exact touching is representable to a few ulp of the size only near the
                // origin (at 1e6 the centres themselves round by 1e-10).
                let touching = a.translated(&(a.axis(0) * (2.0 * scale)));
                assert!(
                    RelativeBoxes::of_obbs(&a, &touching).overlap(),
                    "scale {scale}"
                );
            }
            let b = a.translated(&(a.axis(0) * (2.0 * scale * (1.0 - 1e-9))));
            assert!(RelativeBoxes::of_obbs(&a, &b).overlap(), "scale {scale}");
            let s = separation(&a, &b);
            // Rounding of the translated centre: a few ulp of the offset.
            let tolerance = 1e-12 * scale + 8.0 * f64::EPSILON * offset;
            assert!(
                (s.distance + 2e-9 * scale).abs() <= tolerance,
                "{scale}: {s:?}"
            );
            assert_relative_eq!(s.axis, -a.axis(0), epsilon = 1e-9);
        }
    }

    #[test]
    fn concentric_boxes_use_the_first_axis() {
        let a = cube(Vector3::zeros(), 1.0, Vector3::zeros());
        let s = separation(&a, &a);
        assert_eq!((s.axis, s.distance), (Vector3::x(), -2.0));
    }

    #[test]
    fn zero_size_boxes_are_points() {
        let p = Obb::<f64, 3>::new(
            Vector3::new(0.5, 0.5, 0.5),
            Vector3::zeros(),
            Rotation::identity(),
        )
        .unwrap();
        let q = p.translated(&Vector3::new(0.0, 3.0, 4.0));
        let s = separation(&p, &q);
        // SAT gives a lower bound: the best single axis sees 4 of the distance 5.
        assert_eq!(s.distance, 4.0);
        assert!(!RelativeBoxes::of_obbs(&p, &q).overlap());
        assert!(RelativeBoxes::of_obbs(&p, &p).overlap());
    }
}
