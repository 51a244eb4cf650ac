//! The generic implicit Newton–Raphson solver for quasi-static problems
//! (Coombs et al. 2020 §6.3; the algorithm of AMPLE, Coombs & Augarde 2020).
//!
//! One load step, [`ImplicitSolver::solve_load_step`], is the paper's
//! algorithm, written once per dimension in [`driver`] over the
//! object-safe [`driver::NewtonStages`]; each stage is a method of
//! [`stages`](self::stages) that calls the reusable functions of
//! [`crate::stages`]:
//!
//! 1. [`evaluate_basis`](ImplicitSolver::evaluate_basis): basis values and
//!    gradients at the start of the step, once per step;
//! 2. [`build_system`](ImplicitSolver::build_system): active nodes, dofs,
//!    prescribed increments, sparsity pattern, symbolic factorisation;
//! 3. [`assemble_external_force`](ImplicitSolver::assemble_external_force):
//!    eqs. (24), (25), (29);
//! 4. Newton iterations: [`update_material_points`](ImplicitSolver::update_material_points)
//!    (eq. 7, the constitutive update), [`assemble_internal_force`](ImplicitSolver::assemble_internal_force)
//!    (eqs. 6/23, 28), the convergence test on eq. (40)
//!    ([`NewtonMonitor`]), then
//!    [`update_tangents`](ImplicitSolver::update_tangents) (eqs. A.1,
//!    A.3–A.6), [`assemble_stiffness`](ImplicitSolver::assemble_stiffness)
//!    (eqs. 4/21, 27) and the linear solve (eqs. 26, 30). On an iterate
//!    that Newton expects to correct
//!    ([`NewtonMonitor::expects_correction`]) the update computes the
//!    tangents in the same pass instead
//!    ([`update_material_points_with_tangents`](ImplicitSolver::update_material_points_with_tangents)),
//!    bit for bit the same numbers without storing the responses;
//! 5. [`commit`](ImplicitSolver::commit): positions (eq. 31), deformation,
//!    volumes, history and domains.
//!
//! Material-point loops run in parallel with rayon; every sum is taken in
//! an order fixed by point and node numbering, so results do not depend on
//! the number of threads.
//!
//! The folder holds one concern per file: [`options`] (Newton controls),
//! [`report`] (what a step reports), [`builder`] (composition without
//! spelling types), `stages` (the stage methods), `predictor` (the secant
//! predictor and its checkpoint state) and `verification` (residual and
//! stiffness at a chosen increment, for finite-difference tests and
//! benchmarks).

pub mod builder;
mod contact;
pub mod driver;
mod on_ranks;
pub mod options;
mod predictor;
pub mod report;
mod stages;
mod verification;

pub use builder::ImplicitBuilder;
pub use options::{FirstTangent, MAX_BACKTRACKS, NewtonOptions};
pub use report::{CutStep, FreeStiffness, StageTimes, StepError, StepReport};

use mpm_constitutive::Response;
use nalgebra::{Matrix3, SVector};

use crate::linear::LinearSolver;
use crate::parts::{PointsOf, SolverParts};
use crate::stages::convergence;
use crate::stages::gather::{PointStress, PointTangent};
use crate::stages::ghost::GhostFaces;
use crate::stages::patch::PatchSystem;
use crate::stages::system::StepSystem;

/// Per-iteration buffers, sized once per step.
#[derive(Debug)]
struct Iterate<const D: usize, H> {
    du: Vec<f64>,
    f_ext: Vec<f64>,
    f_int: Vec<f64>,
    rhs: Vec<f64>,
    values: Vec<f64>,
    responses: Vec<Option<Response<H>>>,
    /// `responses` belong to the current increment `du` (false after the
    /// fused update-with-tangents pass and after a failed update).
    responses_current: bool,
    /// Per point, the weighted stress's components in use.
    stress_w: Vec<PointStress<D>>,
    /// Per point, the weighted tangent's components in use.
    tangent_w: Vec<PointTangent<D>>,
    /// Per point, $\|T_p\|_F$ of the full weighted tangent, when the
    /// last tangent pass was asked for it (the rounding-noise bound).
    tangent_norms: Vec<f64>,
    mapped: Vec<SVector<f64, D>>,
    increments: Vec<Matrix3<f64>>,
    /// `values` holds a stiffness assembled on the current system.
    stiffness_assembled: bool,
}

