//! Property tests run for every basis in 2D and 3D by one macro: partition
//! of unity, zero gradient sum, linear reproduction, gradients against
//! finite differences, well-formed stencils (no node outside the grid),
//! hinted evaluation agreeing with the plain one, and the streaming
//! `for_each_node` visiting exactly the evaluated stencil.
#![allow(missing_docs)]

use super::common;

use common::*;
use mpm_basis::{
    BasisFunction, BoundaryBSpline, Corners, Cpdi2, Gimp, LinearMpm, LinearSimplex,
    QuadraticBSpline,
};
use mpm_mesh::SimplexMesh;
use nalgebra::SVector;
use proptest::prelude::*;

/// `basis_properties!(module, basis, D, cases, fd_bound)` instantiates the
/// property tests for `basis` in `D` dimensions; `cases` generates
/// `(position, domain)` pairs with complete support and `fd_bound(x, domain,
/// axis)` returns a bound on the second derivative along `axis` where the
/// basis is differentiable there (`None` skips the finite-difference check
/// on that axis).
macro_rules! basis_properties {
    ($name:ident, $basis:expr, $dim:literal, $cases:expr, $fd_bound:expr) => {
        mod $name {
            use super::*;

            proptest! {
                #![proptest_config(ProptestConfig::with_cases(256))]

                #[test]
                fn partition_of_unity_and_zero_gradient_sum((x, domain) in $cases) {
                    check_partition::<$dim, _>(&$basis, &x, &domain)?;
                }

                #[test]
                fn linear_reproduction((x, domain) in $cases) {
                    check_linear_reproduction::<$dim, _>(&$basis, &x, &domain)?;
                }

                #[test]
                fn gradients_match_finite_differences((x, domain) in $cases) {
                    check_finite_differences::<$dim, _>(&$basis, &x, &domain, $fd_bound)?;
                }

                #[test]
                fn stencil_is_well_formed_and_inside_the_grid((x, domain) in $cases) {
                    check_well_formed::<$dim, _>(&$basis, &x, &domain)?;
                }

                #[test]
                fn tensor_factors_multiply_out_to_the_stencil((x, domain) in $cases) {
                    check_tensor::<$dim, _>(&$basis, &x, &domain)?;
                }

                #[test]
                fn visiting_matches_evaluation((x, domain) in $cases) {
                    check_visited::<$dim, _>(&$basis, &x, &domain)?;
                }

                #[test]
                fn hinted_evaluation_matches((x, domain) in $cases, seed in any::<usize>()) {
                    check_hinted::<$dim, _>(&$basis, &x, &domain, seed)?;
                }
            }
        }
    };
}

/// Standard MPM is linear along each axis inside a cell; skip points within
/// two steps of a node line (kink).
fn linear_bound<const D: usize>(x: &SVector<f64, D>, _: &(), axis: usize) -> Option<f64> {
    (distance_to_node_line(axis, x[axis]) > 2.0 * fd_step(axis)).then_some(0.0)
}

/// Linear simplices: the values are linear inside an element; skip points
/// whose ±2δ neighbourhood along `axis` leaves the element (a barycentric
/// coordinate below 2δ times its gradient component).
fn simplex_bound<const D: usize>(x: &SVector<f64, D>, _: &(), axis: usize) -> Option<f64>
where
    SimplexMesh<D>: TestMesh<D>,
{
    let mesh = SimplexMesh::<D>::test_mesh();
    let mut stencil = mpm_basis::Stencil::for_basis::<LinearSimplex>();
    LinearSimplex.evaluate(mesh, x, &(), &mut stencil).ok()?;
    let margin = 2.0 * fd_step(axis);
    stencil
        .iter()
        .all(|(_, value, gradient)| value > margin * gradient[axis].abs())
        .then_some(0.0)
}

/// GIMP: $|S''| \le 1/(h^2\lambda)$ (the central region); with $\lambda = 0$
/// the axis is standard MPM.
fn gimp_bound<const D: usize>(
    x: &SVector<f64, D>,
    l: &SVector<f64, D>,
    axis: usize,
) -> Option<f64> {
    let h = SPACING[axis];
    if l[axis] == 0.0 {
        linear_bound(x, &(), axis)
    } else {
        Some(1.0 / (h * l[axis]))
    }
}

/// Quadratic B-spline: $|N''| \le 2$, so $|\partial_i^2 S| \le 2/h_i^2$;
/// skip points within two steps of the admissible region's boundary.
fn bspline_bound<const D: usize>(x: &SVector<f64, D>, _: &(), axis: usize) -> Option<f64> {
    let h = SPACING[axis];
    let lo = ORIGIN[axis] + 0.5 * h;
    let hi = node_line(axis, CELLS[axis]) - 0.5 * h;
    let margin = 2.0 * fd_step(axis);
    (x[axis] - margin >= lo && x[axis] + margin <= hi).then_some(2.0 / (h * h))
}

