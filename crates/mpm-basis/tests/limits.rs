//! Limits and relations between the bases: GIMP → standard MPM as the
//! half-length vanishes, CPDI2 with an undeformed box against GIMP (equal
//! inside one cell, a first-order trapezoidal-rule difference across node
//! lines), and continuity across cell faces.
#![allow(missing_docs)]

use super::common;

use common::*;
use mpm_basis::{BasisFunction, Corners, Cpdi2, Gimp, LinearMpm, QuadraticBSpline, Stencil};
use mpm_mesh::RegularGrid;
use nalgebra::SVector;
use proptest::prelude::*;

fn hat(r: f64) -> f64 {
    (1.0 - r.abs()).max(0.0)
}

fn eval<const D: usize, B: BasisFunction<D, Mesh = RegularGrid<D>>>(
    basis: &B,
    grid: &RegularGrid<D>,
    x: &SVector<f64, D>,
    domain: &B::Domain,
) -> Stencil<D> {
    let mut s = Stencil::for_basis::<B>();
    basis
        .evaluate(grid, x, domain, &mut s)
        .expect("evaluation inside the grid");
    s
}

/// Largest difference of values and of gradients over the union of nodes.
fn max_difference<const D: usize>(a: &Stencil<D>, b: &Stencil<D>) -> (f64, f64) {
    union_nodes(a, b)
        .into_iter()
        .fold((0.0f64, 0.0f64), |(v, g), n| {
            (
                v.max((value_of(a, n) - value_of(b, n)).abs()),
                g.max((gradient_of(a, n) - gradient_of(b, n)).norm()),
            )
        })
}

// ---------------------------------------------------------------------------
// GIMP -> standard MPM
// ---------------------------------------------------------------------------

fn gimp_zero_half_length_is_linear<const D: usize>(
    x: SVector<f64, D>,
) -> Result<(), TestCaseError> {
    let g = grid::<D>();
    let gimp = eval(&Gimp, &g, &x, &SVector::zeros());
    let linear = eval(&LinearMpm, &g, &x, &());
    prop_assert_eq!(gimp, linear);
    Ok(())
}

/// Points away from node lines with half-lengths below the distance to the
/// nearest node line: the domain contains no kink of any N_v, so GIMP is
/// exactly the standard MPM basis (up to rounding).
fn gimp_without_node_line_is_linear<const D: usize>(
    t: Vec<(usize, f64, f64)>,
) -> Result<(), TestCaseError> {
    let g = grid::<D>();
    let x =
        SVector::<f64, D>::from_fn(|i, _| node_line(i, t[i].0 % CELLS[i]) + t[i].1 * SPACING[i]);
    let l = SVector::<f64, D>::from_fn(|i, _| {
        t[i].2 * distance_to_node_line(i, x[i]).min(0.5 * SPACING[i])
    });
    let gimp = eval(&Gimp, &g, &x, &l);
    let linear = eval(&LinearMpm, &g, &x, &());
    let (dv, dg) = max_difference(&gimp, &linear);
    prop_assert!(dv <= 1e-15, "values differ by {}", dv);
    prop_assert!(dg <= 1e-13, "gradients differ by {}", dg);
    Ok(())
}

proptest! {
    #[test]
    fn gimp_with_zero_half_length_equals_linear_mpm_2d((x, ()) in linear_cases::<2>()) {
        gimp_zero_half_length_is_linear(x)?;
    }

    #[test]
    fn gimp_with_zero_half_length_equals_linear_mpm_3d((x, ()) in linear_cases::<3>()) {
        gimp_zero_half_length_is_linear(x)?;
    }

    #[test]
    fn gimp_equals_linear_mpm_when_the_domain_contains_no_node_line_2d(
        t in proptest::collection::vec((0usize..100, 0.01..0.99f64, 0.0..0.999f64), 2)
    ) {
        gimp_without_node_line_is_linear::<2>(t)?;
    }

    #[test]
    fn gimp_equals_linear_mpm_when_the_domain_contains_no_node_line_3d(
        t in proptest::collection::vec((0usize..100, 0.01..0.99f64, 0.0..0.999f64), 3)
    ) {
        gimp_without_node_line_is_linear::<3>(t)?;
    }
}

