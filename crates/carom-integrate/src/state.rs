//! The state integrators advance: one ball as a force field sees it ([`BallState`]),
//! what a field returns ([`Acceleration`]), and the struct-of-arrays view of many balls
//! that steppers update in place ([`Bodies`]).
//!
//! Positions, velocities, spins and inverse masses live in separate slices owned by the
//! engine (struct of arrays). A [`Bodies`] borrows them for one step; it checks only that
//! the lengths agree, so building one per step costs nothing. [`Bodies::split_at`] and
//! [`Bodies::chunks`] cut it into disjoint views for parallel stepping.

use core::ops::{Add, AddAssign};

use carom_math::{InvalidValue, Problem, Real, Space, Vector};
use nalgebra::Const;

/// An angular quantity (spin, angular acceleration): `Vector1` (the z component) in 2D,
/// `Vector3` in 3D.
pub type Angular<T, const D: usize> = <Const<D> as Space<T, D>>::Angular;

/// One ball at one instant, as a [`ForceField`](crate::ForceField) sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BallState<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// The centre.
    pub position: Vector<T, D>,
    /// The linear velocity.
    pub velocity: Vector<T, D>,
    /// The angular velocity (zero for balls whose spin is not simulated).
    pub spin: Angular<T, D>,
    /// `1 / mass`; `0` for a body of infinite mass (static or kinematic), which no field
    /// accelerates.
    pub inverse_mass: T,
    /// The time of the evaluation (stage times of multi-stage methods lie inside the step).
    pub time: T,
}

/// The rate of change of a ball's velocity and spin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Acceleration<T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    /// `dv/dt`.
    pub linear: Vector<T, D>,
    /// `dω/dt`.
    pub angular: Angular<T, D>,
}

impl<T: Real, const D: usize> Acceleration<T, D>
where
    Const<D>: Space<T, D>,
{
    /// No acceleration.
    #[inline]
    pub fn zero() -> Self {
        Self {
            linear: Vector::zeros(),
            angular: <Const<D> as Space<T, D>>::angular_zero(),
        }
    }

    /// A linear acceleration only.
    #[inline]
    pub fn linear(linear: Vector<T, D>) -> Self {
        Self {
            linear,
            angular: <Const<D> as Space<T, D>>::angular_zero(),
        }
    }

    /// An angular acceleration only.
    #[inline]
    pub fn angular(angular: Angular<T, D>) -> Self {
        Self {
            linear: Vector::zeros(),
            angular,
        }
    }
}

impl<T: Real, const D: usize> Add for Acceleration<T, D>
where
    Const<D>: Space<T, D>,
{
    type Output = Self;
    #[inline]
    fn add(self, rhs: Self) -> Self {
        Self {
            linear: self.linear + rhs.linear,
            angular: self.angular + rhs.angular,
        }
    }
}

impl<T: Real, const D: usize> AddAssign for Acceleration<T, D>
where
    Const<D>: Space<T, D>,
{
    #[inline]
    fn add_assign(&mut self, rhs: Self) {
        self.linear += rhs.linear;
        self.angular += rhs.angular;
    }
}

/// A mutable struct-of-arrays view of `n` balls: positions, velocities, inverse masses
/// and, for balls that spin, angular velocities.
///
/// Invariant (checked by [`Bodies::new`] and [`Bodies::with_spins`]): every slice has
/// the same length. The values themselves are the engine's to validate (once, when a
/// scene is loaded: [`Bodies::validate`]); steppers take them as they are.
#[derive(Debug)]
pub struct Bodies<'a, T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    positions: &'a mut [Vector<T, D>],
    velocities: &'a mut [Vector<T, D>],
    inverse_masses: &'a [T],
    spins: Option<&'a mut [Angular<T, D>]>,
}

/// `Ok` if a slice of length `len` has between `min` and `max` entries.
///
/// # Errors
/// [`Problem::OutOfRange`] naming `field`.
pub(crate) fn ensure_len(
    field: &'static str,
    len: usize,
    min: usize,
    max: usize,
) -> Result<(), InvalidValue> {
    if (min..=max).contains(&len) {
        Ok(())
    } else {
        Err(InvalidValue::new(
            field,
            Problem::OutOfRange {
                value: len as f64,
                min: min as f64,
                max: if max == usize::MAX {
                    f64::INFINITY
                } else {
                    max as f64
                },
            },
        ))
    }
}

