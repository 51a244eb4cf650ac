//! The explicit solver on several ranks ([`crate::ranks`]): each rank
//! steps the points of its cells; the nodal sums meet over the halo after
//! the point-to-grid stage, every failure and the stable increment are
//! decided collectively, and after a step the points that crossed into
//! another rank's cells move there ([`ExplicitSolver::migrate`]).

use mpm_basis::BasisFunction;
use mpm_constitutive::IncrementalLaw;

use super::grid::GridState;
use super::{
    DilatationTreatment, ExplicitMesh, ExplicitSolver, PointsOf, Transfer, WallWork, grid_update,
    migrate,
};
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
    /// Whether any rank holds material points (their fixities stay with
    /// them, so this is asked once).
    any_held: Option<bool>,
}

impl OnRanks {
    /// This rank and the owner of every node: every rank that touches a
    /// node holds its totals after the halo, so a sum over nodes counts
    /// each on its owner alone.
    pub(super) fn owner_of_node(&self) -> (usize, &[usize]) {
        (self.ranks.rank(), &self.layout.owner_of_node)
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
    /// A decomposition that does not fit the mesh or the ranks; gap-checked
    /// friction walls (each rank sees only its points).
    pub fn on_ranks(
        mut self,
        ranks: Box<dyn Ranks>,
        layout: Decomposition,
    ) -> Result<Self, SolverError> {
        if self.touch.is_active() {
            // Each rank sees only its own points: the marks would differ
            // on the nodes the ranks share.
            return Err(SolverError::InvalidInput(
                "gap-checked friction walls (`gap_check = true`) run on one process only".into(),
            ));
        }
        if self.contact.is_some() {
            return Err(SolverError::InvalidInput(
                "contact between bodies is not yet supported on several ranks".into(),
            ));
        }
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
            any_held: None,
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

    /// The material-point fixities on several ranks: a held point's
    /// multiplier changes the velocities of its nodes, which other ranks'
    /// points share, and the held points couple where their stencils meet.
    /// So every rank gathers every held point (its global id, component,
    /// value and (node, weight) pairs) and the updated mass and velocity
    /// of every node of their stencils (from the lowest rank holding the
    /// node: the halo has given each the totals), runs the same
    /// Gauss–Seidel sweeps ([`grid_update::hold_points_to`], in the order
    /// of the points' ids, to the tolerance of the whole grid's velocity
    /// scale) on that small grid, and takes back the velocities of the
    /// nodes its own points touch. Collective; nothing on one rank or
    /// when no rank holds points.
    ///
    /// # Errors
    /// The transport's.
    pub(super) fn hold_over_ranks(
        &mut self,
        points: &PointsOf<D, B, L, T>,
    ) -> Result<(), SolverError> {
        let Some(on) = &mut self.on_ranks else {
            return Ok(());
        };
        let held = &points.fixed_velocity;
        let any = match on.any_held {
            Some(any) => any,
            None => {
                let mut count = [held.len() as f64];
                on.ranks.all_reduce(&mut count, Reduce::Sum)?;
                *on.any_held.insert(count[0] > 0.0)
            }
        };
        if !any {
            return Ok(());
        }
        let ranks = on.ranks.as_ref();
        let (pairs, ends) = &self.held_stencils;
        let mut all = gather_held(ranks, held, &points.id, pairs, ends)?;
        let nodes = stencil_nodes(&all);
        let mut small = node_totals(ranks, &self.grid, &nodes)?;
        let mut scale = [grid_update::velocity_scale(&self.grid, held)];
        ranks.all_reduce(&mut scale, Reduce::Max)?;
        // The stencils on the small grid of `nodes`.
        for (i, _) in &mut all.pairs {
            *i = nodes.binary_search(i).unwrap_or(0);
        }
        let mut fixities = crate::explicit::VelocityFixities::new();
        for &(n, c, v) in self.fixities.entries() {
            if let Ok(k) = nodes.binary_search(&n) {
                fixities.prescribe([k], c, v);
            }
        }
        fixities.finish();
        grid_update::hold_points_to(
            &mut small,
            &all.points,
            (&all.pairs, &all.ends),
            &fixities,
            scale[0],
        );
        for (k, &i) in nodes.iter().enumerate() {
            if touched(&self.grid, i) {
                self.grid.velocity[i].new = small.velocity[k].new;
            }
        }
        Ok(())
    }

    /// The step's [`WallWork`] of this rank's own nodes summed over the
    /// ranks (one reduction, in runs with friction walls or absorbing
    /// boundaries only): every rank then books the same. Collective.
    ///
    /// # Errors
    /// The transport's.
    pub(super) fn sum_wall_work(&self, local: WallWork) -> Result<WallWork, SolverError> {
        let Some(on) = self
            .on_ranks
            .as_ref()
            .filter(|_| !(self.fixities.walls().is_empty() && self.fixities.dashpots().is_empty()))
        else {
            return Ok(local);
        };
        let mut sums = [local.friction, local.impact, local.absorbed];
        on.ranks.all_reduce(&mut sums, Reduce::Sum)?;
        let [friction, impact, absorbed] = sums;
        Ok(WallWork {
            friction,
            impact,
            absorbed,
        })
    }

    /// The spring layer's displacements as their nodes' owners advanced
    /// them, on every rank: each rank gives those of the nodes it owns and
    /// the ranks sum them (no-op on one rank or without springs).
    pub(super) fn share_spring_displacements(&mut self) -> Result<(), SolverError> {
        let Some(on) = self
            .on_ranks
            .as_ref()
            .filter(|_| self.fixities.dashpots().iter().any(|d| d.has_springs()))
        else {
            return Ok(());
        };
        let (me, owners) = on.owner_of_node();
        let mut flat: Vec<f64> = (self.fixities.dashpots().iter())
            .zip(&self.spring_displacement)
            .flat_map(|(d, u)| {
                let mine = owners.get(d.node) == Some(&me);
                u.iter().map(move |&x| if mine { x } else { 0.0 })
            })
            .collect();
        on.ranks.all_reduce(&mut flat, Reduce::Sum)?;
        for (u, chunk) in self.spring_displacement.iter_mut().zip(flat.chunks(D)) {
            u.copy_from_slice(chunk);
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

/// A held point: (point, component, value).
type Held = (usize, usize, f64);

/// A point's (node, weight) pairs.
type Stencil = Vec<(usize, f64)>;

/// Every rank's held points, in the order of their ids: (id, component,
/// value), and their (node, weight) pairs, point k's at
/// `pairs[ends[k-1]..ends[k]]` (from 0 for the first).
struct HeldPoints {
    points: Vec<Held>,
    pairs: Stencil,
    ends: Vec<usize>,
}

/// Every rank's held points (this rank's `held`, named by `ids`, with
/// the stencils `pairs`/`ends`), sorted by id and component: the same on
/// every rank. Two reductions: the lengths, then the records, each rank
/// writing its own span.
fn gather_held(
    ranks: &dyn Ranks,
    held: &[(usize, usize, f64)],
    ids: &[usize],
    pairs: &[(usize, f64)],
    ends: &[usize],
) -> Result<HeldPoints, SolverError> {
    // Per held point: id, component, value, count, then (node, weight)s.
    let mut mine = Vec::new();
    let mut start = 0;
    for (&(p, c, v), &end) in held.iter().zip(ends) {
        let stencil = &pairs[start..end];
        start = end;
        mine.extend([ids.get(p).copied().unwrap_or(p) as f64, c as f64, v]);
        mine.push(stencil.len() as f64);
        mine.extend(stencil.iter().flat_map(|&(i, w)| [i as f64, w]));
    }
    let (me, size) = (ranks.rank(), ranks.size());
    let mut lengths = vec![0.0; size];
    lengths[me] = mine.len() as f64;
    ranks.all_reduce(&mut lengths, Reduce::Sum)?;
    let offset: usize = lengths[..me].iter().map(|&l| l as usize).sum();
    let total: usize = lengths.iter().map(|&l| l as usize).sum();
    let mut all = vec![0.0; total];
    all[offset..offset + mine.len()].copy_from_slice(&mine);
    ranks.all_reduce(&mut all, Reduce::Sum)?;
    let mut records = Vec::new();
    let mut k = 0;
    while k + 4 <= all.len() {
        let count = all[k + 3] as usize;
        let stencil = (0..count)
            .map(|j| (all[k + 4 + 2 * j] as usize, all[k + 5 + 2 * j]))
            .collect();
        records.push(((all[k] as usize, all[k + 1] as usize, all[k + 2]), stencil));
        k += 4 + 2 * count;
    }
    records.sort_by_key(|(h, _): &(Held, Stencil)| (h.0, h.1));
    let mut held = HeldPoints {
        points: Vec::with_capacity(records.len()),
        pairs: Vec::new(),
        ends: Vec::with_capacity(records.len()),
    };
    for (point, stencil) in records {
        held.points.push(point);
        held.pairs.extend(stencil);
        held.ends.push(held.pairs.len());
    }
    Ok(held)
}

/// Whether this rank's points touched node `i` in this step: the grid
/// keeps the values of earlier steps outside its range `lo..hi`.
fn touched<const D: usize>(grid: &GridState<D>, i: usize) -> bool {
    (grid.lo..grid.hi).contains(&i) && grid.mass[i] > 0.0
}

/// The nodes of every held point's stencil, ascending, once.
fn stencil_nodes(held: &HeldPoints) -> Vec<usize> {
    let mut nodes: Vec<usize> = held.pairs.iter().map(|&(i, _)| i).collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

/// A grid of the `nodes` alone with their updated masses and velocities,
/// each from the lowest rank whose points touched the node in this step
/// (after the halo every such rank holds the totals).
fn node_totals<const D: usize>(
    ranks: &dyn Ranks,
    grid: &GridState<D>,
    nodes: &[usize],
) -> Result<GridState<D>, SolverError> {
    let me = ranks.rank() as f64;
    let mut lowest: Vec<f64> = (nodes.iter())
        .map(|&i| if touched(grid, i) { me } else { f64::INFINITY })
        .collect();
    ranks.all_reduce(&mut lowest, Reduce::Min)?;
    let width = D + 1;
    let mut values = vec![0.0; nodes.len() * width];
    for (k, &i) in nodes.iter().enumerate() {
        if lowest[k] == me {
            values[k * width] = grid.mass[i];
            for c in 0..D {
                values[k * width + 1 + c] = grid.velocity[i].new[c];
            }
        }
    }
    ranks.all_reduce(&mut values, Reduce::Sum)?;
    let mut small = GridState::new(nodes.len());
    for k in 0..nodes.len() {
        small.mass[k] = values[k * width];
        for c in 0..D {
            small.velocity[k].new[c] = values[k * width + 1 + c];
        }
    }
    small.lo = 0;
    small.hi = nodes.len();
    Ok(small)
}
