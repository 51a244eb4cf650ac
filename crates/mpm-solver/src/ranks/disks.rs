//! The reference problem of distributed explicit runs, shared by the
//! thread-rank tests (`tests/ranks.rs`) and the MPI tests of
//! `mpm-distributed`: Sulsky's two elastic disks approaching along the
//! diagonal of a unit square, colliding and separating, so every point
//! crosses between ranks. Quadratic B-splines (reach 2), FLIP, neo-Hookean,
//! CFL factor 0.5; every point's global id is its index in the one-rank
//! run. Every set-up or solver failure is returned, never a panic.

use mpm_basis::QuadraticBSpline;
use mpm_constitutive::NeoHookean;
use mpm_mesh::RegularGrid;
use nalgebra::Vector2;

use super::{Decomposition, Ranks};
use crate::error::SolverError;
use crate::explicit::verification::block;
use crate::explicit::{
    ExplicitOptions, ExplicitSolver, Flip, PointsFor, TimeStep, VelocityFixities,
};
use crate::locking::NoLocking;

type Points = PointsFor<2, NeoHookean, Flip>;

/// How the cells are dealt to the ranks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Deal {
    /// Stripes of columns of cells.
    Stripes,
    /// 3×3-cell blocks dealt round the ranks, so ranks touch at many
    /// places and points change rank often.
    Scattered,
}

/// The problem: `cells` per side, each disk approaching at `speed` (m/s)
/// along the diagonal, run until `end` (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disks {
    /// Cells per side of the unit square.
    pub cells: usize,
    /// Speed of each disk along each axis.
    pub speed: f64,
    /// End time.
    pub end: f64,
}

/// Deals the cells to the ranks anew from the points per cell.
pub type Repartition<'a> = dyn Fn(&[f64]) -> Result<Vec<usize>, SolverError> + 'a;

/// What a run ends with on one rank.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// (global id, position, velocity) of the rank's points.
    pub points: Vec<(usize, Vector2<f64>, Vector2<f64>)>,
    /// Kinetic and strain energy of all points (reduced over the ranks).
    pub energies: (f64, f64),
    /// Steps taken.
    pub steps: usize,
    /// Points this rank sent to others after steps.
    pub migrated: usize,
    /// Points this rank sent to others when the cells were dealt anew.
    pub rebalanced: usize,
}

impl Disks {
    /// The colliding-disks run of `tests/explicit.rs` on a 16-cell grid:
    /// 0.1 m/s each, until both have collided and separated (4 s).
    pub const STANDARD: Disks = Disks {
        cells: 16,
        speed: 0.1,
        end: 4.0,
    };

    /// The background grid: the unit square and one cell of padding.
    ///
    /// # Errors
    /// An invalid cell count.
    pub fn grid(&self) -> Result<RegularGrid<2>, SolverError> {
        let h = 1.0 / self.cells as f64;
        Ok(RegularGrid::new(
            Vector2::new(-h, -h),
            Vector2::new(h, h),
            [self.cells + 2, self.cells + 2],
        )?)
    }

    fn points(&self) -> Result<Points, SolverError> {
        let (all, vol) = block(
            Vector2::zeros(),
            Vector2::new(1.0, 1.0),
            1.0 / self.cells as f64,
            2,
        );
        let centres = [Vector2::new(0.25, 0.25), Vector2::new(0.75, 0.75)];
        let keep: Vec<usize> = (0..all.len())
            .filter(|&p| centres.iter().any(|c| (all[p] - c).norm() < 0.2))
            .collect();
        let x: Vec<_> = keep.iter().map(|&p| all[p]).collect();
        let v: Vec<_> = keep.iter().map(|&p| vol[p]).collect();
        let mut points = Points::new(x, v, 1000.0)?;
        let speed = self.speed;
        points.set_velocity(|x| {
            let s = if x.x + x.y < 1.0 { speed } else { -speed };
            Vector2::new(s, s)
        });
        Ok(points)
    }

