//! The narrow phase of a step: exact times of impact along the balls' chords, and the
//! queue of pending contacts.
//!
//! Within a window every ball moves on a straight segment (see `balls`), so each pair's
//! first contact is carom-toi's closed form for linear relative motion: [`ball_ball`],
//! [`ball_border`] for the walls of a reflecting border, [`ball_obb`] for a box
//! translating at its own velocity. Times are offsets from the time `s` the prediction
//! is made at, within the horizon `end − s`; the event records the in-step time.
//!
//! A contact whose normal approach speed at the time of contact is at the level of
//! rounding ([`Allowance`]: `64 ε` times the two speeds for a ball or a box, and for two
//! balls also the relative speed times the angle rounding turns the normal between their
//! centres by; none for a wall, whose normal is an axis and whose approach is a component
//! of the chord, read exactly; and the rounding of a cluster member's chord) is not an
//! event:
//! it comes from a pair left touching with zero relative normal velocity by a previous
//! response, and acting on it would only repeat that response. Contacts approaching
//! slower than a millionth of what gravity adds in one step are not events either (a
//! wall's, only as far as gravity presses into it): they are the rounding residue of
//! resting corrections, which would otherwise be corrected again and again without
//! change. The overlap one can leave is that speed times the step, and is acted on when
//! the approach grows past it. A push of another ball that leaves a ball closing on a
//! wall or box it touches by less is no rounding, and nothing lifts a sunk ball again:
//! the surface takes it at once (`Contacts::settle_on_surfaces`). Before, a fuzzed
//! scene's resting ball, pushed into the floor by a light ball at 1.5e-8 to 1.1e-7 m/s
//! step after step, was left 2.7e-9 m in it (docs/stepped.md).
//!
//! In a periodic domain a ball meets the minimum image of another ball (the window is
//! short enough for it to be the only one that can be reached), and every image of a
//! box whose swept box the ball's path reaches.
//!
//! [`ball_ball`]: carom_toi::ball_ball
//! [`ball_border`]: carom_toi::ball_border
//! [`ball_obb`]: carom_toi::ball_obb

use core::cmp::Ordering;

use carom_geometry::query::signed_distance;
use carom_geometry::{Ball, Border};
use carom_math::{Real, Space, Vector};
use carom_toi::{Kinematics, Status, Toi, Window, ball_ball, ball_border, ball_obb};
use nalgebra::Const;

use super::balls::BallArrays;
use super::clusters::FREE;
use super::obstacles::{BoxArrays, image_offsets};
use super::sweep::{Sweep, overlap, path_box};
use crate::scene::coordinate_resolution;

/// The rounding of an approach speed, in units of `ε` of the two bodies' speeds (see
/// [`Allowance`]).
const APPROACH_ROUNDING: f64 = 64.0;

/// The same for a ball [`sunk`] into another ball or a box (see [`Allowance`]; a wall
/// counts no speeds).
const SUNK_APPROACH_ROUNDING: f64 = 4.0;

/// The length of `v` for an allowance: its norm, or its largest component where the
/// squares of its components underflow (below `√MIN_POSITIVE`: 1.1e-19 in `f32`,
/// 1.5e-154 in `f64`), which leaves the norm 0 and an allowance of nothing.
///
/// Two balls in `f32`, one resting on the other in a corner and both drifting up at
/// 3.2e-24 m/s, the lower faster by the rounding of a hold's sums (1.2e-30 m/s), were
/// allowed no approach at all: the same contact again, 16,385 times at one instant,
/// and a false crush error (`stepped_fuzz --seed 42`'s s48, `f32`, at 0.012 s). Read
/// so, their speeds' rounding allows them `64 ε · 2 · 3.2e-24`, 4.9e-29 m/s.
fn speed<T: Real, const D: usize>(v: &Vector<T, D>) -> T
where
    Const<D>: Space<T, D>,
{
    v.norm().max(v.amax())
}

/// What a ball touches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Target {
    /// Another ball (with a higher index).
    Ball(u32),
    /// A wall of the reflecting border.
    Border,
    /// A box.
    Box(u32),
}

