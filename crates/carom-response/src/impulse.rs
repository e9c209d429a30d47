//! The contact impulse between two rigid bodies: restitution along the normal, Coulomb
//! friction in the tangent plane. One mechanism for balls, clusters, walls and paddles.
//!
//! # Derivation
//!
//! An impulse `P` at the contact point acts on `b` and `−P` on `a`. It changes
//! `v_b += P/m_b`, `ω_b += I_b⁻¹ (r_b × P)` (and the opposite for `a`), so the relative
//! velocity of the touching points, `v_rel = (v_b + ω_b × r_b) − (v_a + ω_a × r_a)`,
//! changes linearly: `Δv_rel = K P` with the effective inverse-mass matrix
//!
//! ```text
//! K x = (1/m_a + 1/m_b) x + Σ_{i=a,b} (I_i⁻¹ (r_i × x)) × r_i
//!     = [(1/m_a + 1/m_b) 𝟙 − [r_a]ₓ I_a⁻¹ [r_a]ₓ − [r_b]ₓ I_b⁻¹ [r_b]ₓ] x.
//! ```
//!
//! `K` is symmetric positive semi-definite (positive definite if either body is
//! dynamic). In 2D the angular terms are scalars: `(r × x) I⁻¹` is a z spin and
//! `ω × r = ω (−r_y, r_x)`.
//!
//! **Normal impulse (Newton's restitution).** With `v_n = v_rel · n < 0` (approaching),
//! the normal impulse `j_n n` that makes the normal relative velocity `−e v_n` solves
//! `v_n + j_n (n·K n) = −e v_n`:
//!
//! ```text
//! j_n = −(1 + e) v_n / (n·K n),    n·K n = 1/m_a + 1/m_b + Σ (r_i × n)·I_i⁻¹ (r_i × n).
//! ```
//!
//! For two balls `r_i × n = 0` and this is the textbook (and Collision Lab's) result
//! `v'_1n = ((m_1 − e m_2) v_1n + (1 + e) m_2 v_2n) / (m_1 + m_2)`, tangential components
//! unchanged.
//!
//! **Energy.** For any impulse, the work it does on the pair (the change of kinetic
//! energy measured in any frame where neither body is kinematic) is
//! `ΔE = P·v_rel + ½ P·K P = ½ P·(v_rel + v'_rel)`. For the normal impulse,
//! `ΔE = j_n v_n (1 − e)/2 ≤ 0`, zero exactly when `e = 1`.
//!
//! **Friction (Coulomb's cone on impulses).** After the normal impulse the tangential
//! relative velocity is `v_t = v' − (v'·n) n`. The tangential impulse that stops the
//! sliding ("sticking", the contact rolls off) solves `K_tt F* = −v_t` in the tangent
//! plane, `K_tt = (𝟙 − n nᵀ) K (𝟙 − n nᵀ)` (a 1×1 problem in 2D, 2×2 in 3D; solved by
//! `D − 1` steps of conjugate gradients, which are exact for a `D − 1` dimensional
//! symmetric positive definite system). If `|F*| ≤ μ j_n` the contact sticks and
//! `F = F*`; otherwise it slides and `F = F* μ j_n / |F*|`, the largest impulse the
//! cone allows. With `F = s F*`, `s ∈ [0, 1]`, the friction work is
//! `ΔE = −(s − s²/2) v_t·K_tt⁻¹ v_t ≤ 0`: friction never adds energy.
//!
//! For balls `K_tt` is isotropic (`(1/m_a + 1/m_b + ρ_a²/I_a + ρ_b²/I_b) (𝟙 − n nᵀ)`), so
//! `F*` is exactly opposite to the sliding velocity, as Coulomb's law asks. For clusters
//! `K_tt` may be anisotropic and `K` may couple normal and tangential directions: the
//! sliding impulse then points along the sticking impulse (not exactly against the
//! sliding velocity), and the friction impulse may change the normal velocity slightly.
//! This is the simplest model that never adds energy; it does not follow the slip
//! direction during the impact (Stronge's impulse-space integration) and has no
//! tangential restitution (a superball's spin reversal).
//!
//! **Reversibility.** With `e = 1` and `μ = 0` the map is an involution up to
//! reversing velocities: the reversed pair approaches with the same `v_n` and receives the
//! same `j_n`, which undoes the collision. In floating point the second impulse is
//! recomputed from rounded velocities, so reversal holds to a few ulps of the velocities
//! involved, not bit for bit (see the `time_reversal` tests). With `e < 1` or friction the
//! map loses energy and has no inverse.
//!
//! # What is never done
//!
//! No impulse is applied to a receding pair (`v_n > 0`: [`Outcome::Receding`]), to a pair
//! touching with no normal approach (`v_n = 0`: [`Outcome::Touching`]), or between two
//! immovable bodies (`n·K n = 0`: [`Outcome::Immovable`]). The result is finite for
//! every valid input whose impulses (momenta `m v`) are representable.

