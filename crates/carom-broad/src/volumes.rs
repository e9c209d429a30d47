//! The input of every broad phase: bounding volumes as boxes or as balls, and the exact
//! overlap predicate all implementations share.
//!
//! Callers hand a broad phase a [`Volumes`] view each frame: either a slice of
//! [`Aabb`]s, or [`Balls`], the struct-of-arrays a stepped engine already keeps
//! (`&[Vector<T, D>]` centres and `&[T]` radii, plus an optional margin added to every
//! radius, e.g. half a neighbour-list shell). Nothing is converted by the caller; each
//! broad phase copies what it needs into its own reused storage, so an update does not
//! allocate once the buffers have grown to the scene's size.
//!
//! Internally every volume becomes a [`Proxy`]: its box, its centre and its bounding
//! radius (the ball's radius, or a box's half diagonal). Two volumes overlap when
//! [`overlap`] says so, and every implementation (brute force included) calls that one
//! function, so they agree bit for bit:
//!
//! * boxes: `a.min[k] <= b.max[k] && b.min[k] <= a.max[k]` on every axis, exactly
//!   [`BoundingVolume::intersects`](carom_geometry::BoundingVolume::intersects) for
//!   [`Aabb`]: touching boxes overlap;
//! * balls: their boxes overlap **and** `|c_a − c_b|² <= (r_a + r_b)²`, both in `T`.
//!   The box test is implied by the sphere test up to one rounding at exact tangency;
//!   requiring both makes the predicate identical in every implementation, whatever
//!   culling it did before;
//! * in a periodic domain (grid and brute force only) the separation of centres is
//!   the minimum image, and boxes overlap when `|Δ_k| <= h_a[k] + h_b[k]` per axis.

use carom_geometry::{Aabb, Border, BoundingVolume};
use carom_math::{InvalidValue, Problem, Real, Vector, ensure_finite_vector, ensure_non_negative};

use crate::par::fill_indexed;

/// Bounding volumes for one update: boxes or balls.
#[derive(Clone, Copy, Debug)]
pub enum Volumes<'a, T: Real, const D: usize> {
    /// Axis-aligned boxes; pairs are box overlaps.
    Boxes(&'a [Aabb<T, D>]),
    /// Balls as centres and radii; pairs are ball overlaps.
    Balls(Balls<'a, T, D>),
}

impl<'a, T: Real, const D: usize> Volumes<'a, T, D> {
    /// Boxes, indexed by their position in the slice.
    ///
    /// # Errors
    /// `boxes` with [`Problem::OutOfRange`] if there are more than `u32::MAX` of them
    /// (pair indices are `u32`).
    pub fn boxes(boxes: &'a [Aabb<T, D>]) -> Result<Self, InvalidValue> {
        ensure_u32_count("boxes", boxes.len())?;
        Ok(Self::Boxes(boxes))
    }

    /// The number of volumes.
    pub fn len(&self) -> usize {
        match self {
            Self::Boxes(b) => b.len(),
            Self::Balls(b) => b.len(),
        }
    }

    /// `true` if there are no volumes.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl<'a, T: Real, const D: usize> From<Balls<'a, T, D>> for Volumes<'a, T, D> {
    fn from(balls: Balls<'a, T, D>) -> Self {
        Self::Balls(balls)
    }
}

/// Balls in struct-of-arrays form, borrowed from the caller.
///
/// Ball `i` has centre `centers[i]` and radius `radii[i] + margin`.
#[derive(Clone, Copy, Debug)]
pub struct Balls<'a, T: Real, const D: usize> {
    centers: &'a [Vector<T, D>],
    radii: &'a [T],
    margin: T,
}

impl<'a, T: Real, const D: usize> Balls<'a, T, D> {
    /// Checks every value: equal lengths, finite centres, finite radii `>= 0`.
    ///
    /// This is one pass over the data; engines whose state is already validated use
    /// [`Balls::new_unchecked`] in their step.
    ///
    /// # Errors
    /// `radii` ([`Problem::OutOfRange`]) if the lengths differ or exceed `u32::MAX`,
    /// `centers[i][k]` or `radii[i]` for the first bad value.
    pub fn new(centers: &'a [Vector<T, D>], radii: &'a [T]) -> Result<Self, InvalidValue> {
        ensure_u32_count("centers", centers.len())?;
        if radii.len() != centers.len() {
            return Err(InvalidValue::new(
                "radii",
                Problem::OutOfRange {
                    value: radii.len() as f64,
                    min: centers.len() as f64,
                    max: centers.len() as f64,
                },
            ));
        }
        for (i, (c, &r)) in centers.iter().zip(radii).enumerate() {
            ensure_finite_vector("center", c).map_err(|e| e.within(&format!("centers[{i}]")))?;
            ensure_non_negative("radius", r).map_err(|e| e.within(&format!("radii[{i}]")))?;
        }
        Ok(Self {
            centers,
            radii,
            margin: T::zero(),
        })
    }

