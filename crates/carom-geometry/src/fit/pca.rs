//! Oriented boxes from principal component analysis: the box's axes are the eigenvectors
//! of the points' covariance matrix.

use carom_math::{InvalidValue, Real, Rotation, Vector};
use nalgebra::{DMatrix, SMatrix};

use crate::Obb;

use super::{obb_with_axes, reference};

/// An oriented box around the points with axes along their principal directions.
///
/// The covariance `C = (1/n) Σ (p − p̄)(p − p̄)ᵀ` is accumulated relative to the centre of
/// the points' bounding box (two passes: mean, then spread), and its eigenvectors (from
/// nalgebra's `SymmetricEigen`) become the box axes, in decreasing order of variance: axis
/// 0 is the direction of largest spread. The axes are re-orthonormalised and made
/// right-handed (the last one flipped if needed). The box then spans the points' extent
/// along each axis.
///
/// Degenerate sets work: coincident points give a zero-size box, collinear points a box
/// of zero width across the line (and in 3D coplanar points one of zero thickness); where
/// eigenvalues tie the eigenvectors are any orthonormal basis of their eigenspace.
/// PCA is a heuristic: for sets with a few far outliers or even spread, the box can be
/// larger than the minimum-volume one (in 2D see [`min_area_rect`](super::min_area_rect)).
///
/// # Errors
/// `points` if empty; `points[k][i]` if a coordinate is not finite.
pub fn pca_obb<T: Real, const D: usize>(
    points: &[Vector<T, D>],
) -> Result<Obb<T, D>, InvalidValue> {
    let (_, origin) = reference(points)?;
    let n = T::from_count(points.len());
    let mean = points
        .iter()
        .fold(Vector::<T, D>::zeros(), |s, p| s + (p - origin))
        / n;
    let covariance = points.iter().fold(SMatrix::<T, D, D>::zeros(), |c, p| {
        let q = p - origin - mean;
        c + q * q.transpose()
    }) / n;
    let eigen = DMatrix::from_fn(D, D, |i, j| covariance[(i, j)]).symmetric_eigen();
    let mut order: Vec<usize> = (0..D).collect();
    order.sort_by(|&a, &b| {
        eigen.eigenvalues[b]
            .partial_cmp(&eigen.eigenvalues[a])
            .unwrap_or(core::cmp::Ordering::Equal)
    });
    let axes = SMatrix::<T, D, D>::from_fn(|i, j| eigen.eigenvectors[(i, order[j])]);
    obb_with_axes(points, proper_rotation(&axes), &origin)
}

/// The rotation closest in spirit to `axes`: modified Gram–Schmidt over its columns (a
/// column that vanishes against the previous ones is replaced by the coordinate axis that
/// survives best), then the last column negated if the determinant is negative.
pub(super) fn proper_rotation<T: Real, const D: usize>(axes: &SMatrix<T, D, D>) -> Rotation<T, D> {
    let mut q = SMatrix::<T, D, D>::zeros();
    let orthogonalised = |v: Vector<T, D>, q: &SMatrix<T, D, D>, done: usize| {
        (0..done).fold(v, |v, k| {
            let qk = q.column(k);
            let along = qk.dot(&v);
            v - qk * along
        })
    };
    for j in 0..D {
        let mut v = orthogonalised(axes.column(j).into_owned(), &q, j);
        if v.norm() < T::lit(0.5) {
            v = (0..D)
                .map(|i| {
                    let e =
                        Vector::<T, D>::from_fn(|k, _| if k == i { T::one() } else { T::zero() });
                    orthogonalised(e, &q, j)
                })
                .fold(Vector::<T, D>::zeros(), |best, c| {
                    if c.norm_squared() > best.norm_squared() {
                        c
                    } else {
                        best
                    }
                });
        }
        // Twice is enough (Kahan–Parlett): the second pass removes what rounding left.
        let v = orthogonalised(v, &q, j);
        q.set_column(j, &v.normalize());
    }
    if carom_math::determinant(&q) < T::zero() {
        let last = -q.column(D - 1);
        q.set_column(D - 1, &last);
    }
    Rotation::from_matrix_unchecked(q)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::PointQuery;
    use approx::assert_relative_eq;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn a_rotated_rectangle_of_points_is_recovered() {
        // A 10 × 2 grid of points turned by 0.4 rad about (5, −3).
        let angle = 0.4_f64;
        let r = Rotation::<f64, 2>::new(angle);
        let pts: Vec<_> = (0..=20)
            .flat_map(|i| (0..=4).map(move |j| (i, j)))
            .map(|(i, j)| {
                let local = Vector2::new(f64::from(i) * 0.5 - 5.0, f64::from(j) * 0.5 - 1.0);
                Vector2::new(5.0, -3.0) + r * local
            })
            .collect();
        let o = pca_obb(&pts).unwrap();
        assert_relative_eq!(o.center(), Vector2::new(5.0, -3.0), epsilon = 1e-12);
        assert_relative_eq!(o.half_extents(), Vector2::new(5.0, 1.0), epsilon = 1e-12);
        assert_relative_eq!(o.axis(0).x.abs(), angle.cos(), epsilon = 1e-12);
        assert!(pts.iter().all(|p| o.contains_point(p)));
    }

    #[test]
    fn degenerate_sets_give_flat_boxes() {
        let same = [Vector3::new(1.0, 2.0, 3.0); 4];
        let o = pca_obb(&same).unwrap();
        assert_eq!(o.half_extents(), Vector3::zeros());
        assert_eq!(o.center(), Vector3::new(1.0, 2.0, 3.0));
        let line: Vec<_> = (0..10)
            .map(|k| Vector3::new(1.0, 2.0, 2.0) * f64::from(k))
            .collect();
        let o = pca_obb(&line).unwrap();
        assert_relative_eq!(o.half_extents()[0], 13.5, epsilon = 1e-12);
        assert!(o.half_extents()[1] < 1e-12 && o.half_extents()[2] < 1e-12);
        assert!(line.iter().all(|p| o.contains_point(p)));
    }

    #[test]
    fn proper_rotation_repairs_reflections_and_dependent_columns() {
        let reflection = SMatrix::<f64, 3, 3>::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
        let r = proper_rotation(&reflection);
        assert_eq!(r.matrix(), &SMatrix::<f64, 3, 3>::identity());
        let dependent = SMatrix::<f64, 3, 3>::new(1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        let r = proper_rotation(&dependent);
        let m = r.matrix();
        assert_relative_eq!(
            m.transpose() * m,
            SMatrix::<f64, 3, 3>::identity(),
            epsilon = 1e-15
        );
        assert_relative_eq!(carom_math::determinant(m), 1.0, epsilon = 1e-15);
    }
}
