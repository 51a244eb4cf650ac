//! The implicit solver on several ranks (threads standing in for MPI
//! processes, [`mpm_solver::ranks::ThreadRanks`]) on the strip-loaded von
//! Mises block ([`mpm_solver::ranks::strip_load`]: 192 points, 10 load
//! steps, 51 points (53 with F-bar) end on the yield surface, the load
//! not symmetric about any cut between ranks), the points dealt to the
//! ranks in stripes of cell columns, against the same run on one solver.
//!
//! What must hold (issue 42): one rank is the single solver bit for bit;
//! on 2, 3 and 4 ranks every step takes the same Newton iterations, every
//! rank sees the same residuals bit for bit (each decision is the same
//! everywhere), every point is on exactly one rank, the displacements
//! agree within 10 times the Newton tolerance (relative to the largest
//! displacement), the reactions within 1e-8 and the stresses within 1e-9
//! (relative to the largest). Only the order of the sums over points
//! changes between rank counts, a relative 1e-16 per sum, which Newton's
//! quadratic convergence does not amplify: a point dropped or counted
//! twice in a sum would move the result by percents. With F-bar (patches
//! of one cell) the same holds, the patches staying whole on their ranks
//! (a patch split between ranks is refused). A failure on one rank stops
//! every rank in the same step with the failing rank's error.
//!
//! Measured (2, 3, 4 ranks, both treatments): |Δu|/|u| 1.3e-13 to
//! 2.5e-13 against the 1e-8 allowed, reactions 1.7e-14 to 4.0e-14 of the
//! largest, stresses about 6e-13 of the largest; iterations per step 3 to
//! 5, the same on every rank count.
#![allow(clippy::unwrap_used)]

use mpm_solver::linear::FaerDirect;
use mpm_solver::ranks::strip_load::{
    self, Deal, Differences, Outcome, POINTS, Treatment, differences, yielded,
};
use mpm_solver::ranks::{Ranks, Reduce, ThreadRanks};
use mpm_solver::{Factorisation, LinearSolveError, LinearSolver, NewtonOptions, SolverError};

fn on_threads(size: usize, treatment: Treatment, deal: Deal) -> Vec<Result<Outcome, SolverError>> {
    ThreadRanks::run(size, |r| strip_load::on_ranks(Box::new(r), treatment, deal))
}

fn check_against_single(treatment: Treatment) {
    let single = strip_load::single(treatment).unwrap();
    let plastic = yielded(&single);
    eprintln!("{treatment:?}: {plastic} of 192 points at the yield surface");
    assert!(plastic >= 10, "the case must be plastic");
    let iterations: Vec<usize> = single.residuals.iter().map(Vec::len).collect();

    let one = on_threads(1, treatment, Deal::Cells)
        .pop()
        .unwrap()
        .unwrap();
    assert_eq!(one, single, "one rank is the single solver bit for bit");

    let tolerance = NewtonOptions::default().tolerance;
    for size in [2, 3, 4] {
        let runs: Vec<Outcome> = on_threads(size, treatment, Deal::Cells)
            .into_iter()
            .map(Result::unwrap)
            .collect();
        let mut seen = vec![0; POINTS[0] * POINTS[1]];
        let mut worst = Differences::default();
        for run in &runs {
            assert_eq!(run.residuals, runs[0].residuals, "{size} ranks: residuals");
            assert_eq!(run.reactions, runs[0].reactions);
            run.ids.iter().for_each(|&id| seen[id] += 1);
            let d = differences(&single, run);
            worst.displacement = worst.displacement.max(d.displacement);
            worst.stress = worst.stress.max(d.stress);
            worst.reaction = worst.reaction.max(d.reaction);
        }
        assert!(seen.iter().all(|&k| k == 1), "every point on one rank");
        let steps: Vec<usize> = runs[0].residuals.iter().map(Vec::len).collect();
        assert_eq!(
            steps, iterations,
            "{size} ranks: Newton iterations per step"
        );
        eprintln!(
            "{treatment:?} on {size} ranks: iterations {steps:?}, |Δu|/|u| {:.1e}, |Δσ|/|σ| {:.1e}, |ΔR|/|R| {:.1e}",
            worst.displacement, worst.stress, worst.reaction
        );
        assert!(
            worst.displacement <= 10.0 * tolerance,
            "{size} ranks: {worst:?}"
        );
        assert!(worst.reaction <= 1e-8, "{size} ranks: {worst:?}");
        assert!(worst.stress <= 1e-9, "{size} ranks: {worst:?}");
    }
}

#[test]
fn ranks_reproduce_the_single_solver_without_locking() {
    check_against_single(Treatment::Standard);
}

#[test]
fn ranks_reproduce_the_single_solver_with_fbar() {
    check_against_single(Treatment::FBar);
}

