//! Time of impact per query: carom's closed forms against parry 0.31's `cast_shapes`
//! (f32, the same random queries for both), plus the ballistic and cluster queries for
//! reference. Each benchmark runs a batch of 1024 varied queries (hits and misses) so
//! branch prediction sees a realistic mix; criterion reports time per query
//! (`Throughput::Elements`).

use std::hint::black_box;

use carom::geometry::{Aabb, Ball, HalfSpace};
use carom::toi::{
    AdvanceOptions, Cluster, ConstantSpin, Kinematics, Window, ball_aabb, ball_ball, cluster_plane,
};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{Rotation2, Vector1, Vector2, Vector3};

const BATCH: usize = 1024;

/// A small deterministic generator (no dependency): uniform in `[lo, hi)`.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self, lo: f32, hi: f32) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let u = (self.0 >> 40) as f32 / (1u64 << 24) as f32;
        lo + (hi - lo) * u
    }
    fn vec3(&mut self, lo: f32, hi: f32) -> Vector3<f32> {
        Vector3::new(self.next(lo, hi), self.next(lo, hi), self.next(lo, hi))
    }
    fn vec2(&mut self, lo: f32, hi: f32) -> Vector2<f32> {
        Vector2::new(self.next(lo, hi), self.next(lo, hi))
    }
}

/// Relative position and velocity of ball 2 seen from ball 1 at the origin, radii.
struct Pair<V> {
    p: V,
    v: V,
    r1: f32,
    r2: f32,
}

fn pairs3(rng: &mut Lcg) -> Vec<Pair<Vector3<f32>>> {
    (0..BATCH)
        .map(|_| Pair {
            p: rng.vec3(-5.0, 5.0),
            v: rng.vec3(-3.0, 3.0),
            r1: rng.next(0.1, 1.0),
            r2: rng.next(0.1, 1.0),
        })
        .collect()
}

fn pairs2(rng: &mut Lcg) -> Vec<Pair<Vector2<f32>>> {
    (0..BATCH)
        .map(|_| Pair {
            p: rng.vec2(-5.0, 5.0),
            v: rng.vec2(-3.0, 3.0),
            r1: rng.next(0.1, 1.0),
            r2: rng.next(0.1, 1.0),
        })
        .collect()
}

fn ball_ball_linear(c: &mut Criterion) {
    let mut rng = Lcg(1);
    let q3 = pairs3(&mut rng);
    let q2 = pairs2(&mut rng);
    let w32 = Window::forward(10.0_f32).unwrap();
    let w64 = Window::forward(10.0_f64).unwrap();
    let mut g = c.benchmark_group("ball_ball_linear");
    g.throughput(Throughput::Elements(BATCH as u64));
    g.bench_function("carom_3d_f32", |b| {
        b.iter(|| {
            let mut acc = 0.0_f32;
            for q in &q3 {
                let t = ball_ball(
                    &Ball::new_unchecked(Vector3::zeros(), q.r1),
                    &Kinematics::at_rest(),
                    &Ball::new_unchecked(q.p, q.r2),
                    &Kinematics::new_unchecked(q.v, Vector3::zeros()),
                    black_box(&w32),
                );
                acc += t.time.min(1e3);
            }
            black_box(acc)
        });
    });
    g.bench_function("carom_3d_f64", |b| {
        let q64: Vec<_> = q3
            .iter()
            .map(|q| {
                (
                    q.p.cast::<f64>(),
                    q.v.cast::<f64>(),
                    f64::from(q.r1),
                    f64::from(q.r2),
                )
            })
            .collect();
        b.iter(|| {
            let mut acc = 0.0_f64;
            for (p, v, r1, r2) in &q64 {
                let t = ball_ball(
                    &Ball::new_unchecked(Vector3::zeros(), *r1),
                    &Kinematics::at_rest(),
                    &Ball::new_unchecked(*p, *r2),
                    &Kinematics::new_unchecked(*v, Vector3::zeros()),
                    black_box(&w64),
                );
                acc += t.time.min(1e3);
            }
            black_box(acc)
        });
    });
    g.bench_function("parry3d_cast_shapes", |b| {
        let options = parry3d::query::ShapeCastOptions::with_max_time_of_impact(10.0);
        let shapes: Vec<_> = q3
            .iter()
            .map(|q| {
                (
                    parry3d::shape::Ball::new(q.r1),
                    parry3d::shape::Ball::new(q.r2),
                )
            })
            .collect();
        b.iter(|| {
            let mut acc = 0.0_f32;
            for (q, (b1, b2)) in q3.iter().zip(&shapes) {
                let hit = parry3d::query::cast_shapes(
                    &parry3d::math::Pose::IDENTITY,
                    parry3d::math::Vec3::ZERO,
                    b1,
                    &parry3d::math::Pose::from_translation(q.p.into()),
                    q.v.into(),
                    b2,
                    black_box(options),
                )
                .unwrap();
                acc += hit.map_or(1e3, |h| h.time_of_impact);
            }
            black_box(acc)
        });
    });
    g.bench_function("carom_2d_f32", |b| {
        b.iter(|| {
            let mut acc = 0.0_f32;
            for q in &q2 {
                let t = ball_ball(
                    &Ball::new_unchecked(Vector2::zeros(), q.r1),
                    &Kinematics::at_rest(),
                    &Ball::new_unchecked(q.p, q.r2),
                    &Kinematics::new_unchecked(q.v, Vector2::zeros()),
                    black_box(&w32),
                );
                acc += t.time.min(1e3);
            }
            black_box(acc)
        });
    });
    g.bench_function("parry2d_cast_shapes", |b| {
        let options = parry2d::query::ShapeCastOptions::with_max_time_of_impact(10.0);
        let shapes: Vec<_> = q2
            .iter()
            .map(|q| {
                (
                    parry2d::shape::Ball::new(q.r1),
                    parry2d::shape::Ball::new(q.r2),
                )
            })
            .collect();
        b.iter(|| {
            let mut acc = 0.0_f32;
            for (q, (b1, b2)) in q2.iter().zip(&shapes) {
                let hit = parry2d::query::cast_shapes(
                    &parry2d::math::Pose::IDENTITY,
                    parry2d::math::Vec2::ZERO,
                    b1,
                    &parry2d::math::Pose::from_translation(q.p.into()),
                    q.v.into(),
                    b2,
                    black_box(options),
                )
                .unwrap();
                acc += hit.map_or(1e3, |h| h.time_of_impact);
            }
            black_box(acc)
        });
    });
    g.finish();
}

