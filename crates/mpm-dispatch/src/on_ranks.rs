//! A scene's implicit run on several ranks (MPI processes, or threads in
//! tests): every rank builds the whole problem, keeps the material points
//! [`RankRun`] deals it, and runs the implicit solver on the ranks
//! ([`mpm_solver::ImplicitSolver::on_ranks`]: each rank its own points, the
//! step's system reduced, every Newton decision agreed). The snapshot the
//! observer sees after each step is gathered onto rank 0, which alone
//! observes (writes the outputs); whether it failed is then agreed, so an
//! output error stops every rank with it.

use std::sync::Arc;

use mpm_solver::SolverError;
use mpm_solver::ranks::{self, Ranks, Reduce};

use crate::run::Snapshot;

/// The ranks a program runs on, shared by its runs (a `Debug` handle).
#[derive(Clone)]
pub struct SharedRanks(pub Arc<dyn Ranks>);

impl std::fmt::Debug for SharedRanks {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "rank {} of {}", self.0.rank(), self.0.size())
    }
}

/// The ranks of a distributed run and which of them owns each point.
#[derive(Clone)]
pub struct RankRun {
    /// The communication.
    pub ranks: Arc<dyn Ranks>,
    /// The rank of every material point of the problem, in the problem's
    /// order (e.g. its cell's rank in a METIS partition; a patch's points
    /// on one rank under F-patch).
    pub rank_of_point: Vec<usize>,
    /// The rank of every cell of the mesh, the one holding each point in
    /// `rank_of_point`: an explicit run's points follow their cells (they
    /// migrate when they cross into another rank's); unused by an
    /// implicit run, whose points stay where they were dealt.
    pub rank_of_cell: Vec<usize>,
    /// When an explicit run deals its cells anew; `None`: never.
    pub balance: Option<Balance>,
    /// Writes this rank's piece of every output (each rank its own points,
    /// before rank 0 observes them gathered); `None`: rank 0 alone writes.
    pub pieces: Option<WritePiece>,
}

/// Writes a rank's piece of an output: called on every rank with the
/// output's index (an implicit run's step, an explicit run's output), the
/// rank's own points' snapshot, their indices in the problem and which
/// optional fields the pieces hold; its outcome is decided over the ranks.
pub type WritePiece =
    Arc<dyn Fn(usize, &Snapshot, &[usize], PieceFields) -> Result<(), SolverError> + Send + Sync>;

/// The optional fields every piece of an output holds, decided over the
/// ranks (a rank without points cannot tell from its own snapshot, and
/// the pieces of one output must hold the same arrays).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PieceFields {
    /// The points' velocities (an explicit run).
    pub velocity: bool,
    /// The points' domain boxes (a basis with domains).
    pub domains: bool,
}

impl std::fmt::Debug for RankRun {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "RankRun(rank {} of {}, {} points, {} cells)",
            self.ranks.rank(),
            self.ranks.size(),
            self.rank_of_point.len(),
            self.rank_of_cell.len()
        )
    }
}

/// The new rank of every cell from the number of points in every cell
/// (the same answer on every rank, e.g. METIS weighted by the points).
pub type Repartition = dyn Fn(&[f64]) -> Result<Vec<usize>, SolverError> + Send + Sync;

/// How an explicit run on several ranks keeps its work balanced as the
/// points move: every `every` steps the points per rank are counted; when
/// the largest rank holds more than `threshold` times the mean, the cells
/// are dealt anew by `repartition` and the points moved to their cells'
/// new ranks.
#[derive(Clone)]
pub struct Balance {
    /// Steps between measurements.
    pub every: usize,
    /// The imbalance (largest rank's points over the mean) that triggers
    /// a new deal.
    pub threshold: f64,
    /// The new deal.
    pub repartition: Arc<Repartition>,
}

impl std::fmt::Debug for Balance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Balance(every {} steps past {})",
            self.every, self.threshold
        )
    }
}

