//! Small dense linear complementarity problems: the normal impulses of a stack's contacts,
//! exactly.
//!
//! The contacts of a stack (see `stack`) ask for impulses `λ` that leave no contact
//! closing and push only where a contact would otherwise close:
//!
//! ```text
//! w = A λ + q >= 0,   λ >= 0,   λ·w = 0,
//! ```
//!
//! with `A = J M⁻¹ Jᵀ` the contacts' Delassus matrix (symmetric positive semi-definite:
//! `J` maps the bodies' velocities to the contacts' approach speeds, `M` is their mass
//! matrix), `q` each contact's margin before any impulse (the speed it may still close
//! at, less the speed it closes at) and `w` its margin after. These are the optimality
//! conditions of the convex programme `min ½ λᵀAλ + qᵀλ` over `λ >= 0`, which
//! [`Lcp::solve`] solves by an active-set method: Lawson and Hanson's non-negative least
//! squares in its normal-equations form (*Solving Least Squares Problems*, 1974, ch. 23).
//! The passive set `P` (the contacts that push) grows by the contact with the most
//! negative margin; on `P` the margins are zero, `A_PP λ_P = −q_P` (a Cholesky solve); a
//! solution with a negative entry is walked back along the segment from the last feasible
//! point until an entry reaches zero, which leaves `P`. Each step lowers the objective, so
//! no set comes back and the method ends after finitely many steps with the exact
//! solution (to rounding), whatever the masses: a body a million times heavier than the
//! one under it is held in one solve, where projected Gauss–Seidel converges by a factor
//! of about `1 − 10⁻⁶` a sweep.
//!
//! **Scaling.** The problem is solved for `μ = D⁻¹ λ` with `D = diag(A)^(−1/2)`, so that
//! `D A D` has a unit diagonal: its pivots then measure how independent a contact is of
//! the others, whatever the masses.
//!
//! **Dependent contacts.** `A` is singular when contacts constrain the same motion (three
//! members of a flat cluster on the floor in 2D; a 3D cluster resting in three pockets,
//! nine contacts on six degrees of freedom): their impulses are not unique, the
//! velocities are. A contact whose Cholesky pivot on the unit-diagonal matrix falls below
//! [`dependence_threshold`] depends on the passive ones to rounding, so it never joins
//! them as it is: pushing on it moves nothing they do not. If it closes, it *trades places* with one
//! of them: its row is `Σ c_k` times theirs, so raising its impulse by `τ` while lowering
//! theirs by `τ c_k` changes no velocity and lowers the objective by `τ |w|`; the largest
//! `τ` that keeps the impulses non-negative brings one with `c_k > 0` to zero, which
//! leaves the set (a step of the simplex method). The set stays independent, every
//! system solved well conditioned, and the method still ends with the exact solution.
//! Only a contact that no passive one can give way to (no `c_k > 0`: its margin is
//! inconsistent with theirs, which a feasible problem rules out) is left out; what it
//! leaves closing is for the caller to push on (see `stack`: a contact alone is never
//! dependent). Without the trade, a 3D cluster landing tilted in its pockets kept a
//! contact closing after every hold and was held again at the same instant to the event
//! budget (every step, 20,000 events).

/// A Cholesky pivot (squared) below `DEPENDENT` roundings on the unit-diagonal scaled
/// matrix marks a contact as dependent on the passive ones (see the module
/// documentation): [`DEPENDENCE_THRESHOLD`]. Exact dependence leaves a few roundings
/// (~1e-16); a mass ratio `r` between the bodies of two contacts leaves pivots of about
/// `1/r`, so contacts are independent up to `r` ≈ 4e12. That covers the scene
/// contract's 1e-6 kg ball pressed into a wall by a 1e6 kg ball (`r` = 1e12: a threshold
/// of 1e-11 called its two contacts dependent, left the wall's contact closing, and the
/// ball was held again at the same instant until the crush limit).
///
/// The problems are solved in `f64` whatever the scene's precision (the stack builds
/// them in `f64`: `stack::Wide`). In `f32`, whose roundings (~1e-7) cannot tell
/// dependence from a mass ratio above 1e4, the threshold then treats a contact that
/// depends on others to `f32`'s rounding as independent, which costs a poorly
/// conditioned solve, where treating a mass ratio as dependence would leave a contact
/// closing (measured when the solve was in `f32`: a threshold of 1024 `f32` roundings,
/// 1.2e-4, ended five fuzzed scenes with masses 1e-6 to 1e6 in crush errors within their
/// first two steps).
const DEPENDENT: f64 = 1024.0;

