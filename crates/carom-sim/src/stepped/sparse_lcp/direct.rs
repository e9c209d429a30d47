//! The exact solve of a sparse problem on a guessed set of pushing contacts: a sparse
//! Cholesky factorisation of those contacts' matrix, kept while the matrix and the set
//! stay the same.
//!
//! When the contacts that push are known (`F`, the others at zero impulse), the problem
//! is linear: `A_FF λ_F = −q_F`. A pile's hold solves the same matrix again and again
//! (its friction rounds change only `q`), and from round to round, hold to hold, nearly
//! the same contacts push; conjugate gradients paid a few hundred steps per solve for
//! that (`docs/stepped.md`). So `SparseLcp::solve` first guesses `F` from where it
//! starts and solves it directly ([`DirectSolve::solve`]), then amends the guess
//! (`SparseLcp::guess_pushing`: the contacts an answer would pull with leave it, those
//! still closing join it). Where a guess holds, its answer solves the problem within a
//! thousandth of the solve's tolerance ([`PRECISE`]). Where the guesses do not settle,
//! conjugate gradients take over from where the solve started.
//!
//! A guess is solved by proximal rounds ([`PROXIMAL`]), which leave the impulses where
//! they started along the directions the contacts' matrix does not move (a singular
//! `A_FF`), so that an answer never holds pushes of any size that cancel each other.
//!
//! The factorisation is `nalgebra-sparse`'s Cholesky (`CscCholesky`), which follows the
//! matrix's own order; the rows are put in approximate minimum degree order first (the
//! `amd` crate), which keeps the factor's fill-in low (a shuffled chain and an
//! arrowhead factor without any, tested). A
//! factorisation is kept while the matrix stays the same (a hold's friction rounds),
//! and a guess that differs from the factored set by a few contacts is solved on that
//! factor by block elimination ([`Patch`]) instead of a factorisation of its own: in
//! the 480-ball pile's first 62 steps 238,000 of 382,000 guesses needed a new
//! factorisation, 98 % of them differing from the one before by at most four contacts,
//! and the factorisations took about 40 % of the time (`docs/stepped.md`).

use nalgebra::{Cholesky, DMatrix, DMatrixViewMut, DVector, Dyn};
use nalgebra_sparse::CscMatrix;
use nalgebra_sparse::factorization::CscCholesky;

use super::SparseMatrix;

/// `ε` of the proximal rounds, against the scaled problem's unit diagonal.
///
/// A round solves `min ½ xᵀA x + dqᵀx + ½ε|x − x_k|²` on the guess's rows, that is
/// `(A_FF + εI) x = ε x_k − dq_F`: always positive definite, so the factorisation
/// succeeds where `A_FF` is singular (a packed pile has more contacts than its balls
/// have directions to move in). Along a direction `A_FF` moves with eigenvalue `σ` the
/// error shrinks by `ε/(σ + ε)` a round; along one it does not move at all the impulses
/// stay where the start had them. Without it the factorisation of a singular `A_FF`
/// went through on pivots of rounding's size (1e-16 to 1e-10 in the 480-ball pile), and
/// its answers pushed equal and opposite impulses of any size along such directions:
/// valid solutions of the problem, whose friction cones let friction spin balls up (the
/// pile's energy rose from 4.8e4 J to 1.8e7 J).
const PROXIMAL: f64 = 1e-8;

/// The most proximal rounds of one guess.
const PROXIMAL_ROUNDS: usize = 8;

/// The rounds end once no margin of the guess's rows is beyond this fraction of its
/// limit: a solve on the right guess is then exact beyond what conjugate gradients
/// stop at, for a round or two more, each a pair of triangular solves (the
/// factorisation is kept).
const PRECISE: f64 = 1e-3;

/// The most rows by which a guess may differ from the factored set (left out of it or
/// added to it) and still be solved on that set's factor ([`Patch`]) instead of being
/// factored afresh. Patching costs a pair of triangular solves per row it differs by,
/// once, and a few small dense products per solve; a factorisation of the 480-ball
/// pile's sets cost about fifteen pairs in the rows' reverse Cuthill–McKee order (a
/// profile) and 17–20 in their minimum degree order (timed on three of its matrices;
/// `docs/stepped.md`).
const MOST_PATCHED: usize = 8;