use carom_math::{Real, Space, Vector};
use nalgebra::Const;

use crate::{Angular, Body, Coefficients, Contact};

/// What the friction did in a collision.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Friction {
    /// No friction (`μ = 0`) or no tangential relative velocity to resist.
    None,
    /// The contact stuck: the tangential relative velocity is zero afterwards.
    Sticking,
    /// The contact slid: the tangential impulse is `μ` times the normal impulse.
    Sliding,
}

/// Whether and how a collision applied an impulse.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The pair was approaching: an impulse was applied.
    Applied(Friction),
    /// The pair was separating (`v_rel · n > 0`): nothing applied.
    Receding,
    /// The pair was touching with zero normal relative velocity: nothing applied.
    Touching,
    /// Both bodies are immovable (static or kinematic): no impulse can act.
    Immovable,
}

/// What a collision did: impulses, new velocities, energy.
///
/// The velocities are those to give the bodies (`Body::with_velocities`); an immovable
/// body keeps its own. The impulse acts on `b` at the contact point, `−impulse` on `a`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// Whether an impulse was applied and what friction did.
    pub outcome: Outcome,
    /// The normal relative velocity before, `v_rel · n` (negative when approaching).
    pub normal_velocity: T,
    /// The normal impulse `j_n ≥ 0` (along `n`, on `b`).
    pub normal_impulse: T,
    /// The friction impulse (in the tangent plane, on `b`).
    pub tangential_impulse: Vector<T, D>,
    /// The total impulse on `b`: `j_n n + tangential_impulse`.
    pub impulse: Vector<T, D>,
    /// The angular impulse about each body's centre of mass: `r_a × (−P)`, `r_b × P`.
    pub angular_impulse: [Angular<T, D>; 2],
    /// The velocities of `a` and `b` afterwards.
    pub velocity: [Vector<T, D>; 2],
    /// The angular velocities of `a` and `b` afterwards.
    pub angular_velocity: [Angular<T, D>; 2],
    /// The change of kinetic energy of the dynamic bodies of the pair (translation and
    /// rotation). Never positive unless a kinematic body does work on the other.
    pub kinetic_energy_change: T,
    /// The work of the impulse in the contact frame, `½ P·(v_rel + v'_rel)`: never
    /// positive (up to rounding), equal to `kinetic_energy_change` when neither body is
    /// kinematic, and the energy the collision dissipates in any case.
    pub contact_energy_change: T,
}

impl<T: Real, const D: usize> Response<T, D>
where
    Const<D>: Space<T, D>,
{
    /// `true` if an impulse was applied.
    #[inline]
    pub fn applied(&self) -> bool {
        matches!(self.outcome, Outcome::Applied(_))
    }

    /// Body `a` moving as it does after the collision.
    #[inline]
    pub fn body_a(&self, a: &Body<T, D>) -> Body<T, D> {
        a.with_velocities(self.velocity[0], self.angular_velocity[0])
    }

    /// Body `b` moving as it does after the collision.
    #[inline]
    pub fn body_b(&self, b: &Body<T, D>) -> Body<T, D> {
        b.with_velocities(self.velocity[1], self.angular_velocity[1])
    }

    fn without_impulse(
        a: &Body<T, D>,
        b: &Body<T, D>,
        outcome: Outcome,
        normal_velocity: T,
    ) -> Self {
        let zero = <Const<D> as Space<T, D>>::angular_zero();
        Self {
            outcome,
            normal_velocity,
            normal_impulse: T::zero(),
            tangential_impulse: Vector::zeros(),
            impulse: Vector::zeros(),
            angular_impulse: [zero, zero],
            velocity: [a.velocity(), b.velocity()],
            angular_velocity: [a.angular_velocity(), b.angular_velocity()],
            kinetic_energy_change: T::zero(),
            contact_energy_change: T::zero(),
        }
    }
}