impl<'a, T: Real, const D: usize> Bodies<'a, T, D>
where
    Const<D>: Space<T, D>,
{
    /// A view of balls that do not spin (their spin is zero for every field).
    ///
    /// # Errors
    /// `velocities.len` or `inverse_masses.len` if its length differs from that of
    /// `positions`.
    pub fn new(
        positions: &'a mut [Vector<T, D>],
        velocities: &'a mut [Vector<T, D>],
        inverse_masses: &'a [T],
    ) -> Result<Self, InvalidValue> {
        ensure_len(
            "velocities.len",
            velocities.len(),
            positions.len(),
            positions.len(),
        )?;
        ensure_len(
            "inverse_masses.len",
            inverse_masses.len(),
            positions.len(),
            positions.len(),
        )?;
        Ok(Self {
            positions,
            velocities,
            inverse_masses,
            spins: None,
        })
    }

    /// The same view with angular velocities: fields see them (Magnus, spin damping) and
    /// steppers advance them.
    ///
    /// # Errors
    /// `spins.len` if its length differs from the number of balls.
    pub fn with_spins(self, spins: &'a mut [Angular<T, D>]) -> Result<Self, InvalidValue> {
        let n = self.positions.len();
        ensure_len("spins.len", spins.len(), n, n)?;
        Ok(Self {
            spins: Some(spins),
            ..self
        })
    }

    /// The number of balls.
    #[inline]
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// `true` if there are no balls.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// The positions.
    #[inline]
    pub fn positions(&self) -> &[Vector<T, D>] {
        self.positions
    }

    /// The velocities.
    #[inline]
    pub fn velocities(&self) -> &[Vector<T, D>] {
        self.velocities
    }

    /// The inverse masses.
    #[inline]
    pub fn inverse_masses(&self) -> &[T] {
        self.inverse_masses
    }

    /// The angular velocities, if this view has them.
    #[inline]
    pub fn spins(&self) -> Option<&[Angular<T, D>]> {
        self.spins.as_deref()
    }

    /// Checks every value: positions, velocities and spins finite, inverse masses finite
    /// and `>= 0`. `O(n)`: call it when the state enters from outside, not every step.
    ///
    /// # Errors
    /// The first bad value, named like `velocities[7][1]` or `inverse_masses[3]`.
    pub fn validate(&self) -> Result<(), InvalidValue> {
        fn first_bad<'v, T: Real + 'v>(
            name: &str,
            rows: impl Iterator<Item = &'v [T]>,
        ) -> Result<(), InvalidValue> {
            for (i, row) in rows.enumerate() {
                if let Some(j) = row.iter().position(|c| !c.finite()) {
                    return Err(InvalidValue::new(
                        format!("{name}[{i}][{j}]"),
                        Problem::NotFinite(row[j].to_f64()),
                    ));
                }
            }
            Ok(())
        }
        first_bad(
            "positions",
            self.positions.iter().map(Vector::<T, D>::as_slice),
        )?;
        first_bad(
            "velocities",
            self.velocities.iter().map(Vector::<T, D>::as_slice),
        )?;
        if let Some(spins) = self.spins.as_deref() {
            // `w · 0` is zero exactly when every component is finite (∞ · 0 and NaN · 0
            // are NaN), which tests the components through the `Space` interface alone.
            let zero = <Const<D> as Space<T, D>>::angular_zero();
            for (i, w) in spins.iter().enumerate() {
                if *w * T::zero() != zero {
                    let norm2 = <Const<D> as Space<T, D>>::angular_dot(w, w);
                    return Err(InvalidValue::new(
                        format!("spins[{i}]"),
                        Problem::NotFinite(norm2.to_f64()),
                    ));
                }
            }
        }
        for (i, &m) in self.inverse_masses.iter().enumerate() {
            carom_math::ensure_non_negative("inverse_mass", m)
                .map_err(|e| e.within(&format!("inverse_masses[{i}]")))?;
        }
        Ok(())
    }

    /// A shorter-lived view of the same balls (to step twice through one view).
    #[inline]
    pub fn reborrow(&mut self) -> Bodies<'_, T, D> {
        Bodies {
            positions: self.positions,
            velocities: self.velocities,
            inverse_masses: self.inverse_masses,
            spins: self.spins.as_deref_mut(),
        }
    }

    /// Splits into the balls `[0, mid)` and `[mid, n)`, for `rayon::join`-style
    /// parallel stepping. `mid` is clamped to `n`.
    pub fn split_at(self, mid: usize) -> (Self, Self) {
        let mid = mid.min(self.len());
        let (p0, p1) = self.positions.split_at_mut(mid);
        let (v0, v1) = self.velocities.split_at_mut(mid);
        let (m0, m1) = self.inverse_masses.split_at(mid);
        let (s0, s1) = match self.spins {
            Some(s) => {
                let (a, b) = s.split_at_mut(mid);
                (Some(a), Some(b))
            }
            None => (None, None),
        };
        (
            Self {
                positions: p0,
                velocities: v0,
                inverse_masses: m0,
                spins: s0,
            },
            Self {
                positions: p1,
                velocities: v1,
                inverse_masses: m1,
                spins: s1,
            },
        )
    }

    /// Disjoint views of at most `chunk_len` balls each (a `chunk_len` of 0 counts as 1),
    /// in order. Stepping each chunk gives bit-for-bit the state stepping the whole view
    /// gives, because every ball is advanced independently.
    pub fn chunks(self, chunk_len: usize) -> Chunks<'a, T, D> {
        Chunks {
            rest: Some(self),
            chunk_len: chunk_len.max(1),
        }
    }

    /// The arrays, for the steppers' loops.
    #[inline]
    pub(crate) fn arrays(&mut self) -> Arrays<'_, T, D> {
        Arrays {
            positions: self.positions,
            velocities: self.velocities,
            inverse_masses: self.inverse_masses,
            spins: self.spins.as_deref_mut(),
        }
    }
}