/// A set of pushing contacts and the factorisation it is solved on, for one matrix.
#[derive(Clone, Default)]
pub(super) struct DirectSolve {
    /// The rows in a fill-reducing order.
    order: Vec<usize>,
    /// The factored rows (`F₀`), in that order.
    base: Vec<usize>,
    /// A row's position among `base`, `usize::MAX` when not among them.
    position: Vec<usize>,
    /// The factorisation of `B = a_F₀F₀ + εI`, `None` when that could not be factored.
    factor: Option<CscCholesky<f64>>,
    /// The set last solved (`F`), as a change of `F₀`.
    patch: Patch,
    /// Each row's place in a solve's unknowns for `F` (the positions of `F₀`, then those
    /// of the rows `F` adds), `usize::MAX` when not in `F`.
    slot: Vec<usize>,
    /// The rows of `F`.
    rows: Vec<usize>,
    /// Whether the fields above are those of the current matrix.
    kept: bool,
}

impl core::fmt::Debug for DirectSolve {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("DirectSolve")
            .field("rows", &self.rows.len())
            .field("factored", &self.factor.is_some())
            .finish_non_exhaustive()
    }
}

/// A set `F = (F₀ \ R) ∪ J` solved on the factor of `B = a_F₀F₀ + εI`, by block
/// elimination instead of a factorisation of its own.
///
/// Leaving rows `R` out: `B_SS y = c` on `S = F₀ \ R` is `B z = [c; 0] − E_R w` with `w`
/// chosen so that `z_R = 0`, that is `(B⁻¹)_RR w = (B⁻¹[c; 0])_R`; then `y = z_S` (the
/// rows `S` of `B z` are `B_SS z_S + B_SR z_R = c`). `W = B⁻¹ E_R` and the Cholesky
/// factor of `(B⁻¹)_RR = W_R` (a principal block of a positive definite inverse,
/// itself positive definite) are computed once per set.
///
/// Adding rows `J`: `[B_SS B_SJ; B_JS B_JJ] [x_S; x_J] = [b_S; b_J]` by the Schur
/// complement `C = B_JJ − B_JS Y`, `Y = B_SS⁻¹ B_SJ` (positive definite as `a_FF + εI`
/// is): `x_J = C⁻¹(b_J − B_JS y)` and `x_S = y − Y x_J`, `y = B_SS⁻¹ b_S`.
///
/// Each solve then costs the factor's pair of triangular solves and products with the
/// `|R| + |J|` dense columns.
#[derive(Clone, Default)]
struct Patch {
    /// The positions in `F₀` of the rows left out (`R`).
    removed: Vec<usize>,
    /// The rows added (`J`), in the matrix's order.
    joined: Vec<usize>,
    /// `W = B⁻¹ E_R`, one column per removed row.
    w: DMatrix<f64>,
    /// The Cholesky factor of `W_R`.
    w_r: Option<Cholesky<f64, Dyn>>,
    /// `B_SJ`, one column per added row, zero on `R`.
    b_sj: DMatrix<f64>,
    /// `Y = B_SS⁻¹ B_SJ`, zero on `R`.
    y: DMatrix<f64>,
    /// The Cholesky factor of the Schur complement `C`.
    schur: Option<Cholesky<f64, Dyn>>,
}

impl DirectSolve {
    /// Forgets the factorisation and orders the rows of the new matrix `a`.
    pub(super) fn new_matrix(&mut self, a: &SparseMatrix) {
        self.order = fill_reducing_order(a);
        self.kept = false;
        self.factor = None;
        self.base.clear();
        self.rows.clear();
        self.position.clear();
        self.position.resize(a.rows(), usize::MAX);
        self.slot.clear();
        self.slot.resize(a.rows(), usize::MAX);
    }