    /// Balls from data the caller has validated (debug builds check lengths and values).
    #[inline]
    pub fn new_unchecked(centers: &'a [Vector<T, D>], radii: &'a [T]) -> Self {
        debug_assert!(centers.len() == radii.len() && u32::try_from(centers.len()).is_ok());
        debug_assert!(radii.iter().all(|r| r.finite() && *r >= T::zero()));
        debug_assert!(centers.iter().all(|c| c.iter().all(|x| x.finite())));
        Self {
            centers,
            radii,
            margin: T::zero(),
        }
    }

    /// The same balls with `margin` added to every radius: `margin = shell / 2` turns
    /// the overlapping pairs into neighbour lists with a shell
    /// (`|c_i − c_j| <= r_i + r_j + shell`).
    ///
    /// # Errors
    /// `margin` if not finite or negative.
    pub fn with_margin(self, margin: T) -> Result<Self, InvalidValue> {
        Ok(Self {
            margin: ensure_non_negative("margin", margin)?,
            ..self
        })
    }

    /// The number of balls.
    pub fn len(&self) -> usize {
        self.centers.len()
    }

    /// `true` if there are no balls.
    pub fn is_empty(&self) -> bool {
        self.centers.is_empty()
    }
}

/// `Ok(ratio)` for an oversize ratio `>= 1` (`+inf` allowed: nothing is oversized).
pub(crate) fn ensure_ratio(ratio: f64) -> Result<f64, InvalidValue> {
    // Written so that NaN fails too.
    if ratio >= 1.0 {
        Ok(ratio)
    } else {
        Err(InvalidValue::new(
            "ratio",
            Problem::OutOfRange {
                value: ratio,
                min: 1.0,
                max: f64::INFINITY,
            },
        ))
    }
}

fn ensure_u32_count(field: &'static str, n: usize) -> Result<(), InvalidValue> {
    if u32::try_from(n).is_ok() {
        Ok(())
    } else {
        Err(InvalidValue::new(
            field,
            Problem::OutOfRange {
                value: n as f64,
                min: 0.0,
                max: f64::from(u32::MAX),
            },
        ))
    }
}

/// One volume as the broad phases store it: box, centre and bounding radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Proxy<T: Real, const D: usize> {
    /// The axis-aligned box (a ball's is `c ± r`).
    pub(crate) aabb: Aabb<T, D>,
    /// The ball's centre, or the box's centre.
    pub(crate) center: Vector<T, D>,
    /// The ball's radius, or the box's half diagonal (rounded up): every point of the
    /// volume is within this distance of `center`.
    pub(crate) radius: T,
}

impl<T: Real, const D: usize> Proxy<T, D> {
    fn from_box(aabb: &Aabb<T, D>) -> Self {
        let half = aabb.half_extents();
        Self {
            aabb: *aabb,
            center: aabb.center(),
            // One ulp up covers the rounding of the norm and of the centre.
            radius: half.norm() * (T::one() + T::lit(4.0) * T::EPSILON),
        }
    }

    fn from_ball(center: &Vector<T, D>, radius: T) -> Self {
        let r = Vector::<T, D>::repeat(radius);
        Self {
            aabb: Aabb::new_unchecked(center - r, center + r),
            center: *center,
            radius,
        }
    }

    /// The largest edge length of the box.
    #[inline]
    pub(crate) fn extent(&self) -> T {
        let (lo, hi) = (self.aabb.min(), self.aabb.max());
        (0..D).fold(T::zero(), |m, k| m.max(hi[k] - lo[k]))
    }
}

/// `true` if the boxes overlap or touch (`BoundingVolume::intersects` for `Aabb`).
#[inline]
pub(crate) fn boxes_overlap<T: Real, const D: usize>(a: &Aabb<T, D>, b: &Aabb<T, D>) -> bool {
    let (amin, amax, bmin, bmax) = (a.min(), a.max(), b.min(), b.max());
    (0..D).all(|k| amin[k] <= bmax[k] && bmin[k] <= amax[k])
}

