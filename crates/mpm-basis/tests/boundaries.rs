//! Grid boundaries and bad input: typed errors naming the point, stencils
//! left empty on error, the B-spline admissible region, GIMP domains that
//! stick out of the grid.
#![allow(missing_docs)]

use super::common;

use common::*;
use mpm_basis::{
    BasisError, BasisFunction, Corners, Cpdi2, Gimp, LinearMpm, QuadraticBSpline, Stencil,
};
use mpm_mesh::{MeshError, RegularGrid};
use nalgebra::{SVector, Vector2, Vector3};

/// A stencil holding stale entries, to check that errors clear it.
fn dirty<const D: usize>() -> Stencil<D> {
    let mut s = Stencil::with_capacity(64);
    s.push(12345, 0.5, SVector::repeat(1.0));
    s
}

fn assert_outside_error<const D: usize>(result: Result<(), BasisError>, x: &SVector<f64, D>) {
    match result {
        Err(BasisError::Mesh(MeshError::PointOutsideGrid { point, .. })) => {
            assert_eq!(point.len(), D);
            for (a, b) in point.iter().zip(x.iter()) {
                assert!(a == b || (a.is_nan() && b.is_nan()), "{point:?} vs {x:?}");
            }
        }
        other => panic!("point {x:?}: expected PointOutsideGrid, got {other:?}"),
    }
}

fn points_outside<const D: usize>() -> Vec<SVector<f64, D>> {
    let g = grid::<D>();
    let inside = (g.origin() + g.upper()) * 0.5;
    let mut points = Vec::new();
    for axis in 0..D {
        let mut below = inside;
        below[axis] = g.origin()[axis] - 1e-9;
        let mut above = inside;
        above[axis] = g.upper()[axis] + 1e-9;
        let mut nan = inside;
        nan[axis] = f64::NAN;
        points.extend([below, above, nan]);
    }
    points
}

fn outside_points_are_errors<const D: usize>() {
    let g = grid::<D>();
    for x in points_outside::<D>() {
        let mut s = dirty::<D>();
        assert_outside_error(LinearMpm.evaluate(&g, &x, &(), &mut s), &x);
        assert!(s.is_empty());
        let mut s = dirty::<D>();
        assert_outside_error(Gimp.evaluate(&g, &x, &SVector::repeat(0.01), &mut s), &x);
        assert!(s.is_empty());
        let mut s = dirty::<D>();
        assert_outside_error(QuadraticBSpline.evaluate(&g, &x, &(), &mut s), &x);
        assert!(s.is_empty());
        // CPDI2 uses the corners only: a domain around the outside point.
        let mut s = dirty::<D>();
        let corners = Corners::rectangle(&x, &SVector::repeat(0.01));
        let err = Cpdi2.evaluate(&g, &x, &corners, &mut s);
        assert!(
            matches!(
                err,
                Err(BasisError::CornerOutsideGrid { .. } | BasisError::NonFiniteCorner { .. })
            ),
            "{err:?}"
        );
        assert!(s.is_empty());
    }
}

#[test]
fn points_outside_the_grid_are_typed_errors_naming_the_point() {
    outside_points_are_errors::<2>();
    outside_points_are_errors::<3>();
}

#[test]
fn error_messages_name_the_point() {
    let g = grid::<2>();
    let mut s = Stencil::for_basis::<QuadraticBSpline>();
    let x = Vector2::new(-1.1, 1.0);
    let err = QuadraticBSpline
        .evaluate(&g, &x, &(), &mut s)
        .expect_err("too close to the boundary");
    assert_eq!(
        err,
        BasisError::StencilOutsideGrid {
            point: vec![-1.1, 1.0],
            axis: 0
        }
    );
    assert!(err.to_string().contains("[-1.1, 1.0]"), "{err}");
    let err = LinearMpm
        .evaluate(&g, &Vector2::new(9.0, 1.0), &(), &mut s)
        .expect_err("outside");
    assert!(err.to_string().contains("[9.0, 1.0]"), "{err}");
}

