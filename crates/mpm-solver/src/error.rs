//! The crate's error type.

use std::sync::Arc;

use mpm_basis::BasisError;
use mpm_constitutive::ConstitutiveError;
use mpm_mesh::MeshError;
use thiserror::Error;

use crate::domain::DomainError;
use crate::linear::LinearSolveError;

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
    #[error("linear solve failed: {source}")]
    LinearSolve {
        /// What went wrong.
        #[from]
        source: LinearSolveError,
    },
    /// In a distributed run, another rank's points failed (its failure,
    /// as text): every rank takes the same branch, and `backtrack` says
    /// whether that failure lets Newton halve its correction.
    #[error("rank {rank}: {message}")]
    OnRank {
        /// The lowest failing rank (or the rank whose transport failed).
        rank: usize,
        /// Its failure.
        message: String,
        /// Whether halving the correction may cure it.
        backtrack: bool,
    },
}

/// Everything that can stop a simulation.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SolverError {
    /// A load step kept failing after the increment was halved down to the
    /// minimum.
    #[error(
        "load step {step} (load factor {load_factor} -> {target}) failed with increment {increment:e} <= minimum {min_increment:e}; last normalised residual {}; cause: {cause}",
        residual_text(*.last_residual)
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
        /// The last attempt's last normalised residual; NaN when that
        /// attempt failed before its first residual (in the stress update
        /// or the basis), printed as "none".
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
        #[source]
        reason: BasisFailure,
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
    /// A material point could not be advanced by an explicit time step.
    #[error("explicit step {step} at t = {time:e}: material point {point}: {reason}")]
    ExplicitPoint {
        /// The step (counting from 1) that failed.
        step: usize,
        /// The time at the start of that step.
        time: f64,
        /// Index of the material point.
        point: usize,
        /// What went wrong.
        #[source]
        reason: PointFailure,
    },
    /// Another rank of a distributed run stopped it (its error, as text),
    /// or the transport between ranks failed.
    #[error("rank {rank} stopped the run: {message}")]
    Rank {
        /// The rank.
        rank: usize,
        /// Its error.
        message: String,
    },
    /// A fixed explicit time increment exceeds the stable increment of the
    /// CFL condition (MPoint notes eq. 45) for the current state.
    #[error(
        "explicit step {step} at t = {time:e}: the fixed Δt = {dt:e} exceeds the CFL limit h/max(c + |v|) = {limit:e} (Courant number {ratio:.3}); the run would become unstable — use a smaller Δt or the CFL rule", ratio = dt / limit
    )]
    CflExceeded {
        /// The step (counting from 1) that was refused.
        step: usize,
        /// The time at its start.
        time: f64,
        /// The fixed increment.
        dt: f64,
        /// The stable increment.
        limit: f64,
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
        #[source]
        reason: DomainError,
    },
    /// The background mesh could not take its position at a load factor
    /// (moving-mesh conditions).
    #[error("moving the mesh to load factor {load_factor}: {source}")]
    MeshMotion {
        /// The load factor.
        load_factor: f64,
        /// Why.
        source: MeshMotionError,
    },
    /// A mesh could not be built or read.
    #[error("mesh: {0}")]
    Mesh(#[from] MeshError),
    /// A material could not be built (invalid parameters).
    #[error("material: {0}")]
    Material(#[from] ConstitutiveError),
    /// The sparsity pattern of a step could not be analysed by the linear
    /// solver.
    #[error("analysing the stiffness pattern of the step: {0}")]
    Pattern(#[source] LinearSolveError),
    /// The linear solver cannot be used as configured
    /// ([`LinearSolveError::Configuration`]); no step was cut for it.
    #[error("linear solver: {0}")]
    LinearConfiguration(#[source] LinearSolveError),
    /// The observer of a run (output, progress) failed; the state after the
    /// last converged step is intact.
    #[error("output or observer after a converged step: {0}")]
    Observer(#[source] ObserverError),
    /// The ghost penalty cannot be applied to this solver's parts.
    #[error("ghost penalty: {0}")]
    Ghost(&'static str),
    /// A rigid tool's contact cannot be applied as set up
    /// ([`crate::contact::RigidTool`]).
    #[error("contact with rigid tool `{tool}`: {reason}")]
    Contact {
        /// The tool's name.
        tool: String,
        /// What is wrong.
        reason: &'static str,
    },
    /// The locking treatment could not place the points in patches.
    #[error("locking treatment: {0}")]
    Locking(#[from] LockingError),
    /// The converged state of a step could not be recomputed for the
    /// commit (the update that passed during the iterations failed when
    /// repeated at the same increment).
    #[error("recomputing the converged state for the commit: {cause}")]
    Commit {
        /// What failed.
        #[source]
        cause: StepFailure,
    },
    /// An error that stopped a load step without a retry (a point outside
    /// the mesh, a domain that cannot be updated, a mesh that cannot
    /// move, ...), with the step it stopped: the outputs of the steps
    /// before it are complete.
    #[error("load step {step} (load factor {load_factor} -> {target}): {source}")]
    InStep {
        /// Index of the step (counting converged steps from 0, as
        /// [`SolverError::StepTooSmall`]).
        step: usize,
        /// Load factor at the start of the step.
        load_factor: f64,
        /// Load factor the step tried to reach.
        target: f64,
        /// What stopped it.
        source: Box<SolverError>,
    },
}

/// Why a locking treatment could not place the points in patches
/// ([`crate::LockingTreatment::assign`]).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LockingError {
    /// A point lies in no cell of the mesh.
    #[error("material point {point} at {position:?} lies in no cell of the mesh")]
    OutsideMesh {
        /// Index of the material point.
        point: usize,
        /// Its position.
        position: Vec<f64>,
    },
    /// The patch map does not match the mesh.
    #[error(
        "the patch map has {entries} entries for a mesh of {elements} elements (F-patch needs the children mesh of its patch mesh)"
    )]
    PatchMap {
        /// Entries of the map.
        entries: usize,
        /// Elements of the mesh.
        elements: usize,
    },
}

/// What went wrong evaluating a material point's basis.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BasisFailure {
    /// The basis itself failed (point or domain outside the mesh).
    #[error(transparent)]
    Basis(#[from] BasisError),
    /// The basis returned more nodes than it declared or a node outside
    /// the mesh (a bug of the basis).
    #[error("the basis returned {nodes} nodes (at most {max}) or a node outside the mesh")]
    Stencil {
        /// Nodes returned.
        nodes: usize,
        /// `BasisFunction::MAX_NODES`.
        max: usize,
    },
}

/// Why a background mesh could not take a position.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeshMotionError {
    /// The positions do not match the mesh.
    #[error("{got} positions for a mesh of {expected} nodes")]
    NodeCount {
        /// Positions given.
        got: usize,
        /// Nodes of the mesh.
        expected: usize,
    },
    /// A regular grid may only stretch and translate along its axes.
    #[error(
        "moving node {node} to {position:?} would make the grid irregular; regular grids only stretch and translate along their axes"
    )]
    Irregular {
        /// The node.
        node: usize,
        /// The position asked for.
        position: Vec<f64>,
    },
    /// The moved mesh is not admissible (an inverted simplex).
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

/// An error of a run's observer (e.g. writing output), kept with its
/// source. Two are equal when they are the same error or say the same.
#[derive(Debug, Clone)]
pub struct ObserverError(pub Arc<dyn std::error::Error + Send + Sync>);

impl ObserverError {
    /// Wraps `e`.
    pub fn new(e: impl std::error::Error + Send + Sync + 'static) -> Self {
        Self(Arc::new(e))
    }
}

impl std::fmt::Display for ObserverError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for ObserverError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&*self.0)
    }
}

