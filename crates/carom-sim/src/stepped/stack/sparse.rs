//! A large stack's contacts as a sparse problem: its Delassus matrix by rows of non-zero
//! entries (`sparse_lcp`), and the impulses its solves found, to start the next from.
//!
//! The dense exact solve of `lcp` costs `n²` memory and `n³` work for `n` rows: cheap for
//! the few contacts of a cluster on a floor, hopeless for a pile (the settled 480-ball
//! pile is one hold of up to 1,025 rows). A hold of more than [`SPARSE_ROWS`] rows builds only the entries
//! of rows that share a body (a ball's half-dozen contacts each) and solves them by
//! projected conjugate gradients (`sparse_lcp`), starting from the impulses the same
//! rows took last ([`Warm`]): in a pile at rest one step's impulses are nearly the
//! next's.

use std::collections::HashMap;

use carom_math::{Real, Space};
use nalgebra::Const;

use super::super::narrow::Target;
use super::super::sparse_lcp::SparseMatrix;
use super::{Push, Row, Stack, Wide};

/// Holds of more rows than this solve their contacts' problems sparsely (see the module
/// documentation); smaller ones exactly (`lcp`).
pub(crate) const SPARSE_ROWS: usize = 256;

/// A row's identity across holds and steps: its ball and what it touches (a ball, box
/// `k`, or the wall along an axis and side, `2 axis + side`). A contact of two balls is
/// keyed by the lower index first, whichever end the row has it at.
type RowKey = (u32, u8, u32);

/// The impulses sparse solves and a pile's dense ones found, per row, as forces (the
/// impulse over the rest of the step it acted over, but never less than half a step), to
/// start the next solve of the same rows from: the sparse solve from both, a dense one
/// (exact in its normal impulses) from the tangential ones, whose rounds converge
/// linearly. What one step found is kept for the next; rows not met again are forgotten.
///
/// Why not less than half a step: a hold `τ` before the step's end that stops a chord
/// closing at `u` gives an impulse of about `m u` whatever `τ`, and kept over `τ` alone
/// it made the next step start from `m u h / τ`. In a landing pile (`restitution =
/// 0.35`) a step's first hold started from 6.5e7 N s of friction and that step spun the
/// pile up by 1e7 J (`docs/stepped.md`, piles items 12 and 13; that the start came from
/// a late hold is reasoned, not printed hold by hold, and with forces kept over at least
/// half a step the same run ended at 36,897 J). Over at least half a step, a start is at
/// most twice the impulse a hold gave; holds over more (every hold at a step's start)
/// keep their forces as they were.
#[derive(Clone, Debug, Default)]
pub(crate) struct Warm<const D: usize> {
    /// Found in this step.
    current: HashMap<RowKey, (f64, Wide<D>)>,
    /// Found in the step before.
    previous: HashMap<RowKey, (f64, Wide<D>)>,
}

impl<const D: usize> Warm<D> {
    /// At the start of a step: what the last one found becomes the previous step's.
    pub(crate) fn next_step(&mut self) {
        core::mem::swap(&mut self.current, &mut self.previous);
        self.current.clear();
    }

    /// Starts a solve of `rows` acting over `rest` from the impulses each took last (none
    /// for a row not met before), tangential ones only `with_friction`.
    pub(super) fn start<'a, T: Real + 'a>(
        &self,
        rows: impl Iterator<Item = &'a Row<T, D>>,
        rest: f64,
        with_friction: bool,
        lambda: &mut [f64],
        tangential: &mut [Wide<D>],
    ) {
        for ((l, t), row) in lambda.iter_mut().zip(tangential).zip(rows) {
            let (key, sign) = row_key(row);
            let last = self.current.get(&key).or_else(|| self.previous.get(&key));
            (*l, *t) = last.map_or((0.0, Wide::zeros()), |&(l, t)| {
                (l * rest, t * (rest * sign))
            });
            if !with_friction {
                *t = Wide::zeros();
            }
        }
    }

    /// Keeps the impulses `lambda` and `tangential` that `rows` took acting over `rest`
    /// of a step of length `step`.
    pub(super) fn keep<'a, T: Real + 'a>(
        &mut self,
        rows: impl Iterator<Item = &'a Row<T, D>>,
        (rest, step): (f64, f64),
        lambda: &[f64],
        tangential: &[Wide<D>],
    ) {
        let over = rest.max(0.5 * step);
        for ((&l, t), row) in lambda.iter().zip(tangential).zip(rows) {
            let (key, sign) = row_key(row);
            self.current.insert(key, (l / over, t * (sign / over)));
        }
    }
}

/// Row `row`'s identity ([`RowKey`]), and the sign its tangential impulse takes there:
/// `−1` where the key names the row's other ball first (the impulse on the row's ball is
/// the opposite of the one on the key's).
fn row_key<T: Real, const D: usize>(row: &Row<T, D>) -> (RowKey, f64) {
    let ball = row.end.ball as u32;
    match row.target {
        Target::Ball(j) if j < ball => ((j, 0, ball), -1.0),
        Target::Ball(j) => ((ball, 0, j), 1.0),
        Target::Box(k) => ((ball, 1, k), 1.0),
        Target::Border => {
            let axis = (0..D).find(|&a| row.normal[a] != T::zero()).unwrap_or(0);
            let side = 2 * axis as u32 + u32::from(row.normal[axis] > T::zero());
            ((ball, 2, side), 1.0)
        }
    }
}

