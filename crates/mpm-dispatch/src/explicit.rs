//! Runs a scene with `[solver] kind = "explicit"`: the basis, the law, the
//! velocity transfer and the dilatation treatment it names are dispatched
//! to a fully monomorphised [`ExplicitSolver`], which steps the points to
//! `end_time`; at every output time (`output_interval` apart, and at the
//! end) the caller's observer sees the energies and a [`Snapshot`] of the
//! points, with a [`Checkpoint`] to resume from when asked for.
//!
//! The solvers are compiled once per dimension, here ([`RunExplicit`]):
//! basis (`linear`, `bspline2`, `bspline2_boundary`, `gimp` with its
//! `domain_update` rule chosen at run time, and `cpdi2` with its convected
//! corners) × transfer (`FlipPic`, which covers PIC, FLIP and their blend;
//! `Taylor`) × dilatation (`NoLocking`, `CellAveraged`): 20 solvers per
//! dimension; the time loop with its outputs and checkpoints is compiled
//! once per dimension over the object-safe `Stepper` those solvers
//! implement. The materials are a run-time value ([`ExplicitLaws`]: the
//! law chosen per point, each point tagged with its material); a basis
//! without domains stores none.
//!
//! ```
//! use mpm_dispatch::run::RunControl;
//! use mpm_dispatch::{ExplicitEvent, run_explicit};
//! use mpm_scene::Problem;
//!
//! // A free block moving at 1 m/s for 0.1 s: it translates rigidly.
//! let text = r#"
//! [mesh]
//! origin = [0.0, 0.0]
//! size = [2.0, 1.0]
//! cells = [8, 4]
//!
//! [[material]]
//! name = "rubber"
//! model = "neo_hookean"
//! youngs_modulus = 1e4
//! poisson_ratio = 0.3
//! density = 1000.0
//!
//! [[body]]
//! name = "block"
//! material = "rubber"
//! region = { box = { lower = [0.5, 0.25], upper = [1.0, 0.75] } }
//! velocity = [1.0, 0.0]
//!
//! [solver]
//! kind = "explicit"
//! end_time = 0.1
//! "#;
//! let (scene, source) = mpm_scene::parse(text, "block.toml", &[])?;
//! let problem = Problem::<2>::build(&scene, &source, scene.solver.padding())?;
//! let mut outputs = 0;
//! let out = run_explicit(&problem, &RunControl::default(), |event| {
//!     if let ExplicitEvent::Output(_) = event {
//!         outputs += 1;
//!     }
//!     Ok(())
//! })?;
//! assert_eq!(outputs, 21); // t = 0 and every end_time/20
//! assert!((out.last.displacement[0][0] - 0.1).abs() < 1e-9);
//! assert!(out.energy_drift.abs() < 1e-9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::time::Instant;

use mpm_basis::BasisFunction;
use mpm_constitutive::{IncrementalLaw, MaterialSet, MaterialState, Tagged};
use mpm_mesh::RegularGrid;
use mpm_scene::body::InitialDomain;
use mpm_solver::explicit::{
    DilatationTreatment, Energies, ExplicitStageTimes, PointsFor, PointsOf, StepInfo,
    VelocityGradient, WallWork,
};
use mpm_solver::{
    CellAveraged, DomainUpdater, ExplicitOptions, ExplicitPoints, ExplicitSolver, Flat, FlipPic,
    Formulation, NoLocking, RunState, RunSummary, SolverError, Taylor, Transfer,
};
use nalgebra::{Matrix3, SVector};

use crate::run::{Checkpoint, DomainBounds, HistoryOutput, RunControl, Snapshot};
use mpm_scene::rules::Context;
use mpm_scene::variant::{LockingKind, VariantVisitor, dispatch_in};

use crate::explicit_law::{ExplicitLaw, ExplicitLaws};
pub use crate::explicit_ranks::RanksReport;
pub use crate::explicit_ranks::Rebalanced;
use crate::explicit_ranks::Spread;
use mpm_scene::build::{ExplicitSetup, Problem, SceneMesh};
use mpm_scene::format::TransferKind;
use mpm_solver::ranks::Decomposition;

/// What an explicit run reports to its observer.
#[derive(Debug)]
pub enum ExplicitEvent<'a> {
    /// A time step was taken.
    Step(StepInfo),
    /// An output time was reached (or the initial state, output 0).
    Output(ExplicitFrame<'a>),
    /// A run on several ranks dealt its cells anew
    /// ([`crate::on_ranks::Balance`]).
    Rebalanced(Rebalanced),
}

/// The state of an explicit run at an output time.
#[derive(Debug)]
pub struct ExplicitFrame<'a> {
    /// Output number: 0 for the initial state, then 1, 2, …
    pub index: usize,
    /// Simulated time (s).
    pub time: f64,
    /// Time steps taken so far.
    pub steps: usize,
    /// The energies of the points.
    pub energies: Energies,
    /// The points: positions, displacements, velocities, Cauchy stresses,
    /// deformation gradients, volumes, plastic strains, with the
    /// [`Checkpoint`] when the run was asked for one
    /// ([`RunControl::checkpoint`]).
    pub snapshot: &'a Snapshot,
}

/// The observer of an explicit run: sees every step and every output; an
/// error stops the run (e.g. `SolverError::Stopped` after a budget of
/// outputs).
pub type ExplicitObserver<'a> = dyn FnMut(ExplicitEvent<'_>) -> Result<(), SolverError> + 'a;

/// What an explicit run produced.
#[derive(Debug, Clone)]
pub struct ExplicitOutput {
    /// The final state.
    pub last: Snapshot,
    /// Time steps taken (including those before a resumed checkpoint).
    pub steps: usize,
    /// The time reached (s).
    pub time: f64,
    /// Outputs written, the initial state included.
    pub outputs: usize,
    /// The energies at t = 0.
    pub initial: Energies,
    /// The energies at the end.
    pub last_energies: Energies,
    /// The largest kinetic + strain energy seen at the outputs: the scale
    /// of [`Self::energy_drift`].
    pub energy_scale: f64,
    /// The relative drift of the total energy,
    /// (total(end) − total(0)) / [`Self::energy_scale`]: independent of
    /// the datum of the gravitational energy, zero for a conservative
    /// scheme (0 when nothing moves).
    pub energy_drift: f64,
    /// Solver wall time in seconds (observer time excluded), including the
    /// time before a resumed checkpoint.
    pub wall_time_s: f64,
    /// Wall time per stage of this session's steps.
    pub stage_times: ExplicitStageTimes,
    /// On several ranks, what each sent and did in this session.
    pub ranks: Option<RanksReport>,
}

