//! Stacks of balls and stuck clusters under gravity (`inelastic = "stick"`): balls resting
//! on clusters, clusters resting on balls, a cluster tipped by the ball it carries.
//!
//! **Building the scenes.** A pair of balls fuses when its restitution, the smaller of the
//! two, is 0. So every cluster here is held together by *glue* balls of restitution 0
//! (which would fuse with anything they touch) joined to *load-bearing* members of
//! restitution 0.5, and every other ball touches load-bearing members only: it rests,
//! bounces and slides on the cluster without sticking. A cluster is fused at `t = 0` by
//! giving each glued pair equal and opposite momenta along its line of centres: the fused
//! body then has zero momentum and zero angular momentum, whatever the order of the
//! fusions. It is fused 1 mm above its resting place and lands there within the first step
//! (a fusion on the floor would mix with the floor's own contacts of that instant).
//!
//! **Independent references.** The resting places are the geometric stacking heights:
//! a ball of radius `r` in the hollow between two balls of radius `r` whose centres are
//! `2d` apart sits `√(4r² − d²)` above them. On a frictionless floor far from the walls
//! nothing but the floor acts horizontally, so the horizontal momentum stays what it was
//! (zero): the floor supplies vertical impulses only, and once everything rests it
//! supplies exactly the weight, `M g t`, so the momentum stays zero. Energy never grows.
//! Which way a cluster tips follows from statics, how fast it starts to from the
//! closed-form contact dynamics of the first instant. Positions are checked to 1e-9 m:
//! 600 steps of corrections leave ~1e-13 m (measured), while a ball sinking for a single
//! step at the engine's resting floor (the slowest approach it acts on, 1e-6 g h) moves
//! 2.7e-9 m. No two bodies overlap by more than that much, which is what the engine may
//! leave by design (measured: 5.8e-10 m after a bounce into a hollow, then constant).
//!
//! **Unstable equilibria are avoided.** A ball balanced on top of a single ball (or a bar
//! across two balls) is unstable: rounding grows at `√(g/(r₁ + r₂))`, ~7/s here, and
//! the ball falls off within seconds, as it should. The stacks below rest in hollows,
//! except a column standing exactly on one vertical line, where no horizontal component
//! ever arises.

use crate::common;

use carom_geometry::Border;
use carom_integrate::Integrator;
use carom_math::{Space, Vector};
use carom_sim::scene::{BallSpec, BorderSpec, Inelastic, Scene, World};
use carom_sim::{Collision, Simulation, observe};
use common::{Recorder, assert_stays_put, spanning_the_origin, states, stepped};
use nalgebra::Const;

const G: f64 = 9.81;
/// The radius of the load-bearing balls.
const R: f64 = 0.1;
/// The radius of the glue balls under a hollow.
const GLUE: f64 = 0.05;
/// The step of the long holds.
const DT: f64 = 1.0 / 60.0;
/// How long a stack must stay put.
const HOLD: f64 = 10.0;
/// How high a cluster is fused above its resting place.
const LIFT: f64 = 1e-3;
/// Positions (m) and speeds (m/s) at rest: see the module documentation.
const AT_REST: f64 = 1e-9;
/// The overlap allowed between two bodies (m): what the engine may leave by design, a
/// step at its resting floor (approaches slower than 1e-6 g h are no events: see the
/// narrow phase), 1e-6 g h² = 2.7e-9 m.
const OVERLAP: f64 = 1e-6 * G * DT * DT;

const INTEGRATORS: [Integrator; 4] = [
    Integrator::SemiImplicitEuler,
    Integrator::Exact,
    Integrator::VelocityVerlet,
    Integrator::Rk4,
];

fn at<const D: usize>(c: &[f64]) -> Vector<f64, D> {
    Vector::<f64, D>::from_fn(|k, _| c.get(k).copied().unwrap_or(0.0))
}

/// Gravity along `−y`, a floor at `y = 0` of restitution `floor`, walls at `±half`
/// (`x`, and `z` in 3D), frictionless, `inelastic = "stick"`.
fn world<const D: usize>(floor: f64, half: f64) -> World<f64, D> {
    let mut lo = Vector::<f64, D>::from_element(-half);
    let mut hi = Vector::<f64, D>::from_element(half);
    lo[1] = 0.0;
    hi[1] = 10.0;
    World {
        gravity: at(&[0.0, -G]),
        restitution: 0.5,
        inelastic: Inelastic::Stick,
        friction: 0.0,
        border: Some(BorderSpec {
            border: Border::new(lo, hi).unwrap(),
            restitution: floor,
            periodic: false,
        }),
        ..World::default()
    }
}

