//! [`SpringNetwork`]: damped Hooke springs between balls, and from balls to fixed
//! anchors, with forces accumulated in a fixed order.
//!
//! The force on each ball is the sum over the links, taken in link order: a link adds
//! `F` to its `ball` and, if its other end is a ball, `−F` to that one (Newton's third
//! law holds bit for bit, since both ends receive the same rounded `F`). The order of the
//! additions is the order of the links, never that of threads or chunks, so the result
//! is the same on every run.
//!
//! How this meets chunked parallelism: the accumulation is one serial pass over the links
//! (cheap: one spring force per link); it fills a per-ball force buffer. Everything after
//! it, the per-ball stage updates, reads only the ball's own entries and its force, so an
//! engine may run those updates on chunks of balls on any number of threads and get the
//! same bits. (Accumulating in parallel by scattering would make the sums depend on
//! thread timing; a parallel version would instead gather, per ball, the forces of its
//! links in link order.)

use carom_math::{InvalidValue, Real, Vector, ensure_finite_vector};

use crate::Spring;
use crate::state::ensure_len;

/// What the second end of a link is attached to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Attachment<T: Real, const D: usize> {
    /// Another ball, by index.
    Ball(usize),
    /// A fixed point.
    Anchor(Vector<T, D>),
}

/// A spring from a ball to another ball or to a fixed anchor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Link<T: Real, const D: usize> {
    /// The index of the first end's ball.
    pub ball: usize,
    /// The second end.
    pub other: Attachment<T, D>,
    /// The spring.
    pub spring: Spring<T>,
}

/// Springs between balls and from balls to anchors, in a fixed order.
///
/// Invariant (checked by [`SpringNetwork::new`]): every anchor is finite.
#[derive(Clone, Debug, PartialEq)]
pub struct SpringNetwork<T: Real, const D: usize> {
    links: Vec<Link<T, D>>,
    balls_needed: usize,
}

impl<T: Real, const D: usize> SpringNetwork<T, D> {
    /// The network of `links`, evaluated in this order. A link from a ball to itself
    /// exerts no force.
    ///
    /// # Errors
    /// `links[i].anchor[j]` if an anchor component is not finite.
    pub fn new(links: Vec<Link<T, D>>) -> Result<Self, InvalidValue> {
        let mut balls_needed = 0;
        for (i, link) in links.iter().enumerate() {
            balls_needed = balls_needed.max(link.ball + 1);
            match link.other {
                Attachment::Ball(j) => balls_needed = balls_needed.max(j + 1),
                Attachment::Anchor(anchor) => {
                    ensure_finite_vector("anchor", &anchor)
                        .map_err(|e| e.within(&format!("links[{i}]")))?;
                }
            }
        }
        Ok(Self {
            links,
            balls_needed,
        })
    }

    /// The links, in evaluation order.
    #[inline]
    pub fn links(&self) -> &[Link<T, D>] {
        &self.links
    }

