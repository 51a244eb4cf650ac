//! The integration tests of the laws, one module per
//! concern, compiled into one binary: one link of the crate's
//! dependencies instead of one per file (docs/src/benchmarks/build.md).

#![allow(clippy::unwrap_used)]

mod behaviour;
mod drucker_prager;
mod incremental;
mod modified_cam_clay;
mod mohr_coulomb;
mod tangents;
