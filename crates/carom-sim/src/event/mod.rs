//! The exact event-driven engine.

pub mod calendar;
pub mod neighbours;
