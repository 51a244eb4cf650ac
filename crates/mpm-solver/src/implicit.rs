//! The generic implicit Newton–Raphson solver for quasi-static problems
//! (Coombs et al. 2020 §6.3; the algorithm of AMPLE, Coombs & Augarde 2020).
//!
//! One load step, [`ImplicitSolver::solve_load_step`], is the paper's
//! algorithm:
//!
//! 1. [`evaluate_basis`](ImplicitSolver::evaluate_basis): basis values and
//!    gradients at the start of the step, once per step;
//! 2. [`build_system`](ImplicitSolver::build_system): active nodes, dofs,
//!    prescribed increments, sparsity pattern, symbolic factorisation;
//! 3. [`assemble_external_force`](ImplicitSolver::assemble_external_force):
//!    eqs. (24), (25), (29);
//! 4. Newton iterations: [`update_material_points`](ImplicitSolver::update_material_points)
//!    (eq. 7, the constitutive update), [`assemble_internal_force`](ImplicitSolver::assemble_internal_force)
//!    (eqs. 6/23, 28), the convergence check on eq. (40), then
//!    [`assemble_stiffness`](ImplicitSolver::assemble_stiffness) (eqs. 4/21, 27)
//!    and the linear solve (eqs. 26, 30);
//! 5. [`commit`](ImplicitSolver::commit): positions (eq. 31), deformation,
//!    volumes, history and domains.
//!
//! Material-point loops run in parallel with rayon; every sum is taken in
//! an order fixed by point and node numbering, so results do not depend on
//! the number of threads.

use std::marker::PhantomData;

use mpm_basis::{BasisFunction, Stencil};
use mpm_constitutive::tensor::{Tensor4, embed, idx};
use mpm_constitutive::{ConsistentTangent, LogStrainLaw, MaterialState, Response, update};
use nalgebra::{Matrix3, SMatrix, SVector};
use rayon::prelude::*;

use crate::boundary::{Constraints, StepView};
use crate::domain::{DomainContext, DomainError, DomainUpdater};
use crate::error::{SolverError, StepFailure};
use crate::formulation::Formulation;
use crate::linear::{Factorisation, LinearSolver};
use crate::locking::LockingTreatment;
use crate::mesh::{MovableMesh, NodalMesh};
use crate::points::MaterialPoints;
use crate::system::{NONE, StepSystem};

/// Halvings of a Newton correction that inverts a material point before
/// the step fails.
pub const MAX_BACKTRACKS: usize = 10;

/// Newton–Raphson controls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Tolerance on the normalised out-of-balance force, eq. (40).
    pub tolerance: f64,
    /// Maximum number of iterations (linear solves) per step.
    pub max_iterations: usize,
    /// The step is declared divergent when the normalised residual exceeds
    /// this factor times its value at iteration 0.
    pub divergence_factor: f64,
    /// Nodes whose support volume $\sum_p S_{vp}V^n_p$ is below this
    /// fraction of the largest nodal support volume are held fixed over the
    /// step. Such fringe nodes (a GIMP domain or B-spline stencil barely
    /// reaching them) add next to no stiffness; left free they make the
    /// stiffness nearly singular, and the nearly arbitrary increments they
    /// receive would move the points through $S_{vp}\Delta u_v$ (eq. 31).
    /// Zero disables the rule.
    pub weak_node_threshold: f64,
    /// Nodes whose stiffness weight $\sum_p |\nabla S_{vp}|^2 V^n_p$ is below
    /// this fraction of the largest are held fixed over the step too. For
    /// domain-based bases (GIMP, CPDI2, B-splines) value and gradient of a
    /// fringe node vanish together, so holding it adds a reaction of the
    /// order of $\sigma\,\nabla S_{vp}V_p$, which is small; left free, two
    /// such nodes touched by one point only form a mechanism (a rotation
    /// that strains no point) along which Newton iterates run away.
    /// Standard MPM's far-side nodes keep gradients of order $1/h$ and are
    /// not affected. Zero disables the rule.
    pub weak_node_stiffness: f64,
    /// Start each step's iterations from the previous step's converged
    /// increment, scaled by the ratio of load increments, at the free
    /// nodes that were active then (a secant predictor). Off, the free
    /// nodes start at zero increment, as in Coombs et al. 2020. The
    /// predictor saves iterations on smooth load paths and keeps Newton on
    /// the branch of the previous step where the equilibrium path has
    /// bifurcations (perfect plasticity).
    pub predictor: bool,
    /// Largest admissible $\max(\|\Delta F\|_F, \|\Delta F^{-1}\|_F)$ of
    /// any material point within one load step (the identity has
    /// $\sqrt3$; 10 allows principal stretches from about 0.1 to 9.9). An
    /// iterate beyond it fails the step, which is retried with a smaller
    /// increment: Newton iterates that slide along a near-mechanism grow a
    /// point's stretch geometrically while the Hencky stress
    /// $\propto \ln\lambda/\lambda$ and hence the residual decay, and would
    /// otherwise "converge" with the point flung far away.
    pub max_increment_norm: f64,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-9,
            max_iterations: 30,
            divergence_factor: 1e6,
            weak_node_threshold: 1e-6,
            weak_node_stiffness: 1e-4,
            predictor: false,
            max_increment_norm: 10.0,
        }
    }
}