/// The B-spline admissible region is closed: exactly half a cell inside is
/// fine (the outer spline is exactly zero there and omitted), any closer is
/// an error naming the axis, on both sides of every axis.
#[test]
fn bspline_admissible_region_is_half_a_cell_inside_the_grid() {
    let g = grid::<3>();
    // Away from node lines and mid-lines: three nodes along the other axes.
    let centre = g.origin() + SVector::<f64, 3>::from_fn(|i, _| 2.3 * SPACING[i]);
    for axis in 0..3 {
        let h = SPACING[axis];
        for (edge, inward) in [(g.origin()[axis], 1.0), (g.upper()[axis], -1.0)] {
            let mut s = Stencil::for_basis::<QuadraticBSpline>();
            let mut x = centre;
            x[axis] = edge + inward * 0.5 * h;
            QuadraticBSpline
                .evaluate(&g, &x, &(), &mut s)
                .expect("exactly half a cell inside");
            let sum: f64 = s.values.iter().sum();
            assert!((sum - 1.0).abs() <= 1e-12);
            // Two nodes along this axis, three along the others. (When
            // o + h/2 is not representable the point sits an ulp further
            // inside and a third node appears with a value ~1e-31.)
            let significant = s.values.iter().filter(|&&v| v > 1e-12).count();
            assert_eq!(significant, 2 * 3 * 3);
            assert!(s.nodes.iter().all(|&n| n < g.node_count()));
            for depth in [0.0, 0.25 * h, 0.5 * h * (1.0 - 1e-12)] {
                x[axis] = edge + inward * depth;
                let mut s = dirty::<3>();
                let err = QuadraticBSpline.evaluate(&g, &x, &(), &mut s);
                assert!(
                    matches!(&err, Err(BasisError::StencilOutsideGrid { axis: a, .. }) if *a == axis),
                    "axis {axis}, depth {depth}: {err:?}"
                );
                assert!(s.is_empty());
            }
        }
    }
}

#[test]
fn gimp_rejects_bad_half_lengths() {
    let g = grid::<2>();
    let x = Vector2::new(0.1, 1.0);
    let mut s = dirty::<2>();
    for (axis, bad) in [
        (0, -1e-9),
        (1, 0.125 + 1e-12),
        (0, f64::NAN),
        (1, f64::INFINITY),
    ] {
        let mut l = Vector2::new(0.1, 0.1);
        l[axis] = bad;
        let err = Gimp.evaluate(&g, &x, &l, &mut s);
        match err {
            Err(BasisError::InvalidHalfLength {
                axis: a,
                half_length,
                max,
                point,
            }) => {
                assert_eq!(a, axis);
                assert!(half_length == bad || (half_length.is_nan() && bad.is_nan()));
                assert_eq!(max, 0.5 * SPACING[axis]);
                assert_eq!(point, vec![0.1, 1.0]);
            }
            other => panic!("half-length {bad} on axis {axis}: {other:?}"),
        }
        assert!(s.is_empty());
    }
    // The largest admissible half-length is fine.
    Gimp.evaluate(&g, &x, &Vector2::new(0.25, 0.125), &mut s)
        .expect("l = h/2 is admissible");
}

/// Near the boundary GIMP writes only existing nodes; the weight that would
/// go to the missing nodes beyond the boundary is lost. Per axis that is
/// S(δ; λ) of the missing node: a domain centred on the boundary loses
/// (1/2l)∫_0^l (r/h) dr = λ/4, not the half of the domain outside (the
/// boundary node's hat extends beyond the grid).
#[test]
fn gimp_domain_sticking_out_keeps_only_existing_nodes() {
    let g = grid::<3>();
    let l = Vector3::new(0.2, 0.1, 0.15);
    let lambda = SVector::<f64, 3>::from_fn(|i, _| l[i] / SPACING[i]);
    // At the lower corner of the grid: each axis loses λ/4.
    let x = *g.origin();
    let mut s = Stencil::for_basis::<Gimp>();
    Gimp.evaluate(&g, &x, &l, &mut s).expect("point inside");
    let sum: f64 = s.values.iter().sum();
    let expected: f64 = lambda.iter().map(|&lam| 1.0 - 0.25 * lam).product();
    assert!(
        (sum - expected).abs() <= 1e-15,
        "sum {sum}, expected {expected}"
    );
    assert!(s.nodes.iter().all(|&n| n < g.node_count()));
    // Half a half-length inside the upper face along axis 0 (λ = 0.4): the
    // missing node sits at δ = -1.2 - ... its weight is S(t - 2; λ) with
    // t = 1 - λ/2 = 0.8.
    let mut x = g.origin() + SVector::<f64, 3>::from_fn(|i, _| 2.3 * SPACING[i]);
    x[0] = g.upper()[0] - 0.5 * l[0];
    Gimp.evaluate(&g, &x, &l, &mut s).expect("point inside");
    let sum: f64 = s.values.iter().sum();
    let (missing, _) = Gimp::shape_1d(0.8 - 2.0, 0.4);
    assert!((missing - 0.025).abs() <= 1e-15);
    assert!((sum - (1.0 - missing)).abs() <= 1e-14, "sum {sum}");
    assert!(s.nodes.iter().all(|&n| n < g.node_count()));
}