    /// Solves `a_FF μ_F = −dq_F` for the rows `F` where `pushing` is set, with `μ` zero
    /// elsewhere, into `mu`, by proximal rounds from `start`'s impulses on `F` (see
    /// [`PROXIMAL`]), until no row of `F` has a margin beyond [`PRECISE`] of its `limit`,
    /// at most [`PROXIMAL_ROUNDS`] rounds; `a` is the matrix of the last
    /// [`Self::new_matrix`].
    /// Returns false, leaving `mu` as it was, when `a_FF + εI` cannot be factored (which
    /// rounding alone can cause) or a round's impulses are not finite.
    pub(super) fn solve(
        &mut self,
        a: &SparseMatrix,
        dq: &[f64],
        pushing: &[bool],
        (start, limit): (&[f64], &[f64]),
        mu: &mut [f64],
    ) -> bool {
        let same = self.kept
            && self.rows.len() == pushing.iter().filter(|&&p| p).count()
            && self.rows.iter().all(|&r| pushing[r]);
        if !same {
            // A new set: on the kept factor where it is near the factored one, else
            // factored afresh.
            let patched = self.kept && self.factor.is_some() && self.amend(a, pushing);
            if !patched {
                self.factor_rows(a, pushing);
            }
        }
        if self.factor.is_none() {
            return false;
        }
        let unknowns = self.base.len() + self.patch.joined.len();
        let mut x = vec![0.0; unknowns];
        for &r in &self.rows {
            x[self.slot[r]] = start[r].max(0.0);
        }
        let mut margin = vec![0.0; unknowns];
        for round in 0..=PROXIMAL_ROUNDS {
            // The margins a_FF x + dq_F.
            let mut precise = true;
            for &r in &self.rows {
                let product: f64 = (a.row(r))
                    .filter(|&(c, _)| self.slot[c] != usize::MAX)
                    .map(|(c, v)| v * x[self.slot[c]])
                    .sum();
                let g = product + dq[r];
                precise &= g.abs() <= PRECISE * limit[r];
                margin[self.slot[r]] = g;
            }
            if precise || round == PROXIMAL_ROUNDS {
                break;
            }
            // x ← argmin ½ xᵀAx + dqᵀx + ½ε|x − x_k|², that is (A + εI) x = ε x_k − dq,
            // taken as the correction x_k − (A + εI)⁻¹ (A x_k + dq): the same step, in
            // which what the solve leaves of rounding (more where the factor is
            // patched) is corrected by the next round's margins.
            self.solve_shifted(&mut margin);
            if !margin.iter().all(|v| v.is_finite()) {
                return false;
            }
            for (v, m) in x.iter_mut().zip(&margin) {
                *v -= m;
            }
        }
        mu.fill(0.0);
        for &r in &self.rows {
            mu[r] = x[self.slot[r]];
        }
        true
    }

    /// Solves `(a_FF + εI) x = b` in place, `b` and `x` on the slots of `F`.
    fn solve_shifted(&self, b: &mut [f64]) {
        let n0 = self.base.len();
        let (own, joined) = b.split_at_mut(n0);
        self.solve_kept(own);
        let patch = &self.patch;
        if let Some(schur) = &patch.schur {
            // x_J = C⁻¹(b_J − B_JS y), x_S = y − Y x_J.
            let mut x_j = DVector::from_iterator(
                joined.len(),
                (joined.iter().enumerate()).map(|(u, &b)| {
                    b - (patch.b_sj.column(u).iter().zip(&*own))
                        .map(|(v, o)| v * o)
                        .sum::<f64>()
                }),
            );
            schur.solve_mut(&mut x_j);
            for (u, v) in x_j.iter().enumerate() {
                for (o, y) in own.iter_mut().zip(patch.y.column(u).iter()) {
                    *o -= y * v;
                }
            }
            joined.copy_from_slice(x_j.as_slice());
        }
    }