/// A predicted contact.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Event<T: Real, const D: usize> {
    /// The instant: the contact time in units of the simultaneity window (see
    /// [`Event::key_cmp`]).
    instant: u64,
    /// The height of the lower body at contact, along gravity (zero without gravity): its
    /// centre for two balls, the ball's lowest point against a wall or a box.
    height: T,
    /// In-step time of the contact.
    pub(crate) time: T,
    /// The ball (the lower index for two balls).
    pub(crate) ball: u32,
    /// What it touches.
    pub(crate) target: Target,
    /// The versions of the ball and (for two balls) the other ball at prediction.
    pub(crate) versions: [u32; 2],
    /// The unit normal at contact, from the ball to the target.
    pub(crate) normal: Vector<T, D>,
    /// The periodic shift of the target (zero in open space).
    pub(crate) shift: Vector<T, D>,
}

impl<T: Real, const D: usize> Event<T, D> {
    /// The total order the queue pops in: the instant, then bottom-up along gravity, then
    /// the time, the pair and the versions. Contacts within one simultaneity window (a
    /// millionth of the step, or less when balls move fast: `SteppedEngine::instant_width`)
    /// are one instant: a pile of balls touching within rounding
    /// is settled from the floor up, so that every ball finds its supports already at
    /// rest. Equal keys are the same prediction, so the order never depends on how
    /// events were inserted (thread count, chunking).
    fn key_cmp(&self, other: &Self) -> Ordering {
        let cmp = |a: T, b: T| a.partial_cmp(&b).unwrap_or(Ordering::Equal);
        self.instant
            .cmp(&other.instant)
            .then(cmp(self.height, other.height))
            .then(cmp(self.time, other.time))
            .then(self.ball.cmp(&other.ball))
            .then(self.target.cmp(&other.target))
            .then(self.versions.cmp(&other.versions))
    }
}

impl<T: Real, const D: usize> Event<T, D> {
    /// The balls the contact involves: the ball and the other ball, or the ball twice
    /// for a wall or a box.
    pub(crate) fn balls(&self) -> [usize; 2] {
        let i = self.ball as usize;
        match self.target {
            Target::Ball(j) => [i, j as usize],
            Target::Border | Target::Box(_) => [i, i],
        }
    }

    /// A contact of balls `ball < other` at in-step time `time`, without gravity, with a
    /// simultaneity window `window` (for tests of the queue order).
    #[cfg(test)]
    pub(crate) fn between(ball: u32, other: u32, time: T, window: T) -> Self {
        Self {
            instant: (time / window).floor().to_f64() as u64,
            height: T::zero(),
            time,
            ball,
            target: Target::Ball(other),
            versions: [0, 0],
            normal: Vector::zeros(),
            shift: Vector::zeros(),
        }
    }
}

/// A min-queue entry.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pending<T: Real, const D: usize>(pub(crate) Event<T, D>);

impl<T: Real, const D: usize> PartialEq for Pending<T, D> {
    fn eq(&self, other: &Self) -> bool {
        self.0.key_cmp(&other.0) == Ordering::Equal
    }
}
impl<T: Real, const D: usize> Eq for Pending<T, D> {}
impl<T: Real, const D: usize> PartialOrd for Pending<T, D> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl<T: Real, const D: usize> Ord for Pending<T, D> {
    /// Reversed: `BinaryHeap` is a max-heap, the earliest event must come first.
    fn cmp(&self, other: &Self) -> Ordering {
        other.0.key_cmp(&self.0)
    }
}

/// The gap within which a ball of radius `r` at `x` touches a surface or a ball: a
/// billionth of its radius plus the rounding of its coordinates.
pub(crate) fn touch_tolerance<T: Real, const D: usize>(x: &Vector<T, D>, r: T) -> T {
    T::lit(1e-9) * r + T::lit(16.0) * T::EPSILON * (x.amax() + r)
}

