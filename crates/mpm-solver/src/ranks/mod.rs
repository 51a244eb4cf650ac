//! Runs over several ranks — MPI processes, or threads of one process —
//! each holding the material points of its part of a replicated mesh
//! (Wang et al. 2021 §4.3). The solvers see the other ranks only through
//! [`Ranks`]: one message to and from each neighbour rank, reductions, and
//! one text broadcast for errors. Who owns what is a [`Decomposition`]
//! (made by METIS in `mpm-distributed`, or by hand).
//!
//! - [`halo`]: the explicit step's nodal sums added over the ranks that
//!   touch a node (the reverse exchange to its owner) and handed back
//!   (the forward exchange), one message per neighbour each way.
//! - [`agree`]: every local failure decided collectively, so every rank
//!   stops at the same step with the same error.
//! - [`ThreadRanks`]: N ranks as threads of one process, so the default
//!   test suite checks that one rank equals N ranks without MPI.
//! - [`Counted`]: any ranks with their traffic counted ([`Traffic`]).
//!
//! The mesh is replicated; a rank allocates the grid arrays of the whole
//! mesh but touches only the nodes near its points.

pub mod disks;
pub mod halo;
pub mod strip_load;
mod threads;
mod traffic;

pub use threads::ThreadRanks;
pub use traffic::{Counted, Traffic};

use thiserror::Error;

use crate::error::SolverError;

/// A reduction over the ranks, entry by entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reduce {
    /// The sum.
    Sum,
    /// The largest value.
    Max,
    /// The smallest value.
    Min,
}

impl Reduce {
    /// `a` combined with `b`.
    pub fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Reduce::Sum => a + b,
            Reduce::Max => a.max(b),
            Reduce::Min => a.min(b),
        }
    }
}

/// The transport between ranks failed (another rank stopped, a message
/// was malformed).
#[derive(Debug, Clone, PartialEq, Error)]
#[error("rank {rank}: {message}")]
pub struct RankError {
    /// The rank that saw the failure.
    pub rank: usize,
    /// What happened.
    pub message: String,
}

impl From<RankError> for SolverError {
    fn from(e: RankError) -> Self {
        SolverError::Rank {
            rank: e.rank,
            message: e.message,
        }
    }
}

/// The communication a distributed solver needs. Every method is
/// collective over the ranks it names: all ranks call [`Ranks::all_reduce`]
/// and [`Ranks::broadcast_text`] in the same order, and a rank calls
/// [`Ranks::exchange`] together with each of its neighbours.
pub trait Ranks: Send + Sync {
    /// This rank, `0..size()`.
    fn rank(&self) -> usize;

    /// Number of ranks.
    fn size(&self) -> usize;

    /// Sends `outgoing[k]` to rank `neighbours[k]` and receives the message
    /// that rank sent to this one into `incoming[k]` (resized to it): one
    /// message each way per neighbour. The neighbour relation must be
    /// symmetric.
    ///
    /// # Errors
    /// The transport failed.
    fn exchange(
        &self,
        neighbours: &[usize],
        outgoing: &[Vec<f64>],
        incoming: &mut [Vec<f64>],
    ) -> Result<(), RankError>;

    /// Replaces every entry of `values` by its reduction over all ranks.
    ///
    /// # Errors
    /// The transport failed.
    fn all_reduce(&self, values: &mut [f64], op: Reduce) -> Result<(), RankError>;

    /// Sets `text` on every rank to its value on rank `root`.
    ///
    /// # Errors
    /// The transport failed.
    fn broadcast_text(&self, root: usize, text: &mut String) -> Result<(), RankError>;

    /// What this rank has sent so far, when counted ([`Counted`]); `None`
    /// otherwise.
    fn traffic(&self) -> Option<Traffic> {
        None
    }
}

