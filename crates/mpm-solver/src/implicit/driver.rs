//! The Newton load step as a list of named stages, compiled once per
//! dimension: [`solve_load_step`] drives any solver through the
//! object-safe [`NewtonStages`], so the algorithm — the predictor, the
//! linearised start, the iterations with their convergence test, the
//! commit and the report — exists once per `D`, whatever the basis,
//! formulation, law, locking treatment and domain rule. The stages
//! themselves (the per-point and per-node loops) stay monomorphised in
//! [`ImplicitSolver`]; the driver calls about a dozen of them per
//! iteration through a vtable, which costs nothing next to one of them.
//! Stage times are kept by one clock ([`StageClock`]), not by timers in
//! the algorithm.

use std::time::Instant;

use super::{FirstTangent, ImplicitSolver, NewtonOptions, StageTimes, StepError, StepReport};
use crate::error::{SolverError, StepFailure};
use crate::linear::LinearSolveError;
use crate::locking::LockingTreatment;
use crate::parts::{PointsOf, SolverParts};
use crate::stages::convergence::{self, NewtonMonitor, Verdict};
use crate::stages::system::StepSystem;

/// What the Newton driver needs of a composed solver and its points: the
/// stages of one load step (Coombs et al. 2020 §6.3), object-safe.
pub trait NewtonStages<const D: usize> {
    /// The Newton controls.
    fn options(&self) -> &NewtonOptions;
    /// Stage 1: the mesh at `lambda0`, the points located and their basis
    /// evaluated.
    fn prepare_basis(&mut self, lambda0: f64) -> Result<(), SolverError>;
    /// Stage 2: constraints, the system of the step and the external
    /// force at `lambda1`.
    fn prepare_system(&mut self, lambda0: f64, lambda1: f64) -> Result<(), SolverError>;
    /// The secant predictor for the load increment `dlambda`; whether it
    /// set any increment.
    fn predict(&mut self, dlambda: f64) -> bool;
    /// Whether the step starts with prescribed increments (or a moving
    /// rigid tool).
    fn has_prescribed_increment(&self) -> bool;
    /// The first solve linearised about the converged state.
    fn linearised_start(&mut self) -> Result<(), StepFailure>;
    /// Whether the last step converged on its first iterate.
    fn first_iterate_converged(&self) -> bool;
    /// Records whether this step converged on its first iterate.
    fn set_first_iterate_converged(&mut self, converged: bool);
    /// Whether the locking treatment couples points (then the fused
    /// update-with-tangents pass gains nothing).
    fn couples_points(&self) -> bool;
    /// Stage 4a with backtracking; `tangents` asks for the fused pass
    /// (and whether it also computes the tangent norms). Whether it
    /// backtracked.
    fn update_points(
        &mut self,
        after_solve: bool,
        tangents: Option<bool>,
    ) -> Result<bool, StepFailure>;
    /// Stage 4b: the internal force.
    fn assemble_internal_force(&mut self);
    /// Stages 4b and 4d in one pass (after a fused update).
    fn assemble_internal_force_and_stiffness(&mut self);
    /// The step's system.
    fn system(&self) -> &StepSystem<D>;
    /// The internal and external forces per dof.
    fn forces(&self) -> (&[f64], &[f64]);
    /// Stage 4c: the consistent tangents (`norms`: also their norms).
    fn update_tangents(&mut self, norms: bool) -> Result<(), StepFailure>;
    /// The rounding-noise level of the residual, from the first
    /// iteration's tangents.
    fn rounding_noise(&mut self) -> f64;
    /// Stage 4d: the stiffness.
    fn assemble_stiffness(&mut self);
    /// Stage 4e: the linear solve.
    fn solve(&mut self) -> Result<(), LinearSolveError>;
    /// Krylov iterations of the last solve (0 for a direct solve).
    fn linear_iterations(&self) -> usize;
    /// Whether the last solve factorised afresh.
    fn factorisation(&self) -> Option<crate::linear::Factorisation>;
    /// The force of the rigid tools on the body at each node in contact
    /// (mesh id), at the current increment.
    fn contact_forces(&self) -> Vec<(usize, nalgebra::SVector<f64, D>)>;
    /// Stage 5: the converged state, the mesh at `lambda1` and the
    /// predictor's memory of the load increment `dlambda`.
    fn commit(&mut self, lambda1: f64, dlambda: f64) -> Result<(), SolverError>;
    /// On several ranks, a failure of the transport in a stage that could
    /// not return it (a reduction of the forces or the stiffness); read
    /// before their numbers are used.
    fn rank_failure(&mut self) -> Option<SolverError>;
}