    /// Solves `B_SS y = c` in place on `F₀`'s positions (`c` taken as zero on `R`, `y`
    /// left zero there).
    fn solve_kept(&self, c: &mut [f64]) {
        let patch = &self.patch;
        for &p in &patch.removed {
            c[p] = 0.0;
        }
        solve_factored(self.factor.as_ref().expect("solved on a factor"), c);
        if let Some(w_r) = &patch.w_r {
            let mut w =
                DVector::from_iterator(patch.removed.len(), patch.removed.iter().map(|&p| c[p]));
            w_r.solve_mut(&mut w);
            for (k, v) in w.iter().enumerate() {
                for (o, col) in c.iter_mut().zip(patch.w.column(k).iter()) {
                    *o -= col * v;
                }
            }
            for &p in &patch.removed {
                c[p] = 0.0;
            }
        }
    }

    /// Makes `F` the rows where `pushing` is set as a [`Patch`] of the factored set;
    /// false (and nothing solvable) where they differ by more than [`MOST_PATCHED`]
    /// rows or a block cannot be factored.
    fn amend(&mut self, a: &SparseMatrix, pushing: &[bool]) -> bool {
        let removed: Vec<usize> = (0..self.base.len())
            .filter(|&p| !pushing[self.base[p]])
            .collect();
        let joined: Vec<usize> = (self.order.iter().copied())
            .filter(|&r| pushing[r] && self.position[r] == usize::MAX)
            .collect();
        if removed.len() + joined.len() > MOST_PATCHED {
            return false;
        }
        let n0 = self.base.len();
        self.patch = Patch {
            removed,
            ..Patch::default()
        };
        self.set_rows(pushing, &joined);
        let factor = self.factor.as_ref().expect("amended on a factor");
        let r = self.patch.removed.len();
        if r > 0 {
            let mut w = DMatrix::zeros(n0, r);
            for (k, &p) in self.patch.removed.iter().enumerate() {
                let mut column = w.column_mut(k);
                column[p] = 1.0;
                solve_factored(factor, column.as_mut_slice());
            }
            let w_rr = DMatrix::from_fn(r, r, |i, k| w[(self.patch.removed[i], k)]);
            self.patch.w = w;
            self.patch.w_r = Cholesky::new(w_rr);
            if self.patch.w_r.is_none() {
                return false;
            }
        }
        let j = joined.len();
        if j > 0 {
            let mut b_sj = DMatrix::zeros(n0, j);
            let mut b_jj = DMatrix::zeros(j, j);
            for (u, &t) in joined.iter().enumerate() {
                for (c, v) in a.row(t) {
                    if let Some(k) = joined.iter().position(|&s| s == c) {
                        b_jj[(u, k)] = if k == u { v + PROXIMAL } else { v };
                    } else if self.slot[c] != usize::MAX {
                        b_sj[(self.slot[c], u)] = v;
                    }
                }
            }
            let mut y = b_sj.clone();
            for u in 0..j {
                self.solve_kept(y.column_mut(u).as_mut_slice());
            }
            let schur = b_jj - b_sj.tr_mul(&y);
            self.patch.b_sj = b_sj;
            self.patch.y = y;
            self.patch.schur = Cholesky::new(schur);
            if self.patch.schur.is_none() {
                return false;
            }
        }
        self.patch.joined = joined;
        true
    }

    /// Sets `rows` and `slot` for the set where `pushing` is set: `F₀`'s rows in it at
    /// their positions, `joined` after them.
    fn set_rows(&mut self, pushing: &[bool], joined: &[usize]) {
        for &r in &self.rows {
            self.slot[r] = usize::MAX;
        }
        self.rows.clear();
        let n0 = self.base.len();
        for (p, &r) in self.base.iter().enumerate() {
            if pushing[r] {
                self.slot[r] = p;
                self.rows.push(r);
            }
        }
        for (u, &r) in joined.iter().enumerate() {
            self.slot[r] = n0 + u;
            self.rows.push(r);
        }
        self.kept = true;
    }

