//! The integration tests of the basis functions, one module per
//! concern, compiled into one binary: one link of the crate's
//! dependencies instead of one per file (docs/src/benchmarks/build.md).

#![allow(clippy::unwrap_used)]

mod common;

mod boundaries;
mod cpdi2_integration;
mod limits;
mod properties;
