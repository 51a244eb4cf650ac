//! The generators produce conforming meshes: total volume equal to the
//! box / polygonal annulus to rounding, the expected number of boundary
//! faces (a face split differently by two cells would double them), node
//! sets on the right boundaries, quadratic meshes with shared mid-edge
//! nodes at the edge midpoints; bad parameters are typed errors.
#![allow(missing_docs, clippy::unwrap_used)]

use super::common;

use common::*;
use mpm_mesh::{AnnulusMesh, BoxMesh, DiagonalPattern, MeshError, QuadraticMesh, SimplexMesh};
use nalgebra::{SVector, Vector2, Vector3};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

const UPPER: [f64; 3] = [1.0, 0.75, 1.25];

fn check_box<const D: usize>(
    cells: [usize; D],
    alternating: bool,
    grading: [f64; D],
) -> Result<(), TestCaseError> {
    let mesh = box_mesh::<D>(cells, alternating, grading);
    let factorial = if D == 2 { 2 } else { 6 };
    let cell_count: usize = cells.iter().product();
    prop_assert_eq!(mesh.element_count(), factorial * cell_count);
    prop_assert_eq!(
        mesh.node_count(),
        cells.iter().map(|n| n + 1).product::<usize>()
    );
    let volume: f64 = UPPER[..D].iter().product();
    prop_assert!((mesh.total_volume() - volume).abs() <= 1e-14 * volume.max(1.0));
    prop_assert!(mesh.volumes().iter().all(|&v| v > 0.0));
    // Every boundary cell face is split into (D-1)! faces.
    let boundary_cell_faces: usize = (0..D)
        .map(|a| {
            2 * cells
                .iter()
                .enumerate()
                .filter(|&(b, _)| b != a)
                .map(|(_, n)| n)
                .product::<usize>()
        })
        .sum();
    let per_face = if D == 2 { 1 } else { 2 };
    prop_assert_eq!(mesh.boundary_faces().len(), per_face * boundary_cell_faces);
    // Node sets on the faces.
    for axis in 0..D {
        for (side, value) in [(0, 0.0), (1, UPPER[axis])] {
            let name = format!("{}{side}", ["x", "y", "z"][axis]);
            let set = mesh.node_sets().get(&name).unwrap();
            let expected: usize = cells
                .iter()
                .enumerate()
                .filter(|&(b, _)| b != axis)
                .map(|(_, n)| n + 1)
                .product();
            prop_assert_eq!(set.len(), expected);
            for &n in set {
                prop_assert_eq!(mesh.nodes()[n][axis], value);
            }
        }
    }
    check_quadratic(&mesh)
}

