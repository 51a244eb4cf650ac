//! The explicit dynamic material point solver of the MPoint theory notes
//! (`../shared/references/mpoint-explicit-mpm-theory.txt`, Fig. 4 and
//! eqs. 20–46): update-stress-last with a lumped mass matrix, a PIC/FLIP
//! blend or Taylor transfer, a second-order position update, an objective
//! finite-strain stress update and a CFL time step.
//!
//! One [`ExplicitSolver::step`] is the list of stages, each a public
//! function in its own module so another solver can reuse it:
//!
//! 1. time increment, [`ExplicitSolver::time_increment`] (eqs. 45–46);
//! 2. [`p2g::scatter`]: mass, momentum (Taylor term, eq. 29), forces
//!    (eqs. 20–22), in parallel into per-thread [`p2g::GridBuffer`]s;
//! 3. [`grid_update::update`]: the sum of the buffers, velocities (eqs.
//!    30–32), fixities, friction walls and absorbing boundaries;
//! 4. [`g2p`]: velocity (eq. 36), position (eq. 37 corrected), velocity
//!    gradient (eq. 38), optionally the cell-averaged dilatation (eqs.
//!    47–53, [`CellAveraged`]), deformation gradient, volume (eqs. 39–41)
//!    and stress ([`mpm_constitutive::IncrementalLaw`]).
//!
//! Two misprints of the notes are corrected and tested: the bulk modulus
//! of eq. (46) is $E/(3(1-2\nu))$, not $E/(3(1+\nu))$; the position update
//! (37) has $-\tfrac12\Delta t^2$, not $+\Delta t^2$ ([`g2p::move_point`]).
//!
//! Parallelism: the points are split into contiguous ranges, one per
//! thread of the current rayon pool, each scattering into its own buffer
//! (no atomics, no locks); the buffers are summed node by node. The
//! grid-to-point stage is parallel over points. Points that are numbered
//! in spatial order (as the scene generators number them) touch disjoint
//! parts of the grid, so the buffers cost little more than one grid.

pub mod absorbing;
pub mod contact;
pub mod dilatation;
pub mod energy;
pub mod fixities;
pub mod g2p;
mod gather;
pub mod grid;
pub mod grid_update;
pub mod mesh;
pub mod migrate;
mod on_ranks;
pub mod options;
pub mod p2g;
pub mod points;
pub mod tensor;
pub mod touch;
pub mod transfer;
pub mod verification;

use mpm_basis::BasisFunction;
use mpm_constitutive::IncrementalLaw;
use nalgebra::{SMatrix, SVector};

pub use absorbing::Dashpot;
pub use contact::Contact;
pub use dilatation::{CellAveraged, DilatationTreatment};
pub use energy::Energies;
pub use fixities::{FrictionWall, VelocityFixities};
pub use grid_update::{GridState, WallWork};
pub use mesh::ExplicitMesh;
pub use options::{ExplicitOptions, TimeStep};
pub use p2g::GridBuffer;
pub use points::ExplicitPoints;
pub use transfer::{Flip, FlipPic, Pic, Taylor, Transfer, VelocityGradient};

use crate::domain::{DomainUpdater, NoUpdate};
use crate::error::{PointFailure, SolverError};
use crate::locking::NoLocking;
use crate::mesh::NodalMesh;
use crate::par;
use crate::ranks::{self, Reduce};
use on_ranks::OnRanks;

/// Points of one grid-to-point task per thread, times this.
const TASKS_PER_THREAD: usize = 4;

/// The points type of a solver with law `L` and transfer `T` and a basis
/// without domains (standard MPM, B-splines).
pub type PointsFor<const D: usize, L, T> =
    ExplicitPoints<D, <L as IncrementalLaw>::State, <T as Transfer<D>>::PointState>;

/// The points type of a solver with basis `B`, law `L` and transfer `T`:
/// [`PointsFor`] when the basis has no domain.
pub type PointsOf<const D: usize, B, L, T> = ExplicitPoints<
    D,
    <L as IncrementalLaw>::State,
    <T as Transfer<D>>::PointState,
    <B as BasisFunction<D>>::Domain,
>;

/// Wall time spent in each stage since the solver was built, seconds.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ExplicitStageTimes {
    /// Point to grid ([`p2g::scatter`]).
    pub p2g: f64,
    /// Buffer sums and grid update ([`grid_update::update`]).
    pub grid: f64,
    /// Grid to point, stress update included ([`g2p`]).
    pub g2p: f64,
}