    /// Factors `a_FF + εI` for the rows where `pushing` is set, in the kept order, and
    /// makes them the factored set.
    fn factor_rows(&mut self, a: &SparseMatrix, pushing: &[bool]) {
        for &r in &self.base {
            self.position[r] = usize::MAX;
        }
        self.base.clear();
        self.base
            .extend(self.order.iter().copied().filter(|&r| pushing[r]));
        for (k, &r) in self.base.iter().enumerate() {
            self.position[r] = k;
        }
        self.patch = Patch::default();
        self.set_rows(pushing, &[]);
        // `a` is symmetric: its rows restricted to F, in F's order, are the columns of
        // a_FF in compressed-column form; ε goes on the diagonal as they are copied.
        let mut offsets = Vec::with_capacity(self.base.len() + 1);
        let (mut indices, mut values) = (Vec::new(), Vec::new());
        let mut entries: Vec<(usize, f64)> = Vec::new();
        offsets.push(0);
        for &r in &self.base {
            entries.clear();
            let own = self.position[r];
            entries.extend(
                a.row(r)
                    .filter(|&(c, _)| self.position[c] != usize::MAX)
                    .map(|(c, v)| {
                        let k = self.position[c];
                        (k, if k == own { v + PROXIMAL } else { v })
                    }),
            );
            entries.sort_unstable_by_key(|&(k, _)| k);
            indices.extend(entries.iter().map(|&(k, _)| k));
            values.extend(entries.iter().map(|&(_, v)| v));
            offsets.push(indices.len());
        }
        let m = self.base.len();
        self.factor = CscMatrix::try_from_csc_data(m, m, offsets, indices, values)
            .ok()
            .and_then(|shifted| CscCholesky::factor(&shifted).ok());
    }
}

/// Solves `B x = c` in place for `B`'s Cholesky factorisation.
fn solve_factored(factor: &CscCholesky<f64>, c: &mut [f64]) {
    let rows = c.len();
    factor.solve_mut(DMatrixViewMut::from_slice(c, rows, 1));
}

