//! The stages of a load step as methods of [`ImplicitSolver`], each a thin
//! binding of the solver's state to the reusable functions of
//! [`crate::stages`], plus the constitutive update and tangents, which
//! depend on the formulation.

use mpm_constitutive::{
    ConsistentTangent, ConstitutiveError, LogStrainLaw, MaterialState, Response, update,
};
use nalgebra::{Matrix3, SVector};

use super::on_ranks::{self, RankLink};
use super::{ImplicitSolver, MAX_BACKTRACKS};
use crate::boundary::{Constraints, StepView};
use crate::error::{SolverError, StepFailure};
use crate::formulation::Formulation;
use crate::linear::LinearSolveError;
use crate::locking::{LockingTreatment, PatchInput};
use crate::mesh::MovableMesh;
use crate::mesh::NodalMesh;
use crate::par::{self, Rows};
use crate::parts::{PointsOf, SolverParts};
use crate::stages::gather::PointStress;
use crate::stages::patch::PatchSystem;
use crate::stages::system::{NONE, StepSystem};
use crate::stages::{basis, convergence, gather, update as grid_to_point};

/// $\epsilon$ of the forward difference in
/// [`ImplicitSolver::linearised_start`]: small enough that points
/// elastic at the converged state stay elastic, large enough that rounding
/// in $\mathbf f^{int}$ (relative $10^{-16}$ of the stresses, against
/// $\epsilon$ times a step's change) stays far below the tolerance.
const LINEARISED_START_STEP: f64 = 1e-3;

/// The material point a failure names, if any.
fn failed_point(f: &StepFailure) -> Option<usize> {
    match f {
        StepFailure::Constitutive { point, .. } | StepFailure::ExcessiveIncrement { point, .. } => {
            Some(*point)
        }
        _ => None,
    }
}

/// The failure of point `point`'s constitutive update or tangent.
fn at_point(point: usize, source: ConstitutiveError) -> StepFailure {
    StepFailure::Constitutive { point, source }
}

/// Of two parallel partial results, the failure of the lowest point,
/// whatever the thread count.
fn lowest_failure(a: Option<StepFailure>, b: Option<StepFailure>) -> Option<StepFailure> {
    match (
        a.as_ref().and_then(failed_point),
        b.as_ref().and_then(failed_point),
    ) {
        (Some(pa), Some(pb)) if pb < pa => b,
        (Some(_), _) => a,
        _ => b,
    }
}

/// What the pass over points of stage 4a reads.
struct PointPass<'a, const D: usize, P: SolverParts<D>> {
    sys: &'a StepSystem<D>,
    du: &'a [f64],
    law: &'a P::Law,
    patches: &'a PatchSystem<D>,
    increments: &'a [Matrix3<f64>],
    points: &'a PointsOf<D, P>,
    limit: f64,
    /// The locking treatment couples points ([`LockingTreatment::couples_points`]).
    coupled: bool,
}

impl<const D: usize, P: SolverParts<D>> PointPass<'_, D, P> {
    /// $\Delta F$ of point `p`, its update and the excessive-increment
    /// test; `then` reads the response in place (moving a 672-byte
    /// response out of its `Result` is a copy the compiler does not
    /// elide).
    #[inline(always)]
    fn respond(
        &self,
        p: usize,
        then: impl FnOnce(&Response<P::History>) -> Option<StepFailure>,
    ) -> Option<StepFailure> {
        // The motion's ΔF (eq. 7), or the patch-averaged ΔF̄ the law sees
        // under a coupled treatment (Wang et al. eq. 9).
        // The constant folds the branch away for a typed treatment that
        // never couples (`NoLocking`); a run-time choice reads the flag.
        let delta_f =
            if <P::Locking as LockingTreatment<D, P::Mesh>>::COUPLES_POINTS && self.coupled {
                self.patches.modified(p, &self.increments[p])
            } else {
                grid_to_point::deformation_increment(self.sys, self.du, p)
            };
        let state = MaterialState {
            be: self.points.be[p],
            history: self.points.history[p],
        };
        let response = update(self.law, &delta_f, &self.points.f[p], &state);
        let r = match response.as_ref() {
            Ok(r) => r,
            Err(source) => return Some(at_point(p, *source)),
        };
        // Squared norms: the square root only for the report.
        let squared = r.delta_f.norm_squared().max(r.delta_f_inv.norm_squared());
        let limit = self.limit;
        if squared > limit * limit {
            return Some(StepFailure::ExcessiveIncrement {
                point: p,
                norm: squared.sqrt(),
                limit,
            });
        }
        then(r)
    }

    /// The weighted stress of point `p` and, for a formulation that maps
    /// them, its mapped basis gradients (eq. 8) into `chunk`.
    #[inline(always)]
    fn weigh(
        &self,
        p: usize,
        r: &Response<P::History>,
        stress: &mut PointStress<D>,
        chunk: &mut [SVector<f64, D>],
    ) {
        let s = P::Formulation::stress(r) * P::Formulation::volume(r, self.points.volume[p]);
        *stress = s.fixed_view::<D, D>(0, 0).into_owned();
        if <P::Formulation as Formulation>::MAPS_GRADIENTS {
            for (a, s) in self.sys.slots(p).enumerate() {
                chunk[a] = P::Formulation::map_gradient(r, &self.sys.grads[s]);
            }
        }
    }
}

