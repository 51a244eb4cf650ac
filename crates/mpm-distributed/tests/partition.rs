//! The partition invariants of distributed runs (issue 42), on the
//! double-notched plate with F-patch (3,072 ten-node parents split into
//! 24,576 tetrahedra) and on the vane slice's quick mesh, over 1, 2, 3
//! and 4 ranks: every unit, element and point owned once; no patch split;
//! every node owned by a rank that touches it; halo plans symmetric; the
//! work (points plus nodes) balanced within METIS's tolerance. No test names a partition:
//! they differ between METIS versions.
#![allow(missing_docs, clippy::unwrap_used)]

use std::path::Path;

use mpm_distributed::partition::{MeshView, Partition, PartitionError, partition, unit_weights};
use mpm_scene::build::SceneMesh;
use mpm_scene::{self as scene, Problem};

/// The committed scene `name` with `overrides`: its tetrahedra, their
/// patches and the element of every material point.
fn plate_mesh(
    name: &str,
    overrides: &[&str],
) -> (mpm_mesh::SimplexMesh<3>, Vec<usize>, Vec<usize>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let set: Vec<String> = overrides.iter().map(|s| (*s).to_owned()).collect();
    let (scene, src) = scene::parse(&text, &path.to_string_lossy(), &set).unwrap();
    let problem = Problem::<3>::build(&scene, &src, scene.solver.padding()).unwrap();
    let SceneMesh::Simplex(mesh) = &problem.mesh else {
        panic!("{name} is on a simplex mesh");
    };
    let patches = problem.patch_of_element.clone().unwrap();
    let elements = problem
        .position
        .iter()
        .map(|x| mesh.locate(x, None).unwrap().element)
        .collect();
    ((**mesh).clone(), patches, elements)
}

fn view<'a>(
    mesh: &'a mpm_mesh::SimplexMesh<3>,
    patches: &'a [usize],
    points: &'a [usize],
) -> MeshView<'a> {
    MeshView {
        nodes: mesh.node_count(),
        nodes_per_element: 4,
        connectivity: mesh.connectivity(),
        unit_of_element: Some(patches),
        element_of_point: points,
    }
}

/// The invariants of `p` on `mesh` (module docs).
fn assert_invariants(mesh: &MeshView<'_>, p: &Partition) {
    let elements = mesh.connectivity.len() / mesh.nodes_per_element;
    // Every unit, element and point has exactly one rank, each below N,
    // and every rank owns something.
    assert_eq!(p.rank_of_element.len(), elements);
    assert_eq!(p.rank_of_point.len(), mesh.element_of_point.len());
    assert!(p.rank_of_unit.iter().all(|&r| r < p.ranks));
    for r in 0..p.ranks {
        assert!(p.rank_of_unit.contains(&r), "rank {r} owns no unit");
    }
    // No patch split: every element of a unit on the unit's rank, and
    // every point on its element's.
    let unit = |e: usize| mesh.unit_of_element.map_or(e, |u| u[e]);
    for e in 0..elements {
        assert_eq!(p.rank_of_element[e], p.rank_of_unit[unit(e)], "element {e}");
    }
    for (k, &e) in mesh.element_of_point.iter().enumerate() {
        assert_eq!(p.rank_of_point[k], p.rank_of_element[e], "point {k}");
    }
    // Every node used by an element is owned by the lowest rank touching it.
    let mut touching = vec![Vec::new(); mesh.nodes];
    for e in 0..elements {
        for &n in &mesh.connectivity[e * mesh.nodes_per_element..(e + 1) * mesh.nodes_per_element] {
            touching[n].push(p.rank_of_element[e]);
        }
    }
    for (n, ranks) in touching.iter().enumerate() {
        assert_eq!(p.owner_of_node[n], ranks.iter().min().copied(), "node {n}");
    }
    // Halo plans symmetric: what a sends to b is what b receives from a,
    // node for node and in the same order.
    let plans: Vec<_> = (0..p.ranks).map(|r| p.halo_plan(mesh, r)).collect();
    for (a, plan) in plans.iter().enumerate() {
        for (b, nodes) in &plan.send {
            let back = plans[*b].receive.iter().find(|(r, _)| *r == a);
            assert_eq!(back.map(|(_, n)| n), Some(nodes), "send {a} -> {b}");
            assert!(nodes.iter().all(|&n| p.owner_of_node[n] == Some(*b)));
        }
        for (b, nodes) in &plan.receive {
            let there = plans[*b].send.iter().find(|(r, _)| *r == a);
            assert_eq!(there.map(|(_, n)| n), Some(nodes), "receive {a} <- {b}");
        }
    }
}

