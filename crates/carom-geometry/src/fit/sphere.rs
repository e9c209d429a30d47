//! Bounding spheres of point sets: Ritter's fast approximation and Welzl's exact minimum.

use carom_math::{InvalidValue, Real, Vector};
use nalgebra::SMatrix;

use crate::BoundingSphere;

use super::reference;

/// The smallest radius `r` with `|p − centre|² <= r²` in floating point for every point:
/// the square root of the largest squared distance, raised by an ulp at a time until its
/// square covers it (at most a couple of steps).
fn enclosing_radius<T: Real, const D: usize>(center: &Vector<T, D>, points: &[Vector<T, D>]) -> T {
    let far = points
        .iter()
        .map(|p| (p - center).norm_squared())
        .fold(T::zero(), T::max);
    let mut r = far.sqrt();
    while r * r < far {
        r *= T::one() + T::EPSILON;
    }
    r
}

/// The point of `points` (relative to `origin`) farthest from `from`; ties: the first.
fn farthest<T: Real, const D: usize>(
    points: &[Vector<T, D>],
    origin: &Vector<T, D>,
    from: &Vector<T, D>,
) -> Vector<T, D> {
    let mut best = (*from, -T::one());
    for p in points {
        let q = p - origin;
        let d2 = (q - from).norm_squared();
        if d2 > best.1 {
            best = (q, d2);
        }
    }
    best.0
}

/// Ritter's bounding sphere (Graphics Gems, 1990): fast, deterministic, near-minimal.
///
/// Start from the sphere on the segment between two far-apart points (the point farthest
/// from the first point, and the point farthest from that one), then in one pass grow it
/// to take in each point outside: the new sphere has radius `(r + d)/2` and its centre
/// moves towards the point by `(d − r)/2`, so it still contains the old one. Finally the
/// radius is measured from the final centre (it can only shrink).
///
/// # Errors
/// `points` if empty; `points[k][i]` if a coordinate is not finite.
pub fn ritter_sphere<T: Real, const D: usize>(
    points: &[Vector<T, D>],
) -> Result<BoundingSphere<T, D>, InvalidValue> {
    let (_, origin) = reference(points)?;
    let first = points[0] - origin;
    let y = farthest(points, &origin, &first);
    let z = farthest(points, &origin, &y);
    let half = T::lit(0.5);
    let mut center = (y + z) * half;
    let mut radius = (z - y).norm() * half;
    for p in points {
        let offset = p - origin - center;
        let d2 = offset.norm_squared();
        if d2 > radius * radius {
            let d = d2.sqrt();
            let grown = (radius + d) * half;
            center += offset * ((grown - radius) / d);
            radius = grown;
        }
    }
    let center = center + origin;
    Ok(BoundingSphere::new_unchecked(
        center,
        enclosing_radius(&center, points),
    ))
}

/// A sphere during Welzl's recursion: centre and radius, or no sphere yet (`radius < 0`).
#[derive(Clone, Copy)]
struct Sphere<T: Real, const D: usize> {
    center: Vector<T, D>,
    radius: T,
}

impl<T: Real, const D: usize> Sphere<T, D> {
    /// `true` if `p` is outside by more than `slack` (every point is outside "no sphere").
    #[inline]
    fn excludes(&self, p: &Vector<T, D>, slack: T) -> bool {
        self.radius < T::zero()
            || (p - self.center).norm_squared() > {
                let r = self.radius + slack;
                r * r
            }
    }
}

/// The smallest sphere with every support point on its boundary: the circumsphere of the
/// points within their affine hull. With `v_k = s_k − s_0`, the centre is
/// `s_0 + Σ λ_k v_k` where `|c − s_0| = |c − s_k|` gives the linear system
/// `Σ_k 2 (v_j · v_k) λ_k = v_j · v_j` (`j, k = 1..m`), solved by Gaussian elimination with
/// partial pivoting. `None` if the points are affinely dependent (a zero pivot).
fn circumsphere<T: Real, const D: usize>(support: &[Vector<T, D>]) -> Option<Sphere<T, D>> {
    let (s0, rest) = support.split_first()?;
    let m = rest.len();
    let mut a = SMatrix::<T, D, D>::zeros();
    let mut b = Vector::<T, D>::zeros();
    for (j, vj) in rest.iter().enumerate() {
        let vj = vj - s0;
        for (k, vk) in rest.iter().enumerate() {
            a[(j, k)] = (vj.dot(&(vk - s0))) * T::lit(2.0);
        }
        b[j] = vj.norm_squared();
    }
    let lambda = solve(&mut a, &mut b, m)?;
    let mut offset = Vector::<T, D>::zeros();
    for (k, vk) in rest.iter().enumerate() {
        offset += (vk - s0) * lambda[k];
    }
    let sphere = Sphere {
        center: s0 + offset,
        radius: offset.norm(),
    };
    sphere.radius.finite().then_some(sphere)
}