/// The rows of `a` in approximate minimum degree order (the `amd` crate, a translation
/// of SuiteSparse's AMD), which keeps the factor's fill-in low: on matrices of the
/// 480-ball pile (about 615 rows, 3,830 entries) its factors held 5,400 entries against
/// 11,400 in reverse Cuthill–McKee order, and their triangular solves took 11–12 µs
/// against 20 µs (`docs/stepped.md`). Where it refuses the pattern (it cannot for a
/// symmetric matrix's rows) the rows keep their own order.
fn fill_reducing_order(a: &SparseMatrix) -> Vec<usize> {
    match amd::order(a.rows(), &a.start, &a.column, &amd::Control::default()) {
        Ok((order, _, _)) => order,
        Err(_) => (0..a.rows()).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use carom_broad::scenes::SplitMix64;

    /// A sparse matrix from dense row-major entries (zeros left out).
    fn sparse(n: usize, dense: &[f64]) -> SparseMatrix {
        let mut a = SparseMatrix::new();
        for r in 0..n {
            for c in 0..n {
                if dense[r * n + c] != 0.0 {
                    a.push(c, dense[r * n + c]);
                }
            }
            a.end_row();
        }
        a
    }

    /// The Delassus matrix, unit diagonal, of a chain of `n` contacts between `n + 1`
    /// bodies along a line (`a_ii = 1`, `a_i,i±1 = −½`), its rows numbered by `label`.
    fn chain(n: usize, label: &[usize]) -> Vec<f64> {
        let mut dense = vec![0.0; n * n];
        for i in 0..n {
            dense[label[i] * n + label[i]] = 1.0;
            if i + 1 < n {
                dense[label[i] * n + label[i + 1]] = -0.5;
                dense[label[i + 1] * n + label[i]] = -0.5;
            }
        }
        dense
    }

    /// The entries of the Cholesky factor of `a` with its rows put in `order`.
    fn factor_entries(a: &SparseMatrix, order: &[usize]) -> usize {
        let n = a.rows();
        let mut at = vec![0; n];
        for (k, &r) in order.iter().enumerate() {
            at[r] = k;
        }
        let mut coo = nalgebra_sparse::CooMatrix::new(n, n);
        for r in 0..n {
            for (c, v) in a.row(r) {
                coo.push(at[r], at[c], v);
            }
        }
        let factor = CscCholesky::factor(&CscMatrix::from(&coo)).expect("positive definite");
        factor.l().nnz()
    }

    /// The order is every row once, and it factors without fill-in a chain of 200
    /// contacts numbered at random and an arrowhead (one body touching 199 others, the
    /// hub's row first), `2n − 1` entries, where the rows' own order fills in (the
    /// arrowhead's factor completely, `n(n + 1)/2` entries).
    #[test]
    fn the_fill_reducing_order_factors_a_chain_and_an_arrowhead_without_fill() {
        let n = 200;
        let mut label: Vec<usize> = (0..n).collect();
        let mut rng = SplitMix64::new(7);
        for i in (1..n).rev() {
            label.swap(i, rng.range(0.0, (i + 1) as f64) as usize);
        }
        let mut arrowhead = vec![0.0; n * n];
        arrowhead[0] = n as f64;
        for i in 1..n {
            arrowhead[i * n + i] = 1.0;
            arrowhead[i] = -0.5;
            arrowhead[i * n] = -0.5;
        }
        let identity: Vec<usize> = (0..n).collect();
        let cases = [
            ("chain", chain(n, &label), None),
            ("arrowhead", arrowhead, Some(n * (n + 1) / 2)),
        ];
        for (name, dense, own_order_fill) in cases {
            let a = sparse(n, &dense);
            let own = factor_entries(&a, &identity);
            assert!(own > 2 * n - 1, "{name}: {own}");
            assert!(
                own_order_fill.is_none_or(|fill| own == fill),
                "{name}: {own}"
            );
            let order = fill_reducing_order(&a);
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, identity, "{name}");
            assert_eq!(factor_entries(&a, &order), 2 * n - 1, "{name}");
        }
    }

    /// A random positive definite matrix (dense, row-major) of random couplings between
    /// random pairs, each row's diagonal above the sum of its other entries' sizes by 0.1
    /// at least.
    fn random_positive_definite(rng: &mut SplitMix64, n: usize) -> Vec<f64> {
        let mut dense = vec![0.0; n * n];
        for i in 0..n {
            dense[i * n + i] = 0.1;
        }
        for _ in 0..2 * n {
            let (i, j) = (
                rng.range(0.0, n as f64) as usize,
                rng.range(0.0, n as f64) as usize,
            );
            let v = rng.range(-1.0, 1.0);
            dense[i * n + j] += v;
            dense[j * n + i] += v;
            dense[i * n + i] += v.abs() + 0.1;
            dense[j * n + j] += v.abs() + 0.1;
        }
        dense
    }

    /// A random positive definite matrix of `n` rows, dense and sparse, and a direct
    /// solve set to it.
    fn random_problem(rng: &mut SplitMix64, n: usize) -> (Vec<f64>, SparseMatrix, DirectSolve) {
        let dense = random_positive_definite(rng, n);
        let a = sparse(n, &dense);
        let mut direct = DirectSolve::default();
        direct.new_matrix(&a);
        (dense, a, direct)
    }

    /// `mu` is nalgebra's dense Cholesky solve of `a_FF μ_F = −dq_F` on the rows where
    /// `pushing` is set (to 1e-9 relative), and zero elsewhere.
    fn check_dense_solve(dense: &[f64], n: usize, dq: &[f64], pushing: &[bool], mu: &[f64]) {
        let rows: Vec<usize> = (0..n).filter(|&i| pushing[i]).collect();
        let m = rows.len();
        let sub = nalgebra::DMatrix::from_fn(m, m, |r, c| dense[rows[r] * n + rows[c]]);
        let rhs = nalgebra::DVector::from_iterator(m, rows.iter().map(|&r| -dq[r]));
        let want = sub.cholesky().expect("positive definite").solve(&rhs);
        for (k, &r) in rows.iter().enumerate() {
            let tolerance = 1e-9 * (1.0 + want[k].abs());
            assert!(
                (mu[r] - want[k]).abs() <= tolerance,
                "row {r}: {} against {}",
                mu[r],
                want[k]
            );
        }
        assert!((0..n).filter(|&i| !pushing[i]).all(|i| mu[i] == 0.0));
    }

    /// On a random positive definite matrix (bodies of random masses, contacts between
    /// random pairs) and a random pushing set, the answer solves `a_FF μ_F = −dq_F` to the
    /// limit asked (1e-12), against nalgebra's dense Cholesky solve of the same system,
    /// and is zero off the set.
    #[test]
    fn the_answer_on_a_guess_is_the_dense_solve_of_its_rows() {
        let mut rng = SplitMix64::new(2026);
        for trial in 0..50 {
            let n = 20 + trial;
            let (dense, a, mut direct) = random_problem(&mut rng, n);
            let dq: Vec<f64> = (0..n).map(|_| rng.range(-1.0, 1.0)).collect();
            let pushing: Vec<bool> = (0..n).map(|_| rng.next_f64() < 0.7).collect();
            let limit = vec![1e-12; n];
            let mut mu = vec![f64::NAN; n];
            assert!(direct.solve(&a, &dq, &pushing, (&vec![0.0; n], &limit), &mut mu));
            check_dense_solve(&dense, n, &dq, &pushing, &mu);
        }
    }

    /// A set that differs from the factored one by a few rows left out and a few added
    /// is solved on the factored set's factor (the factored rows stay those of the first
    /// set), and its answer is the dense Cholesky solve of its own rows; one that
    /// differs by more than [`MOST_PATCHED`] rows is factored afresh.
    #[test]
    fn a_set_near_the_factored_one_is_solved_on_its_factor() {
        let mut rng = SplitMix64::new(1127);
        for trial in 0..40 {
            let n = 30 + trial;
            let (dense, a, mut direct) = random_problem(&mut rng, n);
            let first: Vec<bool> = (0..n).map(|_| rng.next_f64() < 0.7).collect();
            let limit = vec![1e-12; n];
            let zero = vec![0.0; n];
            let mut mu = vec![0.0; n];
            let dq: Vec<f64> = (0..n).map(|_| rng.range(-1.0, 1.0)).collect();
            assert!(direct.solve(&a, &dq, &first, (&zero, &limit), &mut mu));
            let factored = direct.base.clone();
            for changes in [1, 3, MOST_PATCHED, MOST_PATCHED + 1] {
                let mut pushing = first.clone();
                for _ in 0..changes {
                    // Distinct rows flipped: out of the set or into it.
                    let mut i = rng.range(0.0, n as f64) as usize;
                    while pushing[i] != first[i] {
                        i = (i + 1) % n;
                    }
                    pushing[i] = !pushing[i];
                }
                let dq: Vec<f64> = (0..n).map(|_| rng.range(-1.0, 1.0)).collect();
                assert!(direct.solve(&a, &dq, &pushing, (&zero, &limit), &mut mu));
                assert_eq!(
                    direct.base == factored,
                    changes <= MOST_PATCHED,
                    "trial {trial}"
                );
                check_dense_solve(&dense, n, &dq, &pushing, &mu);
            }
        }
    }

    /// Two contacts on the same line between the same bodies (one contact counted twice:
    /// a singular matrix) share the push they must give as the start shared it: the
    /// proximal rounds change the impulses only along what the matrix moves, so the
    /// difference the start held is kept and the answer is finite.
    #[test]
    fn a_contact_counted_twice_keeps_the_shares_it_started_with() {
        let a = sparse(2, &[1.0, 1.0, 1.0, 1.0]);
        let mut direct = DirectSolve::default();
        direct.new_matrix(&a);
        let limit = [1e-12; 2];
        let start = [0.75, 0.25];
        let mut mu = [0.0; 2];
        assert!(direct.solve(&a, &[-3.0, -3.0], &[true, true], (&start, &limit), &mut mu));
        assert!((mu[0] + mu[1] - 3.0).abs() <= 1e-9, "{mu:?}");
        assert!((mu[0] - mu[1] - 0.5).abs() <= 1e-6, "{mu:?}");
    }
}