    /// `true` if there are no links.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.links.is_empty()
    }

    /// The fewest balls the links refer to: one more than the largest index.
    #[inline]
    pub fn balls_needed(&self) -> usize {
        self.balls_needed
    }

    /// Checks that `len` balls are enough for the links.
    ///
    /// # Errors
    /// `field` (out of range) if `len < self.balls_needed()`.
    pub(crate) fn ensure_balls(&self, field: &'static str, len: usize) -> Result<(), InvalidValue> {
        ensure_len(field, len, self.balls_needed, usize::MAX)
    }

    /// Writes the spring force on every ball into `forces` (zero for balls without
    /// springs), accumulated in link order.
    ///
    /// # Errors
    /// `positions.len` if there are fewer balls than the links need; `velocities.len` or
    /// `forces.len` if their length differs from that of `positions`.
    pub fn forces(
        &self,
        positions: &[Vector<T, D>],
        velocities: &[Vector<T, D>],
        forces: &mut [Vector<T, D>],
    ) -> Result<(), InvalidValue> {
        self.ensure_balls("positions.len", positions.len())?;
        let n = positions.len();
        ensure_len("velocities.len", velocities.len(), n, n)?;
        ensure_len("forces.len", forces.len(), n, n)?;
        self.write_forces(|i| (positions[i], velocities[i]), forces);
        Ok(())
    }

    /// The elastic energy stored in all springs.
    ///
    /// # Errors
    /// `positions.len` if there are fewer balls than the links need.
    pub fn potential_energy(&self, positions: &[Vector<T, D>]) -> Result<T, InvalidValue> {
        self.ensure_balls("positions.len", positions.len())?;
        Ok(self
            .links
            .iter()
            .map(|link| {
                let other = match link.other {
                    Attachment::Ball(j) => positions[j],
                    Attachment::Anchor(anchor) => anchor,
                };
                link.spring
                    .potential_energy(&(positions[link.ball] - other))
            })
            .fold(T::zero(), |a, b| a + b))
    }

    /// Zeroes `forces` and adds every link's force, in link order. `state(i)` gives ball
    /// `i`'s position and velocity; the caller guarantees `forces.len() >=
    /// self.balls_needed()`.
    #[inline]
    pub(crate) fn write_forces(
        &self,
        state: impl Fn(usize) -> (Vector<T, D>, Vector<T, D>),
        forces: &mut [Vector<T, D>],
    ) {
        forces.fill(Vector::zeros());
        for link in &self.links {
            let (x, v) = state(link.ball);
            match link.other {
                Attachment::Ball(j) => {
                    let (xj, vj) = state(j);
                    let f = link.spring.force(&(x - xj), &(v - vj));
                    forces[link.ball] += f;
                    forces[j] -= f;
                }
                Attachment::Anchor(anchor) => {
                    forces[link.ball] += link.spring.force(&(x - anchor), &v);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    fn spring() -> Spring<f64> {
        Spring::new(2.0, 0.1, 1.0).unwrap()
    }

    #[test]
    fn pair_forces_are_equal_and_opposite_to_the_bit() {
        let net = SpringNetwork::new(vec![
            Link {
                ball: 0,
                other: Attachment::Ball(2),
                spring: spring(),
            },
            Link {
                ball: 1,
                other: Attachment::Anchor(Vector2::new(5.0, 5.0)),
                spring: spring(),
            },
        ])
        .unwrap();
        let x = [
            Vector2::new(0.1, 0.2),
            Vector2::new(4.0, 5.0),
            Vector2::new(2.3, -0.4),
        ];
        let v = [
            Vector2::new(1.0, 0.0),
            Vector2::zeros(),
            Vector2::new(-0.5, 0.25),
        ];
        let mut f = [Vector2::new(9.0, 9.0); 3];
        net.forces(&x, &v, &mut f).unwrap();
        assert_eq!(f[0], -f[2]);
        assert_eq!(
            f[1],
            spring().force(&(x[1] - Vector2::new(5.0, 5.0)), &v[1])
        );
        assert_eq!(f[0], spring().force(&(x[0] - x[2]), &(v[0] - v[2])));
    }

    #[test]
    fn too_few_balls_and_bad_anchors_are_named() {
        let net = SpringNetwork::new(vec![Link {
            ball: 0,
            other: Attachment::Ball(4),
            spring: spring(),
        }])
        .unwrap();
        assert_eq!(net.balls_needed(), 5);
        let x = [Vector2::zeros(); 3];
        let mut f = [Vector2::zeros(); 3];
        let e = net.forces(&x, &x, &mut f).unwrap_err();
        assert_eq!(e.field, "positions.len");
        assert!(net.potential_energy(&x).is_err());
        let e = SpringNetwork::new(vec![Link {
            ball: 0,
            other: Attachment::Anchor(Vector2::new(0.0, f64::NAN)),
            spring: spring(),
        }])
        .unwrap_err();
        assert_eq!(e.field, "links[0].anchor[1]");
    }

    #[test]
    fn potential_energy_sums_the_springs() {
        let net = SpringNetwork::new(vec![
            Link {
                ball: 0,
                other: Attachment::Ball(1),
                spring: spring(),
            },
            Link {
                ball: 1,
                other: Attachment::Anchor(Vector2::new(0.0, 0.0)),
                spring: spring(),
            },
        ])
        .unwrap();
        let x = [Vector2::new(3.0, 0.0), Vector2::new(0.0, 4.0)];
        // |x0 − x1| = 5: stretch 4, energy 16; |x1| = 4: stretch 3, energy 9.
        assert_eq!(net.potential_energy(&x).unwrap(), 25.0);
    }
}