/// A stage of an explicit step, as [`ExplicitStageTimes`] reports it.
#[derive(Debug, Clone, Copy)]
enum Stage {
    P2g,
    Grid,
    G2p,
}

/// The wall time of the stages of one step.
#[derive(Debug, Default)]
struct StageClock {
    times: ExplicitStageTimes,
}

impl StageClock {
    /// Runs `f`, adding its wall time to `stage`.
    fn time<R>(&mut self, stage: Stage, f: impl FnOnce() -> R) -> R {
        let start = std::time::Instant::now();
        let out = f();
        let t = &mut self.times;
        *match stage {
            Stage::P2g => &mut t.p2g,
            Stage::Grid => &mut t.grid,
            Stage::G2p => &mut t.g2p,
        } += start.elapsed().as_secs_f64();
        out
    }

    /// Adds the step's times to the solver's.
    fn add_to(&self, total: &mut ExplicitStageTimes) {
        total.p2g += self.times.p2g;
        total.grid += self.times.grid;
        total.g2p += self.times.g2p;
    }
}

/// One point's state as the end of the grid-to-point stage updates it.
#[derive(Debug)]
pub struct PointMut<'a, const D: usize, S, T> {
    /// $F_p$.
    pub f: &'a mut nalgebra::Matrix3<f64>,
    /// $V_p$.
    pub volume: &'a mut f64,
    /// $V^0_p$.
    pub volume0: f64,
    /// $\tau_p$.
    pub tau: &'a mut nalgebra::Matrix3<f64>,
    /// The law's state.
    pub material: &'a mut S,
    /// The transfer's state.
    pub transfer: &'a mut T,
    /// $m_p$.
    pub mass: f64,
    /// The new velocity $v^{n+1}_p$.
    pub velocity: &'a SVector<f64, D>,
}

/// What one step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepInfo {
    /// Steps taken so far (this one included).
    pub step: usize,
    /// The time increment used.
    pub dt: f64,
    /// The time reached.
    pub time: f64,
}

/// The explicit solver, generic over the basis `B`, the incremental law
/// `L`, the velocity transfer `T`, the dilatation treatment `K`
/// ([`NoLocking`] or [`CellAveraged`]) and the domain update `R` of a
/// basis with a domain per point ([`NoUpdate`] unless
/// [`ExplicitSolver::with_domain_update`] names one). After every step
/// each point's domain is updated from its new deformation gradient and
/// the step's increment $\Delta F = I + \Delta t\,\nabla v$ (eq. 39), or
/// from the grid's displacement over the step at its corners or
/// mid-points ([`g2p::grid_displacement`]): GIMP with every rule of
/// Coombs et al. 2020 §6.4 (eqs. 32–39), CPDI2 with
/// [`crate::ConvectedCorners`].
///
/// **Volumes.** A point's volume is $\det F\,V^0_p$ (eq. 40) for every
/// basis, CPDI2 included: the internal force is $V^0_p\tau_p\nabla w$
/// (eq. 20 in Kirchhoff form) and the stored energy $V^0_p\psi(F_p)$, so
/// the work–energy balance holds only with that volume. CPDI2's convected
/// domain has a volume of its own ([`DomainUpdater::volume`], which the
/// implicit solver uses); it follows $\det F\,V^0_p$ to first order in
/// $\Delta t$ per step, and the explicit solver leaves it a property of the
/// domain (measured in `tests/explicit.rs`).
pub struct ExplicitSolver<const D: usize, B, L, T, K = NoLocking, R = NoUpdate>
where
    B: BasisFunction<D>,
{
    basis: B,
    mesh: B::Mesh,
    law: L,
    transfer: T,
    locking: K,
    fixities: VelocityFixities,
    options: ExplicitOptions<D>,
    node_count: usize,
    node_position: Vec<SVector<f64, D>>,
    buffers: Vec<GridBuffer<D>>,
    grid: GridState<D>,
    grad_scratch: Vec<SMatrix<f64, D, D>>,
    cell_scratch: Vec<usize>,
    cell_sums: Vec<(f64, f64)>,
    max_signal: Option<f64>,
    time: f64,
    steps: usize,
    external_work: f64,
    /// What the friction walls and absorbing boundaries took so far (over
    /// every rank).
    wall_work: WallWork,
    /// The accumulated displacement of each absorbing node's spring
    /// layer, one per dashpot of `fixities` (the same on every rank).
    spring_displacement: Vec<SVector<f64, D>>,
    /// The wall nodes the points touch (gap-checked walls only).
    touch: touch::WallTouch<D>,
    stage_times: ExplicitStageTimes,
    fixed_start: Vec<f64>,
    /// The held points' (node, weight) pairs, and where each point's pairs end.
    held_stencils: (Vec<(usize, f64)>, Vec<usize>),
    domain_rule: R,
    /// Positions at the start of the step (the averaged path, bases with
    /// domains only).
    position_scratch: Vec<SVector<f64, D>>,
    /// The other ranks, in a distributed run.
    on_ranks: Option<OnRanks>,
    /// The velocity fields of a run with contact between bodies (`None`:
    /// one field, the stages as without contact).
    contact: Option<Contact<D>>,
}