fn ball<const D: usize>(pos: &[f64], radius: f64, mass: f64, e: f64) -> BallSpec<f64, D> {
    let mut b = BallSpec::new(at(pos), Vector::zeros(), radius, mass);
    b.restitution = Some(e);
    b
}

/// Gives each glued pair `(a, b)` momenta `±p` along its line of centres: they fuse at
/// `t = 0` into a body with zero momentum and zero angular momentum.
fn glue<const D: usize>(balls: &mut [BallSpec<f64, D>], pairs: &[(usize, usize)], p: f64) {
    for &(a, b) in pairs {
        let d = (balls[b].pos - balls[a].pos).normalize();
        balls[a].vel += d * (p / balls[a].mass);
        balls[b].vel -= d * (p / balls[b].mass);
    }
}

/// A scene of `balls` lifted by `lift` and the positions they rest at (the unlifted ones).
fn lifted<const D: usize>(
    world: World<f64, D>,
    mut balls: Vec<BallSpec<f64, D>>,
    lift: f64,
) -> (Scene<f64, D>, Vec<Vector<f64, D>>) {
    let rest = balls.iter().map(|b| b.pos).collect();
    for b in &mut balls {
        b.pos[1] += lift;
    }
    let scene = Scene {
        world,
        balls,
        ..Scene::default()
    };
    (scene, rest)
}

/// The horizontal distance from the glue ball of radius `GLUE` on the floor to each of
/// the load-bearing balls it holds (radius `R`, on the floor, touching it):
/// `d² + (R − GLUE)² = (R + GLUE)²`.
fn spread() -> f64 {
    2.0 * (R * GLUE).sqrt()
}

/// How high a ball of radius `R` sits above two balls of radius `R` whose centres are
/// `2d` apart: `√((2R)² − d²)`.
fn above(d: f64) -> f64 {
    (4.0 * R * R - d * d).sqrt()
}

/// 2D: load-bearing balls 0 and 2 on the floor glued by ball 1 (restitution 0, radius
/// `GLUE`) between and below them, and ball 3 (restitution 1) in the hollow between 0 and
/// 2, `drop` above it; the floor's restitution is `floor`. Ball 3 never reaches the glue:
/// its lowest point, `√(4R² − d²) = 0.141` m up, is above the glue's top, `2 GLUE = 0.1`
/// m.
fn hollow_2d(floor: f64, drop: f64) -> (Scene<f64, 2>, Vec<Vector<f64, 2>>) {
    let d = spread();
    let mut balls = vec![
        ball(&[-d, R], R, 1.0, 0.5),
        ball(&[0.0, GLUE], GLUE, 0.25, 0.0),
        ball(&[d, R], R, 1.0, 0.5),
        ball(&[0.0, R + above(d)], R, 1.0, 1.0),
    ];
    glue(&mut balls, &[(0, 1), (2, 1)], 0.01);
    let (mut s, rest) = lifted::<2>(world(floor, 2.0), balls, LIFT);
    s.balls[3].pos.y += drop;
    (s, rest)
}

/// 3D: three load-bearing balls on the floor at 120° around a glue ball, and a ball in the
/// hollow the three make.
fn hollow_3d() -> (Scene<f64, 3>, Vec<Vector<f64, 3>>) {
    let d = spread();
    let mut balls = vec![ball(&[0.0, GLUE, 0.0], GLUE, 0.25, 0.0)];
    for k in 0..3 {
        let a = f64::from(k) * 2.0 * std::f64::consts::PI / 3.0;
        balls.push(ball(&[d * a.cos(), R, d * a.sin()], R, 1.0, 0.5));
    }
    balls.push(ball(&[0.0, R + above(d), 0.0], R, 1.0, 1.0));
    glue(&mut balls, &[(1, 0), (2, 0), (3, 0)], 0.01);
    lifted(world(0.5, 2.0), balls, LIFT)
}