/// A gap between bodies closing at up to `speed` (the sum of their speeds) as a wedge's
/// hold takes it (`stack`; `h` the step's length, zero in another hold): none within
/// what they close in one unit of the last place of an in-step time, `ε h speed`, and
/// none below zero (an overlap is held as touching unless [`sunk`]).
///
/// A time of impact is an in-step time `s + t`, rounded to the last place of `s`; a `t`
/// below that is lost and the contact is found at `s`, up to `ε h speed` apart. In `f64`
/// that is nothing (2e-12 m at 1e6 m/s with `h = 0.01`). In `f32` the last place is
/// 1.2e-9 s for that step: two bodies at 3e4 m/s each are found in contact up to 7e-5 m
/// apart, far beyond [`touch_tolerance`]. A 1 µg ball between two balls converging on
/// it at 3e4 m/s, found in contact with each in turn at one `f32` instant 4.7e-6 and
/// 6.7e-6 m from them, was held against one at a time and sent into the other, 16,384
/// times: a false crush error (a fuzzed scene). Taking both gaps for none, the hold
/// holds both contacts at once.
///
/// Other holds leave such a gap to the narrow phase, which finds it as a contact if it
/// closes: counted as touching there too, the balls of a clump moving together at 7e4
/// m/s in `f32` were held as one stack and sank 7e-3 m into each other (a fuzzed scene).
pub(crate) fn time_resolved_gap<T: Real>(gap: T, h: T, speed: T) -> T {
    if gap <= T::EPSILON * h * speed {
        T::zero()
    } else {
        gap
    }
}

/// How deep two balls (centre and radius) overlap beyond what the floor lets a contact
/// sink ([`Allowance::sunk_depth`]), or `None` if no deeper: only rounding is allowed
/// the approach of such a pair (see [`Allowance`]), and holds aim it apart.
pub(crate) fn sunk<T: Real, const D: usize>(
    allowance: &Allowance<T, D>,
    a: (&Vector<T, D>, T),
    b: (&Vector<T, D>, T),
) -> Option<T>
where
    Const<D>: Space<T, D>,
{
    let depth = a.1 + b.1 - (b.0 - a.0).norm();
    (depth > allowance.sunk_depth(a.0, a.1, b.0, b.1)).then_some(depth)
}

/// The speed at which the holds aim two [`sunk`] balls (centre and radius) apart: their
/// depth over the rest of the step `rest`; zero for a pair not sunk, or no time left.
pub(crate) fn apart_speed<T: Real, const D: usize>(
    allowance: &Allowance<T, D>,
    a: (&Vector<T, D>, T),
    b: (&Vector<T, D>, T),
    rest: T,
) -> T
where
    Const<D>: Space<T, D>,
{
    match sunk(allowance, a, b) {
        Some(depth) if rest > T::zero() => depth / rest,
        _ => T::zero(),
    }
}

/// Why a prediction could not be made: a time of impact overflowed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Overflow {
    /// The ball.
    pub(crate) ball: u32,
}

