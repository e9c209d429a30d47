//! Dimension-specific algebra behind one trait, so generic code is written once.
//!
//! Everything translational is the same in 2D and 3D and is written with
//! `nalgebra::SVector<T, D>`. What differs is angular: in 2D an angular velocity is a
//! pseudo-scalar (a rotation in the plane), in 3D a vector; the cross product of two
//! vectors is a pseudo-scalar in 2D and a vector in 3D; a uniform ball is a disk
//! (`I = m r²/2`) in 2D and a solid sphere (`I = 2 m r²/5`) in 3D. [`Space`] names these
//! operations and is implemented for [`Const<2>`] and [`Const<3>`]; generic code asks for
//! it with `where Const<D>: Space<T, D>`.
//!
//! The 2D angular quantities are stored as `Vector1<T>` so that both dimensions use
//! nalgebra vectors (`Angular = SVector<T, 1>` or `SVector<T, 3>`).
//!
//! Rigid bodies (collision response, clusters of stuck balls) also need a moment of
//! inertia: a scalar about the z axis in 2D, a symmetric 3×3 tensor in 3D
//! ([`Space::Inertia`]), with the operations grouped under "rigid-body inertia" below.

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

use nalgebra::{Const, Matrix3, Rotation, SVector, Vector1, Vector2, Vector3};

use crate::Real;

mod sealed {
    pub trait Sealed {}
    impl Sealed for nalgebra::Const<2> {}
    impl Sealed for nalgebra::Const<3> {}
}

/// The operations whose form depends on the dimension `D` (2 or 3).
pub trait Space<T: Real, const D: usize>: sealed::Sealed + Copy + Send + Sync + 'static {
    /// Angular velocity, angular momentum and torque: `Vector1` in 2D (the z component),
    /// `Vector3` in 3D.
    type Angular: Copy
        + Debug
        + PartialEq
        + Send
        + Sync
        + 'static
        + Add<Output = Self::Angular>
        + Sub<Output = Self::Angular>
        + Neg<Output = Self::Angular>
        + Mul<T, Output = Self::Angular>
        + AddAssign
        + SubAssign;

    /// The number of independent rotation axes: 1 in 2D, 3 in 3D.
    const ANGULAR_DIM: usize;

    /// The moment of inertia of a uniform ball of unit mass and unit radius about its
    /// centre: `1/2` (disk) in 2D, `2/5` (solid sphere) in 3D.
    fn ball_inertia_factor() -> T;

    /// `a × b`: the z component in 2D, the vector in 3D.
    fn cross(a: &SVector<T, D>, b: &SVector<T, D>) -> Self::Angular;

    /// `ω × r`: the velocity of the point at offset `r` on a body spinning at `ω`.
    fn angular_cross(w: &Self::Angular, r: &SVector<T, D>) -> SVector<T, D>;

    /// The zero angular vector.
    fn angular_zero() -> Self::Angular;

    /// The dot product of two angular vectors.
    fn angular_dot(a: &Self::Angular, b: &Self::Angular) -> T;

    /// The rotation by the angle `|ω| t` about `ω` (the exponential map): the orientation
    /// change of a body spinning at constant `ω` for time `t`.
    fn rotation_from_angular(w: &Self::Angular, t: T) -> Rotation<T, D>;

    /// Writes the candidate separating axes that two oriented boxes have beyond their
    /// face normals (the columns of the rotations): none in 2D, the nine cross products
    /// of edge directions in 3D. Returns how many were written; near-parallel edge pairs
    /// give near-zero vectors, which callers skip.
    fn edge_axes(a: &Rotation<T, D>, b: &Rotation<T, D>, out: &mut [SVector<T, D>; 9]) -> usize;

    /// The components of an angular vector (one in 2D, three in 3D), for validation and
    /// hashing.
    fn angular_as_slice(w: &Self::Angular) -> &[T];

    // --- Rigid-body inertia (collision response and rigid clusters) -------------------

    /// A moment of inertia about a body's centre of mass: `T` (about the z axis) in 2D, a
    /// symmetric 3×3 tensor (`Matrix3<T>`) in 3D. Inverse inertias use the same type.
    type Inertia: Copy
        + Debug
        + PartialEq
        + Send
        + Sync
        + 'static
        + Add<Output = Self::Inertia>
        + Mul<T, Output = Self::Inertia>;

    /// The isotropic inertia `s·𝟙` (`s` in 2D): a ball's inertia, or its inverse.
    fn inertia_isotropic(s: T) -> Self::Inertia;

    /// `I·ω`: the angular momentum of spin `ω`, or (with an inverse inertia) the spin
    /// change of an angular impulse.
    fn inertia_apply(inertia: &Self::Inertia, w: &Self::Angular) -> Self::Angular;

    /// `I⁻¹`, or `None` unless the inertia is finite, symmetric (to rounding:
    /// `|Iᵢⱼ − Iⱼᵢ| ≤ 64 ε max|I|`) and positive definite, and its inverse finite.
    /// In 3D the inverse comes from the Cholesky factor of the symmetric part and is
    /// symmetrised, so `inertia_inverse` of a symmetric tensor is symmetric.
    fn inertia_inverse(inertia: &Self::Inertia) -> Option<Self::Inertia>;

    /// `R I Rᵀ`: a body-frame inertia expressed in the world frame of a body with
    /// orientation `R` (unchanged in 2D, where the inertia is about the fixed z axis).
    fn inertia_rotated(inertia: &Self::Inertia, r: &Rotation<T, D>) -> Self::Inertia;

    /// The parallel-axis (Steiner) term of a mass `m` whose centre is displaced by `d`
    /// from the reference point: `m |d|²` in 2D, `m (|d|² 𝟙 − d dᵀ)` in 3D. A body's
    /// inertia about the reference point is its inertia about its centre plus this term.
    fn inertia_parallel_axis(mass: T, d: &SVector<T, D>) -> Self::Inertia;

    /// The entries of an inertia (one in 2D, nine column-major in 3D), for validation
    /// and hashing.
    fn inertia_as_slice(inertia: &Self::Inertia) -> &[T];
}

