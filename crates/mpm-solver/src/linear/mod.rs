//! The `LinearSolver` plug point: the solve $K\,\delta d = -f^R$ of every
//! Newton iteration (Coombs et al. 2020 eq. 26).
//!
//! A solver is bound to one sparsity pattern per load step
//! ([`LinearSolver::analyse`]: the active set, and with it the pattern,
//! changes only between steps) and then solves once per iteration with new
//! values ([`LinearSolver::solve`]), so symbolic work is done once per
//! step. [`FaerDirect`] (supernodal Cholesky with an LU fallback, faer) is
//! the first implementation; an iterative solver or a distributed one
//! implements the same two calls. Parallelism is a parameter of the
//! implementation ([`FaerDirect::new`]), never a process-global setting.

mod choice;
mod faer_direct;
mod faer_iterative;
mod near_null;

pub use choice::{
    AutoLinear, DEFAULT_MAX_DIRECT_DOFS_2D, DEFAULT_MAX_DIRECT_DOFS_3D, LinearChoice,
    MAX_FALLBACK_DOFS,
};
pub use faer_direct::FaerDirect;
pub use faer_iterative::{FaerIterative, IterativeOptions};
pub use near_null::rigid_body_modes;

use thiserror::Error;

/// Which factorisation (or method) solved the last system.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Factorisation {
    /// Sparse Cholesky $LL^T$ (lower triangle).
    Cholesky,
    /// Sparse LU with partial pivoting.
    Lu,
    /// A preconditioned Krylov method ([`FaerIterative`]).
    Iterative,
}

/// Why a linear solve failed; every variant says where.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LinearSolveError {
    /// The pattern handed to [`LinearSolver::analyse`] is not a valid
    /// compressed-sparse-column pattern (a bug of the assembly).
    #[error("invalid sparsity pattern of a {n}×{n} matrix: {reason}")]
    InvalidPattern {
        /// Matrix size.
        n: usize,
        /// What is wrong.
        reason: &'static str,
    },
    /// [`LinearSolver::solve`] was called with values or a right-hand
    /// side whose length does not match the analysed pattern.
    #[error("expected {expected} {what}, got {got}")]
    Dimension {
        /// `"values"` or `"right-hand side entries"`.
        what: &'static str,
        /// Length of the analysed pattern.
        expected: usize,
        /// Length received.
        got: usize,
    },
    /// No pattern has been analysed for this step.
    #[error("no sparsity pattern has been analysed for this load step")]
    NotAnalysed,
    /// LU found no usable pivot in column `index` of the (permuted)
    /// stiffness: the stiffness is singular there (an unsupported node or
    /// a mechanism).
    #[error("sparse LU found no pivot at column {index}: the stiffness is singular")]
    SingularPivot {
        /// Column of the failed pivot.
        index: usize,
    },
    /// The factorisation ran out of memory or overflowed its index type.
    #[error("the {stage} ran out of memory or overflowed its index type")]
    Resources {
        /// `"symbolic analysis"` or `"numeric factorisation"`.
        stage: &'static str,
    },
    /// The iterative solver did not reach its tolerance.
    #[error(
        "the iterative solver did not converge in {iterations} iterations (relative residual {relative_residual:.3e})"
    )]
    NotConverged {
        /// Iterations made.
        iterations: usize,
        /// $\|b - Kx\|/\|b\|$ reached.
        relative_residual: f64,
    },
    /// An external solver library (PETSc) failed; `message` is its own.
    #[error("{library}: {message}")]
    Backend {
        /// The library.
        library: &'static str,
        /// What it reported.
        message: String,
    },
    /// The solver cannot be used as configured (e.g. an option that no
    /// PETSc object read): a smaller increment cannot help, so Newton
    /// stops at once instead of cutting the step.
    #[error("{library} is misconfigured: {message}")]
    Configuration {
        /// The library.
        library: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The solution has a non-finite entry: the stiffness is singular or
    /// its values are not finite.
    #[error(
        "{factorisation:?} solve produced a non-finite value at free dof {dof} (singular stiffness or non-finite entries)"
    )]
    NonFinite {
        /// The factorisation used.
        factorisation: Factorisation,
        /// First free dof with a non-finite value.
        dof: usize,
    },
}