/// A scene problem whose explicit run is compiled here: implemented for
/// two and three dimensions, each the one place where that dimension's
/// explicit solvers are monomorphised.
pub trait RunExplicit<const D: usize> {
    /// Runs the problem's explicit setup.
    ///
    /// # Errors
    /// As [`run_explicit`].
    fn run_explicit(
        &self,
        control: &RunControl,
        observer: &mut ExplicitObserver<'_>,
    ) -> Result<ExplicitOutput, SolverError>;
}

macro_rules! run_explicit_in {
    ($($d:literal),*) => {$(
        impl RunExplicit<$d> for Problem<$d> {
            #[inline(never)]
            fn run_explicit(
                &self,
                control: &RunControl,
                observer: &mut ExplicitObserver<'_>,
            ) -> Result<ExplicitOutput, SolverError> {
                dispatch(self, control, observer)
            }
        }
    )*};
}

run_explicit_in!(2, 3);

/// Runs a problem built from a scene with `[solver] kind = "explicit"`;
/// `observer` sees every step and every output (the initial state first,
/// unless resumed).
///
/// # Errors
/// [`SolverError::InvalidInput`] for a problem without an explicit setup
/// or off a grid, a checkpoint of another scene;
/// [`SolverError::ExplicitPoint`] when a point leaves the grid, inverts
/// or its stress update fails; the observer's error.
pub fn run_explicit<const D: usize, O>(
    problem: &Problem<D>,
    control: &RunControl,
    mut observer: O,
) -> Result<ExplicitOutput, SolverError>
where
    Problem<D>: RunExplicit<D>,
    O: FnMut(ExplicitEvent<'_>) -> Result<(), SolverError>,
{
    problem.run_explicit(control, &mut observer)
}

/// The problem's grid and setup, or why it has none.
fn parts<const D: usize>(
    problem: &Problem<D>,
) -> Result<(&RegularGrid<D>, &ExplicitSetup<D>), SolverError> {
    let setup = problem.explicit.as_ref().ok_or_else(|| {
        SolverError::InvalidInput("the scene's solver is implicit: run it with scene::run".into())
    })?;
    match &problem.mesh {
        SceneMesh::Grid(grid) => Ok((grid, setup)),
        SceneMesh::Simplex(_) => Err(SolverError::InvalidInput(
            "the explicit solver runs on regular grids".into(),
        )),
    }
}

/// The basis.
fn dispatch<const D: usize>(
    problem: &Problem<D>,
    control: &RunControl,
    observer: &mut ExplicitObserver<'_>,
) -> Result<ExplicitOutput, SolverError> {
    parts(problem)?;
    let run = Run {
        problem,
        control,
        observer,
    };
    dispatch_in(&problem.variant, Context::Explicit, run).map_err(SolverError::InvalidInput)?
}

impl<const D: usize> VariantVisitor<D> for Run<'_, '_, D> {
    type Output = Result<ExplicitOutput, SolverError>;

    /// The basis and its domain rule (`NoUpdate`, `AnyGimpRule` with the
    /// `det F` volume, `ConvectedCorners`); the formulation is the
    /// implicit solver's only.
    fn visit<B, F, U>(self, basis: B, updater: U) -> Self::Output
    where
        B: InitialDomain<D, Mesh = RegularGrid<D>, Domain: Flat + DomainBounds<D>>,
        F: Formulation,
        U: DomainUpdater<D, B::Domain>,
    {
        self.with_basis(basis, updater)
    }
}

/// A grid basis of an explicit scene: its point domains are written to
/// checkpoints and bounded by the grid.
trait SceneBasis<const D: usize>:
    BasisFunction<D, Mesh = RegularGrid<D>, Domain: Flat + DomainBounds<D>>
{
}

impl<const D: usize, B> SceneBasis<D> for B where
    B: BasisFunction<D, Mesh = RegularGrid<D>, Domain: Flat + DomainBounds<D>>
{
}

/// A law whose point state is written to checkpoints and travels between
/// ranks.
trait FlatLaw: IncrementalLaw<State: FlatState + Flat> {}

impl<L: IncrementalLaw<State: FlatState + Flat>> FlatLaw for L {}

/// A velocity transfer whose point state is written to checkpoints and
/// travels between ranks.
trait FlatTransfer<const D: usize>: Transfer<D, PointState: FlatState + Flat> {}

impl<const D: usize, T: Transfer<D, PointState: FlatState + Flat>> FlatTransfer<D> for T {}

struct Run<'a, 'o, const D: usize> {
    problem: &'a Problem<D>,
    control: &'a RunControl,
    observer: &'a mut ExplicitObserver<'o>,
}

impl<const D: usize> Run<'_, '_, D> {
    /// The laws of the scene's materials, chosen per point
    /// ([`ExplicitLaws`]).
    fn with_basis<B, R>(self, basis: B, rule: R) -> Result<ExplicitOutput, SolverError>
    where
        B: SceneBasis<D>,
        R: DomainUpdater<D, B::Domain>,
    {
        let laws = (self.problem.materials.iter())
            .map(|m| ExplicitLaw::new(m.model, &m.params))
            .collect::<Result<Vec<_>, _>>()?;
        let laws: ExplicitLaws = MaterialSet::new(laws)?;
        self.with_law(basis, rule, laws)
    }

    /// The transfer.
    fn with_law<B, R, L>(self, basis: B, rule: R, law: L) -> Result<ExplicitOutput, SolverError>
    where
        B: SceneBasis<D>,
        R: DomainUpdater<D, B::Domain>,
        L: FlatLaw,
    {
        let (_, setup) = parts(self.problem)?;
        let alpha = setup.alpha;
        match setup.transfer {
            TransferKind::Pic | TransferKind::Flip | TransferKind::Blend => {
                self.with_transfer(basis, rule, law, FlipPic { alpha })
            }
            TransferKind::Tpic | TransferKind::Tflip => {
                self.with_transfer(basis, rule, law, Taylor { alpha })
            }
        }
    }

    /// The dilatation treatment.
    fn with_transfer<B, R, L, T>(
        self,
        basis: B,
        rule: R,
        law: L,
        transfer: T,
    ) -> Result<ExplicitOutput, SolverError>
    where
        B: SceneBasis<D>,
        R: DomainUpdater<D, B::Domain>,
        L: FlatLaw,
        T: FlatTransfer<D>,
    {
        let (_, setup) = parts(self.problem)?;
        match setup.locking {
            LockingKind::None => self.with(basis, rule, law, transfer, NoLocking),
            LockingKind::CellAveraged => self.with(basis, rule, law, transfer, CellAveraged),
            other => Err(SolverError::InvalidInput(format!(
                "locking = {other}: refused by the rules (mpm_scene::rules)"
            ))),
        }
    }

    /// Runs with every type chosen: the solver and its points, handed to
    /// the time loop ([`time_loop`], compiled once per dimension).
    fn with<B, R, L, T, K>(
        self,
        basis: B,
        rule: R,
        law: L,
        transfer: T,
        locking: K,
    ) -> Result<ExplicitOutput, SolverError>
    where
        B: SceneBasis<D>,
        R: DomainUpdater<D, B::Domain>,
        L: FlatLaw,
        T: FlatTransfer<D>,
        K: DilatationTreatment,
    {
        let (grid, setup) = parts(self.problem)?;
        let options = ExplicitOptions {
            time_step: setup.time_step,
            gravity: setup.gravity,
        };
        let mut solver = ExplicitSolver::new(
            basis,
            grid.clone(),
            law,
            transfer,
            locking,
            setup.fixities.clone(),
            options,
        )?
        .with_domain_update(rule);
        let mut points = initial_points::<D, B, L, T>(self.problem, setup)?;
        if let Some(contact) = &setup.contact {
            if let Some(run) = &self.control.ranks {
                return Err(SolverError::InvalidInput(format!(
                    "contact between bodies ([[contact]]) is not yet supported on {} ranks; run it on one",
                    run.ranks.size()
                )));
            }
            points.field.clone_from(&contact.field);
            solver = solver.with_contact(contact.friction.clone())?;
        }
        let reach = B::SUPPORT_RADIUS.ceil() as usize;
        let spread = (self.control.ranks.as_ref())
            .map(|run| Spread::new(run, grid, reach))
            .transpose()?;
        if let Some(spread) = &spread {
            // A resumed run restores every point, then deals them as the
            // checkpoint says ([`Spread::resume`]).
            if self.control.resume.is_none() {
                points.keep(&spread.own_points(points.len())?)?;
            }
            solver = solver.on_ranks(spread.ranks(), spread.initial_layout()?)?;
        }
        let mut bound = Bound {
            solver,
            points,
            local_of: Vec::new(),
        };
        let mut out = Outputs {
            initial_position: &self.problem.position,
            control: self.control,
            spread,
            observer: self.observer,
        };
        time_loop(&mut bound, setup, &mut out)
    }
}

/// A composed explicit solver with its points, as the scene's time loop
/// sees it. Object-safe, so that the loop, its outputs and checkpoints
/// ([`time_loop`]) are compiled once per dimension; the solver types
/// differ only behind it.
pub(crate) trait Stepper<const D: usize> {
    /// The simulated time reached.
    fn time(&self) -> f64;
    /// One step of at most `max_dt`, the loads with a curve set to their
    /// values at the step's start.
    fn step(&mut self, setup: &ExplicitSetup<D>, max_dt: f64) -> Result<StepInfo, SolverError>;
    /// Where the run stands.
    fn reached(&self) -> Result<Reached, SolverError>;
    /// The energies now.
    fn energies(&self) -> Result<Energies, SolverError>;
    /// The points as plain arrays at `time`, displacements from
    /// `initial`.
    fn snapshot(&self, initial: &[SVector<f64, D>], time: f64) -> Snapshot;
    /// The points' evolving state as numbers ([`write_points`]).
    fn flat_points(&self) -> Vec<f64>;
    /// The points of checkpoint `c` (whose clock is `clock`), the solver
    /// set to its time and its absorbing boundaries' springs to their
    /// displacements.
    fn resume(&mut self, c: &Checkpoint, clock: &Clock) -> Result<(), SolverError>;
    /// The absorbing boundaries' spring displacements, D numbers per
    /// absorbing node (the same on every rank).
    fn spring_displacements(&self) -> Vec<f64>;
    /// Wall time per stage so far.
    fn stage_times(&self) -> ExplicitStageTimes;
    /// The global ids of the points held here (their indices in the
    /// problem).
    fn ids(&self) -> &[usize];
    /// On several ranks, after a step: the points that entered another
    /// rank's cells go there ([`ExplicitSolver::migrate`]).
    fn migrate(&mut self) -> Result<(usize, usize), SolverError>;
    /// The points in every cell over all ranks
    /// ([`ExplicitSolver::cell_loads`]).
    fn cell_loads(&self) -> Result<Vec<f64>, SolverError>;
    /// The cells dealt anew ([`ExplicitSolver::rebalance`]).
    fn rebalance(&mut self, layout: Decomposition) -> Result<(usize, usize), SolverError>;
    /// Keeps the points at `order` (distinct indices), in that order.
    fn keep(&mut self, order: &[usize]) -> Result<(), SolverError>;
    /// The cell of every point held here (`None` off the grid).
    fn cells(&self) -> Vec<Option<usize>>;
    /// The work of the point forces on this rank's points so far.
    fn local_work(&self) -> f64;
    /// Sets it (a resumed run on several ranks).
    fn set_local_work(&mut self, work: f64);
}

/// A typed solver with its points: the [`Stepper`] of one solver type.
struct Bound<const D: usize, B, L, T, K, R>
where
    B: BasisFunction<D>,
    L: IncrementalLaw,
    T: Transfer<D>,
{
    solver: ExplicitSolver<D, B, L, T, K, R>,
    points: PointsOf<D, B, L, T>,
    /// On several ranks with loads on a curve: the local index of every
    /// problem point last seen here, by id ([`place_point_forces`]).
    local_of: Vec<usize>,
}

impl<const D: usize, B, L, T, K, R> Stepper<D> for Bound<D, B, L, T, K, R>
where
    B: SceneBasis<D>,
    R: DomainUpdater<D, B::Domain>,
    L: FlatLaw,
    T: FlatTransfer<D>,
    K: DilatationTreatment,
{
    fn time(&self) -> f64 {
        self.solver.time()
    }

    fn step(&mut self, setup: &ExplicitSetup<D>, max_dt: f64) -> Result<StepInfo, SolverError> {
        let t = self.solver.time();
        if self.solver.rank().1 > 1 && !setup.timed_forces.is_empty() {
            let points = &mut self.points;
            place_point_forces(
                &points.id,
                &mut points.point_force,
                &mut self.local_of,
                setup,
                t,
            );
        } else {
            scale_timed_forces(&mut self.points.point_force, setup, t);
        }
        self.solver.step(&mut self.points, max_dt)
    }

    fn reached(&self) -> Result<Reached, SolverError> {
        // The energies' work is summed over the ranks (on one, the
        // solver's).
        let energies = self.solver.energies(&self.points)?;
        Ok(Reached {
            time: self.solver.time(),
            steps: self.solver.steps(),
            energies,
            external_work: energies.external_work,
        })
    }

    fn energies(&self) -> Result<Energies, SolverError> {
        self.solver.energies(&self.points)
    }

    fn snapshot(&self, initial: &[SVector<f64, D>], time: f64) -> Snapshot {
        snapshot_of(&self.points, initial, time)
    }

    fn flat_points(&self) -> Vec<f64> {
        write_points(&self.points)
    }

    fn resume(&mut self, c: &Checkpoint, clock: &Clock) -> Result<(), SolverError> {
        let scene_tags: Vec<u32> = self
            .points
            .material
            .iter()
            .map(FlatState::material)
            .collect();
        let points =
            read_points::<D, L::State, T::PointState, B::Domain>(&c.points, self.points.clone())?;
        // A tag past the set's end would index no law: the checkpoint must
        // be of this scene's materials.
        if let Some(p) = (0..points.len()).find(|&p| points.material[p].material() != scene_tags[p])
        {
            return Err(SolverError::InvalidInput(format!(
                "the checkpoint gives point {p} material {}, the scene material {}",
                points.material[p].material(),
                scene_tags[p]
            )));
        }
        self.points = points;
        self.solver.resume_at(
            c.state.load_factor,
            c.state.summary.steps,
            clock.external_work,
        );
        self.solver.resume_wall_work(clock.wall_work);
        let springs = Clock::springs(c)?;
        // A checkpoint without the section has no displaced spring.
        if !springs.is_empty() {
            let u = springs.chunks(D).map(SVector::from_column_slice).collect();
            self.solver.resume_spring_displacements(u)?;
        }
        Ok(())
    }

    fn spring_displacements(&self) -> Vec<f64> {
        let u = self.solver.spring_displacements();
        u.iter().flat_map(|u| u.iter().copied()).collect()
    }

    fn stage_times(&self) -> ExplicitStageTimes {
        *self.solver.stage_times()
    }

    fn ids(&self) -> &[usize] {
        &self.points.id
    }

    fn migrate(&mut self) -> Result<(usize, usize), SolverError> {
        self.solver.migrate(&mut self.points)
    }

    fn cell_loads(&self) -> Result<Vec<f64>, SolverError> {
        self.solver.cell_loads(&self.points)
    }

    fn rebalance(&mut self, layout: Decomposition) -> Result<(usize, usize), SolverError> {
        self.solver.rebalance(&mut self.points, layout)
    }

    fn keep(&mut self, order: &[usize]) -> Result<(), SolverError> {
        self.points.keep(order)
    }

    fn cells(&self) -> Vec<Option<usize>> {
        let grid = self.solver.mesh();
        (self.points.position.iter())
            .map(|x| grid.cell_id(grid.cell_containing(x).ok()?).ok())
            .collect()
    }

    fn local_work(&self) -> f64 {
        self.solver.external_work()
    }

    fn set_local_work(&mut self, work: f64) {
        let (time, steps) = (self.solver.time(), self.solver.steps());
        self.solver.resume_at(time, steps, work);
    }
}

/// The scene's time loop, once per dimension: the start (or the resumed
/// checkpoint), the steps between outputs with the observer shown each,
/// the outputs, the summary.
fn time_loop<const D: usize>(
    run: &mut dyn Stepper<D>,
    setup: &ExplicitSetup<D>,
    out: &mut Outputs<'_, '_, D>,
) -> Result<ExplicitOutput, SolverError> {
    let outputs = output_count(setup.end_time, setup.output_interval);
    let output_time = |k: usize| {
        if k >= outputs {
            setup.end_time
        } else {
            k as f64 * setup.output_interval
        }
    };
    let mut wall = Wall::default();
    let mut clock = match &out.control.resume {
        Some(c) => {
            let clock = Clock::from_checkpoint(c)?;
            run.resume(c, &clock)?;
            if let Some(spread) = &mut out.spread {
                spread.resume(run, Clock::held(c)?, clock.external_work)?;
            }
            wall.earlier = c.wall_time_s;
            clock
        }
        None => out.start(run, run.energies()?, &mut wall)?,
    };
    let session_start = run.stage_times();
    while clock.index < outputs {
        let target = output_time(clock.index + 1);
        // As `ExplicitSolver::run_until`, with the curves' forces set at
        // the start of every step.
        while run.time() < target * (1.0 - 1e-12) {
            let info = out.step(|| run.step(setup, target - run.time()))?;
            let balanced = out.after_step(run, info.step)?;
            wall.observe(|| out.show(ExplicitEvent::Step(info)))?;
            if let Some(b) = balanced {
                wall.observe(|| out.show(ExplicitEvent::Rebalanced(b)))?;
            }
        }
        out.output(run, &run.reached()?, &mut clock, &mut wall)?;
    }
    let mut result = out.summary(run, &run.reached()?, &clock)?;
    result.outputs = outputs + 1;
    result.wall_time_s = wall.so_far();
    let stage = run.stage_times();
    result.stage_times = ExplicitStageTimes {
        p2g: stage.p2g - session_start.p2g,
        grid: stage.grid - session_start.grid,
        g2p: stage.g2p - session_start.g2p,
    };
    if let Some(spread) = &out.spread {
        result.ranks = Some(spread.report(&result.stage_times)?);
    }
    Ok(result)
}

/// The scene's points for basis `B`, law `L` and transfer `T`: positions,
/// volumes, masses, initial velocities, forces (the constant ones, then
/// those of the loads with a curve, whose values `scale_timed_forces`
/// sets before every step), fixities and each point's material.
fn initial_points<const D: usize, B, L, T>(
    problem: &Problem<D>,
    setup: &ExplicitSetup<D>,
) -> Result<PointsOf<D, B, L, T>, SolverError>
where
    B: BasisFunction<D>,
    L: FlatLaw,
    T: Transfer<D>,
{
    let points: PointsFor<D, L, T> =
        ExplicitPoints::new(problem.position.clone(), problem.volume.clone(), 1.0)?;
    let domains = (problem.position.iter().zip(&problem.half_lengths))
        .map(|(x, l)| B::initial_domain(x, l))
        .collect();
    let mut points: PointsOf<D, B, L, T> = points.with_domains(domains)?;
    points.mass.clone_from(&problem.mass);
    points.velocity.clone_from(&setup.velocity);
    points.point_force.clone_from(&setup.point_forces);
    for timed in &setup.timed_forces {
        points.point_force.extend_from_slice(&timed.forces);
    }
    points.fixed_velocity.clone_from(&setup.point_fixities);
    for (state, &m) in points.material.iter_mut().zip(&problem.material_of_point) {
        *state = L::State::for_material(m);
    }
    for (state, be) in points.material.iter_mut().zip(&problem.initial_be) {
        *state.elastic_left_cauchy_green().ok_or_else(|| {
            SolverError::InvalidInput("this law's state cannot start from an initial stress".into())
        })? = *be;
    }
    let mut flat = Vec::new();
    for (state, history) in points.material.iter_mut().zip(&problem.initial_history) {
        flat.clear();
        history.write(&mut flat);
        state.set_history(&flat);
    }
    if points.mass.len() != points.len() || points.velocity.len() != points.len() {
        return Err(SolverError::InvalidInput(format!(
            "{} points but {} masses and {} velocities",
            points.len(),
            points.mass.len(),
            points.velocity.len()
        )));
    }
    Ok(points)
}

/// What the outputs of a run need: the initial positions (displacements),
/// whether to keep checkpoints, the ranks of a run on several, and the
/// caller's observer.
struct Outputs<'a, 'o, const D: usize> {
    initial_position: &'a [SVector<f64, D>],
    control: &'a RunControl,
    spread: Option<Spread<'a>>,
    observer: &'a mut ExplicitObserver<'o>,
}

impl<const D: usize> Outputs<'_, '_, D> {
    /// Runs `step`; on several ranks its traffic counted.
    fn step<T>(&mut self, step: impl FnOnce() -> T) -> T {
        match &mut self.spread {
            Some(spread) => spread.step(step),
            None => step(),
        }
    }

    /// On several ranks, after a step: the migration, and a new deal when
    /// the work has drifted out of balance.
    fn after_step(
        &mut self,
        run: &mut dyn Stepper<D>,
        step: usize,
    ) -> Result<Option<Rebalanced>, SolverError> {
        match &mut self.spread {
            Some(spread) => spread.after_step(run, step),
            None => Ok(None),
        }
    }

    /// Shows the observer `event`: on several ranks on rank 0 only, its
    /// verdict agreed.
    fn show(&mut self, event: ExplicitEvent<'_>) -> Result<(), SolverError> {
        match &self.spread {
            Some(spread) => spread.on_root(|| (self.observer)(event)),
            None => (self.observer)(event),
        }
    }

    /// The run's final state at `at`: on several ranks the points gathered
    /// on rank 0 (the other ranks keep their own).
    fn summary(
        &self,
        run: &dyn Stepper<D>,
        at: &Reached,
        clock: &Clock,
    ) -> Result<ExplicitOutput, SolverError> {
        let mut result = summary(run, at, clock, self.initial_position);
        if let Some(spread) = &self.spread {
            let total = self.initial_position.len();
            if let Some(whole) = spread.gather(run.ids(), &result.last, total)? {
                result.last = whole;
            }
        }
        Ok(result)
    }

    /// Output 0, the initial state with its `energies`, and the clock that
    /// starts from it.
    fn start(
        &mut self,
        run: &dyn Stepper<D>,
        energies: Energies,
        wall: &mut Wall,
    ) -> Result<Clock, SolverError> {
        let clock = Clock {
            index: 0,
            external_work: 0.0,
            wall_work: WallWork::default(),
            initial: energies,
            scale: energies.kinetic + energies.strain,
        };
        let at = Reached {
            time: 0.0,
            steps: 0,
            energies,
            external_work: 0.0,
        };
        self.frame(run, &at, &clock, wall)?;
        Ok(clock)
    }

    /// The next output, reached at `at`: the clock advanced to it, the
    /// observer shown it.
    fn output(
        &mut self,
        run: &dyn Stepper<D>,
        at: &Reached,
        clock: &mut Clock,
        wall: &mut Wall,
    ) -> Result<(), SolverError> {
        clock.index += 1;
        clock.external_work = at.external_work;
        clock.wall_work = WallWork {
            friction: at.energies.friction_work,
            impact: at.energies.wall_work,
            absorbed: at.energies.absorbed_work,
        };
        clock.scale = clock.scale.max(at.energies.kinetic + at.energies.strain);
        self.frame(run, at, clock, wall)
    }

    /// Shows the observer output `clock.index` (its time excluded from the
    /// solver's wall time).
    fn frame(
        &mut self,
        run: &dyn Stepper<D>,
        at: &Reached,
        clock: &Clock,
        wall: &mut Wall,
    ) -> Result<(), SolverError> {
        let so_far = wall.so_far();
        let (initial, control) = (self.initial_position, self.control);
        let observer = &mut *self.observer;
        let mut show = |snapshot: &Snapshot| {
            observer(ExplicitEvent::Output(ExplicitFrame {
                index: clock.index,
                time: at.time,
                steps: at.steps,
                energies: at.energies,
                snapshot,
            }))
        };
        wall.observe(|| {
            let spread = self.spread.as_ref();
            let snapshot = snapshot(run, initial, at, control, clock, so_far, spread)?;
            match &self.spread {
                Some(spread) => {
                    spread.observe_gathered(clock.index, run.ids(), &snapshot, initial.len(), show)
                }
                None => show(&snapshot),
            }
        })
    }
}

/// Where the solver stands at an output.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Reached {
    time: f64,
    steps: usize,
    energies: Energies,
    external_work: f64,
}

