//! Shared fixtures for the simplex mesh tests: random structured and
//! jittered meshes, the committed Gmsh meshes, a random nodal field, and
//! the checks of a location.
#![allow(dead_code)]

use std::path::PathBuf;

use mpm_mesh::{
    BARYCENTRIC_TOLERANCE, BoxMesh, DiagonalPattern, GmshElements, Location, PatchMesh,
    SimplexMesh, read_msh,
};
use nalgebra::{DMatrix, DVector, SVector};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

/// Path of a committed test mesh.
pub fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join("data")
        .join(name)
}

/// A committed linear Gmsh mesh.
pub fn gmsh_linear<const D: usize>(name: &str) -> SimplexMesh<D> {
    match read_msh::<D>(data(name)).expect("committed mesh").elements {
        GmshElements::Linear(mesh) => mesh,
        GmshElements::Quadratic(_) => panic!("{name} is quadratic"),
    }
}

/// The children of a committed quadratic Gmsh mesh.
pub fn gmsh_patches<const D: usize>(name: &str) -> PatchMesh<D> {
    match read_msh::<D>(data(name)).expect("committed mesh").elements {
        GmshElements::Quadratic(mesh) => PatchMesh::from_parents(&mesh).expect("valid parents"),
        GmshElements::Linear(_) => panic!("{name} is linear"),
    }
}

/// The deterministic pseudo-random source of the tests.
pub use mpm_mesh::SplitMix64 as Random;

/// A structured box mesh of [0, 1] x [0, 0.75] (x [0, 1.25]) with the
/// given cells, pattern and grading.
pub fn box_mesh<const D: usize>(
    cells: [usize; D],
    alternating: bool,
    grading: [f64; D],
) -> SimplexMesh<D> {
    let upper = SVector::<f64, D>::from_fn(|i, _| [1.0, 0.75, 1.25][i]);
    let pattern = if alternating {
        DiagonalPattern::Alternating
    } else {
        DiagonalPattern::Uniform
    };
    BoxMesh::new(SVector::zeros(), upper, cells)
        .with_pattern(pattern)
        .with_grading(grading)
        .simplex_mesh()
        .expect("valid box")
}

/// The mesh with every node off the boundary moved by up to `fraction`
/// of the smallest cell size along each axis, rebuilt with the strict
/// constructor (which rejects any element the jitter inverted).
pub fn jittered<const D: usize>(mesh: &SimplexMesh<D>, fraction: f64, seed: u64) -> SimplexMesh<D> {
    let mut on_boundary = vec![false; mesh.node_count()];
    for face in mesh.boundary_faces() {
        for node in mesh.face_nodes(face.element, face.face) {
            on_boundary[node] = true;
        }
    }
    let h = shortest_edge(mesh);
    let mut random = Random(seed);
    let nodes = mesh
        .nodes()
        .iter()
        .zip(&on_boundary)
        .map(|(x, &fixed)| {
            if fixed {
                *x
            } else {
                x + SVector::<f64, D>::from_fn(|_, _| fraction * h * random.symmetric())
            }
        })
        .collect();
    SimplexMesh::new(nodes, mesh.connectivity().to_vec()).expect("jitter keeps elements valid")
}

/// The shortest element edge.
pub fn shortest_edge<const D: usize>(mesh: &SimplexMesh<D>) -> f64 {
    let mut h = f64::INFINITY;
    for e in 0..mesh.element_count() {
        let v = mesh.element_nodes(e);
        for a in 0..=D {
            for b in a + 1..=D {
                h = h.min((mesh.nodes()[v[a]] - mesh.nodes()[v[b]]).norm());
            }
        }
    }
    h
}

/// Strategy for the box meshes: 1 to 5 cells per axis, either pattern,
/// grading in [0.7, 1.4], jitter 0 or up to 0.15 of the smallest edge.
pub fn random_box<const D: usize>() -> BoxedStrategy<SimplexMesh<D>> {
    (
        proptest::collection::vec(1usize..=5, D),
        any::<bool>(),
        proptest::collection::vec(0.7..1.4f64, D),
        prop_oneof![Just(0.0), 0.0..0.15f64],
        any::<u64>(),
    )
        .prop_map(|(cells, alternating, grading, jitter, seed)| {
            let mesh = box_mesh::<D>(
                std::array::from_fn(|i| cells[i]),
                alternating,
                std::array::from_fn(|i| grading[i]),
            );
            if jitter > 0.0 {
                jittered(&mesh, jitter, seed)
            } else {
                mesh
            }
        })
        .boxed()
}