/// Evaluation reuses the caller's buffer: after the first call the
/// capacity never changes, whatever the point.
#[test]
fn evaluation_does_not_grow_the_stencil() {
    let g = grid::<3>();
    let mut s = Stencil::for_basis::<Cpdi2>();
    let capacity = (
        s.nodes.capacity(),
        s.values.capacity(),
        s.gradients.capacity(),
    );
    for k in 0..200 {
        let t = f64::from(k) / 200.0;
        let x = Vector3::new(-0.5 + 1.5 * t, 1.0 + 0.5 * t, 2.5 + t);
        let corners = Corners::rectangle(&x, &Vector3::new(0.3 + 0.2 * t, 0.2, 0.25));
        Cpdi2.evaluate(&g, &x, &corners, &mut s).expect("inside");
        LinearMpm.evaluate(&g, &x, &(), &mut s).expect("inside");
        Gimp.evaluate(&g, &x, &Vector3::new(0.25, 0.125, 0.2), &mut s)
            .expect("inside");
        QuadraticBSpline
            .evaluate(&g, &x, &(), &mut s)
            .expect("inside");
    }
    assert_eq!(
        (
            s.nodes.capacity(),
            s.values.capacity(),
            s.gradients.capacity()
        ),
        capacity
    );
}

#[test]
fn max_nodes_per_basis() {
    assert_eq!(<LinearMpm as BasisFunction<2>>::MAX_NODES, 4);
    assert_eq!(<LinearMpm as BasisFunction<3>>::MAX_NODES, 8);
    assert_eq!(<Gimp as BasisFunction<2>>::MAX_NODES, 9);
    assert_eq!(<Gimp as BasisFunction<3>>::MAX_NODES, 27);
    assert_eq!(<QuadraticBSpline as BasisFunction<2>>::MAX_NODES, 9);
    assert_eq!(<QuadraticBSpline as BasisFunction<3>>::MAX_NODES, 27);
    assert_eq!(<Cpdi2 as BasisFunction<2>>::MAX_NODES, 16);
    assert_eq!(<Cpdi2 as BasisFunction<3>>::MAX_NODES, 64);
}

#[test]
fn grids_other_than_the_test_grid_work_too() {
    // A 1 x 1 cell grid: the smallest possible.
    let g = RegularGrid::new(Vector2::new(0.0, 0.0), Vector2::new(2.0, 3.0), [1, 1]).expect("grid");
    let mut s = Stencil::for_basis::<Gimp>();
    Gimp.evaluate(&g, &Vector2::new(1.0, 1.5), &Vector2::new(1.0, 1.5), &mut s)
        .expect("domain fills the cell");
    let sum: f64 = s.values.iter().sum();
    assert!((sum - 1.0).abs() <= 1e-15);
    // In a single cell only the centre is admissible for B-splines.
    QuadraticBSpline
        .evaluate(&g, &Vector2::new(1.0, 1.5), &(), &mut s)
        .expect("the cell centre is exactly half a cell inside");
    let sum: f64 = s.values.iter().sum();
    assert!((sum - 1.0).abs() <= 1e-15);
    assert_eq!(s.len(), 4);
    assert!(matches!(
        QuadraticBSpline.evaluate(&g, &Vector2::new(1.1, 1.5), &(), &mut s),
        Err(BasisError::StencilOutsideGrid { axis: 0, .. })
    ));
}