/// Checks a compressed-sparse-column pattern (the part of
/// [`LinearSolver::analyse`] every implementation shares).
///
/// # Errors
/// [`LinearSolveError::InvalidPattern`] saying what is wrong.
pub fn check_pattern(
    n: usize,
    col_ptr: &[usize],
    row_idx: &[usize],
) -> Result<(), LinearSolveError> {
    let invalid = |reason| LinearSolveError::InvalidPattern { n, reason };
    if col_ptr.len() != n + 1 || col_ptr.first() != Some(&0) {
        return Err(invalid(
            "column pointers must have n + 1 entries starting at 0",
        ));
    }
    if col_ptr.windows(2).any(|w| w[0] > w[1]) || col_ptr[n] != row_idx.len() {
        return Err(invalid(
            "column pointers must ascend to the number of entries",
        ));
    }
    let sorted = (0..n).all(|c| {
        let rows = &row_idx[col_ptr[c]..col_ptr[c + 1]];
        rows.windows(2).all(|w| w[0] < w[1]) && rows.iter().all(|&r| r < n)
    });
    if !sorted {
        return Err(invalid(
            "rows must ascend strictly within each column and be < n",
        ));
    }
    Ok(())
}

/// Checks the lengths handed to [`LinearSolver::solve`] against an
/// analysed pattern of `nnz` entries and `n` rows.
///
/// # Errors
/// [`LinearSolveError::Dimension`] naming the wrong length.
pub fn check_dimensions(
    nnz: usize,
    n: usize,
    values: &[f64],
    rhs: &[f64],
) -> Result<(), LinearSolveError> {
    if values.len() != nnz {
        return Err(LinearSolveError::Dimension {
            what: "values",
            expected: nnz,
            got: values.len(),
        });
    }
    if rhs.len() != n {
        return Err(LinearSolveError::Dimension {
            what: "right-hand side entries",
            expected: n,
            got: rhs.len(),
        });
    }
    Ok(())
}

/// A linear solver for the stiffness of a load step (module docs).
pub trait LinearSolver: Send + std::fmt::Debug {
    /// Binds the solver to the pattern of an `n × n` matrix in compressed
    /// sparse columns (`col_ptr` of length `n + 1`, rows ascending within
    /// each column, the full pattern rather than one triangle). `symmetric`
    /// says whether the values will be symmetric (then Cholesky may be
    /// used). Called once per load step.
    ///
    /// # Errors
    /// [`LinearSolveError::InvalidPattern`] or
    /// [`LinearSolveError::Resources`].
    fn analyse(
        &mut self,
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        symmetric: bool,
    ) -> Result<(), LinearSolveError>;

    /// Solves $K x = b$ in place for the values `values` in the analysed
    /// pattern: `rhs` holds $b$ on entry and $x$ on exit.
    ///
    /// # Errors
    /// See [`LinearSolveError`]; the solution is never silently non-finite.
    fn solve(&mut self, values: &[f64], rhs: &mut [f64])
    -> Result<Factorisation, LinearSolveError>;

    /// The factorisation used by the last successful solve.
    fn last_factorisation(&self) -> Option<Factorisation>;

    /// Number of stored entries of the analysed pattern.
    fn nnz(&self) -> usize;

    /// Iterations of the last solve for an iterative method (0 for a
    /// direct one).
    fn last_iterations(&self) -> usize {
        0
    }

    /// Whether the solver uses the rigid-body modes of each step's free
    /// dofs ([`LinearSolver::set_rigid_body_modes`]); the implicit solver
    /// computes them only when asked. Default: no.
    fn wants_rigid_body_modes(&self) -> bool {
        false
    }

    /// Whether this solver is one solver over all the ranks of a
    /// distributed run (PETSc's parallel matrices over MPI processes):
    /// then every rank calls [`LinearSolver::analyse_part`] and
    /// [`LinearSolver::solve`] together, each with the values of its own
    /// points only, instead of one rank solving the summed system.
    /// Default: no.
    fn solves_over_ranks(&self) -> bool {
        false
    }

    /// [`LinearSolver::analyse`] for a solver over ranks: the pattern is
    /// the whole system's, the same on every rank, and `entries` (ascending
    /// positions in it) are those this rank's points add to. The values
    /// [`LinearSolver::solve`] then receives are this rank's sums, read at
    /// `entries` only; its right-hand side is the whole one, the same on
    /// every rank, and so is the solution it leaves there. Default:
    /// [`LinearSolver::analyse`] (a solver of the whole system).
    ///
    /// # Errors
    /// As [`LinearSolver::analyse`].
    fn analyse_part(
        &mut self,
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        symmetric: bool,
        entries: &[usize],
    ) -> Result<(), LinearSolveError> {
        let _ = entries;
        self.analyse(n, col_ptr, row_idx, symmetric)
    }

    /// The orthonormal rigid-body modes of the free dofs of the pattern
    /// just analysed ([`rigid_body_modes`]), for a multigrid
    /// preconditioner's near-null space. Default: ignored.
    ///
    /// # Errors
    /// The solver could not use them.
    fn set_rigid_body_modes(&mut self, modes: &[Vec<f64>]) -> Result<(), LinearSolveError> {
        let _ = modes;
        Ok(())
    }
}
