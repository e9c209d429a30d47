//! carom-geometry's queries against parry 0.31, side by side in one run.
//!
//! Every benchmark runs one query over a batch of [`BATCH`] precomputed random inputs
//! (built before timing, so the loop measures queries, not the generator), and criterion
//! reports the time per batch and the throughput; nanoseconds per query are the batch
//! time divided by [`BATCH`]. For each query:
//!
//! * `carom_f64`, `carom_f32`: carom's function on world-space shapes;
//! * `parry_generic`: parry's `query::intersection_test` / `contact` / `distance` on
//!   `&dyn Shape` with poses (the dispatcher every parry user goes through);
//! * `parry_specific`: parry's shape-specific function (`query::details::*`, or the
//!   bounding-volume / ray-cast method), including the relative pose it needs.
//!
//! parry computes in `f32`; `carom_f32` is the like-for-like comparison.
//!
//! Run: `cargo bench --bench geometry` (add `-- --measurement-time 1` for a quick pass).
//! The measured table is in docs/geometry.md.

use std::hint::black_box;
use std::time::Duration;

use carom::geometry::query::{
    Contact, Overlap, PointQuery, Ray, RayCast, cast_ray, contact, distance, overlaps,
};
use carom::geometry::{Aabb, Ball, HalfSpace, Obb, Real, Rotation, Space, Vector};
use carom::math::nalgebra::Const;
use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion, Throughput, criterion_group, criterion_main};

/// Inputs per timed batch.
const BATCH: usize = 1024;

/// SplitMix64: deterministic inputs, the same on every run.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    fn vector<const D: usize>(&mut self, lo: f64, hi: f64) -> Vector<f64, D> {
        Vector::from_fn(|_, _| self.range(lo, hi))
    }
}

/// A random scene element as plain `f64` numbers; each library builds its own shape from
/// it. About half of the pairs drawn from these ranges touch or overlap.
#[derive(Clone, Copy)]
struct Spec<const D: usize> {
    center: Vector<f64, D>,
    /// Ball radius, box half extents (per axis), or (for a half-space) the normal.
    size: Vector<f64, D>,
    rotation: Rotation<f64, D>,
}

impl<const D: usize> Spec<D>
where
    Const<D>: Space<f64, D>,
{
    fn random(rng: &mut Rng, spread: f64) -> Self {
        let (u, v) = (rng.vector::<D>(-2.0, 2.0), rng.vector::<D>(-2.0, 2.0));
        let w = <Const<D> as Space<f64, D>>::cross(&u, &v);
        Self {
            center: rng.vector(-spread, spread),
            size: rng.vector(0.2, 1.5),
            rotation: <Const<D> as Space<f64, D>>::rotation_from_angular(&w, 1.0),
        }
    }

    fn ball<T: Real>(&self) -> Ball<T, D> {
        Ball::new(self.center.map(T::lit), T::lit(self.size[0])).unwrap()
    }

    fn aabb<T: Real>(&self) -> Aabb<T, D> {
        Aabb::from_center_half_extents(self.center.map(T::lit), self.size.map(T::lit)).unwrap()
    }

    fn obb<T: Real>(&self) -> Obb<T, D> {
        let r = Rotation::from_matrix_unchecked(self.rotation.matrix().map(T::lit));
        Obb::new(self.center.map(T::lit), self.size.map(T::lit), r).unwrap()
    }

    fn half_space<T: Real>(&self) -> HalfSpace<T, D> {
        HalfSpace::new(
            self.rotation.matrix().column(0).map(T::lit),
            self.center.map(T::lit),
        )
        .unwrap()
    }

    fn ray<T: Real>(&self) -> Ray<T, D> {
        Ray::new(
            self.center.map(T::lit),
            self.rotation.matrix().column(0).map(T::lit),
        )
        .unwrap()
    }
}