/// The imbalance of a deal: the points of the most loaded rank over the
/// mean, from the points in every cell and the rank of every cell on
/// `ranks` ranks (1 for a perfect balance; 1 when there are no points).
pub fn imbalance(loads: &[f64], rank_of_cell: &[usize], ranks: usize) -> f64 {
    let mut per_rank = vec![0.0; ranks.max(1)];
    for (load, &r) in loads.iter().zip(rank_of_cell) {
        if let Some(slot) = per_rank.get_mut(r) {
            *slot += load;
        }
    }
    let total: f64 = per_rank.iter().sum();
    if total <= 0.0 {
        return 1.0;
    }
    let most = per_rank.iter().copied().fold(0.0, f64::max);
    most * per_rank.len() as f64 / total
}

impl RankRun {
    /// This rank's piece of output `index` written, when pieces are
    /// ([`RankRun::pieces`]); the outcome agreed over the ranks.
    ///
    /// # Errors
    /// The transport's, or the lowest failing rank's error, on every rank.
    pub fn write_piece(
        &self,
        index: usize,
        local: &Snapshot,
        ids: &[usize],
    ) -> Result<(), SolverError> {
        let Some(write) = &self.pieces else {
            return Ok(());
        };
        let mut present = [
            f64::from(u8::from(!local.velocity.is_empty())),
            f64::from(u8::from(!local.domain_bounds.is_empty())),
        ];
        self.ranks.all_reduce(&mut present, Reduce::Max)?;
        let fields = PieceFields {
            velocity: present[0] > 0.0,
            domains: present[1] > 0.0,
        };
        ranks::agree(self.ranks.as_ref(), write(index, local, ids, fields))
    }

    /// Whether this is rank 0, the one that observes.
    pub fn is_root(&self) -> bool {
        self.ranks.rank() == 0
    }

    /// The problem's indices of this rank's points, ascending.
    ///
    /// # Errors
    /// [`SolverError::InvalidInput`] when the deal does not name one rank
    /// of the run for each of the problem's `points` points.
    pub fn own_points(&self, points: usize) -> Result<Vec<usize>, SolverError> {
        let size = self.ranks.size();
        if self.rank_of_point.len() != points {
            return Err(SolverError::InvalidInput(format!(
                "the deal names ranks for {} points, the problem has {points}",
                self.rank_of_point.len()
            )));
        }
        if let Some(r) = self.rank_of_point.iter().find(|&&r| r >= size) {
            return Err(SolverError::InvalidInput(format!(
                "the deal names rank {r} of a run on {size} ranks"
            )));
        }
        let me = self.ranks.rank();
        Ok((0..points)
            .filter(|&p| self.rank_of_point[p] == me)
            .collect())
    }
}

/// The per-point quantities of a snapshot, as rows of one width.
struct Rows {
    velocity: bool,
    domain: bool,
}

impl Rows {
    fn width(&self) -> usize {
        3 + 3 + 9 + 9 + 2 + 3 * usize::from(self.velocity) + 6 * usize::from(self.domain)
    }

    fn write(&self, s: &Snapshot, p: usize, out: &mut Vec<f64>) {
        out.extend(s.position[p]);
        out.extend(s.displacement[p]);
        out.extend(s.sigma[p]);
        out.extend(s.f[p]);
        out.extend([s.volume[p], s.plastic_strain[p]]);
        if self.velocity {
            out.extend(s.velocity[p]);
        }
        if self.domain {
            out.extend(s.domain_bounds[p].0);
            out.extend(s.domain_bounds[p].1);
        }
    }

    fn read(&self, row: &[f64], s: &mut Snapshot) {
        let mut at = 0;
        let mut take = |n: usize| {
            let part = &row[at..at + n];
            at += n;
            part
        };
        let three = |x: &[f64]| std::array::from_fn(|i| x[i]);
        let nine = |x: &[f64]| std::array::from_fn(|i| x[i]);
        s.position.push(three(take(3)));
        s.displacement.push(three(take(3)));
        s.sigma.push(nine(take(9)));
        s.f.push(nine(take(9)));
        let scalars = take(2);
        s.volume.push(scalars[0]);
        s.plastic_strain.push(scalars[1]);
        if self.velocity {
            s.velocity.push(three(take(3)));
        }
        if self.domain {
            let lo = three(take(3));
            let hi = three(take(3));
            s.domain_bounds.push((lo, hi));
        }
    }
}