impl<const D: usize, B, L, T, K> ExplicitSolver<D, B, L, T, K>
where
    B: BasisFunction<D>,
    B::Mesh: ExplicitMesh<D>,
    L: IncrementalLaw,
    T: Transfer<D>,
    K: DilatationTreatment,
{
    /// A solver at time 0.
    ///
    /// # Errors
    /// Invalid options; a fixity on a node or component that does not
    /// exist; a friction wall on a node or axis that does not exist or
    /// with a coefficient that is negative or not finite; a dashpot or
    /// its springs likewise.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        basis: B,
        mesh: B::Mesh,
        law: L,
        transfer: T,
        locking: K,
        fixities: VelocityFixities,
        options: ExplicitOptions<D>,
    ) -> Result<Self, SolverError> {
        options.validate()?;
        let alpha = transfer.alpha();
        if !(0.0..=1.0).contains(&alpha) {
            return Err(SolverError::InvalidInput(format!(
                "the FLIP fraction α = {alpha} must lie in [0, 1]"
            )));
        }
        let node_count = mesh.node_count();
        let mut fixities = fixities;
        fixities.finish();
        if let Some(&(n, c, v)) = fixities
            .entries()
            .iter()
            .find(|(n, c, v)| *n >= node_count || *c >= D || !v.is_finite())
        {
            return Err(SolverError::InvalidInput(format!(
                "velocity fixity ({n}, {c}) = {v}: the mesh has {node_count} nodes of {D} components and velocities must be finite"
            )));
        }
        if let Some(w) = fixities
            .walls()
            .iter()
            .find(|w| w.node >= node_count || w.axis >= D || !(w.mu.is_finite() && w.mu >= 0.0))
        {
            return Err(SolverError::InvalidInput(format!(
                "friction wall at node {} normal to axis {} with μ = {}: the mesh has {node_count} nodes of {D} axes and μ must be finite and non-negative",
                w.node, w.axis, w.mu
            )));
        }
        if let Some(d) = fixities
            .dashpots()
            .iter()
            .find(|d| d.node >= node_count || d.axis >= D || !d.is_valid())
        {
            return Err(SolverError::InvalidInput(format!(
                "absorbing boundary at node {} normal to axis {} with dashpots C_n = {}, C_t = {} and springs K_n = {}, K_t = {}: the mesh has {node_count} nodes of {D} axes and the dashpots and springs must be finite and non-negative",
                d.node, d.axis, d.normal, d.tangential, d.normal_spring, d.tangential_spring
            )));
        }
        let node_position = if T::TAYLOR {
            (0..node_count).map(|i| mesh.node_position(i)).collect()
        } else {
            Vec::new()
        };
        let spring_displacement = vec![SVector::zeros(); fixities.dashpots().len()];
        let touch = touch::WallTouch::new(fixities.walls(), mesh.lattice());
        Ok(Self {
            basis,
            law,
            transfer,
            locking,
            fixities,
            options,
            node_count,
            node_position,
            buffers: Vec::new(),
            grid: GridState::new(node_count),
            grad_scratch: Vec::new(),
            cell_scratch: Vec::new(),
            cell_sums: if K::AVERAGES {
                vec![(0.0, 0.0); mesh.cell_count()]
            } else {
                Vec::new()
            },
            mesh,
            max_signal: None,
            time: 0.0,
            steps: 0,
            external_work: 0.0,
            wall_work: WallWork::default(),
            spring_displacement,
            touch,
            stage_times: ExplicitStageTimes::default(),
            fixed_start: Vec::new(),
            held_stencils: (Vec::new(), Vec::new()),
            domain_rule: NoUpdate,
            position_scratch: Vec::new(),
            on_ranks: None,
            contact: None,
        })
    }
}

