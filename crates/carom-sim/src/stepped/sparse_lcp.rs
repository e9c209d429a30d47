//! Large sparse linear complementarity problems: the normal impulses of a pile's
//! contacts, by projected conjugate gradients.
//!
//! The problem is `lcp`'s (`w = A λ + q >= 0, λ >= 0, λ·w = 0`, `A` the contacts'
//! Delassus matrix), for a stack too large for its dense exact solve: the settled pile
//! of 480 balls (`docs/open-scenes`) is held in one hold of up to 1,025 contacts
//! (`StepStats::largest_hold`), whose dense matrix alone is 8.4 MB and whose
//! factorisations cost `n³`. Here `A` is stored by rows of its non-zero entries (two
//! contacts couple only through a body they share: a ball's half-dozen contacts) and the
//! problem is solved as the convex programme `min ½ λᵀAλ + qᵀλ` over `λ >= 0` by
//! **MPRGP**, Dostál's modified proportioning with reduced gradient projections (Z.
//! Dostál and J. Schöberl, *Minimizing quadratic functions subject to bound constraints
//! with the rate of convergence and finite termination*, Comput. Optim. Appl. 30, 2005):
//!
//! * the gradient `g = A λ + q` (the margins `w`) splits into the **free gradient** `φ`
//!   (`g` on the contacts that push, `λ > 0`) and the **chopped gradient** `β` (`min(g,
//!   0)` on those that do not: contacts closing that should push);
//! * while `β` is small beside `φ` (`|β|² <= Γ² φ·φ̃`, `φ̃` the free gradient cut to
//!   what a step of `ᾱ` can take), **conjugate gradient** steps minimise over the
//!   pushing contacts; a step that would drive an impulse negative instead moves to the
//!   bound and takes a projected gradient step of length `ᾱ` (**expansion**), which
//!   lets several contacts stop pushing at once;
//! * otherwise a step along `β` (**proportioning**) lets closing contacts start to push.
//!
//! Conjugate gradients converge in about `√κ` steps where Gauss–Seidel takes `κ`
//! sweeps (`κ` the condition number: about `k²` for a column of `k` balls), which is
//! what makes a pile's tolerance (a thousandth of the resting floor) reachable in a
//! bounded number of steps. The problem is solved for
//! `μ = D⁻¹ λ` with `D = diag(A)^(−1/2)` (a unit diagonal, as `lcp` does), which makes
//! `ᾱ = 1/‖A‖` with `‖A‖` bounded by its largest absolute row sum (Gershgorin), and
//! starts from the impulses given (a warm start: the last solve of the same contacts).
//!
//! Before the first step it guesses which contacts push, from where it starts, and
//! solves for them exactly with a sparse factorisation (`direct`), amending the guess a
//! few times ([`GUESSES`]); conjugate gradients take over only where no guess solves
//! the problem. A pile's friction rounds solve the same matrix again and again with
//! nearly the same contacts pushing: conjugate gradients took a few hundred steps for
//! each (1.3 million in the first 45 steps of the 480-ball pile); with the guesses,
//! 5,816 of those solves ended at the first guess, 3,928 at the second, about 2,750 at
//! later ones and 211 in conjugate gradients (34,700 steps; `docs/stepped.md`).
//!
//! It stops when no contact closes by more than `tolerance` and none that pushes has a
//! margin beyond it (the projected gradient, in speeds), or after [`MAX_STEPS`] steps.
//! Unlike `lcp` it does not single out contacts that depend on others: on a singular
//! `A` (more contacts than a pile's bodies can move in) conjugate gradients still
//! converge to one of the equally good solutions.

mod direct;

use direct::DirectSolve;

/// The most steps of one solve.
const MAX_STEPS: usize = 20_000;

/// The most guesses of the pushing contacts solved exactly before conjugate gradients.
const GUESSES: usize = 12;

/// `Γ` of the proportioning test.
const GAMMA: f64 = 1.0;

/// A symmetric matrix by rows of its non-zero entries.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct SparseMatrix {
    /// Row `r`'s entries are `start[r]..start[r + 1]`.
    start: Vec<usize>,
    column: Vec<usize>,
    value: Vec<f64>,
}

