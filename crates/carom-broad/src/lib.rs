//! Broad phases: find the pairs of bounding volumes that overlap.
//!
//! Work in progress (issue 4): brute force, sweep-and-prune, k-d tree and uniform grid.