/// How fast a contact may approach and still be no contact worth acting on: the
/// rounding of the approach speed, or the resting floor. The narrow phase takes no
/// slower contact for an event, and a hold (`stack`) stops every contact it holds to a
/// quarter of this, so that what a hold leaves is never found again as a contact at the
/// same instant.
///
/// The rounding counted is `64 ε` of the speeds a response computes the approach
/// from: both bodies' whole speeds for a ball or a box (the normal is any direction),
/// none for a wall of the border (its normal is an axis, and the approach is a
/// component of the chord, read exactly; a hold sets a free ball's chord it leaves
/// closing on a wall by rounding exactly on it, `stack`): a ball bouncing between floor and ceiling at
/// 6e4 m/s in `f32` (where `64 ε` of that is 0.46 m/s) was let through a side wall it
/// approached at 0.04 m/s, and ended 0.95 m outside the box.
///
/// For two balls, rounding also turns the normal: taken between two centres known to
/// the coordinates' resolution `ρ`, a distance `d` apart (the sum of the radii at a
/// contact), its direction is known to about `ρ / d`, and the relative velocity's part
/// across it, `w`, shows in the approach by up to `|w| ρ / d`. Without that term a pair
/// sliding past each other fast far from the origin (two 1,000 kg balls at 1e5 m/s
/// squeezing a 1 g ball 1,000 m out) was left by the wedge's hold approaching at 3e-11
/// m/s along the hold's normal and found approaching at 5.6e-8 m/s along the time of
/// impact's, a contact again at the same instant, until the run ended with a false
/// crush error. A box's normal at a face counts no such term: the hold and the time of
/// impact both take it in the box's frame (`BoxArrays::nearest`), where it is the face's
/// axis exactly. Counting `ρ / r` for boxes instead (tried) let `f32` balls into boxes
/// 1,000 m out by up to 24 times the coordinates' resolution, where `ρ / r` is 1e-2. At
/// an edge or a corner the two still take the direction between two points known to
/// `ρ`; no fuzzed scene has met that.
///
/// A member of a stuck cluster has a chord computed from its rigid places at the
/// segment's two ends, `(x₁ − x₀)/τ`, each known to `ρ`: its chord is known to `2ρ/τ`,
/// which counts for it against a wall too. A cluster held against the floor in a scene
/// without gravity (no resting floor) was left closing on it at 4.4e-12 m/s, 145 units
/// of its coordinates' last place over the rest of the step, and found again 16,384
/// times: a false crush error. That is an allowance for one step, not for good: a
/// member sunk into a wall, a box or a ball deeper than the floor lets a contact sink is
/// allowed only the rounding of the velocities ([`Allowance::rounding`]), not its
/// chord's. A stuck pair sliding along a wall in `f32`, turning one member into it at
/// 6.9e-4 m/s, under the 7.6e-4 m/s of `2ρ/τ` there, sank 7.4e-4 m into it in 2 s (a
/// fuzzed scene's pair did the same in a corner); now the wall takes it at the sunk depth
/// plus a step's closing, 1.5e-5 m. A hold aims such a member out by more than its
/// chord's rounding: its depth over the rest of the step, where the depth is beyond the
/// touch tolerance, `16 ε` of its coordinates, and the chord's rounding is `2ρ = 16 ε` of
/// them over the same time.
///
/// The resting floor holds a wall's contact only as far as gravity presses a ball into
/// it, `|n·ĝ|` of it: a ball sliding down a side wall drifting out at 9.1e-8 m/s, below
/// the floor (9.8e-8 m/s at `h = 0.01`), was never stopped and ended 1.1e-7 m outside
/// the border in 2 s (a fuzzed scene). Between balls and against boxes the whole floor
/// holds, as for balls resting side by side on a floor, except for two balls that
/// overlap deeper than a contact closing at the floor sinks in a step, plus the
/// contacts' rounding ([`sunk`], [`Allowance::sunk_depth`]): only rounding is allowed
/// them. The floor let such a pair close for good: two balls rolling side by side on a
/// floor, the one behind faster by 6.7e-8 m/s, sank into each other at that speed (9.6e-8
/// m in 2 s; a fuzzed scene); now they meet at that depth, 2.1e-9 m at `h = 0.01`. A
/// hold leaves a contact closing at up to a quarter of the floor (the rounding of its
/// impulses), which the narrow phase would find again at the same instant, so the holds
/// aim such a pair apart at its depth over the rest of the step (`stack`, and
/// `Contacts::rest_on` for a ball held on one below it): a 3.4 mg ball struck on the
/// floor by a 0.19 kg ball again and again in one instant at up to 2e4 m/s, 1.5e-8 m
/// inside it after that instant, was left closing at 1.7e-13 m/s by the single-support
/// hold and found again until a false crush error (a fuzzed scene).
///
/// The rounding allowed a sunk pair counts `4 ε` of the two speeds, not `64 ε`
/// ([`SUNK_APPROACH_ROUNDING`]): what a hold or a response leaves of such a pair is
/// aimed apart at its depth over the rest of the step, not at zero approach, so only the
/// rounding of the two velocities themselves is left to allow. With `64 ε` a pair moving
/// fast together, whose allowance grows with its speed and not with its approach, sank
/// on for good: two balls falling side by side at 4.65 m/s in `f32`, closing at 6.9e-5
/// m/s (under the 7.1e-5 m/s of `64 ε`), sank 6.9e-7 m a step, to 5.7e-6 m (a fuzzed
/// scene); now they stop at the sunk depth plus a step's closing, 4.2e-6 m. A ball
/// sunk into a box or a wall is allowed the same (`Narrow::sunk`: deeper than the floor
/// over a step plus the rounding of the ball's and the box's coordinates; a wall's
/// approach counts no speeds, so there only a cluster member's chord was allowed, and
/// is no longer): a ball riding a kinematic box at 1e6 m/s in `f64`, closing on its
/// face at `32 ε` of the two speeds, sank 1.3e-8 m into it in 0.9 s, and on for good. A
/// hold aims a ball sunk into a box or a wall out of it over the rest of the step
/// (`stack::held_surface_gap`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Allowance<T: Real, const D: usize> {
    /// Contacts approaching slower than this are not events: the part of the floor
    /// gravity sets (`Rules::contact_floor`).
    pub(crate) resting_floor: T,
    /// The unit direction of gravity (zero without it).
    pub(crate) down: Vector<T, D>,
    /// The step's length, where every segment ends.
    pub(crate) step: T,
}

