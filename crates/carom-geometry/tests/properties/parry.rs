//! parry2d / parry3d 0.31 (f32, glam 0.33) as oracles, behind one trait so the tests are
//! written once for both dimensions. Conversions go through carom-math's `glam` feature
//! (nalgebra's `From` impls for glam 0.33).

use carom_geometry::query::Ray;
use carom_geometry::{Ball, BoundingVolume, Rotation, Vector};

use crate::scene::Shape;

/// A contact as parry reports it, in carom's convention: the normal points from the
/// shape towards the ball, the depth is positive in penetration.
#[derive(Clone, Copy, Debug)]
pub(crate) struct OracleContact<const D: usize> {
    pub(crate) normal: Vector<f64, D>,
    pub(crate) depth: f64,
    pub(crate) point_on_ball: Vector<f64, D>,
    pub(crate) point_on_shape: Vector<f64, D>,
}

/// What the tests ask parry.
pub(crate) trait Oracle<const D: usize> {
    /// `parry::query::contact(ball, shape, prediction)`.
    fn contact(ball: &Ball<f64, D>, shape: &Shape<D>, prediction: f64) -> Option<OracleContact<D>>;
    /// `parry::query::intersection_test`.
    fn intersects(a: &Shape<D>, b: &Shape<D>) -> bool;
    /// `parry::query::distance`.
    fn distance(a: &Shape<D>, b: &Shape<D>) -> f64;
    /// The signed distance from `parry::query::contact` with a large prediction (parry's
    /// penetration depth when the shapes overlap).
    fn contact_distance(a: &Shape<D>, b: &Shape<D>) -> f64;
    /// `project_point(.., solid = false)`: the nearest boundary point and whether `p` is inside.
    fn project(shape: &Shape<D>, p: &Vector<f64, D>) -> (Vector<f64, D>, bool);
    /// `cast_ray_and_get_normal(.., solid = true)`: time of impact and normal.
    fn cast_ray(shape: &Shape<D>, ray: &Ray<f64, D>, max_toi: f64)
    -> Option<(f64, Vector<f64, D>)>;
}

/// parry's 2D pose: translation and (optionally) the rotation matrix as a unit complex.
fn pose2(c: &Vector<f64, 2>, r: Option<&Rotation<f64, 2>>) -> parry2d::math::Pose {
    let t: glam::Vec2 = c.cast::<f32>().into();
    match r {
        None => parry2d::math::Pose::from_translation(t),
        Some(r) => parry2d::math::Pose::from_parts(
            t,
            parry2d::math::Rotation::from_matrix_unchecked(glam::Mat2::from(r.cast::<f32>())),
        ),
    }
}

/// parry's 3D pose: translation and (optionally) the rotation as a quaternion.
fn pose3(c: &Vector<f64, 3>, r: Option<&Rotation<f64, 3>>) -> parry3d::math::Pose {
    let t: glam::Vec3 = c.cast::<f32>().into();
    match r {
        None => parry3d::math::Pose::from_translation(t),
        Some(r) => parry3d::math::Pose::from_parts(t, glam::Quat::from(r.cast::<f32>())),
    }
}