/// The run's final state at `at` (the caller adds the counts and times of
/// this session).
fn summary<const D: usize>(
    run: &dyn Stepper<D>,
    at: &Reached,
    clock: &Clock,
    initial_position: &[SVector<f64, D>],
) -> ExplicitOutput {
    let scale = clock.scale;
    let drift = at.energies.total() - clock.initial.total();
    ExplicitOutput {
        last: run.snapshot(initial_position, at.time),
        steps: at.steps,
        time: at.time,
        outputs: 0,
        initial: clock.initial,
        last_energies: at.energies,
        energy_scale: scale,
        energy_drift: if scale > 0.0 { drift / scale } else { 0.0 },
        wall_time_s: 0.0,
        stage_times: ExplicitStageTimes::default(),
        ranks: None,
    }
}

/// Sets the forces of the loads with a curve to their values at time `t`
/// (s). They follow the constant forces in `forces`, in the order of
/// `setup.timed_forces`. The solver takes a step's force as constant over
/// the step (the momentum update of eq. 32 is forward Euler), so its
/// external work stays consistent.
fn scale_timed_forces<const D: usize>(
    forces: &mut [(usize, SVector<f64, D>)],
    setup: &ExplicitSetup<D>,
    t: f64,
) {
    let mut at = setup.point_forces.len();
    for timed in &setup.timed_forces {
        let factor = timed.curve.at(t);
        let n = timed.forces.len();
        for (slot, &(_, f)) in forces[at..at + n].iter_mut().zip(&timed.forces) {
            slot.1 = f * factor;
        }
        at += n;
    }
}

