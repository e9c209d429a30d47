//! The exact event-driven engine.

pub mod calendar;