impl<T: Real> Space<T, 2> for Const<2> {
    type Angular = Vector1<T>;
    const ANGULAR_DIM: usize = 1;

    #[inline]
    fn ball_inertia_factor() -> T {
        T::lit(0.5)
    }

    #[inline]
    fn cross(a: &Vector2<T>, b: &Vector2<T>) -> Vector1<T> {
        Vector1::new(a.x * b.y - a.y * b.x)
    }

    #[inline]
    fn angular_cross(w: &Vector1<T>, r: &Vector2<T>) -> Vector2<T> {
        Vector2::new(-w.x * r.y, w.x * r.x)
    }

    #[inline]
    fn angular_zero() -> Vector1<T> {
        Vector1::zeros()
    }

    #[inline]
    fn angular_dot(a: &Vector1<T>, b: &Vector1<T>) -> T {
        a.x * b.x
    }

    #[inline]
    fn rotation_from_angular(w: &Vector1<T>, t: T) -> Rotation<T, 2> {
        Rotation::<T, 2>::new(w.x * t)
    }

    #[inline]
    fn edge_axes(_: &Rotation<T, 2>, _: &Rotation<T, 2>, _: &mut [Vector2<T>; 9]) -> usize {
        0
    }

    #[inline]
    fn angular_as_slice(w: &Vector1<T>) -> &[T] {
        w.as_slice()
    }

    type Inertia = T;

    #[inline]
    fn inertia_isotropic(s: T) -> T {
        s
    }

    #[inline]
    fn inertia_apply(inertia: &T, w: &Vector1<T>) -> Vector1<T> {
        w * *inertia
    }

    #[inline]
    fn inertia_inverse(inertia: &T) -> Option<T> {
        let inverse = T::one() / *inertia;
        (inertia.finite() && *inertia > T::zero() && inverse.finite()).then_some(inverse)
    }

    #[inline]
    fn inertia_rotated(inertia: &T, _: &Rotation<T, 2>) -> T {
        *inertia
    }

    #[inline]
    fn inertia_parallel_axis(mass: T, d: &Vector2<T>) -> T {
        mass * d.norm_squared()
    }

    #[inline]
    fn inertia_as_slice(inertia: &T) -> &[T] {
        core::slice::from_ref(inertia)
    }
}

impl<T: Real> Space<T, 3> for Const<3> {
    type Angular = Vector3<T>;
    const ANGULAR_DIM: usize = 3;

    #[inline]
    fn ball_inertia_factor() -> T {
        T::lit(0.4)
    }

    #[inline]
    fn cross(a: &Vector3<T>, b: &Vector3<T>) -> Vector3<T> {
        a.cross(b)
    }

    #[inline]
    fn angular_cross(w: &Vector3<T>, r: &Vector3<T>) -> Vector3<T> {
        w.cross(r)
    }

    #[inline]
    fn angular_zero() -> Vector3<T> {
        Vector3::zeros()
    }

    #[inline]
    fn angular_dot(a: &Vector3<T>, b: &Vector3<T>) -> T {
        a.dot(b)
    }

    #[inline]
    fn rotation_from_angular(w: &Vector3<T>, t: T) -> Rotation<T, 3> {
        Rotation::<T, 3>::from_scaled_axis(w * t)
    }