/// A stage of the load step, as [`StageTimes`] reports it.
#[derive(Debug, Clone, Copy)]
enum Stage {
    Basis,
    System,
    Material,
    Force,
    Tangent,
    Stiffness,
    Solve,
    Commit,
}

/// The wall time of every stage of one load step.
#[derive(Debug, Default)]
struct StageClock {
    times: StageTimes,
}

impl StageClock {
    /// Runs `f`, adding its wall time to `stage`.
    fn time<T>(&mut self, stage: Stage, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = f();
        let t = &mut self.times;
        *match stage {
            Stage::Basis => &mut t.basis,
            Stage::System => &mut t.system,
            Stage::Material => &mut t.material,
            Stage::Force => &mut t.force,
            Stage::Tangent => &mut t.tangent,
            Stage::Stiffness => &mut t.stiffness,
            Stage::Solve => &mut t.solve,
            Stage::Commit => &mut t.commit,
        } += start.elapsed().as_secs_f64();
        out
    }
}

/// What the iterations of one step count.
#[derive(Debug, Default)]
struct Tally {
    linear_iterations: usize,
    backtracked: Vec<usize>,
    initial_unbalance: Option<f64>,
    fused_updates: usize,
}

/// Solves the load step from load factor `lambda0` to `lambda1`: the
/// stages of [`super`]'s docs. On success the points hold the converged
/// state; on failure they are untouched.
///
/// # Errors
/// [`StepError::Retry`] when a smaller increment may converge,
/// [`StepError::Fatal`] otherwise.
pub fn solve_load_step<const D: usize>(
    k: &mut dyn NewtonStages<D>,
    lambda0: f64,
    lambda1: f64,
) -> Result<StepReport<D>, StepError> {
    let mut clock = StageClock::default();
    let mut tally = Tally::default();
    clock.time(Stage::Basis, || k.prepare_basis(lambda0))?;
    clock.time(Stage::System, || k.prepare_system(lambda0, lambda1))?;
    let predicted = k.predict(lambda1 - lambda0);
    // The first solve linearises about the converged state when the step
    // starts from prescribed increments alone (FirstTangent).
    let linearised_start = k.options().first_tangent == FirstTangent::Converged
        && !predicted
        && k.has_prescribed_increment();
    if linearised_start {
        clock
            .time(Stage::Solve, || k.linearised_start())
            .map_err(|cause| StepError::Retry {
                cause,
                last_residual: f64::NAN,
            })?;
        tally.linear_iterations += k.linear_iterations();
    }
    let o = k.options();
    let mut monitor = NewtonMonitor::new(o.tolerance, o.divergence_factor, o.max_iterations)
        .with_rounding_floor(o.rounding_floor_factor)
        .expecting_first_correction(!k.first_iterate_converged());
    // Whether the converged iterate's fused tangents went unused.
    let unused_tangents = loop {
        if let Some(fused) = iterate(k, &mut monitor, &mut clock, &mut tally)? {
            break fused;
        }
    };
    k.set_first_iterate_converged(monitor.iteration() == 1);
    let (reaction, node_reactions) = {
        let (f_int, f_ext) = k.forces();
        let mut reaction = convergence::reaction(k.system(), f_int, f_ext);
        let mut node_reactions = convergence::node_reactions(k.system(), f_int, f_ext);
        // A tool's force is a reaction too (the residual holds −F at its
        // nodes' free dofs).
        for (v, f) in k.contact_forces() {
            reaction += f;
            match node_reactions.binary_search_by_key(&v, |(u, _)| *u) {
                Ok(at) => node_reactions[at].1 += f,
                Err(at) => node_reactions.insert(at, (v, f)),
            }
        }
        (reaction, node_reactions)
    };
    clock.time(Stage::Commit, || k.commit(lambda1, lambda1 - lambda0))?;
    Ok(StepReport {
        lambda0,
        lambda1,
        rounding_floor: monitor.rounding_floor(),
        at_rounding_floor: monitor.at_rounding_floor(),
        residuals: monitor.into_residuals(),
        initial_unbalance: tally.initial_unbalance,
        reaction,
        node_reactions,
        active_nodes: k.system().n_active(),
        free_dofs: k.system().n_free,
        factorisation: k.factorisation(),
        backtracked: tally.backtracked,
        linearised_start,
        fused_updates: tally.fused_updates,
        unused_tangents,
        times: clock.times,
        linear_iterations: tally.linear_iterations,
        cuts: Vec::new(),
    })
}

