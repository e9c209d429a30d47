//! Bounding volumes fitted to point sets.