impl<const D: usize, P: SolverParts<D>> ImplicitSolver<D, P> {
    /// Stage 0: a moving mesh takes its position at load factor `lambda0`
    /// ([`Constraints::move_mesh`]; nothing for a fixed mesh). Called at
    /// the start of every step attempt and after every converged step, so
    /// that mesh and points always belong to the same load factor.
    pub fn move_mesh(&mut self, lambda0: f64) -> Result<(), SolverError> {
        self.constraints
            .move_mesh(&mut self.mesh, lambda0)
            .map_err(|source| SolverError::MeshMotion {
                load_factor: lambda0,
                source,
            })
    }

    /// Stage 1: basis values and gradients of every point at the start of
    /// the step ([`crate::stages::basis::evaluate`]).
    pub fn evaluate_basis(&mut self, points: &PointsOf<D, P>) -> Result<(), SolverError> {
        let local = basis::evaluate(
            &self.basis,
            &self.mesh,
            &points.position,
            &points.domain,
            &mut self.hints,
            &mut self.system,
        );
        self.agree(local)
    }

    /// A local outcome decided over the ranks (itself on one).
    fn agree(&self, local: Result<(), SolverError>) -> Result<(), SolverError> {
        match &self.ranks {
            Some(link) => link.agree(local),
            None => local,
        }
    }

    /// A local failure of an iterate decided over the ranks (itself on
    /// one).
    fn agree_step(&mut self, local: Result<(), StepFailure>) -> Result<(), StepFailure> {
        match &mut self.ranks {
            Some(link) => link.agree_step(local),
            None => local,
        }
    }

    /// Replaces `values` by their sum over the ranks (nothing on one).
    fn sum_over_ranks(ranks: &mut Option<RankLink>, values: &mut [f64]) {
        if let Some(link) = ranks {
            link.sum(values);
        }
    }

    /// Replaces the stiffness `values` by their sum over the ranks, unless
    /// the linear solver takes each rank's own
    /// ([`LinearSolver::solves_over_ranks`]).
    fn sum_stiffness_over_ranks(&mut self, values: &mut [f64]) {
        if !self.linear.solves_over_ranks() {
            Self::sum_over_ranks(&mut self.ranks, values);
        }
    }

    /// The rounding-noise level of the residual from the last tangent
    /// pass's norms ([`convergence::rounding_noise`]), its node bounds
    /// summed over the ranks.
    pub(super) fn rounding_noise(&mut self) -> f64 {
        let mut bounds =
            convergence::node_bounds(&self.system, self.force_gradients(), &self.it.tangent_norms);
        Self::sum_over_ranks(&mut self.ranks, &mut bounds);
        convergence::noise_of_bounds(&self.system, &bounds)
    }