/// The point forces of `setup` at time `t` on this rank's points: on
/// several ranks a point's place in the force list changes as points
/// migrate, so the list is made anew before every step from the problem's
/// forces, each placed on its point by id (`local_of`, the local index of
/// every id last seen here, kept between steps so that nothing is
/// allocated per step), in the order of the problem's list: the
/// constant forces, then those of every curve scaled by its factor.
fn place_point_forces<const D: usize>(
    ids: &[usize],
    forces: &mut Vec<(usize, SVector<f64, D>)>,
    local_of: &mut Vec<usize>,
    setup: &ExplicitSetup<D>,
    t: f64,
) {
    for (p, &id) in ids.iter().enumerate() {
        if id >= local_of.len() {
            local_of.resize(id + 1, usize::MAX);
        }
        local_of[id] = p;
    }
    let here = |id: usize| {
        let p = local_of.get(id).copied().unwrap_or(usize::MAX);
        (ids.get(p) == Some(&id)).then_some(p)
    };
    forces.clear();
    let constant = setup.point_forces.iter().map(|&(id, f)| (id, f));
    let timed = setup.timed_forces.iter().flat_map(|timed| {
        let factor = timed.curve.at(t);
        timed.forces.iter().map(move |&(id, f)| (id, f * factor))
    });
    forces.extend(
        constant
            .chain(timed)
            .filter_map(|(id, f)| Some((here(id)?, f))),
    );
}