/// What [`settle`] saw.
#[derive(Debug, Default)]
struct Settling {
    /// The most two bodies overlapped, or a ball the floor (m).
    overlap: f64,
    /// Where and when: `(i, j, t)`, `j == i` for the floor.
    worst: (usize, usize, f64),
    /// The largest horizontal momentum (kg m/s).
    sideways: f64,
    /// The largest energy gain from one step to the next (J).
    gain: f64,
}

impl Settling {
    /// Checks that no step gained more than `gain` joules, nothing overlapped beyond
    /// [`OVERLAP`] and the horizontal momentum stayed at rounding (`what` names the case).
    fn check(&self, what: &str, gain: f64) {
        assert!(
            self.gain <= gain,
            "{what}: gained {:.1e} J in a step",
            self.gain
        );
        assert!(
            self.overlap <= OVERLAP,
            "{what}: overlap {:.1e} m {:?}",
            self.overlap,
            self.worst
        );
        assert!(
            self.sideways <= 1e-12,
            "{what}: horizontal momentum {:.1e}",
            self.sideways
        );
    }
}

/// Runs `sim` step by step to `until`, recording overlaps, the horizontal momentum and
/// energy gains.
fn settle<const D: usize>(
    sim: &mut carom_sim::stepped::SteppedEngine<f64, D>,
    scene: &Scene<f64, D>,
    until: f64,
    rec: &mut Recorder<f64>,
) -> Settling
where
    Const<D>: Space<f64, D>,
{
    let mut seen = Settling::default();
    let mut energy = observe::energy(scene, &states(sim));
    let mut k = 1;
    while f64::from(k) * DT <= until + 1e-9 {
        sim.advance_to(f64::from(k) * DT, rec).unwrap();
        let st = states(sim);
        let t = f64::from(k) * DT;
        for (i, (a, x)) in scene.balls.iter().zip(&st.pos).enumerate() {
            if a.radius - x[1] > seen.overlap {
                (seen.overlap, seen.worst) = (a.radius - x[1], (i, i, t));
            }
            for (j, (b, y)) in scene.balls.iter().zip(&st.pos).enumerate().skip(i + 1) {
                let overlap = a.radius + b.radius - (x - y).norm();
                if overlap > seen.overlap {
                    (seen.overlap, seen.worst) = (overlap, (i, j, t));
                }
            }
        }
        let p = observe::momentum(scene, &st);
        let horizontal = (0..D).filter(|&a| a != 1).map(|a| p[a].abs());
        seen.sideways = horizontal.fold(seen.sideways, f64::max);
        let e = observe::energy(scene, &st);
        seen.gain = seen.gain.max(e - energy);
        energy = e;
        k += 1;
    }
    seen
}

/// Runs `scene` for one second (landing, settling) and checks it on the way, then holds
/// it for [`HOLD`] seconds at `rest`; returns the most contacts a step needed.
fn rests_at<const D: usize>(
    scene: &Scene<f64, D>,
    rest: &[Vector<f64, D>],
    integrator: Integrator,
    settling: f64,
    what: &str,
) -> u64
where
    Const<D>: Space<f64, D>,
{
    let mut sim = stepped(scene, integrator, DT);
    let mut rec = Recorder::default();
    let seen = settle(&mut sim, scene, settling, &mut rec);
    let what = format!("{what}, {integrator}");
    // Energy: rounding of the energies themselves (|E| ~ 10 J) at most.
    seen.check(&what, 1e-12);
    assert_stays_put(
        &mut sim,
        scene,
        rest,
        settling + HOLD,
        20,
        AT_REST,
        &mut rec,
        &what,
    );
    let p = observe::momentum(scene, &states(&sim));
    assert!(p.norm() <= AT_REST, "{what}: momentum {p:?} at rest");
    sim.stats().max_contacts_in_step
}

#[test]
fn a_ball_in_the_hollow_of_a_resting_cluster_stays_at_its_stacking_height() {
    let (s2, rest2) = hollow_2d(0.5, 0.0);
    let (s3, rest3) = hollow_3d();
    // The references: the hollow's height from the geometry alone.
    assert!(
        (rest2[3].y - (R + (2.0 * R * R).sqrt())).abs() < 1e-15,
        "45° contacts"
    );
    for integrator in INTEGRATORS {
        rests_at(&s2, &rest2, integrator, 1.0, "2D hollow");
        rests_at(&s3, &rest3, integrator, 1.0, "3D hollow");
    }
}

