//! Integrator throughput in balls per second (criterion reports it as elements/s).
//!
//! One iteration is one step of `N` balls (N = 1e3, 1e4, 1e5) through
//! `carom_integrate::Stepper::step`:
//!
//! * `integrate/2d`: gravity + linear drag, every integrator (this field has a closed
//!   form, so `exact` runs too);
//! * `integrate/3d`: gravity + quadratic drag + Magnus + spin damping on spinning balls
//!   (a table-tennis ball in air), every integrator but `exact`;
//! * `integrate/3d-closed-form`: gravity + linear drag + spin damping in 3D, `exact`
//!   against `semi-implicit-euler` side by side;
//! * `integrate/dispatch`: the 3D air field as a static tuple against a run-time
//!   `Vec<Field>`, N = 1e4.
//!
//! The state evolves in place from iteration to iteration and is copied back to its
//! start every 4096 steps (17 simulated seconds; the copy costs under 0.1% of the
//! steps it serves). Without the reset, drag decays the horizontal velocities towards
//! zero for ever and after about `700/k` simulated seconds (a few hundred thousand
//! iterations) they become subnormal, which slows every scheme some fifty-fold and
//! measures the floating-point unit instead of the integrator.

use std::hint::black_box;
use std::time::Duration;

use carom::integrate::{
    Bodies, Field, ForceField, Gravity, Integrator, LinearDrag, Magnus, QuadraticDrag, SpinDamping,
    Stepper, TimeStep,
};
use carom::math::nalgebra::{SVector, Vector1, Vector2, Vector3};
use carom::math::{Real, Space};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

const COUNTS: [usize; 3] = [1_000, 10_000, 100_000];
const MASS: f64 = 0.0027;
const DT: f64 = 1.0 / 240.0;

/// How many steps a world takes before it is reset to its start.
const RESET_EVERY: usize = 4096;

/// `n` balls with varied positions, velocities and spins (deterministic), and the copy
/// they are reset to.
struct World<const D: usize>
where
    carom::math::Dim<D>: Space<f64, D>,
{
    x: Vec<SVector<f64, D>>,
    v: Vec<SVector<f64, D>>,
    w: Vec<Angular<D>>,
    inverse_masses: Vec<f64>,
    start: (Vec<SVector<f64, D>>, Vec<SVector<f64, D>>, Vec<Angular<D>>),
    steps: usize,
}

type Angular<const D: usize> = <carom::math::Dim<D> as Space<f64, D>>::Angular;

impl<const D: usize> World<D>
where
    carom::math::Dim<D>: Space<f64, D>,
{
    fn new(n: usize, spin: impl Fn(usize) -> Angular<D>) -> Self {
        let wave = |i: usize, j: usize, a: f64| ((i * 7 + j * 3) as f64 * a).sin();
        let x: Vec<_> = (0..n)
            .map(|i| SVector::from_fn(|j, _| wave(i, j, 0.37)))
            .collect();
        let v: Vec<_> = (0..n)
            .map(|i| SVector::from_fn(|j, _| 10.0 * wave(i, j, 0.91)))
            .collect();
        let w: Vec<_> = (0..n).map(spin).collect();
        Self {
            start: (x.clone(), v.clone(), w.clone()),
            x,
            v,
            w,
            inverse_masses: vec![1.0 / MASS; n],
            steps: 0,
        }
    }

    fn step<F: ForceField<f64, D>>(&mut self, stepper: &Stepper<f64, D, F>, spins: bool) {
        if self.steps == RESET_EVERY {
            self.x.copy_from_slice(&self.start.0);
            self.v.copy_from_slice(&self.start.1);
            self.w.copy_from_slice(&self.start.2);
            self.steps = 0;
        }
        let t = self.steps as f64 * DT;
        self.steps += 1;
        let bodies = Bodies::new(&mut self.x, &mut self.v, &self.inverse_masses).unwrap();
        let mut bodies = if spins {
            bodies.with_spins(&mut self.w).unwrap()
        } else {
            bodies
        };
        stepper.step(&mut bodies, t, TimeStep::new(DT).unwrap());
    }
}