/// The work per rank (points plus nodes of its units, the weight METIS
/// balances) within METIS's default k-way imbalance tolerance (1.03) of
/// the mean, plus one unit's weight (a patch cannot be split, so the
/// balance is only as fine as the heaviest unit).
fn assert_balanced(mesh: &MeshView<'_>, p: &Partition) {
    let weights = unit_weights(mesh, p.rank_of_unit.len());
    let mut per_rank = vec![0i64; p.ranks];
    for (u, &r) in p.rank_of_unit.iter().enumerate() {
        per_rank[r] += i64::from(weights[u]);
    }
    let mean = per_rank.iter().sum::<i64>() as f64 / p.ranks as f64;
    let heaviest = f64::from(*weights.iter().max().unwrap());
    let most = *per_rank.iter().max().unwrap() as f64;
    assert!(
        most <= 1.03 * mean + heaviest,
        "work per rank {per_rank:?}, mean {mean}"
    );
}

#[test]
fn fpatch_plate_partitions_keep_patches_whole_and_halos_symmetric() {
    let (mesh, patches, points) = plate_mesh(
        "wang2021_notched_plate.toml",
        &["solver.locking=fpatch", "mesh.cells=[8,16,4]"],
    );
    let v = view(&mesh, &patches, &points);
    for ranks in 1..=4 {
        let p = partition(&v, ranks).unwrap();
        assert_invariants(&v, &p);
        assert_balanced(&v, &p);
        if ranks == 1 {
            assert!(p.halo_plan(&v, 0).send.is_empty() && p.edge_cut == 0);
        } else {
            // Ranks meet: rank 0 owns every node it shares (the lowest
            // rank owns), so it only receives; the last rank only sends.
            let first = p.halo_plan(&v, 0);
            let last = p.halo_plan(&v, ranks - 1);
            assert!(p.edge_cut > 0 && first.send.is_empty() && !first.receive.is_empty());
            assert!(!last.send.is_empty() && last.receive.is_empty());
        }
    }
}

/// Without patches every element is a unit.
#[test]
fn element_partitions_hold_the_same_invariants() {
    let (mesh, _, points) = plate_mesh("wang2021_notched_plate.toml", &["solver.locking=fpatch"]);
    let v = MeshView {
        unit_of_element: None,
        ..view(&mesh, &[], &points)
    };
    for ranks in [2, 4] {
        let p = partition(&v, ranks).unwrap();
        assert_invariants(&v, &p);
        assert_balanced(&v, &p);
    }
}

#[test]
fn impossible_partitions_are_refused() {
    let connectivity = [0, 1, 2, 3];
    let v = MeshView {
        nodes: 4,
        nodes_per_element: 4,
        connectivity: &connectivity,
        unit_of_element: None,
        element_of_point: &[0, 0],
    };
    assert_eq!(
        partition(&v, 2),
        Err(PartitionError::Ranks { units: 1, ranks: 2 })
    );
    assert_eq!(
        partition(&v, 0),
        Err(PartitionError::Ranks { units: 1, ranks: 0 })
    );
    let outside = MeshView {
        element_of_point: &[1],
        ..v
    };
    assert!(matches!(
        partition(&outside, 1),
        Err(PartitionError::Mesh(_))
    ));
    let bad_node = MeshView { nodes: 3, ..v };
    assert!(matches!(
        partition(&bad_node, 1),
        Err(PartitionError::Mesh(_))
    ));
}
