//! Peer engines: carom scenes rebuilt in other physics engines for side-by-side runs.

#[cfg(feature = "rapier")]
pub mod rapier;