/// The slices of a [`Bodies`], of equal lengths, for the steppers' loops.
pub(crate) struct Arrays<'s, T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    pub(crate) positions: &'s mut [Vector<T, D>],
    pub(crate) velocities: &'s mut [Vector<T, D>],
    pub(crate) inverse_masses: &'s [T],
    pub(crate) spins: Option<&'s mut [Angular<T, D>]>,
}

/// The iterator of [`Bodies::chunks`].
#[derive(Debug)]
pub struct Chunks<'a, T: Real, const D: usize>
where
    Const<D>: Space<T, D>,
{
    rest: Option<Bodies<'a, T, D>>,
    chunk_len: usize,
}

impl<'a, T: Real, const D: usize> Iterator for Chunks<'a, T, D>
where
    Const<D>: Space<T, D>,
{
    type Item = Bodies<'a, T, D>;

    fn next(&mut self) -> Option<Self::Item> {
        let rest = self.rest.take()?;
        if rest.is_empty() {
            return None;
        }
        let (chunk, rest) = rest.split_at(self.chunk_len);
        self.rest = Some(rest);
        Some(chunk)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector1, Vector2, Vector3};

    #[test]
    fn lengths_must_agree_and_the_error_names_the_slice() {
        let mut p = [Vector2::<f64>::zeros(); 3];
        let mut v = [Vector2::zeros(); 2];
        let m = [1.0; 3];
        let e = Bodies::new(&mut p, &mut v, &m).unwrap_err();
        assert_eq!(e.to_string(), "velocities.len: must be in [3, 3], got 2");
        let mut v = [Vector2::zeros(); 3];
        let mut w = [Vector1::zeros(); 4];
        let e = Bodies::new(&mut p, &mut v, &m)
            .unwrap()
            .with_spins(&mut w)
            .unwrap_err();
        assert_eq!(e.field, "spins.len");
    }

    #[test]
    fn validate_names_the_first_bad_value() {
        let mut p = [Vector3::<f64>::zeros(); 3];
        let mut v = [Vector3::zeros(); 3];
        v[2].y = f64::NAN;
        let m = [1.0, 0.0, 2.0];
        let e = Bodies::new(&mut p, &mut v, &m)
            .unwrap()
            .validate()
            .unwrap_err();
        assert_eq!(e.field, "velocities[2][1]");
        v[2].y = 0.0;
        let m = [1.0, -1.0, 2.0];
        let e = Bodies::new(&mut p, &mut v, &m)
            .unwrap()
            .validate()
            .unwrap_err();
        assert_eq!(e.field, "inverse_masses[1].inverse_mass");
        let m = [1.0, 0.0, 2.0];
        let mut w = [Vector3::zeros(); 3];
        w[0].z = f64::INFINITY;
        let e = Bodies::new(&mut p, &mut v, &m)
            .unwrap()
            .with_spins(&mut w)
            .unwrap()
            .validate()
            .unwrap_err();
        assert_eq!(e.field, "spins[0]");
        w[0].z = 1e200; // finite, though its square overflows
        let b = Bodies::new(&mut p, &mut v, &m)
            .unwrap()
            .with_spins(&mut w)
            .unwrap();
        assert_eq!(b.validate(), Ok(()));
    }

    #[test]
    fn chunks_cover_every_ball_once_in_order() {
        let mut p: Vec<_> = (0..10).map(|i| Vector2::new(f64::from(i), 0.0)).collect();
        let mut v = vec![Vector2::zeros(); 10];
        let m = vec![1.0; 10];
        let mut w = vec![Vector1::zeros(); 10];
        let bodies = Bodies::new(&mut p, &mut v, &m)
            .unwrap()
            .with_spins(&mut w)
            .unwrap();
        let lens: Vec<_> = bodies.chunks(4).map(|c| c.len()).collect();
        assert_eq!(lens, [4, 4, 2]);
        let bodies = Bodies::new(&mut p, &mut v, &m).unwrap();
        let firsts: Vec<_> = bodies.chunks(0).map(|c| c.positions()[0].x).collect();
        assert_eq!(firsts, (0..10).map(f64::from).collect::<Vec<_>>());
        let (a, b) = Bodies::new(&mut p, &mut v, &m).unwrap().split_at(99);
        assert_eq!((a.len(), b.len()), (10, 0));
    }
}
