//! Benchmark scenes of the reference papers with their analytic or
//! published reference values.
//!
//! This crate will hold the cases of Coombs et al. 2020 §7 (compaction under
//! self weight, simple shear, elastic cantilever, elastic annulus,
//! elasto-plastic collapse) and of Wang et al. 2021, each as data selected by
//! name or by a scene file, and the `mpm` command-line program that runs
//! them. The program arrives with the solver.

pub mod body;
pub mod cases;
pub mod checkpoint;
pub mod error;
pub mod material;
pub mod output;
pub mod params;
pub mod run;
pub mod scene_file;
pub mod variant;
pub mod writer;

pub use error::CasesError;