impl SparseMatrix {
    /// An empty matrix, to fill row by row with [`Self::push`] and [`Self::end_row`].
    pub(crate) fn new() -> Self {
        Self {
            start: vec![0],
            column: Vec::new(),
            value: Vec::new(),
        }
    }

    /// Adds entry `(current row, column) = value`.
    pub(crate) fn push(&mut self, column: usize, value: f64) {
        self.column.push(column);
        self.value.push(value);
    }

    /// Ends the current row.
    pub(crate) fn end_row(&mut self) {
        self.start.push(self.column.len());
    }

    /// The number of rows.
    pub(crate) fn rows(&self) -> usize {
        self.start.len() - 1
    }

    fn row(&self, r: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let span = self.start[r]..self.start[r + 1];
        self.column[span.clone()]
            .iter()
            .copied()
            .zip(self.value[span].iter().copied())
    }

    fn diagonal(&self, r: usize) -> f64 {
        self.row(r).find(|&(c, _)| c == r).map_or(0.0, |(_, v)| v)
    }
}

/// Scratch of [`SparseLcp::solve`], kept between calls.
#[derive(Clone, Debug, Default)]
pub(crate) struct SparseLcp {
    scale: Vec<f64>,
    /// `D A D`.
    scaled: SparseMatrix,
    mu: Vec<f64>,
    gradient: Vec<f64>,
    direction: Vec<f64>,
    product: Vec<f64>,
    free: Vec<f64>,
    /// The chopped gradient of a proportioning step.
    chop: Vec<f64>,
    /// The largest problem solved so far (its number of contacts).
    largest: usize,
    /// The matrix of the last solve, whose scaling, step and factorisations are kept.
    source: SparseMatrix,
    /// `ᾱ = 1/‖DAD‖` (Gershgorin's bound) of that matrix.
    step: f64,
    /// Exact solves of guessed pushing contacts.
    direct: DirectSolve,
}

impl SparseLcp {
    /// The most contacts of any problem solved so far.
    pub(crate) fn largest(&self) -> usize {
        self.largest
    }

