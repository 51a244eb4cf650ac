//! The explicit solver on several ranks ([`mpm_solver::ranks`], threads
//! standing in for MPI processes) on the colliding disks
//! ([`mpm_solver::ranks::disks`]), which cross the whole grid, collide
//! and separate, on 1 to 4 ranks with stripe and scattered partitions,
//! against the same run on one solver. One rank is the single solver bit
//! for bit; on N ranks only the order of the nodal additions changes, so
//! positions agree to rounding: 168 steps of about 1e-16 m each stay far
//! below the 1e-12 m allowed. A missing or doubled contribution in the
//! halo would not: one point carries at least 1/16 of a touched node's
//! mass here (quadratic B-splines, 2×2 points per cell), an error of
//! percents in that node's velocity, which moves the disks by more than
//! 1e-6 m within a step.

use mpm_solver::SolverError;
use mpm_solver::ranks::ThreadRanks;
use mpm_solver::ranks::disks::{Deal, Disks, Outcome, largest_difference};

const BOUND: f64 = 1e-12;

fn on_threads(ranks: usize, deal: Deal, disks: Disks) -> Vec<Result<Outcome, SolverError>> {
    ThreadRanks::run(ranks, |r| disks.on_ranks(Box::new(r), deal))
}

#[test]
fn one_rank_is_the_single_solver_bit_for_bit() {
    let single = Disks::STANDARD.single().unwrap();
    let one = on_threads(1, Deal::Stripes, Disks::STANDARD)
        .pop()
        .unwrap()
        .unwrap();
    assert_eq!(one.steps, single.steps);
    assert_eq!(one.points, single.points);
    assert_eq!(one.energies, single.energies);
}

#[test]
fn n_ranks_equal_one_rank_to_rounding() {
    let single = Disks::STANDARD.single().unwrap();
    for (ranks, deal) in [
        (2, Deal::Stripes),
        (3, Deal::Scattered),
        (4, Deal::Stripes),
        (4, Deal::Scattered),
    ] {
        let outcomes: Vec<Outcome> = on_threads(ranks, deal, Disks::STANDARD)
            .into_iter()
            .map(Result::unwrap)
            .collect();
        let (dx, dv) = largest_difference(&single, &outcomes).unwrap();
        let migrated: usize = outcomes.iter().map(|o| o.migrated).sum();
        eprintln!(
            "{ranks} ranks ({deal:?}): max |Δx| {dx:.2e} m, |Δv| {dv:.2e} m/s, {migrated} migrations, {} steps",
            outcomes[0].steps
        );
        assert!(dx < BOUND && dv < BOUND, "{ranks} ranks: {dx:e} {dv:e}");
        assert!(migrated > 0, "the disks must cross between ranks");
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
        for o in &outcomes {
            assert_eq!(o.steps, single.steps, "the same CFL steps on every rank");
            assert!(
                rel(o.energies.0, single.energies.0) < BOUND,
                "kinetic {:?}",
                o.energies
            );
            assert!(
                rel(o.energies.1, single.energies.1) < BOUND,
                "strain {:?}",
                o.energies
            );
        }
    }
}

/// Disks thrown at 50 m/s leave the grid: every rank stops at the same
/// step; the rank that found the point returns the typed error naming
/// its global id, every other rank that error's message.
#[test]
fn a_failure_on_one_rank_stops_every_rank_with_its_error() {
    let thrown = Disks {
        speed: 50.0,
        ..Disks::STANDARD
    };
    let errors: Vec<SolverError> = on_threads(3, Deal::Scattered, thrown)
        .into_iter()
        .map(|o| o.err().unwrap())
        .collect();
    let typed: Vec<_> = errors
        .iter()
        .filter_map(|e| match e {
            SolverError::ExplicitPoint { step, point, .. } => Some((*step, *point)),
            _ => None,
        })
        .collect();
    assert_eq!(typed.len(), 1, "{errors:?}");
    let (step, point) = typed[0];
    for e in &errors {
        if let SolverError::Rank { message, .. } = e {
            assert!(
                message.contains(&format!("explicit step {step} "))
                    && message.contains(&format!("material point {point}:")),
                "{message}"
            );
        }
    }
}
