//! Time of impact (the narrow phase of the event-driven engine).
//!
//! Work in progress (issue 3).
