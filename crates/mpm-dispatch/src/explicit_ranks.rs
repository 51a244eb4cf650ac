//! An explicit scene on several ranks, the part compiled once per
//! dimension: the cells of the grid dealt over the ranks
//! ([`RankRun::rank_of_cell`]), each rank holding the points of its cells;
//! after every step the points that crossed into another rank's cells
//! migrate, and every [`Balance::every`] steps the points per rank are
//! counted and, past the threshold, the cells dealt anew. Rank 0 alone
//! observes: the points are gathered onto it, by global id, at every
//! output; what it decides (an output error, a stop) is agreed.
//!
//! A checkpoint holds every point in the order of its id (the file one
//! process writes) and how the ranks held them: the deal of the cells,
//! each point's rank and place there, each rank's work of the point
//! forces. Resumed on as many ranks, each takes its points back in the
//! same order, so the run goes on bit for bit; on another number (or from
//! a one-process checkpoint), the cells are dealt from the points' cells.
//!
//! Point forces travel with their points (`mpm_solver`'s migration);
//! with loads on a curve the force list is made anew before every step,
//! each force placed on its point by id. The cell-averaged dilatation
//! needs no communication: the points follow their cells. Material-point
//! fixities are held by every rank together (`mpm_solver`'s
//! `hold_over_ranks`).

use std::sync::Arc;

use mpm_mesh::RegularGrid;
use mpm_solver::SolverError;
use mpm_solver::ranks::{self, Decomposition, Ranks, Reduce};

use crate::explicit::Stepper;
use crate::on_ranks::{Part, RankRun, gather, imbalance, keep_names, rows_by_id, to_root};
use crate::run::Snapshot;

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

/// What the ranks of a run sent and did, per rank: the largest over the
/// ranks and their mean (`[max, mean]`), from this session's steps. The
/// traffic is counted when the ranks are ([`ranks::Counted`]; zero
/// otherwise).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RanksReport {
    /// The number of ranks.
    pub ranks: usize,
    /// Seconds of point work (point to grid and grid to point).
    pub point_seconds: [f64; 2],
    /// Seconds of the grid stage (the halo exchange included).
    pub grid_seconds: [f64; 2],
    /// Point-to-point messages of the steps: the halo exchanges, one per
    /// neighbour each way per step (the outputs' gathers not counted).
    pub halo_messages: [f64; 2],
    /// Bytes those messages carried.
    pub halo_bytes: [f64; 2],
    /// Messages of the migrations (and new deals).
    pub migration_messages: [f64; 2],
    /// Bytes those carried.
    pub migration_bytes: [f64; 2],
    /// Collectives joined in the steps, migrations and new deals
    /// (reductions, error broadcasts; the outputs' not counted).
    pub collectives: [f64; 2],
    /// Points sent to another rank after a step or by a new deal.
    pub migrated_points: [f64; 2],
}

