//! Point location by walking (Wang et al. 2021 Algorithm 1) against the
//! brute-force search, on structured, jittered, annulus and Gmsh meshes in
//! 2D and 3D: points inside elements, exactly on nodes, edges and faces,
//! within 1e-9 of the boundary and outside, from random hints.
#![allow(missing_docs, clippy::unwrap_used)]

use super::common;

use common::*;
use mpm_mesh::{AnnulusMesh, MeshError, SimplexMesh, Walk};
use nalgebra::{SVector, Vector2, Vector3};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

/// Walking and brute force agree: both fail for points in no element
/// (with the typed error naming the point), otherwise both return an
/// element containing the point, with the same interpolation of a random
/// nodal field; for points clearly inside one element (every barycentric
/// coordinate above 1e-9) the element is the same.
fn walk_matches_brute_force<const D: usize>(
    mesh: &SimplexMesh<D>,
    x: &SVector<f64, D>,
    hint: Option<usize>,
    field: &[f64],
) -> Result<(), TestCaseError> {
    let walked = mesh.locate(x, hint);
    let brute = mesh.locate_brute_force(x);
    match (&walked, &brute) {
        (Ok(w), Ok(b)) => {
            check_location(mesh, w, x)?;
            check_location(mesh, b, x)?;
            let (fw, fb) = (interpolate(mesh, w, field), interpolate(mesh, b, field));
            prop_assert!((fw - fb).abs() <= 1e-12, "interpolation {} vs {}", fw, fb);
            if b.min_barycentric() > 1e-9 {
                prop_assert_eq!(w.element, b.element);
            }
        }
        (Err(w), Err(b)) => {
            let expected = MeshError::PointOutsideMesh {
                point: x.iter().copied().collect(),
            };
            prop_assert_eq!(w, &expected);
            prop_assert_eq!(b, &expected);
        }
        _ => prop_assert!(
            false,
            "walk {:?} but brute force {:?} at {:?}",
            walked,
            brute,
            x
        ),
    }
    Ok(())
}

fn check_points<const D: usize>(
    mesh: &SimplexMesh<D>,
    selector: usize,
    index: usize,
    t: &[f64],
    hint: usize,
) -> Result<(), TestCaseError> {
    let x = pick_point(mesh, selector, index, t);
    let field = nodal_field(mesh.node_count(), index as u64);
    // Every ninth case runs without a hint (the bucket grid alone).
    let hint = (!hint.is_multiple_of(9)).then_some(hint % mesh.element_count());
    walk_matches_brute_force(mesh, &x, hint, &field)
}