#[test]
fn a_ball_dropped_onto_a_cluster_settles_in_its_hollow_whatever_the_floor_restitution() {
    // Every integrator: the landings on the held cluster are inelastic impulses and its
    // hold a constant force that takes energy (see `stack`), so no step gains more than
    // rounding (measured: 1.8e-15 J of 9 J).
    for floor in [0.0, 0.5, 1.0] {
        for integrator in INTEGRATORS {
            let (s, rest) = hollow_2d(floor, 0.5);
            let mut sim = stepped(&s, integrator, DT);
            let mut rec = Recorder::default();
            let seen = settle(&mut sim, &s, 5.0, &mut rec);
            let what = format!("floor e = {floor}, {integrator}");
            let hits = rec
                .collisions
                .iter()
                .filter(|c| matches!(c, Collision::BallBall { i, j, .. } if *i == 3 || *j == 3))
                .count();
            assert!(
                hits >= 2,
                "{what}: the ball bounced on the cluster ({hits} hits)"
            );
            // The ball fell on the symmetry axis onto a symmetric cluster: with no
            // horizontal momentum, everything ends where the placed stack rests.
            seen.check(&what, 1e-12);
            assert_stays_put(
                &mut sim,
                &s,
                &rest,
                5.0 + HOLD,
                20,
                AT_REST,
                &mut rec,
                &what,
            );
        }
    }
}

/// A pyramid's base: three load-bearing balls `d` apart glued into one cluster by two
/// small balls between them (the first five balls, glued).
fn pyramid_base(d: f64) -> Vec<BallSpec<f64, 2>> {
    let mut balls = vec![
        ball(&[-2.0 * d, R], R, 1.0, 0.5),
        ball(&[-d, GLUE], GLUE, 0.25, 0.0),
        ball(&[0.0, R], R, 1.0, 0.5),
        ball(&[d, GLUE], GLUE, 0.25, 0.0),
        ball(&[2.0 * d, R], R, 1.0, 0.5),
    ];
    glue(&mut balls, &[(0, 1), (2, 1), (2, 3), (4, 3)], 0.01);
    balls
}

#[test]
fn a_column_on_a_standing_pair_and_a_pyramid_on_a_cluster_stay_put() {
    // A column: a glue ball on the floor, a load-bearing ball fused on top of it, two balls
    // stacked on that, all on x = 0 (heights r, 3r, 5r, 7r).
    let mut column = vec![
        ball(&[0.0, R], R, 1.0, 0.0),
        ball(&[0.0, 3.0 * R], R, 1.0, 0.5),
        ball(&[0.0, 5.0 * R], R, 1.0, 1.0),
        ball(&[0.0, 7.0 * R], R, 1.0, 1.0),
    ];
    glue(&mut column, &[(0, 1)], 0.01);
    let (column, column_rest) = lifted(world::<2>(0.5, 2.0), column, LIFT);
    // A pyramid: three load-bearing balls glued into one cluster, a ball in each of its
    // two hollows, and one in the hollow those two make.
    let d = spread();
    let h = above(d);
    let mut pyramid = pyramid_base(d);
    pyramid.extend([
        ball(&[-d, R + h], R, 1.0, 1.0),
        ball(&[d, R + h], R, 1.0, 1.0),
        ball(&[0.0, R + 2.0 * h], R, 1.0, 1.0),
    ]);
    let (pyramid, pyramid_rest) = lifted(world::<2>(0.5, 2.0), pyramid, LIFT);
    for integrator in INTEGRATORS {
        rests_at(&column, &column_rest, integrator, 1.0, "column");
        rests_at(&pyramid, &pyramid_rest, integrator, 1.0, "pyramid");
    }
}

#[test]
fn a_ball_off_centre_on_a_cluster_held_on_both_sides_of_it_stays_put() {
    // The base of the pyramid and one ball in its right hollow, over x = d: its weight
    // passes between the cluster's outer supports (x = ±2d), so statics holds it, although
    // it is off the cluster's centre of mass (a torque the floor takes).
    let d = spread();
    let mut balls = pyramid_base(d);
    balls.push(ball(&[d, R + above(d)], R, 1.0, 1.0));
    let (s, rest) = lifted(world::<2>(0.5, 2.0), balls, LIFT);
    for integrator in INTEGRATORS {
        rests_at(&s, &rest, integrator, 1.0, "off-centre ball");
    }
}