    /// Stage 2: active nodes, dofs, prescribed increments, adjacency, the
    /// patches of a coupled locking treatment, sparsity pattern and the
    /// symbolic factorisation.
    pub fn build_system(
        &mut self,
        points: &PointsOf<D, P>,
        lambda0: f64,
        lambda1: f64,
    ) -> Result<(), SolverError> {
        self.number_active_nodes();
        self.build_ghost(points)?;
        self.build_neighbours(points)?;
        let weak = self.weak_nodes(&points.volume);
        let sys = &mut self.system;
        let constraints = &self.constraints;
        let active_of_mesh = std::mem::take(&mut sys.active_of_mesh);
        sys.build_pattern(&|node, i| {
            let held = weak[active_of_mesh[node] as usize];
            constraints
                .prescribed(node, i, lambda0, lambda1)
                .or(held.then_some(0.0))
        });
        sys.active_of_mesh = active_of_mesh;
        sys.build_slot_offsets();
        let unsymmetric_contact = self.build_contacts(points, lambda0, lambda1)?;
        let sys = &mut self.system;
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
        // The slip tangent of a frictional tool is not symmetric: LU.
        let symmetric =
            self.law.symmetric_tangent() && !self.locking.couples_points() && !unsymmetric_contact;
        self.analysed = false;
        match &self.ranks {
            Some(link) if self.linear.solves_over_ranks() => {
                let own = link.own_entries(sys);
                let (n, ptr, idx) = (sys.n_free, &sys.col_ptr, &sys.row_idx);
                self.linear.analyse_part(n, ptr, idx, symmetric, &own)
            }
            _ => self
                .linear
                .analyse(sys.n_free, &sys.col_ptr, &sys.row_idx, symmetric),
        }
        .map_err(SolverError::Pattern)?;
        if self.linear.wants_rigid_body_modes() {
            let mesh = &self.mesh;
            let free: Vec<_> = (0..sys.n_active() * D)
                .filter(|&dof| sys.free_of_dof[dof] != crate::stages::system::NONE)
                .map(|dof| {
                    (
                        MovableMesh::node_position(mesh, sys.active[dof / D]),
                        dof % D,
                    )
                })
                .collect();
            self.linear
                .set_rigid_body_modes(&crate::linear::rigid_body_modes(&free))
                .map_err(SolverError::Pattern)?;
        }
        self.analysed = true;
        Ok(())
    }

    /// The active nodes of the step: those any rank's points touch.
    fn number_active_nodes(&mut self) {
        let node_count = self.mesh.node_count();
        let sys = &mut self.system;
        match &mut self.ranks {
            Some(link) => sys.number_nodes_with(node_count, &mut |marks| link.unite_nodes(marks)),
            None => sys.number_nodes(node_count),
        }
        sys.build_adjacency();
    }

    /// The faces of the ghost penalty, when it is on.
    fn build_ghost(&mut self, points: &PointsOf<D, P>) -> Result<(), SolverError> {
        let ghost = &mut self.ghost;
        if !self.options.ghost.is_on() {
            ghost.clear();
            return Ok(());
        }
        if self.ranks.is_some() {
            return Err(SolverError::Ghost(
                "its face terms belong to no rank's points: it is not available on several ranks",
            ));
        }
        let grid = self
            .mesh
            .regular_grid()
            .ok_or(SolverError::Ghost("it is defined on regular grids only"))?;
        // Each point's shear modulus: its material's under a law of
        // several materials.
        let law = &self.law;
        let history = &points.history;
        if history.iter().any(|h| law.point_shear_modulus(h).is_none()) {
            return Err(SolverError::Ghost(
                "it scales with the law's shear modulus, and this law gives none",
            ));
        }
        let g = self.options.ghost;
        if !(g.factor.is_finite() && g.fill > 0.0 && g.fill <= 1.0) {
            return Err(SolverError::Ghost(
                "its factor must be finite and its fill in (0, 1]",
            ));
        }
        ghost.build(
            grid,
            &points.position,
            &points.volume,
            &self.system,
            &|p| g.factor * 2.0 * law.point_shear_modulus(&history[p]).unwrap_or(0.0),
            g.fill,
        )?;
        Ok(())
    }

    /// The neighbour lists of the pattern: the points' stencils, widened
    /// by the patches of a coupled locking treatment and the ghost faces,
    /// united over the ranks.
    fn build_neighbours(&mut self, points: &PointsOf<D, P>) -> Result<(), SolverError> {
        if self.locking.couples_points() {
            let input = PatchInput {
                position: &points.position,
                cells: &self.hints,
                volume: &points.volume,
            };
            let assigned = self
                .locking
                .assign(&self.mesh, input, &mut self.patches.assignment)
                .map_err(SolverError::from);
            self.agree(assigned)?;
            if let Some(link) = &mut self.ranks {
                link.check_patches(&self.patches.assignment)?;
            }
            self.patches.build(&self.system);
            let patches = &self.patches;
            self.system
                .build_neighbours_from(&|w, push| patches.neighbours(w, push));
        } else {
            self.system.build_neighbours();
        }
        let sys = &mut self.system;
        if let Some(link) = &mut self.ranks {
            let (nb_ptr, nb) = (std::mem::take(&mut sys.nb_ptr), std::mem::take(&mut sys.nb));
            link.unite_neighbours(nb_ptr, nb, &mut |all| sys.build_neighbours_from(all));
        }
        let ghost = &self.ghost;
        if !ghost.is_empty() {
            sys.extend_neighbours(&|w, push| ghost.partners(w, push));
        }
        if self.locking.couples_points() {
            self.patches.build_placement(sys);
        }
        Ok(())
    }

