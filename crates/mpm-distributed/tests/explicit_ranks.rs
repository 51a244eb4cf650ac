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