/// `n` random pairs of specs, the second within `spread` of the origin like the first.
fn pairs<const D: usize>(seed: u64, spread: f64) -> Vec<(Spec<D>, Spec<D>)>
where
    Const<D>: Space<f64, D>,
{
    let mut rng = Rng(seed);
    (0..BATCH)
        .map(|_| {
            (
                Spec::random(&mut rng, spread),
                Spec::random(&mut rng, spread),
            )
        })
        .collect()
}

/// The benchmark group `dim/query`, with its throughput in queries.
fn group<'a>(c: &'a mut Criterion, dim: &str, query: &str) -> BenchmarkGroup<'a, WallTime> {
    let mut g = c.benchmark_group(format!("{dim}/{query}"));
    g.throughput(Throughput::Elements(BATCH as u64));
    g
}

/// Times `query` over every input of the batch; `query` returns a number to sum so the
/// optimiser cannot drop the work.
fn run<I>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    inputs: &[I],
    query: impl Fn(&I) -> f64,
) {
    group.bench_function(name, |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for input in black_box(inputs) {
                acc += query(input);
            }
            acc
        });
    });
}

/// Runs the same carom query on the `f64` and `f32` inputs (the first two fields of each
/// input tuple): `$x` is the pair of carom shapes in either precision.
macro_rules! carom_runs {
    ($g:expr, $input:expr, |$x:ident| $body:expr) => {
        run($g, "carom_f64", $input, |($x, _, _)| $body);
        run($g, "carom_f32", $input, |(_, $x, _)| $body);
    };
}

/// The number a query's answer adds to the checksum: 1 for an overlap.
fn flag(b: bool) -> f64 {
    f64::from(u8::from(b))
}

/// The contact depth a carom contact adds to the checksum.
fn depth<T: Real, const D: usize>(c: Option<Contact<T, D>>) -> f64 {
    c.map_or(0.0, |c| c.depth.to_f64())
}

