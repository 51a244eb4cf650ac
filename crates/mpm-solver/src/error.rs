//! The crate's error type.

use mpm_constitutive::ConstitutiveError;
use thiserror::Error;

/// Why a Newton–Raphson load step failed. A failed step is retried with
/// half the load increment; [`SolverError::StepTooSmall`] carries the last
/// cause when halving can go no further.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StepFailure {
    /// The normalised residual (eq. 40) became non-finite or grew beyond the
    /// divergence limit.
    #[error(
        "Newton iterations diverged at iteration {iteration} (normalised residual {residual:e})"
    )]
    Diverged {
        /// Iteration at which divergence was detected.
        iteration: usize,
        /// The normalised residual then.
        residual: f64,
    },
    /// The iteration limit was reached before the tolerance.
    #[error("no convergence in {iterations} iterations (normalised residual {residual:e})")]
    IterationLimit {
        /// Iterations performed.
        iterations: usize,
        /// The last normalised residual.
        residual: f64,
    },
    /// A material point's constitutive update failed (e.g. det F <= 0).
    #[error("material point {point}: {source}")]
    Constitutive {
        /// Index of the material point.
        point: usize,
        /// The constitutive error.
        source: ConstitutiveError,
    },
    /// A Newton iterate stretched or compressed a material point beyond the
    /// admissible increment ([`crate::NewtonOptions::max_increment_norm`]):
    /// the load step is too large, or the iterates are sliding along a
    /// near-mechanism (a point alone with nodes no other point supports)
    /// into the region where the Hencky stress softens.
    #[error(
        "material point {point}: |ΔF| = {norm:.3e} or |ΔF⁻¹| beyond the admissible {limit} in one load step"
    )]
    ExcessiveIncrement {
        /// Index of the material point.
        point: usize,
        /// The larger of $\|\Delta F\|_F$ and $\|\Delta F^{-1}\|_F$.
        norm: f64,
        /// The limit.
        limit: f64,
    },
    /// The linear solver failed (singular or non-finite system).
    #[error("linear solve failed: {reason}")]
    LinearSolve {
        /// What went wrong.
        reason: String,
    },
}

/// Everything that can stop a simulation.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SolverError {
    /// A load step kept failing after the increment was halved down to the
    /// minimum.
    #[error(
        "load step {step} (load factor {load_factor} -> {target}) failed with increment {increment:e} <= minimum {min_increment:e}; last normalised residual {last_residual:e}; cause: {cause}"
    )]
    StepTooSmall {
        /// Index of the step (counting converged steps from 0).
        step: usize,
        /// Load factor at the start of the step.
        load_factor: f64,
        /// Load factor the step tried to reach.
        target: f64,
        /// The last increment tried.
        increment: f64,
        /// The minimum increment allowed.
        min_increment: f64,
        /// The last normalised residual seen.
        last_residual: f64,
        /// The last failure.
        cause: StepFailure,
    },
    /// A basis function could not be evaluated for a material point, most
    /// often because the point (or its domain) left the background grid.
    #[error("material point {point} at {position:?}: {reason}")]
    Basis {
        /// Index of the material point.
        point: usize,
        /// Its position.
        position: Vec<f64>,
        /// The basis error.
        reason: String,
    },
    /// The observer asked the run to stop after a converged step (e.g. a
    /// step budget); the state after that step is complete and a
    /// checkpoint written then can be resumed.
    #[error("stopped after load step {step} at load factor {load_factor}")]
    Stopped {
        /// Converged steps so far.
        step: usize,
        /// Load factor reached.
        load_factor: f64,
    },
    /// Inconsistent problem set-up.
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// The domain update failed for a material point.
    #[error("domain update of material point {point}: {reason}")]
    DomainUpdate {
        /// Index of the material point.
        point: usize,
        /// What went wrong.
        reason: String,
    },
}