    /// Solves `w = A λ + q >= 0, λ >= 0, λ·w = 0` for the symmetric positive
    /// semi-definite `a` (positive diagonal) into `lambda`, starting from the impulses
    /// `lambda` holds (negative ones taken as 0). A contact counts as closing when its
    /// margin is below `−tolerance`. Returns whether the solve converged: no margin below
    /// `−tolerance`, none above `tolerance` where an impulse pushes.
    pub(crate) fn solve(
        &mut self,
        a: &SparseMatrix,
        q: &[f64],
        tolerance: f64,
        lambda: &mut [f64],
    ) -> bool {
        let n = q.len();
        debug_assert_eq!(a.rows(), n);
        self.largest = self.largest.max(n);
        self.start(a, n);
        for (m, (&l, &s)) in self.mu.iter_mut().zip(lambda.iter().zip(&self.scale)) {
            *m = l.max(0.0) / s;
        }
        // The scaled problem: ½ μᵀ(DAD)μ + (Dq)ᵀμ; its gradient is D w, so a margin's
        // tolerance is `tolerance · s_i` on row i.
        let dq: Vec<f64> = q.iter().zip(&self.scale).map(|(q, s)| q * s).collect();
        let limit: Vec<f64> = self.scale.iter().map(|s| tolerance * s).collect();
        let step = self.step;
        self.restart(&dq);
        self.guess_pushing(&dq, &limit);
        let mut converged = false;
        for _ in 0..MAX_STEPS {
            if self.converged(&limit) {
                converged = true;
                break;
            }
            let chopped: f64 = (0..n)
                .filter(|&i| self.mu[i] <= 0.0)
                .map(|i| self.gradient[i].min(0.0).powi(2))
                .sum();
            // φ̃: the free gradient cut to what a step of ᾱ can take before a bound.
            let reduced: f64 = (0..n)
                .filter(|&i| self.mu[i] > 0.0)
                .map(|i| self.free[i] * (self.mu[i] / step).min(self.free[i]))
                .sum();
            if chopped <= GAMMA * GAMMA * reduced {
                multiply(&self.scaled, &self.direction, &mut self.product);
                let curvature = dot(&self.direction, &self.product);
                if curvature <= 0.0 {
                    // The direction moves nothing (rounding of a singular A): restart.
                    self.direction.clone_from(&self.free);
                    self.expand(step, &dq);
                    continue;
                }
                let cg = dot(&self.gradient, &self.direction) / curvature;
                let feasible = (0..n)
                    .filter(|&i| self.direction[i] > 0.0)
                    .map(|i| self.mu[i] / self.direction[i])
                    .fold(f64::INFINITY, f64::min);
                if cg <= feasible {
                    for i in 0..n {
                        self.mu[i] -= cg * self.direction[i];
                        self.gradient[i] -= cg * self.product[i];
                    }
                    self.free_gradient();
                    let beta = dot(&self.free, &self.product) / curvature;
                    for i in 0..n {
                        self.direction[i] = self.free[i] - beta * self.direction[i];
                    }
                } else {
                    // Expansion: to the bound along the direction, then a projected
                    // gradient step of ᾱ.
                    for i in 0..n {
                        self.mu[i] = (self.mu[i] - feasible * self.direction[i]).max(0.0);
                        self.gradient[i] -= feasible * self.product[i];
                    }
                    self.free_gradient();
                    self.expand(step, &dq);
                }
            } else {
                // Proportioning: along the chopped gradient, which only raises impulses.
                for ((c, &g), &m) in self.chop.iter_mut().zip(&self.gradient).zip(&self.mu) {
                    *c = if m <= 0.0 { g.min(0.0) } else { 0.0 };
                }
                multiply(&self.scaled, &self.chop, &mut self.product);
                let curvature = dot(&self.chop, &self.product);
                if curvature > 0.0 {
                    let alpha = dot(&self.gradient, &self.chop) / curvature;
                    let moved = (self.mu.iter_mut().zip(&mut self.gradient))
                        .zip(self.chop.iter().zip(&self.product));
                    for ((m, g), (c, p)) in moved {
                        *m -= alpha * c;
                        *g -= alpha * p;
                    }
                }
                self.free_gradient();
                self.direction.clone_from(&self.free);
            }
        }
        for (l, (&m, &s)) in lambda.iter_mut().zip(self.mu.iter().zip(&self.scale)) {
            *l = m.max(0.0) * s;
        }
        converged
    }

    /// Solves for a guessed set of pushing contacts exactly (see `direct`), and amends the
    /// guess, up to [`GUESSES`] times, from `μ` (non-negative) and its gradient: the first
    /// guess by the primal–dual active-set rule; then, as a primal active-set method does,
    /// `μ` moves towards the guess's answer as far as no impulse turns negative, and if
    /// one would have, the contacts it stopped at leave the guess; else those still
    /// closing join it. Ends at the first `μ` that solves the problem (within `limit`),
    /// else (a guess repeats, or none is left) back where it started.
    fn guess_pushing(&mut self, dq: &[f64], limit: &[f64]) {
        if self.converged(limit) {
            return;
        }
        let start = self.mu.clone();
        let n = start.len();
        let mut pushing: Vec<bool> = (self.mu.iter().zip(&self.gradient))
            .map(|(&m, &g)| m - g > 0.0)
            .collect();
        let mut answer = vec![0.0; n];
        let mut tried = vec![pushing.clone()];
        for _ in 0..GUESSES {
            if !pushing.contains(&true)
                || !(self.direct).solve(&self.scaled, dq, &pushing, (&start, limit), &mut answer)
            {
                break;
            }
            let reach = (self.mu.iter().zip(&answer))
                .filter(|&(_, &x)| x < 0.0)
                .map(|(&m, &x)| m / (m - x))
                .fold(1.0, f64::min);
            for (m, &x) in self.mu.iter_mut().zip(&answer) {
                *m = (*m + reach * (x - *m)).max(0.0);
            }
            self.restart(dq);
            if self.converged(limit) {
                return;
            }
            let mut amended = false;
            for (i, p) in pushing.iter_mut().enumerate() {
                let change = if reach < 1.0 {
                    *p && self.mu[i] <= 0.0 && answer[i] < 0.0
                } else {
                    !*p && self.gradient[i] < -limit[i]
                };
                *p ^= change;
                amended |= change;
            }
            if !amended || tried.contains(&pushing) {
                break;
            }
            tried.push(pushing.clone());
        }
        self.mu.clone_from(&start);
        self.restart(dq);
    }