/// Implements [`Oracle`] for `$oracle` with the parry crate `$parry` of dimension `$dim`.
macro_rules! parry_oracle {
    ($oracle:ident, $parry:ident, $dim:literal, $pose:ident) => {
        /// The parry oracle in this dimension.
        pub(crate) struct $oracle;

        impl $oracle {
            fn glam(v: &Vector<f64, $dim>) -> $parry::math::Vector {
                v.cast::<f32>().into()
            }

            fn carom(v: $parry::math::Vector) -> Vector<f64, $dim> {
                Vector::<f32, $dim>::from(v).cast::<f64>()
            }

            fn shape(s: &Shape<$dim>) -> ($parry::math::Pose, Box<dyn $parry::shape::Shape>) {
                use $parry::shape::{Ball as PBall, Cuboid, HalfSpace as PHalfSpace};
                match s {
                    Shape::Ball(b) => (
                        $pose(&b.center(), None),
                        Box::new(PBall::new(b.radius() as f32)),
                    ),
                    Shape::Aabb(a) => (
                        $pose(&a.center(), None),
                        Box::new(Cuboid::new(Self::glam(&a.half_extents()))),
                    ),
                    Shape::Obb(o) => (
                        $pose(&o.center(), Some(o.rotation())),
                        Box::new(Cuboid::new(Self::glam(&o.half_extents()))),
                    ),
                    Shape::HalfSpace(h) => (
                        $pose(&(h.normal() * h.offset()), None),
                        Box::new(PHalfSpace::new(Self::glam(&h.normal()))),
                    ),
                }
            }
        }

        impl Oracle<$dim> for $oracle {
            fn contact(
                ball: &Ball<f64, $dim>,
                shape: &Shape<$dim>,
                prediction: f64,
            ) -> Option<OracleContact<$dim>> {
                let (p1, g1) = Self::shape(&Shape::Ball(*ball));
                let (p2, g2) = Self::shape(shape);
                if let Shape::HalfSpace(_) = shape {
                    // parry 0.31's `contact(shape, half_space)` passes the pose of the
                    // half-space where the pose of the shape is expected (a missing
                    // `inverse()` in `contact_support_map_halfspace`; its intersection
                    // and distance twins have it). Ask in the other order.
                    let c = $parry::query::contact(&p2, &*g2, &p1, &*g1, prediction as f32)
                        .expect("parry supports every ball pair")?;
                    return Some(OracleContact {
                        normal: Self::carom(c.normal1),
                        depth: -f64::from(c.dist),
                        point_on_ball: Self::carom(c.point2),
                        point_on_shape: Self::carom(c.point1),
                    });
                }
                let c = $parry::query::contact(&p1, &*g1, &p2, &*g2, prediction as f32)
                    .expect("parry supports every ball pair")?;
                Some(OracleContact {
                    normal: -Self::carom(c.normal1),
                    depth: -f64::from(c.dist),
                    point_on_ball: Self::carom(c.point1),
                    point_on_shape: Self::carom(c.point2),
                })
            }

            fn intersects(a: &Shape<$dim>, b: &Shape<$dim>) -> bool {
                let (p1, g1) = Self::shape(a);
                let (p2, g2) = Self::shape(b);
                $parry::query::intersection_test(&p1, &*g1, &p2, &*g2)
                    .expect("parry supports the pair")
                    .intersecting
            }

            fn distance(a: &Shape<$dim>, b: &Shape<$dim>) -> f64 {
                let (p1, g1) = Self::shape(a);
                let (p2, g2) = Self::shape(b);
                f64::from(
                    $parry::query::distance(&p1, &*g1, &p2, &*g2)
                        .expect("parry supports the pair")
                        .distance,
                )
            }

            fn contact_distance(a: &Shape<$dim>, b: &Shape<$dim>) -> f64 {
                // The half-space first: see `contact` for the parry 0.31 bug.
                let (a, b) = if let Shape::HalfSpace(_) = b {
                    (b, a)
                } else {
                    (a, b)
                };
                let (p1, g1) = Self::shape(a);
                let (p2, g2) = Self::shape(b);
                let c = $parry::query::contact(&p1, &*g1, &p2, &*g2, 1e6)
                    .expect("parry supports the pair")
                    .expect("a prediction of 1e6 reaches every test scene");
                f64::from(c.dist)
            }

            fn project(shape: &Shape<$dim>, p: &Vector<f64, $dim>) -> (Vector<f64, $dim>, bool) {
                let (pose, g) = Self::shape(shape);
                let proj = g.project_point(&pose, Self::glam(p), false);
                (Self::carom(proj.point), proj.is_inside)
            }

            fn cast_ray(
                shape: &Shape<$dim>,
                ray: &Ray<f64, $dim>,
                max_toi: f64,
            ) -> Option<(f64, Vector<f64, $dim>)> {
                let (pose, g) = Self::shape(shape);
                let r = $parry::query::Ray::new(
                    Self::glam(&ray.origin()),
                    Self::glam(&ray.direction()),
                );
                g.cast_ray_and_get_normal(&pose, &r, max_toi as f32, true)
                    .map(|hit| (f64::from(hit.time_of_impact), Self::carom(hit.normal)))
            }
        }
    };
}

parry_oracle!(Parry2, parry2d, 2, pose2);
parry_oracle!(Parry3, parry3d, 3, pose3);
