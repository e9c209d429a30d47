//! carom's benchmark report: carom measured against its peers on the same scenes.
//!
//! The report has four sections (error against run time, stability on stiff and extreme
//! cases, throughput, 2-core scaling); [`model`] holds the rows each section produces,
//! which `report.json` serialises as they are. [`peer`] builds carom scenes in the peer
//! engines (rapier2d), so every comparison runs the same physical scene in both.
//! [`reference`](mod@reference) holds the closed forms the accuracy sections measure against, and
//! [`engines`] builds carom's engines for a scene as `carom run` does. [`work_precision`]
//! (section 1) and [`stability`] (section 2) are the accuracy sections.

pub mod engines;
pub mod font;
pub mod model;
pub mod peer;
pub mod reference;
pub mod stability;
pub mod work_precision;