    /// The weak-node rule per active node: its support weights summed
    /// over the ranks' points.
    fn weak_nodes(&mut self, volumes: &[f64]) -> Vec<bool> {
        let (mut support, mut stiffness) = gather::support_weights(&self.system, volumes);
        Self::sum_over_ranks(&mut self.ranks, &mut support);
        Self::sum_over_ranks(&mut self.ranks, &mut stiffness);
        let max = |x: &[f64]| x.iter().copied().fold(0.0, f64::max);
        let (support_cut, stiffness_cut) = (
            self.options.weak_node_threshold * max(&support),
            self.options.weak_node_stiffness * max(&stiffness),
        );
        // The support rule holds a node whose value *and* gradient vanish
        // at its points (a fringe node of a domain or a spline); a node
        // whose value vanishes but whose gradient does not (the node of a
        // linear cell or simplex opposite a point on an edge) shapes the
        // points' strains and stays free.
        let support_stiffness_cut = self.options.weak_node_threshold * max(&stiffness);
        support
            .iter()
            .zip(&stiffness)
            .map(|(&s, &k)| (s < support_cut && k < support_stiffness_cut) || k < stiffness_cut)
            .collect()
    }

    /// Stage 3: the external force of the step
    /// ([`crate::stages::gather::external_force`]), constant over the step.
    pub fn assemble_external_force(&mut self, points: &PointsOf<D, P>, lambda1: f64) {
        gather::external_force(&self.system, points, lambda1, &mut self.it.f_ext);
        Self::sum_over_ranks(&mut self.ranks, &mut self.it.f_ext);
        self.contact.keep_external(&self.it.f_ext);
    }

    /// Stage 4a with backtracking: when a Newton correction inverts a
    /// material point (det ΔF <= 0 or another constitutive failure) or
    /// stretches it beyond [`super::NewtonOptions::max_increment_norm`],
    /// the correction is halved, up to [`MAX_BACKTRACKS`] times, before the
    /// step is declared failed. Sparsely populated cells give nodes with
    /// little stiffness whose corrections can overshoot; backtracking keeps
    /// Newton on track without changing the converged solution.
    ///
    /// With `tangents = Some(norms)`, the update is the fused pass with the
    /// tangents ([`Self::update_with_tangents`]).
    pub(super) fn update_material_points_backtracking(
        &mut self,
        points: &PointsOf<D, P>,
        after_solve: bool,
        tangents: Option<bool>,
    ) -> Result<bool, StepFailure> {
        let update = |s: &mut Self| match tangents {
            Some(norms) => s.update_with_tangents(points, norms),
            None => s.update_material_points(points),
        };
        let mut result = update(self);
        let mut backtracks = 0;
        while result.as_ref().is_err_and(on_ranks::backtracks) {
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
            result = update(self);
        }
        result.map(|()| backtracks > 0)
    }

    /// Stage 4a: for every point, $\Delta F$ from the grid displacement
    /// increment (eq. 7), the locking treatment, the constitutive update
    /// and the weighted stress of the formulation. Keeps every point's
    /// response for the tangents ([`Self::update_tangents`]) and the
    /// commit.
    pub fn update_material_points(&mut self, points: &PointsOf<D, P>) -> Result<(), StepFailure> {
        self.material_pass::<false>(points, false)
    }

    /// Stages 4a and 4c in one pass over the points: what
    /// [`Self::update_material_points`] and then [`Self::update_tangents`]
    /// compute, bit for bit, without keeping the responses. Newton runs it
    /// on the iterations it expects to correct
    /// ([`crate::stages::convergence::NewtonMonitor::expects_correction`]):
    /// writing a point's response costs as much memory traffic as reading
    /// it back for the tangent, and an iteration that needs a tangent has
    /// no other use for it. The commit recomputes the responses of the
    /// converged increment when the last update was this one. A locking
    /// treatment that couples points needs the responses for its patch
    /// terms and runs the two stages.
    pub fn update_material_points_with_tangents(
        &mut self,
        points: &PointsOf<D, P>,
    ) -> Result<(), StepFailure> {
        self.update_with_tangents(points, false)
    }

