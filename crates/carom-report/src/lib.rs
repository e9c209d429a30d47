//! carom's benchmark report: carom measured against its peers on the same scenes.
//!
//! The report has four sections (error against run time, stability on stiff and extreme
//! cases, throughput, 2-core scaling); [`model`] holds the rows each section produces,
//! which `report.json` serialises as they are. [`peer`] builds carom scenes in the peer
//! engines (rapier2d), so every comparison runs the same physical scene in both.

pub mod model;
pub mod peer;
