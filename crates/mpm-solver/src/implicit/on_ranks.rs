//! The implicit solver on several ranks ([`crate::ranks`]): each rank holds
//! its own material points and the whole mesh; the system of a load step
//! is the same on every rank.
//!
//! - **Active nodes and dofs**: the union of the nodes every rank's points
//!   touch (a reduction of the mesh's node marks), numbered by ascending
//!   mesh id as on one rank, so every rank has the same free dofs.
//! - **Pattern**: the union of the ranks' neighbour lists (one exchange
//!   per load step), so the sparsity pattern is the same everywhere.
//! - **Sums over points** (internal and external force, the stiffness
//!   values, the support weights of the weak-node rule and the rounding
//!   noise bounds): each rank sums its points, then one reduction adds the
//!   ranks' sums.
//! - **Linear solve**: on rank 0 with the solver the options name, its
//!   solution (or its failure) sent to every rank, so every rank holds the
//!   same increment; or, with a solver over ranks (PETSc's parallel
//!   matrices, [`LinearSolver::solves_over_ranks`]), on every rank
//!   together, each giving the entries of its own points
//!   ([`RankLink::own_entries`]) unsummed: the stiffness is then never
//!   replicated.
//! - **Decisions**: the residual is reduced before the convergence test,
//!   and every failure of a rank's points (a constitutive update, a basis
//!   evaluation, the commit) is decided together ([`RankLink::agree_step`],
//!   [`crate::ranks::agree`]): every rank backtracks, cuts the step or
//!   stops at the same point, with the lowest failing rank's error.
//!
//! One rank is the single solver bit for bit (no reduction changes a
//! number). On N ranks only the order of the additions over points
//! changes. What stays replicated (the nodal vectors on every rank, and
//! without a solver over ranks the matrix values too, one rank solving)
//! suits a machine's worth of ranks, not hundreds
//! (docs/src/guide/distributed.md).

use crate::error::{SolverError, StepFailure};
use crate::linear::{LinearSolveError, LinearSolver};
use crate::locking::PatchAssignment;
use crate::ranks::{self, RankError, Ranks, Reduce};
use crate::stages::system::{Candidates, NONE, StepSystem};

/// The implicit solver's link to the other ranks of a distributed run.
pub(super) struct RankLink {
    ranks: Box<dyn Ranks>,
    /// The first transport failure of a stage that cannot return it (the
    /// driver reads it before it uses the stage's result).
    failure: Option<SolverError>,
    /// The problem's index of each of this rank's points, which failures
    /// name; empty: the local indices.
    ids: Vec<usize>,
    /// This rank's own neighbour lists of the load step (CSR over the
    /// active nodes), before [`RankLink::unite_neighbours`] united them.
    own_ptr: Vec<usize>,
    own: Vec<u32>,
}

impl std::fmt::Debug for RankLink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RankLink")
            .field("rank", &self.ranks.rank())
            .field("size", &self.ranks.size())
            .field("failure", &self.failure)
            .finish()
    }
}

/// Whether a failure of a Newton iterate is one that halving the
/// correction may cure ([`super::MAX_BACKTRACKS`]).
pub(super) fn backtracks(f: &StepFailure) -> bool {
    matches!(
        f,
        StepFailure::Constitutive { .. }
            | StepFailure::ExcessiveIncrement { .. }
            | StepFailure::OnRank {
                backtrack: true,
                ..
            }
    )
}

impl RankLink {
    /// A link through `ranks`.
    pub(super) fn new(ranks: Box<dyn Ranks>) -> Self {
        Self {
            ranks,
            failure: None,
            ids: Vec::new(),
            own_ptr: Vec::new(),
            own: Vec::new(),
        }
    }

    /// Names this rank's points by `ids` (their indices in the problem) in
    /// the failures it reports.
    pub(super) fn name_points(&mut self, ids: Vec<usize>) {
        self.ids = ids;
    }

    /// The problem's index of local point `p`.
    fn global(&self, p: usize) -> usize {
        self.ids.get(p).copied().unwrap_or(p)
    }

    /// `f` naming its point by the problem's index.
    fn named_step(&self, mut f: StepFailure) -> StepFailure {
        if let StepFailure::Constitutive { point, .. }
        | StepFailure::ExcessiveIncrement { point, .. } = &mut f
        {
            *point = self.global(*point);
        }
        f
    }

    /// `e` naming its point by the problem's index.
    fn named(&self, mut e: SolverError) -> SolverError {
        if let SolverError::Basis { point, .. } | SolverError::DomainUpdate { point, .. } = &mut e {
            *point = self.global(*point);
        }
        e
    }

    /// This rank and the number of ranks.
    pub(super) fn rank_and_size(&self) -> (usize, usize) {
        (self.ranks.rank(), self.ranks.size())
    }