impl<const D: usize, H> Default for Iterate<D, H> {
    fn default() -> Self {
        Self {
            du: Vec::new(),
            f_ext: Vec::new(),
            f_int: Vec::new(),
            rhs: Vec::new(),
            values: Vec::new(),
            responses: Vec::new(),
            responses_current: false,
            stress_w: Vec::new(),
            tangent_w: Vec::new(),
            tangent_norms: Vec::new(),
            mapped: Vec::new(),
            increments: Vec::new(),
            stiffness_assembled: false,
        }
    }
}

/// The implicit quasi-static solver in dimension `D` composed of the
/// components `P` ([`SolverParts`]: basis, formulation, law, locking
/// treatment, domain updater, Dirichlet conditions). Every combination
/// monomorphises; a scene pays only for the components it names. Build
/// one with [`ImplicitBuilder`] (the types are inferred) or
/// [`ImplicitSolver::new`].
pub struct ImplicitSolver<const D: usize, P: SolverParts<D>> {
    /// The basis.
    pub basis: P::Basis,
    /// The background mesh.
    pub mesh: P::Mesh,
    /// The statement of equilibrium.
    pub formulation: P::Formulation,
    /// The material law (one material per body).
    pub law: P::Law,
    /// The locking treatment.
    pub locking: P::Locking,
    /// The domain updater.
    pub updater: P::Updater,
    /// Dirichlet conditions.
    pub constraints: P::Constraints,
    /// Newton controls.
    pub options: NewtonOptions,
    linear: Box<dyn LinearSolver>,
    /// `linear` holds the analysed pattern of the current system.
    analysed: bool,
    system: StepSystem<D>,
    /// The patches of a coupled locking treatment (empty otherwise).
    patches: PatchSystem<D>,
    /// The faces of the ghost penalty (empty when it is off).
    ghost: GhostFaces,
    it: Iterate<D, P::History>,
    /// The last converged increment per mesh dof and its load increment.
    previous: Option<(Vec<f64>, f64)>,
    /// The last converged step converged on its first iterate
    /// ([`NewtonMonitor::expecting_first_correction`]).
    first_iterate_converged: bool,
    /// Per point, the cell where its location starts (the parent cell of
    /// the last step; walking on unstructured meshes, Wang et al. 2021
    /// Algorithm 1); `usize::MAX` when unknown.
    hints: Vec<usize>,
    /// The other ranks of a distributed run ([`Self::on_ranks`]).
    ranks: Option<on_ranks::RankLink>,
    /// The nodes in contact with the rigid tools of the constraints
    /// ([`crate::Constraints::tools`]) and their committed forces.
    contact: contact::ContactState<D>,
}

impl<const D: usize, P: SolverParts<D>> ImplicitSolver<D, P> {
    /// Composes a solver with the default formulation value of
    /// `P::Formulation` and the linear solver of `options.linear`; see
    /// [`ImplicitBuilder`] to choose them as values and let the types be
    /// inferred.
    pub fn new(
        basis: P::Basis,
        mesh: P::Mesh,
        law: P::Law,
        locking: P::Locking,
        updater: P::Updater,
        constraints: P::Constraints,
        options: NewtonOptions,
    ) -> Self {
        Self {
            basis,
            mesh,
            formulation: Default::default(),
            law,
            locking,
            updater,
            constraints,
            options,
            linear: options.linear.build(D),
            analysed: false,
            system: StepSystem::default(),
            patches: PatchSystem::default(),
            ghost: GhostFaces::default(),
            it: Iterate::default(),
            previous: None,
            first_iterate_converged: false,
            hints: Vec::new(),
            ranks: None,
            contact: contact::ContactState::default(),
        }
    }