/// Outputs after the initial state: `end_time / interval` rounded up (an
/// interval that divides the end time to rounding gives no sliver).
fn output_count(end_time: f64, interval: f64) -> usize {
    let n = end_time / interval;
    let rounded = n.round();
    if (n - rounded).abs() <= 1e-9 * n.max(1.0) {
        (rounded as usize).max(1)
    } else {
        (n.ceil() as usize).max(1)
    }
}

/// Solver wall time: total elapsed minus the observer's share, plus the
/// time before a resumed checkpoint.
struct Wall {
    start: Instant,
    observer: f64,
    earlier: f64,
}

impl Default for Wall {
    fn default() -> Self {
        Self {
            start: Instant::now(),
            observer: 0.0,
            earlier: 0.0,
        }
    }
}

impl Wall {
    fn so_far(&self) -> f64 {
        self.earlier + self.start.elapsed().as_secs_f64() - self.observer
    }

    /// Runs `f` and books its time to the observer.
    fn observe<R>(&mut self, f: impl FnOnce() -> R) -> R {
        let t = Instant::now();
        let r = f();
        self.observer += t.elapsed().as_secs_f64();
        r
    }
}

/// What an explicit checkpoint keeps besides the points and the step
/// count: the output reached, the work of the applied forces, what the
/// friction walls and absorbing boundaries took, the initial energies and
/// the energy scale (in [`Checkpoint::case_state`], followed by the
/// spring section — its length, then the absorbing boundaries' spring
/// displacements — and, on several ranks, how they held the points).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Clock {
    index: usize,
    external_work: f64,
    wall_work: WallWork,
    initial: Energies,
    scale: f64,
}