impl<T: Real, const D: usize> Stack<T, D>
where
    Const<D>: Space<T, D>,
{
    /// The Delassus matrix of `rows` ([`Stack::delassus`]'s entries) by rows of its
    /// non-zero entries: only rows that share a body couple.
    pub(super) fn sparse_delassus(&self, rows: &[usize], push: Push) -> SparseMatrix {
        let mut by_part: Vec<Vec<usize>> = vec![Vec::new(); self.parts.len()];
        for (k, &c) in rows.iter().enumerate() {
            for (e, _) in self.ends(c) {
                by_part[e.part].push(k);
            }
        }
        let mut a = SparseMatrix::new();
        let mut column = vec![usize::MAX; rows.len()];
        let mut entries: Vec<(usize, f64)> = Vec::new();
        for &c in rows {
            entries.clear();
            for (ec, _) in self.ends(c) {
                for &l in &by_part[ec.part] {
                    if column[l] == usize::MAX {
                        column[l] = entries.len();
                        entries.push((l, self.coupling(c, rows[l], push)));
                    }
                }
            }
            entries.sort_unstable_by_key(|&(l, _)| l);
            for &(l, v) in &entries {
                column[l] = usize::MAX;
                a.push(l, v);
            }
            a.end_row();
        }
        a
    }
}

#[cfg(test)]
mod tests {
    use super::super::{End, Other};
    use super::*;
    use nalgebra::Vector2;

    /// A contact of ball `ball` with `target` along `normal`.
    fn row(ball: usize, target: Target, normal: Vector2<f64>) -> Row<f64, 2> {
        Row {
            end: End {
                part: 0,
                ball,
                arm: -normal * 0.25,
                lever: -normal * 0.25,
            },
            other: Other::Surface(Vector2::zeros()),
            target,
            normal,
            gap: 0.0,
        }
    }

    /// Starts `rows` over `rest` from what `warm` kept.
    fn started(warm: &Warm<2>, rows: &[Row<f64, 2>], rest: f64) -> (Vec<f64>, Vec<Wide<2>>) {
        let mut lambda = vec![f64::NAN; rows.len()];
        let mut tangential = vec![Wide::repeat(f64::NAN); rows.len()];
        warm.start(rows.iter(), rest, true, &mut lambda, &mut tangential);
        (lambda, tangential)
    }

    /// A step's first hold acts over the whole step: the next step's first starts from
    /// its impulses as they were, the tangential one on a contact of two balls seen
    /// from either ball (each takes the other's opposite).
    #[test]
    fn a_whole_steps_impulses_start_the_next_step_as_they_were() {
        let h = 1.0 / 60.0;
        let up = Vector2::new(0.0, 1.0);
        let floor = row(3, Target::Border, up);
        let (lower, upper) = (row(1, Target::Ball(5), up), row(5, Target::Ball(1), -up));
        let mut warm = Warm::<2>::default();
        let t = Vector2::new(0.1, 0.0);
        warm.keep(
            [&floor, &lower].into_iter(),
            (h, h),
            &[0.5, 0.25],
            &[t, t * 2.0],
        );
        warm.next_step();
        let (lambda, tangential) = started(&warm, &[floor, upper, row(7, Target::Border, up)], h);
        assert_eq!(lambda, [0.5, 0.25, 0.0]);
        assert_eq!(tangential, [t, -t * 2.0, Wide::zeros()]);
        // Rows not met in a step are forgotten after it.
        warm.next_step();
        warm.next_step();
        assert_eq!(started(&warm, &[floor], h).0, [0.0]);
    }

    /// A hold `h / 100` before the step's end stops a landing 1 kg ball closing at 2 m/s
    /// with 2 N s: over that rest alone it was a force of 12,000 N, and the next step
    /// started from 200 N s (`docs/stepped.md`, piles item 13). Over half a step, it
    /// starts from twice the impulse at most.
    #[test]
    fn a_late_holds_impulse_starts_the_next_step_at_most_doubled() {
        let h = 1.0 / 60.0;
        let floor = row(3, Target::Border, Vector2::new(0.0, 1.0));
        let mut warm = Warm::<2>::default();
        let t = Vector2::new(-0.5, 0.0);
        warm.keep([&floor].into_iter(), (h / 100.0, h), &[2.0], &[t]);
        warm.next_step();
        let (lambda, tangential) = started(&warm, &[floor], h);
        assert!(
            (lambda[0] - 4.0).abs() <= 1e-12,
            "started from {} N s",
            lambda[0]
        );
        assert!((tangential[0] - t * 2.0).norm() <= 1e-12, "{tangential:?}");
    }
}