impl<T: Real, const D: usize> Allowance<T, D>
where
    Const<D>: Space<T, D>,
{
    /// The allowance of ball `ball` moving at `u` against `target` moving at
    /// `other_velocity`, along `normal`: the rounding of its approach
    /// ([`Self::rounding`]) or the resting floor, whichever is greater.
    pub(crate) fn of(
        &self,
        balls: &BallArrays<T, D>,
        ball: usize,
        target: Target,
        u: &Vector<T, D>,
        other_velocity: &Vector<T, D>,
        normal: &Vector<T, D>,
    ) -> T {
        let floor = match target {
            Target::Border => self.resting_floor * normal.dot(&self.down).abs(),
            Target::Ball(_) | Target::Box(_) => self.resting_floor,
        };
        let rounding = Self::rounding(balls, ball, target, u, other_velocity, APPROACH_ROUNDING);
        (rounding + self.member_chords(balls, ball, target)).max(floor)
    }

    /// The rounding of the velocities the approach of ball `ball` moving at `u` against
    /// `target` moving at `other_velocity` is computed from: `units` units of `ε` of the
    /// two speeds (none for a wall) and, for two balls, the turn of the normal between
    /// their centres (see the type's documentation). A [`Narrow::sunk`] contact is
    /// allowed this alone, at [`SUNK_APPROACH_ROUNDING`]; [`Self::of`] adds the
    /// rounding of cluster members' chords ([`Self::member_chords`]).
    pub(crate) fn rounding(
        balls: &BallArrays<T, D>,
        ball: usize,
        target: Target,
        u: &Vector<T, D>,
        other_velocity: &Vector<T, D>,
        units: f64,
    ) -> T {
        let speeds = T::lit(units) * T::EPSILON * (speed(u) + speed(other_velocity));
        match target {
            Target::Ball(j) => {
                let j = j as usize;
                // The normal's direction, known to `ρ / d` (see the type's documentation).
                let angle = coordinate_resolution(balls.seg_x[ball].amax())
                    / (balls.radius[ball] + balls.radius[j]);
                speeds + speed(&(u - other_velocity)) * angle
            }
            Target::Box(_) => speeds,
            Target::Border => T::zero(),
        }
    }

    /// How well the chords of the contact's cluster members are known ([`Self::member_chord`]
    /// of ball `ball` and, for two balls, of the other).
    fn member_chords(&self, balls: &BallArrays<T, D>, ball: usize, target: Target) -> T {
        match target {
            Target::Ball(j) => {
                self.member_chord(balls, ball) + self.member_chord(balls, j as usize)
            }
            Target::Box(_) | Target::Border => self.member_chord(balls, ball),
        }
    }

    /// How deep two balls may overlap and still have the floor hold their contact: the
    /// depth a contact closing at the floor reaches over a step, plus what the
    /// contacts' rounding leaves (`touch_tolerance` of each ball at `x` and `y`).
    pub(crate) fn sunk_depth(&self, x: &Vector<T, D>, r: T, y: &Vector<T, D>, q: T) -> T {
        self.resting_floor * self.step + touch_tolerance(x, r) + touch_tolerance(y, q)
    }

    /// How well ball `k`'s chord is known if it is a member of a stuck cluster: `2ρ/τ`
    /// (see the type's documentation); zero for a free ball.
    fn member_chord(&self, balls: &BallArrays<T, D>, k: usize) -> T {
        let span = self.step - balls.seg_t[k];
        if balls.cluster[k] == FREE || span <= T::zero() {
            return T::zero();
        }
        let magnitude = balls.seg_x[k].amax().max(balls.pos[k].amax());
        T::lit(2.0) * coordinate_resolution(magnitude) / span
    }
}

