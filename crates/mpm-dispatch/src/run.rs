//! Running one body on a regular grid with a composed implicit solver.

use std::time::Instant;

use mpm_constitutive::LogStrainLaw;
use mpm_solver::{
    BodyForcePath, Constraints, DomainUpdater, Flat, Formulation, ImplicitSolver, LoadStepping,
    LockingTreatment, MaterialPoints, MovableMesh, NewtonOptions, NoLocking, NodalMesh, Parts,
    RunState, RunSummary, SolverError, StepReport,
};
use nalgebra::SVector;

pub use mpm_scene::body::{DomainBounds, InitialDomain};
pub use mpm_scene::material::HistoryOutput;

use mpm_scene::body::Body;

use crate::on_ranks::{self, RankRun};
use mpm_solver::ranks;

/// What sees each converged step: its number, its report and the state
/// after it. Runs take it as a trait object, so the solver behind a run is
/// compiled once per variant, not once more for every caller's closure.
pub type StepObserver<'a, const D: usize> =
    dyn FnMut(usize, &StepReport<D>, &Snapshot) -> Result<(), SolverError> + 'a;

/// Each point's domain box (in 3 components), for the snapshots; empty for
/// bases without domains.
pub(crate) fn domain_bounds<const D: usize, Dom: DomainBounds<D>>(
    domains: &[Dom],
    positions: &[SVector<f64, D>],
) -> Vec<([f64; 3], [f64; 3])> {
    let pad = |x: &SVector<f64, D>| std::array::from_fn(|i| if i < D { x[i] } else { 0.0 });
    domains
        .iter()
        .zip(positions)
        .filter_map(|(d, x)| d.bounds(x).map(|(lo, hi)| (pad(&lo), pad(&hi))))
        .collect()
}

/// A plain copy of the material point state after a step, for output and
/// error norms (no solver types).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Snapshot {
    /// Load factor.
    pub load_factor: f64,
    /// Positions, padded to 3D.
    pub position: Vec<[f64; 3]>,
    /// Total displacement, padded to 3D.
    pub displacement: Vec<[f64; 3]>,
    /// Velocity, padded to 3D (explicit runs; empty for the quasi-static
    /// solver).
    pub velocity: Vec<[f64; 3]>,
    /// Cauchy stress, row-major 3×3.
    pub sigma: Vec<[f64; 9]>,
    /// Deformation gradient, row-major 3×3.
    pub f: Vec<[f64; 9]>,
    /// Volume.
    pub volume: Vec<f64>,
    /// Equivalent plastic strain.
    pub plastic_strain: Vec<f64>,
    /// Lower and upper corners of each point's domain, padded to 3D; empty
    /// for bases without a domain.
    pub domain_bounds: Vec<([f64; 3], [f64; 3])>,
    /// The background mesh's node positions, padded to 3D, when the mesh
    /// moves (moving-mesh boundary conditions); `None` for a fixed mesh.
    pub mesh_nodes: Option<Vec<[f64; 3]>>,
    /// Everything needed to resume after this step, when the run was asked
    /// for checkpoints ([`RunControl::checkpoint`]).
    pub checkpoint: Option<Checkpoint>,
    /// The step's last assembled stiffness over the free dofs, when the run
    /// was asked for it ([`RunControl::export_tangent`]) and the step
    /// assembled one.
    pub tangent: Option<sprs::CsMat<f64>>,
}

/// The state of a run between two steps, from which it can be resumed with
/// the same results as an uninterrupted run (see [`crate::checkpoint`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Checkpoint {
    /// Load stepping state.
    pub state: RunState,
    /// The Newton predictor's memory (increment per mesh dof, load
    /// increment).
    pub predictor: Option<(Vec<f64>, f64)>,
    /// The rigid tools' committed contact forces
    /// ([`ImplicitSolver::contact_state`]; empty without tools).
    pub contact: Vec<f64>,
    /// The material points ([`MaterialPoints::to_flat`]).
    pub points: Vec<f64>,
    /// Solver wall time so far (s).
    pub wall_time_s: f64,
    /// The case's own accumulators (e.g. a reference solution driven along
    /// the run and the largest error so far), written by the case and
    /// restored by it on resume.
    pub case_state: Vec<f64>,
}