/// A pair standing on the floor (glue ball 0 below, load-bearing ball 1 on it) and ball 2
/// resting on ball 1 at `theta` from the vertical, towards `+x`.
fn tipped_pair(theta: f64) -> Scene<f64, 2> {
    let mut balls = vec![
        ball(&[0.0, R], R, 1.0, 0.0),
        ball(&[0.0, 3.0 * R], R, 1.0, 0.5),
        ball(
            &[2.0 * R * theta.sin(), 3.0 * R + 2.0 * R * theta.cos()],
            R,
            1.0,
            1.0,
        ),
    ];
    glue(&mut balls, &[(0, 1)], 0.01);
    Scene {
        world: world(0.5, 2.0),
        balls,
        ..Scene::default()
    }
}

#[test]
fn a_ball_pushing_the_top_of_a_standing_pair_tips_it_with_the_closed_form_angular_acceleration() {
    // The first instant, from rest (frictionless contacts, so only normal forces): the
    // pair (mass M = 2m, inertia I = 2·(½ m r²) + 2·m r² about its centre 2r up) stands
    // on its floor point; the ball (mass m) presses on the upper member along
    // u = (sin θ, cos θ) with force N. Contact acceleration zero at both contacts gives
    //   N (1/m + sin²θ/M + r² sin²θ/I) = g cos θ,   α = N r sin θ / I,
    // (the floor's reaction passes through the pair's centre line and adds no torque).
    let theta = 20f64.to_radians();
    let (m, mass, r) = (1.0, 2.0, R);
    let inertia = 2.0 * (0.5 * m * r * r) + 2.0 * m * r * r;
    let (sin, cos) = (theta.sin(), theta.cos());
    let force = G * cos / (1.0 / m + sin * sin / mass + r * r * sin * sin / inertia);
    let alpha = force * r * sin / inertia;
    let s = tipped_pair(theta);
    // The hold is a constant force over the step (see `stack`): the end velocities have
    // it for the whole step with every integrator, so the pair's spin after the first
    // step is α h, at any step, to the exact solve's rounding.
    for integrator in INTEGRATORS {
        for dt in [DT, 1.0 / 600.0] {
            let mut sim = stepped(&s, integrator, dt);
            sim.advance_to(dt, &mut ()).unwrap();
            let spin = states(&sim).spin[0].x;
            // Counter-clockwise: the push at the top turns the pair to −x.
            assert!(
                (spin / dt - alpha).abs() <= 1e-9 * alpha,
                "{integrator}, dt = {dt}: α = {} vs {alpha}",
                spin / dt
            );
        }
    }
    // Then, for a tenth of a second (before the ball, sliding off to the right, reaches
    // the glue ball below and sticks to it), the pair turns to the left and the ball moves
    // right, on a frictionless floor: the horizontal momentum stays zero, the energy
    // never grows, nothing overlaps.
    for integrator in INTEGRATORS {
        let mut sim = stepped(&s, integrator, DT);
        let mut rec = Recorder::default();
        let seen = settle(&mut sim, &s, 0.1, &mut rec);
        let st = states(&sim);
        assert!(
            st.spin[0].x > 0.5,
            "the pair turns counter-clockwise: {}",
            st.spin[0].x
        );
        assert!(st.pos[1].x < -0.01, "the pair's top at {:?}", st.pos[1]);
        assert!(
            st.pos[2].x > s.balls[2].pos.x + 0.01,
            "the ball at {:?}",
            st.pos[2]
        );
        seen.check(&format!("tipping pair, {integrator}"), 1e-12);
        assert!(
            rec.collisions.len() == 1,
            "only the pair's fusion: {:?}",
            rec.collisions
        );
    }
}

