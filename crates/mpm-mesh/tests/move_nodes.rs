//! Moving a simplex mesh's nodes (moving-mesh boundary conditions):
//! geometry and location follow, topology and sets stay, an inverting
//! motion is refused and leaves the mesh unchanged.
#![allow(clippy::unwrap_used)]

use mpm_mesh::{BoxMesh, MeshError};
use nalgebra::{Vector2, Vector3};

#[test]
fn a_stretched_box_keeps_its_topology_and_locates_in_the_new_geometry() {
    let mut mesh = BoxMesh::new(Vector3::zeros(), Vector3::new(2.0, 2.0, 2.0), [3, 2, 4])
        .simplex_mesh()
        .unwrap();
    let before = mesh.clone();
    let stretched: Vec<_> = mesh
        .nodes()
        .iter()
        .map(|x| Vector3::new(x[0], 1.75 * x[1], x[2]))
        .collect();
    mesh.move_nodes(stretched).unwrap();
    assert!((mesh.total_volume() - 1.75 * 8.0).abs() < 1e-12);
    for (a, b) in mesh.volumes().iter().zip(before.volumes()) {
        assert!((a - 1.75 * b).abs() < 1e-14);
    }
    assert_eq!(mesh.neighbours(), before.neighbours());
    assert_eq!(mesh.node_sets(), before.node_sets());
    // A point keeps its element and local coordinates under the affine map.
    let x = Vector3::new(0.3, 1.1, 1.7);
    let old = before.locate(&x, None).unwrap();
    let new = mesh
        .locate(&Vector3::new(x[0], 1.75 * x[1], x[2]), Some(0))
        .unwrap();
    assert_eq!(old.element, new.element);
    assert!((old.local - new.local).norm() < 1e-13);
    assert!(mesh.locate(&Vector3::new(0.3, 3.4, 1.0), None).is_ok());
    assert!(before.locate(&Vector3::new(0.3, 3.4, 1.0), None).is_err());
}

#[test]
fn an_inverting_motion_or_a_wrong_count_is_refused_and_changes_nothing() {
    let mut mesh = BoxMesh::new(Vector2::zeros(), Vector2::new(1.0, 1.0), [2, 2])
        .simplex_mesh()
        .unwrap();
    let before = mesh.clone();
    let mirrored: Vec<_> = mesh
        .nodes()
        .iter()
        .map(|x| Vector2::new(-x[0], x[1]))
        .collect();
    assert!(matches!(
        mesh.move_nodes(mirrored),
        Err(MeshError::InvertedElement { .. })
    ));
    assert_eq!(mesh, before);
    let mut short = mesh.nodes().to_vec();
    short.pop();
    assert!(matches!(
        mesh.move_nodes(short),
        Err(MeshError::NodeCountMismatch { .. })
    ));
    let mut nan = mesh.nodes().to_vec();
    nan[0][0] = f64::NAN;
    assert!(mesh.move_nodes(nan).is_err());
    assert_eq!(mesh, before);
}