/// What one converged load step did.
#[derive(Debug, Clone, PartialEq)]
pub struct StepReport<const D: usize> {
    /// Load factor at the start of the step.
    pub lambda0: f64,
    /// Load factor at the end of the step.
    pub lambda1: f64,
    /// Normalised residual (eq. 40) at iterations 0, 1, ...
    pub residuals: Vec<f64>,
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
}

impl<const D: usize> StepReport<D> {
    /// Number of Newton iterations (linear solves).
    pub fn iterations(&self) -> usize {
        self.residuals.len().saturating_sub(1)
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
    /// [`SolverError::InvalidInput`] if the arrays do not form a CSC matrix
    /// (which would be a bug of the assembly).
    pub fn to_sprs(&self) -> Result<sprs::CsMat<f64>, SolverError> {
        sprs::CsMat::try_new_csc(
            (self.n, self.n),
            self.col_ptr.to_vec(),
            self.row_idx.to_vec(),
            self.values.to_vec(),
        )
        .map_err(|(.., e)| {
            SolverError::InvalidInput(format!("the assembled stiffness is not a CSC matrix: {e}"))
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

/// Per-iteration buffers, sized once per step.
#[derive(Debug)]
struct Iterate<const D: usize, H> {
    du: Vec<f64>,
    f_ext: Vec<f64>,
    f_int: Vec<f64>,
    rhs: Vec<f64>,
    values: Vec<f64>,
    responses: Vec<Option<Response<H>>>,
    stress_w: Vec<Matrix3<f64>>,
    tangent_w: Vec<Tensor4>,
    mapped: Vec<SVector<f64, D>>,
    increments: Vec<Matrix3<f64>>,
    volumes: Vec<f64>,
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
            stress_w: Vec::new(),
            tangent_w: Vec::new(),
            mapped: Vec::new(),
            increments: Vec::new(),
            volumes: Vec::new(),
            stiffness_assembled: false,
        }
    }
}

/// The implicit quasi-static solver, generic over dimension `D`, basis `B`,
/// formulation `F`, material law `L`, locking treatment `K`, domain updater
/// `U` and Dirichlet conditions `C`. Every combination monomorphises; a
/// scene pays only for the components it names.
pub struct ImplicitSolver<const D: usize, B, F, L, K, U, C>
where
    B: BasisFunction<D>,
    L: LogStrainLaw,
{
    /// The basis.
    pub basis: B,
    /// The background mesh.
    pub mesh: B::Mesh,
    /// The material law (one material per body).
    pub law: L,
    /// The locking treatment.
    pub locking: K,
    /// The domain updater.
    pub updater: U,
    /// Dirichlet conditions.
    pub constraints: C,
    /// Newton controls.
    pub options: NewtonOptions,
    system: StepSystem<D>,
    it: Iterate<D, L::History>,
    linear: Option<LinearSolver>,
    /// The last converged increment per mesh dof and its load increment.
    previous: Option<(Vec<f64>, f64)>,
    /// Per point, the cell where its location starts (the parent cell of
    /// the last step; walking on unstructured meshes, Wang et al. 2021
    /// Algorithm 1); `usize::MAX` when unknown.
    hints: Vec<usize>,
    _formulation: PhantomData<F>,
}

impl<const D: usize, B, F, L, K, U, C> ImplicitSolver<D, B, F, L, K, U, C>
where
    B: BasisFunction<D>,
    B::Mesh: MovableMesh<D>,
    F: Formulation,
    L: LogStrainLaw,
    K: LockingTreatment,
    U: DomainUpdater<D, B::Domain>,
    C: Constraints<D>,
{
    /// Composes a solver.
    pub fn new(
        basis: B,
        mesh: B::Mesh,
        law: L,
        locking: K,
        updater: U,
        constraints: C,
        options: NewtonOptions,
    ) -> Self {
        Self {
            basis,
            mesh,
            law,
            locking,
            updater,
            constraints,
            options,
            system: StepSystem::default(),
            it: Iterate::default(),
            linear: None,
            previous: None,
            hints: Vec::new(),
            _formulation: PhantomData,
        }
    }

    /// Solves the load step from load factor `lambda0` to `lambda1`: the
    /// stages of the module docs. On success the points hold the converged
    /// state; on failure they are untouched.
    pub fn solve_load_step(
        &mut self,
        points: &mut MaterialPoints<D, L::History, B::Domain>,
        lambda0: f64,
        lambda1: f64,
    ) -> Result<StepReport<D>, StepError> {
        self.prepare_step(points, lambda0, lambda1)?;
        self.predict(lambda1 - lambda0);
        let mut residuals = Vec::new();
        let mut backtracked = Vec::new();
        let mut force_scale = 0.0f64;
        let mut initial_unbalance = None;
        loop {
            let iteration = residuals.len();
            let shortened = self.update_material_points_backtracking(points, iteration > 0);
            if matches!(shortened, Ok(true)) {
                backtracked.push(iteration);
            }
            shortened.map_err(|cause| StepError::Retry {
                cause,
                last_residual: residuals.last().copied().unwrap_or(f64::NAN),
            })?;
            self.assemble_internal_force();
            // Eq. (40), normalised by the largest external-plus-reaction
            // force of the step so far: when the solution is stress free
            // (a rigid motion imposed on the boundary) the reactions vanish
            // with the residual and the plain ratio would stay of order one.
            let (r, d) = self.residual_parts();
            if iteration == 0 {
                initial_unbalance = self.unbalance_all_dofs();
            }
            force_scale = force_scale.max(d);
            let residual = ratio(r, force_scale);
            residuals.push(residual);
            if residual <= self.options.tolerance {
                break;
            }
            if !residual.is_finite()
                || residual
                    > self.options.divergence_factor * residuals[0].max(self.options.tolerance)
            {
                return Err(StepError::Retry {
                    cause: StepFailure::Diverged {
                        iteration,
                        residual,
                    },
                    last_residual: residual,
                });
            }
            if iteration >= self.options.max_iterations {
                return Err(StepError::Retry {
                    cause: StepFailure::IterationLimit {
                        iterations: iteration,
                        residual,
                    },
                    last_residual: residual,
                });
            }
            self.update_tangents(points)
                .map_err(|cause| StepError::Retry {
                    cause,
                    last_residual: residual,
                })?;
            self.assemble_stiffness();
            self.solve().map_err(|reason| StepError::Retry {
                cause: StepFailure::LinearSolve { reason },
                last_residual: residual,
            })?;
        }
        let reaction = self.reaction();
        self.commit(points)?;
        // The mesh follows to the end of the step, with the points.
        self.move_mesh(lambda1)?;
        self.remember_increment(lambda1 - lambda0);
        Ok(StepReport {
            lambda0,
            lambda1,
            residuals,
            initial_unbalance,
            reaction,
            active_nodes: self.system.n_active(),
            free_dofs: self.system.n_free,
            factorisation: self
                .linear
                .as_ref()
                .and_then(LinearSolver::last_factorisation),
            backtracked,
        })
    }

    /// Stage 0: a moving mesh takes its position at load factor `lambda0`
    /// ([`Constraints::move_mesh`]; nothing for a fixed mesh). Called at
    /// the start of every step attempt and after every converged step, so
    /// that mesh and points always belong to the same load factor.
    pub fn move_mesh(&mut self, lambda0: f64) -> Result<(), SolverError> {
        self.constraints
            .move_mesh(&mut self.mesh, lambda0)
            .map_err(|reason| {
                SolverError::InvalidInput(format!(
                    "moving the mesh to load factor {lambda0}: {reason}"
                ))
            })
    }

    /// Stage 1: basis values and gradients of every point at the start of
    /// the step, into fixed-stride slots (no allocation per point: each
    /// worker reuses one stencil buffer).
    pub fn evaluate_basis(
        &mut self,
        points: &MaterialPoints<D, L::History, B::Domain>,
    ) -> Result<(), SolverError> {
        let n = points.len();
        let stride = B::MAX_NODES;
        let sys = &mut self.system;
        sys.stride = stride;
        sys.nodes.clear();
        sys.nodes.resize(n * stride, 0);
        sys.values.clear();
        sys.values.resize(n * stride, 0.0);
        sys.grads.clear();
        sys.grads.resize(n * stride, SVector::zeros());
        sys.counts.clear();
        sys.counts.resize(n, 0);
        let (basis, mesh) = (&self.basis, &self.mesh);
        let node_count = mesh.node_count();
        self.hints.resize(n, usize::MAX);
        sys.nodes
            .par_chunks_mut(stride)
            .zip(sys.values.par_chunks_mut(stride))
            .zip(sys.grads.par_chunks_mut(stride))
            .zip(sys.counts.par_iter_mut())
            .zip(self.hints.par_iter_mut())
            .enumerate()
            .try_for_each_init(
                || Stencil::<D>::with_capacity(stride),
                |stencil, (p, ((((nodes, values), grads), count), hint))| {
                    let x = &points.position[p];
                    basis
                        .evaluate_hinted(mesh, x, &points.domain[p], hint, stencil)
                        .map_err(|e| SolverError::Basis {
                            point: p,
                            position: x.iter().copied().collect(),
                            reason: e.to_string(),
                        })?;
                    let m = stencil.nodes.len();
                    if m > stride || stencil.nodes.iter().any(|&v| v >= node_count) {
                        return Err(SolverError::Basis {
                            point: p,
                            position: x.iter().copied().collect(),
                            reason: format!(
                                "basis returned {m} nodes (max {stride}) or a node outside the mesh"
                            ),
                        });
                    }
                    for a in 0..m {
                        nodes[a] = stencil.nodes[a] as u32;
                        values[a] = stencil.values[a];
                        grads[a] = stencil.gradients[a];
                    }
                    *count = m as u32;
                    Ok(())
                },
            )
    }

    /// Stage 2: active nodes, dofs, prescribed increments, adjacency,
    /// sparsity pattern and the symbolic factorisation.
    pub fn build_system(
        &mut self,
        volumes: &[f64],
        lambda0: f64,
        lambda1: f64,
    ) -> Result<(), SolverError> {
        let node_count = self.mesh.node_count();
        let sys = &mut self.system;
        sys.number_nodes(node_count);
        sys.build_adjacency();
        sys.build_neighbours();
        // Per active node: support Σ S V and stiffness weight Σ |∇S|² V.
        let (support, stiffness): (Vec<f64>, Vec<f64>) = (0..sys.n_active())
            .map(|v| {
                sys.adj[sys.adj_ptr[v]..sys.adj_ptr[v + 1]].iter().fold(
                    (0.0, 0.0),
                    |(s, k), &(p, a)| {
                        let slot = p as usize * sys.stride + a as usize;
                        let volume = volumes[p as usize];
                        (
                            s + sys.values[slot] * volume,
                            k + sys.grads[slot].norm_squared() * volume,
                        )
                    },
                )
            })
            .unzip();
        let max = |x: &[f64]| x.iter().copied().fold(0.0, f64::max);
        let (support_cut, stiffness_cut) = (
            self.options.weak_node_threshold * max(&support),
            self.options.weak_node_stiffness * max(&stiffness),
        );
        let weak: Vec<bool> = support
            .iter()
            .zip(&stiffness)
            .map(|(&s, &k)| s < support_cut || k < stiffness_cut)
            .collect();
        let constraints = &self.constraints;
        let active_of_mesh = std::mem::take(&mut sys.active_of_mesh);
        sys.build_pattern(|node, i| {
            let held = weak[active_of_mesh[node] as usize];
            constraints
                .prescribed(node, i, lambda0, lambda1)
                .or(held.then_some(0.0))
        });
        sys.active_of_mesh = active_of_mesh;
        let n_dofs = D * sys.n_active();
        let it = &mut self.it;
        it.du.clear();
        it.du.extend_from_slice(&sys.prescribed);
        it.f_int.clear();
        it.f_int.resize(n_dofs, 0.0);
        it.f_ext.clear();
        it.f_ext.resize(n_dofs, 0.0);
        it.values.clear();
        it.values.resize(sys.row_idx.len(), 0.0);
        it.stiffness_assembled = false;
        let symmetric = L::SYMMETRIC_TANGENT && !K::COUPLES_POINTS;
        self.linear = Some(
            LinearSolver::new(
                sys.n_free,
                sys.col_ptr.clone(),
                sys.row_idx.clone(),
                symmetric,
            )
            .map_err(|e| SolverError::InvalidInput(format!("sparsity analysis failed: {e}")))?,
        );
        Ok(())
    }

    /// The secant predictor ([`NewtonOptions::predictor`]): free dofs start
    /// from the previous converged increment scaled to this step.
    fn predict(&mut self, dlambda: f64) {
        if !self.options.predictor {
            return;
        }
        let Some((previous, dlambda_prev)) = &self.previous else {
            return;
        };
        let scale = dlambda / dlambda_prev;
        let sys = &self.system;
        for (dof, &free) in sys.free_of_dof.iter().enumerate() {
            if free != NONE {
                let mesh_dof = D * sys.active[dof / D] + dof % D;
                self.it.du[dof] = scale * previous[mesh_dof];
            }
        }
    }

    /// The secant predictor's memory: the last converged increment per mesh
    /// dof and its load increment ([`NewtonOptions::predictor`]); `None`
    /// before the first step or with the predictor off. Saved with a
    /// checkpoint so that a resumed run repeats the uninterrupted one.
    pub fn predictor_state(&self) -> Option<(&[f64], f64)> {
        self.previous.as_ref().map(|(u, dl)| (u.as_slice(), *dl))
    }

    /// Restores [`Self::predictor_state`].
    ///
    /// # Errors
    /// [`SolverError::InvalidInput`] if the increment does not have one
    /// entry per mesh dof or is not finite.
    pub fn set_predictor_state(
        &mut self,
        state: Option<(Vec<f64>, f64)>,
    ) -> Result<(), SolverError> {
        if let Some((u, dl)) = &state {
            let n = D * self.mesh.node_count();
            if u.len() != n || !u.iter().all(|x| x.is_finite()) || !(dl.is_finite() && *dl > 0.0) {
                return Err(SolverError::InvalidInput(format!(
                    "predictor state has {} finite-checked entries for {n} mesh dofs and load increment {dl}",
                    u.len()
                )));
            }
        }
        self.previous = state;
        Ok(())
    }

    /// Stores the converged increment per mesh dof for the predictor.
    fn remember_increment(&mut self, dlambda: f64) {
        if !self.options.predictor {
            return;
        }
        let n = D * self.mesh.node_count();
        let (mut store, _) = self.previous.take().unwrap_or_default();
        store.clear();
        store.resize(n, 0.0);
        for (dof, du) in self.it.du.iter().enumerate() {
            store[D * self.system.active[dof / D] + dof % D] = *du;
        }
        self.previous = Some((store, dlambda));
    }

    /// Stage 3: $f^{ext} = \lambda_1\sum_p [S_{vp}]^T(b_p + f_p)$ (eqs. 24,
    /// 25, 29), plus the non-proportional body force
    /// $\sum_p [S_{vp}]^T b_p(\lambda_1)$ when the points have one; constant
    /// over the step.
    pub fn assemble_external_force(
        &mut self,
        points: &MaterialPoints<D, L::History, B::Domain>,
        lambda1: f64,
    ) {
        let sys = &self.system;
        let f_ext = &mut self.it.f_ext;
        let mut add = |p: usize, force: &SVector<f64, D>| {
            for s in sys.slots(p) {
                let v = sys.nodes[s] as usize;
                for i in 0..D {
                    f_ext[D * v + i] += lambda1 * sys.values[s] * force[i];
                }
            }
        };
        for (p, b) in points.body_force.iter().enumerate() {
            add(p, b);
        }
        for (p, force) in &points.point_force {
            add(*p, force);
        }
        if let Some(path) = &points.body_force_path {
            for p in 0..points.len() {
                let force = (path.0)(p, lambda1);
                for s in sys.slots(p) {
                    let v = sys.nodes[s] as usize;
                    for i in 0..D {
                        f_ext[D * v + i] += sys.values[s] * force[i];
                    }
                }
            }
        }
    }

    /// Stage 4a with backtracking: when a Newton correction inverts a
    /// material point (det ΔF <= 0 or another constitutive failure) or
    /// stretches it beyond [`NewtonOptions::max_increment_norm`], the
    /// correction is halved, up to [`MAX_BACKTRACKS`] times, before the step
    /// is declared failed. Sparsely populated cells give nodes with little
    /// stiffness whose corrections can overshoot; backtracking keeps Newton
    /// on track without changing the converged solution.
    fn update_material_points_backtracking(
        &mut self,
        points: &MaterialPoints<D, L::History, B::Domain>,
        after_solve: bool,
    ) -> Result<bool, StepFailure> {
        let mut result = self.update_material_points(points);
        let mut backtracks = 0;
        while let Err(StepFailure::Constitutive { .. } | StepFailure::ExcessiveIncrement { .. }) =
            result
        {
            if !after_solve || backtracks == MAX_BACKTRACKS {
                break;
            }
            backtracks += 1;
            let sys = &self.system;
            let it = &mut self.it;
            for (dof, &free) in sys.free_of_dof.iter().enumerate() {
                if free != NONE {
                    let half = 0.5 * it.rhs[free as usize];
                    it.du[dof] -= half;
                    it.rhs[free as usize] = half;
                }
            }
            result = self.update_material_points(points);
        }
        result.map(|()| backtracks > 0)
    }

    /// Stage 4a: for every point, $\Delta F$ from the grid displacement
    /// increment (eq. 7), the locking treatment, the constitutive update
    /// and the weighted stress of the formulation.
    pub fn update_material_points(
        &mut self,
        points: &MaterialPoints<D, L::History, B::Domain>,
    ) -> Result<(), StepFailure> {
        let n = points.len();
        let sys = &self.system;
        let it = &mut self.it;
        it.responses.resize(n, None);
        it.stress_w.resize(n, Matrix3::zeros());
        if F::MAPS_GRADIENTS {
            it.mapped.resize(sys.grads.len(), SVector::zeros());
        }
        let du = &it.du;
        let increment = |p: usize| -> Matrix3<f64> {
            let mut g = SMatrix::<f64, D, D>::identity();
            for s in sys.slots(p) {
                let v = sys.nodes[s] as usize;
                for i in 0..D {
                    for j in 0..D {
                        g[(i, j)] += du[D * v + i] * sys.grads[s][j];
                    }
                }
            }
            embed(&g)
        };
        if K::COUPLES_POINTS {
            it.increments.resize(n, Matrix3::identity());
            it.increments
                .par_iter_mut()
                .enumerate()
                .for_each(|(p, m)| *m = increment(p));
            it.volumes.clear();
            it.volumes.extend_from_slice(&points.volume);
            self.locking.prepare(&it.increments, &it.volumes);
        }
        let (law, locking) = (&self.law, &self.locking);
        let limit = self.options.max_increment_norm;
        let stride = sys.stride;
        let mapped_chunks = it.mapped.par_chunks_mut(stride.max(1));
        let failure = it
            .responses
            .par_iter_mut()
            .zip(it.stress_w.par_iter_mut())
            .enumerate()
            .map(|(p, (response, stress))| {
                let delta_f = locking.modified_increment(p, &increment(p));
                let state = MaterialState {
                    be: points.be[p],
                    history: points.history[p],
                };
                match update(law, &delta_f, &points.f[p], &state) {
                    Ok(r) => {
                        let norm = r.delta_f.norm().max(r.delta_f_inv.norm());
                        if norm > limit {
                            return Some(StepFailure::ExcessiveIncrement {
                                point: p,
                                norm,
                                limit,
                            });
                        }
                        *stress = F::stress(&r) * F::volume(&r, points.volume[p]);
                        *response = Some(r);
                        None
                    }
                    Err(source) => Some(StepFailure::Constitutive { point: p, source }),
                }
            })
            .reduce(
                || None,
                // The failure of the lowest point, whatever the thread count.
                |a, b| match (
                    a.as_ref().and_then(failed_point),
                    b.as_ref().and_then(failed_point),
                ) {
                    (Some(pa), Some(pb)) if pb < pa => b,
                    (Some(_), _) => a,
                    _ => b,
                },
            );
        if let Some(f) = failure {
            return Err(f);
        }
        if F::MAPS_GRADIENTS {
            let responses = &it.responses;
            mapped_chunks.enumerate().for_each(|(p, chunk)| {
                if let Some(r) = &responses[p] {
                    for (a, s) in sys.slots(p).enumerate() {
                        chunk[a] = F::map_gradient(r, &sys.grads[s]);
                    }
                }
            });
        }
        Ok(())
    }

    /// Stage 4b: $f^{int}_v = \sum_p [\nabla S_{vp}]^T\{\text{stress}\}V$
    /// (eqs. 6, 23, 28), one active node per task.
    pub fn assemble_internal_force(&mut self) {
        let grads = if F::MAPS_GRADIENTS {
            &self.it.mapped
        } else {
            &self.system.grads
        };
        let sys = &self.system;
        let stress_w = &self.it.stress_w;
        self.it
            .f_int
            .par_chunks_mut(D)
            .enumerate()
            .for_each(|(v, f)| {
                f.iter_mut().for_each(|x| *x = 0.0);
                for &(p, a) in &sys.adj[sys.adj_ptr[v]..sys.adj_ptr[v + 1]] {
                    let s = p as usize * sys.stride + a as usize;
                    let sw = &stress_w[p as usize];
                    for i in 0..D {
                        for j in 0..D {
                            f[i] += sw[(i, j)] * grads[s][j];
                        }
                    }
                }
            });
    }

    /// Normalised out-of-balance force (eq. 40):
    /// $\|f^R\| / \|f^{ext} + f^{react}\|$, the residual taken over free
    /// dofs and the reactions over prescribed ones.
    pub fn normalised_residual(&self) -> f64 {
        let (r, d) = self.residual_parts();
        ratio(r, d)
    }

    /// $(\|f^R\|, \|f^{ext} + f^{react}\|)$ of eq. (40).
    fn residual_parts(&self) -> (f64, f64) {
        let (mut r2, mut d2) = (0.0, 0.0);
        for (dof, &free) in self.system.free_of_dof.iter().enumerate() {
            let (fi, fe) = (self.it.f_int[dof], self.it.f_ext[dof]);
            if free == NONE {
                d2 += fi * fi;
            } else {
                r2 += (fi - fe) * (fi - fe);
                d2 += fe * fe;
            }
        }
        (r2.sqrt(), d2.sqrt())
    }

    /// $\|f^{ext} - f^{int}\| / \|f^{ext}\|$ over every active dof
    /// (see [`StepReport::initial_unbalance`]); `None` without external
    /// force or when not finite.
    fn unbalance_all_dofs(&self) -> Option<f64> {
        let (mut r2, mut e2) = (0.0, 0.0);
        for (fi, fe) in self.it.f_int.iter().zip(&self.it.f_ext) {
            r2 += (fe - fi) * (fe - fi);
            e2 += fe * fe;
        }
        let u = r2.sqrt() / e2.sqrt();
        (e2 > 0.0 && u.is_finite()).then_some(u)
    }

    /// Sum of reactions per component at prescribed dofs.
    fn reaction(&self) -> SVector<f64, D> {
        let mut r = SVector::<f64, D>::zeros();
        for (dof, &free) in self.system.free_of_dof.iter().enumerate() {
            if free == NONE {
                r[dof % D] += self.it.f_int[dof] - self.it.f_ext[dof];
            }
        }
        r
    }

    /// Stage 4c: the formulation's consistent tangent at every point,
    /// weighted by its integration volume.
    pub fn update_tangents(
        &mut self,
        points: &MaterialPoints<D, L::History, B::Domain>,
    ) -> Result<(), StepFailure> {
        let law = &self.law;
        let it = &mut self.it;
        it.tangent_w.resize(it.responses.len(), Tensor4::zeros());
        it.tangent_w
            .par_iter_mut()
            .zip(it.responses.par_iter())
            .enumerate()
            .try_for_each(|(p, (t, r))| {
                if let Some(r) = r {
                    let volume = F::volume(r, points.volume[p]);
                    *t = F::Tangent::tangent(law, r)
                        .map_err(|source| StepFailure::Constitutive { point: p, source })?
                        * volume;
                }
                Ok(())
            })
    }

    /// Stage 4d: the stiffness (eqs. 4/21, 27) in CSC over free dofs, one
    /// block column (active node) per task; each entry is summed over
    /// points in ascending order.
    pub fn assemble_stiffness(&mut self) {
        let grads = if F::MAPS_GRADIENTS {
            &self.it.mapped
        } else {
            &self.system.grads
        };
        let sys = &self.system;
        let tangent_w = &self.it.tangent_w;
        let n = sys.n_active();
        let block = |w: usize, vals: &mut [f64]| {
            vals.iter_mut().for_each(|x| *x = 0.0);
            let nbs = &sys.nb[sys.nb_ptr[w]..sys.nb_ptr[w + 1]];
            let map = &sys.block_map[sys.nb_ptr[w] * D * D..sys.nb_ptr[w + 1] * D * D];
            for &(p, b) in &sys.adj[sys.adj_ptr[w]..sys.adj_ptr[w + 1]] {
                let p = p as usize;
                let t = &tangent_w[p];
                let gw = &grads[p * sys.stride + b as usize];
                // q[i][j][k] = Σ_l T_(ij)(kl) g_w,l
                let mut q = [[[0.0f64; D]; D]; D];
                for i in 0..D {
                    for j in 0..D {
                        for k in 0..D {
                            let mut acc = 0.0;
                            for l in 0..D {
                                acc += t[(idx(i, j), idx(k, l))] * gw[l];
                            }
                            q[i][j][k] = acc;
                        }
                    }
                }
                for s in sys.slots(p) {
                    let v = sys.nodes[s];
                    let pos = match nbs.binary_search(&v) {
                        Ok(pos) => pos,
                        Err(_) => continue,
                    };
                    let gv = &grads[s];
                    for i in 0..D {
                        for k in 0..D {
                            let off = map[(pos * D + i) * D + k];
                            if off != NONE {
                                let mut acc = 0.0;
                                for j in 0..D {
                                    acc += gv[j] * q[i][j][k];
                                }
                                vals[off as usize] += acc;
                            }
                        }
                    }
                }
            }
        };
        split_blocks(0, n, &mut self.it.values, 0, &sys.block_ptr, &block);
        self.it.stiffness_assembled = true;
    }

    /// The stiffness last assembled on the current load step's system (in
    /// a converged step: at the last iterate before the final correction),
    /// or `None` if the step converged without assembling one.
    pub fn free_stiffness(&self) -> Option<FreeStiffness<'_>> {
        self.it.stiffness_assembled.then(|| FreeStiffness {
            n: self.system.n_free,
            col_ptr: &self.system.col_ptr,
            row_idx: &self.system.row_idx,
            values: &self.it.values,
        })
    }

    /// Stage 4e: solve $K\,\delta d = -f^R$ (eq. 26) and accumulate the
    /// increment (eq. 30).
    pub fn solve(&mut self) -> Result<(), String> {
        let sys = &self.system;
        let it = &mut self.it;
        it.rhs.clear();
        it.rhs.resize(sys.n_free, 0.0);
        for (dof, &free) in sys.free_of_dof.iter().enumerate() {
            if free != NONE {
                it.rhs[free as usize] = it.f_ext[dof] - it.f_int[dof];
            }
        }
        let linear = self
            .linear
            .as_mut()
            .ok_or("no linear solver for this step")?;
        linear.solve(&it.values, &mut it.rhs)?;
        for (dof, &free) in sys.free_of_dof.iter().enumerate() {
            if free != NONE {
                it.du[dof] += it.rhs[free as usize];
            }
        }
        Ok(())
    }

    /// The converged grid displacement increment interpolated at `x` (a
    /// point of the configuration at the start of the step) with the
    /// background mesh's own linear shape functions,
    /// $\Delta\mathbf u(\mathbf x) = \sum_v N_v(\mathbf x)\Delta\mathbf u_v$
    /// (eq. 35); used by domain updates that convect corners or mid-points.
    /// Nodes outside the step's active set may appear only with a zero
    /// value (a corner on the face of a cell the domain does not enter).
    fn displacement_at(
        &self,
        x: &SVector<f64, D>,
        stencil: &mut Stencil<D>,
    ) -> Result<SVector<f64, D>, DomainError> {
        self.mesh
            .shape_functions(x, stencil)
            .map_err(|e| DomainError(e.to_string()))?;
        let mut u = SVector::<f64, D>::zeros();
        for (a, &node) in stencil.nodes.iter().enumerate() {
            let value = stencil.values[a];
            let v = self
                .system
                .active_of_mesh
                .get(node)
                .copied()
                .unwrap_or(NONE);
            if v == NONE {
                if value == 0.0 {
                    continue;
                }
                return Err(DomainError(format!(
                    "node {node} near {:?} is not active",
                    x.as_slice()
                )));
            }
            for i in 0..D {
                u[i] += value * self.it.du[D * v as usize + i];
            }
        }
        Ok(u)
    }

    /// Stage 5: positions (eq. 31), converged deformation and stresses,
    /// volumes (eq. 22) and domains (the domain updater).
    pub fn commit(
        &mut self,
        points: &mut MaterialPoints<D, L::History, B::Domain>,
    ) -> Result<(), SolverError> {
        let n = points.len();
        let stencil = std::cell::RefCell::new(Stencil::<D>::with_capacity(1 << D));
        for p in 0..n {
            let Some(r) = self.it.responses[p].as_ref() else {
                continue;
            };
            let mut du = SVector::<f64, D>::zeros();
            for s in self.system.slots(p) {
                let v = self.system.nodes[s] as usize;
                for i in 0..D {
                    du[i] += self.system.values[s] * self.it.du[D * v + i];
                }
            }
            let previous = points.position[p];
            let position = previous + du;
            let ctx = DomainContext {
                initial: &points.domain0[p],
                previous: &points.domain[p],
                f: &r.f,
                delta_f: &r.delta_f,
                position_previous: &previous,
                position: &position,
            };
            let domain = self
                .updater
                .update(&ctx, |x| self.displacement_at(x, &mut stencil.borrow_mut()))
                .map_err(|e| SolverError::DomainUpdate {
                    point: p,
                    reason: e.0,
                })?;
            points.position[p] = position;
            points.displacement[p] += du;
            points.f[p] = r.f;
            points.be[p] = r.state.be;
            points.history[p] = r.state.history;
            points.sigma[p] = r.sigma;
            points.volume[p] = self.updater.volume(&domain, r.j * points.volume0[p]);
            points.domain[p] = domain;
        }
        Ok(())
    }
}

/// $r/d$, with $0/0 = 0$ and $r/0 = \infty$.
fn ratio(r: f64, d: f64) -> f64 {
    if r == 0.0 {
        0.0
    } else if d == 0.0 {
        f64::INFINITY
    } else {
        r / d
    }
}

/// The material point a failure names, if any.
fn failed_point(f: &StepFailure) -> Option<usize> {
    match f {
        StepFailure::Constitutive { point, .. } | StepFailure::ExcessiveIncrement { point, .. } => {
            Some(*point)
        }
        _ => None,
    }
}

/// Runs `f(w, values_of_block_w)` for the block columns `lo..hi` in
/// parallel, splitting `vals` (which starts at block `lo`, value index
/// `base`) into disjoint slices at block boundaries.
fn split_blocks<F>(lo: usize, hi: usize, vals: &mut [f64], base: usize, block_ptr: &[usize], f: &F)
where
    F: Fn(usize, &mut [f64]) + Sync,
{
    const GRAIN: usize = 64;
    if hi - lo <= GRAIN {
        let mut rest = vals;
        for w in lo..hi {
            let len = block_ptr[w + 1] - block_ptr[w];
            let (head, tail) = rest.split_at_mut(len);
            f(w, head);
            rest = tail;
        }
        return;
    }
    let mid = (lo + hi) / 2;
    let (left, right) = vals.split_at_mut(block_ptr[mid] - base);
    rayon::join(
        || split_blocks(lo, mid, left, base, block_ptr, f),
        || split_blocks(mid, hi, right, block_ptr[mid], block_ptr, f),
    );
}

/// Verification helpers: the residual and the assembled stiffness as dense
/// arrays at a chosen displacement increment, so that tests can compare
/// the stiffness with finite differences of the residual.
impl<const D: usize, B, F, L, K, U, C> ImplicitSolver<D, B, F, L, K, U, C>
where
    B: BasisFunction<D>,
    B::Mesh: MovableMesh<D>,
    F: Formulation,
    L: LogStrainLaw,
    K: LockingTreatment,
    U: DomainUpdater<D, B::Domain>,
    C: Constraints<D>,
{
    /// A load step from `lambda0` to `lambda1` up to its Newton
    /// iterations — mesh position, then stages 1–3 of the module docs
    /// (basis, constraints and system, external force) —
    /// [`Self::solve_load_step`] starts with it; returns the number of free
    /// dofs.
    pub fn prepare_step(
        &mut self,
        points: &MaterialPoints<D, L::History, B::Domain>,
        lambda0: f64,
        lambda1: f64,
    ) -> Result<usize, SolverError> {
        self.move_mesh(lambda0)?;
        self.evaluate_basis(points)?;
        let sys = &self.system;
        self.constraints.begin_step(&StepView::new(
            &points.position,
            &sys.nodes,
            &sys.counts,
            sys.stride,
        ));
        self.build_system(&points.volume, lambda0, lambda1)?;
        self.assemble_external_force(points, lambda1);
        Ok(self.system.n_free)
    }

    /// The out-of-balance force $f^{int} - f^{ext}$ on the free dofs at the
    /// free-dof increment `du_free` (prescribed dofs at their prescribed
    /// increments).
    pub fn free_residual(
        &mut self,
        points: &MaterialPoints<D, L::History, B::Domain>,
        du_free: &[f64],
    ) -> Result<Vec<f64>, StepFailure> {
        self.set_free_increment(du_free);
        self.update_material_points(points)?;
        self.assemble_internal_force();
        let sys = &self.system;
        let mut r = vec![0.0; sys.n_free];
        for (dof, &free) in sys.free_of_dof.iter().enumerate() {
            if free != NONE {
                r[free as usize] = self.it.f_int[dof] - self.it.f_ext[dof];
            }
        }
        Ok(r)
    }

    /// The assembled stiffness over free dofs at `du_free`, dense and
    /// column-major (`n_free × n_free`).
    pub fn free_stiffness_dense(
        &mut self,
        points: &MaterialPoints<D, L::History, B::Domain>,
        du_free: &[f64],
    ) -> Result<Vec<f64>, StepFailure> {
        self.assemble_at(points, du_free)?;
        let sys = &self.system;
        let n = sys.n_free;
        let mut k = vec![0.0; n * n];
        for c in 0..n {
            for e in sys.col_ptr[c]..sys.col_ptr[c + 1] {
                k[c * n + sys.row_idx[e]] = self.it.values[e];
            }
        }
        Ok(k)
    }

    /// One Newton iteration's assembly at `du_free`: material update,
    /// internal force, consistent tangents and the sparse stiffness (what
    /// the benchmarks time).
    pub fn assemble_at(
        &mut self,
        points: &MaterialPoints<D, L::History, B::Domain>,
        du_free: &[f64],
    ) -> Result<f64, StepFailure> {
        self.set_free_increment(du_free);
        self.update_material_points(points)?;
        self.assemble_internal_force();
        self.update_tangents(points)?;
        self.assemble_stiffness();
        Ok(self.normalised_residual())
    }

    /// The current increment at the free dofs (after a converged step: the
    /// converged increment of that step), in the numbering of
    /// [`Self::prepare_step`].
    pub fn free_increment(&self) -> Vec<f64> {
        let sys = &self.system;
        let mut du = vec![0.0; sys.n_free];
        for (dof, &free) in sys.free_of_dof.iter().enumerate() {
            if free != NONE {
                du[free as usize] = self.it.du[dof];
            }
        }
        du
    }

    fn set_free_increment(&mut self, du_free: &[f64]) {
        let sys = &self.system;
        for (dof, &free) in sys.free_of_dof.iter().enumerate() {
            self.it.du[dof] = if free == NONE {
                sys.prescribed[dof]
            } else {
                du_free.get(free as usize).copied().unwrap_or(0.0)
            };
        }
    }
}
