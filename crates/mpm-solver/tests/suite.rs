//! The integration tests of the solvers, one module per
//! concern, compiled into one binary: one link of the crate's
//! dependencies instead of one per file (docs/src/benchmarks/build.md).

#![allow(clippy::unwrap_used)]

mod common;

mod bspline_boundary;
mod contact;
mod domain_table2;
mod explicit;
mod implicit_ranks;
mod locking;
mod moving_mesh;
mod ranks;
mod stiffness;
