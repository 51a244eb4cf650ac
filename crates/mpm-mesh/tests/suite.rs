//! The integration tests of meshes, location and Gmsh input, one module per
//! concern, compiled into one binary: one link of the crate's
//! dependencies instead of one per file (docs/src/benchmarks/build.md).

#![allow(clippy::unwrap_used)]

mod common;
mod fuzz_support;

mod fuzz_gmsh;
mod generate;
mod gmsh;
mod locate;
mod move_nodes;
mod neighbours;
mod patches;
