//! The reference problem of distributed implicit runs, shared by the
//! thread-rank tests (`tests/implicit_ranks.rs`) and the MPI tests of
//! `mpm-distributed`: a von Mises block (E = 10 kPa, ν = 0.3, σ_y =
//! 20 Pa, unit density, g = 10 m/s²) of 3 m × 1 m on a fixed base
//! between rollers, under its weight and a strip load of 40 Pa over the
//! left third of its top (about 0.7 of the Prandtl pressure
//! (2 + π)σ_y/√3), in 10 load steps of the updated Lagrangian formulation
//! on linear MPM (cells of 0.25 m, 2×2 points per cell, 192 points).
//! About a quarter of the points end on the yield surface, and the load is
//! not symmetric about any cut between ranks. Every point's global id is
//! its index in the one-rank run. Every set-up or solver failure is
//! returned, never a panic.

use mpm_basis::LinearMpm;
use mpm_constitutive::VonMises;
use mpm_mesh::RegularGrid;
use nalgebra::{Matrix3, Vector2};

use super::Ranks;
use crate::boundary::NodalConstraints;
use crate::domain::NoUpdate;
use crate::error::SolverError;
use crate::formulation::UpdatedLagrangian;
use crate::implicit::{ImplicitSolver, NewtonOptions};
use crate::linear::LinearSolver;
use crate::locking::{FBar, LockingTreatment, NoLocking};
use crate::parts::Parts;
use crate::points::MaterialPoints;
use crate::stepping::LoadStepping;

/// Cell size (m).
pub const H: f64 = 0.25;
/// Cells of the grid (the body fills the lower 4 rows).
pub const CELLS: [usize; 2] = [12, 6];
/// Points per direction in the body (2 per cell over 12 × 4 cells).
pub const POINTS: [usize; 2] = [24, 8];
/// Load steps.
pub const STEPS: usize = 10;
/// The yield stress (Pa).
pub const YIELD: f64 = 20.0;

/// The locking treatment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Treatment {
    /// None.
    Standard,
    /// F-bar over patches of one cell.
    FBar,
}

/// How the points are dealt to the ranks, and what goes wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Deal {
    /// Stripes of cell columns.
    Cells,
    /// As `Cells`, with one point of rank 1 (its first) outside the grid.
    Stray,
    /// Point columns in turn: every cell's points on two ranks.
    SplitCells,
}

/// What one rank (or the single solver) ends with.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// Global id of each of its points.
    pub ids: Vec<usize>,
    /// Their final positions.
    pub position: Vec<Vector2<f64>>,
    /// Their final Cauchy stresses.
    pub sigma: Vec<Matrix3<f64>>,
    /// Per step, the normalised residuals.
    pub residuals: Vec<Vec<f64>>,
    /// Per step, the total reaction.
    pub reactions: Vec<Vector2<f64>>,
}

/// The initial position of the point with global id `id`.
pub fn initial_position(id: usize) -> Vector2<f64> {
    let (i, j) = (id % POINTS[0], id / POINTS[0]);
    Vector2::new((i as f64 + 0.5) * H / 2.0, (j as f64 + 0.5) * H / 2.0)
}

/// The problem on one solver.
///
/// # Errors
/// The solver's.
pub fn single(treatment: Treatment) -> Result<Outcome, SolverError> {
    run(treatment, None, Deal::Cells, None)
}

/// This rank's part of the problem on `ranks`, the points dealt as `deal`
/// says.
///
/// # Errors
/// The solver's, decided over the ranks.
pub fn on_ranks(
    ranks: Box<dyn Ranks>,
    treatment: Treatment,
    deal: Deal,
) -> Result<Outcome, SolverError> {
    run(treatment, Some(ranks), deal, None)
}

/// [`on_ranks`] with the linear solver `linear` (e.g. one over all
/// ranks, [`LinearSolver::solves_over_ranks`]) instead of the default
/// options'.
///
/// # Errors
/// The solver's, decided over the ranks.
pub fn on_ranks_with(
    ranks: Box<dyn Ranks>,
    treatment: Treatment,
    deal: Deal,
    linear: Box<dyn LinearSolver>,
) -> Result<Outcome, SolverError> {
    run(treatment, Some(ranks), deal, Some(linear))
}

fn run(
    treatment: Treatment,
    ranks: Option<Box<dyn Ranks>>,
    deal: Deal,
    linear: Option<Box<dyn LinearSolver>>,
) -> Result<Outcome, SolverError> {
    match treatment {
        Treatment::Standard => solve(NoLocking, ranks, deal, linear),
        Treatment::FBar => solve(FBar::default(), ranks, deal, linear),
    }
}

/// This rank's points: their global ids and positions.
fn dealt(rank: usize, size: usize, deal: Deal) -> (Vec<usize>, Vec<Vector2<f64>>) {
    let mine = |i: usize| match deal {
        Deal::SplitCells => i % size == rank,
        Deal::Cells | Deal::Stray => (i / 2) * size / CELLS[0] == rank,
    };
    let ids: Vec<usize> = (0..POINTS[0] * POINTS[1])
        .filter(|&id| mine(id % POINTS[0]))
        .collect();
    let mut position: Vec<_> = ids.iter().map(|&id| initial_position(id)).collect();
    if deal == Deal::Stray
        && rank == 1
        && let Some(x) = position.first_mut()
    {
        *x = Vector2::new(-1.0, 0.1);
    }
    (ids, position)
}