    fn solver(&self) -> Result<ExplicitSolver<2, QuadraticBSpline, NeoHookean, Flip>, SolverError> {
        let options = ExplicitOptions {
            time_step: TimeStep::Cfl { factor: 0.5 },
            ..Default::default()
        };
        ExplicitSolver::new(
            QuadraticBSpline,
            self.grid()?,
            NeoHookean::new(1000.0, 0.3)?,
            Flip,
            NoLocking,
            VelocityFixities::new(),
            options,
        )
    }

    /// The run on one solver holding every point.
    ///
    /// # Errors
    /// The set-up's or the solver's.
    pub fn single(&self) -> Result<Outcome, SolverError> {
        let mut points = self.points()?;
        let mut s = self.solver()?;
        s.run_until(&mut points, self.end, |_, _, _| Ok(()))?;
        let e = s.energies(&points)?;
        Ok(Outcome {
            points: listing(&points),
            energies: (e.kinetic, e.strain),
            steps: s.steps(),
            migrated: 0,
            rebalanced: 0,
        })
    }

    /// The grid's connectivity (four nodes per cell) and the cell of
    /// every point at the start, for a partitioner.
    ///
    /// # Errors
    /// The set-up's.
    pub fn cells(&self) -> Result<(Vec<usize>, Vec<usize>), SolverError> {
        let grid = self.grid()?;
        let points = self.points()?;
        let of_points = (0..points.len())
            .map(|p| cell_of(&grid, &points.position[p]))
            .collect::<Result<_, _>>()?;
        Ok((connectivity(&grid)?, of_points))
    }

    /// This rank's part of the run on `ranks`, the cells dealt by `deal`:
    /// step, then migrate, until the end.
    ///
    /// # Errors
    /// The set-up's or the solver's, decided over the ranks.
    pub fn on_ranks(&self, ranks: Box<dyn Ranks>, deal: Deal) -> Result<Outcome, SolverError> {
        let cells = dealt(&self.grid()?, ranks.size(), deal)?;
        self.on_cells(ranks, cells)
    }

    /// As [`Self::on_ranks`] with the rank of every cell given (e.g. by
    /// METIS).
    ///
    /// # Errors
    /// The set-up's or the solver's, decided over the ranks.
    pub fn on_cells(
        &self,
        ranks: Box<dyn Ranks>,
        cells: Vec<usize>,
    ) -> Result<Outcome, SolverError> {
        self.rebalanced(ranks, cells, usize::MAX, &|_| unreachable_repartition())
    }

    /// As [`Self::on_cells`], the cells dealt anew every `every` steps by
    /// `repartition` from the points per cell
    /// ([`crate::explicit::ExplicitSolver::cell_loads`]; it must give every
    /// rank the same answer) and the points moved there
    /// ([`crate::explicit::ExplicitSolver::rebalance`]). The points moved
    /// by those count in [`Outcome::rebalanced`].
    ///
    /// # Errors
    /// The set-up's, the partitioner's or the solver's, decided over the
    /// ranks.
    pub fn rebalanced(
        &self,
        ranks: Box<dyn Ranks>,
        cells: Vec<usize>,
        every: usize,
        repartition: &Repartition<'_>,
    ) -> Result<Outcome, SolverError> {
        let grid = self.grid()?;
        let rank = ranks.rank();
        let mut points = share(&self.points()?, &grid, &cells, rank)?;
        let connectivity = connectivity(&grid)?;
        let decompose =
            |cells| Decomposition::from_cells(rank, cells, &connectivity, 4, grid.node_count(), 2);
        let mut s = self.solver()?.on_ranks(ranks, decompose(cells)?)?;
        let (mut migrated, mut rebalanced) = (0, 0);
        while s.time() < self.end * (1.0 - 1e-12) {
            s.step(&mut points, self.end - s.time())?;
            migrated += s.migrate(&mut points)?.0;
            if s.steps() % every == 0 {
                let cells = repartition(&s.cell_loads(&points)?)?;
                rebalanced += s.rebalance(&mut points, decompose(cells)?)?.0;
            }
        }
        let e = s.energies(&points)?;
        Ok(Outcome {
            points: listing(&points),
            energies: (e.kinetic, e.strain),
            steps: s.steps(),
            migrated,
            rebalanced,
        })
    }
}