/// At a node, GIMP's value there is $(1-\lambda/2)^D$ against 1 for
/// standard MPM: the difference vanishes linearly with the half-length.
fn gimp_converges_at_a_node<const D: usize>() {
    let g = grid::<D>();
    let x = SVector::<f64, D>::from_fn(|i, _| node_line(i, 2));
    let mut previous: Option<f64> = None;
    for lambda in [1e-1, 1e-2, 1e-3, 1e-4] {
        let l = SVector::<f64, D>::from_fn(|i, _| lambda * SPACING[i]);
        let gimp = eval(&Gimp, &g, &x, &l);
        let linear = eval(&LinearMpm, &g, &x, &());
        let (dv, _) = max_difference(&gimp, &linear);
        let predicted = 1.0 - (1.0 - 0.5 * lambda).powi(D as i32);
        assert!(
            (dv - predicted).abs() <= 1e-14,
            "D = {D}, lambda = {lambda}: max |S_GIMP - S_MPM| = {dv}, predicted {predicted}"
        );
        if let Some(p) = previous {
            let ratio = p / dv;
            assert!(
                (9.0..11.0).contains(&ratio),
                "not first order: ratio {ratio}"
            );
        }
        previous = Some(dv);
    }
}

#[test]
fn gimp_converges_to_linear_mpm_as_the_half_length_vanishes() {
    gimp_converges_at_a_node::<2>();
    gimp_converges_at_a_node::<3>();
}

// ---------------------------------------------------------------------------
// CPDI2 with an undeformed box against GIMP
// ---------------------------------------------------------------------------

/// The trapezoidal-rule error of the hat average, from the kinks of the
/// hat inside (a, b): slope jumps kappa = +1 at r = ±1 and -2 at r = 0 give
/// T - A = 1/2 sum kappa (k - a)(b - k)/(b - a).
fn trapezoid_minus_average(delta: f64, lambda: f64) -> f64 {
    let (a, b) = (delta - lambda, delta + lambda);
    [(-1.0, 1.0), (0.0, -2.0), (1.0, 1.0)]
        .into_iter()
        .filter(|&(k, _)| a < k && k < b)
        .map(|(k, kappa)| 0.5 * kappa * (k - a) * (b - k) / (b - a))
        .sum()
}

proptest! {
    /// The 1D calculation behind the finding: CPDI2's factor per axis,
    /// (hat(δ-λ) + hat(δ+λ))/2, minus GIMP's exact average equals the
    /// kink formula; its size is at most λ/2, reached with a node at the
    /// domain centre. The derivative factors (secants) are identical.
    #[test]
    fn one_dimensional_cpdi2_minus_gimp_is_the_trapezoid_error(
        delta in -1.6..1.6f64,
        lambda in 1e-3..=0.5f64,
    ) {
        let trapezoid = 0.5 * (hat(delta - lambda) + hat(delta + lambda));
        let secant = (hat(delta + lambda) - hat(delta - lambda)) / (2.0 * lambda);
        let (average, slope) = Gimp::shape_1d(delta, lambda);
        let predicted = trapezoid_minus_average(delta, lambda);
        prop_assert!((trapezoid - average - predicted).abs() <= 1e-14);
        prop_assert!(predicted.abs() <= 0.5 * lambda + 1e-15);
        prop_assert!((slope - secant).abs() <= 1e-12);
    }
}

fn cpdi2_box_in_one_cell_equals_gimp<const D: usize>(
    t: Vec<(usize, f64, f64)>,
) -> Result<(), TestCaseError> {
    let g = grid::<D>();
    // lambda in (0, 1/2], centre t in [lambda, 1 - lambda]: the box lies in
    // one closed cell.
    let lambda = SVector::<f64, D>::from_fn(|i, _| t[i].2);
    let x = SVector::<f64, D>::from_fn(|i, _| {
        let local = lambda[i] + t[i].1 * (1.0 - 2.0 * lambda[i]);
        node_line(i, t[i].0 % CELLS[i]) + local * SPACING[i]
    });
    let l = SVector::<f64, D>::from_fn(|i, _| lambda[i] * SPACING[i]);
    let cpdi = eval(&Cpdi2, &g, &x, &Corners::rectangle(&x, &l));
    let gimp = eval(&Gimp, &g, &x, &l);
    let (dv, dg) = max_difference(&cpdi, &gimp);
    prop_assert!(dv <= 1e-14, "values differ by {}", dv);
    prop_assert!(dg <= 1e-12, "gradients differ by {}", dg);
    Ok(())
}

