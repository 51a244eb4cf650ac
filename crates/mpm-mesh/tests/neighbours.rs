//! The neighbour table (Wang et al. 2021 Algorithm 2) against an
//! independent face count: symmetric, every interior face shared by exactly
//! two elements and every boundary face by one, and the boundary closed
//! (its measure is the box's surface or the annulus's perimeter).
#![allow(missing_docs, clippy::unwrap_used)]

use super::common;

use std::collections::BTreeMap;

use common::*;
use mpm_mesh::{AnnulusMesh, BoundaryFace, MeshError, NO_NEIGHBOUR, SimplexMesh};
use nalgebra::{DMatrix, SVector, Vector2};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

/// Sorted node ids of face `face` of `element`.
fn face_key<const D: usize>(mesh: &SimplexMesh<D>, element: usize, face: usize) -> Vec<usize> {
    let mut key: Vec<usize> = mesh.face_nodes(element, face).collect();
    key.sort_unstable();
    key
}

/// Measure (length in 2D, area in 3D) of a face, from the Gram determinant.
fn face_measure<const D: usize>(mesh: &SimplexMesh<D>, element: usize, face: usize) -> f64 {
    let x: Vec<SVector<f64, D>> = mesh
        .face_nodes(element, face)
        .map(|n| mesh.nodes()[n])
        .collect();
    let edges = DMatrix::from_fn(D, D - 1, |i, j| x[j + 1][i] - x[0][i]);
    let gram = edges.transpose() * &edges;
    gram.determinant().sqrt() / if D == 3 { 2.0 } else { 1.0 }
}

/// Check the table and return the boundary's measure.
fn check_table<const D: usize>(mesh: &SimplexMesh<D>) -> Result<f64, TestCaseError> {
    let mut holders: BTreeMap<Vec<usize>, Vec<(usize, usize)>> = BTreeMap::new();
    for element in 0..mesh.element_count() {
        for face in 0..=D {
            holders
                .entry(face_key(mesh, element, face))
                .or_default()
                .push((element, face));
        }
    }
    let mut boundary = Vec::new();
    for (key, held) in &holders {
        match held.as_slice() {
            [(e, f)] => {
                prop_assert_eq!(mesh.neighbour(*e, *f), None);
                prop_assert_eq!(mesh.neighbours()[e * (D + 1) + f], NO_NEIGHBOUR);
                boundary.push(BoundaryFace {
                    element: *e,
                    face: *f,
                });
            }
            [(a, fa), (b, fb)] => {
                prop_assert_eq!(mesh.neighbour(*a, *fa), Some(*b));
                prop_assert_eq!(mesh.neighbour(*b, *fb), Some(*a));
                prop_assert_eq!(&face_key(mesh, *b, *fb), key);
            }
            more => prop_assert!(false, "face {:?} held by {:?}", key, more),
        }
    }
    boundary.sort_unstable();
    prop_assert_eq!(mesh.boundary_faces(), boundary.as_slice());
    // Symmetry read from the table itself.
    for element in 0..mesh.element_count() {
        for face in 0..=D {
            if let Some(other) = mesh.neighbour(element, face) {
                let back: Vec<usize> = (0..=D)
                    .filter(|&g| mesh.neighbour(other, g) == Some(element))
                    .collect();
                prop_assert_eq!(back.len(), 1);
                prop_assert_eq!(
                    face_key(mesh, other, back[0]),
                    face_key(mesh, element, face)
                );
            }
        }
    }
    Ok(mesh
        .boundary_faces()
        .iter()
        .map(|f| face_measure(mesh, f.element, f.face))
        .sum())
}

/// Surface of the box [0, 1] x [0, 0.75] (x [0, 1.25]) of `box_mesh`.
fn box_boundary(dimension: usize) -> f64 {
    if dimension == 2 {
        2.0 * (1.0 + 0.75)
    } else {
        2.0 * (0.75 + 1.25 + 0.75 * 1.25)
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn neighbour_table_is_symmetric_and_closed_2d(mesh in random_box::<2>()) {
        let measure = check_table(&mesh)?;
        prop_assert!((measure - box_boundary(2)).abs() <= 1e-12, "perimeter {}", measure);
    }

    #[test]
    fn neighbour_table_is_symmetric_and_closed_3d(mesh in random_box::<3>()) {
        let measure = check_table(&mesh)?;
        prop_assert!((measure - box_boundary(3)).abs() <= 1e-12, "surface {}", measure);
    }

    #[test]
    fn neighbour_table_of_annuli(
        (radial, circumferential, jitter, seed) in (1usize..5, 12usize..40, 0.0..=0.2f64, any::<u64>()),
    ) {
        let mesh = AnnulusMesh::new(0.75, 1.25, radial, circumferential)
            .with_jitter(jitter, seed)
            .simplex_mesh()
            .unwrap();
        let measure = check_table(&mesh)?;
        let n = circumferential as f64;
        let chord = 2.0 * (std::f64::consts::PI / n).sin();
        prop_assert!((measure - n * chord * (0.75 + 1.25)).abs() <= 1e-12);
    }
}

#[test]
fn neighbour_tables_of_gmsh_meshes() {
    let rectangle = gmsh_linear::<2>("rectangle_tri3.msh");
    assert!((check_table(&rectangle).unwrap() - 6.0).abs() < 1e-12);
    let annulus = gmsh_linear::<2>("annulus_tri3.msh");
    let perimeter = check_table(&annulus).unwrap();
    let circles = std::f64::consts::TAU * (0.75 + 1.25);
    assert!(
        perimeter < circles && perimeter > 0.999 * circles,
        "{perimeter}"
    );
    let patches = gmsh_patches::<3>("box_tet10.msh");
    // Box [0, 1] x [0, 1] x [0, 2].
    assert!((check_table(patches.mesh()).unwrap() - 10.0).abs() < 1e-12);
    let patches = gmsh_patches::<2>("rectangle_tri6.msh");
    assert!((check_table(patches.mesh()).unwrap() - 6.0).abs() < 1e-12);
}

#[test]
fn non_manifold_faces_are_rejected() {
    // Three triangles on the edge (0, 1).
    let nodes = vec![
        Vector2::new(0.0, 0.0),
        Vector2::new(1.0, 0.0),
        Vector2::new(0.5, 1.0),
        Vector2::new(0.5, -1.0),
        Vector2::new(0.4, 0.5),
    ];
    let err = SimplexMesh::new(nodes, vec![0, 1, 2, 1, 0, 3, 0, 1, 4]).unwrap_err();
    assert_eq!(
        err,
        MeshError::NonManifoldFace {
            nodes: vec![0, 1],
            first: 0,
            second: 1,
            third: 2
        }
    );
}