/// The pivot below which a contact is dependent: [`DEPENDENT`] roundings, 2.3e-13.
const DEPENDENCE_THRESHOLD: f64 = DEPENDENT * f64::EPSILON;

/// The mass ratio between two bodies in contact beyond which their contacts cannot be
/// held: a ratio `r` leaves pivots of about `1/r` (see [`DEPENDENT`]), which the solve
/// takes for dependence below [`DEPENDENCE_THRESHOLD`]: 4.4e12, in `f32` scenes as in
/// `f64` ones. Measured with a heavy ball dropped onto a 1 g ball on the floor
/// (`docs/open-scenes/stepped-crush_mass_ratio_f64.toml`): held up to 2e9 kg, crushed
/// from 5e9 kg, in both precisions. (While the stack solved in the scene's precision,
/// `f32` held only up to 1e4 kg: `1/m_light + 1/m_heavy` rounded to `1/m_light`.)
pub(crate) const RESOLVABLE_MASS_RATIO: f64 = 1.0 / DEPENDENCE_THRESHOLD;

/// Scratch of [`Lcp::solve`], kept between calls.
#[derive(Clone, Debug, Default)]
pub(crate) struct Lcp {
    scale: Vec<f64>,
    /// `D A D`, row-major: each entry computed once a solve.
    scaled: Vec<f64>,
    /// Whether each contact is in `passive`.
    in_passive: Vec<bool>,
    mu: Vec<f64>,
    z: Vec<f64>,
    w: Vec<f64>,
    passive: Vec<usize>,
    excluded: Vec<bool>,
    /// The Cholesky factor `L` of the passive set's matrix, row `r` at `r * n` (the
    /// problem's size, so that rows keep their places as the set changes).
    factor: Vec<f64>,
    /// `Lᵀ` likewise, for the backward substitution to read along rows.
    transposed: Vec<f64>,
    /// How many leading rows of `factor` hold the factor of the current passive set's
    /// first contacts: a row depends only on the contacts before it, so a contact added
    /// at the end costs one row, and one leaving costs the rows from its place on.
    factored: usize,
    forward: Vec<f64>,
    /// The row of the factor whose pivot failed in the last [`Self::solve_passive`].
    dependent: Option<usize>,
    /// The largest problem solved so far (its number of contacts).
    largest: usize,
}

impl Lcp {
    /// The most contacts of any problem solved so far.
    pub(crate) fn largest(&self) -> usize {
        self.largest
    }

    /// Solves `w = A λ + q >= 0, λ >= 0, λ·w = 0` for the `n × n` matrix `a` (row-major,
    /// symmetric positive semi-definite, positive diagonal) into `lambda` (length `n`).
    /// A contact counts as closing when its margin is below `−tolerance` (the speed below
    /// which a closing is rounding). Returns whether every margin ended above
    /// `−tolerance` (dependent contacts with inconsistent margins make it `false`; the
    /// impulses are still the best the independent ones give).
    pub(crate) fn solve(
        &mut self,
        a: &[f64],
        q: &[f64],
        tolerance: f64,
        lambda: &mut [f64],
    ) -> bool {
        let n = q.len();
        self.largest = self.largest.max(n);
        debug_assert_eq!(a.len(), n * n);
        debug_assert_eq!(lambda.len(), n);
        self.start(a, n);
        self.iterate(q, tolerance);
        self.finish(a, q, tolerance, lambda)
    }