    /// The scaling and the scaled matrix of `a` (kept when `a` is the last call's), and
    /// the scratch sized for `n` contacts.
    fn start(&mut self, a: &SparseMatrix, n: usize) {
        if *a != self.source {
            self.source.clone_from(a);
            self.scale.clear();
            self.scale
                .extend((0..n).map(|r| 1.0 / a.diagonal(r).max(f64::MIN_POSITIVE).sqrt()));
            self.scaled.clone_from(a);
            for r in 0..n {
                for k in a.start[r]..a.start[r + 1] {
                    self.scaled.value[k] *= self.scale[r] * self.scale[a.column[k]];
                }
            }
            self.step = 1.0 / gershgorin(&self.scaled);
            self.direct.new_matrix(&self.scaled);
        }
        for v in [
            &mut self.mu,
            &mut self.gradient,
            &mut self.direction,
            &mut self.product,
            &mut self.free,
            &mut self.chop,
        ] {
            v.clear();
            v.resize(n, 0.0);
        }
    }

    /// `φ`: the gradient on the contacts that push, zero elsewhere.
    fn free_gradient(&mut self) {
        for ((f, &g), &m) in self.free.iter_mut().zip(&self.gradient).zip(&self.mu) {
            *f = if m > 0.0 { g } else { 0.0 };
        }
    }

    /// The projected gradient step of length `step` from `μ`, the gradient recomputed
    /// (from `dq`, the scaled `q`) and the direction restarted.
    fn expand(&mut self, step: f64, dq: &[f64]) {
        for (m, &f) in self.mu.iter_mut().zip(&self.free) {
            *m = (*m - step * f).max(0.0);
        }
        self.restart(dq);
    }

    /// The gradient `DAD μ + Dq` computed afresh from `μ` (`dq` the scaled `q`), and the
    /// direction restarted along the free gradient.
    fn restart(&mut self, dq: &[f64]) {
        multiply(&self.scaled, &self.mu, &mut self.gradient);
        for (g, d) in self.gradient.iter_mut().zip(dq) {
            *g += d;
        }
        self.free_gradient();
        self.direction.clone_from(&self.free);
    }

    /// Whether every scaled margin is within `limit`: none closing, none open where the
    /// contact pushes.
    fn converged(&self, limit: &[f64]) -> bool {
        (self.gradient.iter().zip(&self.mu).zip(limit)).all(|((&g, &m), &l)| {
            if m > 0.0 { g.abs() <= l } else { g >= -l }
        })
    }
}