    /// [`Self::update_material_points_with_tangents`], with the norms of
    /// [`Self::update_tangents_with`] on request.
    pub(super) fn update_with_tangents(
        &mut self,
        points: &PointsOf<D, P>,
        norms: bool,
    ) -> Result<(), StepFailure> {
        if self.locking.couples_points() {
            self.material_pass::<false>(points, false)?;
            self.update_tangents_with(points, false, norms)
        } else {
            self.material_pass::<true>(points, norms)
        }
    }

    /// The pass over points of stage 4a, with the tangents of stage 4c
    /// instead of the stored responses when `TANGENTS`.
    fn material_pass<const TANGENTS: bool>(
        &mut self,
        points: &PointsOf<D, P>,
        norms: bool,
    ) -> Result<(), StepFailure> {
        let local = self.material_pass_here::<TANGENTS>(points, norms);
        self.agree_step(local)
    }

    /// [`Self::material_pass`] over this rank's points alone.
    fn material_pass_here<const TANGENTS: bool>(
        &mut self,
        points: &PointsOf<D, P>,
        norms: bool,
    ) -> Result<(), StepFailure> {
        let n = points.len();
        let sys = &self.system;
        let it = &mut self.it;
        let maps_gradients = <P::Formulation as Formulation>::MAPS_GRADIENTS;
        it.stress_w.resize(n, PointStress::<D>::zeros());
        if maps_gradients {
            it.mapped.resize(sys.grads.len(), SVector::zeros());
        }
        // Until this pass succeeds, no stored response belongs to the
        // current increment.
        it.responses_current = false;
        if TANGENTS {
            it.tangent_w.resize(n, [[[[0.0; D]; D]; D]; D]);
            it.tangent_norms.resize(n, 0.0);
        } else {
            it.responses.resize(n, None);
        }
        let du = &it.du;
        let coupled = self.locking.couples_points();
        if coupled {
            it.increments.resize(n, Matrix3::identity());
            par::for_each(&mut it.increments[..], 1, &|start, increments| {
                for (k, m) in increments.iter_mut().enumerate() {
                    *m = grid_to_point::deformation_increment(sys, du, start + k);
                }
            });
            self.patches
                .average(&it.increments)
                .map_err(|e| StepFailure::Constitutive {
                    point: e.point,
                    source: ConstitutiveError::NonPositiveJacobian {
                        which: "ΔF",
                        det: e.det,
                    },
                })?;
        }
        let (law, patches, increments) = (&self.law, &self.patches, &it.increments[..]);
        let limit = self.options.max_increment_norm;
        let stride = sys.stride.max(1);
        // Each point's slots of the mapped gradients, or an empty row per
        // point when the formulation does not map them.
        let mapped = if maps_gradients {
            Rows::new(&mut it.mapped, stride)
        } else {
            Rows::empty(n)
        };
        let pass = PointPass::<D, P> {
            sys,
            du,
            law,
            patches,
            increments,
            points,
            limit,
            coupled,
        };
        let failure = if TANGENTS {
            let data = (
                &mut it.stress_w[..],
                mapped,
                &mut it.tangent_w[..],
                &mut it.tangent_norms[..],
            );
            par::reduce(
                data,
                1,
                &|start, (stress, mut mapped, t, norm)| {
                    let mut failure = None;
                    for k in 0..stress.len() {
                        let p = start + k;
                        let f = pass.respond(p, |r| {
                            pass.weigh(p, r, &mut stress[k], mapped.row(k));
                            let volume = P::Formulation::volume(r, points.volume[p]);
                            // Read in place, as the response.
                            let tangent = <P::Formulation as Formulation>::Tangent::tangent(law, r);
                            let a = match tangent.as_ref() {
                                Ok(a) => a,
                                Err(source) => return Some(at_point(p, *source)),
                            };
                            gather::restrict_tangent(a, volume, &mut t[k]);
                            if norms {
                                norm[k] = (a * volume).norm();
                            }
                            None
                        });
                        failure = lowest_failure(failure, f);
                    }
                    failure
                },
                lowest_failure,
            )
        } else {
            let data = (&mut it.stress_w[..], mapped, &mut it.responses[..]);
            par::reduce(
                data,
                1,
                &|start, (stress, mut mapped, responses)| {
                    let mut failure = None;
                    for k in 0..stress.len() {
                        let p = start + k;
                        let f = pass.respond(p, |r| {
                            pass.weigh(p, r, &mut stress[k], mapped.row(k));
                            responses[k] = Some(*r);
                            None
                        });
                        failure = lowest_failure(failure, f);
                    }
                    failure
                },
                lowest_failure,
            )
        };
        match failure {
            Some(f) => Err(f),
            None => {
                it.responses_current = !TANGENTS;
                Ok(())
            }
        }
    }