fn ball_cuboid_linear(c: &mut Criterion) {
    let mut rng = Lcg(2);
    let q3: Vec<_> = (0..BATCH)
        .map(|_| {
            (
                rng.vec3(-5.0, 5.0),
                rng.vec3(-3.0, 3.0),
                rng.next(0.1, 1.0),
                rng.vec3(0.1, 1.5),
            )
        })
        .collect();
    let q2: Vec<_> = (0..BATCH)
        .map(|_| {
            (
                rng.vec2(-5.0, 5.0),
                rng.vec2(-3.0, 3.0),
                rng.next(0.1, 1.0),
                rng.vec2(0.1, 1.5),
            )
        })
        .collect();
    let w = Window::forward(10.0_f32).unwrap();
    let mut g = c.benchmark_group("ball_cuboid_linear");
    g.throughput(Throughput::Elements(BATCH as u64));
    g.bench_function("carom_3d_f32", |b| {
        b.iter(|| {
            let mut acc = 0.0_f32;
            for (p, v, r, h) in &q3 {
                let t = ball_aabb(
                    &Ball::new_unchecked(*p, *r),
                    &Kinematics::new_unchecked(*v, Vector3::zeros()),
                    &Aabb::new_unchecked(-h, *h),
                    &Kinematics::at_rest(),
                    black_box(&w),
                );
                acc += t.time.min(1e3);
            }
            black_box(acc)
        });
    });
    g.bench_function("parry3d_cast_shapes", |b| {
        let options = parry3d::query::ShapeCastOptions::with_max_time_of_impact(10.0);
        let shapes: Vec<_> = q3
            .iter()
            .map(|(_, _, r, h)| {
                (
                    parry3d::shape::Ball::new(*r),
                    parry3d::shape::Cuboid::new((*h).into()),
                )
            })
            .collect();
        b.iter(|| {
            let mut acc = 0.0_f32;
            for ((p, v, _, _), (ball, cuboid)) in q3.iter().zip(&shapes) {
                let hit = parry3d::query::cast_shapes(
                    &parry3d::math::Pose::from_translation((*p).into()),
                    (*v).into(),
                    ball,
                    &parry3d::math::Pose::IDENTITY,
                    parry3d::math::Vec3::ZERO,
                    cuboid,
                    black_box(options),
                )
                .unwrap();
                acc += hit.map_or(1e3, |h| h.time_of_impact);
            }
            black_box(acc)
        });
    });
    g.bench_function("carom_2d_f32", |b| {
        b.iter(|| {
            let mut acc = 0.0_f32;
            for (p, v, r, h) in &q2 {
                let t = ball_aabb(
                    &Ball::new_unchecked(*p, *r),
                    &Kinematics::new_unchecked(*v, Vector2::zeros()),
                    &Aabb::new_unchecked(-h, *h),
                    &Kinematics::at_rest(),
                    black_box(&w),
                );
                acc += t.time.min(1e3);
            }
            black_box(acc)
        });
    });
    g.bench_function("parry2d_cast_shapes", |b| {
        let options = parry2d::query::ShapeCastOptions::with_max_time_of_impact(10.0);
        let shapes: Vec<_> = q2
            .iter()
            .map(|(_, _, r, h)| {
                (
                    parry2d::shape::Ball::new(*r),
                    parry2d::shape::Cuboid::new((*h).into()),
                )
            })
            .collect();
        b.iter(|| {
            let mut acc = 0.0_f32;
            for ((p, v, _, _), (ball, cuboid)) in q2.iter().zip(&shapes) {
                let hit = parry2d::query::cast_shapes(
                    &parry2d::math::Pose::from_translation((*p).into()),
                    (*v).into(),
                    ball,
                    &parry2d::math::Pose::IDENTITY,
                    parry2d::math::Vec2::ZERO,
                    cuboid,
                    black_box(options),
                )
                .unwrap();
                acc += hit.map_or(1e3, |h| h.time_of_impact);
            }
            black_box(acc)
        });
    });
    g.finish();
}

