//! Guards against the two infinite loops of inelastic hard-ball dynamics, as explicit
//! policies with documented parameters. The functions decide; the engine keeps the
//! history (the time of each ball's last collision) and acts on the decision.
//!
//! # Inelastic collapse ([`CollapseGuard`])
//!
//! With restitution `e < 1`, a group of balls can collide infinitely often in finite
//! time: each collision shrinks the relative velocities by a constant factor, so the
//! times between collisions form a convergent geometric series (McNamara and Young,
//! Phys. Fluids A 4, 496 (1992); three balls on a line can collapse only for
//! `e < 7 − 4√3 ≈ 0.072`, Constantin, Grossman and Mungan, Physica D 84, 1995). An
//! event-driven engine then never gets past the accumulation time. Two guards:
//!
//! * [`CollapseGuard::TcModel`] (Luding and McNamara, "How to handle the inelastic
//!   collapse of a dissipative hard-sphere gas with the TC model", Granular Matter 1,
//!   113 (1998)): a collision is elastic (`e = 1`) if either ball already collided
//!   within the last `t_c` (the duration of a real contact). A ball in a rapid sequence
//!   of collisions stops dissipating, which cuts the geometric series; `t_c` should be
//!   much shorter than the mean free time so that dilute dynamics is unchanged.
//! * [`CollapseGuard::ElasticBelow`]: a collision whose approach speed is below `v_min`
//!   is elastic. This mirrors the velocity-dependent restitution of viscoelastic spheres,
//!   `e(v) → 1` as `v → 0` (Brilliantov, Spahn, Hertzsch and Pöschel, Phys. Rev. E 53,
//!   5382 (1996)). The other choice, `e → 0` below `v_min`, does **not** prevent
//!   collapse: a ball hitting a touching chain with `e = 0` starts an infinite sequence of
//!   zero-distance collisions that converges to a common velocity. `v_min` should be far
//!   below the speeds of interest (for example 1e-6 of the typical speed).
//!
//! # Zeno bouncing ([`RestingGuard`])
//!
//! A ball bouncing on a static floor under gravity `g` with `e < 1` rebounds at
//! `e^k v₀` after `k` bounces; the flight times `2 e^k v₀ / g` sum to the finite
//! `2 v₀ e / (g (1 − e))`: infinitely many bounces in finite time. The guard has a
//! minimum flight time `t_min`: a bounce whose rebound flight would be shorter,
//! `2 e v / g_n < t_min`, i.e. rebound speed `e v < g_n t_min / 2`, ends the bouncing
//! ([`Bounce::Rest`]). The engine then resolves that contact with `e = 0` (the normal
//! relative velocity is removed; friction still acts) and switches the ball to a resting
//! state on the surface: its normal acceleration is cancelled, it slides or rolls along
//! the surface, and it leaves that state when another body hits it or the acceleration
//! pulls it away from the surface (`g_n ≤ 0`). A natural `t_min` is the engine's time
//! step or a fixed small time (1e-4 s for a table-tennis ball is far below anything
//! visible). The number of bounces is then finite:
//! `k = ⌈ln(g t_min / (2 e v₀)) / ln e⌉` at most.

use carom_math::{InvalidValue, Real, ensure_positive};

/// The inelastic-collapse guard of ball–ball collisions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CollapseGuard<T: Real> {
    /// No guard: the given restitution is always used (an engine may then collapse).
    Off,
    /// Luding and McNamara's TC model: elastic if either ball collided within
    /// `contact_duration` before this collision.
    TcModel {
        /// `t_c > 0`, the duration of a real contact.
        contact_duration: T,
    },
    /// Elastic below a minimum approach speed.
    ElasticBelow {
        /// `v_min > 0`: collisions approaching slower than this are elastic.
        approach_speed: T,
    },
}

