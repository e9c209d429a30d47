//! carom: generic physics components for ball-centred simulation.
//!
//! This facade re-exports the component crates, each behind a cargo feature of its own
//! (all on by default). Engine authors who need one component depend on that crate
//! directly (`carom-geometry`, `carom-broad`, ...); everyone else depends on `carom` and
//! turns off what they never use:
//!
//! ```toml
//! carom = { version = "0.1", default-features = false, features = ["geometry", "toi"] }
//! ```
//!
//! | feature     | crate              | what it is                                              |
//! |-------------|--------------------|---------------------------------------------------------|
//! | `geometry`  | [`geometry`]       | shapes, bounding volumes, overlap/contact/ray queries   |
//! | `broad`     | [`broad`]          | broad phases: brute force, sweep-and-prune, k-d tree, grid |
//! | `toi`       | [`toi`]            | exact time of impact                                    |
//! | `response`  | [`response`]       | collision impulses, clusters, guards                    |
//! | `integrate` | [`integrate`]      | integrators and force fields                            |
//! | `sim`       | [`sim`]            | the engines, scenes and planner                         |
//! | `glam`      |                    | `From`/`Into` between nalgebra vectors and glam 0.33    |
//!
//! [`d2`] and [`d3`] gather the concrete per-dimension aliases (`carom::d2::Ball`).

pub use carom_math as math;
pub use carom_math::{InvalidValue, Real};

#[cfg(feature = "broad")]
pub use carom_broad as broad;
#[cfg(feature = "geometry")]
pub use carom_geometry as geometry;
#[cfg(feature = "integrate")]
pub use carom_integrate as integrate;
#[cfg(feature = "response")]
pub use carom_response as response;
#[cfg(feature = "sim")]
pub use carom_sim as sim;
#[cfg(feature = "toi")]
pub use carom_toi as toi;

/// Concrete 2D types, `f64` unless a scalar is given.
pub mod d2 {
    #[cfg(feature = "geometry")]
    pub use carom_geometry::d2::*;
}

/// Concrete 3D types, `f64` unless a scalar is given.
pub mod d3 {
    #[cfg(feature = "geometry")]
    pub use carom_geometry::d3::*;
}