/// The queries without a parry peer: ballistic ball–ball (quartic), ballistic ball–box,
/// and a spinning cluster against a wall (conservative advancement), all f64.
fn reference(c: &mut Criterion) {
    let mut rng = Lcg(3);
    let gravity = Vector3::new(0.0, -9.81, 0.0);
    let q: Vec<_> = (0..BATCH)
        .map(|_| {
            (
                rng.vec3(-5.0, 5.0).cast::<f64>(),
                rng.vec3(-3.0, 3.0).cast::<f64>(),
                rng.vec3(0.1, 1.5).cast::<f64>(),
            )
        })
        .collect();
    let w = Window::forward(10.0_f64).unwrap();
    let mut g = c.benchmark_group("reference_f64");
    g.throughput(Throughput::Elements(BATCH as u64));
    g.bench_function("ball_ball_3d_differing_gravity", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (p, v, _) in &q {
                let t = ball_ball(
                    &Ball::new_unchecked(Vector3::zeros(), 0.5),
                    &Kinematics::at_rest(),
                    &Ball::new_unchecked(*p, 0.5),
                    &Kinematics::new_unchecked(*v, gravity),
                    black_box(&w),
                );
                acc += t.time.min(1e3);
            }
            black_box(acc)
        });
    });
    g.bench_function("ball_box_3d_gravity", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (p, v, h) in &q {
                let t = ball_aabb(
                    &Ball::new_unchecked(*p, 0.3),
                    &Kinematics::new_unchecked(*v, gravity),
                    &Aabb::new_unchecked(-h, *h),
                    &Kinematics::at_rest(),
                    black_box(&w),
                );
                acc += t.time.min(1e3);
            }
            black_box(acc)
        });
    });
    let cluster = Cluster::new(&[
        (Vector2::new(1.0, 0.0), 0.2),
        (Vector2::new(-1.0, 0.0), 0.2),
        (Vector2::new(0.0, 0.6), 0.3),
    ])
    .unwrap();
    let options = AdvanceOptions::relative_to(cluster.bounding_radius()).unwrap();
    let wall = HalfSpace::new(Vector2::new(-1.0, 0.0), Vector2::new(2.0, 0.0)).unwrap();
    let motions: Vec<_> = (0..64)
        .map(|_| {
            ConstantSpin::new(
                Vector2::zeros(),
                Rotation2::new(f64::from(rng.next(0.0, 6.3))),
                Kinematics::linear(rng.vec2(-1.0, 1.0).cast::<f64>()).unwrap(),
                Vector1::new(f64::from(rng.next(-8.0, 8.0))),
            )
            .unwrap()
        })
        .collect();
    g.throughput(Throughput::Elements(motions.len() as u64));
    g.bench_function("cluster_wall_2d_spinning", |b| {
        let window = Window::forward(10.0).unwrap();
        b.iter(|| {
            let mut acc = 0.0;
            for m in &motions {
                acc += cluster_plane(&cluster, m, &wall, black_box(&window), &options)
                    .time
                    .min(1e3);
            }
            black_box(acc)
        });
    });
    g.finish();
}

criterion_group!(benches, ball_ball_linear, ball_cuboid_linear, reference);
criterion_main!(benches);