/// Shared ranks are ranks: a run that keeps its communication (e.g. for
/// gathering outputs) and hands the solver a `Box<dyn Ranks>` of it.
impl<R: Ranks + ?Sized> Ranks for std::sync::Arc<R> {
    fn rank(&self) -> usize {
        (**self).rank()
    }

    fn size(&self) -> usize {
        (**self).size()
    }

    fn exchange(
        &self,
        neighbours: &[usize],
        outgoing: &[Vec<f64>],
        incoming: &mut [Vec<f64>],
    ) -> Result<(), RankError> {
        (**self).exchange(neighbours, outgoing, incoming)
    }

    fn all_reduce(&self, values: &mut [f64], op: Reduce) -> Result<(), RankError> {
        (**self).all_reduce(values, op)
    }

    fn broadcast_text(&self, root: usize, text: &mut String) -> Result<(), RankError> {
        (**self).broadcast_text(root, text)
    }

    fn traffic(&self) -> Option<Traffic> {
        (**self).traffic()
    }
}

/// Who owns what: the rank of every mesh cell (its material points live
/// there), the owner of every node (where its nodal sums meet), and this
/// rank's neighbours (the ranks whose points may touch a node this rank's
/// points touch).
#[derive(Debug, Clone, PartialEq)]
pub struct Decomposition {
    /// Rank of every cell, in the numbering of
    /// [`crate::explicit::ExplicitMesh::cell_of`].
    pub rank_of_cell: Vec<usize>,
    /// Owner rank of every node.
    pub owner_of_node: Vec<usize>,
    /// This rank's neighbours, ascending, without itself.
    pub neighbours: Vec<usize>,
}

impl Decomposition {
    /// Checks the decomposition against a mesh of `cells` cells and `nodes`
    /// nodes for rank `rank` of `size`.
    ///
    /// # Errors
    /// [`SolverError::InvalidInput`] saying what does not fit.
    pub fn check(
        &self,
        rank: usize,
        size: usize,
        cells: usize,
        nodes: usize,
    ) -> Result<(), SolverError> {
        let invalid =
            |what: String| Err(SolverError::InvalidInput(format!("decomposition: {what}")));
        if self.rank_of_cell.len() != cells || self.owner_of_node.len() != nodes {
            return invalid(format!(
                "{} cell ranks and {} node owners for a mesh of {cells} cells and {nodes} nodes",
                self.rank_of_cell.len(),
                self.owner_of_node.len()
            ));
        }
        if let Some(r) = self
            .rank_of_cell
            .iter()
            .chain(&self.owner_of_node)
            .find(|&&r| r >= size)
        {
            return invalid(format!("rank {r} of {size} ranks"));
        }
        let ascending = self.neighbours.windows(2).all(|w| w[0] < w[1]);
        if !ascending || self.neighbours.iter().any(|&q| q == rank || q >= size) {
            return invalid(format!(
                "neighbours {:?} of rank {rank} must ascend, lie below {size} and exclude {rank}",
                self.neighbours
            ));
        }
        Ok(())
    }

