//! The integration tests of the cases, the `mpm` program and its outputs, one module per
//! concern, compiled into one binary: one link of the crate's
//! dependencies instead of one per file (docs/src/benchmarks/build.md).

#![allow(clippy::unwrap_used)]

mod common;

mod annulus;
mod cantilever;
mod cli;
mod collapse;
mod column;
mod coombs2020;
mod explicit;
mod explicit_ranks;
mod fuzz_scenes;
mod kill_resume;
mod locking;
mod output_files;
mod output_vtk;
mod regression;
mod scene_file;
mod scene_ranks;
mod scenes;
mod shear;
mod stretch;
mod vane;
mod vtk_python;
mod wang2021_3d;