impl Clock {
    pub(crate) const LEN: usize = 10;

    fn to_case_state(self) -> Vec<f64> {
        let e = self.initial;
        vec![
            self.index as f64,
            self.external_work,
            e.kinetic,
            e.strain,
            e.gravitational,
            e.external_work,
            self.scale,
            self.wall_work.friction,
            self.wall_work.impact,
            self.wall_work.absorbed,
        ]
    }

    /// The spring section of checkpoint `c`: after the clock, the count
    /// of numbers then the absorbing nodes' spring displacements (empty
    /// in a checkpoint without the section).
    fn springs(c: &Checkpoint) -> Result<&[f64], SolverError> {
        let s = &c.case_state[Self::LEN.min(c.case_state.len())..];
        let Some((&n, rest)) = s.split_first() else {
            return Ok(&[]);
        };
        if !(n >= 0.0 && n.fract() == 0.0 && n as usize <= rest.len()) {
            return Err(SolverError::InvalidInput(format!(
                "the checkpoint's spring section claims {n} numbers of {}",
                rest.len()
            )));
        }
        Ok(&rest[..n as usize])
    }

    /// What follows the clock and the spring section in checkpoint `c`:
    /// how the ranks held the points.
    fn held(c: &Checkpoint) -> Result<&[f64], SolverError> {
        let springs = Self::springs(c)?.len();
        let start = (Self::LEN + 1 + springs).min(c.case_state.len());
        Ok(&c.case_state[start..])
    }