    /// The basis gradients of the force and stiffness: the step's, or
    /// mapped by eq. (8) for formulations that map them.
    pub(super) fn force_gradients(&self) -> &[SVector<f64, D>] {
        if <P::Formulation as Formulation>::MAPS_GRADIENTS {
            &self.it.mapped
        } else {
            &self.system.grads
        }
    }

    /// Stage 4b: the internal force (eqs. 6, 23, 28;
    /// [`crate::stages::gather::internal_force`]).
    pub fn assemble_internal_force(&mut self) {
        let mut f_int = std::mem::take(&mut self.it.f_int);
        gather::internal_force(
            &self.system,
            self.force_gradients(),
            &self.it.stress_w,
            &mut f_int,
        );
        if !self.ghost.is_empty() {
            self.ghost.add_force::<D>(&self.it.du, &mut f_int);
        }
        if !self.contact.is_empty() {
            self.add_contact_force();
        }
        Self::sum_over_ranks(&mut self.ranks, &mut f_int);
        self.it.f_int = f_int;
    }

    /// Stage 4c: the formulation's consistent tangent at every point,
    /// weighted by its integration volume.
    pub fn update_tangents(&mut self, points: &PointsOf<D, P>) -> Result<(), StepFailure> {
        self.update_tangents_with(points, false, false)
    }

    /// [`Self::update_tangents`] with each law's algorithmic tangent
    /// (`loading = false`) or its tangent for continued loading
    /// (`LogStrainLaw::loading_tangent`, `loading = true`), which differ
    /// only for points on a yield surface. (A run-time flag rather than a
    /// const parameter: one instantiation per solver type less to compile,
    /// for a branch per point that is always predicted.) With `norms`,
    /// also the Frobenius norm of each full weighted tangent as the
    /// stiffness uses it (for [`convergence::rounding_noise`]).
    ///
    /// Each point's $9\times 9$ tangent is read where the law leaves it
    /// and only the `D`-dimensional components the later stages use are
    /// kept ([`gather::PointTangent`]).
    pub(super) fn update_tangents_with(
        &mut self,
        points: &PointsOf<D, P>,
        loading: bool,
        norms: bool,
    ) -> Result<(), StepFailure> {
        if !self.it.responses_current {
            // After the fused pass or a failed update.
            self.material_pass::<false>(points, false)?;
        }
        let local = self.tangents_here(points, loading, norms);
        self.agree_step(local)
    }

    /// The tangents of [`Self::update_tangents_with`] over this rank's
    /// points, from their current responses.
    fn tangents_here(
        &mut self,
        points: &PointsOf<D, P>,
        loading: bool,
        norms: bool,
    ) -> Result<(), StepFailure> {
        let coupled = self.locking.couples_points();
        let (law, alpha) = (&self.law, &self.patches.alpha);
        let it = &mut self.it;
        let n = it.responses.len();
        let responses = &it.responses;
        it.tangent_w.resize(n, [[[[0.0; D]; D]; D]; D]);
        it.tangent_norms.resize(n, 0.0);
        let failure = par::first(
            (&mut it.tangent_w[..], &mut it.tangent_norms[..]),
            1,
            &|start, (t, norm)| {
                for k in 0..t.len() {
                    let p = start + k;
                    let Some(r) = &responses[p] else {
                        continue;
                    };
                    let volume = P::Formulation::volume(r, points.volume[p]);
                    // Read in place: moving the tensor out of its `Result`
                    // is a 648-byte copy the compiler does not elide.
                    let tangent = if loading {
                        <P::Formulation as Formulation>::Tangent::loading_tangent(law, r)
                    } else {
                        <P::Formulation as Formulation>::Tangent::tangent(law, r)
                    };
                    let a = match tangent.as_ref() {
                        Ok(a) => a,
                        Err(source) => return Some(at_point(p, *source)),
                    };
                    gather::restrict_tangent(a, volume, &mut t[k]);
                    if norms {
                        // Of the tensor the stiffness uses: scaled by α_p
                        // under a coupled treatment (`patch_tangents`).
                        norm[k] = if coupled {
                            (a * volume * alpha[p]).norm()
                        } else {
                            (a * volume).norm()
                        };
                    }
                }
                None
            },
        );
        if let Some(f) = failure {
            return Err(f);
        }
        if coupled {
            self.patch_tangents();
        }
        Ok(())
    }

