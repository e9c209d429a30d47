//! Order-preserving data-parallel helpers for the update passes.
//!
//! Each helper computes the same values in the same order whether it runs on the rayon
//! pool or not (element-wise maps, and maxima, which are exact in any order), so a
//! parallel update leaves a broad phase in exactly the state a sequential one does.
//! Without the `parallel` feature, or for short inputs, they run sequentially.

/// Below this many elements a pass stays on the calling thread.
#[cfg(feature = "parallel")]
pub(crate) const MIN_PARALLEL: usize = 8192;

/// Appends `f(0), …, f(n − 1)` to `v`, in order.
#[cfg_attr(not(feature = "parallel"), allow(unused_variables))]
pub(crate) fn extend_indexed<X: Send>(
    v: &mut Vec<X>,
    n: usize,
    parallel: bool,
    f: impl Fn(usize) -> X + Sync + Send,
) {
    #[cfg(feature = "parallel")]
    if parallel && n >= MIN_PARALLEL {
        use rayon::prelude::*;
        v.par_extend((0..n).into_par_iter().map(f));
        return;
    }
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
        use rayon::prelude::*;
        v.par_iter_mut().for_each(|x| *x = f(*x));
        return;
    }
    for x in v {
        *x = f(*x);
    }
}

/// Replaces every element `x` of `v` by `f(x)` while `f` returns `Some`; `false` (with
/// `v` partly mapped) as soon as it returns `None`.
#[cfg_attr(not(feature = "parallel"), allow(unused_variables))]
pub(crate) fn try_map_in_place<X: Send + Copy>(
    v: &mut [X],
    parallel: bool,
    f: impl Fn(X) -> Option<X> + Sync + Send,
) -> bool {
    let step = |x: &mut X| f(*x).map(|y| *x = y).is_some();
    #[cfg(feature = "parallel")]
    if parallel && v.len() >= MIN_PARALLEL {
        use rayon::prelude::*;
        return v.par_iter_mut().all(step);
    }
    v.iter_mut().all(step)
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
        use rayon::prelude::*;
        return (0..n)
            .into_par_iter()
            .fold(&init, &fold)
            .reduce(&init, &merge);
    }
    (0..n).fold(init(), fold)
}

/// The largest of `f(0), …, f(n − 1)` and `0` (NaN-free input).
#[cfg_attr(not(feature = "parallel"), allow(unused_variables))]
pub(crate) fn max_indexed(n: usize, parallel: bool, f: impl Fn(usize) -> f64 + Sync + Send) -> f64 {
    #[cfg(feature = "parallel")]
    if parallel && n >= MIN_PARALLEL {
        use rayon::prelude::*;
        return (0..n).into_par_iter().map(f).reduce(|| 0.0, f64::max);
    }
    (0..n).map(f).fold(0.0, f64::max)
}