/// Solves the leading `m × m` system `a x = b` in place; `None` on a pivot at or below
/// `m ε` times the largest entry (a singular system: affinely dependent support points).
fn solve<T: Real, const D: usize>(
    a: &mut SMatrix<T, D, D>,
    b: &mut Vector<T, D>,
    m: usize,
) -> Option<Vector<T, D>> {
    let scale = (0..m)
        .flat_map(|i| (0..m).map(move |j| (i, j)))
        .fold(T::zero(), |s, (i, j)| s.max(a[(i, j)].abs()));
    let tiny = scale * T::EPSILON * T::from_count(m);
    for col in 0..m {
        let pivot = (col..m).fold(col, |p, i| {
            if a[(i, col)].abs() > a[(p, col)].abs() {
                i
            } else {
                p
            }
        });
        if a[(pivot, col)].abs() <= tiny {
            return None;
        }
        a.swap_rows(pivot, col);
        b.swap_rows(pivot, col);
        for row in col + 1..m {
            let f = a[(row, col)] / a[(col, col)];
            for k in col..m {
                let sub = f * a[(col, k)];
                a[(row, k)] -= sub;
            }
            let sub = f * b[col];
            b[row] -= sub;
        }
    }
    let mut x = Vector::<T, D>::zeros();
    for row in (0..m).rev() {
        let mut s = b[row];
        for k in row + 1..m {
            s -= a[(row, k)] * x[k];
        }
        x[row] = s / a[(row, row)];
    }
    Some(x)
}

/// Welzl's minimal sphere in Gärtner's move-to-front form: `mtf(end, support)` returns
/// the smallest sphere containing `points[..end]` with every support point on its
/// boundary. Each recursive call adds a support point, so the recursion is at most
/// `D + 1` deep whatever the number of points (100k points never overflow the stack).
/// A point found outside is moved to the front of the list, where later passes meet it
/// first.
///
/// A point counts as outside only beyond `slack` (a few ulp of the set's size): rounding
/// can put a boundary point an ulp outside, and pushing it would ask for a sphere through
/// affinely dependent points. If the support is degenerate anyway, the parent sphere is
/// kept; the final radius pass keeps every point inside.
fn move_to_front<T: Real, const D: usize>(
    points: &mut [Vector<T, D>],
    end: usize,
    support: &mut Vec<Vector<T, D>>,
    parent: Sphere<T, D>,
    slack: T,
) -> Sphere<T, D> {
    let mut sphere = if support.is_empty() {
        parent
    } else {
        match circumsphere(support) {
            Some(s) => s,
            None => return parent,
        }
    };
    if support.len() == D + 1 {
        return sphere;
    }
    for i in 0..end {
        if sphere.excludes(&points[i], slack) {
            support.push(points[i]);
            sphere = move_to_front(points, i, support, sphere, slack);
            support.pop();
            points[..=i].rotate_right(1);
        }
    }
    sphere
}

/// SplitMix64 (Steele, Lea and Flood 2014): a tiny generator for the deterministic shuffle.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform index in `0..n` by Lemire's multiply-shift (bias below 2⁻⁴⁰ for n < 2²⁴).
    fn below(&mut self, n: usize) -> usize {
        ((u128::from(self.next()) * n as u128) >> 64) as usize
    }
}

/// The fixed seed of the shuffle: the same input gives the same sphere on every run.
const SHUFFLE_SEED: u64 = 0x6361_726F_6D00_0001;

