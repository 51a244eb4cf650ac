//! The nodal sums of an explicit step over the ranks: every rank scatters
//! its own points into its grid buffer; then the sums of each node some
//! rank touches but does not own go to the node's owner in one message per
//! neighbour (the reverse exchange, with the node numbers), the owner adds
//! them to its own, and sends the totals back along the same lists (the
//! forward exchange, values only). Afterwards every rank holds, for every
//! node its points touch, the same sums a single rank holding all points
//! would (up to the order of the additions), bit for bit the same on every
//! rank that touches the node.
//!
//! A node counts as touched when its sums are not all zero; a point
//! exactly on a cell face gives zero weight and, unstressed, zero force to
//! the nodes across the face, and the rank then reads its own zero for a
//! node whose velocity it multiplies by a zero weight — only the velocity
//! gradient of such a point can differ (see `docs/src/guide/distributed.md`).

use super::{Decomposition, RankError, Ranks};
use crate::error::SolverError;
use crate::explicit::{GridBuffer, grid::NodeSums};

/// Numbers per node in a message: mass, momentum, force.
const fn per_node(d: usize) -> usize {
    1 + 2 * d
}

/// The lists and buffers of the two exchanges, kept between steps (no
/// allocation per step once they have grown).
#[derive(Debug, Default, Clone)]
pub struct Halo {
    /// Per neighbour slot: the nodes this rank sent (reverse exchange), in
    /// message order.
    sent: Vec<Vec<usize>>,
    /// Per neighbour slot: the nodes received (owned here), in message
    /// order.
    received: Vec<Vec<usize>>,
    outgoing: Vec<Vec<f64>>,
    incoming: Vec<Vec<f64>>,
}

impl Halo {
    fn reset(&mut self, neighbours: usize) {
        for v in [&mut self.sent, &mut self.received] {
            v.resize_with(neighbours, Vec::new);
            v.iter_mut().for_each(Vec::clear);
        }
        for v in [&mut self.outgoing, &mut self.incoming] {
            v.resize_with(neighbours, Vec::new);
            v.iter_mut().for_each(Vec::clear);
        }
    }

    /// Adds the sums of `grid` over the ranks (module docs). `grid` holds
    /// this rank's sums; afterwards it holds the totals of every node it
    /// touched or owns and was touched elsewhere.
    ///
    /// # Errors
    /// A touched node whose owner is not a neighbour (the decomposition's
    /// neighbours are too few for the basis's reach); a malformed message;
    /// the transport's failure.
    pub fn sum<const D: usize>(
        &mut self,
        ranks: &dyn Ranks,
        layout: &Decomposition,
        grid: &mut GridBuffer<D>,
    ) -> Result<(), SolverError> {
        // A rank that fails still takes part in both exchanges (with what
        // it packed), so no neighbour waits for it; the caller decides
        // the first failure over the ranks.
        self.reset(layout.neighbours.len());
        let packed = self.pack_reverse(ranks.rank(), layout, grid);
        ranks.exchange(&layout.neighbours, &self.outgoing, &mut self.incoming)?;
        let added = self.add_received(ranks.rank(), layout, grid);
        self.pack_forward(grid);
        ranks.exchange(&layout.neighbours, &self.outgoing, &mut self.incoming)?;
        let set = self.set_totals(ranks.rank(), layout, grid);
        packed.and(added).and(set)
    }

    /// The reverse messages: each touched node owned elsewhere, with its
    /// number, to its owner.
    fn pack_reverse<const D: usize>(
        &mut self,
        me: usize,
        layout: &Decomposition,
        grid: &GridBuffer<D>,
    ) -> Result<(), SolverError> {
        for i in grid.lo..grid.hi.min(grid.nodes.len()) {
            let n = &grid.nodes[i];
            if *n == NodeSums::ZERO || layout.owner_of_node[i] == me {
                continue;
            }
            let owner = layout.owner_of_node[i];
            let slot = layout.slot(owner).ok_or_else(|| {
                SolverError::InvalidInput(format!(
                    "rank {me}: the points touch node {i}, owned by rank {owner}, which is not a neighbour {:?}",
                    layout.neighbours
                ))
            })?;
            self.sent[slot].push(i);
            let out = &mut self.outgoing[slot];
            out.push(i as f64);
            out.push(n.mass);
            out.extend_from_slice(n.momentum.as_slice());
            out.extend_from_slice(n.force.as_slice());
        }
        Ok(())
    }

    /// Adds the neighbours' sums to the owned nodes.
    fn add_received<const D: usize>(
        &mut self,
        me: usize,
        layout: &Decomposition,
        grid: &mut GridBuffer<D>,
    ) -> Result<(), SolverError> {
        let stride = 1 + per_node(D);
        for (slot, message) in self.incoming.iter().enumerate() {
            if message.len() % stride != 0 {
                return Err(malformed(me, layout.neighbours[slot], message.len()).into());
            }
            for record in message.chunks_exact(stride) {
                let i = record[0] as usize;
                if i >= grid.nodes.len() || layout.owner_of_node[i] != me {
                    return Err(malformed(me, layout.neighbours[slot], i).into());
                }
                let n = &mut grid.nodes[i];
                n.mass += record[1];
                for c in 0..D {
                    n.momentum[c] += record[2 + c];
                    n.force[c] += record[2 + D + c];
                }
                grid.lo = grid.lo.min(i);
                grid.hi = grid.hi.max(i + 1);
                self.received[slot].push(i);
            }
        }
        Ok(())
    }

    /// The forward messages: the totals of the received nodes, in the
    /// order received.
    fn pack_forward<const D: usize>(&mut self, grid: &GridBuffer<D>) {
        for (out, nodes) in self.outgoing.iter_mut().zip(&self.received) {
            out.clear();
            for &i in nodes {
                let n = &grid.nodes[i];
                out.push(n.mass);
                out.extend_from_slice(n.momentum.as_slice());
                out.extend_from_slice(n.force.as_slice());
            }
        }
    }

    /// The owners' totals replace this rank's partial sums.
    fn set_totals<const D: usize>(
        &mut self,
        me: usize,
        layout: &Decomposition,
        grid: &mut GridBuffer<D>,
    ) -> Result<(), SolverError> {
        let stride = per_node(D);
        for (slot, (message, nodes)) in self.incoming.iter().zip(&self.sent).enumerate() {
            if message.len() != stride * nodes.len() {
                return Err(malformed(me, layout.neighbours[slot], message.len()).into());
            }
            for (record, &i) in message.chunks_exact(stride).zip(nodes) {
                let n = &mut grid.nodes[i];
                n.mass = record[0];
                for c in 0..D {
                    n.momentum[c] = record[1 + c];
                    n.force[c] = record[1 + D + c];
                }
            }
        }
        Ok(())
    }
}

fn malformed(me: usize, from: usize, what: usize) -> RankError {
    RankError {
        rank: me,
        message: format!("malformed halo message from rank {from} ({what})"),
    }
}
