//! Material points that moved into another rank's cells go to that rank
//! after a step, with their whole state and their global id (one message
//! per neighbour); the points arriving are appended. The state travels as
//! numbers ([`Flat`]), in the order of [`Record`], followed by the point
//! forces and velocity fixities of the points sent ([`Attached`]): those
//! name points by index, which migration changes, so they are held by id
//! while the points move and named by their new indices after.

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

/// A migration message that does not parse.
fn malformed(me: usize, from: usize, numbers: usize, len: usize) -> SolverError {
    RankError {
        rank: me,
        message: format!(
            "malformed migration message from rank {from}: {numbers} numbers, records of {len}"
        ),
    }
    .into()
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

/// The point forces and fixities of a rank's points by global id while
/// the points move.
struct Attached<const D: usize> {
    forces: Vec<(usize, SVector<f64, D>)>,
    fixities: Vec<(usize, usize, f64)>,
}

impl<const D: usize> Attached<D> {
    /// Takes them off `points`, naming each point by its id.
    fn take<S, T, Dom>(points: &mut ExplicitPoints<D, S, T, Dom>) -> Self {
        let id = &points.id;
        Self {
            forces: (points.point_force.drain(..))
                .map(|(p, f)| (id[p], f))
                .collect(),
            fixities: (points.fixed_velocity.drain(..))
                .map(|(p, axis, v)| (id[p], axis, v))
                .collect(),
        }
    }

    fn is_empty(&self) -> bool {
        self.forces.is_empty() && self.fixities.is_empty()
    }

    /// Appends to `out` (after the records) those of the points `leaving`
    /// (their ids, ascending) and keeps the others: a count and
    /// (id, force) rows, a count and (id, axis, velocity) rows.
    fn send(&mut self, leaving: &[usize], out: &mut Vec<f64>) {
        let goes = |id: &usize| leaving.binary_search(id).is_ok();
        let (forces, kept): (Vec<_>, Vec<_>) = self.forces.drain(..).partition(|(id, _)| goes(id));
        self.forces = kept;
        out.push(forces.len() as f64);
        for (id, f) in forces {
            out.push(id as f64);
            out.extend(f.iter());
        }
        let (fixities, kept): (Vec<_>, Vec<_>) =
            self.fixities.drain(..).partition(|(id, _, _)| goes(id));
        self.fixities = kept;
        out.push(fixities.len() as f64);
        for (id, axis, v) in fixities {
            out.extend([id as f64, axis as f64, v]);
        }
    }

    /// Reads what [`Self::send`] appended; `None` for a malformed tail.
    fn receive(&mut self, mut tail: &[f64]) -> Option<()> {
        let count = |tail: &mut &[f64]| {
            let (&n, rest) = tail.split_first()?;
            *tail = rest;
            Some(n as usize)
        };
        let n = count(&mut tail)?;
        let rows = tail.get(..n * (1 + D))?;
        for r in rows.chunks_exact(1 + D) {
            self.forces
                .push((r[0] as usize, SVector::from_column_slice(&r[1..])));
        }
        tail = &tail[n * (1 + D)..];
        let n = count(&mut tail)?;
        let rows = tail.get(..n * 3)?;
        for r in rows.chunks_exact(3) {
            self.fixities.push((r[0] as usize, r[1] as usize, r[2]));
        }
        (tail.len() == n * 3).then_some(())
    }

    /// Gives them back to `points`, each point named by its index now.
    fn give<S, T, Dom>(self, points: &mut ExplicitPoints<D, S, T, Dom>) -> Result<(), SolverError> {
        let size = points.id.iter().max().map_or(0, |m| m + 1);
        let mut index = vec![usize::MAX; size];
        for (p, &id) in points.id.iter().enumerate() {
            index[id] = p;
        }
        let at = |id: usize| {
            index
                .get(id)
                .copied()
                .filter(|&p| p != usize::MAX)
                .ok_or_else(|| {
                    SolverError::InvalidInput(format!(
                        "a force or fixity of point {id}, which is not here"
                    ))
                })
        };
        points.point_force = (self.forces.into_iter())
            .map(|(id, f)| Ok((at(id)?, f)))
            .collect::<Result<_, SolverError>>()?;
        points.fixed_velocity = (self.fixities.into_iter())
            .map(|(id, axis, v)| Ok((at(id)?, axis, v)))
            .collect::<Result<_, SolverError>>()?;
        Ok(())
    }
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
        let mut attached = Attached::take(points);
        let mut leaving: Vec<Vec<usize>> = vec![Vec::new(); n];
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
            leaving[slot].push(points.id[p]);
            swap_remove(points, p);
            sent += 1;
        }
        // Each message: the number of records, the records, then the
        // forces and fixities of the points they carry.
        for (message, ids) in self.outgoing.iter_mut().zip(&mut leaving) {
            ids.sort_unstable();
            let len = Record::len::<D, S, T, Dom>();
            let mut whole = Vec::with_capacity(1 + message.len() + 2);
            whole.push((message.len() / len) as f64);
            whole.append(message);
            attached.send(ids, &mut whole);
            *message = whole;
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
            let records = message.first().map_or(0, |&k| k as usize);
            let body = message.get(1..1 + records * len);
            let tail = message.get(1 + records * len..);
            let (Some(body), Some(tail)) = (body, tail) else {
                return Err(malformed(me, layout.neighbours[slot], message.len(), len));
            };
            if attached.receive(tail).is_none() {
                return Err(malformed(me, layout.neighbours[slot], message.len(), len));
            }
            for r in body.chunks_exact(len) {
                Record::push(points, r);
                received += 1;
            }
        }
        if !attached.is_empty() {
            attached.give(points)?;
        }
        Ok((sent, received))
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector2;

    use super::Migration;
    use crate::explicit::ExplicitPoints;
    use crate::ranks::{Decomposition, Ranks, ThreadRanks};

    /// What a rank holds after the migration, by id: its points, their
    /// forces (x component) and fixities.
    type Held = (Vec<usize>, Vec<(usize, f64)>, Vec<(usize, usize, f64)>);

    /// Two cells, x < 1 on rank 0 and x ≥ 1 on rank 1. Rank 0 holds points
    /// 0, 1, 2, of which 1 has moved into rank 1's cell; rank 1 holds point
    /// 3, which has moved into rank 0's. The forces and fixities go with
    /// their points and are named by the points' new indices.
    #[test]
    fn points_take_their_forces_and_fixities_along() {
        let held: Vec<Held> = ThreadRanks::run(2, |ranks| {
            let me = ranks.rank();
            let (ids, xs) = if me == 0 {
                (vec![0, 1, 2], vec![0.5, 1.5, 0.25])
            } else {
                (vec![3], vec![0.75])
            };
            let n = xs.len();
            let position = xs.iter().map(|&x| Vector2::new(x, 0.5)).collect();
            let mut points: ExplicitPoints<2, (), ()> =
                ExplicitPoints::new(position, vec![1.0; n], 1.0).expect("points");
            points.id = ids;
            let force = |x: f64| Vector2::new(x, 0.0);
            if me == 0 {
                points.point_force = vec![(1, force(1.0)), (2, force(2.0))];
                points.fixed_velocity = vec![(1, 0, 0.1)];
            } else {
                points.point_force = vec![(0, force(3.0))];
                points.fixed_velocity = vec![(0, 1, 0.3)];
            }
            let layout = Decomposition {
                rank_of_cell: vec![0, 1],
                owner_of_node: Vec::new(),
                neighbours: vec![1 - me],
            };
            let cell_of = |x: &Vector2<f64>| Some(usize::from(x[0] >= 1.0));
            let moved = Migration::default()
                .migrate(&ranks, &layout, cell_of, &mut points)
                .expect("migrated");
            assert_eq!(moved, (1, 1), "rank {me}");
            let id = &points.id;
            let mut ids = id.clone();
            ids.sort_unstable();
            let mut forces: Vec<_> = (points.point_force.iter())
                .map(|&(p, f)| (id[p], f[0]))
                .collect();
            forces.sort_by_key(|f| f.0);
            let mut fixities: Vec<_> = (points.fixed_velocity.iter())
                .map(|&(p, c, v)| (id[p], c, v))
                .collect();
            fixities.sort_by_key(|f| f.0);
            (ids, forces, fixities)
        });
        assert_eq!(
            held[0],
            (vec![0, 2, 3], vec![(2, 2.0), (3, 3.0)], vec![(3, 1, 0.3)])
        );
        assert_eq!(held[1], (vec![1], vec![(1, 1.0)], vec![(1, 0, 0.1)]));
    }
}