/// CPDI2 for the box x ± l anywhere: the tensor product of the 1D
/// trapezoid factors and secant slopes, differing from GIMP by at most
/// sum_i λ_i / 2.
fn cpdi2_box_is_the_trapezoid_product<const D: usize>(
    x: SVector<f64, D>,
    l: SVector<f64, D>,
) -> Result<(), TestCaseError> {
    let g = grid::<D>();
    let cpdi = eval(&Cpdi2, &g, &x, &Corners::rectangle(&x, &l));
    let gimp = eval(&Gimp, &g, &x, &l);
    let lambda = SVector::<f64, D>::from_fn(|i, _| l[i] / SPACING[i]);
    for (node, value, gradient) in cpdi.iter() {
        let xv = g.node_position(node).expect("node in grid");
        let delta = SVector::<f64, D>::from_fn(|i, _| (x[i] - xv[i]) / SPACING[i]);
        let factor = |i: usize| 0.5 * (hat(delta[i] - lambda[i]) + hat(delta[i] + lambda[i]));
        let slope = |i: usize| {
            (hat(delta[i] + lambda[i]) - hat(delta[i] - lambda[i])) / (2.0 * lambda[i]) / SPACING[i]
        };
        let expected: f64 = (0..D).map(factor).product();
        prop_assert!(
            (value - expected).abs() <= 1e-14,
            "node {}: {} vs {}",
            node,
            value,
            expected
        );
        for j in 0..D {
            let expected_j: f64 = (0..D)
                .map(|i| if i == j { slope(i) } else { factor(i) })
                .product();
            prop_assert!((gradient[j] - expected_j).abs() <= 1e-12);
        }
    }
    let bound = 0.5 * lambda.sum() + 1e-14;
    let (dv, _) = max_difference(&cpdi, &gimp);
    prop_assert!(dv <= bound, "CPDI2 - GIMP = {} > {}", dv, bound);
    Ok(())
}

proptest! {
    #[test]
    fn cpdi2_box_inside_one_cell_equals_gimp_2d(
        t in proptest::collection::vec((0usize..100, 0.0..=1.0f64, 1e-3..=0.5f64), 2)
    ) {
        cpdi2_box_in_one_cell_equals_gimp::<2>(t)?;
    }

    #[test]
    fn cpdi2_box_inside_one_cell_equals_gimp_3d(
        t in proptest::collection::vec((0usize..100, 0.0..=1.0f64, 1e-3..=0.5f64), 3)
    ) {
        cpdi2_box_in_one_cell_equals_gimp::<3>(t)?;
    }

    #[test]
    fn cpdi2_box_is_the_product_of_trapezoid_factors_2d((x, l) in gimp_cases_positive::<2>()) {
        cpdi2_box_is_the_trapezoid_product(x, l)?;
    }

    #[test]
    fn cpdi2_box_is_the_product_of_trapezoid_factors_3d((x, l) in gimp_cases_positive::<3>()) {
        cpdi2_box_is_the_trapezoid_product(x, l)?;
    }
}