/// The snapshot of the whole problem (`total` points, in the problem's
/// order) on rank 0, from every rank's snapshot `local` of its points
/// `ids`; `None` on the other ranks. Collective. The values travel as
/// they are: the gathered snapshot holds the same bits as the ranks'.
///
/// # Errors
/// The transport's, or ids that do not cover the problem once.
pub fn gather(
    ranks: &dyn Ranks,
    ids: &[usize],
    local: &Snapshot,
    total: usize,
) -> Result<Option<Snapshot>, SolverError> {
    let mut flags = [
        f64::from(u8::from(!local.velocity.is_empty())),
        f64::from(u8::from(!local.domain_bounds.is_empty())),
    ];
    ranks.all_reduce(&mut flags, Reduce::Max)?;
    let rows = Rows {
        velocity: flags[0] > 0.0,
        domain: flags[1] > 0.0,
    };
    let width = rows.width();
    let mut numbers = Vec::with_capacity(ids.len() * width);
    for p in 0..ids.len() {
        rows.write(local, p, &mut numbers);
    }
    let Some(parts) = to_root(ranks, ids, &numbers)? else {
        return Ok(None);
    };
    let (all, _) = rows_by_id(&parts, width, 0, total).map_err(|e| gathered(&e))?;
    // Rank 0's checkpoint, when the run keeps them, is the whole
    // problem's already (the ranks' parts joined when it was made).
    let mut whole = Snapshot {
        load_factor: local.load_factor,
        mesh_nodes: local.mesh_nodes.clone(),
        tangent: local.tangent.clone(),
        checkpoint: local.checkpoint.clone(),
        ..Snapshot::default()
    };
    for row in all.chunks(width) {
        rows.read(row, &mut whole);
    }
    Ok(Some(whole))
}

/// One rank's part of the points, collected on rank 0 ([`to_root`]): the
/// problem's indices of its points, in its order, and its numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// The problem's index of each of the rank's points.
    pub ids: Vec<usize>,
    /// What the rank sent about them.
    pub numbers: Vec<f64>,
}

/// Every rank's `ids` and `numbers` sent to rank 0: there, the parts in
/// rank order; `None` on the other ranks. Collective; one message per rank.
///
/// # Errors
/// The transport's; on rank 0, a message that does not parse.
pub fn to_root(
    ranks: &dyn Ranks,
    ids: &[usize],
    numbers: &[f64],
) -> Result<Option<Vec<Part>>, SolverError> {
    let mut message = Vec::with_capacity(1 + ids.len() + numbers.len());
    message.push(ids.len() as f64);
    message.extend(ids.iter().map(|&p| p as f64));
    message.extend_from_slice(numbers);
    if ranks.rank() != 0 {
        ranks.exchange(&[0], &[message], &mut [Vec::new()])?;
        return Ok(None);
    }
    let others: Vec<usize> = (1..ranks.size()).collect();
    let mut incoming = vec![Vec::new(); others.len()];
    ranks.exchange(&others, &vec![Vec::new(); others.len()], &mut incoming)?;
    let part = |m: &Vec<f64>| {
        let n = m.first().copied().unwrap_or(0.0) as usize;
        let head = m
            .get(1..1 + n)
            .ok_or_else(|| gathered("a message shorter than its ids"))?;
        Ok(Part {
            ids: head.iter().map(|&i| i as usize).collect(),
            numbers: m[1 + n..].to_vec(),
        })
    };
    let parts = std::iter::once(&message).chain(&incoming).map(part);
    parts.collect::<Result<_, SolverError>>().map(Some)
}

/// Each point's rank and place in that rank's part, by id.
pub type Places = Vec<(usize, usize)>;

/// The rows of `width` numbers the `parts` hold after `skip` numbers of
/// their own, one per point, placed by id: all `total` rows, and each
/// point's rank and place in that rank's part.
///
/// # Errors
/// A part of another length than its points, a point twice, beyond
/// `total` or in no part.
pub fn rows_by_id(
    parts: &[Part],
    width: usize,
    skip: usize,
    total: usize,
) -> Result<(Vec<f64>, Places), String> {
    let mut all = vec![f64::NAN; total * width];
    let mut place = vec![(usize::MAX, 0); total];
    for (rank, part) in parts.iter().enumerate() {
        if part.numbers.len() != skip + part.ids.len() * width {
            return Err("a part of another length than its points".into());
        }
        let rows = part.numbers[skip..].chunks_exact(width.max(1));
        for (slot, (&id, row)) in part.ids.iter().zip(rows).enumerate() {
            match place.get_mut(id) {
                Some(p) if p.0 == usize::MAX => *p = (rank, slot),
                _ => return Err("a point twice or beyond the problem".into()),
            }
            all[id * width..(id + 1) * width].copy_from_slice(row);
        }
    }
    if place.iter().any(|p| p.0 == usize::MAX) {
        return Err("a point of no rank".into());
    }
    Ok((all, place))
}

