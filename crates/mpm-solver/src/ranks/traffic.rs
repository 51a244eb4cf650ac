//! What a rank sent: [`Counted`] wraps any [`Ranks`] and counts its
//! point-to-point messages, the values they carried and its collectives,
//! for the measurements of a distributed run (halo and migration traffic,
//! reductions per step) and the communication model built on them
//! (`docs/src/benchmarks/scaling.md`).

use std::sync::atomic::{AtomicU64, Ordering};

use super::{RankError, Ranks, Reduce};

/// Counts of what one rank sent.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Traffic {
    /// Point-to-point messages sent ([`Ranks::exchange`], one per
    /// neighbour per call).
    pub messages: u64,
    /// The `f64` values those messages carried (8 bytes each).
    pub values: u64,
    /// Collectives joined ([`Ranks::all_reduce`], [`Ranks::broadcast_text`]).
    pub collectives: u64,
}

impl Traffic {
    /// What was sent since `earlier` (a count taken before).
    pub fn since(self, earlier: Traffic) -> Traffic {
        Traffic {
            messages: self.messages.saturating_sub(earlier.messages),
            values: self.values.saturating_sub(earlier.values),
            collectives: self.collectives.saturating_sub(earlier.collectives),
        }
    }

    /// The sum of two counts.
    pub fn plus(self, other: Traffic) -> Traffic {
        Traffic {
            messages: self.messages + other.messages,
            values: self.values + other.values,
            collectives: self.collectives + other.collectives,
        }
    }
}

/// Ranks `R` whose traffic is counted ([`Ranks::traffic`]).
#[derive(Debug)]
pub struct Counted<R> {
    inner: R,
    messages: AtomicU64,
    values: AtomicU64,
    collectives: AtomicU64,
}

impl<R> Counted<R> {
    /// `inner`, counted from zero.
    pub fn new(inner: R) -> Self {
        Self {
            inner,
            messages: AtomicU64::new(0),
            values: AtomicU64::new(0),
            collectives: AtomicU64::new(0),
        }
    }

    fn count(counter: &AtomicU64, by: usize) {
        counter.fetch_add(by as u64, Ordering::Relaxed);
    }
}

impl<R: Ranks> Ranks for Counted<R> {
    fn rank(&self) -> usize {
        self.inner.rank()
    }

    fn size(&self) -> usize {
        self.inner.size()
    }

    fn exchange(
        &self,
        neighbours: &[usize],
        outgoing: &[Vec<f64>],
        incoming: &mut [Vec<f64>],
    ) -> Result<(), RankError> {
        Self::count(&self.messages, neighbours.len());
        Self::count(&self.values, outgoing.iter().map(Vec::len).sum());
        self.inner.exchange(neighbours, outgoing, incoming)
    }

    fn all_reduce(&self, values: &mut [f64], op: Reduce) -> Result<(), RankError> {
        Self::count(&self.collectives, 1);
        self.inner.all_reduce(values, op)
    }

    fn broadcast_text(&self, root: usize, text: &mut String) -> Result<(), RankError> {
        Self::count(&self.collectives, 1);
        self.inner.broadcast_text(root, text)
    }

    fn traffic(&self) -> Option<Traffic> {
        Some(Traffic {
            messages: self.messages.load(Ordering::Relaxed),
            values: self.values.load(Ordering::Relaxed),
            collectives: self.collectives.load(Ordering::Relaxed),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::{Counted, Traffic};
    use crate::ranks::{Ranks, Reduce, ThreadRanks};

    #[test]
    fn counts_what_each_rank_sent() {
        let counts = ThreadRanks::run(3, |r| {
            let me = r.rank();
            let ranks = Counted::new(r);
            let others: Vec<usize> = (0..3).filter(|&q| q != me).collect();
            // Rank k sends k + 1 values to each other rank.
            let outgoing = vec![vec![1.0; me + 1]; 2];
            let mut incoming = vec![Vec::new(); 2];
            ranks
                .exchange(&others, &outgoing, &mut incoming)
                .expect("exchange");
            let mut v = [me as f64];
            ranks.all_reduce(&mut v, Reduce::Sum).expect("reduction");
            assert_eq!(v[0], 3.0);
            ranks.traffic().expect("counted")
        });
        for (k, t) in counts.iter().enumerate() {
            let expected = Traffic {
                messages: 2,
                values: 2 * (k as u64 + 1),
                collectives: 1,
            };
            assert_eq!(*t, expected, "rank {k}");
        }
        assert_eq!(counts[2].since(counts[0]).values, 4);
        assert_eq!(counts[0].plus(counts[1]).messages, 4);
    }
}