    fn from_checkpoint(c: &Checkpoint) -> Result<Self, SolverError> {
        // A run on several ranks adds how they held the points.
        let s = &c.case_state;
        if s.len() < Self::LEN || !(s[0] >= 0.0 && s[0].fract() == 0.0) {
            return Err(SolverError::InvalidInput(
                "the checkpoint was not written by an explicit run of this scene".into(),
            ));
        }
        Ok(Self {
            index: s[0] as usize,
            external_work: s[1],
            // Output 0, where a run starts, has taken nothing at its walls.
            initial: Energies {
                kinetic: s[2],
                strain: s[3],
                gravitational: s[4],
                external_work: s[5],
                ..Energies::default()
            },
            scale: s[6],
            wall_work: WallWork {
                friction: s[7],
                impact: s[8],
                absorbed: s[9],
            },
        })
    }
}

/// A snapshot of the points at `at`, with a checkpoint when the run keeps
/// them: on several ranks (`spread`) rank 0's holds every point, in the
/// order of their ids, and how the ranks held them. Collective then.
///
/// # Errors
/// The gather's, on every rank.
fn snapshot<const D: usize>(
    run: &dyn Stepper<D>,
    initial: &[SVector<f64, D>],
    at: &Reached,
    control: &RunControl,
    clock: &Clock,
    wall_time_s: f64,
    spread: Option<&Spread<'_>>,
) -> Result<Snapshot, SolverError> {
    let (time, steps) = (at.time, at.steps);
    let mut snap = run.snapshot(initial, time);
    if control.checkpoint {
        let (points, held) = match spread {
            Some(spread) => spread.checkpoint(run, initial.len())?,
            None => (run.flat_points(), Vec::new()),
        };
        let mut case_state = clock.to_case_state();
        let springs = run.spring_displacements();
        case_state.push(springs.len() as f64);
        case_state.extend(springs);
        case_state.extend(held);
        snap.checkpoint = Some(Checkpoint {
            state: RunState {
                load_factor: time,
                increment: 0.0,
                summary: RunSummary {
                    steps,
                    cut_steps: 0,
                    iterations: 0,
                },
            },
            predictor: None,
            contact: Vec::new(),
            points,
            wall_time_s,
            case_state,
        });
    }
    Ok(snap)
}

/// The points as plain arrays: positions, displacements from `initial`,
/// velocities, Cauchy stresses, deformation gradients, volumes, plastic
/// strains.
fn snapshot_of<const D: usize, S: FlatState, T: FlatState, Dom: DomainBounds<D>>(
    points: &ExplicitPoints<D, S, T, Dom>,
    initial: &[SVector<f64, D>],
    time: f64,
) -> Snapshot {
    let pad = |x: &SVector<f64, D>| std::array::from_fn(|i| if i < D { x[i] } else { 0.0 });
    let flat = |m: &Matrix3<f64>| std::array::from_fn(|k| m[(k / 3, k % 3)]);
    Snapshot {
        load_factor: time,
        position: points.position.iter().map(pad).collect(),
        // By id: on several ranks a rank holds some of the points, in the
        // order migration left them.
        displacement: (points.position.iter().zip(&points.id))
            .map(|(x, &id)| pad(&(x - initial[id])))
            .collect(),
        velocity: points.velocity.iter().map(pad).collect(),
        sigma: (0..points.len()).map(|p| flat(&points.cauchy(p))).collect(),
        f: points.f.iter().map(flat).collect(),
        volume: points.volume.clone(),
        plastic_strain: points
            .material
            .iter()
            .map(FlatState::plastic_strain)
            .collect(),
        domain_bounds: crate::run::domain_bounds(&points.domain, &points.position),
        ..Snapshot::default()
    }
}

/// A per-point state stored in a checkpoint as exactly [`FlatState::LEN`]
/// numbers: the laws' states ($b^e$ and the history) and the transfers'
/// (nothing, or the velocity gradient).
pub trait FlatState: Copy + Default + Send + Sync + std::fmt::Debug + PartialEq + 'static {
    /// Numbers per value.
    const LEN: usize;
    /// Appends the value's numbers to `out`.
    fn write(&self, out: &mut Vec<f64>);
    /// Reads a value from exactly [`FlatState::LEN`] numbers.
    fn read(from: &[f64]) -> Self;
    /// Equivalent plastic strain of a law's state (0 otherwise).
    fn plastic_strain(&self) -> f64 {
        0.0
    }
    /// The initial state of a point of scene material `material`: tagged
    /// with it for a [`MaterialSet`]'s state, the default otherwise.
    fn for_material(material: u32) -> Self {
        let _ = material;
        Self::default()
    }
    /// The material a state is tagged with (0 when untagged).
    fn material(&self) -> u32 {
        0
    }
    /// The elastic left Cauchy–Green tensor of a law's state, to start it
    /// from an initial stress (`None`: the state has none).
    fn elastic_left_cauchy_green(&mut self) -> Option<&mut Matrix3<f64>> {
        None
    }
    /// Sets the history of a law's state from the flat form of the scene's
    /// initial history (`Problem::initial_history`, a `SceneHistory`: the
    /// scene's laws' states hold one); nothing for a state without one.
    fn set_history(&mut self, flat: &[f64]) {
        let _ = flat;
    }
}

/// A [`MaterialSet`]'s state: the material index, then the law's state.
impl<S: FlatState> FlatState for Tagged<S> {
    const LEN: usize = 1 + S::LEN;
    fn write(&self, out: &mut Vec<f64>) {
        out.push(f64::from(self.material));
        self.inner.write(out);
    }
    fn read(from: &[f64]) -> Self {
        // Anything but a whole number in range reads as u32::MAX, which
        // the caller's check against the scene's tags refuses.
        let m = from[0];
        let material = if m.fract() == 0.0 && (0.0..f64::from(u32::MAX)).contains(&m) {
            m as u32
        } else {
            u32::MAX
        };
        Self::new(material, S::read(&from[1..]))
    }
    fn plastic_strain(&self) -> f64 {
        self.inner.plastic_strain()
    }
    fn for_material(material: u32) -> Self {
        Self::new(material, S::default())
    }
    fn material(&self) -> u32 {
        self.material
    }
    fn elastic_left_cauchy_green(&mut self) -> Option<&mut Matrix3<f64>> {
        self.inner.elastic_left_cauchy_green()
    }
    fn set_history(&mut self, flat: &[f64]) {
        self.inner.set_history(flat);
    }
}