fn point_cases() -> impl Strategy<Value = (usize, usize, Vec<f64>, usize)> {
    (
        0usize..6,
        any::<usize>(),
        proptest::collection::vec(0.0..=1.0f64, 3),
        any::<usize>(),
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn walk_equals_brute_force_on_boxes_2d(
        mesh in random_box::<2>(),
        (selector, index, t, hint) in point_cases(),
    ) {
        check_points(&mesh, selector, index, &t, hint)?;
    }

    #[test]
    fn walk_equals_brute_force_on_boxes_3d(
        mesh in random_box::<3>(),
        (selector, index, t, hint) in point_cases(),
    ) {
        check_points(&mesh, selector, index, &t, hint)?;
    }

    #[test]
    fn walk_equals_brute_force_on_jittered_annuli(
        (radial, circumferential, jitter, seed) in (1usize..5, 12usize..40, 0.0..=0.2f64, any::<u64>()),
        (selector, index, t, hint) in point_cases(),
    ) {
        let mesh = AnnulusMesh::new(0.75, 1.25, radial, circumferential)
            .with_jitter(jitter, seed)
            .simplex_mesh()
            .expect("valid annulus");
        check_points(&mesh, selector, index, &t, hint)?;
    }
}

/// On a structured box mesh (a Delaunay triangulation: every cell's
/// corners lie on a sphere) the walk alone, without the fallback, reaches
/// every point of the mesh from every start (a visibility walk terminates
/// on Delaunay triangulations), in at most a few steps per cell crossed.
fn walk_alone_finds_points<const D: usize>(
    cells: [usize; D],
    alternating: bool,
    grading: [f64; D],
    selector: usize,
    index: usize,
    t: &[f64],
    hint: usize,
) -> Result<(), TestCaseError> {
    let mesh = box_mesh::<D>(cells, alternating, grading);
    // Nodes, edges, faces and element interiors: all inside the mesh.
    let x = pick_point(&mesh, selector % 4, index, t);
    let start = hint % mesh.element_count();
    match mesh.walk(&x, start).unwrap() {
        Walk::Found { location, steps } => {
            check_location(&mesh, &location, &x)?;
            let crossed: usize = cells.iter().sum();
            prop_assert!(steps <= 2 * D * crossed + D, "{} steps", steps);
        }
        other => prop_assert!(false, "walk from {} to {:?} ended {:?}", start, x, other),
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn walk_alone_reaches_every_point_of_boxes_2d(
        (cells, alternating, grading) in (proptest::array::uniform2(1usize..=6), any::<bool>(), proptest::array::uniform2(0.7..1.4f64)),
        (selector, index, t, hint) in point_cases(),
    ) {
        walk_alone_finds_points::<2>(cells, alternating, grading, selector, index, &t, hint)?;
    }

    #[test]
    fn walk_alone_reaches_every_point_of_boxes_3d(
        (cells, alternating, grading) in (proptest::array::uniform3(1usize..=6), any::<bool>(), proptest::array::uniform3(0.7..1.4f64)),
        (selector, index, t, hint) in point_cases(),
    ) {
        walk_alone_finds_points::<3>(cells, alternating, grading, selector, index, &t, hint)?;
    }
}

/// The walk stops at the boundary face separating it from an outside
/// point.
#[test]
fn walk_ends_on_the_boundary_for_outside_points() {
    let mesh = box_mesh::<2>([3, 3], false, [1.0, 1.0]);
    let x = Vector2::new(0.5, -0.1);
    let start = mesh.locate(&Vector2::new(0.5, 0.7), None).unwrap().element;
    match mesh.walk(&x, start).unwrap() {
        Walk::Boundary { element, face } => {
            assert_eq!(mesh.neighbour(element, face), None);
            // The face lies on y = 0.
            assert!(
                mesh.face_nodes(element, face)
                    .all(|n| mesh.nodes()[n][1] == 0.0)
            );
        }
        other => panic!("{other:?}"),
    }
}

/// The committed Gmsh meshes: unstructured, and non-convex for the annulus
/// (walks from the far side of the hole end on the inner boundary and
/// need the fallback).
mod gmsh {
    use super::*;
    use std::sync::OnceLock;

    fn rectangle() -> &'static SimplexMesh<2> {
        static MESH: OnceLock<SimplexMesh<2>> = OnceLock::new();
        MESH.get_or_init(|| gmsh_linear("rectangle_tri3.msh"))
    }

    fn annulus() -> &'static SimplexMesh<2> {
        static MESH: OnceLock<SimplexMesh<2>> = OnceLock::new();
        MESH.get_or_init(|| gmsh_linear("annulus_tri3.msh"))
    }

    fn rectangle_patches() -> &'static SimplexMesh<2> {
        static MESH: OnceLock<SimplexMesh<2>> = OnceLock::new();
        MESH.get_or_init(|| gmsh_patches::<2>("rectangle_tri6.msh").into_mesh())
    }

    fn box_patches() -> &'static SimplexMesh<3> {
        static MESH: OnceLock<SimplexMesh<3>> = OnceLock::new();
        MESH.get_or_init(|| gmsh_patches::<3>("box_tet10.msh").into_mesh())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        #[test]
        fn walk_equals_brute_force_on_gmsh_rectangle((selector, index, t, hint) in point_cases()) {
            check_points(rectangle(), selector, index, &t, hint)?;
        }

        #[test]
        fn walk_equals_brute_force_on_gmsh_annulus((selector, index, t, hint) in point_cases()) {
            check_points(annulus(), selector, index, &t, hint)?;
        }

        #[test]
        fn walk_equals_brute_force_on_gmsh_tri6_patches((selector, index, t, hint) in point_cases()) {
            check_points(rectangle_patches(), selector, index, &t, hint)?;
        }

        #[test]
        fn walk_equals_brute_force_on_gmsh_tet10_patches((selector, index, t, hint) in point_cases()) {
            check_points(box_patches(), selector, index, &t, hint)?;
        }
    }

    /// A walk from one side of the annulus to a point across the hole
    /// stops at the inner boundary; the fallback still finds the point.
    #[test]
    fn walk_across_the_hole_finds_the_point() {
        let mesh = annulus();
        let start = mesh
            .locate(&Vector2::new(-1.0, 0.0), None)
            .expect("inside the annulus");
        let target = Vector2::new(1.0, 0.0);
        let found = mesh.locate(&target, Some(start.element)).expect("inside");
        let brute = mesh.locate_brute_force(&target).expect("inside");
        assert_eq!(found.element, brute.element);
        // The straight walk is blocked: the centre is outside the mesh.
        assert!(mesh.locate(&Vector2::zeros(), Some(start.element)).is_err());
    }
}

