//! PETSc for the implicit solver: [`PetscLinear`], a [`LinearSolver`]
//! whose Krylov method and preconditioner are PETSc's (KSP and PC), chosen
//! by an options string as on PETSc's command line
//! (`-ksp_type cg -pc_type gamg`), over a matrix preallocated once per
//! load step from its COO pattern and filled once per Newton iteration.
//!
//! Only [`raw`] calls C (bindgen's declarations of `petscksp.h`, built by
//! `build.rs` against the PETSc that pkg-config finds). This crate is not
//! a default workspace member: the default build needs neither PETSc nor
//! MPI (README, "Distributed runs").
#![warn(missing_docs)]

mod error;
pub mod raw;
mod solver;

pub use error::PetscError;
pub use solver::PetscLinear;

pub use mpm_solver::LinearSolver;