    /// Solves the problem of the last [`Self::solve`] or `resolve` again with the same
    /// matrix and a new `q`, starting from the last solution's passive set, its factor
    /// and impulses: the friction rounds of a hold change only `q`, and a passive set
    /// that still holds costs two triangular solves instead of a factorisation. The
    /// result is the same solution (the margins are unique), to rounding, where it
    /// returns `true`: with dependent contacts the walk back can end short of it (seen
    /// in fuzzed scenes), and the caller then solves from scratch.
    pub(crate) fn resolve(
        &mut self,
        a: &[f64],
        q: &[f64],
        tolerance: f64,
        lambda: &mut [f64],
    ) -> bool {
        let n = q.len();
        debug_assert_eq!(self.scale.len(), n);
        self.excluded.iter_mut().for_each(|e| *e = false);
        // The last passive set for the new margins: walked back from the last impulses
        // (all positive on it) while a passive impulse would turn negative.
        for _ in 0..=self.passive.len() {
            if self.passive.is_empty() || !self.solve_passive(q, n) {
                break;
            }
            if self.passive.iter().all(|&i| self.z[i] > 0.0) {
                for &i in &self.passive {
                    self.mu[i] = self.z[i];
                }
                break;
            }
            self.walk_back(None);
        }
        self.iterate(q, tolerance);
        self.finish(a, q, tolerance, lambda)
    }

    /// The active-set iterations from the current passive set and impulses.
    fn iterate(&mut self, q: &[f64], tolerance: f64) {
        let n = q.len();
        // The same test in scaled units for every contact: margin w_i / s_i (a speed).
        let closing = |this: &Self, i: usize| this.w[i] < -tolerance * this.scale[i];
        // Each outer step adds a contact for good or excludes one; each inner step
        // removes one. Bounded well above what the theory needs, against rounding.
        for _ in 0..4 * n + 8 {
            // w = D q + (D A D) μ, μ zero off the passive set: the passive columns added
            // to all the margins at once (columns are rows: the matrix is symmetric), a
            // loop the compiler vectorises, where a dot product per margin over the
            // passive set gathered its entries one by one and waited on each addition.
            // Each margin sums the same terms in the same order as that dot product.
            for ((w, &qi), &s) in self.w.iter_mut().zip(q).zip(&self.scale) {
                *w = qi * s;
            }
            for &j in &self.passive {
                let (mu, column) = (self.mu[j], &self.scaled[j * n..(j + 1) * n]);
                for (w, &a) in self.w.iter_mut().zip(column) {
                    *w += a * mu;
                }
            }
            let entering = (0..n)
                .filter(|&i| !self.excluded[i] && !self.in_passive[i] && closing(self, i))
                .min_by(|&i, &j| {
                    self.w[i]
                        .partial_cmp(&self.w[j])
                        .unwrap_or(core::cmp::Ordering::Equal)
                });
            let Some(t) = entering else {
                break;
            };
            self.passive.push(t);
            self.in_passive[t] = true;
            for _ in 0..=self.passive.len() {
                if !self.solve_passive(q, n) {
                    // Dependent on the passive contacts: pushing on it moves nothing the
                    // others do not. Trade it for one of them along the null direction.
                    if !self.exchange(t, n) {
                        self.leave(|&i| i != t);
                        self.excluded[t] = true;
                        break;
                    }
                    continue;
                }
                if self.passive.iter().all(|&i| self.z[i] > 0.0) {
                    for &i in &self.passive {
                        self.mu[i] = self.z[i];
                    }
                    break;
                }
                if self.z[t] <= 0.0 && self.mu[t] == 0.0 {
                    // Rounding: the contact that entered would not push after all.
                    self.leave(|&i| i != t);
                    self.excluded[t] = true;
                    break;
                }
                self.walk_back(Some(t));
            }
        }
    }

    /// Walks from μ towards z until the first passive entry reaches zero; it leaves the
    /// set (with any other that rounding left at zero). `entering`: the contact that
    /// entered last, the blocking one where no other blocks first.
    fn walk_back(&mut self, entering: Option<usize>) {
        let (mut step, mut blocking) = (1.0, entering);
        for &i in &self.passive {
            if self.z[i] <= 0.0 {
                let reach = self.mu[i] / (self.mu[i] - self.z[i]);
                if reach < step || blocking.is_none() {
                    (step, blocking) = (reach, Some(i));
                }
            }
        }
        for &i in &self.passive {
            let mu = self.mu[i];
            self.mu[i] = mu + (self.z[i] - mu) * step;
        }
        if let Some(b) = blocking {
            self.mu[b] = 0.0;
        }
        let mut mu = core::mem::take(&mut self.mu);
        self.leave(|&i| {
            if mu[i] > 0.0 {
                return true;
            }
            mu[i] = 0.0;
            false
        });
        self.mu = mu;
    }

