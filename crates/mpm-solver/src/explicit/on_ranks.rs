//! The explicit solver on several ranks ([`crate::ranks`]): each rank
//! steps the points of its cells; the nodal sums meet over the halo after
//! the point-to-grid stage, every failure and the stable increment are
//! decided collectively, and after a step the points that crossed into
//! another rank's cells move there ([`ExplicitSolver::migrate`]).

use mpm_basis::BasisFunction;
use mpm_constitutive::IncrementalLaw;

use super::{DilatationTreatment, ExplicitMesh, ExplicitSolver, PointsOf, Transfer, migrate};
use crate::checkpoint::Flat;
use crate::domain::DomainUpdater;
use crate::error::SolverError;
use crate::mesh::NodalMesh;
use crate::ranks::{self, Decomposition, Ranks, Reduce, halo::Halo};

/// A solver's link to the other ranks of a distributed run.
pub(super) struct OnRanks {
    pub(super) ranks: Box<dyn Ranks>,
    layout: Decomposition,
    halo: Halo,
    migration: migrate::Migration,
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
    /// The same solver as one rank of a distributed run: it steps the
    /// points it is given (those of its cells, with their global ids) and
    /// meets the other ranks through `ranks` as `layout` says.
    ///
    /// Under the cell-averaged dilatation a cell's average needs all its
    /// points: each step checks that every point starts it in a cell of
    /// its own rank (as when the points follow their cells, migrating
    /// after every step: [`Self::migrate`]), so the averages need no
    /// communication.
    ///
    /// # Errors
    /// A decomposition that does not fit the mesh or the ranks.
    pub fn on_ranks(
        mut self,
        ranks: Box<dyn Ranks>,
        layout: Decomposition,
    ) -> Result<Self, SolverError> {
        layout.check(
            ranks.rank(),
            ranks.size(),
            self.mesh.cell_count(),
            self.node_count,
        )?;
        self.on_ranks = Some(OnRanks {
            ranks,
            layout,
            halo: Halo::default(),
            migration: migrate::Migration::default(),
        });
        Ok(self)
    }

    /// This rank and the number of ranks ((0, 1) on one).
    pub fn rank(&self) -> (usize, usize) {
        self.on_ranks
            .as_ref()
            .map_or((0, 1), |on| (on.ranks.rank(), on.ranks.size()))
    }

    /// Under the cell-averaged dilatation on several ranks, that every
    /// point starts the step in a cell of its own rank ([`Self::on_ranks`]);
    /// nothing otherwise. Not collective.
    ///
    /// # Errors
    /// [`SolverError::InvalidInput`] naming the first point held by
    /// another rank than its cell's.
    pub(super) fn check_cells_held(
        &self,
        points: &PointsOf<D, B, L, T>,
    ) -> Result<(), SolverError> {
        let Some(on) = self.on_ranks.as_ref().filter(|_| K::AVERAGES) else {
            return Ok(());
        };
        let me = on.ranks.rank();
        for (p, x) in points.position.iter().enumerate() {
            let cell = self.mesh.cell_of(x);
            let owner = cell.and_then(|c| on.layout.rank_of_cell.get(c).copied());
            if let (Some(c), Some(r)) = (cell, owner)
                && r != me
            {
                return Err(SolverError::InvalidInput(format!(
                    "the cell-averaged dilatation needs every point of a cell on its rank: \
                     material point {} of rank {me} is in cell {c} of rank {r}",
                    points.id.get(p).copied().unwrap_or(p)
                )));
            }
        }
        Ok(())
    }

    /// A local outcome decided over the ranks ([`ranks::agree`]).
    pub(super) fn collective<V>(&self, local: Result<V, SolverError>) -> Result<V, SolverError> {
        match &self.on_ranks {
            Some(on) => ranks::agree(on.ranks.as_ref(), local),
            None => local,
        }
    }

    /// `value` reduced over the ranks.
    pub(super) fn reduce(&self, value: f64, op: Reduce) -> Result<f64, SolverError> {
        let mut v = [value];
        if let Some(on) = &self.on_ranks {
            on.ranks.all_reduce(&mut v, op)?;
        }
        Ok(v[0])
    }