/// A box centred on a node: GIMP gives $(1-\lambda/2)^D$ at that node and
/// CPDI2 $(1-\lambda)^D$. The difference is first order in the half-length
/// (halving λ halves it), not second order; only the volume-weighted
/// difference $V_p\,\Delta S$ in 1D, $l^2/h$, is quadratic.
fn cpdi2_gimp_difference_at_a_node<const D: usize>() {
    let g = grid::<D>();
    let x = SVector::<f64, D>::from_fn(|i, _| node_line(i, 2));
    let centre = g.node_id(std::array::from_fn(|_| 2)).expect("node in grid");
    let mut previous: Option<f64> = None;
    let mut ratios = Vec::new();
    for lambda in [0.4, 0.2, 0.1, 0.05, 0.025] {
        let l = SVector::<f64, D>::from_fn(|i, _| lambda * SPACING[i]);
        let cpdi = eval(&Cpdi2, &g, &x, &Corners::rectangle(&x, &l));
        let gimp = eval(&Gimp, &g, &x, &l);
        let (g_value, c_value) = (value_of(&gimp, centre), value_of(&cpdi, centre));
        let d = D as i32;
        assert!((g_value - (1.0 - 0.5 * lambda).powi(d)).abs() <= 1e-14);
        assert!((c_value - (1.0 - lambda).powi(d)).abs() <= 1e-14);
        let (dv, _) = max_difference(&cpdi, &gimp);
        assert!(
            (dv - (g_value - c_value)).abs() <= 1e-14,
            "the largest difference is at the centre node"
        );
        if D == 1 {
            let volume = Corners::rectangle(&x, &l).volume().expect("valid box");
            let h = SPACING[0];
            assert!((volume * dv - (lambda * h).powi(2) / h).abs() <= 1e-15);
        }
        // (1 - λ/2)^D - (1 - λ)^D = Dλ/2 + O(λ²) with an O(λ²) remainder
        // below D² λ²: first order, slope D/2.
        let d = D as f64;
        assert!(
            (dv / lambda - 0.5 * d).abs() <= d * d * lambda,
            "D = {D}, lambda = {lambda}: difference / lambda = {}",
            dv / lambda
        );
        if let Some(p) = previous {
            ratios.push(p / dv);
        }
        previous = Some(dv);
    }
    // Halving λ halves the difference in the limit.
    let last = ratios.last().copied().unwrap_or(0.0);
    assert!((1.9..2.1).contains(&last), "D = {D}: last ratio {last}");
}

#[test]
fn cpdi2_minus_gimp_is_first_order_in_the_half_length() {
    cpdi2_gimp_difference_at_a_node::<1>();
    cpdi2_gimp_difference_at_a_node::<2>();
    cpdi2_gimp_difference_at_a_node::<3>();
}

// ---------------------------------------------------------------------------
// Continuity across cell faces
// ---------------------------------------------------------------------------

/// Evaluate on both sides of the plane `x[axis] = plane` at distance
/// `eta`, returning the largest jumps of values and gradients.
fn jump_across<const D: usize, B: BasisFunction<D, Mesh = RegularGrid<D>>>(
    basis: &B,
    x: &SVector<f64, D>,
    domain: &B::Domain,
    shift: impl Fn(&B::Domain, &SVector<f64, D>) -> B::Domain,
    axis: usize,
    plane: f64,
    eta: f64,
) -> (f64, f64) {
    let g = grid::<D>();
    let mut e = SVector::<f64, D>::zeros();
    e[axis] = plane - eta - x[axis];
    let below = eval(basis, &g, &(x + e), &shift(domain, &e));
    e[axis] = plane + eta - x[axis];
    let above = eval(basis, &g, &(x + e), &shift(domain, &e));
    max_difference(&below, &above)
}

const ETA: f64 = 1e-10;