/// Points exactly on every node of a structured 3D mesh, from every
/// element as hint: the returned element contains the node, and the
/// barycentric coordinate of that node is 1.
#[test]
fn every_node_from_many_hints() {
    let mesh = box_mesh::<3>([3, 2, 2], true, [1.0, 1.2, 0.8]);
    for (node, x) in mesh.nodes().iter().enumerate() {
        for hint in (0..mesh.element_count()).step_by(7) {
            let location = mesh.locate(x, Some(hint)).unwrap();
            let k = mesh
                .element_nodes(location.element)
                .iter()
                .position(|&n| n == node)
                .expect("node is a vertex of the element found");
            assert!((location.barycentric(k) - 1.0).abs() < 1e-14);
        }
    }
}

#[test]
fn bad_hints_and_points_are_typed_errors() {
    let mesh = box_mesh::<2>([2, 2], false, [1.0, 1.0]);
    let count = mesh.element_count();
    assert_eq!(
        mesh.locate(&Vector2::new(0.5, 0.5), Some(count)),
        Err(MeshError::ElementIdOutOfRange { id: count, count })
    );
    for x in [
        Vector2::new(f64::NAN, 0.5),
        Vector2::new(0.5, f64::INFINITY),
        Vector2::new(1.0 + 1e-6, 0.5),
        Vector2::new(-3.0, 7.0),
    ] {
        for hint in [None, Some(0), Some(count - 1)] {
            match mesh.locate(&x, hint) {
                Err(MeshError::PointOutsideMesh { point }) => {
                    assert_eq!(point.len(), 2);
                    assert!(point[0] == x[0] || point[0].is_nan());
                }
                other => panic!("{x:?} from {hint:?}: {other:?}"),
            }
        }
        assert!(mesh.locate_brute_force(&x).is_err());
    }
    let err = mesh.locate(&Vector2::new(-3.0, 7.0), None).unwrap_err();
    assert!(err.to_string().contains("[-3.0, 7.0]"), "{err}");
}

/// The walk stops in the element it starts from when the point is there,
/// and a point on a shared face is accepted by the first element reached.
#[test]
fn tie_rule_on_shared_faces() {
    // Unit square split along 0-2.
    let nodes = vec![
        Vector2::new(0.0, 0.0),
        Vector2::new(1.0, 0.0),
        Vector2::new(1.0, 1.0),
        Vector2::new(0.0, 1.0),
    ];
    let mesh = SimplexMesh::new(nodes, vec![0, 1, 2, 0, 2, 3]).unwrap();
    let on_diagonal = Vector2::new(0.25, 0.25);
    assert_eq!(mesh.locate(&on_diagonal, Some(0)).unwrap().element, 0);
    assert_eq!(mesh.locate(&on_diagonal, Some(1)).unwrap().element, 1);
    // Without a hint and by brute force: the lowest id.
    assert_eq!(mesh.locate(&on_diagonal, None).unwrap().element, 0);
    assert_eq!(mesh.locate_brute_force(&on_diagonal).unwrap().element, 0);
    // Walking from element 0 to a point of element 1 crosses face 1.
    let loc = mesh.locate(&Vector2::new(0.1, 0.9), Some(0)).unwrap();
    assert_eq!(loc.element, 1);
    assert!((loc.barycentric(0) - 0.1).abs() < 1e-15);
}

/// A long walk across a fine 3D mesh (from one corner to the opposite
/// one) still lands on the brute-force element.
#[test]
fn long_walks_across_the_mesh() {
    let mesh = box_mesh::<3>([12, 12, 12], false, [1.0, 1.0, 1.0]);
    let far = Vector3::new(0.97, 0.71, 1.2);
    let start = mesh.locate(&Vector3::new(0.01, 0.01, 0.01), None).unwrap();
    let Walk::Found { location, steps } = mesh.walk(&far, start.element).unwrap() else {
        panic!("the walk alone must reach the point in a convex Delaunay mesh");
    };
    assert!(steps >= 12, "{steps} steps across 12 cells");
    check_location(&mesh, &location, &far).unwrap();
    assert_eq!(
        location.element,
        mesh.locate_brute_force(&far).unwrap().element
    );
}
