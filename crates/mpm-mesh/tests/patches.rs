//! Patch splitting (Wang et al. 2021 §4.1, Fig. 3): volume preserved, every
//! child inside its parent and labelled with it, the octahedron split on
//! its shortest diagonal, and the active elements per patch (Fig. 3B).
#![allow(missing_docs, clippy::unwrap_used)]

use super::common;

use common::*;
use mpm_mesh::{
    ActivePatches, BoxMesh, GmshElements, MeshError, PatchMesh, QuadraticMesh, read_msh,
};
use nalgebra::{Vector2, Vector3};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

/// Volume of the vertex simplex of a parent.
fn parent_volume<const D: usize>(parents: &QuadraticMesh<D>, p: usize) -> f64 {
    let ids = parents.element_nodes(p);
    let x = parents.nodes();
    let t = nalgebra::DMatrix::from_fn(D, D, |i, j| x[ids[j + 1]][i] - x[ids[0]][i]);
    t.determinant() / if D == 2 { 2.0 } else { 6.0 }
}

fn check_patches<const D: usize>(
    parents: &QuadraticMesh<D>,
    straight: bool,
) -> Result<(), TestCaseError> {
    let patches = PatchMesh::from_parents(parents).unwrap();
    let mesh = patches.mesh();
    let children = 1 << D;
    prop_assert_eq!(mesh.element_count(), children * parents.element_count());
    prop_assert_eq!(mesh.node_count(), parents.node_count());
    prop_assert_eq!(patches.patch_count(), parents.element_count());
    for p in 0..parents.element_count() {
        let range = patches.children(p);
        prop_assert_eq!(range.len(), children);
        let ids = parents.element_nodes(p);
        let mut volume = 0.0;
        for child in range {
            prop_assert_eq!(patches.patch_of_element()[child], p);
            // Every vertex of the child is a node of its parent.
            for n in mesh.element_nodes(child) {
                prop_assert!(ids.contains(n));
            }
            volume += mesh.volumes()[child];
        }
        if straight {
            let parent = parent_volume(parents, p);
            prop_assert!((volume - parent).abs() <= 1e-13 * parent.abs().max(1e-300) + 1e-16);
            // Children of straight parents: corners are 1/2^D of the
            // parent; in 2D so is the middle triangle, in 3D the four
            // octahedron tetrahedra make half the parent.
            let first = patches.children(p).start;
            for corner in 0..=D {
                let v = mesh.volumes()[first + corner];
                prop_assert!((v - parent / children as f64).abs() <= 1e-13 * parent);
            }
            if D == 3 {
                let octahedron: f64 = mesh.volumes()[first + 4..first + 8].iter().sum();
                prop_assert!((octahedron - 0.5 * parent).abs() <= 1e-13 * parent);
                // The four octahedron tetrahedra share the shortest diagonal.
                let shared: Vec<usize> = mesh
                    .element_nodes(first + 4)
                    .iter()
                    .copied()
                    .filter(|n| (5..8).all(|c| mesh.element_nodes(first + c).contains(n)))
                    .collect();
                prop_assert_eq!(shared.len(), 2);
                let x = parents.nodes();
                let length = (x[shared[0]] - x[shared[1]]).norm();
                for [a, b] in [[4, 8], [6, 9], [7, 5]] {
                    prop_assert!(length <= (x[ids[a]] - x[ids[b]]).norm() + 1e-15);
                }
            }
        }
    }
    // Node sets carry over; element sets map to the children.
    prop_assert_eq!(mesh.node_sets(), parents.node_sets());
    for (name, set) in parents.element_sets().iter() {
        let expected: Vec<usize> = set.iter().flat_map(|&p| patches.children(p)).collect();
        prop_assert_eq!(mesh.element_sets().get(name).unwrap(), expected.as_slice());
    }
    Ok(())
}

fn jittered_parents<const D: usize>(cells: [usize; D], jitter: f64, seed: u64) -> QuadraticMesh<D> {
    let linear = box_mesh::<D>(cells, true, [1.0; D]);
    QuadraticMesh::from_linear(&jittered(&linear, jitter, seed))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn patches_preserve_volume_2d(cells in proptest::array::uniform2(1usize..=4), jitter in 0.0..0.15f64, seed in any::<u64>()) {
        check_patches(&jittered_parents::<2>(cells, jitter, seed), true)?;
    }

    #[test]
    fn patches_preserve_volume_3d(cells in proptest::array::uniform3(1usize..=3), jitter in 0.0..0.15f64, seed in any::<u64>()) {
        check_patches(&jittered_parents::<3>(cells, jitter, seed), true)?;
    }
}

fn gmsh_parents<const D: usize>(name: &str) -> QuadraticMesh<D> {
    match read_msh::<D>(data(name)).unwrap().elements {
        GmshElements::Quadratic(q) => q,
        GmshElements::Linear(_) => panic!("{name} is linear"),
    }
}

