//! [`ThreadRanks`]: N ranks as threads of one process, over channels.
//! Deterministic: a reduction adds the ranks' values in rank order on every
//! rank, as MPI's reductions do for a fixed number of processes.

use std::collections::VecDeque;
use std::sync::Mutex;
use std::sync::mpsc::{Receiver, Sender, channel};

use super::{RankError, Ranks, Reduce};

/// Point-to-point messages and collectives travel apart, so a fast rank's
/// next collective never overtakes a neighbour message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    PointToPoint = 0,
    Collective = 1,
    /// The sender's rank has ended (returned or panicked): a rank waiting
    /// for more from it gets an error instead of waiting for ever.
    Stopped = 2,
}

/// One message: sender, kind, payload.
type Message = (usize, Kind, Vec<f64>);

/// What a rank has received and not yet read, per kind and sender (each
/// sender's messages arrive in the order sent).
#[derive(Debug)]
struct Inbox {
    receiver: Receiver<Message>,
    pending: [Vec<VecDeque<Vec<f64>>>; 2],
    stopped: Vec<bool>,
}

/// One rank of a group of threads ([`ThreadRanks::group`]).
#[derive(Debug)]
pub struct ThreadRanks {
    rank: usize,
    senders: Vec<Sender<Message>>,
    inbox: Mutex<Inbox>,
}

impl ThreadRanks {
    /// The `size` ranks of one group, rank `k` at index `k`; hand each to
    /// its own thread.
    pub fn group(size: usize) -> Vec<ThreadRanks> {
        let (senders, receivers): (Vec<_>, Vec<_>) = (0..size).map(|_| channel()).unzip();
        receivers
            .into_iter()
            .enumerate()
            .map(|(rank, receiver)| ThreadRanks {
                rank,
                senders: senders.clone(),
                inbox: Mutex::new(Inbox {
                    receiver,
                    pending: [vec![VecDeque::new(); size], vec![VecDeque::new(); size]],
                    stopped: vec![false; size],
                }),
            })
            .collect()
    }

    /// Runs `work` on `size` ranks, each on its own thread with its rank,
    /// and returns their results in rank order.
    pub fn run<R: Send>(size: usize, work: impl Fn(ThreadRanks) -> R + Sync) -> Vec<R> {
        let ranks = Self::group(size);
        let work = &work;
        std::thread::scope(|s| {
            let handles: Vec<_> = ranks
                .into_iter()
                .map(|r| s.spawn(move || work(r)))
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
                .collect()
        })
    }

    fn error(&self, message: impl Into<String>) -> RankError {
        RankError {
            rank: self.rank,
            message: message.into(),
        }
    }

    fn send(&self, to: usize, kind: Kind, data: Vec<f64>) -> Result<(), RankError> {
        let sender = self
            .senders
            .get(to)
            .ok_or_else(|| self.error(format!("no rank {to}")))?;
        sender
            .send((self.rank, kind, data))
            .map_err(|_| self.error(format!("rank {to} has stopped")))
    }

    fn receive(&self, from: usize, kind: Kind) -> Result<Vec<f64>, RankError> {
        let mut inbox = self
            .inbox
            .lock()
            .map_err(|_| self.error("a thread of this rank panicked"))?;
        loop {
            if let Some(data) = inbox.pending[kind as usize]
                .get_mut(from)
                .and_then(VecDeque::pop_front)
            {
                return Ok(data);
            }
            if inbox.stopped.get(from).copied().unwrap_or(true) {
                return Err(self.error(format!("rank {from} has stopped")));
            }
            let (sender, k, data) = inbox
                .receiver
                .recv()
                .map_err(|_| self.error(format!("rank {from} has stopped")))?;
            if k == Kind::Stopped {
                if let Some(s) = inbox.stopped.get_mut(sender) {
                    *s = true;
                }
            } else if let Some(queue) = inbox.pending[k as usize].get_mut(sender) {
                queue.push_back(data);
            }
        }
    }
}

/// A rank that ends tells every other, so none waits for it for ever (a
/// panic on one thread rank fails the others' next exchange with it).
impl Drop for ThreadRanks {
    fn drop(&mut self) {
        for (q, sender) in self.senders.iter().enumerate() {
            if q != self.rank {
                // A rank that has ended already needs no word.
                let _ = sender.send((self.rank, Kind::Stopped, Vec::new()));
            }
        }
    }
}