fn gathered(what: &str) -> SolverError {
    SolverError::InvalidInput(format!("gathering the ranks' points: {what}"))
}

/// Calls `observe` with the whole snapshot on rank 0 and agrees on its
/// result over the ranks. Collective.
///
/// # Errors
/// The observer's (on every rank), or the transport's.
pub fn observe_on_root(
    ranks: &dyn Ranks,
    ids: &[usize],
    local: &Snapshot,
    total: usize,
    observe: &mut dyn FnMut(&Snapshot) -> Result<(), SolverError>,
) -> Result<(), SolverError> {
    let whole = gather(ranks, ids, local, total)?;
    let seen = whole.as_ref().map_or(Ok(()), observe);
    ranks::agree(ranks, seen)
}

/// The ranks of a new deal `new` renamed to keep as many points as it can
/// where the old deal `old` has them: METIS numbers its parts anew each
/// time, and a part that holds mostly the points of old rank 3 should be
/// rank 3 again, not move them all. Greedy on the points shared by a new
/// part and an old rank (`loads`: the points of every cell), largest
/// first; each name used once.
pub fn keep_names(old: &[usize], new: &[usize], loads: &[f64], ranks: usize) -> Vec<usize> {
    let mut shared = vec![0.0; ranks * ranks];
    for ((&o, &n), &load) in old.iter().zip(new).zip(loads) {
        if o < ranks && n < ranks {
            shared[n * ranks + o] += load;
        }
    }
    let mut pairs: Vec<usize> = (0..ranks * ranks).collect();
    // Largest overlap first; ties by index, so every rank decides alike.
    pairs.sort_by(|&a, &b| shared[b].total_cmp(&shared[a]).then(a.cmp(&b)));
    let mut name = vec![usize::MAX; ranks];
    let mut taken = vec![false; ranks];
    for k in pairs {
        let (n, o) = (k / ranks, k % ranks);
        if name[n] == usize::MAX && !taken[o] {
            name[n] = o;
            taken[o] = true;
        }
    }
    new.iter()
        .map(|&n| name.get(n).copied().unwrap_or(n))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::{imbalance, keep_names};

    #[test]
    fn a_new_deal_keeps_the_names_of_the_ranks_whose_points_it_keeps() {
        // The old deal: cells 0, 1 on rank 0, cells 2, 3 on rank 1; the
        // new one moves cell 1 and swaps the names.
        let old = [0, 0, 1, 1];
        let new = [1, 0, 0, 0];
        let loads = [4.0, 1.0, 3.0, 3.0];
        // New part 1 holds rank 0's 4 points, new part 0 rank 1's 6 (and
        // 1 of rank 0's): renamed, only cell 1's point moves.
        assert_eq!(keep_names(&old, &new, &loads, 2), [0, 1, 1, 1]);
        // The same deal under the same names stays.
        assert_eq!(keep_names(&old, &old, &loads, 2), old);
    }

    #[test]
    fn the_imbalance_is_the_largest_ranks_points_over_the_mean() {
        // Cells of 4, 0, 2 and 2 points on ranks 0, 0, 1, 1: 4 and 4.
        assert_eq!(imbalance(&[4.0, 0.0, 2.0, 2.0], &[0, 0, 1, 1], 2), 1.0);
        // 6 and 2 points: the mean is 4, the largest 6.
        assert_eq!(imbalance(&[4.0, 2.0, 0.0, 2.0], &[0, 0, 1, 1], 2), 1.5);
        // A rank without cells counts in the mean.
        assert_eq!(imbalance(&[1.0, 1.0], &[0, 0], 2), 2.0);
        assert_eq!(imbalance(&[0.0, 0.0], &[0, 1], 2), 1.0);
    }
}