    /// The first transport failure since the last call, if any.
    pub(super) fn take_failure(&mut self) -> Option<SolverError> {
        self.failure.take()
    }

    fn record(&mut self, result: Result<(), RankError>) {
        if let Err(e) = result {
            self.failure.get_or_insert(e.into());
        }
    }

    /// Replaces `values` by their sum over the ranks.
    pub(super) fn sum(&mut self, values: &mut [f64]) {
        if self.ranks.size() > 1 {
            let result = self.ranks.all_reduce(values, Reduce::Sum);
            self.record(result);
        }
    }

    /// A local outcome decided over the ranks ([`ranks::agree`]).
    pub(super) fn agree(&self, local: Result<(), SolverError>) -> Result<(), SolverError> {
        ranks::agree(self.ranks.as_ref(), local.map_err(|e| self.named(e)))
    }

    /// A local failure of a Newton iterate decided over the ranks: when
    /// any rank failed, the lowest failing rank returns its own failure
    /// and every other rank [`StepFailure::OnRank`] with its message and
    /// whether it backtracks, so that all ranks take the same branch.
    pub(super) fn agree_step(&mut self, local: Result<(), StepFailure>) -> Result<(), StepFailure> {
        let local = local.map_err(|f| self.named_step(f));
        // The first character says whether the failure backtracks.
        let describe = || match &local {
            Err(f) => format!("{}{f}", if backtracks(f) { 'b' } else { 'f' }),
            Ok(()) => String::new(),
        };
        match ranks::lowest_failure(self.ranks.as_ref(), local.is_err(), describe) {
            Err(e) => Err(StepFailure::OnRank {
                rank: e.rank,
                message: e.message,
                backtrack: false,
            }),
            Ok(Some((rank, text))) if rank != self.ranks.rank() => Err(StepFailure::OnRank {
                rank,
                backtrack: text.starts_with('b'),
                message: text.get(1..).unwrap_or_default().to_owned(),
            }),
            Ok(_) => local,
        }
    }

    /// Marks the nodes any rank's points touch: `marks` holds 0 for a
    /// node this rank touches and [`NONE`] otherwise, on entry and exit.
    pub(super) fn unite_nodes(&mut self, marks: &mut [u32]) {
        if self.ranks.size() == 1 {
            return;
        }
        let mut touched: Vec<f64> = marks.iter().map(|&m| f64::from(m == 0)).collect();
        let result = self.ranks.all_reduce(&mut touched, Reduce::Max);
        self.record(result);
        for (m, &t) in marks.iter_mut().zip(&touched) {
            *m = if t > 0.0 { 0 } else { NONE };
        }
    }