fn spin_2d(i: usize) -> Vector1<f64> {
    Vector1::new(50.0 * (i as f64 * 0.13).sin())
}

fn spin_3d(i: usize) -> Vector3<f64> {
    let s = |a: f64| 100.0 * (i as f64 * a).sin();
    Vector3::new(s(0.13), s(0.29), s(0.41))
}

fn air_3d() -> (
    Gravity<f64, 3>,
    QuadraticDrag<f64>,
    Magnus<f64>,
    SpinDamping<f64>,
) {
    (
        Gravity::new(Vector3::new(0.0, 0.0, -9.81)).unwrap(),
        QuadraticDrag::new(3.8e-4).unwrap(),
        Magnus::new(4e-6).unwrap(),
        SpinDamping::new(0.01).unwrap(),
    )
}

fn bench_field<const D: usize, F: ForceField<f64, D> + Copy>(
    c: &mut Criterion,
    group_name: &str,
    integrators: &[Integrator],
    field: F,
    spin: fn(usize) -> Angular<D>,
    spins: bool,
) where
    carom::math::Dim<D>: Space<f64, D>,
{
    let mut group = c.benchmark_group(group_name);
    for &n in &COUNTS {
        group.throughput(Throughput::Elements(n as u64));
        for &integrator in integrators {
            let stepper = Stepper::new(integrator, field).unwrap();
            let mut world = World::<D>::new(n, spin);
            group.bench_function(BenchmarkId::new(integrator.name(), n), |b| {
                b.iter(|| world.step(black_box(&stepper), spins));
            });
            black_box(world.x[n / 2].norm().to_f64());
        }
    }
    group.finish();
}

fn integrators(c: &mut Criterion) {
    let g2 = Gravity::new(Vector2::new(0.0, -9.81)).unwrap();
    let drag = LinearDrag::new(1e-3).unwrap();
    bench_field::<2, _>(
        c,
        "integrate/2d",
        &Integrator::ALL,
        (g2, drag),
        spin_2d,
        false,
    );

    let staged = [
        Integrator::ExplicitEuler,
        Integrator::SemiImplicitEuler,
        Integrator::VelocityVerlet,
        Integrator::Rk4,
    ];
    bench_field::<3, _>(c, "integrate/3d", &staged, air_3d(), spin_3d, true);

    let g3 = Gravity::new(Vector3::new(0.0, 0.0, -9.81)).unwrap();
    let closed = (g3, drag, SpinDamping::new(0.01).unwrap());
    bench_field::<3, _>(
        c,
        "integrate/3d-closed-form",
        &[Integrator::SemiImplicitEuler, Integrator::Exact],
        closed,
        spin_3d,
        true,
    );
}

fn dispatch(c: &mut Criterion) {
    let n = 10_000;
    let mut group = c.benchmark_group("integrate/dispatch");
    group.throughput(Throughput::Elements(n as u64));
    let (g, q, m, s) = air_3d();
    let dynamic: Vec<Field<f64, 3>> = vec![g.into(), q.into(), m.into(), s.into()];
    for integrator in [Integrator::SemiImplicitEuler, Integrator::Rk4] {
        let tuple = Stepper::new(integrator, air_3d()).unwrap();
        let mut world = World::<3>::new(n, spin_3d);
        group.bench_function(BenchmarkId::new(format!("{integrator}/tuple"), n), |b| {
            b.iter(|| world.step(black_box(&tuple), true));
        });
        let vec = Stepper::new(integrator, dynamic.clone()).unwrap();
        let mut world = World::<3>::new(n, spin_3d);
        group.bench_function(
            BenchmarkId::new(format!("{integrator}/vec-field"), n),
            |b| {
                b.iter(|| world.step(black_box(&vec), true));
            },
        );
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(20);
    targets = integrators, dispatch
}
criterion_main!(benches);
