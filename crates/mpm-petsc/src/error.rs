//! The errors of this crate.

use thiserror::Error;

/// A PETSc call failed, or its input could not be handed to it.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PetscError {
    /// A PETSc call returned an error code.
    #[error("PETSc error {code} in {call}: {message}")]
    Call {
        /// The PETSc function.
        call: &'static str,
        /// Its error code.
        code: i32,
        /// PETSc's message.
        message: String,
    },
    /// A string handed to PETSc holds a NUL byte.
    #[error("a PETSc options string may not hold a NUL byte")]
    Nul,
    /// A size does not fit PETSc's 32-bit index.
    #[error("the system is too large for PETSc's 32-bit indices")]
    Size,
    /// A vector's length is not its local size.
    #[error("expected {expected} vector entries, got {got}")]
    Length {
        /// Local size.
        expected: usize,
        /// Length handed over.
        got: usize,
    },
    /// Options no PETSc object read (misspelt or not applicable).
    #[error(
        "PETSc options not used by the solver (misspelt, or not applicable to the method chosen): {0}"
    )]
    Unused(String),
}

impl From<PetscError> for mpm_solver::LinearSolveError {
    fn from(e: PetscError) -> Self {
        match e {
            PetscError::Unused(_) => Self::Configuration {
                library: "PETSc",
                message: e.to_string(),
            },
            e => Self::Backend {
                library: "PETSc",
                message: e.to_string(),
            },
        }
    }
}
