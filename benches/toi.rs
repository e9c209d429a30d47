//! Time of impact per query: carom's closed forms against parry 0.31's `cast_shapes`
//! (f32, the same random queries for both), plus the ballistic and cluster queries for
//! reference. Each benchmark runs a batch of 1024 varied queries (hits and misses) so
//! branch prediction sees a realistic mix; criterion reports time per query
//! (`Throughput::Elements`).
//!
//! `ball_ball_gas` is the event-driven engine's inner loop: a 3D hard-sphere gas, each
//! query a ball and one of its neighbour-list partners (centre distance between `R` and
//! `1.5 R`, Maxwellian relative velocity), so about half recede and many of the rest
//! miss.
//!
//! Instruction counts. With `TOI_COUNT=<group>/<name>` (and optionally `TOI_REPS`, default
//! 100) the binary skips criterion and runs that one query batch `TOI_REPS` times in the
//! function `counted`, for `valgrind --tool=callgrind --toggle-collect='*counted*'`:
//! instructions per query are the collected total over `TOI_REPS × 1024` (see
//! docs/toi.md). Instruction counts do not depend on the machine's load.

use std::hint::black_box;

use carom::geometry::{Aabb, Ball, HalfSpace};
use carom::toi::{
    AdvanceOptions, Cluster, ConstantSpin, Kinematics, Window, ball_aabb, ball_ball, cluster_plane,
};
use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion, Throughput, criterion_group};
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

/// One batch of queries: the sum of the (capped) times keeps the work observable.
fn batch_sum<Q>(batch: &[Q], query: &impl Fn(&Q) -> f64) -> f64 {
    let mut acc = 0.0;
    for q in batch {
        acc += query(black_box(q)).min(1e3);
    }
    acc
}

/// The instruction-counting mode: the case named by `TOI_COUNT` and the repetitions.
fn count_mode() -> Option<(String, usize)> {
    let case = std::env::var("TOI_COUNT").ok()?;
    let reps = std::env::var("TOI_REPS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(100);
    Some((case, reps))
}

/// The batch repeated `reps` times, out of line so callgrind can collect just this.
#[inline(never)]
fn counted<Q>(batch: &[Q], query: &impl Fn(&Q) -> f64, reps: usize) -> f64 {
    (0..reps).map(|_| batch_sum(batch, query)).sum()
}

/// A criterion group, or in counting mode the group's name only.
struct Group<'c> {
    name: &'static str,
    timed: BenchmarkGroup<'c, WallTime>,
}

impl<'c> Group<'c> {
    fn new(c: &'c mut Criterion, name: &'static str, elements: usize) -> Self {
        let mut timed = c.benchmark_group(name);
        timed.throughput(Throughput::Elements(elements as u64));
        Self { name, timed }
    }

    /// Times `query` over the whole batch (or counts it, see the module docs).
    fn run<Q>(&mut self, name: &str, batch: &[Q], query: impl Fn(&Q) -> f64) {
        if let Some((case, reps)) = count_mode() {
            if case == format!("{}/{name}", self.name) {
                black_box(counted(batch, &query, reps));
            }
            return;
        }
        self.timed
            .bench_function(name, |b| b.iter(|| black_box(batch_sum(batch, &query))));
    }

    fn throughput(&mut self, elements: usize) {
        self.timed.throughput(Throughput::Elements(elements as u64));
    }

    fn finish(self) {
        self.timed.finish();
    }
}