/// Four balls packed on the floor between walls, and a cluster of two load-bearing balls
/// (mass `mass` each) resting in the hollows between the first two and the last two,
/// glued by a ball of radius 2R and mass 4·`mass` above them (out of reach of the floor
/// balls).
fn cluster_on_balls(mass: f64) -> (Scene<f64, 2>, Vec<Vector<f64, 2>>) {
    let y = R + above(R);
    // The glue touches both load-bearing balls: √((2R)² + h²) = 3R.
    let h = 5f64.sqrt() * R;
    let mut balls = vec![
        ball(&[-3.0 * R, R], R, 1.0, 0.5),
        ball(&[-R, R], R, 1.0, 0.5),
        ball(&[R, R], R, 1.0, 0.5),
        ball(&[3.0 * R, R], R, 1.0, 0.5),
        ball(&[-2.0 * R, y], R, mass, 0.5),
        ball(&[2.0 * R, y], R, mass, 0.5),
        ball(&[0.0, y + h], 2.0 * R, 4.0 * mass, 0.0),
    ];
    glue(&mut balls, &[(4, 6), (5, 6)], 0.01 * mass);
    // Only the cluster is lifted: the floor balls rest from the start.
    let (mut s, rest) = lifted::<2>(world(0.5, 4.0 * R), balls, 0.0);
    for b in &mut s.balls[4..] {
        b.pos.y += LIFT;
    }
    (s, rest)
}

#[test]
fn a_cluster_resting_in_the_hollows_of_packed_balls_stays_put_even_a_million_times_heavier() {
    // The floor balls are packed between the walls: held by the floor, the walls and each
    // other, they are immovable supports for the cluster, which rests on each of them
    // along a contact at 30° from the vertical. At mass ratio 1e6 too.
    for mass in [1.0, 1e6] {
        let (s, rest) = cluster_on_balls(mass);
        for integrator in INTEGRATORS {
            let mut sim = stepped(&s, integrator, DT);
            let mut rec = Recorder::default();
            let seen = settle(&mut sim, &s, 1.0, &mut rec);
            let what = format!("mass {mass}, {integrator}");
            assert!(
                seen.overlap <= OVERLAP,
                "{what}: overlap {:.1e} m {:?}",
                seen.overlap,
                seen.worst
            );
            // Relative to the energy (~2.5e7 J at mass 1e6).
            let scale = observe::energy(&s, &states(&sim)).abs();
            assert!(
                seen.gain <= 1e-15 * scale,
                "{what}: gained {:.1e} J",
                seen.gain
            );
            assert_stays_put(
                &mut sim,
                &s,
                &rest,
                1.0 + HOLD,
                20,
                AT_REST,
                &mut rec,
                &what,
            );
        }
    }
}

#[test]
fn far_from_the_origin_the_stack_stays_put_to_the_rounding_of_its_coordinates() {
    // The hollow stack moved to (1e6, 1e6): coordinates carry ε·1e6 ≈ 2.2e-10 m of
    // rounding each, which the geometry of every contact sees; positions are checked to
    // 64 ε |x| = 1.4e-8 m, speeds likewise (a step's position rounding over the step is
    // 1.3e-8 m/s), the energy (dominated by m g y ≈ 3e7 J) to 1e-9 relative.
    let offset = 1e6;
    let (mut s, mut rest) = hollow_2d(0.5, 0.0);
    for (b, x) in s.balls.iter_mut().zip(&mut rest) {
        b.pos.x += offset;
        b.pos.y += offset;
        x.x += offset;
        x.y += offset;
    }
    if let Some(border) = s.world.border.as_mut() {
        let shift = at::<2>(&[offset, offset]);
        border.border =
            Border::new(border.border.min() + shift, border.border.max() + shift).unwrap();
    }
    // Computed in the scene's own coordinates (a box at the origin) and from its middle.
    let tolerance = 64.0 * f64::EPSILON * offset * 2f64.sqrt();
    let frames = [(spanning_the_origin(&s), "own"), (s, "middle")];
    for ((s, frame), integrator) in frames
        .iter()
        .flat_map(|f| [Integrator::SemiImplicitEuler, Integrator::Exact].map(|i| (f, i)))
    {
        let mut sim = stepped(s, integrator, DT);
        let mut rec = Recorder::default();
        sim.advance_to(1.0, &mut rec).unwrap();
        let what = format!("at 1e6, {frame} coordinates, {integrator}");
        assert_stays_put(
            &mut sim,
            s,
            &rest,
            1.0 + HOLD,
            20,
            tolerance,
            &mut rec,
            &what,
        );
    }
}

