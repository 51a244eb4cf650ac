//! What a load step reports: the converged step's figures, the stiffness
//! it assembled, and why an attempt failed.

use nalgebra::SVector;

use crate::error::{SolverError, StepFailure};
use crate::linear::{Factorisation, LinearSolveError};

/// What one converged load step did.
#[derive(Debug, Clone, PartialEq)]
pub struct StepReport<const D: usize> {
    /// Load factor at the start of the step.
    pub lambda0: f64,
    /// Load factor at the end of the step.
    pub lambda1: f64,
    /// Normalised residual (eq. 40) at iterations 0, 1, ...
    pub residuals: Vec<f64>,
    /// The rounding noise of the residual normalised like it
    /// ([`crate::stages::convergence::rounding_noise`]): the smallest
    /// normalised residual the step could be expected to reach (zero when
    /// it converged without assembling a stiffness).
    pub rounding_floor: f64,
    /// Whether the step was accepted at that floor, stalled above the
    /// tolerance ([`crate::NewtonOptions::rounding_floor_factor`]).
    pub at_rounding_floor: bool,
    /// The out-of-balance force at iteration 0 measured before the
    /// reactions are known, $\|f^{ext} - f^{int}\| / \|f^{ext}\|$ over
    /// every active dof, prescribed ones included: the first residual the
    /// authors' code prints, so the iteration-0 row of Coombs et al.
    /// (2020) Tables 3 and 8. Not a convergence measure: at prescribed
    /// dofs $f^{int}$ carries the reactions of the previous step. `None`
    /// when the step has no external force (displacement-driven steps).
    pub initial_unbalance: Option<f64>,
    /// Sum of the reactions at prescribed dofs, per component.
    pub reaction: SVector<f64, D>,
    /// The reaction at every node with a prescribed dof, by mesh node id
    /// (ascending): $f^{int} - f^{ext}$ at its prescribed components, zero
    /// at its free ones. Sums over named node sets (a footing, a base)
    /// come from it.
    pub node_reactions: Vec<(usize, SVector<f64, D>)>,
    /// Active nodes, free dofs and stiffness entries of the step.
    pub active_nodes: usize,
    /// Free degrees of freedom.
    pub free_dofs: usize,
    /// Factorisation used by the last solve.
    pub factorisation: Option<Factorisation>,
    /// Iterations (indices into `residuals`) whose Newton correction was
    /// shortened by backtracking; the iterations after the last of them are
    /// plain Newton steps.
    pub backtracked: Vec<usize>,
    /// Whether the step began with the solve linearised about the
    /// converged state ([`crate::FirstTangent::Converged`]): one
    /// assembly and solve more than `residuals` counts.
    pub linearised_start: bool,
    /// Iterations whose update computed the tangents in the same pass
    /// because Newton expected to correct them
    /// ([`crate::ImplicitSolver::update_material_points_with_tangents`]).
    pub fused_updates: usize,
    /// Whether the converged iterate was one of them: its tangents and
    /// stiffness went unused and the commit recomputed the responses (a
    /// wrong prediction of
    /// [`crate::stages::convergence::NewtonMonitor::expects_correction`]).
    pub unused_tangents: bool,
    /// Wall-clock seconds of each stage over the step (all iterations).
    pub times: StageTimes,
    /// Iterations of the iterative linear solver over the step (0 with a
    /// direct solver).
    pub linear_iterations: usize,
    /// The attempts from `lambda0` that failed and were halved before this
    /// step converged, in order (filled by [`crate::ImplicitSolver::run`];
    /// empty from `solve_load_step` and in most steps).
    pub cuts: Vec<CutStep>,
}

/// A load step that failed and was halved: from `lambda0` towards
/// `target`, with the normalised residual it last reached (NaN when it
/// failed before the first one) and why.
#[derive(Debug, Clone, PartialEq)]
pub struct CutStep {
    /// Load factor the attempt started from.
    pub lambda0: f64,
    /// Load factor it aimed at.
    pub target: f64,
    /// Last normalised residual (eq. 40) of the attempt.
    pub last_residual: f64,
    /// Why it failed.
    pub cause: StepFailure,
}