#[test]
fn a_failure_on_one_rank_stops_every_rank_with_its_error() {
    let outcomes = on_threads(3, Treatment::Standard, Deal::Stray);
    // Rank 1's first point strays; the failure names it by its index in
    // the problem (the strip's lowest row: its column), as one process
    // would, not by its index on rank 1 (0).
    let mut named = None;
    for (rank, outcome) in outcomes.iter().enumerate() {
        let Err(SolverError::InStep {
            step: 0, source, ..
        }) = outcome
        else {
            panic!("rank {rank}: {outcome:?}");
        };
        match (rank, &**source) {
            (1, SolverError::Basis { point, .. }) => named = Some(*point),
            (0 | 2, SolverError::Rank { rank: 1, .. }) => {}
            _ => panic!("rank {rank}: {source:?}"),
        }
    }
    let point = named.unwrap();
    assert!(point > 0, "the global id of rank 1's first point");
    for outcome in &outcomes {
        let message = outcome.as_ref().unwrap_err().to_string();
        assert!(
            message.contains(&format!("material point {point} ")),
            "{message}"
        );
    }
}

/// F-bar's patches are cells: with every cell's points on two ranks, the
/// first step stops on every rank with the same error naming a split
/// patch, rather than averaging each half alone. Without a coupled
/// treatment the same deal runs (a point's rank is free).
#[test]
fn a_patch_split_between_ranks_is_refused() {
    for outcome in on_threads(2, Treatment::FBar, Deal::SplitCells) {
        let Err(SolverError::InStep {
            step: 0, source, ..
        }) = &outcome
        else {
            panic!("{outcome:?}");
        };
        let SolverError::InvalidInput(message) = &**source else {
            panic!("{source:?}");
        };
        assert!(message.contains("points of ranks 0 and 1"), "{message}");
    }
    let single = strip_load::single(Treatment::Standard).unwrap();
    for run in on_threads(2, Treatment::Standard, Deal::SplitCells) {
        let run = run.unwrap();
        assert_eq!(run.residuals.len(), single.residuals.len());
        assert!(differences(&single, &run).displacement <= 1e-8);
    }
}

/// A linear solver over ranks ([`LinearSolver::solves_over_ranks`]) made
/// of the direct solver and a second group of thread ranks: it adds the
/// ranks' own values at the entries each says its points touch, then
/// solves the whole system on every rank. If the entries missed one that a
/// rank's points add to, that contribution would be lost and the steps
/// would differ by far more than rounding; with them right, each sum is
/// the replicated path's sum (the same additions, in rank order, with
/// zeros for the entries a rank does not touch), so the runs agree bit
/// for bit.
#[derive(Debug)]
struct Together {
    ranks: ThreadRanks,
    direct: FaerDirect,
    entries: Vec<usize>,
    whole: Vec<f64>,
}

impl LinearSolver for Together {
    fn analyse(
        &mut self,
        _: usize,
        _: &[usize],
        _: &[usize],
        _: bool,
    ) -> Result<(), LinearSolveError> {
        Err(LinearSolveError::Configuration {
            library: "test",
            message: "a solver over ranks is analysed by its parts".into(),
        })
    }

    fn analyse_part(
        &mut self,
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        symmetric: bool,
        entries: &[usize],
    ) -> Result<(), LinearSolveError> {
        assert!(entries.windows(2).all(|w| w[0] < w[1]), "ascending, once");
        self.entries = entries.to_vec();
        self.direct.analyse(n, col_ptr, row_idx, symmetric)
    }

    fn solve(
        &mut self,
        values: &[f64],
        rhs: &mut [f64],
    ) -> Result<Factorisation, LinearSolveError> {
        self.whole.clear();
        self.whole.resize(values.len(), 0.0);
        for &e in &self.entries {
            self.whole[e] = values[e];
        }
        self.ranks.all_reduce(&mut self.whole, Reduce::Sum).unwrap();
        self.direct.solve(&self.whole, rhs)
    }

    fn last_factorisation(&self) -> Option<Factorisation> {
        self.direct.last_factorisation()
    }

    fn nnz(&self) -> usize {
        self.direct.nnz()
    }

    fn solves_over_ranks(&self) -> bool {
        true
    }
}

#[test]
fn a_solver_over_ranks_given_each_ranks_own_entries_solves_the_same_system() {
    for treatment in [Treatment::Standard, Treatment::FBar] {
        for size in [2, 3] {
            let replicated: Vec<Outcome> = on_threads(size, treatment, Deal::Cells)
                .into_iter()
                .map(Result::unwrap)
                .collect();
            let solvers = ThreadRanks::group(size);
            let runs = ThreadRanks::group(size);
            let together: Vec<Outcome> = std::thread::scope(|s| {
                let handles: Vec<_> = runs
                    .into_iter()
                    .zip(solvers)
                    .map(|(r, ranks)| {
                        s.spawn(move || {
                            let linear = Together {
                                ranks,
                                direct: FaerDirect::default(),
                                entries: Vec::new(),
                                whole: Vec::new(),
                            };
                            strip_load::on_ranks_with(
                                Box::new(r),
                                treatment,
                                Deal::Cells,
                                Box::new(linear),
                            )
                        })
                    })
                    .collect();
                handles
                    .into_iter()
                    .map(|h| h.join().unwrap().unwrap())
                    .collect()
            });
            assert_eq!(together, replicated, "{treatment:?} on {size} ranks");
        }
    }
}
