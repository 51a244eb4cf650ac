//! The linear solver a scene asks for beyond the built-in ones: PETSc's
//! KSP (`linear = { petsc = "..." }`), built by the function a program
//! compiled with PETSc puts in [`crate::run::RunControl::external_linear`]
//! (mpm-distributed's `petsc` feature). This crate does not depend on
//! PETSc: building with it recompiles none of the solvers here.

use mpm_scene::build::PetscRequest;
use mpm_solver::{IterativeOptions, LinearChoice, LinearSolver, SolverError};

/// Builds a solver from PETSc's options and the scene's iterative
/// tolerances.
pub type ExternalLinear =
    fn(options: &str, tolerances: IterativeOptions) -> Result<Box<dyn LinearSolver>, SolverError>;

/// The solver replacing `choice`'s when the scene makes a PETSc `request`
/// (with `choice`'s iterative tolerances), `None` for the built-in ones.
///
/// # Errors
/// [`SolverError::InvalidInput`] with the scene's located message when
/// the program has no `build` for it; `build`'s own errors.
pub fn external(
    request: Option<&PetscRequest>,
    choice: LinearChoice,
    build: Option<ExternalLinear>,
) -> Result<Option<Box<dyn LinearSolver>>, SolverError> {
    let Some(request) = request else {
        return Ok(None);
    };
    let Some(build) = build else {
        return Err(SolverError::InvalidInput(request.without_petsc.clone()));
    };
    let tolerances = match choice {
        LinearChoice::Iterative(t) | LinearChoice::Auto { iterative: t, .. } => t,
        LinearChoice::Direct => IterativeOptions::default(),
    };
    build(&request.options, tolerances).map(Some)
}