impl<T: Real> CollapseGuard<T> {
    /// The TC model with contact duration `t_c`.
    ///
    /// # Errors
    /// `contact_duration` if not finite and `> 0`.
    pub fn tc_model(contact_duration: T) -> Result<Self, InvalidValue> {
        Ok(Self::TcModel {
            contact_duration: ensure_positive("contact_duration", contact_duration)?,
        })
    }

    /// Elastic collisions below the approach speed `v_min`.
    ///
    /// # Errors
    /// `approach_speed` if not finite and `> 0`.
    pub fn elastic_below(approach_speed: T) -> Result<Self, InvalidValue> {
        Ok(Self::ElasticBelow {
            approach_speed: ensure_positive("approach_speed", approach_speed)?,
        })
    }

    /// The restitution to use for a collision with nominal `restitution`, approaching at
    /// `approach_speed` (`−v_rel·n`, see [`crate::normal_velocity`]), whose two balls last
    /// collided `since_last[0]` and `since_last[1]` ago (`T::INFINITY` if never; the
    /// engine counts every collision of a ball, with balls and with walls, and passes
    /// `T::INFINITY` for a static or kinematic body).
    #[inline]
    pub fn restitution(&self, restitution: T, approach_speed: T, since_last: [T; 2]) -> T {
        let elastic = match *self {
            Self::Off => false,
            Self::TcModel { contact_duration } => {
                since_last[0] < contact_duration || since_last[1] < contact_duration
            }
            Self::ElasticBelow {
                approach_speed: v_min,
            } => approach_speed < v_min,
        };
        if elastic { T::one() } else { restitution }
    }
}

/// What the resting guard decided for a bounce.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bounce {
    /// The ball rebounds with the nominal restitution.
    Rebound,
    /// The ball comes to rest on the surface: resolve with `e = 0` and switch it to a
    /// resting (sliding or rolling) state.
    Rest,
}

/// The Zeno guard of a ball bouncing on a static or kinematic surface under a constant
/// acceleration: a bounce whose rebound flight would last less than `min_flight_time`
/// ends in rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestingGuard<T: Real> {
    min_flight_time: T,
}

impl<T: Real> RestingGuard<T> {
    /// A guard with minimum flight time `t_min`.
    ///
    /// # Errors
    /// `min_flight_time` if not finite and `> 0`.
    pub fn new(min_flight_time: T) -> Result<Self, InvalidValue> {
        Ok(Self {
            min_flight_time: ensure_positive("min_flight_time", min_flight_time)?,
        })
    }

    /// The minimum flight time `t_min`.
    #[inline]
    pub fn min_flight_time(&self) -> T {
        self.min_flight_time
    }

    /// The rebound speed below which the ball rests: `g_n t_min / 2`, where
    /// `normal_acceleration` `g_n` is the ball's acceleration relative to the surface
    /// along the contact normal (from the ball into the surface; `g·n` for gravity).
    /// Zero when the acceleration does not push the ball onto the surface.
    #[inline]
    pub fn rest_speed(&self, normal_acceleration: T) -> T {
        if normal_acceleration > T::zero() {
            normal_acceleration * self.min_flight_time * T::lit(0.5)
        } else {
            T::zero()
        }
    }

    /// The decision for a bounce approaching at `approach_speed` with `restitution`
    /// under `normal_acceleration` (see [`RestingGuard::rest_speed`]): rest when the
    /// rebound speed `e v` is below the rest speed, i.e. the rebound flight `2 e v / g_n`
    /// would be shorter than `t_min`.
    #[inline]
    pub fn decide(&self, approach_speed: T, restitution: T, normal_acceleration: T) -> Bounce {
        if restitution * approach_speed < self.rest_speed(normal_acceleration) {
            Bounce::Rest
        } else {
            Bounce::Rebound
        }
    }