/// How a run is driven beyond its scene: checkpoints and resumption.
#[derive(Debug, Clone, Default)]
pub struct RunControl {
    /// Attach a [`Checkpoint`] to every step's [`Snapshot`].
    pub checkpoint: bool,
    /// Continue from this checkpoint instead of starting at load factor 0.
    pub resume: Option<Checkpoint>,
    /// Builds the linear solver a scene asks for beyond the built-in ones
    /// (PETSc's, `linear = { petsc = "..." }`): set by a program built
    /// with it (mpm-distributed's `petsc` feature); `None` refuses such a
    /// scene.
    pub external_linear: Option<crate::linear::ExternalLinear>,
    /// Attach each step's assembled stiffness to its [`Snapshot`] (for
    /// Matrix Market export).
    pub export_tangent: bool,
    /// Run on these ranks, each with the points it is dealt; the observer
    /// is called on rank 0 alone, with the whole problem's snapshot
    /// ([`crate::on_ranks`]). `None`: one process.
    pub ranks: Option<crate::on_ranks::RankRun>,
}

impl Snapshot {
    /// Copies the state of `points`.
    pub fn of<const D: usize, H: HistoryOutput, Dom: DomainBounds<D>>(
        points: &MaterialPoints<D, H, Dom>,
        load_factor: f64,
    ) -> Self {
        let pad = |x: &SVector<f64, D>| {
            let mut out = [0.0; 3];
            for i in 0..D.min(3) {
                out[i] = x[i];
            }
            out
        };
        let flat = |m: &nalgebra::Matrix3<f64>| {
            let mut out = [0.0; 9];
            for i in 0..3 {
                for j in 0..3 {
                    out[3 * i + j] = m[(i, j)];
                }
            }
            out
        };
        Self {
            load_factor,
            position: points.position.iter().map(pad).collect(),
            displacement: points.displacement.iter().map(pad).collect(),
            velocity: Vec::new(),
            sigma: points.sigma.iter().map(flat).collect(),
            f: points.f.iter().map(flat).collect(),
            volume: points.volume.clone(),
            plastic_strain: points
                .history
                .iter()
                .map(HistoryOutput::equivalent_plastic_strain)
                .collect(),
            domain_bounds: domain_bounds(&points.domain, &points.position),
            mesh_nodes: None,
            checkpoint: None,
            tangent: None,
        }
    }
}

/// Loads on a body.
#[derive(Debug, Clone, Default)]
pub struct Loads<const D: usize> {
    /// Gravitational acceleration reached at load factor 1.
    pub gravity: Option<SVector<f64, D>>,
    /// Point loads (point index, force at load factor 1).
    pub point_forces: Vec<(usize, SVector<f64, D>)>,
    /// A body force that is not proportional to the load factor.
    pub body_force_path: Option<BodyForcePath<D>>,
}

/// Everything a run produced.
#[derive(Debug, Clone)]
pub struct RunOutput<const D: usize> {
    /// The final state, with the moving mesh's nodes when the mesh moves.
    pub last: Snapshot,
    /// Reports of the converged steps (of this session, when resumed).
    pub reports: Vec<StepReport<D>>,
    /// Step and iteration counts.
    pub summary: RunSummary,
    /// Solver wall time (observer time excluded), seconds, including the
    /// time before a resumed checkpoint.
    pub wall_time_s: f64,
}

/// A body, a mesh, a law, loads and constraints: one quasi-static analysis.
#[derive(Debug, Clone)]
pub struct Setup<'a, const D: usize, M, L, C> {
    /// The background mesh.
    pub grid: M,
    /// The material points' layout.
    pub body: &'a Body<D>,
    /// Density.
    pub density: f64,
    /// The material.
    pub law: L,
    /// Loads.
    pub loads: Loads<D>,
    /// Dirichlet conditions.
    pub constraints: C,
    /// Load stepping.
    pub stepping: LoadStepping,
    /// Newton controls.
    pub newton: NewtonOptions,
}

/// Everything of an analysis but its material points: the mesh, the law,
/// the Dirichlet conditions and the controls.
#[derive(Debug, Clone)]
pub struct Analysis<M, L, C> {
    /// The background mesh.
    pub grid: M,
    /// The material.
    pub law: L,
    /// Dirichlet conditions.
    pub constraints: C,
    /// Load stepping.
    pub stepping: LoadStepping,
    /// Newton controls.
    pub newton: NewtonOptions,
    /// PETSc's options when the linear solves go to PETSc
    /// ([`crate::linear::external`]), `None` for `newton.linear`.
    pub petsc: Option<mpm_scene::build::PetscRequest>,
}