/// The exact overlap predicate shared by every broad phase (see the module docs).
#[inline]
pub(crate) fn overlap<T: Real, const D: usize>(
    a: &Proxy<T, D>,
    b: &Proxy<T, D>,
    balls: bool,
    period: Option<&Vector<T, D>>,
) -> bool {
    match period {
        None => {
            boxes_overlap(&a.aabb, &b.aabb)
                && (!balls || {
                    let r = a.radius + b.radius;
                    (a.center - b.center).norm_squared() <= r * r
                })
        }
        Some(period) => {
            let delta = minimum_image(&(b.center - a.center), period);
            let (ha, hb) = (a.aabb.half_extents(), b.aabb.half_extents());
            (0..D).all(|k| delta[k].abs() <= ha[k] + hb[k])
                && (!balls || {
                    let r = a.radius + b.radius;
                    delta.norm_squared() <= r * r
                })
        }
    }
}

/// The minimum image of a separation: each component shifted by whole periods into
/// `[−L/2, L/2]` (the formula of [`Border::minimum_image`]; `round` is symmetric, so
/// the image of `−Δ` is exactly `−(image of Δ)` and the predicate is symmetric).
#[inline]
pub(crate) fn minimum_image<T: Real, const D: usize>(
    delta: &Vector<T, D>,
    period: &Vector<T, D>,
) -> Vector<T, D> {
    Vector::<T, D>::from_fn(|k, _| delta[k] - period[k] * (delta[k] / period[k]).round())
}

/// The squared distance from `p` to the box (0 inside).
#[inline]
fn box_distance_squared<T: Real, const D: usize>(aabb: &Aabb<T, D>, p: &Vector<T, D>) -> T {
    let (lo, hi) = (aabb.min(), aabb.max());
    (0..D).fold(T::zero(), |s, k| {
        let d = (lo[k] - p[k]).max(p[k] - hi[k]).max(T::zero());
        s + d * d
    })
}

