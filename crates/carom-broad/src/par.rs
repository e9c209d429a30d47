//! Order-preserving data-parallel helpers for the update passes.
//!
//! Each helper computes the same values in the same order whether it runs on the rayon
//! pool or not (element-wise maps, and maxima, which are exact in any order), so a
//! parallel update leaves a broad phase in exactly the state a sequential one does.
//! Without the `parallel` feature, or for short inputs, they run sequentially.
//!
//! On the pool, the work is split into a few chunks of consecutive indices per thread,
//! each running the same plain loop as the sequential path: the per-element closure is
//! then inlined (and vectorized) as it is sequentially, instead of being called once
//! per element through rayon's adaptors, which cost about a quarter more instructions
//! per update (measured with callgrind on the grid).

#[cfg(feature = "parallel")]
use rayon::prelude::*;

/// Below this many elements a pass stays on the calling thread.
#[cfg(feature = "parallel")]
pub(crate) const MIN_PARALLEL: usize = 8192;

/// The length of the chunks `n` elements are split into on the pool.
#[cfg(feature = "parallel")]
fn chunk_len(n: usize) -> usize {
    n.div_ceil(crate::parallel_chunks()).max(1)
}

/// Makes `v` exactly `f(0), …, f(n − 1)`, reusing its buffer. On the pool, elements
/// the buffer already holds are overwritten in place (no extra pass over them).
#[cfg_attr(not(feature = "parallel"), allow(unused_variables))]
pub(crate) fn fill_indexed<X: Send + Sync + Copy>(
    v: &mut Vec<X>,
    n: usize,
    parallel: bool,
    f: impl Fn(usize) -> X + Sync + Send,
) {
    #[cfg(feature = "parallel")]
    if parallel && n >= MIN_PARALLEL {
        v.truncate(n);
        if v.len() < n {
            v.resize(n, f(0));
        }
        let len = chunk_len(n);
        v.par_chunks_mut(len).enumerate().for_each(|(c, out)| {
            for (k, x) in out.iter_mut().enumerate() {
                *x = f(c * len + k);
            }
        });
        return;
    }
    v.clear();
    v.extend((0..n).map(f));
}

/// Replaces every element `x` of `v` by `f(x)`.
#[cfg_attr(not(feature = "parallel"), allow(unused_variables))]
pub(crate) fn map_in_place<X: Send + Copy>(
    v: &mut [X],
    parallel: bool,
    f: impl Fn(X) -> X + Sync + Send,
) {
    #[cfg(feature = "parallel")]
    if parallel && v.len() >= MIN_PARALLEL {
        let len = chunk_len(v.len());
        v.par_chunks_mut(len).for_each(|out| {
            for x in out {
                *x = f(*x);
            }
        });
        return;
    }
    for x in v {
        *x = f(*x);
    }
}

/// Replaces every element `x` of `v` by `f(x)` while `f` returns `Some`; `false` (with
/// `v` partly mapped) if it returned `None` for some element.
#[cfg_attr(not(feature = "parallel"), allow(unused_variables))]
pub(crate) fn try_map_in_place<X: Send + Copy>(
    v: &mut [X],
    parallel: bool,
    f: impl Fn(X) -> Option<X> + Sync + Send,
) -> bool {
    let map = |out: &mut [X]| out.iter_mut().all(|x| f(*x).map(|y| *x = y).is_some());
    #[cfg(feature = "parallel")]
    if parallel && v.len() >= MIN_PARALLEL {
        let len = chunk_len(v.len());
        return v.par_chunks_mut(len).all(map);
    }
    map(v)
}

/// `fold` over `0..n` from `init()`, the partial results of parallel chunks combined
/// with `merge`. For order-independent folds (maxima, minima) the result is the same
/// sequentially and on any number of threads.
#[cfg_attr(not(feature = "parallel"), allow(unused_variables))]
pub(crate) fn fold_indexed<A: Send>(
    n: usize,
    parallel: bool,
    init: impl Fn() -> A + Sync + Send,
    fold: impl Fn(A, usize) -> A + Sync + Send,
    merge: impl Fn(A, A) -> A + Sync + Send,
) -> A {
    #[cfg(feature = "parallel")]
    if parallel && n >= MIN_PARALLEL {
        let len = chunk_len(n);
        return (0..n.div_ceil(len))
            .into_par_iter()
            .map(|c| (c * len..((c + 1) * len).min(n)).fold(init(), &fold))
            .reduce(&init, &merge);
    }
    (0..n).fold(init(), fold)
}

/// The largest of `f(0), …, f(n − 1)` and `0` (NaN-free input).
pub(crate) fn max_indexed(n: usize, parallel: bool, f: impl Fn(usize) -> f64 + Sync + Send) -> f64 {
    fold_indexed(n, parallel, || 0.0, |m, i| f64::max(m, f(i)), f64::max)
}