/// Runs `setup` with basis `B`, formulation `F` and updater `U`; `observer`
/// sees each converged step's report and state (its time is excluded from
/// `wall_time_s`). `control` asks for checkpoints or resumes from one.
pub fn simulate<const D: usize, B, F, U, L, C, O>(
    setup: Setup<'_, D, B::Mesh, L, C>,
    basis: B,
    updater: U,
    control: &RunControl,
    observer: O,
) -> Result<RunOutput<D>, SolverError>
where
    B: InitialDomain<D, Mesh: MovableMesh<D>, Domain: Flat + DomainBounds<D>>,
    F: Formulation,
    U: DomainUpdater<D, B::Domain>,
    L: LogStrainLaw<History: HistoryOutput + Flat>,
    C: Constraints<D>,
    O: FnMut(usize, &StepReport<D>, &Snapshot) -> Result<(), SolverError>,
{
    let body = setup.body;
    let domains = body
        .position
        .iter()
        .zip(&body.half_lengths)
        .map(|(x, l)| B::initial_domain(x, l))
        .collect();
    let mut points: MaterialPoints<D, L::History, B::Domain> = MaterialPoints::new(
        body.position.clone(),
        body.volume.clone(),
        setup.density,
        domains,
    )?;
    if let Some(g) = setup.loads.gravity {
        points.set_gravity(g);
    }
    points.point_force = setup.loads.point_forces.clone();
    points.body_force_path = setup.loads.body_force_path.clone();
    let analysis = Analysis {
        grid: setup.grid,
        law: setup.law,
        constraints: setup.constraints,
        stepping: setup.stepping,
        newton: setup.newton,
        petsc: None,
    };
    let mut observer = observer;
    simulate_points::<D, B, F, U, NoLocking, L, C>(
        points,
        analysis,
        basis,
        updater,
        NoLocking,
        control,
        &mut observer,
    )
}

/// [`simulate`] from material points the caller has set up (per-point
/// masses, initial histories such as material tags, loads), with the
/// locking treatment `locking`.
#[allow(clippy::too_many_arguments)]
pub fn simulate_points<const D: usize, B, F, U, K, L, C>(
    mut points: MaterialPoints<D, L::History, B::Domain>,
    analysis: Analysis<B::Mesh, L, C>,
    basis: B,
    updater: U,
    locking: K,
    control: &RunControl,
    observer: &mut StepObserver<'_, D>,
) -> Result<RunOutput<D>, SolverError>
where
    B: InitialDomain<D, Mesh: MovableMesh<D>, Domain: Flat + DomainBounds<D>>,
    F: Formulation,
    U: DomainUpdater<D, B::Domain>,
    K: LockingTreatment<D, B::Mesh>,
    L: LogStrainLaw<History: HistoryOutput + Flat>,
    C: Constraints<D>,
{
    let setup = analysis;
    let moves_mesh = setup.constraints.moves_mesh();
    let external = crate::linear::external(
        setup.petsc.as_ref(),
        setup.newton.linear,
        control.external_linear,
    )?;
    let mut solver: ImplicitSolver<D, Parts<B, F, L, K, U, C>> = ImplicitSolver::new(
        basis,
        setup.grid,
        setup.law,
        locking,
        updater,
        setup.constraints,
        setup.newton,
    );
    if let Some(linear) = external {
        if control.ranks.is_some() && linear.solves_over_ranks() && control.export_tangent {
            return Err(SolverError::InvalidInput(
                "--export-tangent writes the whole stiffness, which no process holds when \
                 PETSc solves over the processes; export it from a run on one process"
                    .into(),
            ));
        }
        solver.set_linear_solver(linear);
    }
    let total = points.len();
    // A checkpoint holds the whole problem's points (joined from the ranks'
    // parts when written on several), so it resumes on any number of
    // ranks: restored whole, then dealt as at the start.
    let (state, earlier_time) = match &control.resume {
        Some(c) => {
            resume_points(c, &mut points)?;
            solver.set_predictor_state(c.predictor.clone())?;
            solver.set_contact_state(&c.contact)?;
            (c.state, c.wall_time_s)
        }
        None => (RunState::start(&setup.stepping), 0.0),
    };
    let dealt = control.ranks.as_ref().map(|r| deal(r, &mut points));
    let own = dealt.transpose()?;
    if let (Some(r), Some(ids)) = (&control.ranks, &own) {
        solver.on_ranks(Box::new(r.ranks.clone()));
        solver.name_points(ids.clone());
    }
    let mut reports = Vec::new();
    // The moving mesh after the last step, for `RunOutput::last`.
    let mut last_mesh = None;
    let mut observer_time = 0.0;
    let start = Instant::now();
    let summary = solver.run_from(
        &mut points,
        &setup.stepping,
        state,
        |step, report, pts, now| {
            let t = Instant::now();
            reports.push(report.clone());
            let mut snapshot = Snapshot::of(pts, report.lambda1);
            if moves_mesh {
                snapshot.mesh_nodes = Some(
                    (0..now.mesh.node_count())
                        .map(|v| {
                            let x = now.mesh.node_position(v);
                            std::array::from_fn(|i| if i < D { x[i] } else { 0.0 })
                        })
                        .collect(),
                );
            }
            if control.checkpoint {
                let points = match (&control.ranks, &own) {
                    (Some(r), Some(ids)) => whole_points(r, ids, pts, total)?,
                    _ => pts.to_flat(),
                };
                snapshot.checkpoint = Some(Checkpoint {
                    state: now.state,
                    predictor: now.predictor.map(|(u, dl)| (u.to_vec(), dl)),
                    contact: now.contact.to_vec(),
                    points,
                    wall_time_s: earlier_time + start.elapsed().as_secs_f64() - observer_time,
                    case_state: Vec::new(),
                });
            }
            if control.export_tangent {
                snapshot.tangent = now.stiffness.map(|k| k.to_sprs()).transpose()?;
            }
            match (&control.ranks, &own) {
                (Some(r), Some(ids)) => {
                    r.write_piece(step, &snapshot, ids)?;
                    on_ranks::observe_on_root(
                        r.ranks.as_ref(),
                        ids,
                        &snapshot,
                        total,
                        &mut |whole| observer(step, report, whole),
                    )?;
                }
                _ => observer(step, report, &snapshot)?,
            }
            last_mesh = snapshot.mesh_nodes.take();
            observer_time += t.elapsed().as_secs_f64();
            Ok(())
        },
    )?;
    let wall_time_s = earlier_time + start.elapsed().as_secs_f64() - observer_time;
    let mut last = Snapshot {
        mesh_nodes: last_mesh,
        ..Snapshot::of(&points, 1.0)
    };
    if let (Some(r), Some(ids)) = (&control.ranks, &own) {
        // Rank 0 reports the whole problem; the others their own points.
        if let Some(whole) = on_ranks::gather(r.ranks.as_ref(), ids, &last, total)? {
            last = whole;
        }
    }
    Ok(RunOutput {
        last,
        reports,
        summary,
        wall_time_s,
    })
}

