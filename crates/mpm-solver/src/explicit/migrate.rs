//! Material points that moved into another rank's cells go to that rank
//! after a step, with their whole state and their global id (one message
//! per neighbour); the points arriving are appended. The state travels as
//! numbers ([`Flat`]), in the order of [`Record`].

use nalgebra::{Matrix3, SVector};

use super::points::ExplicitPoints;
use crate::checkpoint::Flat;
use crate::error::SolverError;
use crate::ranks::{Decomposition, RankError, Ranks};

/// The numbers of one point in a migration message: id, position,
/// velocity, mass, initial and current volume, F, τ, the law's and the
/// transfer's state, the domain and the initial domain.
struct Record;

impl Record {
    fn len<const D: usize, S: Flat, T: Flat, Dom: Flat>() -> usize {
        1 + 2 * D + 3 + 18 + S::LEN + T::LEN + 2 * Dom::LEN
    }

    fn write<const D: usize, S: Flat, T: Flat, Dom: Flat>(
        points: &ExplicitPoints<D, S, T, Dom>,
        p: usize,
        out: &mut Vec<f64>,
    ) {
        out.push(points.id[p] as f64);
        points.position[p].write(out);
        points.velocity[p].write(out);
        out.extend([points.mass[p], points.volume0[p], points.volume[p]]);
        points.f[p].write(out);
        points.tau[p].write(out);
        points.material[p].write(out);
        points.transfer[p].write(out);
        points.domain[p].write(out);
        points.domain0[p].write(out);
    }

    fn push<const D: usize, S: Flat, T: Flat, Dom: Flat>(
        points: &mut ExplicitPoints<D, S, T, Dom>,
        r: &[f64],
    ) {
        let mut at = 0;
        let mut take = |n: usize| {
            let s = &r[at..at + n];
            at += n;
            s
        };
        points.id.push(take(1)[0] as usize);
        points.position.push(SVector::read(take(D)));
        points.velocity.push(SVector::read(take(D)));
        let m = take(3);
        points.mass.push(m[0]);
        points.volume0.push(m[1]);
        points.volume.push(m[2]);
        points.f.push(Matrix3::read(take(9)));
        points.tau.push(Matrix3::read(take(9)));
        points.material.push(S::read(take(S::LEN)));
        points.transfer.push(T::read(take(T::LEN)));
        points.domain.push(Dom::read(take(Dom::LEN)));
        points.domain0.push(Dom::read(take(Dom::LEN)));
    }
}

/// Removes point `p` from every array (the last point takes its place).
fn swap_remove<const D: usize, S, T, Dom>(points: &mut ExplicitPoints<D, S, T, Dom>, p: usize) {
    points.id.swap_remove(p);
    points.position.swap_remove(p);
    points.velocity.swap_remove(p);
    points.mass.swap_remove(p);
    points.volume0.swap_remove(p);
    points.volume.swap_remove(p);
    points.f.swap_remove(p);
    points.tau.swap_remove(p);
    points.material.swap_remove(p);
    points.transfer.swap_remove(p);
    points.domain.swap_remove(p);
    points.domain0.swap_remove(p);
}

/// The messages of a migration, kept between steps.
#[derive(Debug, Default, Clone)]
pub struct Migration {
    outgoing: Vec<Vec<f64>>,
    incoming: Vec<Vec<f64>>,
}

impl Migration {
    /// Sends every point whose cell (`cell_of` its position) belongs to
    /// another rank to that rank and appends the points other ranks send
    /// here; returns (sent, received). A point outside the mesh stays: the
    /// next step reports it.
    ///
    /// # Errors
    /// A point entering the cell of a rank that is not a neighbour (it
    /// moved more than the decomposition's reach in one step); a malformed
    /// message; the transport's failure.
    pub fn migrate<const D: usize, S: Flat, T: Flat, Dom: Flat>(
        &mut self,
        ranks: &dyn Ranks,
        layout: &Decomposition,
        cell_of: impl Fn(&SVector<f64, D>) -> Option<usize>,
        points: &mut ExplicitPoints<D, S, T, Dom>,
    ) -> Result<(usize, usize), SolverError> {
        let me = ranks.rank();
        let n = layout.neighbours.len();
        self.outgoing.resize_with(n, Vec::new);
        self.incoming.resize_with(n, Vec::new);
        self.outgoing.iter_mut().for_each(Vec::clear);
        let mut sent = 0;
        let mut stray = None;
        for p in (0..points.len()).rev() {
            let Some(cell) = cell_of(&points.position[p]) else {
                continue;
            };
            let owner = layout.rank_of_cell[cell];
            if owner == me {
                continue;
            }
            let Some(slot) = layout.slot(owner) else {
                stray.get_or_insert((points.id[p], cell, owner));
                continue;
            };
            Record::write(points, p, &mut self.outgoing[slot]);
            swap_remove(points, p);
            sent += 1;
        }
        // Exchanged even when a point strayed, so no neighbour waits.
        ranks.exchange(&layout.neighbours, &self.outgoing, &mut self.incoming)?;
        if let Some((id, cell, owner)) = stray {
            return Err(SolverError::InvalidInput(format!(
                "rank {me}: point {id} entered cell {cell} of rank {owner}, which is not a neighbour {:?}",
                layout.neighbours
            )));
        }
        let len = Record::len::<D, S, T, Dom>();
        let mut received = 0;
        for (slot, message) in self.incoming.iter().enumerate() {
            if message.len() % len != 0 {
                return Err(RankError {
                    rank: me,
                    message: format!(
                        "malformed migration message from rank {}: {} numbers, records of {len}",
                        layout.neighbours[slot],
                        message.len()
                    ),
                }
                .into());
            }
            for r in message.chunks_exact(len) {
                Record::push(points, r);
                received += 1;
            }
        }
        Ok((sent, received))
    }
}