/// Wall-clock seconds per stage of a load step, summed over its Newton
/// iterations: where a run's time goes (`docs/src/benchmarks/linear.md`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StageTimes {
    /// Moving the mesh, locating the points and evaluating their basis
    /// functions (once per step).
    pub basis: f64,
    /// Constraints, node numbering, patches, the sparsity pattern and the
    /// linear solver's symbolic analysis (once per step).
    pub system: f64,
    /// $\Delta F$, the locking treatment and the constitutive update
    /// (every iteration, with backtracking), with the tangents on the
    /// iterations that compute them in the same pass
    /// ([`StepReport::fused_updates`]).
    pub material: f64,
    /// The internal force (in the stiffness's pass on the iterations
    /// that compute their tangents with the update).
    pub force: f64,
    /// The consistent tangents (and a patch treatment's coupling vectors).
    pub tangent: f64,
    /// The sparse stiffness.
    pub stiffness: f64,
    /// The linear solves (factorisation or Krylov iterations), the
    /// linearised start's included.
    pub solve: f64,
    /// Committing the converged state and moving the mesh to the end.
    pub commit: f64,
}

impl StageTimes {
    /// The sum of the stages.
    pub fn total(&self) -> f64 {
        self.basis
            + self.system
            + self.material
            + self.force
            + self.tangent
            + self.stiffness
            + self.solve
            + self.commit
    }
}

impl<const D: usize> StepReport<D> {
    /// Number of Newton iterations (linear solves).
    pub fn iterations(&self) -> usize {
        self.residuals.len().saturating_sub(1)
    }

    /// The sum of the reactions on the mesh nodes `nodes` (sorted
    /// ascending): a footing's or a base's force.
    pub fn reaction_on(&self, nodes: &[usize]) -> SVector<f64, D> {
        self.node_reactions
            .iter()
            .filter(|(v, _)| nodes.binary_search(v).is_ok())
            .fold(SVector::zeros(), |t, (_, r)| t + r)
    }
}

/// The stiffness over the free dofs as last assembled: compressed sparse
/// columns, the full (not triangular) pattern, rows ascending within each
/// column, free dofs numbered as in [`ImplicitSolver::free_increment`].
#[derive(Debug, Clone, Copy)]
pub struct FreeStiffness<'a> {
    /// Free dofs (rows and columns).
    pub n: usize,
    /// Column pointers (`n + 1`).
    pub col_ptr: &'a [usize],
    /// Row index of each entry.
    pub row_idx: &'a [usize],
    /// Value of each entry.
    pub values: &'a [f64],
}

impl FreeStiffness<'_> {
    /// A copy as a `sprs` matrix (for export or inspection), checked for
    /// a consistent structure.
    ///
    /// # Errors
    /// [`SolverError::Pattern`] if the arrays do not form a CSC matrix
    /// (which would be a bug of the assembly).
    pub fn to_sprs(&self) -> Result<sprs::CsMat<f64>, SolverError> {
        sprs::CsMat::try_new_csc(
            (self.n, self.n),
            self.col_ptr.to_vec(),
            self.row_idx.to_vec(),
            self.values.to_vec(),
        )
        .map_err(|_| {
            SolverError::Pattern(LinearSolveError::InvalidPattern {
                n: self.n,
                reason: "the assembled stiffness is not a CSC matrix",
            })
        })
    }
}

/// Failure of one attempt at a load step.
#[derive(Debug, Clone, PartialEq)]
pub enum StepError {
    /// The step may succeed with a smaller increment.
    Retry {
        /// The cause.
        cause: StepFailure,
        /// The last normalised residual.
        last_residual: f64,
    },
    /// The simulation cannot continue (e.g. a point left the grid).
    Fatal(SolverError),
}

impl From<SolverError> for StepError {
    fn from(e: SolverError) -> Self {
        StepError::Fatal(e)
    }
}