/// 2D: the pyramid's base (mass `lower` per load-bearing ball) on the floor, and a
/// cluster of two load-bearing balls (mass `upper` each) in its two hollows, glued by a
/// ball of radius `GLUE` above them: `d² + GLUE² = (R + GLUE)²` puts it `GLUE` above
/// their centres, out of reach of the base. The base is fused `LIFT` above its place, the
/// upper cluster `2 LIFT` above its own, so that it lands on the base already fused.
fn cluster_on_cluster_2d(lower: f64, upper: f64) -> (Scene<f64, 2>, Vec<Vector<f64, 2>>) {
    let d = spread();
    let h = above(d);
    let mut balls = pyramid_base(d);
    // Every mass of the base scaled alike: its glued pairs' momenta stay equal and
    // opposite.
    for b in &mut balls {
        b.mass *= lower;
    }
    let mut top = vec![
        ball(&[-d, R + h], R, upper, 0.5),
        ball(&[d, R + h], R, upper, 0.5),
        ball(&[0.0, R + h + GLUE], GLUE, 0.25 * upper, 0.0),
    ];
    glue(&mut top, &[(0, 2), (1, 2)], 0.01 * upper);
    let first = balls.len();
    balls.extend(top);
    let (mut s, rest) = lifted::<2>(world(0.5, 2.0), balls, LIFT);
    for b in &mut s.balls[first..] {
        b.pos.y += LIFT;
    }
    (s, rest)
}

/// 3D: a hexagonal layer of six load-bearing balls (mass `lower`, centres `2R` apart) on
/// the floor, glued by balls of radius `R/3` under its three upward holes (`(2R/√3)² +
/// (2R/3)² = (4R/3)²`: they touch the three balls around the hole and the floor), and a
/// cluster of three load-bearing balls (mass `upper`) in the pockets above those holes,
/// `2R √(2/3)` above the layer (a regular tetrahedron of side `2R` with the hole's three
/// balls), glued by a ball of radius `R/2` above their centre
/// (`(2R/√3)² + k² = (3R/2)²`). Lifted as in [`cluster_on_cluster_2d`].
fn cluster_on_cluster_3d(lower: f64, upper: f64) -> (Scene<f64, 3>, Vec<Vector<f64, 3>>) {
    let r3 = 3f64.sqrt();
    // The layer in units of R, centred on the middle hole's centroid.
    let layer = [
        (0.0, 0.0),
        (2.0, 0.0),
        (4.0, 0.0),
        (1.0, r3),
        (3.0, r3),
        (2.0, 2.0 * r3),
    ];
    let holes = [(0, 1, 3), (1, 2, 4), (3, 4, 5)];
    let centre = (2.0, 2.0 * r3 / 3.0);
    let place = |(x, z): (f64, f64), y: f64| [(x - centre.0) * R, y, (z - centre.1) * R];
    let centroid = |(a, b, c): (usize, usize, usize)| {
        (
            (layer[a].0 + layer[b].0 + layer[c].0) / 3.0,
            (layer[a].1 + layer[b].1 + layer[c].1) / 3.0,
        )
    };
    let mut balls: Vec<BallSpec<f64, 3>> = layer
        .iter()
        .map(|&xz| ball(&place(xz, R), R, lower, 0.5))
        .collect();
    let mut pairs = Vec::new();
    for hole in holes {
        let k = balls.len();
        balls.push(ball(
            &place(centroid(hole), R / 3.0),
            R / 3.0,
            0.1 * lower,
            0.0,
        ));
        pairs.extend([(hole.0, k), (hole.1, k), (hole.2, k)]);
    }
    glue(&mut balls, &pairs, 0.01 * lower);
    let first = balls.len();
    let up = R + 2.0 * R * (2.0f64 / 3.0).sqrt();
    let mut top: Vec<BallSpec<f64, 3>> = holes
        .iter()
        .map(|&hole| ball(&place(centroid(hole), up), R, upper, 0.5))
        .collect();
    let k = ((1.5 * R).powi(2) - 4.0 * R * R / 3.0).sqrt();
    top.push(ball(&[0.0, up + k, 0.0], R / 2.0, 0.25 * upper, 0.0));
    glue(&mut top, &[(0, 3), (1, 3), (2, 3)], 0.01 * upper);
    balls.extend(top);
    let (mut s, rest) = lifted(world(0.5, 2.0), balls, LIFT);
    for b in &mut s.balls[first..] {
        b.pos[1] += LIFT;
    }
    (s, rest)
}