fn ball_ball_linear(c: &mut Criterion) {
    let mut rng = Lcg(1);
    let q3 = pairs3(&mut rng);
    let q2 = pairs2(&mut rng);
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
    let (w32, w64) = (
        Window::forward(10.0_f32).unwrap(),
        Window::forward(10.0_f64).unwrap(),
    );
    let o3 = parry3d::query::ShapeCastOptions::with_max_time_of_impact(10.0);
    let o2 = parry2d::query::ShapeCastOptions::with_max_time_of_impact(10.0);
    let mut g = Group::new(c, "ball_ball_linear", BATCH);
    g.run("carom_3d_f32", &q3, |q| {
        let (b1, b2) = (
            Ball::new_unchecked(Vector3::zeros(), q.r1),
            Ball::new_unchecked(q.p, q.r2),
        );
        let k2 = Kinematics::new_unchecked(q.v, Vector3::zeros());
        f64::from(ball_ball(&b1, &Kinematics::at_rest(), &b2, &k2, &w32).time)
    });
    g.run("carom_3d_f64", &q64, |(p, v, r1, r2)| {
        let (b1, b2) = (
            Ball::new_unchecked(Vector3::zeros(), *r1),
            Ball::new_unchecked(*p, *r2),
        );
        let k2 = Kinematics::new_unchecked(*v, Vector3::zeros());
        ball_ball(&b1, &Kinematics::at_rest(), &b2, &k2, &w64).time
    });
    g.run("parry3d_cast_shapes", &q3, |q| {
        let (b1, b2) = (
            parry3d::shape::Ball::new(q.r1),
            parry3d::shape::Ball::new(q.r2),
        );
        let pose = parry3d::math::Pose::from_translation(q.p.into());
        let hit = parry3d::query::cast_shapes(
            &parry3d::math::Pose::IDENTITY,
            parry3d::math::Vec3::ZERO,
            &b1,
            &pose,
            q.v.into(),
            &b2,
            o3,
        );
        f64::from(hit.unwrap().map_or(1e3, |h| h.time_of_impact))
    });
    g.run("carom_2d_f32", &q2, |q| {
        let (b1, b2) = (
            Ball::new_unchecked(Vector2::zeros(), q.r1),
            Ball::new_unchecked(q.p, q.r2),
        );
        let k2 = Kinematics::new_unchecked(q.v, Vector2::zeros());
        f64::from(ball_ball(&b1, &Kinematics::at_rest(), &b2, &k2, &w32).time)
    });
    g.run("parry2d_cast_shapes", &q2, |q| {
        let (b1, b2) = (
            parry2d::shape::Ball::new(q.r1),
            parry2d::shape::Ball::new(q.r2),
        );
        let pose = parry2d::math::Pose::from_translation(q.p.into());
        let hit = parry2d::query::cast_shapes(
            &parry2d::math::Pose::IDENTITY,
            parry2d::math::Vec2::ZERO,
            &b1,
            &pose,
            q.v.into(),
            &b2,
            o2,
        );
        f64::from(hit.unwrap().map_or(1e3, |h| h.time_of_impact))
    });
    g.finish();
}

