//! An explicit scene on several ranks, the part compiled once per
//! dimension: the cells of the grid dealt over the ranks
//! ([`RankRun::rank_of_cell`]), each rank holding the points of its cells;
//! after every step the points that crossed into another rank's cells
//! migrate, and every [`Balance::every`] steps the points per rank are
//! counted and, past the threshold, the cells dealt anew. Rank 0 alone
//! observes: the points are gathered onto it, by global id, at every
//! output; what it decides (an output error, a stop) is agreed.
//!
//! Not yet on several ranks (refused): checkpoints and resumption, point
//! forces and point fixities (they name points by index, which migration
//! changes), the cell-averaged dilatation.

use std::sync::Arc;

use mpm_mesh::RegularGrid;
use mpm_scene::build::ExplicitSetup;
use mpm_solver::SolverError;
use mpm_solver::ranks::{self, Decomposition, Ranks, Reduce};

use crate::explicit::Stepper;
use crate::on_ranks::{RankRun, gather, imbalance, keep_names};
use crate::run::{RunControl, Snapshot};

/// A new deal of the cells during a run on several ranks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rebalanced {
    /// The step after which the cells were dealt anew.
    pub step: usize,
    /// The imbalance before (the most loaded rank's points over the mean).
    pub before: f64,
    /// The imbalance of the new deal.
    pub after: f64,
    /// The points that changed rank.
    pub moved: usize,
}

/// What a run on several ranks does not do yet.
///
/// # Errors
/// [`SolverError::InvalidInput`] naming it.
pub(crate) fn supported<const D: usize>(
    setup: &ExplicitSetup<D>,
    control: &RunControl,
) -> Result<(), SolverError> {
    let refuse = |what: &str| {
        Err(SolverError::InvalidInput(format!(
            "{what} of an explicit scene on several ranks: not yet (issue 42); run it on one process"
        )))
    };
    if control.checkpoint || control.resume.is_some() {
        return refuse("checkpoints and resumption");
    }
    let point_loads = !setup.point_forces.is_empty() || !setup.timed_forces.is_empty();
    if point_loads || !setup.point_fixities.is_empty() {
        return refuse("point loads and point fixities");
    }
    Ok(())
}

/// A run's spread over the ranks: the deal, the grid's connectivity for
/// new deals, and the basis's reach.
pub(crate) struct Spread<'a> {
    run: &'a RankRun,
    connectivity: Vec<usize>,
    nodes_per_cell: usize,
    nodes: usize,
    reach: usize,
    rank_of_cell: Vec<usize>,
}

impl<'a> Spread<'a> {
    /// The spread of `run` over `grid`, for a basis whose points reach
    /// `reach` rings of cells beyond their own.
    ///
    /// # Errors
    /// A deal of another number of cells than the grid's.
    pub(crate) fn new<const D: usize>(
        run: &'a RankRun,
        grid: &RegularGrid<D>,
        reach: usize,
    ) -> Result<Self, SolverError> {
        let cells = grid.cell_count();
        if run.rank_of_cell.len() != cells {
            return Err(SolverError::InvalidInput(format!(
                "the deal names ranks for {} cells, the grid has {cells}",
                run.rank_of_cell.len()
            )));
        }
        let invalid = |e: &dyn std::fmt::Display| SolverError::InvalidInput(e.to_string());
        let mut connectivity = Vec::with_capacity(cells << D);
        for c in 0..cells {
            let cell = grid.cell_index(c).map_err(|e| invalid(&e))?;
            connectivity.extend(grid.cell_nodes(cell).map_err(|e| invalid(&e))?);
        }
        Ok(Self {
            run,
            connectivity,
            nodes_per_cell: 1 << D,
            nodes: grid.node_count(),
            reach,
            rank_of_cell: run.rank_of_cell.clone(),
        })
    }

    /// The communication, for the solver.
    pub(crate) fn ranks(&self) -> Box<dyn Ranks> {
        Box::new(Arc::clone(&self.run.ranks))
    }