/// From a checkpoint's `held` of `size` ranks (as [`Spread::join`] wrote
/// it), rank `me`'s deal of the `cells`, its points of the `total` in
/// their order, and its work of the point forces.
///
/// # Errors
/// A `held` of another length, or ranks and places out of range.
fn held_by(
    held: &[f64],
    size: usize,
    cells: usize,
    total: usize,
    me: usize,
) -> Result<(Vec<usize>, Vec<usize>, f64), SolverError> {
    let bad = || {
        SolverError::InvalidInput(
            "the checkpoint's record of the ranks does not fit this scene".into(),
        )
    };
    if held.len() != 1 + size + cells + 2 * total {
        return Err(bad());
    }
    let index = |x: f64, below: usize| {
        (x >= 0.0 && x.fract() == 0.0 && (x as usize) < below)
            .then_some(x as usize)
            .ok_or_else(bad)
    };
    let deal = (held[1 + size..1 + size + cells].iter())
        .map(|&r| index(r, size))
        .collect::<Result<Vec<_>, _>>()?;
    let places = &held[1 + size + cells..];
    let mut mine = Vec::new();
    for id in 0..total {
        if index(places[2 * id], size)? == me {
            mine.push((index(places[2 * id + 1], total)?, id));
        }
    }
    mine.sort_unstable();
    Ok((
        deal,
        mine.into_iter().map(|(_, id)| id).collect(),
        held[1 + me],
    ))
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
    /// This session's traffic of the steps (the halo exchanges and the
    /// step's reductions), of the migrations and new deals, and the points
    /// this rank sent in them; the outputs' gathers are in neither.
    stepping: ranks::Traffic,
    migration: ranks::Traffic,
    migrated: usize,
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
            stepping: ranks::Traffic::default(),
            migration: ranks::Traffic::default(),
            migrated: 0,
        })
    }

    /// Runs `step`, counting its traffic as the steps'.
    pub(crate) fn step<T>(&mut self, step: impl FnOnce() -> T) -> T {
        let counted = self.traffic();
        let result = step();
        self.stepping = self.stepping.plus(self.traffic().since(counted));
        result
    }

    /// The traffic so far (zero when not counted).
    fn traffic(&self) -> ranks::Traffic {
        self.run.ranks.traffic().unwrap_or_default()
    }

    /// What every rank sent and did in this session, `times` this rank's
    /// stage times of it. Collective.
    ///
    /// # Errors
    /// The transport's.
    pub(crate) fn report(
        &self,
        times: &mpm_solver::explicit::ExplicitStageTimes,
    ) -> Result<RanksReport, SolverError> {
        let (halo, migration) = (self.stepping, self.migration);
        let bytes = |t: ranks::Traffic| 8.0 * t.values as f64;
        let mine = [
            times.p2g + times.g2p,
            times.grid,
            halo.messages as f64,
            bytes(halo),
            migration.messages as f64,
            bytes(migration),
            (halo.collectives + migration.collectives) as f64,
            self.migrated as f64,
        ];
        let mut max = mine;
        let mut sum = mine;
        self.run.ranks.all_reduce(&mut max, Reduce::Max)?;
        self.run.ranks.all_reduce(&mut sum, Reduce::Sum)?;
        let size = self.run.ranks.size();
        let pair = |k: usize| [max[k], sum[k] / size as f64];
        Ok(RanksReport {
            ranks: size,
            point_seconds: pair(0),
            grid_seconds: pair(1),
            halo_messages: pair(2),
            halo_bytes: pair(3),
            migration_messages: pair(4),
            migration_bytes: pair(5),
            collectives: pair(6),
            migrated_points: pair(7),
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
        let counted = self.traffic();
        let (sent, _) = run.migrate()?;
        self.migrated += sent;
        self.migration = self.migration.plus(self.traffic().since(counted));
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
        let counted = self.traffic();
        let (sent, _) = run.rebalance(self.layout(cells.clone())?)?;
        self.migrated += sent;
        self.migration = self.migration.plus(self.traffic().since(counted));
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

    /// A checkpoint's points on rank 0 — every rank's records
    /// ([`Stepper::flat_points`]) placed by id, the count first: what one
    /// process writes — and how the ranks held them ([`Self::resume`]);
    /// empty on the other ranks. Collective.
    ///
    /// # Errors
    /// The transport's, or parts that do not cover the points once, on
    /// every rank.
    pub(crate) fn checkpoint<const D: usize>(
        &self,
        run: &dyn Stepper<D>,
        total: usize,
    ) -> Result<(Vec<f64>, Vec<f64>), SolverError> {
        let ranks = self.run.ranks.as_ref();
        // The rank's work of the point forces, then its records.
        let mut numbers = run.flat_points();
        numbers[0] = run.local_work();
        let joined = match to_root(ranks, run.ids(), &numbers) {
            Ok(Some(parts)) => self.join(&parts, total),
            other => other.map(|_| (Vec::new(), Vec::new())),
        };
        ranks::agree(ranks, joined)
    }

    /// Rank 0's side of [`Self::checkpoint`]: the parts (each its work,
    /// then its records) joined into the records by id, the count first,
    /// and how the ranks held them: their number, each one's work, the deal
    /// of the cells, each point's rank and place.
    fn join(&self, parts: &[Part], total: usize) -> Result<(Vec<f64>, Vec<f64>), SolverError> {
        let (size, cells) = (parts.len(), self.rank_of_cell.len());
        let numbers = parts.iter().map(|p| p.numbers.len()).sum::<usize>();
        let per = numbers.saturating_sub(size) / total.max(1);
        let (records, places) = rows_by_id(parts, per, 1, total).map_err(|what| {
            SolverError::InvalidInput(format!("a checkpoint of the ranks: {what}"))
        })?;
        let whole = std::iter::once(total as f64).chain(records).collect();
        let mut held = Vec::with_capacity(1 + size + cells + 2 * total);
        held.push(size as f64);
        held.extend(parts.iter().map(|p| p.numbers[0]));
        held.extend(self.rank_of_cell.iter().map(|&r| r as f64));
        held.extend(places.iter().flat_map(|&(r, slot)| [r as f64, slot as f64]));
        Ok((whole, held))
    }

    /// After the points were restored whole on every rank: each rank keeps
    /// its own as `held` says (a checkpoint of as many ranks: the same deal
    /// and order, so the run goes on bit for bit) or, from a checkpoint of
    /// another number of ranks or of one process, those of its cells in a
    /// new deal, rank 0 taking the work of the point forces (`work`, the
    /// sum over the ranks). Collective.
    ///
    /// # Errors
    /// A `held` that does not fit, the repartition's, the transport's.
    pub(crate) fn resume<const D: usize>(
        &mut self,
        run: &mut dyn Stepper<D>,
        held: &[f64],
        work: f64,
    ) -> Result<(), SolverError> {
        let (size, me) = (self.run.ranks.size(), self.run.ranks.rank());
        let (total, cells) = (run.ids().len(), self.rank_of_cell.len());
        let same_ranks = held.first() == Some(&(size as f64));
        let (deal, order, work) = if same_ranks {
            held_by(held, size, cells, total, me)?
        } else {
            let balance = self.run.balance.as_ref().ok_or_else(|| {
                SolverError::InvalidInput(
                    "resuming on another number of ranks needs a new deal (RankRun::balance)"
                        .into(),
                )
            })?;
            let of_points = run.cells();
            let mut loads = vec![0.0; cells];
            for &c in of_points.iter().flatten() {
                loads[c] += 1.0;
            }
            let deal = ranks::agree(self.run.ranks.as_ref(), (balance.repartition)(&loads))?;
            let mine = |p: &usize| of_points[*p].map_or(me == 0, |c| deal.get(c) == Some(&me));
            let order = (0..total).filter(mine).collect();
            (deal, order, if me == 0 { work } else { 0.0 })
        };
        run.keep(&order)?;
        // Every point is in its rank's cells: nothing moves, the deal is
        // installed.
        run.rebalance(self.layout(deal.clone())?)?;
        run.set_local_work(work);
        self.rank_of_cell = deal;
        Ok(())
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
        index: usize,
        ids: &[usize],
        local: &Snapshot,
        total: usize,
        observe: impl FnOnce(&Snapshot) -> Result<(), SolverError>,
    ) -> Result<(), SolverError> {
        self.run.write_piece(index, local, ids)?;
        let whole = self.gather(ids, local, total)?;
        ranks::agree(
            self.run.ranks.as_ref(),
            whole.as_ref().map_or(Ok(()), observe),
        )
    }
}