impl<H> FlatState for MaterialState<H>
where
    H: Flat + HistoryOutput + Copy + Default + Send + Sync + std::fmt::Debug + PartialEq + 'static,
{
    const LEN: usize = 9 + H::LEN;
    fn write(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(self.be.as_slice());
        self.history.write(out);
    }
    fn read(from: &[f64]) -> Self {
        Self {
            be: Matrix3::from_column_slice(&from[..9]),
            history: H::read(&from[9..]),
        }
    }
    fn plastic_strain(&self) -> f64 {
        self.history.equivalent_plastic_strain()
    }
    fn elastic_left_cauchy_green(&mut self) -> Option<&mut Matrix3<f64>> {
        Some(&mut self.be)
    }
    fn set_history(&mut self, flat: &[f64]) {
        if flat.len() == H::LEN {
            self.history = H::read(flat);
        }
    }
}

impl FlatState for () {
    const LEN: usize = 0;
    fn write(&self, _: &mut Vec<f64>) {}
    fn read(_: &[f64]) -> Self {}
}

impl<const D: usize> FlatState for VelocityGradient<D> {
    const LEN: usize = D * D;
    fn write(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(self.0.as_slice());
    }
    fn read(from: &[f64]) -> Self {
        Self(nalgebra::SMatrix::from_column_slice(&from[..D * D]))
    }
}

/// Numbers per point of [`write_points`].
fn point_len<const D: usize, S: FlatState, T: FlatState, Dom: Flat>() -> usize {
    2 * D + 3 + 18 + S::LEN + T::LEN + Dom::LEN
}

/// The points' evolving state as numbers: the count, then per point its
/// position, velocity, mass, initial and current volume, F, τ, the law's
/// and the transfer's state, the basis's domain (none for bases without
/// one). Point forces, fixities and initial domains are the scene's and
/// not stored.
fn write_points<const D: usize, S: FlatState, T: FlatState, Dom: Flat>(
    points: &ExplicitPoints<D, S, T, Dom>,
) -> Vec<f64> {
    let n = points.len();
    let mut out = Vec::with_capacity(1 + n * point_len::<D, S, T, Dom>());
    out.push(n as f64);
    for p in 0..n {
        out.extend_from_slice(points.position[p].as_slice());
        out.extend_from_slice(points.velocity[p].as_slice());
        out.extend([points.mass[p], points.volume0[p], points.volume[p]]);
        out.extend_from_slice(points.f[p].as_slice());
        out.extend_from_slice(points.tau[p].as_slice());
        points.material[p].write(&mut out);
        points.transfer[p].write(&mut out);
        points.domain[p].write(&mut out);
    }
    out
}

/// [`write_points`] read back into `points` (the scene's points, which
/// keep their point forces).
fn read_points<const D: usize, S: FlatState, T: FlatState, Dom: Flat>(
    flat: &[f64],
    mut points: ExplicitPoints<D, S, T, Dom>,
) -> Result<ExplicitPoints<D, S, T, Dom>, SolverError> {
    let n = points.len();
    let per = point_len::<D, S, T, Dom>();
    if flat.first() != Some(&(n as f64)) || flat.len() != 1 + n * per {
        return Err(SolverError::InvalidInput(format!(
            "the checkpoint holds {} numbers, {n} points of this scene's explicit run take {}",
            flat.len(),
            1 + n * per
        )));
    }
    for (p, chunk) in flat[1..].chunks_exact(per).enumerate() {
        let (x, rest) = chunk.split_at(D);
        let (v, rest) = rest.split_at(D);
        points.position[p] = SVector::from_column_slice(x);
        points.velocity[p] = SVector::from_column_slice(v);
        points.mass[p] = rest[0];
        points.volume0[p] = rest[1];
        points.volume[p] = rest[2];
        let rest = &rest[3..];
        points.f[p] = Matrix3::from_column_slice(&rest[..9]);
        points.tau[p] = Matrix3::from_column_slice(&rest[9..18]);
        let rest = &rest[18..];
        points.material[p] = S::read(&rest[..S::LEN]);
        points.transfer[p] = T::read(&rest[S::LEN..S::LEN + T::LEN]);
        points.domain[p] = Dom::read(&rest[S::LEN + T::LEN..]);
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn output_times_end_at_the_end_time_without_slivers() {
        assert_eq!(output_count(1.0, 0.05), 20);
        assert_eq!(output_count(3.0, 0.1), 30);
        assert_eq!(output_count(1.0, 0.3), 4);
        assert_eq!(output_count(1.0, 5.0), 1);
    }

    #[test]
    fn points_survive_their_flat_form() {
        type S = MaterialState<mpm_constitutive::VonMisesHistory>;
        let mut points: ExplicitPoints<2, S, VelocityGradient<2>> = ExplicitPoints::new(
            vec![Vector2::new(0.1, 0.2), Vector2::new(0.3, 0.4)],
            vec![0.5, 0.25],
            2.0,
        )
        .expect("points");
        points.velocity[1] = Vector2::new(-1.0, 2.0);
        points.f[0][(0, 1)] = 0.1;
        points.tau[1][(2, 2)] = 5.0;
        points.material[1].history.alpha = 0.01;
        points.material[0].be[(1, 1)] = 1.1;
        points.transfer[1] = VelocityGradient(nalgebra::Matrix2::new(1.0, 2.0, 3.0, 4.0));
        let flat = write_points(&points);
        let fresh: ExplicitPoints<2, S, VelocityGradient<2>> =
            ExplicitPoints::new(vec![Vector2::zeros(); 2], vec![1.0; 2], 1.0).expect("points");
        let back = read_points(&flat, fresh).expect("read");
        assert_eq!(back.position, points.position);
        assert_eq!(back.velocity, points.velocity);
        assert_eq!(back.mass, points.mass);
        assert_eq!(back.f, points.f);
        assert_eq!(back.tau, points.tau);
        assert_eq!(back.material, points.material);
        assert_eq!(back.transfer, points.transfer);
        let short = ExplicitPoints::<2, S, VelocityGradient<2>>::new(
            vec![SVector::zeros(); 3],
            vec![1.0; 3],
            1.0,
        )
        .expect("points");
        assert!(read_points(&flat, short).is_err());
    }
}