/// A point of the mesh chosen by `selector` and `t`: a node, a point on
/// an edge or face of an element, a point inside an element, a point
/// within 1e-9 of the bounding box, or a uniform point of the bounding
/// box (possibly outside a non-convex mesh).
pub fn pick_point<const D: usize>(
    mesh: &SimplexMesh<D>,
    selector: usize,
    index: usize,
    t: &[f64],
) -> SVector<f64, D> {
    let element = index % mesh.element_count();
    let vertices = mesh.element_nodes(element);
    let x = |k: usize| mesh.nodes()[vertices[k]];
    let b = mesh.bounding_box();
    match selector % 6 {
        0 => mesh.nodes()[index % mesh.node_count()],
        // On an edge: between local vertices 0 and 1.
        1 => x(0) + (x(1) - x(0)) * t[0],
        // On the face opposite local vertex 0 (an edge in 2D).
        2 => {
            let (u, v) = (t[0], t[1] * (1.0 - t[0]));
            if D == 2 {
                x(1) + (x(2) - x(1)) * t[0]
            } else {
                x(1) + (x(2) - x(1)) * u + (x(D) - x(1)) * v
            }
        }
        // Inside the element.
        3 => {
            let mut weights = [0.0; 4];
            let mut sum = 0.0;
            for (k, w) in weights.iter_mut().take(D + 1).enumerate() {
                *w = 0.05 + t[k % t.len()];
                sum += *w;
            }
            (0..=D).fold(SVector::zeros(), |acc, k| acc + x(k) * (weights[k] / sum))
        }
        // Near the bounding box: just inside or outside a face.
        4 => {
            let mut p =
                SVector::from_fn(|i, _| b.lower[i] + t[i % t.len()] * (b.upper[i] - b.lower[i]));
            let axis = index % D;
            let offset = if t[0] < 0.5 { 1e-9 } else { -1e-9 };
            p[axis] = if index.is_multiple_of(2) {
                b.lower[axis] + offset
            } else {
                b.upper[axis] + offset
            };
            p
        }
        _ => SVector::from_fn(|i, _| {
            let margin = 0.1 * (b.upper[i] - b.lower[i]);
            b.lower[i] - margin + t[i % t.len()] * (b.upper[i] - b.lower[i] + 2.0 * margin)
        }),
    }
}

/// Nodal values of a random field.
pub fn nodal_field(node_count: usize, seed: u64) -> Vec<f64> {
    let mut random = Random(seed);
    (0..node_count).map(|_| random.symmetric()).collect()
}

/// $\sum_k \lambda_k f_k$ over the located element.
pub fn interpolate<const D: usize>(
    mesh: &SimplexMesh<D>,
    location: &Location<D>,
    field: &[f64],
) -> f64 {
    mesh.element_nodes(location.element)
        .iter()
        .enumerate()
        .map(|(k, &n)| location.barycentric(k) * field[n])
        .sum()
}

/// The location's element contains `x` within the tolerance, and its
/// local coordinates reproduce `x`; both checked against barycentric
/// coordinates computed here independently (LU solve of eq. 14).
pub fn check_location<const D: usize>(
    mesh: &SimplexMesh<D>,
    location: &Location<D>,
    x: &SVector<f64, D>,
) -> Result<(), TestCaseError> {
    let vertices = mesh.element_nodes(location.element);
    let x0 = mesh.nodes()[vertices[0]];
    let t = DMatrix::from_fn(D, D, |i, j| mesh.nodes()[vertices[j + 1]][i] - x0[i]);
    let rhs = DVector::from_fn(D, |i, _| x[i] - x0[i]);
    let xi = t.lu().solve(&rhs).expect("non-degenerate element");
    let xi = SVector::<f64, D>::from_fn(|i, _| xi[i]);
    prop_assert!(
        (xi - location.local).norm() <= 1e-10,
        "local coordinates {:?}, expected {:?}",
        location.local,
        xi
    );
    let lambda_min = xi.min().min(1.0 - xi.sum());
    prop_assert!(
        lambda_min >= -BARYCENTRIC_TOLERANCE - 1e-13,
        "point {:?} outside element {} (min barycentric {})",
        x,
        location.element,
        lambda_min
    );
    let back = (0..=D).fold(SVector::<f64, D>::zeros(), |acc, k| {
        acc + mesh.nodes()[vertices[k]] * location.barycentric(k)
    });
    prop_assert!(
        (back - x).norm() <= 1e-12,
        "reconstruction {:?} of {:?}",
        back,
        x
    );
    Ok(())
}
