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
//! matrix's own order; the rows are put in reverse Cuthill–McKee order first (a
//! breadth-first order of the contact graph, reversed, which confines the factor's
//! fill-in to a band: a shuffled chain goes back to bandwidth 1, tested). A
//! factorisation is kept while the matrix and the guess stay the same (a pile's
//! friction rounds).

use nalgebra::DMatrix;
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

/// A set of pushing contacts and its factorisation, for one matrix.
#[derive(Clone, Default)]
pub(super) struct DirectSolve {
    /// The rows in reverse Cuthill–McKee order.
    order: Vec<usize>,
    /// The rows of the factorisation kept, in that order (`F`).
    rows: Vec<usize>,
    /// Their shifted matrix `a_FF + εI` and its factor, `None` when that could not be
    /// factored.
    factor: Option<(CscMatrix<f64>, CscCholesky<f64>)>,
    /// Whether `rows` and `factor` are those of the current matrix.
    kept: bool,
    /// A row's index among `rows`, `usize::MAX` when not among them.
    index: Vec<usize>,
}

impl core::fmt::Debug for DirectSolve {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("DirectSolve")
            .field("rows", &self.rows.len())
            .field("factored", &self.factor.is_some())
            .finish_non_exhaustive()
    }
}

impl DirectSolve {
    /// Forgets the factorisation and orders the rows of the new matrix `a`.
    pub(super) fn new_matrix(&mut self, a: &SparseMatrix) {
        self.order = reverse_cuthill_mckee(a);
        self.kept = false;
        self.factor = None;
        self.rows.clear();
        self.index.clear();
        self.index.resize(a.rows(), usize::MAX);
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
            self.factor_rows(a, pushing);
        }
        let Some((shifted, factor)) = &self.factor else {
            return false;
        };
        let m = self.rows.len();
        let mut x = DMatrix::from_iterator(m, 1, self.rows.iter().map(|&r| start[r].max(0.0)));
        let mut residual = vec![0.0; m];
        for _ in 0..PROXIMAL_ROUNDS {
            // x ← argmin ½ xᵀAx + dqᵀx + ½ε|x − x_k|²: (A + εI) x = ε x_k − dq.
            for (v, &r) in x.iter_mut().zip(&self.rows) {
                *v = PROXIMAL * *v - dq[r];
            }
            factor.solve_mut(&mut x);
            if !x.iter().all(|v| v.is_finite()) {
                return false;
            }
            // a_FF x = (a_FF + εI) x − ε x.
            for (g, &v) in residual.iter_mut().zip(x.iter()) {
                *g = -PROXIMAL * v;
            }
            for (k, column) in shifted.col_iter().enumerate() {
                for (&row, &v) in column.row_indices().iter().zip(column.values()) {
                    residual[row] += v * x[k];
                }
            }
            if (residual.iter().zip(&self.rows))
                .all(|(&g, &r)| (g + dq[r]).abs() <= PRECISE * limit[r])
            {
                break;
            }
        }
        mu.fill(0.0);
        for (&r, &v) in self.rows.iter().zip(x.iter()) {
            mu[r] = v;
        }
        true
    }

    /// Factors `a_FF + εI` for the rows where `pushing` is set, in the kept order.
    fn factor_rows(&mut self, a: &SparseMatrix, pushing: &[bool]) {
        for &r in &self.rows {
            self.index[r] = usize::MAX;
        }
        self.rows.clear();
        self.rows
            .extend(self.order.iter().copied().filter(|&r| pushing[r]));
        for (k, &r) in self.rows.iter().enumerate() {
            self.index[r] = k;
        }
        // `a` is symmetric: its rows restricted to F, in F's order, are the columns of
        // a_FF in compressed-column form; ε goes on the diagonal as they are copied.
        let mut offsets = Vec::with_capacity(self.rows.len() + 1);
        let (mut indices, mut values) = (Vec::new(), Vec::new());
        let mut entries: Vec<(usize, f64)> = Vec::new();
        offsets.push(0);
        for &r in &self.rows {
            entries.clear();
            let own = self.index[r];
            entries.extend(
                a.row(r)
                    .filter(|&(c, _)| self.index[c] != usize::MAX)
                    .map(|(c, v)| {
                        let k = self.index[c];
                        (k, if k == own { v + PROXIMAL } else { v })
                    }),
            );
            entries.sort_unstable_by_key(|&(k, _)| k);
            indices.extend(entries.iter().map(|&(k, _)| k));
            values.extend(entries.iter().map(|&(_, v)| v));
            offsets.push(indices.len());
        }
        let m = self.rows.len();
        self.kept = true;
        self.factor = CscMatrix::try_from_csc_data(m, m, offsets, indices, values)
            .ok()
            .and_then(|shifted| {
                let factor = CscCholesky::factor(&shifted).ok()?;
                Some((shifted, factor))
            });
    }
}