/// Runs a cluster resting on a cluster: one second to land and settle, then [`HOLD`]
/// seconds step by step. Checks every step for overlaps and energy gains, then at rest
/// every ball's height and vertical speed against the geometric stacking height `rest`,
/// the horizontal momentum, how many contacts a step costs and that no step ran out of
/// its event budget.
fn cluster_rests_on_cluster<const D: usize>(
    scene: &Scene<f64, D>,
    rest: &[Vector<f64, D>],
    integrator: Integrator,
    what: &str,
) where
    Const<D>: Space<f64, D>,
{
    let what = format!("{what}, {integrator}");
    let mut sim = stepped(scene, integrator, DT);
    let mut rec = Recorder::default();
    let seen = settle(&mut sim, scene, 1.0, &mut rec);
    let mut energy = observe::energy(scene, &states(&sim));
    let scale = energy.abs();
    let mut most = 0u64;
    let (mut height, mut vertical, mut horizontal, mut gain) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut overlap = seen.overlap;
    let steps = (HOLD / DT).round() as u32;
    for k in 1..=steps {
        let before = sim.stats().contacts;
        sim.advance_to(1.0 + f64::from(k) * DT, &mut rec).unwrap();
        most = most.max(sim.stats().contacts - before);
        let st = states(&sim);
        for (i, (x, v)) in st.pos.iter().zip(&st.vel).enumerate() {
            height = height.max((x[1] - rest[i][1]).abs());
            vertical = vertical.max(v[1].abs());
            let mut off = x - rest[i];
            off[1] = 0.0;
            horizontal = horizontal.max(off.norm());
            overlap = overlap.max(scene.balls[i].radius - x[1]);
            for (j, y) in st.pos.iter().enumerate().skip(i + 1) {
                let r = scene.balls[i].radius + scene.balls[j].radius;
                overlap = overlap.max(r - (x - y).norm());
            }
        }
        let e = observe::energy(scene, &st);
        gain = gain.max(e - energy);
        energy = e;
    }
    // Energy: what the heights' jitter within the resting floor's reach is worth, a
    // relative 1e-11 (measured: rounding, up to 4e-12 with the upper cluster a million
    // times heavier, heights still within 2e-10 m).
    assert!(
        seen.gain.max(gain) <= 1e-11 * scale,
        "{what}: gained {:.1e} J of {scale:.1e}",
        seen.gain.max(gain)
    );
    assert!(overlap <= OVERLAP, "{what}: overlap {overlap:.1e} m");
    let mass: f64 = scene.balls.iter().map(|b| b.mass).sum();
    assert!(
        seen.sideways <= 1e-12 * mass,
        "{what}: horizontal momentum {:.1e}",
        seen.sideways
    );
    assert!(
        height <= AT_REST,
        "{what}: a ball {height:.1e} m off its height"
    );
    assert!(
        vertical <= AT_REST,
        "{what}: a ball moves at {vertical:.1e} m/s"
    );
    assert!(
        horizontal <= AT_REST,
        "{what}: a ball {horizontal:.1e} m off its place sideways"
    );
    // At rest a step costs the one contact the stack is held at, not an event per
    // correction (measured: 1).
    assert!(most <= 4, "{what}: {most} contacts in a step at rest");
    assert_eq!(
        sim.stats().capped_steps,
        0,
        "{what}: a step ran out of events"
    );
}

#[test]
fn a_cluster_resting_on_a_cluster_stays_at_its_stacking_height_whatever_the_mass_ratio() {
    for (lower, upper) in [(1.0, 1.0), (1.0, 1e6), (1e6, 1.0)] {
        let (s2, rest2) = cluster_on_cluster_2d(lower, upper);
        let (s3, rest3) = cluster_on_cluster_3d(lower, upper);
        for integrator in INTEGRATORS {
            let what = format!("lower {lower:e}, upper {upper:e}");
            cluster_rests_on_cluster(&s2, &rest2, integrator, &format!("2D {what}"));
            cluster_rests_on_cluster(&s3, &rest3, integrator, &format!("3D {what}"));
        }
    }
}
