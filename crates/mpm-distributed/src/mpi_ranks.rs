//! MPI processes as the ranks of a distributed run (feature `mpi`): the
//! [`Ranks`] of `mpm-solver` over `MPI_COMM_WORLD` with the `mpi` crate.
//! A neighbour exchange posts every send (non-blocking), then receives
//! one message from each neighbour in turn (probed, so of any length);
//! reductions are `MPI_Allreduce`, which on a fixed number of processes
//! combines in a fixed order, so every rank gets the same bits.
//!
//! [`Mpi::init`] installs a panic hook that calls `MPI_Abort`: a panic on
//! one rank would otherwise leave the others waiting in their next
//! exchange for ever. Errors the solver can name are decided collectively
//! instead ([`mpm_solver::ranks::agree`]) and end every rank cleanly.

use mpi::collective::SystemOperation;
use mpi::environment::Universe;
use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, CommunicatorCollectives, Destination, Root, Source};
use mpm_solver::ranks::{RankError, Ranks, Reduce};

/// MPI, initialised for this process; finalised when dropped (when this
/// value initialised it).
pub struct Mpi {
    _universe: Option<Universe>,
}

impl std::fmt::Debug for Mpi {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let r = self.ranks();
        write!(f, "Mpi(rank {} of {})", r.rank, r.size)
    }
}

impl Mpi {
    /// Initialises MPI (any thread may call it, one at a time), or joins
    /// an MPI that PETSc initialised, and installs the abort-on-panic hook.
    pub fn init() -> Self {
        let universe = mpi::initialize_with_threading(mpi::Threading::Serialized).map(|(u, _)| u);
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            previous(info);
            // Stop every rank: the others may be waiting for this one.
            SimpleCommunicator::world().abort(101)
        }));
        Self {
            _universe: universe,
        }
    }

    /// This process's rank in `MPI_COMM_WORLD`.
    pub fn ranks(&self) -> MpiRanks {
        let world = SimpleCommunicator::world();
        MpiRanks {
            rank: usize::try_from(world.rank()).unwrap_or(0),
            size: usize::try_from(world.size()).unwrap_or(1),
        }
    }
}

/// One MPI process's [`Ranks`].
#[derive(Debug, Clone, Copy)]
pub struct MpiRanks {
    rank: usize,
    size: usize,
}

impl MpiRanks {
    fn process(&self, q: usize) -> Result<i32, RankError> {
        i32::try_from(q)
            .ok()
            .filter(|_| q < self.size)
            .ok_or(RankError {
                rank: self.rank,
                message: format!("no rank {q} among {}", self.size),
            })
    }
}

impl Ranks for MpiRanks {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.size
    }

    fn exchange(
        &self,
        neighbours: &[usize],
        outgoing: &[Vec<f64>],
        incoming: &mut [Vec<f64>],
    ) -> Result<(), RankError> {
        let world = SimpleCommunicator::world();
        let targets = neighbours
            .iter()
            .map(|&q| self.process(q))
            .collect::<Result<Vec<_>, _>>()?;
        mpi::request::scope(|scope| {
            let sends: Vec<_> = targets
                .iter()
                .zip(outgoing)
                .map(|(&q, data)| world.process_at_rank(q).immediate_send(scope, &data[..]))
                .collect();
            for (&q, slot) in targets.iter().zip(incoming.iter_mut()) {
                *slot = world.process_at_rank(q).receive_vec::<f64>().0;
            }
            for s in sends {
                s.wait();
            }
        });
        Ok(())
    }

    fn all_reduce(&self, values: &mut [f64], op: Reduce) -> Result<(), RankError> {
        let world = SimpleCommunicator::world();
        let local = values.to_vec();
        let op = match op {
            Reduce::Sum => SystemOperation::sum(),
            Reduce::Max => SystemOperation::max(),
            Reduce::Min => SystemOperation::min(),
        };
        world.all_reduce_into(&local[..], values, op);
        Ok(())
    }

    fn broadcast_text(&self, root: usize, text: &mut String) -> Result<(), RankError> {
        let world = SimpleCommunicator::world();
        let root = world.process_at_rank(self.process(root)?);
        let mut len = [text.len() as u64];
        root.broadcast_into(&mut len[..]);
        let mut bytes = text.as_bytes().to_vec();
        bytes.resize(usize::try_from(len[0]).unwrap_or(0), 0);
        root.broadcast_into(&mut bytes[..]);
        *text = String::from_utf8_lossy(&bytes).into_owned();
        Ok(())
    }
}