proptest! {
    /// GIMP (all half-lengths positive): values and gradients continuous
    /// across interior node lines. Bounds: |∂S| <= 1/h and |∂²S| <= 1/(h l).
    #[test]
    fn gimp_is_continuous_across_cell_faces(
        (x, l) in gimp_cases_positive::<3>(),
        axis in 0usize..3,
        k in 1usize..5,
    ) {
        let eta = ETA * SPACING[axis];
        let (dv, dg) = jump_across(&Gimp, &x, &l, |l, _| *l, axis, node_line(axis, k), eta);
        prop_assert!(dv <= 2.0 * eta / SPACING[axis] + 1e-15, "value jump {}", dv);
        let m: f64 = (0..3).map(|i| 1.0 / (SPACING[i] * l[i])).sum();
        prop_assert!(dg <= 2.0 * eta * m + 1e-12, "gradient jump {}", dg);
    }

    /// Quadratic B-splines: values and gradients continuous across node
    /// lines and across cell mid-lines (where the stencil switches).
    #[test]
    fn bspline_is_continuous_across_faces_and_stencil_switches(
        (x, ()) in bspline_cases::<3>(),
        axis in 0usize..3,
        k in 1usize..4,
        mid in proptest::bool::ANY,
    ) {
        let plane = node_line(axis, k) + if mid { 0.5 * SPACING[axis] } else { 0.0 };
        let eta = ETA * SPACING[axis];
        let (dv, dg) = jump_across(&QuadraticBSpline, &x, &(), |_, _| (), axis, plane, eta);
        prop_assert!(dv <= 2.0 * eta / SPACING[axis] + 1e-15, "value jump {}", dv);
        let m: f64 = (0..3).map(|i| 2.0 / (SPACING[i] * SPACING[i])).sum();
        prop_assert!(dg <= 2.0 * eta * m + 1e-12, "gradient jump {}", dg);
    }

    /// CPDI2: values and gradients continuous as a corner crosses a node
    /// line (they depend continuously on N_v at the corners).
    #[test]
    fn cpdi2_is_continuous_as_a_corner_crosses_a_face(
        (x, corners) in cpdi2_cases::<3>(),
        axis in 0usize..3,
        corner in 0usize..8,
    ) {
        let xc = corners.as_slice()[corner];
        // The node line nearest to the corner among those that keep the
        // whole domain at least 1e-6 inside the grid after the move.
        let b = corners.bounding_box();
        let (h, m) = (SPACING[axis], 1e-6);
        let k_lo = ((xc[axis] - b.lower[axis] + m) / h).ceil() as usize;
        let k_hi = ((node_line(axis, CELLS[axis]) - ORIGIN[axis] - (b.upper[axis] - xc[axis]) - m) / h)
            .floor() as usize;
        let nearest = ((xc[axis] - ORIGIN[axis]) / h).round() as usize;
        let k = nearest.max(k_lo).min(k_hi);
        // Move the domain so that the corner lies on node line k; the rest
        // of the domain must stay in the grid.
        let mut to_plane = SVector::<f64, 3>::zeros();
        to_plane[axis] = node_line(axis, k) - xc[axis];
        let moved = corners.translated(&to_plane);
        prop_assume!(moved.as_slice().iter().all(|p| {
            (0..3).all(|i| p[i] > ORIGIN[i] + 1e-6 && p[i] < node_line(i, CELLS[i]) - 1e-6)
        }));
        let _ = x;
        let eta = ETA * SPACING[axis];
        // The position argument (unused by CPDI2) tracks the corner.
        let corner_position = moved.as_slice()[corner];
        let (dv, dg) = jump_across(
            &Cpdi2,
            &corner_position,
            &moved,
            |c, e| c.translated(e),
            axis,
            node_line(axis, k),
            eta,
        );
        // N_v is Lipschitz with constant 1/h along the axis and the weights
        // do not change under translation: |ΔS| <= 2η/h, and
        // |Δ∇S| <= 2η/h · Σ_c |w^g_c|.
        let w = Cpdi2::domain_integrals(&moved).expect("valid domain");
        let wg: f64 = w.gradient_weights.iter().map(|v| v.norm()).sum();
        prop_assert!(dv <= 2.0 * eta / SPACING[axis] + 1e-15, "value jump {}", dv);
        prop_assert!(dg <= 2.0 * eta / SPACING[axis] * wg + 1e-12, "gradient jump {}", dg);
    }

    /// Calibration: the same check sees the gradient jump of standard MPM
    /// across a node line (its values are continuous).
    #[test]
    fn linear_mpm_values_are_continuous_but_gradients_jump(
        (x, ()) in linear_cases::<3>(),
        axis in 0usize..3,
        k in 1usize..5,
    ) {
        let eta = ETA * SPACING[axis];
        let (dv, dg) = jump_across(&LinearMpm, &x, &(), |_, _| (), axis, node_line(axis, k), eta);
        prop_assert!(dv <= 2.0 * eta / SPACING[axis] + 1e-15, "value jump {}", dv);
        // Node k's slope along the axis flips from +1/h to -1/h, times
        // the other axes' factors, whose largest product is >= 1/4.
        prop_assert!(dg >= 0.49 / SPACING[axis], "no gradient jump seen: {}", dg);
    }
}