/// `out = a x`.
fn multiply(a: &SparseMatrix, x: &[f64], out: &mut [f64]) {
    for (r, o) in out.iter_mut().enumerate() {
        *o = a.row(r).map(|(c, v)| v * x[c]).sum();
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// An upper bound of the largest eigenvalue of `a`: its largest absolute row sum.
fn gershgorin(a: &SparseMatrix) -> f64 {
    (0..a.rows())
        .map(|r| a.row(r).map(|(_, v)| v.abs()).sum::<f64>())
        .fold(f64::MIN_POSITIVE, f64::max)
}

#[cfg(test)]
mod tests {
    use super::super::lcp::Lcp;
    use super::*;
    use carom_broad::scenes::SplitMix64;

    /// The dense matrix of `a`, row-major.
    fn dense(a: &SparseMatrix) -> Vec<f64> {
        let n = a.rows();
        let mut out = vec![0.0; n * n];
        for r in 0..n {
            for (c, v) in a.row(r) {
                out[r * n + c] = v;
            }
        }
        out
    }

    /// The Delassus matrix of a column of `k` unit-mass balls (unit inverse masses) on a
    /// floor, each also resting on a fixed support below and to its left (normal at 30°
    /// below the horizontal), and `q` for every ball falling at `g`: the floor's and the
    /// supports' contacts approach at `g` and `g/2`, the balls' contacts at 0.
    fn pile(k: usize, g: f64) -> (SparseMatrix, Vec<f64>) {
        let slant = [-(3.0_f64.sqrt()) / 2.0, -0.5];
        let mut normals: Vec<Vec<(usize, [f64; 2])>> = vec![vec![(0, [0.0, -1.0])]];
        let mut q = vec![-g];
        for i in 1..k {
            normals.push(vec![(i, [0.0, -1.0]), (i - 1, [0.0, 1.0])]);
            q.push(0.0);
        }
        for i in 0..k {
            normals.push(vec![(i, slant)]);
            q.push(-g / 2.0);
        }
        let n = normals.len();
        let mut a = SparseMatrix::new();
        for r in 0..n {
            for c in 0..n {
                let mut v = 0.0;
                for (bi, ni) in &normals[r] {
                    for (bj, nj) in &normals[c] {
                        if bi == bj {
                            v += ni[0] * nj[0] + ni[1] * nj[1];
                        }
                    }
                }
                if v != 0.0 {
                    a.push(c, v);
                }
            }
            a.end_row();
        }
        (a, q)
    }

    fn margins(a: &[f64], q: &[f64], lambda: &[f64]) -> Vec<f64> {
        let n = q.len();
        (0..n)
            .map(|i| q[i] + (0..n).map(|j| a[i * n + j] * lambda[j]).sum::<f64>())
            .collect()
    }

    /// A column of 30 balls on a floor, pressed against a slanted support each: the
    /// solve ends with every margin within the tolerance and the contacts' velocities
    /// those of the dense exact solve (`lcp`), to 1e-9 of gravity's step.
    #[test]
    fn a_column_of_thirty_balls_is_held_as_the_exact_solve_holds_it() {
        let g = 0.16;
        let (a, q) = pile(30, g);
        let tolerance = 1e-12;
        let mut lambda = vec![0.0; q.len()];
        assert!(SparseLcp::default().solve(&a, &q, tolerance, &mut lambda));
        let dense_a = dense(&a);
        let mut exact = vec![0.0; q.len()];
        assert!(Lcp::default().solve(&dense_a, &q, tolerance, &mut exact));
        let (w, w_exact) = (
            margins(&dense_a, &q, &lambda),
            margins(&dense_a, &q, &exact),
        );
        for (i, (&wi, &we)) in w.iter().zip(&w_exact).enumerate() {
            assert!(wi >= -1e-9 * g, "contact {i} closes: {wi}");
            assert!(lambda[i] >= 0.0);
            assert!(
                (wi - we).abs() <= 1e-9 * g,
                "contact {i}: {wi} against {we}"
            );
            assert!(lambda[i] * wi <= 1e-9 * g * lambda[i].max(1.0));
        }
    }

    /// A column of 30 balls held, then each contact's approach changed by up to a
    /// thousandth (a friction round's change): started from the first solve's impulses,
    /// the second is solved for the same pushing contacts exactly (`direct`), its margins
    /// within a thousandth of the tolerance asked (1e-6 of gravity's step) of those of
    /// the dense exact solve, where conjugate gradients stop once within the tolerance.
    #[test]
    fn a_problem_near_the_last_one_is_solved_exactly_from_its_impulses() {
        let g = 0.16;
        let (a, q) = pile(30, g);
        let dense_a = dense(&a);
        let mut solver = SparseLcp::default();
        let mut lambda = vec![0.0; q.len()];
        assert!(solver.solve(&a, &q, 1e-12, &mut lambda));
        let mut rng = SplitMix64::new(11);
        let nearby: Vec<f64> = q
            .iter()
            .map(|&qi| qi + g * rng.range(-1e-3, 1e-3))
            .collect();
        let tolerance = 1e-6 * g;
        assert!(solver.solve(&a, &nearby, tolerance, &mut lambda));
        let mut exact = vec![0.0; q.len()];
        assert!(Lcp::default().solve(&dense_a, &nearby, 1e-14, &mut exact));
        let (w, w_exact) = (
            margins(&dense_a, &nearby, &lambda),
            margins(&dense_a, &nearby, &exact),
        );
        for (i, (&wi, &we)) in w.iter().zip(&w_exact).enumerate() {
            assert!(
                (wi - we).abs() <= 1e-3 * tolerance,
                "contact {i}: {wi:e} against {we:e}"
            );
        }
    }

    /// Random sparse problems (contacts between random pairs of bodies with random
    /// normals and masses): the solve's margins agree with the dense exact solve's, and
    /// a warm start from the exact impulses ends at once.
    #[test]
    fn random_sparse_problems_agree_with_the_exact_solve() {
        let mut rng = SplitMix64::new(20261128);
        let mut compared = 0;
        for trial in 0..200 {
            let bodies = 4 + (rng.range(0.0, 40.0) as usize);
            let contacts = 2 + (rng.range(0.0, 2.0 * bodies as f64) as usize);
            let inverse_mass: Vec<f64> = (0..bodies)
                .map(|_| 10f64.powf(rng.range(-3.0, 3.0)))
                .collect();
            // Each contact pushes body b along n and (if not a wall) body c along −n.
            let rows: Vec<(usize, Option<usize>, [f64; 2])> = (0..contacts)
                .map(|_| {
                    let b = rng.range(0.0, bodies as f64) as usize;
                    let c = rng.range(0.0, bodies as f64 + 3.0) as usize;
                    let angle = rng.range(0.0, std::f64::consts::TAU);
                    let other = (c < bodies && c != b).then_some(c);
                    (b, other, [angle.cos(), angle.sin()])
                })
                .collect();
            let n = rows.len();
            let mut a = SparseMatrix::new();
            for r in 0..n {
                for c in 0..n {
                    let ends = |k: usize| {
                        let (b, o, nn) = rows[k];
                        core::iter::once((b, nn, 1.0)).chain(o.map(|o| (o, nn, -1.0)))
                    };
                    let mut v = 0.0;
                    for (bi, ni, si) in ends(r) {
                        for (bj, nj, sj) in ends(c) {
                            if bi == bj {
                                v += si * sj * (ni[0] * nj[0] + ni[1] * nj[1]) * inverse_mass[bi];
                            }
                        }
                    }
                    if v != 0.0 {
                        a.push(c, v);
                    }
                }
                a.end_row();
            }
            let q: Vec<f64> = (0..n).map(|_| rng.range(-1.0, 1.0)).collect();
            let dense_a = dense(&a);
            let mut exact = vec![0.0; n];
            let tolerance = 1e-10;
            if !Lcp::default().solve(&dense_a, &q, tolerance, &mut exact) {
                continue;
            }
            let mut lambda = vec![0.0; n];
            let done = SparseLcp::default().solve(&a, &q, tolerance, &mut lambda);
            assert!(done, "trial {trial}: did not converge");
            let w = margins(&dense_a, &q, &lambda);
            let w_exact = margins(&dense_a, &q, &exact);
            for i in 0..n {
                let scale = dense_a[i * n + i].sqrt();
                assert!(
                    w[i] >= -2.0 * tolerance,
                    "trial {trial}, contact {i}: {}",
                    w[i]
                );
                // The velocities (margins) of a convex programme's solutions are unique.
                assert!(
                    (w[i] - w_exact[i]).abs() <= 1e-6 * (1.0 + scale),
                    "trial {trial}, contact {i}: {} against {}",
                    w[i],
                    w_exact[i]
                );
            }
            let mut warm = exact.clone();
            assert!(SparseLcp::default().solve(&a, &q, tolerance, &mut warm));
            compared += 1;
        }
        // Problems the exact solve reports infeasible (inconsistent dependent contacts)
        // are skipped; most are not.
        assert!(compared >= 150, "{compared} of 200 compared");
    }
}