    /// Writes the impulses into `lambda`; whether every margin is above `−tolerance`.
    fn finish(&self, a: &[f64], q: &[f64], tolerance: f64, lambda: &mut [f64]) -> bool {
        let n = q.len();
        for (l, (&m, &s)) in lambda.iter_mut().zip(self.mu.iter().zip(&self.scale)) {
            *l = m * s;
        }
        (0..n).all(|i| q[i] + dot(&a[i * n..(i + 1) * n], lambda) >= -tolerance)
    }

    /// Trades contact `t`, which entered the passive set last and depends on the others
    /// (see [`Self::solve_passive`]), for one of them; `false` if none can leave.
    ///
    /// Its row is `Σ c_k` times theirs, `c = (D A D)_PP⁻¹ (D A D)_Pt`, so the impulses
    /// `μ_t = τ`, `μ_P − τ c` move no body differently for any `τ`: the margins stay, and
    /// the objective falls by `τ |w_t|` (`t` closes, the others are at zero margin). The
    /// largest `τ` keeping `μ_P >= 0` brings a contact with `c_k > 0` to zero: it leaves,
    /// `t` takes its place, and the set is independent again. If no `c_k` is positive, no
    /// impulses of these contacts open `t` (its margin is inconsistent with theirs).
    fn exchange(&mut self, t: usize, n: usize) -> bool {
        let p = self.passive.len();
        let r = p - 1;
        if self.dependent != Some(r) || self.passive[r] != t {
            return false;
        }
        // The failed row of the factor holds y = L⁻¹ (D A D)_Pt; Lᵀ c = y.
        let mut c = core::mem::take(&mut self.forward);
        c.clear();
        c.resize(r, 0.0);
        for k in (0..r).rev() {
            let mut sum = self.factor[r * n + k];
            for (l, &cl) in c.iter().enumerate().take(r).skip(k + 1) {
                sum -= self.factor[l * n + k] * cl;
            }
            c[k] = sum / self.factor[k * n + k];
        }
        let mut leaving = None;
        let mut tau = 0.0;
        for (k, &ck) in c.iter().enumerate() {
            if ck > 0.0 {
                let reach = self.mu[self.passive[k]] / ck;
                if leaving.is_none() || reach < tau {
                    (leaving, tau) = (Some(k), reach);
                }
            }
        }
        let Some(leaving) = leaving else {
            self.forward = c;
            return false;
        };
        for (k, &ck) in c.iter().enumerate() {
            let i = self.passive[k];
            self.mu[i] = (self.mu[i] - ck * tau).max(0.0);
        }
        self.mu[self.passive[leaving]] = 0.0;
        self.mu[t] = tau;
        self.forward = c;
        let mu = core::mem::take(&mut self.mu);
        self.leave(|&i| i == t || mu[i] > 0.0);
        self.mu = mu;
        true
    }

    /// Empties the scratch for a problem of `n` contacts with matrix `a`: no contact
    /// passive, no impulse, the scaling `D` and `D A D`.
    fn start(&mut self, a: &[f64], n: usize) {
        self.scale.clear();
        self.scale
            .extend((0..n).map(|i| 1.0 / a[i * n + i].max(f64::MIN_POSITIVE).sqrt()));
        self.mu.clear();
        self.mu.resize(n, 0.0);
        self.z.clear();
        self.z.resize(n, 0.0);
        self.w.clear();
        self.w.resize(n, 0.0);
        self.passive.clear();
        self.excluded.clear();
        self.excluded.resize(n, false);
        // Every entry of the factor a solve reads it wrote first (rows below `factored`),
        // so the scratch is only grown, not cleared.
        if self.factor.len() < n * n {
            self.factor.resize(n * n, 0.0);
            self.transposed.resize(n * n, 0.0);
        }
        self.factored = 0;
        self.in_passive.clear();
        self.in_passive.resize(n, false);
        self.scaled.clear();
        self.scaled.extend((0..n * n).map(|k| {
            let (i, j) = (k / n, k % n);
            a[k] * self.scale[i] * self.scale[j]
        }));
    }