/// The pair and contact as the impulse computation sees them.
struct Pair<'a, T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    a: &'a Body<T, D>,
    b: &'a Body<T, D>,
    n: Vector<T, D>,
    r_a: Vector<T, D>,
    r_b: Vector<T, D>,
}

impl<'a, T: Real, const D: usize> Pair<'a, T, D>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn new(a: &'a Body<T, D>, b: &'a Body<T, D>, contact: &Contact<T, D>) -> Self {
        Self {
            a,
            b,
            n: contact.normal(),
            r_a: contact.offset_a(),
            r_b: contact.offset_b(),
        }
    }

    /// `v_rel = (v_b + ω_b × r_b) − (v_a + ω_a × r_a)`.
    #[inline]
    fn relative_velocity(&self) -> Vector<T, D> {
        self.b.point_velocity(&self.r_b) - self.a.point_velocity(&self.r_a)
    }

    /// `K x`: the change of the relative contact velocity under the impulse `x` on `b`.
    #[inline]
    fn apply_k(&self, x: &Vector<T, D>) -> Vector<T, D> {
        let turn = |body: &Body<T, D>, r: &Vector<T, D>| {
            let spin = <Const<D> as Space<T, D>>::inertia_apply(
                &body.inverse_inertia(),
                &<Const<D> as Space<T, D>>::cross(r, x),
            );
            <Const<D> as Space<T, D>>::angular_cross(&spin, r)
        };
        x * (self.a.inverse_mass() + self.b.inverse_mass())
            + turn(self.a, &self.r_a)
            + turn(self.b, &self.r_b)
    }

    /// For each body, the spin `I⁻¹ (r × n)` a unit normal impulse gives it (on `b`; `a`
    /// gets the opposite), and `n·K n = 1/m_a + 1/m_b + Σ (r × n)·I⁻¹ (r × n)`, written as
    /// a sum of non-negative terms so that rounding cannot make it negative for isotropic
    /// inertias. The spins are reused to apply the normal impulse.
    #[inline]
    fn normal_response(&self) -> ([Angular<T, D>; 2], T) {
        let n = &self.n;
        let lever = |body: &Body<T, D>, r: &Vector<T, D>| {
            let torque = <Const<D> as Space<T, D>>::cross(r, n);
            let spin = <Const<D> as Space<T, D>>::inertia_apply(&body.inverse_inertia(), &torque);
            (spin, <Const<D> as Space<T, D>>::angular_dot(&torque, &spin))
        };
        let (spin_a, term_a) = lever(self.a, &self.r_a);
        let (spin_b, term_b) = lever(self.b, &self.r_b);
        (
            [spin_a, spin_b],
            self.a.inverse_mass() + self.b.inverse_mass() + term_a + term_b,
        )
    }

    /// The tangential impulse `F*` that stops the tangential relative velocity `v_t`:
    /// the solution of `K_tt F* = −v_t` in the plane orthogonal to `n`, by `D − 1`
    /// conjugate-gradient steps (exact in exact arithmetic for the `D − 1` dimensional
    /// symmetric positive definite `K_tt`).
    fn sticking_impulse(&self, v_t: &Vector<T, D>) -> Vector<T, D> {
        let n = &self.n;
        let tangential = |x: Vector<T, D>| x - n * n.dot(&x);
        let mut x = Vector::<T, D>::zeros();
        let mut residual = -v_t;
        let mut direction = residual;
        let mut rr = residual.norm_squared();
        // Converged when the residual is at rounding level of the right-hand side: for
        // balls (isotropic K_tt) the first step is already exact.
        let converged = rr * T::EPSILON * T::EPSILON;
        for _ in 1..D {
            if rr <= converged {
                break;
            }
            let k_direction = tangential(self.apply_k(&direction));
            let curvature = direction.dot(&k_direction);
            if curvature <= T::zero() {
                break;
            }
            let step = rr / curvature;
            x += direction * step;
            residual -= k_direction * step;
            let rr_next = residual.norm_squared();
            direction = residual + direction * (rr_next / rr);
            rr = rr_next;
        }
        tangential(x)
    }
}

