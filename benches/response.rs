//! Collision response costs: one ball–ball impulse (frictionless and with Coulomb
//! friction, 2D and 3D, f64 and f32) and one stick fusion of two clusters.
//!
//! Each iteration resolves a batch of 1024 precomputed random pairs (approaching, so
//! every call computes an impulse), so the per-element time is the cost of one call.
//! Run: `cargo bench --bench response`.

use std::hint::black_box;

use carom::math::nalgebra::{Const, SVector};
use carom::math::{Real, Space};
use carom::response::{Angular, Body, Coefficients, Contact, RigidCluster, resolve};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

const BATCH: usize = 1024;

/// A small deterministic generator (the bench needs varied inputs, not a crate).
struct Lcg(u64);

impl Lcg {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }

    fn vector<T: Real, const D: usize>(&mut self, r: f64) -> SVector<T, D> {
        SVector::from_fn(|_, _| T::lit(self.uniform(-r, r)))
    }

    fn angular<T: Real, const D: usize>(&mut self, r: f64) -> Angular<T, D>
    where
        Const<D>: Space<T, D>,
    {
        let mut w = <Const<D> as Space<T, D>>::angular_zero();
        // Any angular vector is a sum of crosses; two random crosses cover every axis.
        for _ in 0..2 {
            let (a, b) = (self.vector::<T, D>(1.0), self.vector::<T, D>(r));
            w += <Const<D> as Space<T, D>>::cross(&a, &b);
        }
        w
    }
}

type Pair<T, const D: usize> = (Body<T, D>, Body<T, D>, Contact<T, D>);

/// `BATCH` approaching ball pairs with random masses, radii, velocities and spins.
fn ball_pairs<T: Real, const D: usize>() -> Vec<Pair<T, D>>
where
    Const<D>: Space<T, D>,
{
    let mut rng = Lcg(7);
    let mut pairs = Vec::with_capacity(BATCH);
    while pairs.len() < BATCH {
        let (ra, rb) = (
            T::lit(rng.uniform(0.01, 1.0)),
            T::lit(rng.uniform(0.01, 1.0)),
        );
        let a = Body::ball(
            T::lit(rng.uniform(0.1, 10.0)),
            ra,
            rng.vector(5.0),
            rng.angular(5.0),
        )
        .unwrap();
        let b = Body::ball(
            T::lit(rng.uniform(0.1, 10.0)),
            rb,
            rng.vector(5.0),
            rng.angular(5.0),
        )
        .unwrap();
        let Ok(contact) = Contact::between_balls(&SVector::zeros(), ra, &rng.vector(1.0), rb)
        else {
            continue;
        };
        if carom::response::normal_velocity(&a, &b, &contact) < T::zero() {
            pairs.push((a, b, contact));
        }
    }
    pairs
}

fn bench_impulses<T: Real, const D: usize>(c: &mut Criterion, name: &str)
where
    Const<D>: Space<T, D>,
{
    let pairs = ball_pairs::<T, D>();
    let mut group = c.benchmark_group(format!("response/ball_ball_{name}"));
    group.throughput(Throughput::Elements(BATCH as u64));
    for (label, coefficients) in [
        (
            "frictionless",
            Coefficients::frictionless(T::lit(0.9)).unwrap(),
        ),
        (
            "friction",
            Coefficients::new(T::lit(0.9), T::lit(0.3)).unwrap(),
        ),
    ] {
        group.bench_function(label, |bencher| {
            bencher.iter(|| {
                let mut sum = T::zero();
                for (a, b, contact) in black_box(&pairs) {
                    sum += resolve(a, b, contact, &coefficients).normal_impulse;
                }
                sum
            });
        });
    }
    group.finish();
}

fn bench_fusion<const D: usize>(c: &mut Criterion, name: &str)
where
    Const<D>: Space<f64, D>,
{
    let mut rng = Lcg(11);
    let clusters: Vec<RigidCluster<f64, D>> = (0..=BATCH)
        .map(|_| {
            RigidCluster::ball(
                rng.uniform(0.1, 10.0),
                rng.uniform(0.01, 1.0),
                rng.vector(10.0),
                rng.vector(5.0),
                rng.angular(5.0),
            )
            .unwrap()
        })
        .collect();
    let mut group = c.benchmark_group(format!("response/fusion_{name}"));
    group.throughput(Throughput::Elements(BATCH as u64));
    group.bench_function("two_balls", |bencher| {
        bencher.iter(|| {
            let mut lost = 0.0;
            for pair in black_box(&clusters).windows(2) {
                lost += pair[0].fuse(&pair[1]).unwrap().kinetic_energy_change;
            }
            lost
        });
    });
    group.finish();
}

fn response(c: &mut Criterion) {
    bench_impulses::<f64, 2>(c, "2d_f64");
    bench_impulses::<f64, 3>(c, "3d_f64");
    bench_impulses::<f32, 3>(c, "3d_f32");
    bench_fusion::<2>(c, "2d_f64");
    bench_fusion::<3>(c, "3d_f64");
}

criterion_group!(benches, response);
criterion_main!(benches);
