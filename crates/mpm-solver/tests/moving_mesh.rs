//! Moving-mesh conditions in the implicit solver: a disk of material whose
//! mesh rotates with its driven rim turns rigidly — every point keeps
//! zero stress and F = R(θ) while it is located by walking in the rotated
//! mesh — and a mesh whose rim is translated, with the interior blended
//! towards the fixed hole, keeps every point of the strained body inside.
#![allow(clippy::unwrap_used)]

use mpm_basis::LinearSimplex;
use mpm_constitutive::HenckyElastic;
use mpm_mesh::{AnnulusMesh, SimplexMesh};
use mpm_solver::{
    Constraints, ImplicitSolver, LoadStepping, MaterialPoints, MovingMesh, NewtonOptions,
    NoLocking, NoUpdate, NodalConstraints, Parts, PreviouslyConverged, Rotation, Translation,
};
use nalgebra::{Matrix3, Vector2};

/// Standard MPM on `mesh`, Hencky elasticity (E = 1 kPa, ν = 0.3),
/// previously converged formulation.
fn elastic_solver<C: Constraints<2>>(
    mesh: SimplexMesh<2>,
    constraints: C,
) -> ImplicitSolver<
    2,
    Parts<LinearSimplex, PreviouslyConverged, HenckyElastic, NoLocking, NoUpdate, C>,
> {
    ImplicitSolver::new(
        LinearSimplex,
        mesh,
        HenckyElastic::new(1e3, 0.3).unwrap(),
        NoLocking,
        NoUpdate,
        constraints,
        NewtonOptions::default(),
    )
}

/// Points at the centroids of the elements of `mesh`.
fn points(mesh: &SimplexMesh<2>) -> MaterialPoints<2, (), ()> {
    let x: Vec<Vector2<f64>> = (0..mesh.element_count())
        .map(|e| {
            mesh.element_nodes(e)
                .iter()
                .map(|&v| mesh.nodes()[v])
                .sum::<Vector2<f64>>()
                / 3.0
        })
        .collect();
    let n = x.len();
    MaterialPoints::new(x, mesh.volumes().to_vec(), 1.0, vec![(); n]).unwrap()
}

#[test]
fn a_mesh_rotating_with_its_rim_turns_the_body_rigidly() {
    let mesh = AnnulusMesh::new(0.5, 1.0, 3, 24).simplex_mesh().unwrap();
    let rim: Vec<usize> = mesh.node_sets().get("outer").unwrap().to_vec();
    let mut pts = points(&mesh);
    let x0 = pts.position.clone();
    let angle = std::f64::consts::FRAC_PI_2;
    let motion = Rotation::planar(Vector2::zeros(), angle);
    let constraints = MovingMesh::new(
        NodalConstraints::<2>::new(mesh.node_count()),
        motion,
        mesh.nodes().to_vec(),
        &rim,
        [true, true],
    );
    let mut solver = elastic_solver(mesh, constraints);
    let steps = 9;
    for s in 0..steps {
        let (l0, l1) = (s as f64 / steps as f64, (s + 1) as f64 / steps as f64);
        solver.solve_load_step(&mut pts, l0, l1).unwrap();
    }
    let r = motion.matrix(angle);
    let r3 = Matrix3::new(
        r[(0, 0)],
        r[(0, 1)],
        0.0,
        r[(1, 0)],
        r[(1, 1)],
        0.0,
        0.0,
        0.0,
        1.0,
    );
    for (p, x) in x0.iter().enumerate() {
        assert!((pts.position[p] - r * x).norm() < 1e-9, "point {p}");
        assert!((pts.f[p] - r3).norm() < 1e-9, "point {p}: F = {}", pts.f[p]);
        assert!(
            pts.sigma[p].norm() < 1e-6,
            "point {p}: sigma = {}",
            pts.sigma[p]
        );
    }
    // The mesh turned with the rim.
    let moved = solver.mesh.nodes()[0];
    let start = AnnulusMesh::new(0.5, 1.0, 3, 24)
        .simplex_mesh()
        .unwrap()
        .nodes()[0];
    assert!((moved - r * start).norm() < 1e-12);
}

#[test]
fn a_mesh_translated_at_its_rim_keeps_the_strained_body_inside() {
    let mesh = AnnulusMesh::new(0.5, 1.0, 3, 24).simplex_mesh().unwrap();
    let (outer, inner) = (
        mesh.node_sets().get("outer").unwrap().to_vec(),
        mesh.node_sets().get("inner").unwrap().to_vec(),
    );
    let far = Vector2::new(0.3, -0.2);
    assert!(
        Translation::new(mesh.nodes(), &outer, &[], far).is_none(),
        "a translation needs a fixed set"
    );
    let motion = Translation::new(mesh.nodes(), &outer, &inner, far).unwrap();
    let mut pts = points(&mesh);
    let constraints = MovingMesh::new(
        NodalConstraints::<2>::new(mesh.node_count()),
        motion.clone(),
        mesh.nodes().to_vec(),
        &outer,
        [true, true],
    );
    let mut fixed = constraints;
    fixed.inner.fix(inner.iter().copied(), 0);
    fixed.inner.fix(inner.iter().copied(), 1);
    let mut solver = elastic_solver(mesh, fixed);
    let summary = solver
        .run(&mut pts, &LoadStepping::uniform(4), |_, report, _| {
            assert!(*report.residuals.last().unwrap() <= 1e-9);
            Ok(())
        })
        .unwrap();
    assert!(summary.steps >= 4);
    // The rim moved by d, the hole stayed: the body is strained, the mesh
    // interior followed the blending weights, and every point still lies
    // in the moved mesh.
    for x in &pts.position {
        assert!(solver.mesh.locate(x, None).is_ok());
    }
    assert!(pts.sigma.iter().any(|s| s.norm() > 1.0));
}
