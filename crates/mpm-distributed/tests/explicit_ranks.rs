//! The explicit solver on ranks dealt by METIS (k-way on the grid's cells,
//! each weighing its points plus its nodes): the colliding disks
//! ([`mpm_solver::ranks::disks`]) on 2, 3 and 4 thread ranks equal the
//! one-solver run to rounding (the bound and its reason: `mpm-solver`'s
//! `tests/ranks.rs`), with points migrating. No test names a partition:
//! they differ between METIS versions.
#![allow(missing_docs, clippy::unwrap_used)]

use mpm_distributed::partition::{MeshView, partition};
use mpm_solver::ranks::ThreadRanks;
use mpm_solver::ranks::disks::{Disks, largest_difference};

#[test]
fn disks_on_metis_partitions_equal_one_solver() {
    let disks = Disks::STANDARD;
    let grid = disks.grid().unwrap();
    let (connectivity, cell_of_point) = disks.cells().unwrap();
    let mesh = MeshView {
        nodes: grid.node_count(),
        nodes_per_element: 4,
        connectivity: &connectivity,
        unit_of_element: None,
        element_of_point: &cell_of_point,
    };
    let single = disks.single().unwrap();
    for ranks in [2, 3, 4] {
        let p = partition(&mesh, ranks).unwrap();
        let outcomes: Vec<_> = ThreadRanks::run(ranks, |r| {
            let layout = p
                .decomposition(&mesh, mpm_solver::ranks::Ranks::rank(&r), 2)
                .unwrap();
            disks.on_cells(Box::new(r), layout.rank_of_cell)
        })
        .into_iter()
        .map(Result::unwrap)
        .collect();
        let (dx, dv) = largest_difference(&single, &outcomes).unwrap();
        let migrated: usize = outcomes.iter().map(|o| o.migrated).sum();
        eprintln!(
            "METIS {ranks} ranks (edge cut {}): max |Δx| {dx:.2e} m, |Δv| {dv:.2e} m/s, {migrated} migrations",
            p.edge_cut
        );
        assert!(dx < 1e-12 && dv < 1e-12, "{ranks} ranks: {dx:e} {dv:e}");
        assert!(migrated > 0, "the disks must cross between ranks");
    }
}

/// The disks dealt in stripes over 4 ranks, dealt anew by METIS from the
/// points per cell every 20 steps: still the one-solver run to rounding,
/// and after each new deal every rank's work (its cells' points plus
/// nodes, METIS's weight) within METIS's balance tolerance (1.03 of the
/// mean) plus one cell's weight (a cell is never split).
#[test]
fn rebalancing_by_metis_keeps_the_run_and_balances_the_work() {
    let disks = Disks::STANDARD;
    let grid = disks.grid().unwrap();
    let (connectivity, _) = disks.cells().unwrap();
    let single = disks.single().unwrap();
    let ranks = 4;
    let stripes: Vec<usize> = (0..grid.cell_count())
        .map(|c| (grid.cell_index(c).unwrap()[0] * ranks / grid.cells_per_axis()[0]).min(ranks - 1))
        .collect();
    let worst_balance = std::sync::Mutex::new(0.0f64);
    let repartition = |loads: &[f64]| {
        // METIS sees each point as one in its cell.
        let element_of_point: Vec<usize> = loads
            .iter()
            .enumerate()
            .flat_map(|(c, &n)| std::iter::repeat_n(c, n as usize))
            .collect();
        let mesh = MeshView {
            nodes: grid.node_count(),
            nodes_per_element: 4,
            connectivity: &connectivity,
            unit_of_element: None,
            element_of_point: &element_of_point,
        };
        let p = partition(&mesh, ranks).unwrap();
        let weights = mpm_distributed::partition::unit_weights(&mesh, grid.cell_count());
        let mut work = vec![0.0; ranks];
        for (c, &r) in p.rank_of_element.iter().enumerate() {
            work[r] += weights[c] as f64;
        }
        let mean = work.iter().sum::<f64>() / ranks as f64;
        let largest_cell = weights.iter().copied().max().unwrap_or(0) as f64;
        let balance = work.iter().fold(0.0f64, |m, &w| m.max(w)) / (1.03 * mean + largest_cell);
        let mut worst = worst_balance.lock().unwrap();
        *worst = worst.max(balance);
        Ok(p.rank_of_element)
    };
    let outcomes: Vec<_> = ThreadRanks::run(ranks, |r| {
        disks.rebalanced(Box::new(r), stripes.clone(), 20, &repartition)
    })
    .into_iter()
    .map(Result::unwrap)
    .collect();
    let (dx, dv) = largest_difference(&single, &outcomes).unwrap();
    let moved: usize = outcomes.iter().map(|o| o.rebalanced).sum();
    let worst = *worst_balance.lock().unwrap();
    eprintln!(
        "rebalanced every 20 steps: {moved} points moved by new deals, max |Δx| {dx:.2e} m, |Δv| {dv:.2e} m/s, worst work / (1.03 mean + one cell) {worst:.3}"
    );
    assert!(dx < 1e-12 && dv < 1e-12, "{dx:e} {dv:e}");
    assert!(
        moved > 0,
        "the first new deal must move points off the stripes"
    );
    assert!(worst <= 1.0, "{worst}");
}
