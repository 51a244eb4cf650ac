//! What a run needs beyond the built-in solvers and one process, each
//! behind a cargo feature so the default build needs none of it:
//!
//! - `petsc`: PETSc's Krylov methods and preconditioners as the implicit
//!   solver's linear solver ([`mpm_petsc::PetscLinear`]) for scenes with
//!   `linear = { petsc = "-ksp_type cg -pc_type gamg" }`.
//!
//! - `mpi`: [`mpi_ranks`], MPI processes as the ranks of a distributed
//!   run (`mpm_solver::ranks`), with an abort-on-panic hook.
//!
//! - always: [`partition`], the ownership of patches (or elements),
//!   points and nodes over N ranks by METIS, and each rank's halo plan.
//!
//! The `mpm` program puts [`external_linear`] in its run control; built
//! without the feature, a scene asking for PETSc is refused at its key.

#[cfg(feature = "mpi")]
pub mod mpi_ranks;
pub mod partition;

use mpm_dispatch::linear::ExternalLinear;

/// The builder of PETSc's linear solver when this crate is built with the
/// `petsc` feature, `None` otherwise.
pub fn external_linear() -> Option<ExternalLinear> {
    #[cfg(feature = "petsc")]
    {
        Some(petsc_linear)
    }
    #[cfg(not(feature = "petsc"))]
    {
        None
    }
}

/// A [`mpm_petsc::PetscLinear`] with `options` and `tolerances`.
#[cfg(feature = "petsc")]
fn petsc_linear(
    options: &str,
    tolerances: mpm_solver::IterativeOptions,
) -> Result<Box<dyn mpm_solver::LinearSolver>, mpm_solver::SolverError> {
    Ok(Box::new(mpm_petsc::PetscLinear::new(options, tolerances)))
}