/// What predictions read: the balls, the obstacles, the window end and the thresholds.
pub(crate) struct Narrow<'a, T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    pub(crate) balls: &'a BallArrays<T, D>,
    pub(crate) boxes: &'a BoxArrays<T, D>,
    /// The reflecting border, if any.
    pub(crate) border: Option<&'a Border<T, D>>,
    /// The periodic domain, if any.
    pub(crate) periodic: Option<&'a Border<T, D>>,
    /// The end of the current window (in-step time).
    pub(crate) end: T,
    /// How fast a contact may approach and be no event.
    pub(crate) allowance: Allowance<T, D>,
    /// Gravity (for the bottom-up order of simultaneous contacts).
    pub(crate) gravity: Vector<T, D>,
    /// The simultaneity window (in-step time).
    pub(crate) instant: T,
}

type Prediction<T, const D: usize> = Result<Option<Event<T, D>>, Overflow>;

impl<T: Real, const D: usize> Narrow<'_, T, D>
where
    Const<D>: Space<T, D>,
{
    fn window(&self, s: T) -> Window<T> {
        Window::forward((self.end - s).max(T::zero())).unwrap_or_else(|_| {
            Window::forward(T::zero()).unwrap_or(Window::unbounded(carom_toi::Direction::Forward))
        })
    }

    fn kinematics(&self, i: usize) -> Kinematics<T, D> {
        Kinematics::new_unchecked(self.balls.chord[i], Vector::zeros())
    }

    /// Whether a ball moving at `u` against `target`, moving at `other_velocity`, along
    /// `normal` (into it) at in-step time `s` is no contact worth acting on: approaching
    /// no faster than its [`Allowance::of`], unless it is [`Self::sunk`] (touching,
    /// with `status`) and approaching faster than the rounding alone
    /// ([`Allowance::rounding`]).
    #[allow(clippy::too_many_arguments)]
    fn no_contact(
        &self,
        status: Status,
        ball: usize,
        target: Target,
        (u, other_velocity): (&Vector<T, D>, &Vector<T, D>),
        normal: &Vector<T, D>,
        s: T,
        shift: &Vector<T, D>,
    ) -> bool {
        let approach = (u - other_velocity).dot(normal);
        let allowance = &self.allowance;
        let units = SUNK_APPROACH_ROUNDING;
        // Within the floor: no contact, but for a pair sunk deeper than it lets a contact
        // sink, which is allowed only rounding (checked last: rarely needed).
        approach <= allowance.of(self.balls, ball, target, u, other_velocity, normal)
            && !(status == Status::AlreadyTouching
                && approach
                    > Allowance::rounding(self.balls, ball, target, u, other_velocity, units)
                && self.sunk(ball, target, s, shift, normal))
    }

    /// Whether ball `i` is sunk into `target` (its image shifted by `shift`) at `s`:
    /// deeper than the floor lets a contact sink in a step, plus the rounding of both
    /// bodies' coordinates ([`sunk`] for a ball; for a box, the box taken as a point at
    /// its centre in [`Allowance::sunk_depth`]; for the wall `normal` points into, the
    /// wall's rounding taken where the ball is, as a hold takes it).
    fn sunk(
        &self,
        i: usize,
        target: Target,
        s: T,
        shift: &Vector<T, D>,
        normal: &Vector<T, D>,
    ) -> bool {
        let b = self.balls;
        let (x, r) = (b.position_at(i, s), b.radius[i]);
        match target {
            Target::Ball(j) => {
                let (y, q) = (b.position_at(j as usize, s) + shift, b.radius[j as usize]);
                sunk(&self.allowance, (&x, r), (&y, q)).is_some()
            }
            Target::Box(k) => {
                let obb = self.boxes.at(k as usize, s).translated(shift);
                let depth = -signed_distance(&Ball::new_unchecked(x, r), &obb);
                depth > (self.allowance).sunk_depth(&x, r, &obb.center(), T::zero())
            }
            Target::Border => self.border.is_some_and(|border| {
                // The wall the normal points into (an axis, outwards).
                let gaps = border.wall_gaps(&Ball::new_unchecked(x, r));
                let depth = (0..D).fold(T::zero(), |depth, k| {
                    let (below, above) = gaps[k];
                    match normal[k].partial_cmp(&T::zero()) {
                        Some(Ordering::Greater) => depth.max(-above),
                        Some(Ordering::Less) => depth.max(-below),
                        _ => depth,
                    }
                });
                depth > (self.allowance).sunk_depth(&x, r, &x, T::zero())
            }),
        }
    }

    /// Turns a time of impact into an event, or `None` if it is no contact worth acting
    /// on: approaching no faster than the contact's [`Allowance`], or, for a ball
    /// overlapping another ball or a box deeper than the floor lets it sink
    /// ([`Self::sunk`]), than its rounding.
    #[allow(clippy::too_many_arguments)]
    fn event<F>(
        &self,
        toi: &Toi<T, D, F>,
        s: T,
        ball: usize,
        target: Target,
        other_velocity: &Vector<T, D>,
        versions: [u32; 2],
        shift: Vector<T, D>,
    ) -> Prediction<T, D> {
        if s >= self.end {
            // Predicted at the window's end: no time is left to act in, and a resting
            // contact there could only be found again unchanged (a member of a cluster
            // held by a speculative contact reaches the surface exactly at the step's
            // end), to the event budget. The next window or step starts with it.
            return Ok(None);
        }
        match toi.status {
            Status::Hit | Status::AlreadyTouching => {}
            Status::NoHit => return Ok(None),
            Status::NotConverged => return Err(Overflow { ball: ball as u32 }),
        }
        let u = &self.balls.chord[ball];
        let motion = (u, other_velocity);
        if self.no_contact(toi.status, ball, target, motion, &toi.normal, s, &shift) {
            return Ok(None);
        }
        let time = (s + toi.time).min(self.end);
        let x = self.balls.position_at(ball, time);
        let height = match target {
            Target::Ball(j) => {
                let y = self.balls.position_at(j as usize, time) + shift;
                -self.gravity.dot(&x).max(self.gravity.dot(&y))
            }
            // The ball's lowest point: a ball's support below it (a floor, a box) comes
            // before the balls resting on it at the same centre height (a cluster resting
            // on a row of balls finds all of them held).
            Target::Border | Target::Box(_) => {
                -self.gravity.dot(&x) - self.gravity.norm() * self.balls.radius[ball]
            }
        };
        Ok(Some(Event {
            instant: (time / self.instant).floor().to_f64() as u64,
            height,
            time,
            ball: ball as u32,
            target,
            versions,
            normal: toi.normal,
            shift,
        }))
    }

    /// The first contact of balls `i < j` after `s`.
    pub(crate) fn ball_ball(&self, i: usize, j: usize, s: T) -> Prediction<T, D> {
        let b = self.balls;
        if b.cluster[i] != FREE && b.cluster[i] == b.cluster[j] {
            // Members of one rigid cluster never collide with each other.
            return Ok(None);
        }
        let (pi, pj) = (b.position_at(i, s), b.position_at(j, s));
        let shift = match self.periodic {
            Some(p) => (pi + p.minimum_image(&(pj - pi))) - pj,
            None => Vector::zeros(),
        };
        let toi = ball_ball(
            &Ball::new_unchecked(pi, b.radius[i]),
            &self.kinematics(i),
            &Ball::new_unchecked(pj + shift, b.radius[j]),
            &self.kinematics(j),
            &self.window(s),
        );
        self.event(
            &toi,
            s,
            i,
            Target::Ball(j as u32),
            &b.chord[j],
            [b.version[i], b.version[j]],
            shift,
        )
    }

    /// Appends to `found` the contacts of ball `i` after `s` within the window: the
    /// balls and boxes of `sweep`'s candidates for its remaining path (skipping balls in
    /// `skip`, already predicted against `i`), every box in a periodic domain, and the
    /// walls. `candidates` is scratch.
    ///
    /// # Errors
    /// The first overflowing prediction (the others are still appended).
    pub(crate) fn ball_events(
        &self,
        sweep: &Sweep<T, D>,
        i: usize,
        s: T,
        skip: &[u32],
        candidates: &mut Vec<u32>,
        found: &mut Vec<Event<T, D>>,
    ) -> Result<(), Overflow> {
        let n = self.balls.len();
        let x = self.balls.position_at(i, s);
        let path = path_box(&x, &self.balls.pos[i], self.balls.radius[i]);
        sweep.candidates(i, &path, candidates);
        candidates.sort_unstable();
        candidates.dedup();
        let mut result = Ok(());
        let mut push = |p: Prediction<T, D>| match p {
            Ok(Some(e)) => found.push(e),
            Ok(None) => {}
            Err(e) => result = result.and(Err(e)),
        };
        for &c in candidates.iter() {
            let c = c as usize;
            if c < n {
                if c != i && !skip.contains(&(c as u32)) {
                    push(self.ball_ball(i.min(c), i.max(c), s));
                }
            } else if sweep.boxes_inside() {
                push(self.ball_box(i, c - n, s));
            }
        }
        if self.periodic.is_some() {
            for k in 0..self.boxes.len() {
                push(self.ball_box(i, k, s));
            }
        }
        push(self.ball_border(i, s));
        result
    }

    /// The first wall of the reflecting border ball `i` touches after `s`.
    pub(crate) fn ball_border(&self, i: usize, s: T) -> Prediction<T, D> {
        let Some(border) = self.border else {
            return Ok(None);
        };
        let b = self.balls;
        let x = b.position_at(i, s);
        let r = b.radius[i];
        let y = x + b.chord[i] * (self.end - s);
        // Clear of every wall by more than rounding along the whole segment: no contact.
        let margin = r + T::lit(8.0) * T::EPSILON * (x.amax() + y.amax() + r);
        let (lo, hi) = (border.min(), border.max());
        if (0..D).all(|k| lo[k] + margin < x[k].min(y[k]) && x[k].max(y[k]) + margin < hi[k]) {
            return Ok(None);
        }
        let ball = Ball::new_unchecked(x, r);
        let window = self.window(s);
        // A wall the ball does not approach (it slides along it, touching it or within
        // rounding of it, pressed in by rounding or by less than the resting floor) is no
        // contact, but `ball_border` reports it before any other, as touched now or hit
        // after the time the rounding takes to close the gap: the walls are asked again
        // without the chord's component along it, which changes no other wall's time
        // (the walls are axis-aligned). Otherwise a ball sliding along one wall passes
        // through the next: a ball 1e-12 m off a wall, pressed into it at 1e-8 m/s while
        // falling at 3 m/s, ended the step 2.1 cm through the floor.
        let mut u = b.chord[i];
        let mut asked = 0;
        let toi = loop {
            let toi = ball_border(
                &ball,
                &Kinematics::new_unchecked(u, Vector::zeros()),
                border,
                &window,
            );
            asked += 1;
            let sliding = matches!(toi.status, Status::AlreadyTouching | Status::Hit)
                && self.no_contact(
                    toi.status,
                    i,
                    Target::Border,
                    (&u, &Vector::zeros()),
                    &toi.normal,
                    s,
                    &Vector::zeros(),
                );
            if !sliding || asked == D {
                break toi;
            }
            u -= toi.normal * u.dot(&toi.normal);
        };
        self.event(
            &toi,
            s,
            i,
            Target::Border,
            &Vector::zeros(),
            [b.version[i], 0],
            Vector::zeros(),
        )
    }

    /// The first contact of ball `i` with box `k` (or, in a periodic domain, any of its
    /// images) after `s`.
    pub(crate) fn ball_box(&self, i: usize, k: usize, s: T) -> Prediction<T, D> {
        let b = self.balls;
        let x = b.position_at(i, s);
        let r = b.radius[i];
        let ball = Ball::new_unchecked(x, r);
        let path = path_box(&x, &(x + b.chord[i] * (self.end - s)), r);
        let obb = self.boxes.at(k, s);
        let box_motion = Kinematics::new_unchecked(self.boxes.vel[k], Vector::zeros());
        let swept = self.boxes.swept(k, s, self.end);
        let window = self.window(s);
        let mut best: Prediction<T, D> = Ok(None);
        let mut try_image = |shift: Vector<T, D>| {
            if !overlap(&swept.translated(&shift), &path) {
                return;
            }
            let toi = ball_obb(
                &ball,
                &self.kinematics(i),
                &obb.translated(&shift),
                &box_motion,
                &window,
            );
            let found = self.event(
                &toi,
                s,
                i,
                Target::Box(k as u32),
                &self.boxes.vel[k],
                [b.version[i], 0],
                shift,
            );
            best = match (best, found) {
                (Err(e), _) | (_, Err(e)) => Err(e),
                (Ok(Some(a)), Ok(Some(c))) => Ok(Some(if c.time < a.time { c } else { a })),
                (Ok(a), Ok(c)) => Ok(a.or(c)),
            };
        };
        match self.periodic {
            None => try_image(Vector::zeros()),
            Some(border) => image_offsets(border).for_each(try_image),
        }
        best
    }
}