/// The quadratic mesh: one node per distinct edge at its midpoint, shared
/// by the elements around the edge; node sets extended to the mid-edge
/// nodes of their edges.
fn check_quadratic<const D: usize>(mesh: &SimplexMesh<D>) -> Result<(), TestCaseError> {
    let quadratic = QuadraticMesh::from_linear(mesh);
    let mut edges = std::collections::BTreeSet::new();
    for e in 0..mesh.element_count() {
        let v = mesh.element_nodes(e);
        for a in 0..=D {
            for b in a + 1..=D {
                edges.insert((v[a].min(v[b]), v[a].max(v[b])));
            }
        }
    }
    prop_assert_eq!(quadratic.node_count(), mesh.node_count() + edges.len());
    prop_assert_eq!(quadratic.element_count(), mesh.element_count());
    let pairs: &[[usize; 2]] = if D == 2 {
        &[[0, 1], [1, 2], [2, 0]]
    } else {
        &[[0, 1], [1, 2], [2, 0], [3, 0], [3, 2], [3, 1]]
    };
    let x = quadratic.nodes();
    for e in 0..quadratic.element_count() {
        let ids = quadratic.element_nodes(e);
        prop_assert_eq!(&ids[..=D], mesh.element_nodes(e));
        for (k, [a, b]) in pairs.iter().enumerate() {
            let mid = (x[ids[*a]] + x[ids[*b]]) * 0.5;
            prop_assert!((x[ids[D + 1 + k]] - mid).norm() <= 1e-15);
        }
    }
    // Rebuilding validates shared mid-edge nodes.
    let rebuilt = QuadraticMesh::new(x.to_vec(), quadratic.connectivity().to_vec());
    prop_assert!(rebuilt.is_ok(), "{:?}", rebuilt.err());
    for (name, ids) in mesh.node_sets().iter() {
        let extended = quadratic.node_sets().get(name).unwrap();
        prop_assert!(ids.iter().all(|n| extended.binary_search(n).is_ok()));
        // Box faces are planar: every node of the extended set lies on the
        // face of the linear set.
        let axis = ["x", "y", "z"]
            .iter()
            .position(|a| name.starts_with(a))
            .unwrap();
        let value = x[ids[0]][axis];
        for &n in extended {
            prop_assert!((x[n][axis] - value).abs() <= 1e-15);
        }
        prop_assert!(extended.len() > ids.len());
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn boxes_are_conforming_2d(
        cells in proptest::array::uniform2(1usize..=7),
        alternating in any::<bool>(),
        grading in proptest::array::uniform2(0.5..2.0f64),
    ) {
        check_box::<2>(cells, alternating, grading)?;
    }

    #[test]
    fn boxes_are_conforming_3d(
        cells in proptest::array::uniform3(1usize..=5),
        alternating in any::<bool>(),
        grading in proptest::array::uniform3(0.5..2.0f64),
    ) {
        check_box::<3>(cells, alternating, grading)?;
    }

    #[test]
    fn annuli_cover_the_polygonal_annulus(
        (radial, circumferential, jitter, seed) in (1usize..6, 12usize..64, 0.0..=0.2f64, any::<u64>()),
    ) {
        let (ri, ro) = (0.75, 1.25);
        let mesh = AnnulusMesh::new(ri, ro, radial, circumferential)
            .with_jitter(jitter, seed)
            .simplex_mesh()
            .unwrap();
        let n = circumferential as f64;
        let area = 0.5 * n * (std::f64::consts::TAU / n).sin() * (ro * ro - ri * ri);
        prop_assert!((mesh.total_volume() - area).abs() <= 1e-13, "{} vs {}", mesh.total_volume(), area);
        prop_assert_eq!(mesh.element_count(), 2 * radial * circumferential);
        prop_assert_eq!(mesh.boundary_faces().len(), 2 * circumferential);
        for (name, radius) in [("inner", ri), ("outer", ro)] {
            let set = mesh.node_sets().get(name).unwrap();
            prop_assert_eq!(set.len(), circumferential);
            for &node in set {
                prop_assert!((mesh.nodes()[node].norm() - radius).abs() <= 1e-14);
            }
        }
        // Jittered interior nodes stay strictly between the radii.
        for x in mesh.nodes() {
            prop_assert!(x.norm() >= ri - 1e-14 && x.norm() <= ro + 1e-14);
        }
    }
}

/// The two patterns differ (the alternating one mirrors odd cells) and
/// both are conforming.
#[test]
fn patterns_split_cells_differently() {
    let uniform = box_mesh::<2>([2, 1], false, [1.0, 1.0]);
    let alternating = box_mesh::<2>([2, 1], true, [1.0, 1.0]);
    assert_ne!(uniform.connectivity(), alternating.connectivity());
    // Uniform: both diagonals go from (i, 0) to (i + 1, 1); alternating:
    // the second cell's diagonal goes from (2, 0) to (1, 1).
    let has_edge = |mesh: &SimplexMesh<2>, a: usize, b: usize| {
        (0..mesh.element_count()).any(|e| {
            let v = mesh.element_nodes(e);
            v.contains(&a) && v.contains(&b)
        })
    };
    // Nodes: (i, j) -> i + 3 j.
    assert!(has_edge(&uniform, 1, 5) && !has_edge(&uniform, 2, 4));
    assert!(has_edge(&alternating, 2, 4) && !has_edge(&alternating, 1, 5));
}

#[test]
fn bad_generator_parameters_are_typed_errors() {
    let lower = Vector2::new(0.0, 0.0);
    assert_eq!(
        BoxMesh::new(lower, Vector2::new(1.0, 0.0), [1, 1]).simplex_mesh(),
        Err(MeshError::InvalidBounds {
            axis: 1,
            lower: 0.0,
            upper: 0.0
        })
    );
    assert_eq!(
        BoxMesh::new(lower, Vector2::new(1.0, 1.0), [3, 0]).simplex_mesh(),
        Err(MeshError::NoCells { axis: 1 })
    );
    assert!(matches!(
        BoxMesh::new(lower, Vector2::new(1.0, 1.0), [3, 3])
            .with_grading([1.0, -2.0])
            .simplex_mesh(),
        Err(MeshError::InvalidGeneratorParameter {
            parameter: "grading",
            ..
        })
    ));
    assert_eq!(
        BoxMesh::new(SVector::<f64, 4>::zeros(), SVector::repeat(1.0), [1; 4]).simplex_mesh(),
        Err(MeshError::UnsupportedDimension { dimension: 4 })
    );
    assert_eq!(
        BoxMesh::new(SVector::<f64, 1>::zeros(), SVector::repeat(1.0), [1]).quadratic_mesh(),
        Err(MeshError::UnsupportedDimension { dimension: 1 })
    );
    let cases = [
        (AnnulusMesh::new(0.0, 1.0, 2, 16), "inner_radius"),
        (AnnulusMesh::new(1.0, 1.0, 2, 16), "outer_radius"),
        (AnnulusMesh::new(0.75, 1.25, 0, 16), "radial"),
        (AnnulusMesh::new(0.75, 1.25, 2, 2), "circumferential"),
        // Too few nodes per ring: the outer chord cuts the inner ring.
        (AnnulusMesh::new(0.75, 1.25, 4, 5), "circumferential"),
        (
            AnnulusMesh::new(0.75, 1.25, 2, 16).with_jitter(0.3, 1),
            "jitter",
        ),
    ];
    for (spec, name) in cases {
        match spec.simplex_mesh() {
            Err(MeshError::InvalidGeneratorParameter { parameter, .. }) => {
                assert_eq!(parameter, name)
            }
            other => panic!("{spec:?}: {other:?}"),
        }
    }
    // R_o cos(pi / n) > R_o - dr = 1.125 needs n >= 7 for n_r = 4.
    assert!(matches!(
        AnnulusMesh::new(0.75, 1.25, 4, 6).simplex_mesh(),
        Err(MeshError::InvalidGeneratorParameter { .. })
    ));
    let coarsest = AnnulusMesh::new(0.75, 1.25, 4, 7).simplex_mesh().unwrap();
    assert!(coarsest.volumes().iter().all(|&v| v > 0.0));
}

/// Construction errors name the element.
#[test]
fn invalid_elements_are_named() {
    let nodes = vec![
        Vector2::new(0.0, 0.0),
        Vector2::new(1.0, 0.0),
        Vector2::new(0.0, 1.0),
        Vector2::new(2.0, 0.0),
    ];
    let mesh = |c: Vec<usize>| SimplexMesh::new(nodes.clone(), c);
    assert_eq!(
        mesh(vec![0, 1, 2, 0, 1]),
        Err(MeshError::ConnectivityLength {
            length: 5,
            nodes_per_element: 3
        })
    );
    assert_eq!(mesh(vec![]), Err(MeshError::NoElements));
    assert_eq!(
        mesh(vec![0, 1, 2, 1, 4, 2]),
        Err(MeshError::ElementNodeOutOfRange {
            element: 1,
            local: 1,
            node: 4,
            count: 4
        })
    );
    assert_eq!(
        mesh(vec![0, 1, 2, 1, 2, 1]),
        Err(MeshError::RepeatedElementNode {
            element: 1,
            node: 1
        })
    );
    // Nodes 0, 1, 3 are collinear.
    assert!(matches!(
        mesh(vec![0, 1, 2, 0, 1, 3]),
        Err(MeshError::DegenerateElement { element: 1, .. })
    ));
    let inverted = mesh(vec![0, 2, 1]);
    assert!(matches!(
        inverted,
        Err(MeshError::InvertedElement { element: 0, volume }) if volume == -0.5
    ));
    let reoriented = SimplexMesh::new_reoriented(nodes.clone(), vec![0, 2, 1]).unwrap();
    assert_eq!(reoriented.element_nodes(0), &[0, 1, 2]);
    assert_eq!(reoriented.volumes(), &[0.5]);
    let mut bad = nodes.clone();
    bad[2] = Vector2::new(f64::NAN, 1.0);
    assert!(matches!(
        SimplexMesh::new(bad, vec![0, 1, 2]),
        Err(MeshError::NonFiniteNode { node: 2, .. })
    ));
    let tet = SimplexMesh::<3>::new(
        vec![
            Vector3::zeros(),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::new(0.0, 0.0, 1.0),
        ],
        vec![0, 1, 2, 3],
    )
    .unwrap();
    assert!((tet.volumes()[0] - 1.0 / 6.0).abs() < 1e-16);
    // Gradients of the shape functions (eq. 15) of the reference tetrahedron.
    let g = tet.shape_gradients(0);
    assert_eq!(g[0], Vector3::new(-1.0, -1.0, -1.0));
    assert_eq!(g[3], Vector3::new(0.0, 0.0, 1.0));
    assert_eq!(
        SimplexMesh::<1>::new(vec![SVector::<f64, 1>::zeros()], vec![0, 0]),
        Err(MeshError::UnsupportedDimension { dimension: 1 })
    );
}

#[test]
fn named_sets_are_checked() {
    let mut mesh = box_mesh::<2>([2, 2], false, [1.0, 1.0]);
    mesh.sets_mut()
        .insert_nodes("corner", vec![8, 0, 8])
        .unwrap();
    assert_eq!(mesh.node_sets().get("corner"), Some(&[0, 8][..]));
    assert_eq!(
        mesh.sets_mut().insert_elements("bad", vec![1, 8]),
        Err(MeshError::SetIdOutOfRange {
            set: "bad".to_string(),
            id: 8,
            count: 8
        })
    );
    assert_eq!(
        mesh.node_sets().names().collect::<Vec<_>>(),
        vec!["corner", "x0", "x1", "y0", "y1"]
    );
}

/// The quadratic mesh constructor rejects a mid-edge node that disagrees
/// with a neighbour's, naming the element.
#[test]
fn inconsistent_mid_edge_nodes_are_rejected() {
    let linear = box_mesh::<2>([1, 1], false, [1.0, 1.0]);
    let quadratic = QuadraticMesh::from_linear(&linear);
    let mut connectivity = quadratic.connectivity().to_vec();
    let mut nodes = quadratic.nodes().to_vec();
    // Give element 1 its own node on the shared diagonal.
    let shared = (3..6)
        .find(|&k| {
            let id = connectivity[6 + k];
            connectivity[..6].contains(&id)
        })
        .unwrap();
    nodes.push(nodes[connectivity[6 + shared]]);
    connectivity[6 + shared] = nodes.len() - 1;
    assert!(matches!(
        QuadraticMesh::new(nodes, connectivity),
        Err(MeshError::InconsistentEdgeNode { element: 1, .. })
    ));
}

/// Box quadratic meshes keep the orientation and the generators' patterns
/// stay valid in 3D too.
#[test]
fn quadratic_boxes_in_both_dimensions() {
    let q2 = BoxMesh::new(Vector2::zeros(), Vector2::new(2.0, 1.0), [3, 2])
        .with_pattern(DiagonalPattern::Alternating)
        .quadratic_mesh()
        .unwrap();
    assert_eq!(q2.element_count(), 12);
    assert_eq!(QuadraticMesh::<2>::NODES_PER_ELEMENT, 6);
    let q3 = BoxMesh::new(Vector3::zeros(), Vector3::new(1.0, 1.0, 1.0), [1, 1, 1])
        .quadratic_mesh()
        .unwrap();
    // 8 corners + 12 cube edges + 6 face diagonals + 1 body diagonal.
    assert_eq!(q3.node_count(), 8 + 12 + 6 + 1);
    assert_eq!(QuadraticMesh::<3>::NODES_PER_ELEMENT, 10);
}