    /// The nodal sums over the ranks: the threads' buffers folded into the
    /// first, then the halo exchange ([`Halo::sum`]). Nothing on one rank.
    pub(super) fn sum_over_ranks(&mut self) -> Result<(), SolverError> {
        let Some(on) = &mut self.on_ranks else {
            return Ok(());
        };
        let (first, rest) = self
            .buffers
            .split_first_mut()
            .ok_or_else(|| SolverError::InvalidInput("no grid buffer".into()))?;
        for b in rest {
            for i in b.lo..b.hi {
                let (n, into) = (&b.nodes[i], &mut first.nodes[i]);
                into.mass += n.mass;
                into.momentum += n.momentum;
                into.force += n.force;
            }
            first.lo = first.lo.min(b.lo);
            first.hi = first.hi.max(b.hi);
            b.clear();
        }
        let result = on.halo.sum(on.ranks.as_ref(), &on.layout, first);
        ranks::agree(on.ranks.as_ref(), result)
    }

    /// Before the first step: the largest signal speed over all ranks.
    pub(super) fn agree_initial_signal(
        &mut self,
        points: &PointsOf<D, B, L, T>,
    ) -> Result<(), SolverError> {
        if self.max_signal.is_some() {
            return Ok(());
        }
        let local = self.local_signal(points);
        self.max_signal = Some(self.reduce(local, Reduce::Max)?);
        Ok(())
    }
}

impl<const D: usize, B, L, T, K, R> ExplicitSolver<D, B, L, T, K, R>
where
    B: BasisFunction<D, Domain: Flat>,
    B::Mesh: ExplicitMesh<D> + NodalMesh<D>,
    L: IncrementalLaw<State: Flat>,
    T: Transfer<D, PointState: Flat>,
    K: DilatationTreatment,
    R: DomainUpdater<D, B::Domain>,
{
    /// After a step of a distributed run: the points that entered another
    /// rank's cells go there, those entering this rank's arrive (their
    /// order changes; their global ids stay). Returns (sent, received);
    /// (0, 0) on one rank.
    ///
    /// # Errors
    /// As [`migrate::Migration::migrate`], decided over the ranks.
    pub fn migrate(
        &mut self,
        points: &mut PointsOf<D, B, L, T>,
    ) -> Result<(usize, usize), SolverError> {
        let Some(on) = &mut self.on_ranks else {
            return Ok((0, 0));
        };
        let mesh = &self.mesh;
        let moved =
            on.migration
                .migrate(on.ranks.as_ref(), &on.layout, |x| mesh.cell_of(x), points);
        ranks::agree(on.ranks.as_ref(), moved)
    }

    /// The number of points in every cell over all ranks (the same on
    /// every rank): the loads a partitioner balances
    /// ([`Self::rebalance`]). Empty on one rank.
    ///
    /// # Errors
    /// The transport's.
    pub fn cell_loads(&self, points: &PointsOf<D, B, L, T>) -> Result<Vec<f64>, SolverError> {
        let Some(on) = &self.on_ranks else {
            return Ok(Vec::new());
        };
        let mut loads = vec![0.0; self.mesh.cell_count()];
        for x in &points.position {
            if let Some(c) = self.mesh.cell_of(x) {
                loads[c] += 1.0;
            }
        }
        on.ranks.all_reduce(&mut loads, Reduce::Sum)?;
        Ok(loads)
    }

    /// A new decomposition for a run under way (the same on every rank,
    /// e.g. METIS on [`Self::cell_loads`]): every point whose cell now
    /// belongs to another rank goes there, from any rank to any (it may be
    /// a neighbour in neither decomposition), then the run goes on with
    /// `layout`. Returns (sent, received); (0, 0) on one rank.
    ///
    /// # Errors
    /// A decomposition that does not fit; the transport's; decided over
    /// the ranks.
    pub fn rebalance(
        &mut self,
        points: &mut PointsOf<D, B, L, T>,
        mut layout: Decomposition,
    ) -> Result<(usize, usize), SolverError> {
        let Some(on) = &mut self.on_ranks else {
            return Ok((0, 0));
        };
        let (rank, size) = (on.ranks.rank(), on.ranks.size());
        let fits = layout.check(rank, size, self.mesh.cell_count(), self.node_count);
        ranks::agree(on.ranks.as_ref(), fits)?;
        let everyone = (0..size).filter(|&q| q != rank).collect();
        let neighbours = std::mem::replace(&mut layout.neighbours, everyone);
        let mesh = &self.mesh;
        let moved = on
            .migration
            .migrate(on.ranks.as_ref(), &layout, |x| mesh.cell_of(x), points);
        let moved = ranks::agree(on.ranks.as_ref(), moved)?;
        layout.neighbours = neighbours;
        on.layout = layout;
        Ok(moved)
    }
}