    /// Stage 3b ([`crate::FirstTangent::Converged`]): the first solve of a
    /// step that starts from its prescribed increments $\Delta\mathbf u_p$
    /// alone, linearised about the converged state,
    /// $K_{ff}(0)\,\Delta\mathbf u_f = \mathbf f^{ext}_f - \mathbf
    /// f^{int}_f(0) - K_{fp}(0)\,\Delta\mathbf u_p$. $K_{ff}(0)$ is the
    /// stiffness at zero increment (every point's tangent at $\Delta F = I$
    /// with its committed state, for continued loading where a point sits
    /// on its yield surface: `LogStrainLaw::loading_tangent`); the coupling $K_{fp}(0)\Delta\mathbf
    /// u_p$, whose block the free-dof assembly does not hold, is the
    /// forward difference $[\mathbf f^{int}(\epsilon\Delta\mathbf u_p) -
    /// \mathbf f^{int}(0)]/\epsilon$ with $\epsilon$ =
    /// [`LINEARISED_START_STEP`] (exact for a linear response, and the
    /// directional derivative of the return map where a point is loaded
    /// plastically from the yield surface). Leaves the increment at
    /// $(\Delta\mathbf u_f, \Delta\mathbf u_p)$ for Newton's iteration 0.
    pub(super) fn linearised_start(&mut self, points: &PointsOf<D, P>) -> Result<(), StepFailure> {
        // Once per step: the prescribed increments and f_int(0) are kept
        // aside while the increment goes to 0 and to ε Δu_p.
        let prescribed = self.it.du.clone();
        self.it.du.fill(0.0);
        self.update_material_points(points)?;
        self.assemble_internal_force();
        let f0 = self.it.f_int.clone();
        // The points that yielded in the last step sit on the yield
        // surface; the increment continues their loading.
        self.update_tangents_with(points, true, false)?;
        self.assemble_stiffness();
        let eps = LINEARISED_START_STEP;
        for (u, p) in self.it.du.iter_mut().zip(&prescribed) {
            *u = eps * p;
        }
        self.update_material_points(points)?;
        self.assemble_internal_force();
        for (f, f0) in self.it.f_int.iter_mut().zip(&f0) {
            *f = f0 + (*f - f0) / eps;
        }
        self.it.du.copy_from_slice(&prescribed);
        self.solve()
            .map_err(|source| StepFailure::LinearSolve { source })
    }

    /// The coupled part of the tangent ([`crate::stages::patch`]): the
    /// motion's spatial gradients and their patch averages, $\mathbf
    /// h_{vp} = B_p\nabla S_{vp}$ with $B_p = \tfrac1D T_p : K_p$, and the
    /// point tangents scaled by $\alpha_p$ for the standard kernel.
    fn patch_tangents(&mut self) {
        let it = &mut self.it;
        let responses = &it.responses;
        let patches = &mut self.patches;
        patches.gradients(&self.system, &|p| {
            responses[p]
                .as_ref()
                .map_or_else(Matrix3::identity, |r| r.delta_f_inv)
        });
        let sys = &self.system;
        let grads: &[SVector<f64, D>] = if <P::Formulation as Formulation>::MAPS_GRADIENTS {
            &it.mapped
        } else {
            &sys.grads
        };
        let stride = sys.stride.max(1);
        let alpha = &patches.alpha;
        let data = (Rows::new(&mut patches.h, stride), &mut it.tangent_w[..]);
        par::for_each(data, 1, &|start, (mut h, t)| {
            for (k, t) in t.iter_mut().enumerate() {
                let p = start + k;
                let Some(r) = &responses[p] else {
                    continue;
                };
                let k_dir = P::Formulation::volumetric_direction(r);
                let mut b = [[0.0f64; D]; D];
                for (i, row) in b.iter_mut().enumerate() {
                    for (j, bij) in row.iter_mut().enumerate() {
                        let mut acc = 0.0;
                        for a in 0..D {
                            for c in 0..D {
                                acc += t[i][j][a][c] * k_dir[(a, c)];
                            }
                        }
                        *bij = acc / D as f64;
                    }
                }
                let h = h.row(k);
                for (slot, hv) in h.iter_mut().take(sys.counts[p] as usize).enumerate() {
                    let g = &grads[p * stride + slot];
                    *hv = SVector::<f64, D>::from_fn(|i, _| (0..D).map(|j| b[i][j] * g[j]).sum());
                }
                t.iter_mut()
                    .flatten()
                    .flatten()
                    .flatten()
                    .for_each(|x| *x *= alpha[p]);
            }
        });
    }