/// The boundary-modified spline is C¹ and piecewise quadratic (linear on
/// the boundary half cells) everywhere in the grid: the spline's bound,
/// away from the grid boundary by the finite-difference margin.
fn boundary_bspline_bound<const D: usize>(x: &SVector<f64, D>, _: &(), axis: usize) -> Option<f64> {
    let h = SPACING[axis];
    let margin = 2.0 * fd_step(axis);
    (x[axis] - margin >= ORIGIN[axis] && x[axis] + margin <= node_line(axis, CELLS[axis]))
        .then_some(2.0 / (h * h))
}

/// CPDI2: the gradient (domain average of the gradient of the corner
/// interpolant) is the derivative of the values under translation for a
/// parallelogram inside one cell, and in 3D for a parallelepiped inside one
/// cell whose edges are parallel to coordinate planes (then N_v is at most
/// quadratic along every edge, where the secant equals the mean of the end
/// slopes). There the values are linear along each axis (bound 0). Other
/// domains are checked against the divergence theorem, and the failure of
/// the identity for a fully sheared parallelepiped is shown, in
/// `cpdi2_integration.rs`.
fn cpdi2_bound<const D: usize>(_: &SVector<f64, D>, c: &Corners<D>, axis: usize) -> Option<f64> {
    let g = grid::<D>();
    let p = c.as_slice();
    let cell = g.cell_containing(&p[0]).ok()?;
    for x in p {
        for i in 0..D {
            let lo = node_line(i, cell[i]) + 2.0 * fd_step(i);
            let hi = node_line(i, cell[i] + 1) - 2.0 * fd_step(i);
            if !(lo..=hi).contains(&x[i]) {
                return None;
            }
        }
    }
    let scale = (p[p.len() - 1] - p[0]).norm();
    for (k, x) in p.iter().enumerate() {
        let affine = (0..D)
            .filter(|i| k >> i & 1 == 1)
            .fold(p[0], |y, i| y + (p[1 << i] - p[0]));
        if (x - affine).norm() > 1e-12 * scale {
            return None;
        }
    }
    if D == 3 {
        for i in 0..D {
            let edge = p[1 << i] - p[0];
            if edge.iter().all(|e| e.abs() > 1e-12 * scale) {
                return None;
            }
        }
    }
    let _ = axis;
    Some(0.0)
}

basis_properties!(
    linear_mpm_2d,
    LinearMpm,
    2,
    linear_cases::<2>(),
    linear_bound::<2>
);
basis_properties!(
    linear_mpm_3d,
    LinearMpm,
    3,
    linear_cases::<3>(),
    linear_bound::<3>
);
basis_properties!(
    linear_simplex_2d,
    LinearSimplex,
    2,
    linear_cases::<2>(),
    simplex_bound::<2>
);
basis_properties!(
    linear_simplex_3d,
    LinearSimplex,
    3,
    linear_cases::<3>(),
    simplex_bound::<3>
);
basis_properties!(gimp_2d, Gimp, 2, gimp_cases::<2>(), gimp_bound::<2>);
basis_properties!(gimp_3d, Gimp, 3, gimp_cases::<3>(), gimp_bound::<3>);
basis_properties!(cpdi2_2d, Cpdi2, 2, cpdi2_cases::<2>(), cpdi2_bound::<2>);
basis_properties!(cpdi2_3d, Cpdi2, 3, cpdi2_cases::<3>(), cpdi2_bound::<3>);
basis_properties!(
    quadratic_bspline_2d,
    QuadraticBSpline,
    2,
    bspline_cases::<2>(),
    bspline_bound::<2>
);
basis_properties!(
    quadratic_bspline_3d,
    QuadraticBSpline,
    3,
    bspline_cases::<3>(),
    bspline_bound::<3>
);

/// The finite-difference check must actually run: count the CPDI2 cases it
/// applies to in a fixed sample, so a strategy change cannot silently turn
/// it off.
#[test]
fn cpdi2_finite_difference_check_applies_to_in_cell_parallelograms() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let strategy = cpdi2_cases::<3>();
    let mut applicable = 0;
    for _ in 0..200 {
        let (x, c) = strategy.new_tree(&mut runner).expect("tree").current();
        if cpdi2_bound(&x, &c, 0).is_some() {
            applicable += 1;
        }
    }
    assert!(applicable >= 50, "only {applicable} of 200 cases checked");
}

/// The simplex finite-difference check must run on most cases: points off
/// the node lines are mostly well inside an element.
#[test]
fn simplex_finite_difference_check_applies_inside_elements() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let strategy = linear_cases::<3>();
    let mut applicable = 0;
    for _ in 0..200 {
        let (x, ()) = strategy.new_tree(&mut runner).expect("tree").current();
        if (0..3).all(|axis| simplex_bound(&x, &(), axis).is_some()) {
            applicable += 1;
        }
    }
    assert!(applicable >= 50, "only {applicable} of 200 cases checked");
}
basis_properties!(
    boundary_bspline_2d,
    BoundaryBSpline,
    2,
    boundary_bspline_cases::<2>(),
    boundary_bspline_bound::<2>
);
basis_properties!(
    boundary_bspline_3d,
    BoundaryBSpline,
    3,
    boundary_bspline_cases::<3>(),
    boundary_bspline_bound::<3>
);