/// The median of `value(0..n)`, estimated from at most 1025 evenly strided samples (all
/// of them when `n <= 1025`). It only sizes cells and oversize thresholds, which affect
/// speed, never results; being a function of the input alone, it keeps results
/// deterministic.
pub(crate) fn sampled_median(
    n: usize,
    value: impl Fn(usize) -> f64,
    scratch: &mut Vec<f64>,
) -> f64 {
    scratch.clear();
    if n == 0 {
        return 0.0;
    }
    let stride = n.div_ceil(1025);
    scratch.extend((0..n).step_by(stride).map(value));
    let mid = scratch.len() / 2;
    *scratch.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// The volumes of the current frame, in index order, with the predicate settings.
#[derive(Clone, Debug, Default)]
pub(crate) struct Store<T: Real, const D: usize> {
    pub(crate) proxies: Vec<Proxy<T, D>>,
    /// `true` when the volumes are balls (the sphere test applies).
    pub(crate) balls: bool,
    /// The periods of a periodic domain.
    pub(crate) period: Option<Vector<T, D>>,
    /// The caller's index of each volume when this store holds a subset of another
    /// (a coarser grid level); empty when the indices are the caller's already.
    pub(crate) global: Vec<u32>,
}

impl<T: Real, const D: usize> Store<T, D> {
    /// Copies the volumes in (reusing the buffer).
    pub(crate) fn load(&mut self, volumes: Volumes<'_, T, D>, parallel: bool) {
        self.global.clear();
        match volumes {
            Volumes::Boxes(boxes) => {
                self.balls = false;
                fill_indexed(&mut self.proxies, boxes.len(), parallel, |i| {
                    Proxy::from_box(&boxes[i])
                });
            }
            Volumes::Balls(b) => {
                self.balls = true;
                fill_indexed(&mut self.proxies, b.len(), parallel, |i| {
                    Proxy::from_ball(&b.centers[i], b.radii[i] + b.margin)
                });
            }
        }
    }

    /// Copies the volumes `ids` of `parent` (with their caller indices and settings).
    pub(crate) fn load_subset(&mut self, parent: &Self, ids: &[u32], parallel: bool) {
        self.balls = parent.balls;
        self.period = parent.period;
        fill_indexed(&mut self.proxies, ids.len(), parallel, |x| {
            parent.proxies[ids[x] as usize]
        });
        fill_indexed(&mut self.global, ids.len(), parallel, |x| {
            parent.gid(ids[x])
        });
    }

    /// The caller's index of volume `i`.
    #[inline]
    pub(crate) fn gid(&self, i: u32) -> u32 {
        if self.global.is_empty() {
            i
        } else {
            self.global[i as usize]
        }
    }

    /// The periodic domain, if any.
    pub(crate) fn set_period(&mut self, border: Option<&Border<T, D>>) {
        self.period = border.map(Border::extents);
    }

    /// The number of volumes.
    pub(crate) fn len(&self) -> usize {
        self.proxies.len()
    }

    /// The exact predicate for volumes `i` and `j`.
    #[inline]
    pub(crate) fn overlap(&self, i: usize, j: usize) -> bool {
        overlap(
            &self.proxies[i],
            &self.proxies[j],
            self.balls,
            self.period.as_ref(),
        )
    }

    /// `true` if volume `j` intersects the query box (touching counts).
    #[inline]
    pub(crate) fn hits_box(&self, j: usize, query: &Aabb<T, D>) -> bool {
        let p = &self.proxies[j];
        let q = Proxy {
            aabb: *query,
            center: query.center(),
            radius: T::zero(),
        };
        match &self.period {
            None => {
                boxes_overlap(&p.aabb, query)
                    && (!self.balls
                        || box_distance_squared(query, &p.center) <= p.radius * p.radius)
            }
            Some(period) => {
                // Move the query to the image nearest to the volume, then test as usual.
                let shift = minimum_image(&(q.center - p.center), period) - (q.center - p.center);
                let moved = query.translated(&shift);
                boxes_overlap(&p.aabb, &moved)
                    && (!self.balls
                        || box_distance_squared(&moved, &p.center) <= p.radius * p.radius)
            }
        }
    }

    /// `true` if volume `j` intersects the ball `(center, radius)` (touching counts).
    #[inline]
    pub(crate) fn hits_ball(&self, j: usize, center: &Vector<T, D>, radius: T) -> bool {
        let p = &self.proxies[j];
        let c = match &self.period {
            None => *center,
            Some(period) => p.center + minimum_image(&(center - p.center), period),
        };
        let r = Vector::<T, D>::repeat(radius);
        if !radius.finite()
            || radius < T::zero()
            || !boxes_overlap(&p.aabb, &Aabb::new_unchecked(c - r, c + r))
        {
            return false;
        }
        if self.balls {
            let s = p.radius + radius;
            (p.center - c).norm_squared() <= s * s
        } else {
            box_distance_squared(&p.aabb, &c) <= radius * radius
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn balls_validation_names_the_field() {
        let c = [Vector2::new(0.0, 0.0), Vector2::new(1.0, f64::NAN)];
        let e = Balls::new(&c, &[1.0, 1.0]).unwrap_err();
        assert_eq!(e.field, "centers[1].center[1]");
        let c = [Vector2::new(0.0, 0.0)];
        assert_eq!(
            Balls::new(&c, &[-1.0]).unwrap_err().field,
            "radii[0].radius"
        );
        assert_eq!(Balls::new(&c, &[1.0, 2.0]).unwrap_err().field, "radii");
        let b = Balls::new(&c, &[1.0]).unwrap();
        assert_eq!(b.with_margin(-0.5).unwrap_err().field, "margin");
    }

    #[test]
    fn oversize_ratios_below_one_and_nan_are_rejected() {
        assert_eq!(ensure_ratio(f64::INFINITY), Ok(f64::INFINITY));
        assert_eq!(ensure_ratio(1.0), Ok(1.0));
        assert!(ensure_ratio(f64::NAN).is_err());
        assert_eq!(ensure_ratio(0.5).unwrap_err().field, "ratio");
    }

    #[test]
    fn predicate_matches_bounding_volume_intersects_for_boxes() {
        let a = Aabb::new(Vector2::new(0.0, 0.0), Vector2::new(1.0, 1.0)).unwrap();
        let b = Aabb::new(Vector2::new(1.0, 1.0), Vector2::new(2.0, 2.0)).unwrap();
        let c = b.translated(&Vector2::new(1e-12, 0.0));
        for (x, y) in [(a, b), (a, c), (b, c)] {
            let (p, q) = (Proxy::from_box(&x), Proxy::from_box(&y));
            assert_eq!(overlap(&p, &q, false, None), x.intersects(&y));
        }
    }

    #[test]
    fn touching_balls_overlap_and_separated_ones_do_not() {
        let a = Proxy::from_ball(&Vector2::new(0.0, 0.0), 1.0);
        let b = Proxy::from_ball(&Vector2::new(2.0, 0.0), 1.0);
        let c = Proxy::from_ball(&Vector2::new(1.5, 1.5), 0.5);
        assert!(overlap(&a, &b, true, None));
        // The boxes of a and c overlap, the discs do not: |(1.5, 1.5)| = 2.12 > 1.5.
        assert!(boxes_overlap(&a.aabb, &c.aabb));
        assert!(!overlap(&a, &c, true, None));
    }

    #[test]
    fn periodic_predicate_uses_the_minimum_image() {
        let period = Vector2::new(10.0, 10.0);
        let a = Proxy::from_ball(&Vector2::new(0.2, 5.0), 0.5);
        let b = Proxy::from_ball(&Vector2::new(9.5, 5.0), 0.5);
        assert!(!overlap(&a, &b, true, None));
        assert!(overlap(&a, &b, true, Some(&period)));
        assert!(overlap(&b, &a, true, Some(&period)));
    }
}