    /// The problem's indices of this rank's points.
    ///
    /// # Errors
    /// As [`RankRun::own_points`].
    pub(crate) fn own_points(&self, points: usize) -> Result<Vec<usize>, SolverError> {
        self.run.own_points(points)
    }

    /// The decomposition of the first deal.
    ///
    /// # Errors
    /// As [`Decomposition::from_cells`].
    pub(crate) fn initial_layout(&self) -> Result<Decomposition, SolverError> {
        self.layout(self.rank_of_cell.clone())
    }

    fn layout(&self, rank_of_cell: Vec<usize>) -> Result<Decomposition, SolverError> {
        Decomposition::from_cells(
            self.run.ranks.rank(),
            rank_of_cell,
            &self.connectivity,
            self.nodes_per_cell,
            self.nodes,
            self.reach,
        )
    }

    /// After step `step`: the migration, then, every
    /// [`crate::on_ranks::Balance::every`] steps, the imbalance measured
    /// and, past the threshold, a new deal when it is better. Collective.
    ///
    /// # Errors
    /// The migration's, the repartition's and the transport's, agreed.
    pub(crate) fn after_step<const D: usize>(
        &mut self,
        run: &mut dyn Stepper<D>,
        step: usize,
    ) -> Result<Option<Rebalanced>, SolverError> {
        run.migrate()?;
        let Some(balance) = &self.run.balance else {
            return Ok(None);
        };
        if balance.every == 0 || !step.is_multiple_of(balance.every) {
            return Ok(None);
        }
        let size = self.run.ranks.size();
        let loads = run.cell_loads()?;
        let before = imbalance(&loads, &self.rank_of_cell, size);
        if before <= balance.threshold {
            return Ok(None);
        }
        let cells = ranks::agree(self.run.ranks.as_ref(), (balance.repartition)(&loads))?;
        let cells = keep_names(&self.rank_of_cell, &cells, &loads, size);
        let after = imbalance(&loads, &cells, size);
        if after >= before {
            return Ok(None);
        }
        let (sent, _) = run.rebalance(self.layout(cells.clone())?)?;
        self.rank_of_cell = cells;
        let mut moved = [sent as f64];
        self.run.ranks.all_reduce(&mut moved, Reduce::Sum)?;
        Ok(Some(Rebalanced {
            step,
            before,
            after,
            moved: moved[0] as usize,
        }))
    }

    /// Runs `observe` on rank 0 and agrees on its verdict. Collective.
    ///
    /// # Errors
    /// The observer's, on every rank.
    pub(crate) fn on_root(
        &self,
        observe: impl FnOnce() -> Result<(), SolverError>,
    ) -> Result<(), SolverError> {
        let seen = if self.run.is_root() {
            observe()
        } else {
            Ok(())
        };
        ranks::agree(self.run.ranks.as_ref(), seen)
    }

    /// The snapshot of all `total` points on rank 0 from this rank's
    /// `local` of its points `ids`; `None` on the others. Collective.
    ///
    /// # Errors
    /// As [`gather`].
    pub(crate) fn gather(
        &self,
        ids: &[usize],
        local: &Snapshot,
        total: usize,
    ) -> Result<Option<Snapshot>, SolverError> {
        gather(self.run.ranks.as_ref(), ids, local, total)
    }

    /// `observe` shown the gathered snapshot on rank 0, its verdict
    /// agreed. Collective.
    ///
    /// # Errors
    /// The gather's, or the observer's on every rank.
    pub(crate) fn observe_gathered(
        &self,
        ids: &[usize],
        local: &Snapshot,
        total: usize,
        observe: impl FnOnce(&Snapshot) -> Result<(), SolverError>,
    ) -> Result<(), SolverError> {
        let whole = self.gather(ids, local, total)?;
        ranks::agree(
            self.run.ranks.as_ref(),
            whole.as_ref().map_or(Ok(()), observe),
        )
    }
}