    #[inline]
    fn edge_axes(a: &Rotation<T, 3>, b: &Rotation<T, 3>, out: &mut [Vector3<T>; 9]) -> usize {
        let (ma, mb) = (a.matrix(), b.matrix());
        for i in 0..3 {
            for j in 0..3 {
                out[3 * i + j] = ma.column(i).cross(&mb.column(j));
            }
        }
        9
    }

    #[inline]
    fn angular_as_slice(w: &Vector3<T>) -> &[T] {
        w.as_slice()
    }

    type Inertia = Matrix3<T>;

    #[inline]
    fn inertia_isotropic(s: T) -> Matrix3<T> {
        Matrix3::from_diagonal_element(s)
    }

    #[inline]
    fn inertia_apply(inertia: &Matrix3<T>, w: &Vector3<T>) -> Vector3<T> {
        inertia * w
    }

    fn inertia_inverse(inertia: &Matrix3<T>) -> Option<Matrix3<T>> {
        if !inertia.iter().all(|x| x.finite()) {
            return None;
        }
        let scale = inertia.amax();
        let asymmetry = (inertia - inertia.transpose()).amax();
        if asymmetry > T::lit(64.0) * T::EPSILON * scale {
            return None;
        }
        let symmetric = (inertia + inertia.transpose()) * T::lit(0.5);
        let inverse = symmetric.cholesky()?.inverse();
        let inverse = (inverse + inverse.transpose()) * T::lit(0.5);
        inverse.iter().all(|x| x.finite()).then_some(inverse)
    }

    #[inline]
    fn inertia_rotated(inertia: &Matrix3<T>, r: &Rotation<T, 3>) -> Matrix3<T> {
        let m = r.matrix();
        m * inertia * m.transpose()
    }

    #[inline]
    fn inertia_parallel_axis(mass: T, d: &Vector3<T>) -> Matrix3<T> {
        (Matrix3::from_diagonal_element(d.norm_squared()) - d * d.transpose()) * mass
    }