/// One Newton iteration: update the points, assemble the forces, test
/// eq. (40); unless converged, the tangents, the stiffness and the solve.
/// `Some(fused)` when converged (`fused`: the iterate's tangents came
/// with its update and go unused).
fn iterate<const D: usize>(
    k: &mut dyn NewtonStages<D>,
    monitor: &mut NewtonMonitor,
    clock: &mut StageClock,
    tally: &mut Tally,
) -> Result<Option<bool>, StepError> {
    let retry = |cause, monitor: &NewtonMonitor| StepError::Retry {
        cause,
        last_residual: monitor.last(),
    };
    let iteration = monitor.iteration();
    // The first iteration's tangents also give the rounding noise.
    let first = iteration == 0;
    // Where Newton expects to correct this iterate, its tangents come with
    // the update (a coupled treatment gains nothing: it keeps the
    // responses for its patch terms).
    let fused = !k.couples_points() && monitor.expects_correction();
    tally.fused_updates += usize::from(fused);
    let update = clock.time(Stage::Material, || {
        k.update_points(iteration > 0, fused.then_some(first))
    });
    if update.map_err(|cause| retry(cause, monitor))? {
        tally.backtracked.push(iteration);
    }
    if fused {
        // The stiffness is known before the test as well.
        clock.time(Stage::Stiffness, || {
            k.assemble_internal_force_and_stiffness()
        });
    } else {
        clock.time(Stage::Force, || k.assemble_internal_force());
    }
    if let Some(e) = k.rank_failure() {
        return Err(StepError::Fatal(e));
    }
    let (f_int, f_ext) = k.forces();
    if first {
        tally.initial_unbalance = convergence::unbalance_all_dofs(f_int, f_ext);
    }
    let (r, d) = convergence::residual_parts(k.system(), f_int, f_ext);
    match monitor.check(r, d) {
        Verdict::Converged => return Ok(Some(fused)),
        Verdict::Failed(cause) => return Err(retry(cause, monitor)),
        Verdict::Continue => {}
    }
    clock.time(Stage::Tangent, || {
        if !fused {
            k.update_tangents(first)
                .map_err(|cause| retry(cause, monitor))?;
        }
        if first {
            monitor.set_rounding_noise(k.rounding_noise());
        }
        Ok::<(), StepError>(())
    })?;
    if !fused {
        clock.time(Stage::Stiffness, || k.assemble_stiffness());
    }
    clock
        .time(Stage::Solve, || k.solve())
        .map_err(|source| match source {
            LinearSolveError::Configuration { .. } => {
                StepError::Fatal(SolverError::LinearConfiguration(source))
            }
            source => retry(StepFailure::LinearSolve { source }, monitor),
        })?;
    tally.linear_iterations += k.linear_iterations();
    Ok(None)
}