/// The benches of one dimension, with the parry crate of that dimension.
macro_rules! parry_benches {
    ($name:ident, $parry:ident, $dim:literal, $pose:ident) => {
        mod $name {
            use super::*;
            use $parry::bounding_volume::BoundingVolume as _;
            use $parry::math::{Pose, Vector as PVector};
            use $parry::query::{self as pq, details as pd};
            use $parry::shape::{Ball as PBall, Cuboid, HalfSpace as PHalfSpace, Shape};

            /// A pair of parry shapes with their poses.
            type Pair<A, B> = ((Pose, A), (Pose, B));

            fn vector(v: &Vector<f64, $dim>) -> PVector {
                PVector::from_slice(v.map(|x| x as f32).as_slice())
            }

            fn ball(s: &Spec<$dim>) -> (Pose, PBall) {
                (
                    Pose::from_translation(vector(&s.center)),
                    PBall::new(s.size[0] as f32),
                )
            }

            fn aabb(s: &Spec<$dim>) -> (Pose, Cuboid) {
                (
                    Pose::from_translation(vector(&s.center)),
                    Cuboid::new(vector(&s.size)),
                )
            }

            fn obb(s: &Spec<$dim>) -> (Pose, Cuboid) {
                (
                    $pose(vector(&s.center), &s.rotation),
                    Cuboid::new(vector(&s.size)),
                )
            }

            fn half_space(s: &Spec<$dim>) -> (Pose, PHalfSpace) {
                let n = s.rotation.matrix().column(0).into_owned();
                (
                    Pose::from_translation(vector(&s.center)),
                    PHalfSpace::new(vector(&n)),
                )
            }

            /// parry's generic `intersection_test` on a pair.
            fn parry_overlap<A: Shape, B: Shape>(((pa, a), (pb, b)): &Pair<A, B>) -> f64 {
                flag(pq::intersection_test(pa, a, pb, b).unwrap().intersecting)
            }

            /// parry's generic `contact` on a pair (prediction 0).
            fn parry_contact<A: Shape, B: Shape>(((pa, a), (pb, b)): &Pair<A, B>) -> f64 {
                parry_depth(pq::contact(pa, a, pb, b, 0.0).unwrap())
            }

            fn parry_depth(c: Option<pq::Contact>) -> f64 {
                c.map_or(0.0, |c| f64::from(c.dist))
            }

            pub(super) fn benches(c: &mut Criterion) {
                let dim = concat!($dim, "d");
                let near = pairs::<$dim>(0xC0FFEE + $dim, 1.5);
                ball_ball(c, dim, &near);
                ball_box(
                    c,
                    dim,
                    "aabb",
                    &near,
                    Spec::aabb::<f64>,
                    Spec::aabb::<f32>,
                    aabb,
                );
                ball_box(
                    c,
                    dim,
                    "obb",
                    &near,
                    Spec::obb::<f64>,
                    Spec::obb::<f32>,
                    obb,
                );
                ball_half_space(c, dim, &near);
                box_box(c, dim, &near);
                ray_group(
                    c,
                    dim,
                    "ray_ball",
                    &near,
                    Spec::ball::<f64>,
                    Spec::ball::<f32>,
                    ball,
                );
                ray_group(
                    c,
                    dim,
                    "ray_aabb",
                    &near,
                    Spec::aabb::<f64>,
                    Spec::aabb::<f32>,
                    aabb,
                );
                ray_group(
                    c,
                    dim,
                    "ray_obb",
                    &near,
                    Spec::obb::<f64>,
                    Spec::obb::<f32>,
                    obb,
                );
            }

            /// Ball–ball overlap and contact.
            fn ball_ball(c: &mut Criterion, dim: &str, near: &[(Spec<$dim>, Spec<$dim>)]) {
                let input: Vec<_> = near
                    .iter()
                    .map(|(a, b)| {
                        (
                            (a.ball::<f64>(), b.ball::<f64>()),
                            (a.ball::<f32>(), b.ball::<f32>()),
                            (ball(a), ball(b)),
                        )
                    })
                    .collect();
                let mut g = group(c, dim, "ball_ball_overlap");
                carom_runs!(&mut g, &input, |x| flag(overlaps(&x.0, &x.1)));
                run(&mut g, "parry_generic", &input, |(_, _, p)| {
                    parry_overlap(p)
                });
                run(
                    &mut g,
                    "parry_specific",
                    &input,
                    |(_, _, ((pa, a), (pb, b)))| {
                        flag(pd::intersection_test_ball_ball(
                            pb.translation - pa.translation,
                            a,
                            b,
                        ))
                    },
                );
                g.finish();
                let mut g = group(c, dim, "ball_ball_contact");
                carom_runs!(&mut g, &input, |x| depth(contact(&x.0, &x.1)));
                run(&mut g, "parry_generic", &input, |(_, _, p)| {
                    parry_contact(p)
                });
                run(
                    &mut g,
                    "parry_specific",
                    &input,
                    |(_, _, ((pa, a), (pb, b)))| {
                        parry_depth(pd::contact_ball_ball(&pa.inv_mul(pb), a, b, 0.0))
                    },
                );
                g.finish();
            }

            /// Ball–box overlap and contact, for one kind of box (`aabb` or `obb`).
            fn ball_box<S64, S32>(
                c: &mut Criterion,
                dim: &str,
                kind: &str,
                near: &[(Spec<$dim>, Spec<$dim>)],
                carom64: impl Fn(&Spec<$dim>) -> S64,
                carom32: impl Fn(&Spec<$dim>) -> S32,
                parry: impl Fn(&Spec<$dim>) -> (Pose, Cuboid),
            ) where
                Ball<f64, $dim>: Overlap<S64>,
                Ball<f32, $dim>: Overlap<S32>,
                S64: PointQuery<f64, $dim>,
                S32: PointQuery<f32, $dim>,
            {
                let input: Vec<_> = near
                    .iter()
                    .map(|(a, b)| {
                        (
                            (a.ball::<f64>(), carom64(b)),
                            (a.ball::<f32>(), carom32(b)),
                            (ball(a), parry(b)),
                        )
                    })
                    .collect();
                let mut g = group(c, dim, &format!("ball_{kind}_overlap"));
                carom_runs!(&mut g, &input, |x| flag(overlaps(&x.0, &x.1)));
                run(&mut g, "parry_generic", &input, |(_, _, p)| {
                    parry_overlap(p)
                });
                run(
                    &mut g,
                    "parry_specific",
                    &input,
                    |(_, _, ((pa, a), (pb, b)))| {
                        flag(
                            pd::intersection_test_ball_point_query(&pa.inv_mul(pb), a, b)
                                .intersecting,
                        )
                    },
                );
                g.finish();
                let mut g = group(c, dim, &format!("ball_{kind}_contact"));
                carom_runs!(&mut g, &input, |x| depth(contact(&x.0, &x.1)));
                run(&mut g, "parry_generic", &input, |(_, _, p)| {
                    parry_contact(p)
                });
                run(
                    &mut g,
                    "parry_specific",
                    &input,
                    |(_, _, ((pa, a), (pb, b)))| {
                        parry_depth(pd::contact_ball_convex_polyhedron(
                            &pa.inv_mul(pb),
                            a,
                            b,
                            0.0,
                        ))
                    },
                );
                g.finish();
            }

            /// Ball–half-space contact. parry is asked half-space first: its
            /// `contact(shape, half_space)` order has a pose bug in 0.31.
            fn ball_half_space(c: &mut Criterion, dim: &str, near: &[(Spec<$dim>, Spec<$dim>)]) {
                let input: Vec<_> = near
                    .iter()
                    .map(|(a, b)| {
                        (
                            (a.ball::<f64>(), b.half_space::<f64>()),
                            (a.ball::<f32>(), b.half_space::<f32>()),
                            (half_space(b), ball(a)),
                        )
                    })
                    .collect();
                let mut g = group(c, dim, "ball_half_space_contact");
                carom_runs!(&mut g, &input, |x| depth(contact(&x.0, &x.1)));
                run(&mut g, "parry_generic", &input, |(_, _, p)| {
                    parry_contact(p)
                });
                run(
                    &mut g,
                    "parry_specific",
                    &input,
                    |(_, _, ((ph, h), (pb, b)))| {
                        parry_depth(pd::contact_halfspace_support_map(
                            &ph.inv_mul(pb),
                            h,
                            b,
                            0.0,
                        ))
                    },
                );
                g.finish();
            }

            /// AABB–AABB and OBB–OBB overlap, OBB–OBB distance.
            fn box_box(c: &mut Criterion, dim: &str, near: &[(Spec<$dim>, Spec<$dim>)]) {
                let input: Vec<_> = near
                    .iter()
                    .map(|(a, b)| {
                        let bv = |s: &Spec<$dim>| {
                            $parry::bounding_volume::Aabb::from_half_extents(
                                vector(&s.center),
                                vector(&s.size),
                            )
                        };
                        (
                            (a.aabb::<f64>(), b.aabb::<f64>()),
                            (a.aabb::<f32>(), b.aabb::<f32>()),
                            ((aabb(a), aabb(b)), (bv(a), bv(b))),
                        )
                    })
                    .collect();
                let mut g = group(c, dim, "aabb_aabb_overlap");
                carom_runs!(&mut g, &input, |x| flag(overlaps(&x.0, &x.1)));
                run(&mut g, "parry_generic", &input, |(_, _, (p, _))| {
                    parry_overlap(p)
                });
                run(&mut g, "parry_specific", &input, |(_, _, (_, (a, b)))| {
                    flag(a.intersects(b))
                });
                g.finish();

                let input: Vec<_> = near
                    .iter()
                    .map(|(a, b)| {
                        (
                            (a.obb::<f64>(), b.obb::<f64>()),
                            (a.obb::<f32>(), b.obb::<f32>()),
                            (obb(a), obb(b)),
                        )
                    })
                    .collect();
                let mut g = group(c, dim, "obb_obb_overlap");
                carom_runs!(&mut g, &input, |x| flag(overlaps(&x.0, &x.1)));
                run(&mut g, "parry_generic", &input, |(_, _, p)| {
                    parry_overlap(p)
                });
                run(
                    &mut g,
                    "parry_specific",
                    &input,
                    |(_, _, ((pa, a), (pb, b)))| {
                        flag(pd::intersection_test_cuboid_cuboid(&pa.inv_mul(pb), a, b))
                    },
                );
                g.finish();
                let mut g = group(c, dim, "obb_obb_distance");
                carom_runs!(&mut g, &input, |x| distance(&x.0, &x.1).to_f64());
                run(
                    &mut g,
                    "parry_generic",
                    &input,
                    |(_, _, ((pa, a), (pb, b)))| {
                        f64::from(pq::distance(pa, a, pb, b).unwrap().distance)
                    },
                );
                run(
                    &mut g,
                    "parry_specific",
                    &input,
                    |(_, _, ((pa, a), (pb, b)))| {
                        f64::from(pd::distance_cuboid_cuboid(&pa.inv_mul(pb), a, b))
                    },
                );
                g.finish();
            }

            /// Ray casts against one kind of shape: carom in both precisions and parry's
            /// `cast_ray_and_get_normal` on the concrete shape (solid). Rays start at a
            /// random point along a random unit direction, with reach 10.
            fn ray_group<S64, S32, P>(
                c: &mut Criterion,
                dim: &str,
                query: &str,
                near: &[(Spec<$dim>, Spec<$dim>)],
                carom64: impl Fn(&Spec<$dim>) -> S64,
                carom32: impl Fn(&Spec<$dim>) -> S32,
                parry: impl Fn(&Spec<$dim>) -> (Pose, P),
            ) where
                S64: RayCast<f64, $dim>,
                S32: RayCast<f32, $dim>,
                P: pq::RayCast,
            {
                let input: Vec<_> = near
                    .iter()
                    .map(|(r, s)| {
                        let d = r.rotation.matrix().column(0).into_owned();
                        (
                            (r.ray::<f64>(), carom64(s)),
                            (r.ray::<f32>(), carom32(s)),
                            (pq::Ray::new(vector(&r.center), vector(&d)), parry(s)),
                        )
                    })
                    .collect();
                let mut g = group(c, dim, query);
                carom_runs!(&mut g, &input, |x| {
                    cast_ray(&x.1, &x.0, Real::lit(10.0)).map_or(0.0, |h| h.toi.to_f64())
                });
                run(
                    &mut g,
                    "parry_specific",
                    &input,
                    |(_, _, (ray, (pose, s)))| {
                        s.cast_ray_and_get_normal(pose, ray, 10.0, true)
                            .map_or(0.0, |h| f64::from(h.time_of_impact))
                    },
                );
                g.finish();
            }
        }
    };
}

/// parry's 2D pose: translation and the rotation as a unit complex number.
fn pose2(t: parry2d::math::Vector, r: &Rotation<f64, 2>) -> parry2d::math::Pose {
    let m = r.matrix();
    parry2d::math::Pose::from_parts(
        t,
        parry2d::math::Rotation::from_cos_sin_unchecked(m[(0, 0)] as f32, m[(1, 0)] as f32),
    )
}

/// parry's 3D pose: translation and the rotation as a unit quaternion.
fn pose3(t: parry3d::math::Vector, r: &Rotation<f64, 3>) -> parry3d::math::Pose {
    let q = carom::math::nalgebra::UnitQuaternion::from_rotation_matrix(r);
    let quat = glam::Quat::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32).normalize();
    parry3d::math::Pose::from_parts(t, quat)
}

parry_benches!(d2, parry2d, 2, pose2);
parry_benches!(d3, parry3d, 3, pose3);

fn config() -> Criterion {
    Criterion::default()
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .sample_size(30)
}

criterion_group! {
    name = geometry;
    config = config();
    targets = d2::benches, d3::benches
}
criterion_main!(geometry);