    #[inline]
    fn inertia_as_slice(inertia: &Matrix3<T>) -> &[T] {
        inertia.as_slice()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn cross_2d_is_the_z_component_of_the_3d_cross() {
        let (a, b) = (Vector2::new(1.5, -2.0), Vector2::new(0.25, 4.0));
        let c3 = Vector3::new(a.x, a.y, 0.0).cross(&Vector3::new(b.x, b.y, 0.0));
        assert_eq!(<Const<2> as Space<f64, 2>>::cross(&a, &b).x, c3.z);
    }

    #[test]
    fn angular_cross_2d_matches_3d_and_is_perpendicular() {
        let w = Vector1::new(0.7);
        let r = Vector2::new(2.0, -1.0);
        let v = <Const<2> as Space<f64, 2>>::angular_cross(&w, &r);
        let v3 = Vector3::new(0.0, 0.0, 0.7).cross(&Vector3::new(2.0, -1.0, 0.0));
        assert_relative_eq!(v, Vector2::new(v3.x, v3.y));
        assert_eq!(v.dot(&r), 0.0);
    }

    #[test]
    fn rotation_from_angular_turns_by_omega_t() {
        let r2 = <Const<2> as Space<f64, 2>>::rotation_from_angular(&Vector1::new(2.0), 0.25);
        assert_relative_eq!(r2.angle(), 0.5, epsilon = 1e-15);
        let w = Vector3::new(0.0, 0.0, 2.0);
        let r3 = <Const<3> as Space<f64, 3>>::rotation_from_angular(&w, 0.25);
        assert_relative_eq!(
            r3 * Vector3::x(),
            Vector3::new(0.5f64.cos(), 0.5f64.sin(), 0.0),
            epsilon = 1e-15
        );
    }

    #[test]
    fn edge_axes_are_all_nine_crosses_in_3d_and_none_in_2d() {
        let mut out = [Vector3::zeros(); 9];
        let id = Rotation::<f64, 3>::identity();
        assert_eq!(
            <Const<3> as Space<f64, 3>>::edge_axes(&id, &id, &mut out),
            9
        );
        assert_eq!(out[1], Vector3::z()); // x × y
        let mut out2 = [Vector2::zeros(); 9];
        let id2 = Rotation::<f64, 2>::identity();
        assert_eq!(
            <Const<2> as Space<f64, 2>>::edge_axes(&id2, &id2, &mut out2),
            0
        );
    }

    type S2 = Const<2>;
    type S3 = Const<3>;

    #[test]
    fn inertia_apply_and_inverse_agree_in_both_dimensions() {
        let i2 = <S2 as Space<f64, 2>>::inertia_isotropic(4.0);
        let w2 = Vector1::new(0.5);
        assert_eq!(<S2 as Space<f64, 2>>::inertia_apply(&i2, &w2).x, 2.0);
        assert_eq!(<S2 as Space<f64, 2>>::inertia_inverse(&i2), Some(0.25));
        assert_eq!(<S2 as Space<f64, 2>>::inertia_inverse(&0.0), None);
        assert_eq!(<S2 as Space<f64, 2>>::inertia_inverse(&-1.0), None);
        assert_eq!(<S2 as Space<f64, 2>>::inertia_inverse(&f64::NAN), None);
        assert_eq!(<S2 as Space<f64, 2>>::inertia_inverse(&1e-310), None); // inverse overflows

        let i3 = Matrix3::new(2.0, 0.5, 0.0, 0.5, 3.0, 0.25, 0.0, 0.25, 1.5);
        let inv = <S3 as Space<f64, 3>>::inertia_inverse(&i3).unwrap();
        assert_relative_eq!(inv * i3, Matrix3::identity(), epsilon = 1e-14);
        assert_eq!(inv, inv.transpose());
        let w = Vector3::new(1.0, -2.0, 0.5);
        assert_eq!(<S3 as Space<f64, 3>>::inertia_apply(&i3, &w), i3 * w);
    }

    #[test]
    fn inertia_inverse_rejects_indefinite_asymmetric_and_non_finite_tensors() {
        let indefinite = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0));
        assert_eq!(<S3 as Space<f64, 3>>::inertia_inverse(&indefinite), None);
        let singular = Matrix3::from_diagonal(&Vector3::new(1.0, 0.0, 1.0));
        assert_eq!(<S3 as Space<f64, 3>>::inertia_inverse(&singular), None);
        let mut asymmetric = Matrix3::<f64>::identity();
        asymmetric[(0, 1)] = 0.1;
        assert_eq!(<S3 as Space<f64, 3>>::inertia_inverse(&asymmetric), None);
        let mut nan = Matrix3::<f64>::identity();
        nan[(2, 2)] = f64::NAN;
        assert_eq!(<S3 as Space<f64, 3>>::inertia_inverse(&nan), None);
    }

    #[test]
    fn rotated_inertia_keeps_the_spectrum_and_turns_the_principal_axes() {
        let body = Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0));
        let r =
            Rotation::<f64, 3>::from_axis_angle(&Vector3::z_axis(), core::f64::consts::FRAC_PI_2);
        let world = <S3 as Space<f64, 3>>::inertia_rotated(&body, &r);
        // The body x axis (moment 1) now points along world y.
        assert_relative_eq!(world * Vector3::y(), Vector3::y(), epsilon = 1e-15);
        assert_relative_eq!(world * Vector3::x(), Vector3::x() * 2.0, epsilon = 1e-15);
        assert_relative_eq!(world.trace(), 6.0, epsilon = 1e-15);
        let r2 = Rotation::<f64, 2>::new(0.3);
        assert_eq!(<S2 as Space<f64, 2>>::inertia_rotated(&5.0, &r2), 5.0);
    }

    #[test]
    fn parallel_axis_term_is_the_point_mass_inertia() {
        // A point mass m at d has inertia m |d|² about the z axis in 2D.
        let d2 = Vector2::new(3.0, 4.0);
        assert_eq!(<S2 as Space<f64, 2>>::inertia_parallel_axis(2.0, &d2), 50.0);
        // In 3D, L = m d × (ω × d) = (m (|d|² 𝟙 − d dᵀ)) ω for every ω.
        let d = Vector3::new(1.0, -2.0, 0.5);
        let w = Vector3::new(0.3, 0.7, -1.1);
        let term = <S3 as Space<f64, 3>>::inertia_parallel_axis(2.0, &d);
        assert_relative_eq!(term * w, d.cross(&w.cross(&d)) * 2.0, epsilon = 1e-14);
        assert_eq!(term, term.transpose());
    }

    #[test]
    fn slices_expose_every_component() {
        assert_eq!(
            <S2 as Space<f64, 2>>::angular_as_slice(&Vector1::new(1.5)),
            &[1.5]
        );
        assert_eq!(
            <S3 as Space<f64, 3>>::angular_as_slice(&Vector3::new(1.0, 2.0, 3.0)),
            &[1.0, 2.0, 3.0]
        );
        assert_eq!(<S2 as Space<f64, 2>>::inertia_as_slice(&2.0), &[2.0]);
        assert_eq!(
            <S3 as Space<f64, 3>>::inertia_as_slice(&Matrix3::identity()).len(),
            9
        );
    }

    #[test]
    fn ball_inertia_factors_are_disk_and_solid_sphere() {
        assert_eq!(<Const<2> as Space<f64, 2>>::ball_inertia_factor(), 0.5);
        assert_eq!(<Const<3> as Space<f32, 3>>::ball_inertia_factor(), 0.4);
    }
}