/// A solver bound to its points: the [`NewtonStages`] of a typed solver.
pub(super) struct Bound<'a, const D: usize, P: SolverParts<D>> {
    /// The solver.
    pub solver: &'a mut ImplicitSolver<D, P>,
    /// Its points.
    pub points: &'a mut PointsOf<D, P>,
}

impl<const D: usize, P: SolverParts<D>> NewtonStages<D> for Bound<'_, D, P> {
    fn options(&self) -> &NewtonOptions {
        &self.solver.options
    }

    fn prepare_basis(&mut self, lambda0: f64) -> Result<(), SolverError> {
        self.solver.move_mesh(lambda0)?;
        self.solver.evaluate_basis(self.points)
    }

    fn prepare_system(&mut self, lambda0: f64, lambda1: f64) -> Result<(), SolverError> {
        self.solver.begin_constraints(self.points);
        self.solver.build_system(self.points, lambda0, lambda1)?;
        self.solver.assemble_external_force(self.points, lambda1);
        self.rank_failure().map_or(Ok(()), Err)
    }

    fn predict(&mut self, dlambda: f64) -> bool {
        self.solver.predict(dlambda)
    }

    fn has_prescribed_increment(&self) -> bool {
        self.solver.it.du.iter().any(|&u| u != 0.0) || self.solver.contact.tools_move()
    }

    fn linearised_start(&mut self) -> Result<(), StepFailure> {
        self.solver.linearised_start(self.points)
    }

    fn first_iterate_converged(&self) -> bool {
        self.solver.first_iterate_converged
    }

    fn set_first_iterate_converged(&mut self, converged: bool) {
        self.solver.first_iterate_converged = converged;
    }

    fn couples_points(&self) -> bool {
        self.solver.locking.couples_points()
    }

    fn update_points(
        &mut self,
        after_solve: bool,
        tangents: Option<bool>,
    ) -> Result<bool, StepFailure> {
        self.solver
            .update_material_points_backtracking(self.points, after_solve, tangents)
    }

    fn assemble_internal_force(&mut self) {
        self.solver.assemble_internal_force();
    }

    fn assemble_internal_force_and_stiffness(&mut self) {
        self.solver.assemble_internal_force_and_stiffness();
    }

    fn system(&self) -> &StepSystem<D> {
        &self.solver.system
    }

    fn forces(&self) -> (&[f64], &[f64]) {
        (&self.solver.it.f_int, &self.solver.it.f_ext)
    }

    fn update_tangents(&mut self, norms: bool) -> Result<(), StepFailure> {
        self.solver.update_tangents_with(self.points, false, norms)
    }

    fn rounding_noise(&mut self) -> f64 {
        self.solver.rounding_noise()
    }

    fn assemble_stiffness(&mut self) {
        self.solver.assemble_stiffness();
    }

    fn solve(&mut self) -> Result<(), LinearSolveError> {
        self.solver.solve()
    }

    fn linear_iterations(&self) -> usize {
        self.solver.linear.last_iterations()
    }

    fn factorisation(&self) -> Option<crate::linear::Factorisation> {
        self.solver.linear.last_factorisation()
    }

    fn rank_failure(&mut self) -> Option<SolverError> {
        self.solver.ranks.as_mut()?.take_failure()
    }

    fn contact_forces(&self) -> Vec<(usize, nalgebra::SVector<f64, D>)> {
        self.solver.contact_forces()
    }

    fn commit(&mut self, lambda1: f64, dlambda: f64) -> Result<(), SolverError> {
        self.solver.commit(self.points)?;
        // The mesh follows to the end of the step, with the points.
        self.solver.move_mesh(lambda1)?;
        self.solver.remember_increment(dlambda);
        Ok(())
    }
}