    /// As [`RestingGuard::decide`], and also rest when the rebound would rise less than
    /// `resolution`: `(e v)² < 2 g_n · resolution`.
    ///
    /// `resolution` is the smallest height the caller can represent at the contact, a
    /// few roundings of its coordinates. Far from the origin it dwarfs the height of the
    /// shortest flight, `g_n t_min² / 8`: a ball at `y = −702` m (rounding 1.1e-13 m)
    /// rebounding 1e-6 m/s flies 5e-14 m, below what its position can say. Each contact
    /// is then placed to the rounding of the position, which may add the flight's whole
    /// energy back, and such a ball bounced forever at a constant height (5 million
    /// bounces per simulated second) instead of coming to rest.
    #[inline]
    pub fn decide_resolved(
        &self,
        approach_speed: T,
        restitution: T,
        normal_acceleration: T,
        resolution: T,
    ) -> Bounce {
        let rebound = restitution * approach_speed;
        let too_low = normal_acceleration > T::zero()
            && rebound * rebound < T::lit(2.0) * normal_acceleration * resolution;
        if too_low {
            Bounce::Rest
        } else {
            self.decide(approach_speed, restitution, normal_acceleration)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tc_model_is_elastic_only_inside_the_contact_duration() {
        let g = CollapseGuard::tc_model(1e-3_f64).unwrap();
        assert_eq!(g.restitution(0.5, 1.0, [f64::INFINITY, f64::INFINITY]), 0.5);
        assert_eq!(g.restitution(0.5, 1.0, [2e-3, 5e-4]), 1.0);
        assert_eq!(g.restitution(0.5, 1.0, [1e-3, 1e-3]), 0.5);
        assert_eq!(CollapseGuard::Off.restitution(0.5, 0.0, [0.0, 0.0]), 0.5);
        assert_eq!(
            CollapseGuard::<f64>::tc_model(0.0).unwrap_err().field,
            "contact_duration"
        );
    }

    #[test]
    fn threshold_guard_is_elastic_below_the_speed() {
        let g = CollapseGuard::elastic_below(1e-6_f32).unwrap();
        assert_eq!(g.restitution(0.3, 1e-7, [0.0, 0.0]), 1.0);
        assert_eq!(g.restitution(0.3, 1e-6, [0.0, 0.0]), 0.3);
        assert!(CollapseGuard::<f32>::elastic_below(f32::NAN).is_err());
    }

    #[test]
    fn resting_guard_rests_when_the_rebound_flight_is_shorter_than_the_minimum() {
        let g = RestingGuard::new(0.01_f64).unwrap();
        // g = 10: rest speed 0.05; rebound flight 2 e v / g.
        assert_eq!(g.rest_speed(10.0), 0.05);
        assert_eq!(g.decide(0.2, 0.5, 10.0), Bounce::Rebound); // flight 0.02
        assert_eq!(g.decide(0.09, 0.5, 10.0), Bounce::Rest); // flight 0.009
        assert_eq!(g.decide(1.0, 0.0, 10.0), Bounce::Rest);
        // Gravity pulling away from the surface never makes a ball rest on it.
        assert_eq!(g.decide(1e-9, 0.5, -10.0), Bounce::Rebound);
        assert_eq!(
            RestingGuard::<f64>::new(-1.0).unwrap_err().field,
            "min_flight_time"
        );
    }

    #[test]
    fn resting_guard_rests_when_the_rebound_rises_less_than_the_resolution() {
        let g = RestingGuard::new(1e-8_f64).unwrap();
        // g = 10, resolution 1e-12 m: rebounds below √(2·10·1e-12) ≈ 4.47e-6 m/s rest.
        assert_eq!(g.decide_resolved(4e-6, 1.0, 10.0, 1e-12), Bounce::Rest);
        assert_eq!(g.decide_resolved(5e-6, 1.0, 10.0, 1e-12), Bounce::Rebound);
        assert_eq!(g.decide(4e-6, 1.0, 10.0), Bounce::Rebound);
        // A zero resolution is the plain decision; gravity pulling away never rests.
        assert_eq!(g.decide_resolved(1e-9, 1.0, 10.0, 0.0), Bounce::Rest);
        assert_eq!(g.decide_resolved(1e-9, 1.0, -10.0, 1.0), Bounce::Rebound);
    }
}