/// Replaces the scene's `points` by the checkpoint's (the body-force path,
/// code rather than state, kept).
fn resume_points<const D: usize, H: Copy + Default + Flat, Dom: Copy + Flat>(
    c: &Checkpoint,
    points: &mut MaterialPoints<D, H, Dom>,
) -> Result<(), SolverError> {
    let resumed = MaterialPoints::from_flat(&c.points)?;
    if resumed.len() != points.len() {
        return Err(SolverError::InvalidInput(format!(
            "the checkpoint holds {} material points, the scene {}",
            resumed.len(),
            points.len()
        )));
    }
    *points = MaterialPoints {
        body_force_path: points.body_force_path.take(),
        ..resumed
    };
    Ok(())
}

/// Keeps this rank's points of `points` (all of the problem's, built on
/// every rank) and returns their indices in the problem.
fn deal<const D: usize, H: Copy + Default, Dom: Copy>(
    run: &RankRun,
    points: &mut MaterialPoints<D, H, Dom>,
) -> Result<Vec<usize>, SolverError> {
    let ids = run.own_points(points.len())?;
    points.keep(&ids)?;
    Ok(ids)
}

/// The whole problem's points as numbers ([`MaterialPoints::to_flat`]) on
/// rank 0, for its checkpoint: every rank's part (its points `ids` of
/// `total`) sent there and joined ([`MaterialPoints::join`]); empty on the
/// other ranks. The values travel as they are, so the checkpoint is the
/// one a single process would hold at that state. Collective.
///
/// # Errors
/// The transport's, or parts that do not join, on every rank.
fn whole_points<const D: usize, H: Copy + Default + Flat, Dom: Copy + Flat>(
    run: &RankRun,
    ids: &[usize],
    points: &MaterialPoints<D, H, Dom>,
    total: usize,
) -> Result<Vec<f64>, SolverError> {
    let ranks = run.ranks.as_ref();
    let joined = match on_ranks::to_root(ranks, ids, &points.to_flat()) {
        Ok(Some(parts)) => join_flat::<D, H, Dom>(&parts, total),
        other => other.map(|_| Vec::new()),
    };
    ranks::agree(ranks, joined)
}

/// The ranks' parts of [`whole_points`] joined into the whole problem's.
fn join_flat<const D: usize, H: Copy + Default + Flat, Dom: Copy + Flat>(
    parts: &[on_ranks::Part],
    total: usize,
) -> Result<Vec<f64>, SolverError> {
    let points = (parts.iter())
        .map(|p| {
            Ok((
                p.ids.as_slice(),
                MaterialPoints::<D, H, Dom>::from_flat(&p.numbers)?,
            ))
        })
        .collect::<Result<Vec<_>, SolverError>>()?;
    Ok(MaterialPoints::join(&points, total)?.to_flat())
}