impl Ranks for ThreadRanks {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.senders.len()
    }

    fn exchange(
        &self,
        neighbours: &[usize],
        outgoing: &[Vec<f64>],
        incoming: &mut [Vec<f64>],
    ) -> Result<(), RankError> {
        for (&q, data) in neighbours.iter().zip(outgoing) {
            self.send(q, Kind::PointToPoint, data.clone())?;
        }
        for (&q, slot) in neighbours.iter().zip(incoming.iter_mut()) {
            *slot = self.receive(q, Kind::PointToPoint)?;
        }
        Ok(())
    }

    fn all_reduce(&self, values: &mut [f64], op: Reduce) -> Result<(), RankError> {
        let size = self.size();
        for q in (0..size).filter(|&q| q != self.rank) {
            self.send(q, Kind::Collective, values.to_vec())?;
        }
        let mine = values.to_vec();
        for q in 0..size {
            let theirs = if q == self.rank {
                mine.clone()
            } else {
                self.receive(q, Kind::Collective)?
            };
            if theirs.len() != values.len() {
                return Err(self.error(format!(
                    "reduction of {} values met {} from rank {q}",
                    values.len(),
                    theirs.len()
                )));
            }
            for (v, t) in values.iter_mut().zip(theirs) {
                *v = if q == 0 { t } else { op.apply(*v, t) };
            }
        }
        Ok(())
    }

    fn broadcast_text(&self, root: usize, text: &mut String) -> Result<(), RankError> {
        if self.rank == root {
            let bytes: Vec<f64> = text.bytes().map(f64::from).collect();
            for q in (0..self.size()).filter(|&q| q != root) {
                self.send(q, Kind::Collective, bytes.clone())?;
            }
        } else {
            let bytes = self.receive(root, Kind::Collective)?;
            let bytes: Vec<u8> = bytes.iter().map(|&b| b as u8).collect();
            *text = String::from_utf8_lossy(&bytes).into_owned();
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reductions_agree_on_every_rank_and_add_in_rank_order() {
        let out = ThreadRanks::run(4, |r| {
            let mut v = [r.rank() as f64, 0.1 * (r.rank() + 1) as f64];
            r.all_reduce(&mut v, Reduce::Sum).map(|()| v)
        });
        let expected = [6.0, ((0.1 + 0.2) + 0.3) + 0.4];
        for v in out {
            assert_eq!(v.ok(), Some(expected));
        }
    }

    #[test]
    fn ring_exchange_delivers_each_neighbours_message() {
        let out = ThreadRanks::run(3, |r| {
            let n = r.size();
            let (left, right) = ((r.rank() + n - 1) % n, (r.rank() + 1) % n);
            let mut neighbours = vec![left, right];
            neighbours.sort_unstable();
            let outgoing: Vec<Vec<f64>> = neighbours
                .iter()
                .map(|&q| vec![(10 * r.rank() + q) as f64])
                .collect();
            let mut incoming = vec![Vec::new(); 2];
            r.exchange(&neighbours, &outgoing, &mut incoming)
                .map(|()| (neighbours, incoming))
        });
        for (me, result) in out.into_iter().enumerate() {
            let (neighbours, incoming) = result.expect("exchange");
            for (q, got) in neighbours.iter().zip(incoming) {
                assert_eq!(got, vec![(10 * q + me) as f64]);
            }
        }
    }

    #[test]
    fn a_panicking_rank_fails_the_others_instead_of_hanging_them() {
        let out = std::panic::catch_unwind(|| {
            ThreadRanks::run(3, |r| {
                if r.rank() == 1 {
                    panic!("rank 1 fails");
                }
                let mut v = [1.0];
                r.all_reduce(&mut v, Reduce::Sum)
            })
        });
        // The run re-raises rank 1's panic once the others have returned
        // (with an error): it ends.
        assert!(out.is_err());
    }

    #[test]
    fn text_broadcast_reaches_every_rank() {
        let out = ThreadRanks::run(3, |r| {
            let mut t = if r.rank() == 2 {
                "det F ≤ 0 at point 7".to_owned()
            } else {
                String::new()
            };
            r.broadcast_text(2, &mut t).map(|()| t)
        });
        assert!(
            out.iter()
                .all(|t| t.as_deref() == Ok("det F ≤ 0 at point 7"))
        );
    }
}