/// The collision response of bodies `a` and `b` touching at `contact` (normal from `a`
/// to `b`) with restitution and friction `coefficients`. A pure function: it returns the
/// new velocities and everything the collision did (see the module documentation for
/// the derivation).
///
/// No impulse acts on a receding or merely touching pair or between two immovable
/// bodies ([`Outcome`]). No allocation; no panic on valid input.
pub fn resolve<T: Real, const D: usize>(
    a: &Body<T, D>,
    b: &Body<T, D>,
    contact: &Contact<T, D>,
    coefficients: &Coefficients<T>,
) -> Response<T, D>
where
    Const<D>: Space<T, D>,
{
    let pair = Pair::new(a, b, contact);
    let n = pair.n;
    let v_rel = pair.relative_velocity();
    let v_n = v_rel.dot(&n);
    if v_n > T::zero() {
        return Response::without_impulse(a, b, Outcome::Receding, v_n);
    }
    if v_n == T::zero() {
        return Response::without_impulse(a, b, Outcome::Touching, v_n);
    }
    let (normal_spins, stiffness) = pair.normal_response();
    if stiffness <= T::zero() {
        return Response::without_impulse(a, b, Outcome::Immovable, v_n);
    }

    let j_n = -(T::one() + coefficients.restitution()) * v_n / stiffness;
    let normal_impulse = n * j_n;

    let (tangential_impulse, friction) = if coefficients.friction() > T::zero() {
        let after_normal = v_rel + pair.apply_k(&normal_impulse);
        let v_t = after_normal - n * n.dot(&after_normal);
        let sticking = pair.sticking_impulse(&v_t);
        let magnitude = sticking.norm();
        let limit = coefficients.friction() * j_n;
        if magnitude == T::zero() {
            (Vector::zeros(), Friction::None)
        } else if magnitude <= limit {
            (sticking, Friction::Sticking)
        } else {
            (sticking * (limit / magnitude), Friction::Sliding)
        }
    } else {
        (Vector::zeros(), Friction::None)
    };

    apply(
        &pair,
        v_rel,
        v_n,
        (j_n, normal_spins),
        tangential_impulse,
        friction,
    )
}