impl PartialEq for ObserverError {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0) || self.0.to_string() == other.0.to_string()
    }
}

/// Why the explicit solver could not advance a material point.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PointFailure {
    /// The basis could not be evaluated at the point: it left the grid (or
    /// came closer to its boundary than the basis allows).
    #[error("at {position:?}: {source}")]
    Basis {
        /// The point's position.
        position: Vec<f64>,
        /// The basis error.
        #[source]
        source: BasisFailure,
    },
    /// The stress update failed.
    #[error(transparent)]
    Constitutive(#[from] ConstitutiveError),
    /// The deformation gradient lost its positive determinant.
    #[error("det F = {det:e} <= 0: the motion inverts the point")]
    Inverted {
        /// $\det F$ after the step.
        det: f64,
    },
    /// The velocity became non-finite.
    #[error("the velocity became non-finite ({velocity:?})")]
    NonFinite {
        /// The velocity.
        velocity: Vec<f64>,
    },
    /// The domain update failed (a basis with domains, e.g. GIMP).
    #[error("domain update `{rule}`: {source}")]
    Domain {
        /// The rule's name.
        rule: &'static str,
        /// Why (boxed: it is large and rare).
        #[source]
        source: Box<DomainError>,
    },
}

/// A residual for a message: "none" for the NaN that stands for no
/// residual computed yet.
fn residual_text(residual: f64) -> String {
    if residual.is_nan() {
        "none (the last attempt failed before its first residual)".to_owned()
    } else {
        format!("{residual:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn too_small(last_residual: f64) -> String {
        SolverError::StepTooSmall {
            step: 3,
            load_factor: 0.5,
            target: 0.75,
            increment: 1e-5,
            min_increment: 1e-5,
            last_residual,
            cause: StepFailure::Diverged {
                iteration: 2,
                residual: 1e3,
            },
        }
        .to_string()
    }

    #[test]
    fn a_step_without_a_residual_says_so_instead_of_nan() {
        let none = too_small(f64::NAN);
        assert!(none.contains("last normalised residual none"), "{none}");
        assert!(!none.contains("NaN"), "{none}");
        let some = too_small(0.125);
        assert!(some.contains("last normalised residual 1.25e-1;"), "{some}");
    }
}