/// The fixed base and the rollers on both sides.
fn supports(grid: &RegularGrid<2>) -> Result<NodalConstraints<2>, SolverError> {
    let mut c = NodalConstraints::<2>::new(grid.node_count());
    let width = CELLS[0] as f64 * H;
    for node in 0..grid.node_count() {
        let x = grid
            .node_position(node)
            .map_err(|e| SolverError::InvalidInput(e.to_string()))?;
        if x[1] <= 1e-12 {
            c.fix([node], 0);
            c.fix([node], 1);
        }
        if x[0] <= 1e-12 || x[0] >= width - 1e-12 {
            c.fix([node], 0);
        }
    }
    Ok(c)
}

fn solve<K>(
    locking: K,
    ranks: Option<Box<dyn Ranks>>,
    deal: Deal,
    linear: Option<Box<dyn LinearSolver>>,
) -> Result<Outcome, SolverError>
where
    K: LockingTreatment<2, RegularGrid<2>>,
{
    let invalid = |e: &dyn std::fmt::Display| SolverError::InvalidInput(e.to_string());
    let grid = RegularGrid::new(Vector2::zeros(), Vector2::from_element(H), CELLS)
        .map_err(|e| invalid(&e))?;
    let (rank, size) = ranks.as_ref().map_or((0, 1), |r| (r.rank(), r.size()));
    let (ids, position) = dealt(rank, size, deal);
    let n = position.len();
    let mut points: MaterialPoints<2, _, ()> =
        MaterialPoints::new(position, vec![(H / 2.0).powi(2); n], 1.0, vec![(); n])?;
    points.set_gravity(Vector2::new(0.0, -10.0));
    for (p, &id) in ids.iter().enumerate() {
        let (i, j) = (id % POINTS[0], id / POINTS[0]);
        if j == POINTS[1] - 1 && i < POINTS[0] / 3 {
            points
                .point_force
                .push((p, Vector2::new(0.0, -40.0 * H / 2.0)));
        }
    }
    let law = VonMises::new(1e4, 0.3, YIELD, 0.0).map_err(|e| invalid(&e))?;
    let constraints = supports(&grid)?;
    let mut solver: ImplicitSolver<2, Parts<LinearMpm, UpdatedLagrangian, _, K, NoUpdate, _>> =
        ImplicitSolver::new(
            LinearMpm,
            grid,
            law,
            locking,
            NoUpdate,
            constraints,
            NewtonOptions::default(),
        );
    if let Some(r) = ranks {
        solver.on_ranks(r);
        solver.name_points(ids.clone());
    }
    if let Some(linear) = linear {
        solver.set_linear_solver(linear);
    }
    let (mut residuals, mut reactions) = (Vec::new(), Vec::new());
    solver.run(
        &mut points,
        &LoadStepping::uniform(STEPS),
        |_, report, _| {
            residuals.push(report.residuals.clone());
            reactions.push(report.reaction);
            Ok(())
        },
    )?;
    Ok(Outcome {
        ids,
        position: points.position.clone(),
        sigma: points.sigma.clone(),
        residuals,
        reactions,
    })
}

/// Largest differences of a rank's outcome from the single solver's:
/// positions relative to the largest displacement, stresses relative to
/// the largest stress, reactions relative to the largest reaction.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Differences {
    /// Max |Δx| / max |u|.
    pub displacement: f64,
    /// Max |Δσ| / max |σ|.
    pub stress: f64,
    /// Max |ΔR| / max |R|.
    pub reaction: f64,
}

/// The differences of `mine` (one rank's points) from `single`.
pub fn differences(single: &Outcome, mine: &Outcome) -> Differences {
    let u_max = single
        .position
        .iter()
        .enumerate()
        .map(|(id, x)| (x - initial_position(id)).norm())
        .fold(0.0, f64::max);
    let s_max = single.sigma.iter().map(Matrix3::norm).fold(0.0, f64::max);
    let r_max = single
        .reactions
        .iter()
        .map(|r| r.norm())
        .fold(0.0, f64::max);
    let mut d = Differences::default();
    for (k, &id) in mine.ids.iter().enumerate() {
        d.displacement = d
            .displacement
            .max((mine.position[k] - single.position[id]).norm() / u_max);
        d.stress = d
            .stress
            .max((mine.sigma[k] - single.sigma[id]).norm() / s_max);
    }
    d.reaction = mine
        .reactions
        .iter()
        .zip(&single.reactions)
        .map(|(a, b)| (a - b).norm() / r_max)
        .fold(0.0, f64::max);
    d
}

/// The number of the single solver's points at the yield surface
/// (von Mises stress within 1 % of σ_y).
pub fn yielded(single: &Outcome) -> usize {
    single
        .sigma
        .iter()
        .filter(|s| {
            let dev = *s - Matrix3::identity() * (s.trace() / 3.0);
            (1.5 * dev.norm_squared()).sqrt() > 0.99 * YIELD
        })
        .count()
}