    /// Runs this solver as one rank of a distributed run: its points are
    /// this rank's, the mesh and the constraints every rank's
    /// (`on_ranks`'s module docs: the system of each step is the same on
    /// every rank, rank 0 solves it). Every rank must call the same
    /// methods with the same load factors. The ghost penalty is refused
    /// at the first step (its face terms belong to no rank's points), and
    /// a patch of a coupled locking treatment must hold the points of one
    /// rank only.
    pub fn on_ranks(&mut self, ranks: Box<dyn crate::ranks::Ranks>) {
        self.ranks = Some(on_ranks::RankLink::new(ranks));
    }

    /// On several ranks, the problem's index of each of this rank's points
    /// (e.g. their global ids), by which its failures name them, as one
    /// process would; without it they name the rank's local indices.
    /// Nothing on one rank.
    pub fn name_points(&mut self, ids: Vec<usize>) {
        if let Some(link) = &mut self.ranks {
            link.name_points(ids);
        }
    }

    /// This rank and the number of ranks ((0, 1) on one).
    pub fn rank(&self) -> (usize, usize) {
        self.ranks
            .as_ref()
            .map_or((0, 1), on_ranks::RankLink::rank_and_size)
    }

    /// Replaces the linear solver (the default is the one
    /// `options.linear` describes: [`crate::LinearChoice`]).
    pub fn set_linear_solver(&mut self, linear: Box<dyn LinearSolver>) {
        self.linear = linear;
        self.analysed = false;
    }

    /// The linear solver.
    pub fn linear_solver(&self) -> &dyn LinearSolver {
        &*self.linear
    }

    /// Solves the load step from load factor `lambda0` to `lambda1`: the
    /// stages of the module docs. On success the points hold the converged
    /// state; on failure they are untouched.
    pub fn solve_load_step(
        &mut self,
        points: &mut PointsOf<D, P>,
        lambda0: f64,
        lambda1: f64,
    ) -> Result<StepReport<D>, StepError> {
        let mut bound = driver::Bound {
            solver: self,
            points,
        };
        driver::solve_load_step(&mut bound, lambda0, lambda1)
    }

    /// Normalised out-of-balance force (eq. 40):
    /// $\|f^R\| / \|f^{ext} + f^{react}\|$, the residual taken over free
    /// dofs and the reactions over prescribed ones.
    pub fn normalised_residual(&self) -> f64 {
        let (r, d) = convergence::residual_parts(&self.system, &self.it.f_int, &self.it.f_ext);
        convergence::ratio(r, d)
    }

    /// The number of faces the ghost penalty acts on in the current load
    /// step ([`crate::NewtonOptions::ghost`]; zero when it is off).
    pub fn ghost_face_count(&self) -> usize {
        self.ghost.len()
    }

    /// The stiffness last assembled on the current load step's system (in
    /// a converged step: at the last iterate before the final correction,
    /// or at the converged iterate when Newton expected to correct it,
    /// [`StepReport::unused_tangents`]), or `None` if the step converged
    /// without assembling one.
    /// `None` too on ranks whose linear solver takes each rank's own
    /// values ([`LinearSolver::solves_over_ranks`]): no rank holds the
    /// whole stiffness.
    pub fn free_stiffness(&self) -> Option<FreeStiffness<'_>> {
        let partial = self.ranks.is_some() && self.linear.solves_over_ranks();
        (self.it.stiffness_assembled && !partial).then(|| FreeStiffness {
            n: self.system.n_free,
            col_ptr: &self.system.col_ptr,
            row_idx: &self.system.row_idx,
            values: &self.it.values,
        })
    }
}
