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

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

use nalgebra::{Const, Rotation, SVector, Vector1, Vector2, Vector3};

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

    #[test]
    fn ball_inertia_factors_are_disk_and_solid_sphere() {
        assert_eq!(<Const<2> as Space<f64, 2>>::ball_inertia_factor(), 0.5);
        assert_eq!(<Const<3> as Space<f32, 3>>::ball_inertia_factor(), 0.4);
    }
}
