//! Time reversal: an elastic event-driven run forward, then the same number of events
//! backward from the final state, returns to the initial state. This checks that the
//! backward queries find exactly the events of the forward run, in reverse order.

use carom_geometry::{Ball, Border};
use carom_toi::{Direction, Kinematics, Side, Status, Window, ball_ball, ball_border};
use nalgebra::Vector2;

#[derive(Clone, Copy, Debug)]
struct State {
    p: [Vector2<f64>; 2],
    v: [Vector2<f64>; 2],
}

const R: f64 = 0.3;

/// Advances to the next event in `direction` (equal masses, restitution 1), returning
/// the signed time advanced.
fn step(s: &mut State, border: &Border<f64, 2>, direction: Direction) -> f64 {
    let w = Window::unbounded(direction);
    let ball = |i: usize| Ball::new(s.p[i], R).unwrap();
    let k = |i: usize| Kinematics::linear(s.v[i]).unwrap();
    let pair = ball_ball(&ball(0), &k(0), &ball(1), &k(1), &w);
    let walls = [0, 1].map(|i| ball_border(&ball(i), &k(i), border, &w));
    let mut best = (pair.time.abs(), 2);
    for (i, t) in walls.iter().enumerate() {
        if t.is_hit() && t.time.abs() < best.0 {
            best = (t.time.abs(), i);
        }
    }
    let t = best.0 * direction.sign::<f64>();
    for i in 0..2 {
        s.p[i] += s.v[i] * t;
    }
    if best.1 == 2 {
        // At the turning point the last forward event is met again at time 0.
        assert!(matches!(pair.status, Status::Hit | Status::AlreadyTouching));
        // Exchange the normal components (equal masses, e = 1).
        let n = pair.normal;
        let dv = n * (s.v[1] - s.v[0]).dot(&n);
        s.v[0] += dv;
        s.v[1] -= dv;
    } else {
        let wall = walls[best.1].feature;
        let sign = if wall.side == Side::Upper { 1.0 } else { -1.0 };
        let vn = s.v[best.1][wall.axis];
        assert!(
            vn * sign * direction.sign::<f64>() > 0.0,
            "approaching the wall in the query's direction"
        );
        s.v[best.1][wall.axis] = -vn;
    }
    t
}

#[test]
fn forward_then_backward_returns_to_the_start() {
    let border = Border::new(Vector2::new(0.0, 0.0), Vector2::new(3.0, 2.0)).unwrap();
    let start = State {
        p: [Vector2::new(0.7, 0.6), Vector2::new(2.2, 1.3)],
        v: [Vector2::new(1.3, 0.4), Vector2::new(-0.8, 0.9)],
    };
    let mut s = start;
    let mut clock = 0.0;
    for _ in 0..40 {
        clock += step(&mut s, &border, Direction::Forward);
    }
    assert!(clock > 1.0);
    // Backward, the first event is the last forward one, at time 0: undoing 40 events
    // brings the balls back to the first event with their initial velocities.
    for k in 0..40 {
        let dt = step(&mut s, &border, Direction::Backward);
        assert!(dt <= 0.0 && (k > 0 || dt == 0.0), "step {k}: {dt}");
        clock += dt;
    }
    for i in 0..2 {
        s.p[i] -= s.v[i] * clock;
    }
    for i in 0..2 {
        assert!(
            (s.p[i] - start.p[i]).norm() < 1e-9,
            "{:?} vs {:?}",
            s.p[i],
            start.p[i]
        );
        assert!(
            (s.v[i] - start.v[i]).norm() < 1e-9,
            "{:?} vs {:?}",
            s.v[i],
            start.v[i]
        );
    }
}