/// The rows of `a` in reverse Cuthill–McKee order: each connected part of its graph
/// breadth-first from a row of least degree, a row's unvisited neighbours by ascending
/// degree (ties by index), the whole reversed. A band-limiting order: a row's neighbours
/// come at most about one breadth-first layer away.
fn reverse_cuthill_mckee(a: &SparseMatrix) -> Vec<usize> {
    let n = a.rows();
    let degree: Vec<usize> = (0..n).map(|r| a.row(r).count()).collect();
    let mut by_degree: Vec<usize> = (0..n).collect();
    by_degree.sort_by_key(|&r| (degree[r], r));
    let mut seen = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut next: Vec<usize> = Vec::new();
    for &root in &by_degree {
        if seen[root] {
            continue;
        }
        seen[root] = true;
        let mut k = order.len();
        order.push(root);
        while k < order.len() {
            let r = order[k];
            next.clear();
            next.extend(a.row(r).map(|(c, _)| c).filter(|&c| !seen[c]));
            next.sort_by_key(|&c| (degree[c], c));
            for &c in &next {
                seen[c] = true;
                order.push(c);
            }
            k += 1;
        }
    }
    order.reverse();
    order
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

    /// The widest distance between a row and a column of a non-zero entry, with the rows
    /// put in `order`.
    fn bandwidth(a: &SparseMatrix, order: &[usize]) -> usize {
        let mut at = vec![0; order.len()];
        for (k, &r) in order.iter().enumerate() {
            at[r] = k;
        }
        (0..a.rows())
            .flat_map(|r| a.row(r).map(move |(c, _)| (r, c)))
            .map(|(r, c)| at[r].abs_diff(at[c]))
            .max()
            .unwrap_or(0)
    }

    /// A chain of 200 contacts numbered at random (bandwidth in the hundreds) is put back
    /// in chain order, every row once: bandwidth 1.
    #[test]
    fn reverse_cuthill_mckee_orders_a_shuffled_chain_into_a_band() {
        let n = 200;
        let mut label: Vec<usize> = (0..n).collect();
        let mut rng = SplitMix64::new(7);
        for i in (1..n).rev() {
            label.swap(i, rng.range(0.0, (i + 1) as f64) as usize);
        }
        let a = sparse(n, &chain(n, &label));
        let identity: Vec<usize> = (0..n).collect();
        assert!(bandwidth(&a, &identity) > 100);
        let order = reverse_cuthill_mckee(&a);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, identity);
        assert_eq!(bandwidth(&a, &order), 1);
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
            // Random couplings, each row's diagonal above the sum of its row's other
            // entries' sizes by 0.1 at least: positive definite.
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
            let a = sparse(n, &dense);
            let dq: Vec<f64> = (0..n).map(|_| rng.range(-1.0, 1.0)).collect();
            let pushing: Vec<bool> = (0..n).map(|_| rng.next_f64() < 0.7).collect();
            let rows: Vec<usize> = (0..n).filter(|&i| pushing[i]).collect();
            let m = rows.len();
            let sub = nalgebra::DMatrix::from_fn(m, m, |r, c| dense[rows[r] * n + rows[c]]);
            let rhs = nalgebra::DVector::from_iterator(m, rows.iter().map(|&r| -dq[r]));
            let want = sub.cholesky().expect("positive definite").solve(&rhs);
            let mut direct = DirectSolve::default();
            direct.new_matrix(&a);
            let limit = vec![1e-12; n];
            let mut mu = vec![f64::NAN; n];
            assert!(direct.solve(&a, &dq, &pushing, (&vec![0.0; n], &limit), &mut mu));
            for (k, &r) in rows.iter().enumerate() {
                let tolerance = 1e-9 * (1.0 + want[k].abs());
                assert!(
                    (mu[r] - want[k]).abs() <= tolerance,
                    "trial {trial}, row {r}: {} against {}",
                    mu[r],
                    want[k]
                );
            }
            assert!((0..n).filter(|&i| !pushing[i]).all(|i| mu[i] == 0.0));
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