    /// Rank `rank`'s decomposition from the rank of every cell of a mesh
    /// whose cell `c` has the nodes
    /// `connectivity[c * nodes_per_cell..(c + 1) * nodes_per_cell]`: every
    /// node owned by the lowest rank among the cells holding it, and as
    /// neighbours the ranks of the cells within `reach` rings of this
    /// rank's cells (a ring: the cells sharing a node with the previous
    /// ones). A basis whose points touch the nodes of their own cell only
    /// (linear shape functions) needs `reach` 1; one that reaches the next
    /// cells (GIMP, quadratic B-splines) 2.
    ///
    /// # Errors
    /// Connectivity and ranks that do not fit together.
    pub fn from_cells(
        rank: usize,
        rank_of_cell: Vec<usize>,
        connectivity: &[usize],
        nodes_per_cell: usize,
        nodes: usize,
        reach: usize,
    ) -> Result<Self, SolverError> {
        let cells = rank_of_cell.len();
        if nodes_per_cell == 0 || connectivity.len() != cells * nodes_per_cell {
            return Err(SolverError::InvalidInput(format!(
                "decomposition: {} connectivity entries for {cells} cells of {nodes_per_cell} nodes",
                connectivity.len()
            )));
        }
        if let Some(&n) = connectivity.iter().find(|&&n| n >= nodes) {
            return Err(SolverError::InvalidInput(format!(
                "decomposition: node {n} of a mesh of {nodes} nodes"
            )));
        }
        let cell_nodes = |c: usize| &connectivity[c * nodes_per_cell..(c + 1) * nodes_per_cell];
        let mut owner_of_node = vec![usize::MAX; nodes];
        let mut node_cells = vec![Vec::new(); nodes];
        for (c, &r) in rank_of_cell.iter().enumerate() {
            for &n in cell_nodes(c) {
                owner_of_node[n] = owner_of_node[n].min(r);
                node_cells[n].push(c);
            }
        }
        // Nodes of no cell are never touched; any owner will do.
        owner_of_node
            .iter_mut()
            .filter(|o| **o == usize::MAX)
            .for_each(|o| *o = 0);
        let mut reached: Vec<bool> = rank_of_cell.iter().map(|&r| r == rank).collect();
        let mut front: Vec<usize> = (0..cells).filter(|&c| reached[c]).collect();
        for _ in 0..reach {
            let mut next = Vec::new();
            for &c in &front {
                for &n in cell_nodes(c) {
                    for &d in &node_cells[n] {
                        if !reached[d] {
                            reached[d] = true;
                            next.push(d);
                        }
                    }
                }
            }
            front = next;
        }
        let mut neighbours: Vec<usize> = (0..cells)
            .filter(|&c| reached[c] && rank_of_cell[c] != rank)
            .map(|c| rank_of_cell[c])
            .collect();
        neighbours.sort_unstable();
        neighbours.dedup();
        Ok(Self {
            rank_of_cell,
            owner_of_node,
            neighbours,
        })
    }

    /// The slot of rank `q` in [`Self::neighbours`].
    pub fn slot(&self, q: usize) -> Option<usize> {
        self.neighbours.binary_search(&q).ok()
    }
}

/// When any rank failed (`failed` on this one), the lowest failing rank
/// and its message, which `describe` gives on that rank alone; `None`
/// when no rank failed, after one reduction.
///
/// # Errors
/// The transport's.
pub fn lowest_failure(
    ranks: &dyn Ranks,
    failed: bool,
    describe: impl FnOnce() -> String,
) -> Result<Option<(usize, String)>, RankError> {
    let me = ranks.rank();
    let mut failing = [if failed { me as f64 } else { f64::INFINITY }];
    ranks.all_reduce(&mut failing, Reduce::Min)?;
    if failing[0].is_infinite() {
        return Ok(None);
    }
    let root = failing[0] as usize;
    let mut text = if me == root {
        describe()
    } else {
        String::new()
    };
    ranks.broadcast_text(root, &mut text)?;
    Ok(Some((root, text)))
}

/// Decides a local outcome collectively: when any rank failed, every rank
/// returns an error — the lowest failing rank its own, the others
/// [`SolverError::Rank`] carrying that error's message — so all ranks stop
/// at the same point with the same report. One reduction when no rank
/// failed.
///
/// # Errors
/// As above, or the transport's.
pub fn agree<T>(ranks: &dyn Ranks, local: Result<T, SolverError>) -> Result<T, SolverError> {
    let describe = || {
        local
            .as_ref()
            .err()
            .map(ToString::to_string)
            .unwrap_or_default()
    };
    match lowest_failure(ranks, local.is_err(), describe)? {
        Some((rank, message)) if rank != ranks.rank() => Err(SolverError::Rank { rank, message }),
        _ => local,
    }
}