    /// Stage 4d: the stiffness (eqs. 4/21, 27) in CSC over free dofs
    /// ([`crate::stages::gather::stiffness`]).
    pub fn assemble_stiffness(&mut self) {
        let mut values = std::mem::take(&mut self.it.values);
        gather::stiffness(
            &self.system,
            self.force_gradients(),
            &self.it.tangent_w,
            &mut values,
        );
        if self.locking.couples_points() {
            gather::patch_coupling(&self.system, &self.patches, &mut values);
        }
        if !self.ghost.is_empty() {
            self.ghost.add_stiffness(&self.system, &mut values);
        }
        if !self.contact.is_empty() {
            self.add_contact_stiffness(&mut values);
        }
        self.sum_stiffness_over_ranks(&mut values);
        self.it.values = values;
        self.it.stiffness_assembled = true;
    }

    /// Stages 4b and 4d in one pass over the nodes
    /// ([`crate::stages::gather::internal_force_and_stiffness`]) for an
    /// iteration whose tangents came with the update
    /// ([`Self::update_material_points_with_tangents`]): the numbers of
    /// [`Self::assemble_internal_force`] and [`Self::assemble_stiffness`]
    /// bit for bit, each point-node pair read once.
    pub fn assemble_internal_force_and_stiffness(&mut self) {
        let mut f_int = std::mem::take(&mut self.it.f_int);
        let mut values = std::mem::take(&mut self.it.values);
        gather::internal_force_and_stiffness(
            &self.system,
            self.force_gradients(),
            &self.it.stress_w,
            &self.it.tangent_w,
            &mut f_int,
            &mut values,
        );
        if self.locking.couples_points() {
            gather::patch_coupling(&self.system, &self.patches, &mut values);
        }
        if !self.ghost.is_empty() {
            self.ghost.add_force::<D>(&self.it.du, &mut f_int);
            self.ghost.add_stiffness(&self.system, &mut values);
        }
        if !self.contact.is_empty() {
            self.add_contact_force();
            self.add_contact_stiffness(&mut values);
        }
        Self::sum_over_ranks(&mut self.ranks, &mut f_int);
        self.sum_stiffness_over_ranks(&mut values);
        self.it.f_int = f_int;
        self.it.values = values;
        self.it.stiffness_assembled = true;
    }

    /// Stage 4e: solve $K\,\delta d = -f^R$ (eq. 26) with the linear
    /// solver and accumulate the increment (eq. 30).
    pub fn solve(&mut self) -> Result<(), LinearSolveError> {
        if !self.analysed {
            return Err(LinearSolveError::NotAnalysed);
        }
        let sys = &self.system;
        let it = &mut self.it;
        it.rhs.clear();
        it.rhs.resize(sys.n_free, 0.0);
        for (dof, &free) in sys.free_of_dof.iter().enumerate() {
            if free != NONE {
                it.rhs[free as usize] = it.f_ext[dof] - it.f_int[dof];
            }
        }
        match &mut self.ranks {
            Some(link) => link.solve(self.linear.as_mut(), &it.values, &mut it.rhs)?,
            None => {
                self.linear.solve(&it.values, &mut it.rhs)?;
            }
        }
        for (dof, &free) in sys.free_of_dof.iter().enumerate() {
            if free != NONE {
                it.du[dof] += it.rhs[free as usize];
            }
        }
        Ok(())
    }

    /// Stage 5: positions (eq. 31), converged deformation and stresses,
    /// volumes (eq. 22) and domains ([`crate::stages::update::commit`]).
    /// The responses are those of the last update; after
    /// [`Self::update_material_points_with_tangents`], which keeps none,
    /// they are recomputed at the same increment first.
    pub fn commit(&mut self, points: &mut PointsOf<D, P>) -> Result<(), SolverError> {
        if !self.it.responses_current {
            self.material_pass::<false>(points, false)
                .map_err(|cause| SolverError::Commit { cause })?;
        }
        let local = grid_to_point::commit(
            &self.system,
            &self.it.du,
            &self.mesh,
            &self.updater,
            &self.it.responses,
            points,
        );
        self.agree(local)?;
        self.commit_contacts();
        Ok(())
    }

    /// The view [`Constraints::begin_step`] receives.
    pub(super) fn begin_constraints(&mut self, points: &PointsOf<D, P>) {
        let sys = &self.system;
        self.constraints.begin_step(&StepView::new(
            &points.position,
            &sys.nodes,
            &sys.counts,
            sys.stride,
        ));
    }
}