/// The smallest enclosing sphere (Welzl 1991, move-to-front form of Gärtner 1999).
///
/// Exact up to rounding: the centre and radius come from the circumsphere of at most
/// `D + 1` support points. The points are copied and shuffled with a fixed-seed generator
/// (expected linear time on any input order, and the same answer on every run and
/// platform); the recursion is at most `D + 1` deep, so large sets do not overflow the
/// stack. Degenerate sets (coincident, collinear, cocircular points) are handled.
///
/// # Errors
/// `points` if empty; `points[k][i]` if a coordinate is not finite.
///
/// ```
/// use carom_geometry::fit::minimal_sphere;
/// use nalgebra::Vector2;
///
/// // A right triangle: the minimal circle has the hypotenuse as diameter.
/// let pts = [Vector2::new(0.0_f64, 0.0), Vector2::new(4.0, 0.0), Vector2::new(0.0, 3.0)];
/// let s = minimal_sphere(&pts)?;
/// assert!((s.radius() - 2.5).abs() < 1e-12);
/// # Ok::<(), carom_geometry::InvalidValue>(())
/// ```
pub fn minimal_sphere<T: Real, const D: usize>(
    points: &[Vector<T, D>],
) -> Result<BoundingSphere<T, D>, InvalidValue> {
    let (bounds, origin) = reference(points)?;
    let mut local: Vec<Vector<T, D>> = points.iter().map(|p| p - origin).collect();
    let mut rng = SplitMix64(SHUFFLE_SEED);
    for i in (1..local.len()).rev() {
        local.swap(i, rng.below(i + 1));
    }
    let size = bounds.extents().amax();
    let slack = T::lit(8.0) * T::EPSILON * size;
    let mut support = Vec::with_capacity(D + 1);
    let none = Sphere {
        center: Vector::zeros(),
        radius: -T::one(),
    };
    let n = local.len();
    let sphere = move_to_front(&mut local, n, &mut support, none, slack);
    let center = sphere.center + origin;
    Ok(BoundingSphere::new_unchecked(
        center,
        enclosing_radius(&center, points),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::BoundingVolume;
    use approx::assert_relative_eq;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn one_point_and_coincident_points_give_radius_zero() {
        let p = [Vector3::new(1.0, 2.0, 3.0); 5];
        for s in [ritter_sphere(&p).unwrap(), minimal_sphere(&p).unwrap()] {
            assert_eq!(s.radius(), 0.0);
            assert_eq!(s.center(), Vector3::new(1.0, 2.0, 3.0));
        }
    }

    #[test]
    fn collinear_points_give_the_segment_sphere() {
        let pts: Vec<_> = (0..50)
            .map(|k| Vector2::new(f64::from(k), 2.0 * f64::from(k)))
            .collect();
        let s = minimal_sphere(&pts).unwrap();
        assert_relative_eq!(s.radius(), 0.5 * 49.0 * 5f64.sqrt(), max_relative = 1e-14);
        assert_relative_eq!(s.center(), Vector2::new(24.5, 49.0), epsilon = 1e-12);
        let r = ritter_sphere(&pts).unwrap();
        assert_relative_eq!(r.radius(), s.radius(), max_relative = 1e-14);
    }

    #[test]
    fn cocircular_points_give_their_circle() {
        let pts: Vec<_> = (0..64)
            .map(|k| {
                let a = f64::from(k) * core::f64::consts::TAU / 64.0;
                Vector2::new(3.0 + 2.0 * a.cos(), -1.0 + 2.0 * a.sin())
            })
            .collect();
        let s = minimal_sphere(&pts).unwrap();
        assert_relative_eq!(s.radius(), 2.0, max_relative = 1e-13);
        assert_relative_eq!(s.center(), Vector2::new(3.0, -1.0), epsilon = 1e-13);
    }

    #[test]
    fn regular_tetrahedron_gives_its_circumsphere() {
        let pts = [
            Vector3::new(1.0, 1.0, 1.0),
            Vector3::new(1.0, -1.0, -1.0),
            Vector3::new(-1.0, 1.0, -1.0),
            Vector3::new(-1.0, -1.0, 1.0),
        ];
        let s = minimal_sphere(&pts).unwrap();
        assert_relative_eq!(s.radius(), 3f64.sqrt(), max_relative = 1e-15);
        assert_relative_eq!(s.center(), Vector3::zeros(), epsilon = 1e-15);
    }

    #[test]
    fn a_hundred_thousand_points_neither_overflow_nor_escape() {
        let mut rng = SplitMix64(7);
        let mut unit = || (rng.next() >> 11) as f64 / (1u64 << 53) as f64;
        let pts: Vec<_> = (0..100_000)
            .map(|_| Vector3::new(unit(), unit(), unit()) * 2.0 - Vector3::repeat(1.0))
            .collect();
        let s = minimal_sphere(&pts).unwrap();
        assert!(pts.iter().all(|p| s.contains_point(p)));
        // Points fill the cube: the minimal sphere is nearly its circumsphere.
        assert!(s.radius() <= 3f64.sqrt() && s.radius() > 1.6);
        assert_eq!(minimal_sphere(&pts).unwrap(), s, "deterministic");
    }

    #[test]
    fn the_solver_rejects_singular_systems() {
        let mut a = SMatrix::<f64, 3, 3>::new(2.0, 4.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0);
        let mut b = Vector3::new(1.0, 1.0, 0.0);
        assert!(solve(&mut a, &mut b, 2).is_none());
        let mut a = SMatrix::<f64, 3, 3>::new(0.0, 2.0, 0.0, 4.0, 1.0, 0.0, 0.0, 0.0, 0.0);
        let mut b = Vector3::new(2.0, 9.0, 0.0);
        assert_eq!(solve(&mut a, &mut b, 2), Some(Vector3::new(2.0, 1.0, 0.0)));
    }

    #[test]
    fn far_from_the_origin_the_fit_keeps_relative_precision() {
        let base = Vector3::new(1e6, -1e6, 1e6);
        let pts: Vec<_> = [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1e-3, 0.0, 0.0),
            Vector3::new(0.0, 1e-3, 0.0),
        ]
        .iter()
        .map(|p| base + p)
        .collect();
        let s = minimal_sphere(&pts).unwrap();
        // Right isosceles triangle: the hypotenuse (1e-3 √2) is the diameter.
        assert_relative_eq!(s.radius(), 0.5e-3 * 2f64.sqrt(), max_relative = 1e-6);
    }
}