/// The committed six-node rectangle [0, 2] x [0, 1] and ten-node box
/// [0, 1] x [0, 1] x [0, 2] have straight edges: both of measure 2.
#[test]
fn gmsh_parents_split_into_patches() {
    let rectangle = gmsh_parents::<2>("rectangle_tri6.msh");
    check_patches(&rectangle, true).unwrap();
    let area = PatchMesh::from_parents(&rectangle)
        .unwrap()
        .mesh()
        .total_volume();
    assert!((area - 2.0).abs() < 1e-13);
    let cube = gmsh_parents::<3>("box_tet10.msh");
    check_patches(&cube, true).unwrap();
    let volume = PatchMesh::from_parents(&cube)
        .unwrap()
        .mesh()
        .total_volume();
    assert!((volume - 2.0).abs() < 1e-13);
}

/// Fig. 3B by hand: two six-node triangles (patches 0 and 1, children 0-3
/// and 4-7); material points in children 1, 3 and 6 only.
#[test]
fn active_elements_per_patch_by_hand() {
    let parents = BoxMesh::new(Vector2::zeros(), Vector2::new(1.0, 1.0), [1, 1])
        .quadratic_mesh()
        .unwrap();
    let patches = PatchMesh::from_parents(&parents).unwrap();
    assert_eq!(patches.patch_count(), 2);
    assert_eq!(patches.patch_of_element(), &[0, 0, 0, 0, 1, 1, 1, 1]);
    let mut active = vec![false; 8];
    for e in [1, 3, 6] {
        active[e] = true;
    }
    let mut out = ActivePatches::with_capacity(2, 8);
    patches.active_elements(&active, &mut out).unwrap();
    assert_eq!(out.patches(), &[0, 1]);
    assert_eq!(out.elements(0), &[1, 3]);
    assert_eq!(out.elements(1), &[6]);
    assert_eq!(
        out.iter().collect::<Vec<_>>(),
        vec![(0, &[1, 3][..]), (1, &[6][..])]
    );
    // Material points leave patch 0: only patch 1 is listed; the buffers are
    // reused, not reallocated.
    let pointer = out.patches().as_ptr();
    active[1] = false;
    active[3] = false;
    active[7] = true;
    patches.active_elements(&active, &mut out).unwrap();
    assert_eq!(out.len(), 1);
    assert_eq!(out.patches(), &[1]);
    assert_eq!(out.elements(0), &[6, 7]);
    assert_eq!(out.patches().as_ptr(), pointer);
    // Nothing active.
    patches.active_elements(&[false; 8], &mut out).unwrap();
    assert!(out.is_empty());
    assert_eq!(
        patches.active_elements(&[true; 7], &mut out),
        Err(MeshError::MaskLength {
            expected: 8,
            found: 7
        })
    );
    assert!(out.is_empty());
}

/// One straight ten-node tetrahedron with a unique shortest octahedron
/// diagonal, m03-m12 (nodes 7 and 5): squared lengths 1.4825 (m01-m23),
/// 1.5825 (m02-m13) and 1.1825 (m03-m12).
#[test]
fn one_tetrahedron_splits_on_its_shortest_diagonal() {
    let mut nodes = vec![
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(2.0, 0.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
        Vector3::new(0.2, 0.3, 1.0),
    ];
    for [a, b] in [[0, 1], [1, 2], [2, 0], [3, 0], [3, 2], [3, 1]] {
        nodes.push((nodes[a] + nodes[b]) * 0.5);
    }
    let squared = |a: usize, b: usize| -> f64 { (nodes[a] - nodes[b]).norm_squared() };
    assert!((squared(4, 8) - 1.4825).abs() < 1e-14);
    assert!((squared(6, 9) - 1.5825).abs() < 1e-14);
    assert!((squared(7, 5) - 1.1825).abs() < 1e-14);
    let parents = QuadraticMesh::new(nodes, (0..10).collect()).unwrap();
    let patches = PatchMesh::from_parents(&parents).unwrap();
    let mesh = patches.mesh();
    assert_eq!(mesh.element_nodes(0), &[0, 4, 6, 7]);
    for child in 4..8 {
        let v = mesh.element_nodes(child);
        assert!(v.contains(&7) && v.contains(&5), "child {child}: {v:?}");
    }
    let parent = 2.0 / 6.0;
    assert!((mesh.total_volume() - parent).abs() < 1e-15);
    // Eight children, no two alike.
    let mut sorted: Vec<Vec<usize>> = (0..8)
        .map(|e| {
            let mut v = mesh.element_nodes(e).to_vec();
            v.sort_unstable();
            v
        })
        .collect();
    sorted.sort();
    sorted.dedup();
    assert_eq!(sorted.len(), 8);
}