    /// Keeps the passive contacts `keep` says, in order; the factor's rows from the first
    /// that leaves on no longer hold (see `factored`).
    fn leave(&mut self, mut keep: impl FnMut(&usize) -> bool) {
        if let Some(first) = self.passive.iter().position(|i| !keep(i)) {
            self.factored = self.factored.min(first);
            let in_passive = &mut self.in_passive;
            self.passive.retain(|i| {
                let kept = keep(i);
                in_passive[*i] = kept;
                kept
            });
        }
    }

    /// `z_P = −(D A D)_PP⁻¹ (D q)_P` on the passive set by Cholesky, `z = 0` elsewhere;
    /// `false` if a pivot marks the last passive contact as dependent on the others.
    /// The rows of the factor from `factored` on are computed anew; the ones before are
    /// the same numbers whether kept or computed again (a row reads only the rows before
    /// it), so keeping them changes no result.
    fn solve_passive(&mut self, q: &[f64], n: usize) -> bool {
        let p = self.passive.len();
        self.dependent = None;
        // L Lᵀ = (D A D)_PP, row by row (lower triangle).
        for r in self.factored.min(p)..p {
            let row = self.passive[r] * n;
            for c in 0..=r {
                let sum = self.scaled[row + self.passive[c]]
                    - dot(
                        &self.factor[r * n..r * n + c],
                        &self.factor[c * n..c * n + c],
                    );
                let entry = if r == c {
                    if sum <= DEPENDENCE_THRESHOLD {
                        self.dependent = Some(r);
                        self.factored = r;
                        return false;
                    }
                    sum.sqrt()
                } else {
                    sum / self.factor[c * n + c]
                };
                self.factor[r * n + c] = entry;
                self.transposed[c * n + r] = entry;
            }
        }
        self.factored = p;
        self.z.iter_mut().for_each(|z| *z = 0.0);
        // Forward: L y = −(D q)_P; backward: Lᵀ z_P = y.
        let mut y = core::mem::take(&mut self.forward);
        y.clear();
        y.resize(p, 0.0);
        for r in 0..p {
            let i = self.passive[r];
            let sum = -q[i] * self.scale[i] - dot(&self.factor[r * n..r * n + r], &y[..r]);
            y[r] = sum / self.factor[r * n + r];
        }
        // In place: `y[r + 1..]` holds `z` in the passive set's order by the time row `r`
        // reads it.
        for r in (0..p).rev() {
            let sum = y[r] - dot(&self.transposed[r * n + r + 1..r * n + p], &y[r + 1..p]);
            y[r] = sum / self.factor[r * n + r];
            self.z[self.passive[r]] = y[r];
        }
        self.forward = y;
        true
    }
}

/// `Σ xₖ yₖ` over the shorter of the two, in four interleaved partial sums added
/// pairwise at the end (`x₀y₀ + x₄y₄ + …` in the first, and so on).
///
/// The solve's loops are sums of products. In one running sum each addition waits for
/// the one before (an addition's latency, where the processor could start one or two
/// a cycle), and the dense solve was 78 % of the 96-ball pile drop's `perf` samples. Four
/// sums keep four additions in flight, and chunks of four need no index checks: the
/// drop's 18 draws ran 1.64× faster (docs/stepped.md, piles item 16). Only the order of the
/// additions changes: the error bound is a running sum's, `γ_n Σ |xₖ yₖ|` (Higham,
/// *Accuracy and Stability of Numerical Algorithms*, §3.1), so the solution is as
/// accurate, though not the same to the last bit.
#[inline]
fn dot(x: &[f64], y: &[f64]) -> f64 {
    let len = x.len().min(y.len());
    let (x, rest_x) = x[..len].as_chunks::<4>();
    let (y, rest_y) = y[..len].as_chunks::<4>();
    let mut s = [0.0_f64; 4];
    for (a, b) in x.iter().zip(y) {
        for lane in 0..4 {
            s[lane] += a[lane] * b[lane];
        }
    }
    for (lane, (a, b)) in rest_x.iter().zip(rest_y).enumerate() {
        s[lane] += a * b;
    }
    (s[0] + s[1]) + (s[2] + s[3])
}

