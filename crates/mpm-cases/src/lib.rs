//! Benchmark cases of the reference papers with their analytic or
//! published reference values, and the `mpm` command-line program.
//!
//! A case ([`cases`]) builds its mesh, body, loads and constraints from a
//! parameter struct (every field a scene-file key with a default), runs the
//! generic solver with the variant the scene names and measures its result
//! against the reference. The variant — basis, formulation, locking
//! treatment, domain update ([`variant`]) — and the constitutive law
//! ([`material`]) are chosen by name at run time and dispatched to a fully
//! monomorphised solver; each basis and law is one line of a registry
//! (`register_bases!`, `register_laws!`). Outputs ([`output`], [`writer`])
//! are VTU/PVD for ParaView, CSV histories and `summary.json`, written
//! atomically; [`checkpoint`] resumes an interrupted run.
//!
//! ```
//! use mpm_cases::cases::Solve;
//! use mpm_cases::cases::column::{ColumnCase, ColumnParams};
//! use mpm_cases::run::RunControl;
//! use mpm_cases::variant::Variant;
//!
//! let params = ColumnParams { h: 12.5, ..ColumnParams::default() };
//! let result = ColumnCase::run(&params, &Variant::default(), &RunControl::default(), |_, _, _| Ok(()))?;
//! assert!(result.error < 0.1, "eq. (42) error {}", result.error);
//! # Ok::<(), mpm_solver::SolverError>(())
//! ```

pub mod cases;
pub mod checkpoint;
pub mod error;
pub mod locking;
pub mod params;
pub mod scene;
pub mod session;
pub mod writer;

pub use mpm_dispatch::run;
pub use mpm_distributed as distributed;
pub use mpm_output as output;
pub use mpm_scene::source as scene_file;
pub use mpm_scene::{body, manufactured, material, variant};

pub use error::CasesError;
