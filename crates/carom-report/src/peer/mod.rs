//! Peer engines: carom scenes rebuilt in other physics engines for side-by-side runs.
//!
//! * [`rapier`]: rapier2d 0.36, the peer of both engines;
//! * [`parry`]: parry 0.31's BVH (the broad phase under rapier), the peer of carom's
//!   broad phases.
//!
//! Both come with the `rapier` feature (default).

#[cfg(feature = "rapier")]
pub mod parry;
#[cfg(feature = "rapier")]
pub mod rapier;