#[cfg(test)]
mod tests {
    use super::*;
    use carom_broad::scenes::SplitMix64;

    /// Deterministic numbers in `[−1, 1)`, from carom-broad's scene generator.
    struct Numbers(SplitMix64);

    impl Numbers {
        fn new(seed: u64) -> Self {
            Self(SplitMix64::new(seed))
        }

        fn next(&mut self) -> f64 {
            self.0.range(-1.0, 1.0)
        }
    }

    /// A 1 mg ball between a wall and a 1,000 t ball closing on it at 979 m/s (a mass
    /// ratio of 1e12, as in a fuzzed scene): both contacts push, each with the closed-form
    /// impulse `979 m_H` (the wall's margin is the light ball's speed `λ₁ − λ₂` over its
    /// mass, zero; the heavy ball stops, `λ₂ = 979 m_H`). With a fixed dependence
    /// threshold of 1e-11 the wall's contact (pivot 1e-12) counted as dependent and was
    /// left closing.
    #[test]
    fn a_milligram_ball_pressed_into_a_wall_by_a_thousand_tonne_ball_is_held_by_both_contacts() {
        let (light, heavy) = (1e-6_f64, 1e6_f64);
        let a = [
            1.0 / light,
            -1.0 / light,
            -1.0 / light,
            1.0 / light + 1.0 / heavy,
        ];
        let q = [0.0, -979.0];
        let mut lambda = [0.0; 2];
        // Its return is not asked: the margins are differences of terms of 1e15 m/s
        // (`λ / m_L`), whose rounding (~0.2 m/s) is above any tolerance of a speed.
        Lcp::default().solve(&a, &q, 1e-9, &mut lambda);
        for l in lambda {
            assert!((l / (979.0 * heavy) - 1.0).abs() < 1e-3, "{lambda:?}");
        }
    }

    /// Asserts that `lambda` solves the problem: non-negative impulses, non-negative
    /// margins, and no impulse where a margin is open.
    fn assert_complementary(a: &[f64], q: &[f64], lambda: &[f64], trial: usize) {
        let w = margins(a, q, lambda);
        assert!(
            lambda.iter().all(|&l| l >= 0.0),
            "trial {trial}: {lambda:?}"
        );
        assert!(
            w.iter().all(|&v| v >= -1e-9),
            "trial {trial}: margins {w:?}"
        );
        assert!(
            lambda.iter().zip(&w).all(|(l, v)| (l * v).abs() <= 1e-9),
            "trial {trial}: complementarity {lambda:?} {w:?}"
        );
    }

    /// `A = J W Jᵀ` for `n` contacts on `m` degrees of freedom with inverse masses `w`.
    fn delassus(j: &[f64], w: &[f64], n: usize, m: usize) -> Vec<f64> {
        let mut a = vec![0.0; n * n];
        for r in 0..n {
            for c in 0..n {
                a[r * n + c] = (0..m).map(|k| j[r * m + k] * w[k] * j[c * m + k]).sum();
            }
        }
        a
    }

    /// The margins `A λ + q`.
    fn margins(a: &[f64], q: &[f64], lambda: &[f64]) -> Vec<f64> {
        let n = q.len();
        (0..n)
            .map(|i| q[i] + (0..n).map(|j| a[i * n + j] * lambda[j]).sum::<f64>())
            .collect()
    }