impl<const D: usize, B, L, T, K, R> ExplicitSolver<D, B, L, T, K, R>
where
    B: BasisFunction<D>,
    B::Mesh: ExplicitMesh<D> + NodalMesh<D>,
    L: IncrementalLaw,
    T: Transfer<D>,
    K: DilatationTreatment,
    R: DomainUpdater<D, B::Domain>,
{
    /// Whether the basis has a domain per point (`Domain` is not `()`).
    const HAS_DOMAIN: bool = std::mem::size_of::<B::Domain>() > 0;

    /// The same solver with the domain update `rule` (GIMP: e.g.
    /// [`crate::StretchU`] or [`crate::CornerMidpoint`]; CPDI2:
    /// [`crate::ConvectedCorners`]).
    pub fn with_domain_update<R2: DomainUpdater<D, B::Domain>>(
        self,
        rule: R2,
    ) -> ExplicitSolver<D, B, L, T, K, R2> {
        ExplicitSolver {
            basis: self.basis,
            mesh: self.mesh,
            law: self.law,
            transfer: self.transfer,
            locking: self.locking,
            fixities: self.fixities,
            options: self.options,
            node_count: self.node_count,
            node_position: self.node_position,
            buffers: self.buffers,
            grid: self.grid,
            grad_scratch: self.grad_scratch,
            cell_scratch: self.cell_scratch,
            cell_sums: self.cell_sums,
            max_signal: self.max_signal,
            time: self.time,
            steps: self.steps,
            external_work: self.external_work,
            wall_work: self.wall_work,
            spring_displacement: self.spring_displacement,
            touch: self.touch,
            stage_times: self.stage_times,
            fixed_start: self.fixed_start,
            held_stencils: self.held_stencils,
            domain_rule: rule,
            position_scratch: self.position_scratch,
            on_ranks: self.on_ranks,
            contact: self.contact,
        }
    }

    /// The same solver with multi-field contact between bodies
    /// ([`contact`]): `friction[k]` is the Coulomb coefficient of velocity
    /// field `k` (at a node the largest of the fields present applies),
    /// and every point's field is `points.field[p]` (one entry per
    /// point, below `friction.len()`).
    ///
    /// # Errors
    /// As [`Contact::new`]; absorbing boundaries (their springs hold one
    /// state per node, not per field) or a run on several ranks (not yet
    /// supported).
    pub fn with_contact(mut self, friction: Vec<f64>) -> Result<Self, SolverError> {
        if !self.fixities.dashpots().is_empty() {
            return Err(SolverError::InvalidInput(
                "contact between bodies is not supported with absorbing boundaries".into(),
            ));
        }
        if self.on_ranks.is_some() {
            return Err(SolverError::InvalidInput(
                "contact between bodies is not yet supported on several ranks".into(),
            ));
        }
        let cell = self.mesh.cell_volume();
        self.contact = Some(Contact::new(friction, self.node_count, cell)?);
        Ok(self)
    }

    /// The contact between bodies, if the run has one.
    pub fn contact(&self) -> Option<&Contact<D>> {
        self.contact.as_ref()
    }

    /// The domain update.
    pub fn domain_update(&self) -> &R {
        &self.domain_rule
    }

    /// The background mesh.
    pub fn mesh(&self) -> &B::Mesh {
        &self.mesh
    }

    /// The law.
    pub fn law(&self) -> &L {
        &self.law
    }

    /// The transfer.
    pub fn transfer(&self) -> &T {
        &self.transfer
    }

    /// The locking treatment.
    pub fn locking(&self) -> &K {
        &self.locking
    }

    /// The options.
    pub fn options(&self) -> &ExplicitOptions<D> {
        &self.options
    }

    /// The grid state of the last step.
    pub fn grid(&self) -> &GridState<D> {
        &self.grid
    }

    /// Time reached.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Steps taken.
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// Sets the clock of a resumed run: the time, the steps taken and the
    /// work of the applied forces so far (as [`Self::time`],
    /// [`Self::steps`] and [`Self::external_work`] returned them when the
    /// checkpoint was written). The next time increment is recomputed from
    /// the points.
    pub fn resume_at(&mut self, time: f64, steps: usize, external_work: f64) {
        self.time = time;
        self.steps = steps;
        self.external_work = external_work;
        self.max_signal = None;
    }

    /// What the friction walls and absorbing boundaries took so far: the
    /// energy friction dissipated, the energy lost in impacts on the walls
    /// and the energy the dashpots absorbed (summed over the ranks, the
    /// same on each).
    pub fn wall_work(&self) -> WallWork {
        self.wall_work
    }

    /// Sets what the friction walls and dashpots took so far (a resumed run, as
    /// [`Self::wall_work`] returned it when the checkpoint was written).
    pub fn resume_wall_work(&mut self, work: WallWork) {
        self.wall_work = work;
    }

    /// The accumulated displacements of the absorbing boundaries' spring
    /// layer, one per dashpot in the order of
    /// [`VelocityFixities::dashpots`] (zero without springs).
    pub fn spring_displacements(&self) -> &[SVector<f64, D>] {
        &self.spring_displacement
    }

    /// Sets the spring layer's displacements (a resumed run, as
    /// [`Self::spring_displacements`] returned them).
    ///
    /// # Errors
    /// Not one per dashpot, or not finite.
    pub fn resume_spring_displacements(
        &mut self,
        displacements: Vec<SVector<f64, D>>,
    ) -> Result<(), SolverError> {
        if displacements.len() != self.spring_displacement.len()
            || displacements
                .iter()
                .any(|u| !u.iter().all(|x| x.is_finite()))
        {
            return Err(SolverError::InvalidInput(format!(
                "{} spring displacements for {} absorbing nodes; they must be one per node and finite",
                displacements.len(),
                self.spring_displacement.len()
            )));
        }
        self.spring_displacement = displacements;
        Ok(())
    }

    /// Wall time per stage so far.
    pub fn stage_times(&self) -> &ExplicitStageTimes {
        &self.stage_times
    }

    /// Work done on the points by the applied point forces so far.
    pub fn external_work(&self) -> f64 {
        self.external_work
    }

    /// The stable increment of eq. (45) times the CFL factor, or the fixed
    /// increment, for the points' current state.
    pub fn time_increment(&mut self, points: &PointsOf<D, B, L, T>) -> f64 {
        match self.options.time_step {
            TimeStep::Fixed(dt) => dt,
            TimeStep::Cfl { factor } => factor * self.stable_increment(points),
        }
    }

    /// The stable increment of eq. (45), $h/\max_p(c_p + \|v_p\|)$, for the
    /// points' current state (from the last step's grid-to-point stage, or
    /// computed from the points before the first step).
    pub fn stable_increment(&mut self, points: &PointsOf<D, B, L, T>) -> f64 {
        let signal = match self.max_signal {
            Some(s) => s,
            None => *self.max_signal.insert(self.local_signal(points)),
        };
        self.mesh.min_spacing() / signal
    }

    /// The largest signal speed $c_p + \|v_p\|$ of this solver's points.
    fn local_signal(&self, points: &PointsOf<D, B, L, T>) -> f64 {
        (0..points.len())
            .map(|p| {
                let m = self.law.point_p_wave_modulus(&points.material[p]);
                g2p::signal_speed(m, points.mass[p], points.volume[p], &points.velocity[p])
            })
            .fold(0.0, f64::max)
    }

    /// Advances the points by one step of at most `max_dt`.
    ///
    /// # Errors
    /// [`SolverError::CflExceeded`] when a fixed increment exceeds the
    /// stable one of eq. (45) (the state is then left as it was);
    /// [`SolverError::ExplicitPoint`] naming the point, the step and the
    /// time when a point leaves the grid, inverts, or its stress update
    /// fails. The points may then be partly updated; keep a copy (or a
    /// checkpoint) to go back.
    pub fn step(
        &mut self,
        points: &mut PointsOf<D, B, L, T>,
        max_dt: f64,
    ) -> Result<StepInfo, SolverError> {
        let admissible = self
            .admissible_increment(points, max_dt)
            .and_then(|dt| self.check_cells_held(points).map(|()| dt));
        let dt = self.collective(admissible)?;
        let held = self.hold_fixed_points(points);
        self.collective(held)?;
        let mut clock = StageClock::default();
        let scattered = clock
            .time(Stage::P2g, || self.point_to_grid(points))
            .map_err(|e| self.point_failure(&points.id, e));
        self.collective(scattered)?;
        clock.time(Stage::Grid, || self.sum_over_ranks())?;
        let updated = clock
            .time(Stage::Grid, || self.update_grid(points, dt))
            .map_err(|e| self.point_failure(&points.id, e));
        let walls = self.collective(updated)?;
        self.wall_work = self.wall_work.plus(self.sum_wall_work(walls)?);
        self.share_spring_displacements()?;
        clock.time(Stage::Grid, || self.hold_over_ranks(points))?;
        let work = self.point_force_power(points);
        let gathered = clock
            .time(Stage::G2p, || self.gather(points, dt))
            .map_err(|e| self.point_failure(&points.id, e));
        let signal = self.collective(gathered)?;
        let signal = self.reduce(signal, Reduce::Max)?;
        self.move_fixed_points(points, dt);
        clock.add_to(&mut self.stage_times);
        self.external_work += 0.5 * dt * (work + self.point_force_power(points));
        self.max_signal = Some(signal);
        self.steps += 1;
        self.time += dt;
        Ok(StepInfo {
            step: self.steps,
            dt,
            time: self.time,
        })
    }

    /// The step's increment: `max_dt` or the solver's, whichever is
    /// smaller, refused when it is not positive and finite or exceeds the
    /// stable increment of eq. (45); the points' domains checked.
    fn admissible_increment(
        &mut self,
        points: &PointsOf<D, B, L, T>,
        max_dt: f64,
    ) -> Result<f64, SolverError> {
        self.agree_initial_signal(points)?;
        let dt = self.time_increment(points).min(max_dt);
        if !(dt.is_finite() && dt > 0.0) {
            return Err(SolverError::InvalidInput(format!(
                "time increment {dt} (limit {max_dt}) must be positive and finite"
            )));
        }
        // A fixed increment beyond the CFL limit would grow every wave
        // mode until the stresses overflow: stop before the step instead.
        let stable = self.stable_increment(points);
        if dt > stable {
            return Err(SolverError::CflExceeded {
                step: self.steps + 1,
                time: self.time,
                dt,
                limit: stable,
            });
        }
        if points.domain.len() != points.len()
            || points.domain0.len() != points.len()
            || points.id.len() != points.len()
        {
            return Err(SolverError::InvalidInput(format!(
                "{} points but {} domains, {} initial domains and {} ids",
                points.len(),
                points.domain.len(),
                points.domain0.len(),
                points.id.len()
            )));
        }
        if let Some(c) = &self.contact {
            check_fields(c.fields(), points)?;
        }
        Ok(dt)
    }

    /// The error of a point that failed in the step being taken, named by
    /// its global id.
    fn point_failure(&self, id: &[usize], (point, reason): (usize, PointFailure)) -> SolverError {
        SolverError::ExplicitPoint {
            step: self.steps + 1,
            time: self.time,
            point: id.get(point).copied().unwrap_or(point),
            reason,
        }
    }

    /// The grid update (eq. 32) and the fixed points' velocities held on
    /// the grid; returns what the friction walls and dashpots took at the nodes this
    /// rank owns.
    fn update_grid(
        &mut self,
        points: &PointsOf<D, B, L, T>,
        dt: f64,
    ) -> Result<WallWork, (usize, PointFailure)> {
        self.touch
            .mark(&points.position, &points.velocity, &points.volume, dt);
        if let Some(contact) = &mut self.contact {
            return Ok(contact::update_fields(
                contact,
                &mut self.grid,
                dt,
                &self.fixities,
                self.touch.touched(),
            ));
        }
        let owner = self.on_ranks.as_ref().map(OnRanks::owner_of_node);
        let work = grid_update::update(
            &self.buffers,
            &mut self.grid,
            dt,
            &self.fixities,
            &mut self.spring_displacement,
            self.touch.touched(),
            |i| owner.is_none_or(|(me, owners)| owners.get(i) == Some(&me)),
        );
        // On several ranks the stencils are rebuilt even when this rank
        // holds no point now (its held points may have migrated away).
        if !points.fixed_velocity.is_empty() || self.on_ranks.is_some() {
            self.hold_on_grid(points)?;
        }
        Ok(work)
    }

    /// Points with prescribed velocity components move with them.
    fn move_fixed_points(&self, points: &mut PointsOf<D, B, L, T>, dt: f64) {
        for (k, &(p, c, v)) in points.fixed_velocity.iter().enumerate() {
            points.velocity[p][c] = v;
            points.position[p][c] = self.fixed_start[k] + dt * v;
        }
    }

    /// Steps until `end_time`, calling `observer` after every step (it may
    /// stop the run by returning an error).
    ///
    /// # Errors
    /// As [`ExplicitSolver::step`], or the observer's error.
    pub fn run_until(
        &mut self,
        points: &mut PointsOf<D, B, L, T>,
        end_time: f64,
        mut observer: impl FnMut(&Self, &PointsOf<D, B, L, T>, &StepInfo) -> Result<(), SolverError>,
    ) -> Result<usize, SolverError> {
        let start = self.steps;
        // Stop within a relative rounding of the end rather than take a
        // sliver of a step.
        while self.time < end_time * (1.0 - 1e-12) {
            let info = self.step(points, end_time - self.time)?;
            observer(self, points, &info)?;
        }
        Ok(self.steps - start)
    }

    /// Kinetic, stored and gravitational energy of the points, the work
    /// of the applied point forces so far and what the friction walls
    /// and absorbing boundaries took.
    ///
    /// # Errors
    /// A law without a stored energy.
    pub fn energies(&self, points: &PointsOf<D, B, L, T>) -> Result<Energies, SolverError> {
        let local = energy::energies(&self.law, &self.options.gravity, points, self.external_work)
            .map(|e| Energies {
                spring_energy: absorbing::spring_energy(
                    self.fixities.dashpots(),
                    &self.spring_displacement,
                ),
                ..e.with_wall_work(self.wall_work)
            });
        let Some(on) = &self.on_ranks else {
            return local;
        };
        let e = ranks::agree(on.ranks.as_ref(), local)?;
        let mut sums = [e.kinetic, e.strain, e.gravitational, e.external_work];
        on.ranks.all_reduce(&mut sums, Reduce::Sum)?;
        let [kinetic, strain, gravitational, external_work] = sums;
        Ok(Energies {
            kinetic,
            strain,
            gravitational,
            external_work,
            ..e
        })
    }

    /// Checks the material-point fixities, sets the fixed velocity
    /// components (so that the momentum they bring to the grid is the
    /// prescribed one) and keeps the fixed position components of the step's
    /// start.
    fn hold_fixed_points(&mut self, points: &mut PointsOf<D, B, L, T>) -> Result<(), SolverError> {
        self.fixed_start.clear();
        for &(p, c, v) in &points.fixed_velocity {
            if p >= points.len() || c >= D || !v.is_finite() {
                return Err(SolverError::InvalidInput(format!(
                    "material-point fixity ({p}, {c}) = {v}: there are {} points of {D} components and velocities must be finite",
                    points.len()
                )));
            }
            points.velocity[p][c] = v;
            self.fixed_start.push(points.position[p][c]);
        }
        Ok(())
    }

    /// The (node, weight) pairs of every held point of this rank
    /// ([`Self::held_stencils`]), then on one rank their grid side
    /// ([`grid_update::hold_points`]); on several the ranks hold them
    /// together after the step's failures are agreed
    /// ([`Self::hold_over_ranks`]).
    fn hold_on_grid(&mut self, points: &PointsOf<D, B, L, T>) -> Result<(), (usize, PointFailure)> {
        let mut stencil = self.basis.new_stencil();
        // Buffers kept between steps: no allocation per held point.
        let (pairs, ends) = &mut self.held_stencils;
        pairs.clear();
        ends.clear();
        for &(p, _, _) in &points.fixed_velocity {
            p2g::visit_nodes(
                &self.basis,
                &self.mesh,
                &points.position[p],
                &points.domain[p],
                self.node_count,
                &mut stencil,
                |i, w, _| pairs.push((i, w)),
            )
            .map_err(|e| (p, e))?;
            ends.push(pairs.len());
        }
        if self.on_ranks.is_none() {
            grid_update::hold_points(
                &mut self.grid,
                &points.fixed_velocity,
                pairs,
                ends,
                &self.fixities,
            );
        }
        Ok(())
    }

    fn point_force_power(&self, points: &PointsOf<D, B, L, T>) -> f64 {
        points
            .point_force
            .iter()
            .map(|(p, f)| f.dot(&points.velocity[*p]))
            .sum()
    }

    fn point_to_grid(
        &mut self,
        points: &PointsOf<D, B, L, T>,
    ) -> Result<(), (usize, PointFailure)> {
        if self.contact.is_some() {
            return self.point_to_fields(points);
        }
        let threads = rayon::current_num_threads().max(1);
        self.buffers
            .resize_with(threads, || GridBuffer::new(self.node_count));
        let n = points.len();
        let per = n.div_ceil(threads).max(1);
        let view = p2g::PointsView {
            position: &points.position,
            velocity: &points.velocity,
            mass: &points.mass,
            volume0: &points.volume0,
            tau: &points.tau,
            transfer: &points.transfer,
            domain: &points.domain,
        };
        let (basis, mesh, gravity, node_position) = (
            &self.basis,
            &self.mesh,
            &self.options.gravity,
            &self.node_position,
        );
        par::reduce(
            &mut self.buffers[..],
            1,
            &|first, buffers| {
                let mut stencil = basis.new_stencil();
                let mut result = Ok(0.0);
                for (j, buffer) in buffers.iter_mut().enumerate() {
                    let k = first + j;
                    buffer.clear();
                    let range = (k * per).min(n)..((k + 1) * per).min(n);
                    let scattered = p2g::scatter::<D, B, T>(
                        basis,
                        mesh,
                        &view,
                        node_position,
                        gravity,
                        range,
                        buffer,
                        &mut stencil,
                    );
                    result = gather::worse(result, scattered.map(|()| 0.0));
                }
                result
            },
            gather::worse,
        )?;
        if !points.point_force.is_empty() {
            let mut stencil = self.basis.new_stencil();
            p2g::scatter_point_forces(
                &self.basis,
                &self.mesh,
                &points.position,
                &points.domain,
                &points.point_force,
                &mut self.buffers[0],
                &mut stencil,
            )?;
        }
        Ok(())
    }

    /// Point to grid with contact: [`contact::scatter_fields`] over the
    /// threads' field buffers, then the applied point forces.
    fn point_to_fields(
        &mut self,
        points: &PointsOf<D, B, L, T>,
    ) -> Result<(), (usize, PointFailure)> {
        let Some(contact) = &mut self.contact else {
            return Ok(());
        };
        let threads = rayon::current_num_threads().max(1);
        let fields = contact.fields();
        contact.buffers.resize_with(threads, || {
            contact::FieldBuffer::new(self.node_count, fields)
        });
        let n = points.len();
        let per = n.div_ceil(threads).max(1);
        let view = p2g::PointsView {
            position: &points.position,
            velocity: &points.velocity,
            mass: &points.mass,
            volume0: &points.volume0,
            tau: &points.tau,
            transfer: &points.transfer,
            domain: &points.domain,
        };
        let (basis, mesh, gravity, node_position) = (
            &self.basis,
            &self.mesh,
            &self.options.gravity,
            &self.node_position,
        );
        let field = &points.field[..];
        par::reduce(
            &mut contact.buffers[..],
            1,
            &|first, buffers| {
                let mut stencil = basis.new_stencil();
                let mut result = Ok(0.0);
                for (j, buffer) in buffers.iter_mut().enumerate() {
                    let k = first + j;
                    buffer.clear();
                    let range = (k * per).min(n)..((k + 1) * per).min(n);
                    let scattered = contact::scatter_fields::<D, B, T>(
                        basis,
                        mesh,
                        &view,
                        (field, &points.volume),
                        node_position,
                        gravity,
                        range,
                        buffer,
                        &mut stencil,
                    );
                    result = gather::worse(result, scattered.map(|()| 0.0));
                }
                result
            },
            gather::worse,
        )?;
        if !points.point_force.is_empty() {
            let mut stencil = self.basis.new_stencil();
            contact::scatter_field_forces(
                &self.basis,
                &self.mesh,
                &points.position,
                &points.domain,
                field,
                &points.point_force,
                &mut contact.buffers[0],
                &mut stencil,
            )?;
        }
        Ok(())
    }
}

/// The points of a run with `fields` velocity fields: one field each,
/// below `fields`, and no material-point fixity (held on one field's grid
/// only, it would not hold).
fn check_fields<const D: usize, S, T, Dom>(
    fields: usize,
    points: &ExplicitPoints<D, S, T, Dom>,
) -> Result<(), SolverError> {
    if points.field.len() != points.len() {
        return Err(SolverError::InvalidInput(format!(
            "contact between bodies needs a velocity field per point: {} points, {} fields given",
            points.len(),
            points.field.len()
        )));
    }
    if let Some(p) = points.field.iter().position(|&k| usize::from(k) >= fields) {
        return Err(SolverError::InvalidInput(format!(
            "point {p} is in velocity field {}; the contact has {fields}",
            points.field[p]
        )));
    }
    if !points.fixed_velocity.is_empty() {
        return Err(SolverError::InvalidInput(
            "contact between bodies is not supported with material-point fixities".into(),
        ));
    }
    Ok(())
}