    /// The union over the ranks of the neighbour lists `nb_ptr`/`nb` (CSR
    /// over the active nodes): every rank sends its lists to every other
    /// one. `rebuild` receives a function that pushes node `w`'s
    /// neighbours from every rank (the caller sorts and deduplicates). The
    /// rank's own lists are kept for [`RankLink::own_entries`].
    pub(super) fn unite_neighbours(
        &mut self,
        nb_ptr: Vec<usize>,
        nb: Vec<u32>,
        rebuild: &mut dyn FnMut(&Candidates<'_>),
    ) {
        let (me, size) = self.rank_and_size();
        let others: Vec<usize> = (0..size).filter(|&q| q != me).collect();
        // Per node with neighbours: its id, their count, then them.
        let mut mine = Vec::with_capacity(nb.len() + 2 * nb_ptr.len());
        for w in 0..nb_ptr.len().saturating_sub(1) {
            let list = &nb[nb_ptr[w]..nb_ptr[w + 1]];
            if !list.is_empty() {
                mine.push(w as f64);
                mine.push(list.len() as f64);
                mine.extend(list.iter().map(|&v| f64::from(v)));
            }
        }
        let outgoing = vec![mine; others.len()];
        let mut incoming = vec![Vec::new(); others.len()];
        let result = self.ranks.exchange(&others, &outgoing, &mut incoming);
        self.record(result);
        let n = nb_ptr.len().saturating_sub(1);
        let mut received: Vec<Vec<u32>> = vec![Vec::new(); n];
        for message in &incoming {
            let mut k = 0;
            while k + 1 < message.len() {
                let (w, count) = (message[k] as usize, message[k + 1] as usize);
                let list = message.get(k + 2..k + 2 + count).unwrap_or_default();
                if let Some(into) = received.get_mut(w) {
                    into.extend(list.iter().map(|&v| v as u32));
                }
                k += 2 + count;
            }
        }
        rebuild(&|w, push| {
            nb[nb_ptr[w]..nb_ptr[w + 1]]
                .iter()
                .chain(&received[w])
                .for_each(|&v| push(v));
        });
        self.own_ptr = nb_ptr;
        self.own = nb;
    }

    /// Checks that no patch of a coupled locking treatment holds points
    /// of two ranks (its average would miss the other rank's points).
    ///
    /// # Errors
    /// [`SolverError::InvalidInput`] naming the patch and two of its ranks.
    pub(super) fn check_patches(
        &mut self,
        assignment: &PatchAssignment,
    ) -> Result<(), SolverError> {
        let me = self.ranks.rank() as f64;
        let mut count = [assignment
            .patch
            .iter()
            .map(|&q| q as f64 + 1.0)
            .fold(0.0, f64::max)];
        self.ranks.all_reduce(&mut count, Reduce::Max)?;
        let n = count[0] as usize;
        let mut lowest = vec![f64::INFINITY; n];
        let mut highest = vec![f64::NEG_INFINITY; n];
        for &q in &assignment.patch {
            lowest[q as usize] = me;
            highest[q as usize] = me;
        }
        self.ranks.all_reduce(&mut lowest, Reduce::Min)?;
        self.ranks.all_reduce(&mut highest, Reduce::Max)?;
        match (0..n).find(|&q| lowest[q] < highest[q]) {
            None => Ok(()),
            Some(q) => Err(SolverError::InvalidInput(format!(
                "patch {q} of the locking treatment holds points of ranks {} and {}: the \
                 points of a patch must live on one rank",
                lowest[q], highest[q]
            ))),
        }
    }

    /// Solves the system of the summed values (or, with a solver over
    /// ranks, of every rank's own values: [`LinearSolver::solves_over_ranks`])
    /// and decides the outcome together: on return `rhs` holds the same
    /// solution on every rank. Without a solver over ranks, rank 0 solves
    /// and sends its solution.
    ///
    /// # Errors
    /// The lowest failing rank's own error there; elsewhere a
    /// [`LinearSolveError::Backend`] (or [`LinearSolveError::Configuration`]
    /// when that rank's was one) carrying its message.
    pub(super) fn solve(
        &mut self,
        linear: &mut dyn LinearSolver,
        values: &[f64],
        rhs: &mut [f64],
    ) -> Result<(), LinearSolveError> {
        if self.ranks.size() == 1 {
            return linear.solve(values, rhs).map(|_| ());
        }
        let together = linear.solves_over_ranks();
        let solves_here = together || self.ranks.rank() == 0;
        let local = if solves_here {
            linear.solve(values, rhs).map(|_| ())
        } else {
            Ok(())
        };
        let transport = |e: RankError| LinearSolveError::Backend {
            library: "rank transport",
            message: e.to_string(),
        };
        // The first character says whether the failure is fatal.
        let describe = || match &local {
            Err(e @ LinearSolveError::Configuration { .. }) => format!("c{e}"),
            Err(e) => format!("f{e}"),
            Ok(()) => String::new(),
        };
        match ranks::lowest_failure(self.ranks.as_ref(), local.is_err(), describe)
            .map_err(transport)?
        {
            None if together => Ok(()),
            None => {
                if !solves_here {
                    rhs.fill(0.0);
                }
                // Zeros elsewhere: the sum is rank 0's solution exactly.
                self.ranks.all_reduce(rhs, Reduce::Sum).map_err(transport)
            }
            Some((rank, _)) if rank == self.ranks.rank() => local,
            Some((_, text)) => {
                let message = text.get(1..).unwrap_or_default().to_owned();
                let library = "another rank's linear solver";
                Err(if text.starts_with('c') {
                    LinearSolveError::Configuration { library, message }
                } else {
                    LinearSolveError::Backend { library, message }
                })
            }
        }
    }

    /// The positions in the united pattern of `sys` of the entries this
    /// rank's points add to (ascending): those of its own neighbour lists,
    /// kept by [`RankLink::unite_neighbours`].
    pub(super) fn own_entries<const D: usize>(&self, sys: &StepSystem<D>) -> Vec<usize> {
        let (own_ptr, own) = (&self.own_ptr, &self.own);
        let mut entries = Vec::with_capacity(own.len() * D * D);
        for w in 0..own_ptr.len().saturating_sub(1) {
            let all = &sys.nb[sys.nb_ptr[w]..sys.nb_ptr[w + 1]];
            let blocks = &sys.block_map[sys.nb_ptr[w] * D * D..];
            for &v in &own[own_ptr[w]..own_ptr[w + 1]] {
                let Ok(pos) = all.binary_search(&v) else {
                    continue;
                };
                let block = &blocks[pos * D * D..(pos + 1) * D * D];
                entries.extend(
                    block
                        .iter()
                        .filter(|&&at| at != NONE)
                        .map(|&at| sys.block_ptr[w] + at as usize),
                );
            }
        }
        entries.sort_unstable();
        entries
    }
}