    /// The solution by trying every passive set (positive definite `A` only): the one
    /// whose equalities give `λ >= 0` and `w >= 0`.
    fn brute_force(a: &[f64], q: &[f64]) -> Vec<f64> {
        let n = q.len();
        for set in 0u32..(1 << n) {
            let idx: Vec<usize> = (0..n).filter(|&i| set & (1 << i) != 0).collect();
            let p = idx.len();
            // Gaussian elimination on A_PP λ_P = −q_P.
            let mut m: Vec<Vec<f64>> = idx
                .iter()
                .map(|&r| {
                    let mut row: Vec<f64> = idx.iter().map(|&c| a[r * n + c]).collect();
                    row.push(-q[r]);
                    row
                })
                .collect();
            for col in 0..p {
                let pivot = (col..p)
                    .max_by(|&x, &y| m[x][col].abs().partial_cmp(&m[y][col].abs()).unwrap())
                    .unwrap();
                m.swap(col, pivot);
                let (upper, lower) = m.split_at_mut(col + 1);
                let pivot_row = &upper[col];
                for row in lower.iter_mut() {
                    let f = row[col] / pivot_row[col];
                    for (x, y) in row[col..].iter_mut().zip(&pivot_row[col..]) {
                        *x -= f * y;
                    }
                }
            }
            let mut x = vec![0.0; p];
            for row in (0..p).rev() {
                let s: f64 = (row + 1..p).map(|k| m[row][k] * x[k]).sum();
                x[row] = (m[row][p] - s) / m[row][row];
            }
            let mut lambda = vec![0.0; n];
            for (k, &i) in idx.iter().enumerate() {
                lambda[i] = x[k];
            }
            let w = margins(a, q, &lambda);
            if lambda.iter().all(|&l| l >= -1e-12) && w.iter().all(|&v| v >= -1e-12) {
                return lambda;
            }
        }
        panic!("no passive set solves the problem");
    }

    #[test]
    fn random_positive_definite_problems_match_every_passive_set_tried() {
        let mut rng = Numbers::new(11);
        let mut lcp = Lcp::default();
        for trial in 0..300 {
            let n = 1 + trial % 7;
            let m = n + 2;
            let j: Vec<f64> = (0..n * m).map(|_| rng.next()).collect();
            let w: Vec<f64> = (0..m).map(|_| 0.5 + rng.next().abs()).collect();
            let a = delassus(&j, &w, n, m);
            let q: Vec<f64> = (0..n).map(|_| rng.next()).collect();
            let mut lambda = vec![0.0; n];
            assert!(lcp.solve(&a, &q, 1e-12, &mut lambda), "trial {trial}");
            let expected = brute_force(&a, &q);
            for (l, e) in lambda.iter().zip(&expected) {
                assert!(
                    (l - e).abs() <= 1e-9 * (1.0 + e.abs()),
                    "trial {trial}: {lambda:?} vs {expected:?}"
                );
            }
        }
    }