/// Applies the normal impulse `j_n n` and the friction impulse (on `b`, the opposite on
/// `a`) and reports what they did. `normal_spins` are the spins of a unit normal impulse.
fn apply<T: Real, const D: usize>(
    pair: &Pair<'_, T, D>,
    v_rel: Vector<T, D>,
    v_n: T,
    (j_n, normal_spins): (T, [Angular<T, D>; 2]),
    tangential_impulse: Vector<T, D>,
    friction: Friction,
) -> Response<T, D>
where
    Const<D>: Space<T, D>,
{
    let half = T::lit(0.5);
    let impulse = pair.n * j_n + tangential_impulse;
    // One body's share: the impulse it receives (sign ±1), its new motion, and the work
    // done on it, ½ P·(v + v') + ½ L·(ω + ω') with L = r × P (exact:
    // ½ m (|v'|² − |v|²) = ½ (m Δv)·(v + v')). The spin change is j_n times the normal
    // spin plus, with friction, I⁻¹ (r × F).
    let kick = |body: &Body<T, D>, r: &Vector<T, D>, sign: T, normal_spin: &Angular<T, D>| {
        let p = impulse * sign;
        let angular = <Const<D> as Space<T, D>>::cross(r, &p);
        let v = body.velocity() + p * body.inverse_mass();
        let mut spin = *normal_spin * (j_n * sign);
        if friction != Friction::None {
            spin += <Const<D> as Space<T, D>>::inertia_apply(
                &body.inverse_inertia(),
                &<Const<D> as Space<T, D>>::cross(r, &(tangential_impulse * sign)),
            );
        }
        let w = body.angular_velocity() + spin;
        let work = if body.is_dynamic() {
            half * (p.dot(&(body.velocity() + v))
                + <Const<D> as Space<T, D>>::angular_dot(&angular, &(body.angular_velocity() + w)))
        } else {
            T::zero()
        };
        (angular, v, w, work)
    };
    let (angular_a, v_a, w_a, work_a) = kick(pair.a, &pair.r_a, -T::one(), &normal_spins[0]);
    let (angular_b, v_b, w_b, work_b) = kick(pair.b, &pair.r_b, T::one(), &normal_spins[1]);

    let after = pair.b.with_velocities(v_b, w_b).point_velocity(&pair.r_b)
        - pair.a.with_velocities(v_a, w_a).point_velocity(&pair.r_a);
    Response {
        outcome: Outcome::Applied(friction),
        normal_velocity: v_n,
        normal_impulse: j_n,
        tangential_impulse,
        impulse,
        angular_impulse: [angular_a, angular_b],
        velocity: [v_a, v_b],
        angular_velocity: [w_a, w_b],
        kinetic_energy_change: work_a + work_b,
        contact_energy_change: half * impulse.dot(&(v_rel + after)),
    }
}

/// Two smooth (frictionless) balls colliding: the impulse along the line of centres, the
/// new velocities `[v_a', v_b']`, or `None` for a receding or merely touching pair.
///
/// `normal` is the unit vector from ball `a`'s centre to ball `b`'s, `inverse_mass_*`
/// are `1/m` (`0` for an immovable ball), `restitution` is `e ∈ [0, 1]`. With the normal
/// relative velocity `v_n = (v_b − v_a)·n < 0` (closing), the impulse on `b` is `J n`
/// with `J = −(1 + e) v_n / (1/m_a + 1/m_b)` (and `−J n` on `a`), so that the normal
/// relative velocity after is `−e v_n`; tangential components are unchanged. This is
/// [`resolve`] for two balls without friction: a central impulse has no moment about
/// either centre and changes no spin, so the angular terms of `resolve`'s effective mass
/// vanish (there they are rounding, `|r × n| ≈ 1e-17 r`) and the few products here give
/// the same velocities to rounding, without `resolve`'s spins and work (the event-driven
/// engine's gas collisions spent 7 % of their instructions in `resolve` and
/// `Contact::between_balls`). `None` too when both balls are immovable.
#[inline]
pub fn central_impulse<T: Real, const D: usize>(
    (inverse_mass_a, velocity_a): (T, &Vector<T, D>),
    (inverse_mass_b, velocity_b): (T, &Vector<T, D>),
    normal: &Vector<T, D>,
    restitution: T,
) -> Option<[Vector<T, D>; 2]> {
    let v_n = (velocity_b - velocity_a).dot(normal);
    let stiffness = inverse_mass_a + inverse_mass_b;
    if v_n >= T::zero() || stiffness <= T::zero() {
        return None;
    }
    let j = -(T::one() + restitution) * v_n / stiffness;
    let impulse = normal * j;
    Some([
        velocity_a - impulse * inverse_mass_a,
        velocity_b + impulse * inverse_mass_b,
    ])
}

/// The normal relative velocity `v_rel · n` of the contact (negative when approaching):
/// what the guards of [`crate::guard`] look at before choosing a restitution.
#[inline]
pub fn normal_velocity<T: Real, const D: usize>(
    a: &Body<T, D>,
    b: &Body<T, D>,
    contact: &Contact<T, D>,
) -> T
where
    Const<D>: Space<T, D>,
{
    (b.point_velocity(&contact.offset_b()) - a.point_velocity(&contact.offset_a()))
        .dot(&contact.normal())
}