/// The repartition of a run that never repartitions.
fn unreachable_repartition() -> Result<Vec<usize>, SolverError> {
    Err(SolverError::InvalidInput(
        "no repartition was asked for".into(),
    ))
}

/// The largest distance in position and in velocity between the points
/// of `parts` (one rank's each) and those of `whole`, matched by id; an
/// error when the ids differ (a point lost or held twice).
///
/// # Errors
/// As above.
pub fn largest_difference(whole: &Outcome, parts: &[Outcome]) -> Result<(f64, f64), SolverError> {
    let mut all: Vec<_> = parts
        .iter()
        .flat_map(|o| o.points.iter().copied())
        .collect();
    let mut reference = whole.points.clone();
    all.sort_by_key(|p| p.0);
    reference.sort_by_key(|p| p.0);
    let ids = |v: &[(usize, Vector2<f64>, Vector2<f64>)]| v.iter().map(|p| p.0).collect::<Vec<_>>();
    if ids(&all) != ids(&reference) {
        return Err(SolverError::InvalidInput(format!(
            "the ranks hold {} points, the single run {}, or their ids differ",
            all.len(),
            reference.len()
        )));
    }
    Ok(all
        .iter()
        .zip(&reference)
        .fold((0.0, 0.0), |(dx, dv), (a, b)| {
            (dx.max((a.1 - b.1).norm()), dv.max((a.2 - b.2).norm()))
        }))
}

fn listing(points: &Points) -> Vec<(usize, Vector2<f64>, Vector2<f64>)> {
    (0..points.len())
        .map(|p| (points.id[p], points.position[p], points.velocity[p]))
        .collect()
}

fn cell_of(grid: &RegularGrid<2>, x: &Vector2<f64>) -> Result<usize, SolverError> {
    Ok(grid.cell_id(grid.cell_containing(x)?)?)
}

/// The points of `points` in the cells of `rank` (global ids kept).
fn share(
    points: &Points,
    grid: &RegularGrid<2>,
    rank_of_cell: &[usize],
    rank: usize,
) -> Result<Points, SolverError> {
    let mut mine = Vec::new();
    for p in 0..points.len() {
        if rank_of_cell[cell_of(grid, &points.position[p])?] == rank {
            mine.push(p);
        }
    }
    let mut out = Points::new(
        mine.iter().map(|&p| points.position[p]).collect(),
        mine.iter().map(|&p| points.volume[p]).collect(),
        1000.0,
    )?;
    out.velocity = mine.iter().map(|&p| points.velocity[p]).collect();
    out.id = mine;
    Ok(out)
}

fn connectivity(grid: &RegularGrid<2>) -> Result<Vec<usize>, SolverError> {
    let mut out = Vec::with_capacity(4 * grid.cell_count());
    for c in 0..grid.cell_count() {
        out.extend(grid.cell_nodes(grid.cell_index(c)?)?);
    }
    Ok(out)
}

fn dealt(grid: &RegularGrid<2>, ranks: usize, deal: Deal) -> Result<Vec<usize>, SolverError> {
    let [nx, _] = grid.cells_per_axis();
    (0..grid.cell_count())
        .map(|c| {
            let [i, j] = grid.cell_index(c)?;
            Ok(match deal {
                Deal::Scattered => (i / 3 + 2 * (j / 3)) % ranks,
                Deal::Stripes => (i * ranks / nx).min(ranks - 1),
            })
        })
        .collect()
}