    /// A solve again with the same matrix and new margins (as a hold's friction rounds
    /// make them), from the last passive set, gives what a solve from scratch gives:
    /// the same margins, complementary impulses; dependent contacts included.
    #[test]
    fn a_solve_again_from_the_last_passive_set_matches_a_solve_from_scratch() {
        let mut rng = Numbers::new(23);
        let (mut again, mut fresh) = (Lcp::default(), Lcp::default());
        for trial in 0..300 {
            let m = 2 + trial % 6;
            let n = 1 + trial % 9;
            let j: Vec<f64> = (0..n * m).map(|_| rng.next()).collect();
            let w: Vec<f64> = (0..m).map(|_| 0.5 + rng.next().abs()).collect();
            let a = delassus(&j, &w, n, m);
            // Feasible margins (q = −A λ* + s, λ*, s >= 0), moved each round.
            let star: Vec<f64> = (0..n).map(|_| rng.next().max(0.0)).collect();
            let pushed = margins(&a, &vec![0.0; n], &star);
            let mut q: Vec<f64> = (0..n).map(|i| -pushed[i] + rng.next().max(0.0)).collect();
            let mut lambda = vec![0.0; n];
            assert!(again.solve(&a, &q, 1e-12, &mut lambda), "trial {trial}");
            for round in 0..4 {
                // Either way where every set of contacts is independent (`n <= m`: a
                // solution exists for any margins); only opening otherwise.
                for (qi, p) in q.iter_mut().zip(&pushed) {
                    let d = rng.next();
                    *qi += 0.1 * if n > m { d.abs() } else { d } * (1.0 + p.abs());
                }
                let mut expected = vec![0.0; n];
                assert!(fresh.solve(&a, &q, 1e-12, &mut expected), "trial {trial}");
                assert!(
                    again.resolve(&a, &q, 1e-12, &mut lambda),
                    "trial {trial}.{round}"
                );
                assert_complementary(&a, &q, &lambda, trial);
                let (w, w_expected) = (margins(&a, &q, &lambda), margins(&a, &q, &expected));
                for (x, y) in w.iter().zip(&w_expected) {
                    assert!(
                        (x - y).abs() <= 1e-9,
                        "trial {trial}.{round}: {w:?} vs {w_expected:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn dependent_contacts_give_the_unique_margins_with_non_negative_impulses() {
        // Three contacts on two degrees of freedom (a flat body on three supports in a
        // plane: vertical motion and rotation), twice as many as independent ones.
        let mut rng = Numbers::new(5);
        let mut lcp = Lcp::default();
        for trial in 0..200 {
            let n = 3 + trial % 4;
            let m = 2;
            let j: Vec<f64> = (0..n)
                .flat_map(|_| [1.0, rng.next()]) // rows (1, x_i): supports at x_i
                .collect();
            let w = [1.0, 3.0];
            let a = delassus(&j, &w, n, m);
            // Everything falls at speed 1 onto the supports: q = −1 on every contact.
            let q = vec![-1.0; n];
            let mut lambda = vec![0.0; n];
            lcp.solve(&a, &q, 1e-12, &mut lambda);
            assert_complementary(&a, &q, &lambda, trial);
        }
    }

    #[test]
    fn dependent_contacts_with_inconsistent_margins_trade_places_in_the_set() {
        // More contacts than degrees of freedom (a 3D cluster in three pockets: nine
        // contacts on six), with margins no single independent set of them satisfies:
        // q = −A λ* + s with λ*, s >= 0, so λ* is feasible and a solution exists.
        let mut rng = Numbers::new(17);
        let mut lcp = Lcp::default();
        for trial in 0..300 {
            let m = 2 + trial % 5;
            let n = m + 1 + trial % 4;
            let j: Vec<f64> = (0..n * m).map(|_| rng.next()).collect();
            let w: Vec<f64> = (0..m).map(|_| 0.5 + rng.next().abs()).collect();
            let a = delassus(&j, &w, n, m);
            let star: Vec<f64> = (0..n).map(|_| rng.next().max(0.0)).collect();
            let pushed = margins(&a, &vec![0.0; n], &star);
            let q: Vec<f64> = (0..n).map(|i| -pushed[i] + rng.next().max(0.0)).collect();
            let mut lambda = vec![0.0; n];
            assert!(lcp.solve(&a, &q, 1e-12, &mut lambda), "trial {trial}");
            assert_complementary(&a, &q, &lambda, trial);
        }
    }

    #[test]
    fn a_heavy_body_on_a_light_one_on_the_floor_is_held_in_one_solve() {
        // Two bodies on a vertical line, masses m (below) and M = 1e6 m (on top), both
        // falling at speed 1: the floor must stop both, the contact between them the top
        // one. Closed form: λ_top = M, λ_floor = M + m.
        let (m, heavy) = (1.0, 1e6);
        // Velocities (lower, upper), upwards. Margins: 0 floor–lower, the lower one's
        // velocity; 1 between them, upper − lower.
        let j = [1.0, 0.0, -1.0, 1.0];
        let a = delassus(&j, &[1.0 / m, 1.0 / heavy], 2, 2);
        // Before any impulse the floor contact closes at 1, the pair not at all.
        let q = [-1.0, 0.0];
        let mut lambda = [0.0; 2];
        assert!(Lcp::default().solve(&a, &q, 1e-12, &mut lambda));
        assert!(
            (lambda[0] - (heavy + m)).abs() <= 1e-9 * heavy,
            "{lambda:?}"
        );
        assert!((lambda[1] - heavy).abs() <= 1e-9 * heavy, "{lambda:?}");
    }
}