/// A 3D hard-sphere gas seen by the event-driven engine: each query is a ball and a
/// neighbour-list partner (shell `1.5 R`), relative velocities the difference of two
/// Maxwellian velocities (sums of uniforms), f64, no horizon.
fn ball_ball_gas(c: &mut Criterion) {
    let mut rng = Lcg(4);
    let (r, shell) = (0.5_f64, 1.5_f64);
    let gaussian = |rng: &mut Lcg| {
        let s: f32 = (0..4).map(|_| rng.next(-1.0, 1.0)).sum();
        f64::from(s)
    };
    let q: Vec<_> = (0..BATCH)
        .map(|_| {
            let dir = loop {
                let d = rng.vec3(-1.0, 1.0).cast::<f64>();
                let n = d.norm();
                if n > 0.1 && n <= 1.0 {
                    break d / n;
                }
            };
            let dist = 2.0 * r * (1.0 + (shell - 1.0) * f64::from(rng.next(0.0, 1.0)));
            let v = Vector3::from_fn(|_, _| gaussian(&mut rng));
            (dir * dist, v)
        })
        .collect();
    let w = Window::unbounded(carom::toi::Direction::Forward);
    let mut g = Group::new(c, "ball_ball_gas", BATCH);
    g.run("carom_3d_f64", &q, |(p, v)| {
        let (b1, b2) = (
            Ball::new_unchecked(Vector3::zeros(), r),
            Ball::new_unchecked(*p, r),
        );
        let k2 = Kinematics::new_unchecked(*v, Vector3::zeros());
        ball_ball(&b1, &Kinematics::at_rest(), &b2, &k2, &w).time
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
    let o3 = parry3d::query::ShapeCastOptions::with_max_time_of_impact(10.0);
    let o2 = parry2d::query::ShapeCastOptions::with_max_time_of_impact(10.0);
    let mut g = Group::new(c, "ball_cuboid_linear", BATCH);
    g.run("carom_3d_f32", &q3, |(p, v, r, h)| {
        let k = Kinematics::new_unchecked(*v, Vector3::zeros());
        let toi = ball_aabb(
            &Ball::new_unchecked(*p, *r),
            &k,
            &Aabb::new_unchecked(-h, *h),
            &Kinematics::at_rest(),
            &w,
        );
        f64::from(toi.time)
    });
    g.run("parry3d_cast_shapes", &q3, |(p, v, r, h)| {
        let (ball, cuboid) = (
            parry3d::shape::Ball::new(*r),
            parry3d::shape::Cuboid::new((*h).into()),
        );
        let pose = parry3d::math::Pose::from_translation((*p).into());
        let hit = parry3d::query::cast_shapes(
            &pose,
            (*v).into(),
            &ball,
            &parry3d::math::Pose::IDENTITY,
            parry3d::math::Vec3::ZERO,
            &cuboid,
            o3,
        );
        f64::from(hit.unwrap().map_or(1e3, |h| h.time_of_impact))
    });
    g.run("carom_2d_f32", &q2, |(p, v, r, h)| {
        let k = Kinematics::new_unchecked(*v, Vector2::zeros());
        let toi = ball_aabb(
            &Ball::new_unchecked(*p, *r),
            &k,
            &Aabb::new_unchecked(-h, *h),
            &Kinematics::at_rest(),
            &w,
        );
        f64::from(toi.time)
    });
    g.run("parry2d_cast_shapes", &q2, |(p, v, r, h)| {
        let (ball, cuboid) = (
            parry2d::shape::Ball::new(*r),
            parry2d::shape::Cuboid::new((*h).into()),
        );
        let pose = parry2d::math::Pose::from_translation((*p).into());
        let hit = parry2d::query::cast_shapes(
            &pose,
            (*v).into(),
            &ball,
            &parry2d::math::Pose::IDENTITY,
            parry2d::math::Vec2::ZERO,
            &cuboid,
            o2,
        );
        f64::from(hit.unwrap().map_or(1e3, |h| h.time_of_impact))
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
    let mut g = Group::new(c, "reference_f64", BATCH);
    g.run("ball_ball_3d_differing_gravity", &q, |(p, v, _)| {
        let k = Kinematics::new_unchecked(*v, gravity);
        let (b1, b2) = (
            Ball::new_unchecked(Vector3::zeros(), 0.5),
            Ball::new_unchecked(*p, 0.5),
        );
        ball_ball(&b1, &Kinematics::at_rest(), &b2, &k, &w).time
    });
    g.run("ball_box_3d_gravity", &q, |(p, v, h)| {
        let k = Kinematics::new_unchecked(*v, gravity);
        ball_aabb(
            &Ball::new_unchecked(*p, 0.3),
            &k,
            &Aabb::new_unchecked(-h, *h),
            &Kinematics::at_rest(),
            &w,
        )
        .time
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
            let k = Kinematics::linear(rng.vec2(-1.0, 1.0).cast::<f64>()).unwrap();
            let spin = Vector1::new(f64::from(rng.next(-8.0, 8.0)));
            ConstantSpin::new(
                Vector2::zeros(),
                Rotation2::new(f64::from(rng.next(0.0, 6.3))),
                k,
                spin,
            )
            .unwrap()
        })
        .collect();
    g.throughput(motions.len());
    g.run("cluster_wall_2d_spinning", &motions, |m| {
        cluster_plane(&cluster, m, &wall, &w, &options).time
    });
    g.finish();
}

criterion_group!(
    benches,
    ball_ball_linear,
    ball_ball_gas,
    ball_cuboid_linear,
    reference
);

fn main() {
    benches();
    if count_mode().is_none() {
        Criterion::default().configure_from_args().final_summary();
    }
}
