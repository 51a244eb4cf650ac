//! CPDI2 domain integrals: the 2^D-point Gauss rule against independent
//! references (5-point Gauss with a separate Jacobian, the divergence
//! theorem, closed-form areas/volumes/centroids), and the relation between
//! the CPDI2 gradient and the derivative of the values.
#![allow(missing_docs)]

use super::common;

use common::*;
use mpm_basis::{BasisError, BasisFunction, Corners, Cpdi2, Stencil};
use mpm_mesh::RegularGrid;
use nalgebra::{DMatrix, DVector, Matrix2, Matrix3, Vector2, Vector3};
use proptest::prelude::*;

/// 5-point Gauss–Legendre rule on [-1, 1] (exact to degree 9).
fn gauss5() -> [(f64, f64); 5] {
    let a = (5.0 - 2.0 * (10.0f64 / 7.0).sqrt()).sqrt() / 3.0;
    let b = (5.0 + 2.0 * (10.0f64 / 7.0).sqrt()).sqrt() / 3.0;
    let wa = (322.0 + 13.0 * 70.0f64.sqrt()) / 900.0;
    let wb = (322.0 - 13.0 * 70.0f64.sqrt()) / 900.0;
    [(-b, wb), (-a, wa), (0.0, 128.0 / 225.0), (a, wa), (b, wb)]
}

/// Tensor 5-point rule on [-1, 1]^n: (points, weights).
fn tensor_rule(n: usize) -> Vec<(Vec<f64>, f64)> {
    let g = gauss5();
    let mut rule = vec![(Vec::new(), 1.0)];
    for _ in 0..n {
        rule = rule
            .into_iter()
            .flat_map(|(p, w)| {
                g.iter().map(move |&(x, wx)| {
                    let mut q = p.clone();
                    q.push(x);
                    (q, w * wx)
                })
            })
            .collect();
    }
    rule
}

/// Independent multilinear corner function and gradient on the reference
/// cube (written out again here, not taken from the crate).
fn m_hat(c: usize, xi: &[f64]) -> (f64, DVector<f64>) {
    let d = xi.len();
    let s = |i: usize| if (c >> i) & 1 == 1 { 1.0 } else { -1.0 };
    let value = (0..d).map(|i| 0.5 * (1.0 + s(i) * xi[i])).product();
    let gradient = DVector::from_fn(d, |j, _| {
        (0..d)
            .map(|i| {
                if i == j {
                    0.5 * s(i)
                } else {
                    0.5 * (1.0 + s(i) * xi[i])
                }
            })
            .product()
    });
    (value, gradient)
}

fn jacobian(points: &[DVector<f64>], xi: &[f64]) -> DMatrix<f64> {
    let d = xi.len();
    let mut j = DMatrix::zeros(d, d);
    for (c, x) in points.iter().enumerate() {
        j += x * m_hat(c, xi).1.transpose();
    }
    j
}

fn dynamic<const D: usize>(corners: &Corners<D>) -> Vec<DVector<f64>> {
    corners
        .as_slice()
        .iter()
        .map(|p| DVector::from_column_slice(p.as_slice()))
        .collect()
}

/// V, w_c and w^g_c by the 5-point tensor rule with nalgebra's dynamic
/// determinant and inverse.
fn reference_integrals(points: &[DVector<f64>], d: usize) -> (f64, Vec<f64>, Vec<DVector<f64>>) {
    let n = points.len();
    let mut volume = 0.0;
    let mut w = vec![0.0; n];
    let mut wg = vec![DVector::zeros(d); n];
    for (xi, weight) in tensor_rule(d) {
        let j = jacobian(points, &xi);
        let det = j.determinant();
        let inverse = j.clone().try_inverse().expect("regular Jacobian");
        volume += weight * det;
        for c in 0..n {
            let (m, g) = m_hat(c, &xi);
            w[c] += weight * m * det;
            wg[c] += inverse.transpose() * g * (weight * det);
        }
    }
    for c in 0..n {
        w[c] /= volume;
        wg[c] /= volume;
    }
    (volume, w, wg)
}

/// w^g_c V = ∮ M_c n dA = Σ_faces ∫ M̂_c cof(J) N dA_ref (Nanson), with the
/// 5-point rule on every face of the reference cube.
fn boundary_gradient_integrals(points: &[DVector<f64>], d: usize) -> Vec<DVector<f64>> {
    let n = points.len();
    let mut out = vec![DVector::zeros(d); n];
    for k in 0..d {
        for side in [-1.0, 1.0] {
            for (face_xi, weight) in tensor_rule(d - 1) {
                let mut xi = face_xi.clone();
                xi.insert(k, side);
                let j = jacobian(points, &xi);
                let cof = j
                    .clone()
                    .try_inverse()
                    .expect("regular Jacobian")
                    .transpose()
                    * j.determinant();
                let normal = DVector::from_fn(d, |i, _| if i == k { side } else { 0.0 });
                let flux = cof * normal;
                for (c, integral) in out.iter_mut().enumerate() {
                    *integral += &flux * (weight * m_hat(c, &xi).0);
                }
            }
        }
    }
    out
}

fn check_against_references<const D: usize>(corners: &Corners<D>) -> Result<(), TestCaseError> {
    let w = Cpdi2::domain_integrals(corners).expect("valid domain");
    let points = dynamic(corners);
    let (volume, value_weights, gradient_weights) = reference_integrals(&points, D);
    let boundary = boundary_gradient_integrals(&points, D);
    let scale = corners
        .as_slice()
        .iter()
        .map(|p| (p - corners.as_slice()[0]).norm())
        .fold(0.0, f64::max);
    prop_assert!(
        (w.volume - volume).abs() <= 1e-13 * volume,
        "volume {} vs {}",
        w.volume,
        volume
    );
    for c in 0..Corners::<D>::COUNT {
        prop_assert!(
            (w.value_weights[c] - value_weights[c]).abs() <= 1e-13,
            "w_{} = {} vs {}",
            c,
            w.value_weights[c],
            value_weights[c]
        );
        let ours = DVector::from_column_slice(w.gradient_weights[c].as_slice());
        let tol = 1e-12 / scale;
        prop_assert!(
            (&ours - &gradient_weights[c]).norm() <= tol,
            "w^g_{} = {} vs {}",
            c,
            ours,
            gradient_weights[c]
        );
        let surface = &boundary[c] / w.volume;
        prop_assert!(
            (&ours - &surface).norm() <= tol,
            "w^g_{} = {} vs boundary integral {}",
            c,
            ours,
            surface
        );
    }
    Ok(())
}

proptest! {
    #[test]
    fn weights_are_exact_2d((_, corners) in cpdi2_cases::<2>()) {
        check_against_references(&corners)?;
    }

    #[test]
    fn weights_are_exact_3d((_, corners) in cpdi2_cases::<3>()) {
        check_against_references(&corners)?;
    }

    /// 2D closed forms independent of any quadrature: the shoelace area and
    /// w^g_c = (x_next - x_prev)^⊥ / (2V) in counter-clockwise order.
    #[test]
    fn quadrilateral_area_and_gradient_weights_in_closed_form((_, corners) in cpdi2_cases::<2>()) {
        let p = corners.as_slice();
        let ccw = [0, 1, 3, 2];
        // Shoelace relative to corner 0, avoiding cancellation of the large
        // absolute cross products of a small domain far from the origin.
        let area = 0.5 * (0..4)
            .map(|i| {
                let (a, b) = (p[ccw[i]] - p[0], p[ccw[(i + 1) % 4]] - p[0]);
                a.x * b.y - b.x * a.y
            })
            .sum::<f64>();
        let w = Cpdi2::domain_integrals(&corners).expect("valid domain");
        prop_assert!((w.volume - area).abs() <= 1e-13 * area);
        for i in 0..4 {
            let (prev, next) = (p[ccw[(i + 3) % 4]], p[ccw[(i + 1) % 4]]);
            let e = next - prev;
            let expected = Vector2::new(e.y, -e.x) / (2.0 * area);
            let got = w.gradient_weights[ccw[i]];
            prop_assert!((got - expected).norm() <= 1e-12 * expected.norm().max(1.0));
        }
    }
}

#[test]
fn frustum_volume_and_centroid() {
    // Square half-side a at z = -c and b at z = +c (a frustum of a square
    // pyramid): V = 8c(a² + ab + b²)/3, centroid height ∫ z A(z) dz / V.
    let (a, b, c) = (0.3, 0.1, 0.2);
    let corners = Corners::<3>::from_fn(|k| {
        let s = Corners::<3>::reference(k);
        let half = if s.z < 0.0 { a } else { b };
        Vector3::new(1.0 + s.x * half, 2.0 + s.y * half, 3.0 + s.z * c)
    });
    let volume = corners.volume().expect("valid");
    let expected = 8.0 * c * (a * a + a * b + b * b) / 3.0;
    assert!(
        (volume - expected).abs() <= 1e-15 * expected.max(1.0),
        "{volume} vs {expected}"
    );
    // A(z) = 4 s(z)², s(z) = a + (b - a)(z + c)/(2c); ∫ z A dz over [-c, c].
    let moment: f64 = {
        let rule = gauss5();
        rule.iter()
            .map(|&(t, w)| {
                let z = c * t;
                let s = a + (b - a) * (z + c) / (2.0 * c);
                w * c * z * 4.0 * s * s
            })
            .sum()
    };
    let centroid = corners.centroid().expect("valid");
    assert!((centroid - Vector3::new(1.0, 2.0, 3.0 + moment / expected)).norm() <= 1e-14);
}

#[test]
fn trapezoid_centroid() {
    // Trapezoid with parallel sides 2a (bottom, y = 0) and 2b (top, y = H):
    // area H (a + b), centroid height H/3 (a + 2b)/(a + b).
    let (a, b, height) = (0.4, 0.2, 0.3);
    let corners = Corners::<2>::from_slice(&[
        Vector2::new(-a, 0.0),
        Vector2::new(a, 0.0),
        Vector2::new(-b, height),
        Vector2::new(b, height),
    ])
    .expect("four corners");
    let area = corners.volume().expect("valid");
    assert!((area - height * (a + b)).abs() <= 1e-15);
    let centroid = corners.centroid().expect("valid");
    let y_bar = height / 3.0 * (a + 2.0 * b) / (a + b);
    assert!(
        (centroid - Vector2::new(0.0, y_bar)).norm() <= 1e-15,
        "{centroid}"
    );
}

#[test]
fn affine_domains_have_volume_det_a_times_two_to_the_d() {
    let a2 = Matrix2::new(0.3, 0.05, -0.1, 0.2);
    let v2 = Corners::affine(&Vector2::new(1.0, 1.0), &a2)
        .volume()
        .expect("valid");
    assert!((v2 - 4.0 * a2.determinant()).abs() <= 1e-15);
    let a3 = Matrix3::new(0.3, 0.05, 0.0, -0.1, 0.2, 0.04, 0.02, 0.0, 0.25);
    let v3 = Corners::affine(&Vector3::new(1.0, 1.0, 1.0), &a3)
        .volume()
        .expect("valid");
    assert!((v3 - 8.0 * a3.determinant()).abs() <= 1e-15);
}

/// Largest |translation derivative - CPDI2 gradient| along x for an affine
/// domain inside one unit cell.
fn translation_mismatch(a: &Matrix3<f64>) -> f64 {
    let grid = RegularGrid::new(Vector3::zeros(), Vector3::new(1.0, 1.0, 1.0), [4, 4, 4])
        .expect("valid grid");
    let centre = Vector3::new(1.5, 1.5, 1.5);
    let corners = Corners::affine(&centre, a);
    let eval = |c: &Corners<3>| {
        let mut s = Stencil::for_basis::<Cpdi2>();
        Cpdi2
            .evaluate(&grid, &centre, c, &mut s)
            .expect("valid domain");
        s
    };
    let base = eval(&corners);
    let step = 1e-5;
    let e = Vector3::new(step, 0.0, 0.0);
    let (plus, minus) = (
        eval(&corners.translated(&e)),
        eval(&corners.translated(&-e)),
    );
    base.iter()
        .map(|(node, _, g)| {
            let fd = (value_of(&plus, node) - value_of(&minus, node)) / (2.0 * step);
            (fd - g.x).abs()
        })
        .fold(0.0, f64::max)
}

/// The CPDI2 gradient is the domain average of the gradient of the corner
/// interpolant. Inside one cell it equals the derivative of the values
/// under translation when every edge is parallel to a coordinate plane
/// (trilinear N_v at most quadratic along edges), and not for a fully
/// sheared parallelepiped (cubic xyz term along the edges). Both values are
/// linear in the translation inside one cell, so the central difference is
/// exact up to rounding (~1e-11 with this step).
#[test]
fn cpdi2_gradient_is_translation_derivative_only_for_planar_edges() {
    let s = 0.08;
    let planar = Matrix3::new(0.2, s, 0.0, 0.0, 0.2, s, s, 0.0, 0.2);
    let full = Matrix3::new(0.2, s, s, s, 0.2, s, s, s, 0.2);
    let m_planar = translation_mismatch(&planar);
    let m_full = translation_mismatch(&full);
    assert!(m_planar <= 1e-9, "planar shear: mismatch {m_planar:e}");
    assert!(m_full >= 1e-3, "full shear: mismatch only {m_full:e}");
}

#[test]
fn bad_domains_are_typed_errors() {
    let grid = RegularGrid::new(Vector2::zeros(), Vector2::new(1.0, 1.0), [4, 4]).expect("grid");
    let centre = Vector2::new(2.0, 2.0);
    let mut stencil = Stencil::for_basis::<Cpdi2>();
    let good = Corners::rectangle(&centre, &Vector2::new(0.2, 0.3));

    // Inverted: mirror the domain (swap corners 0 <-> 1 and 2 <-> 3).
    let p = good.as_slice();
    let inverted = Corners::from_slice(&[p[1], p[0], p[3], p[2]]).expect("four corners");
    let err = Cpdi2.evaluate(&grid, &centre, &inverted, &mut stencil);
    assert!(
        matches!(&err, Err(BasisError::DegenerateDomain { determinant, .. }) if *determinant < 0.0),
        "{err:?}"
    );
    assert!(stencil.is_empty());

    // Collapsed to a point.
    let collapsed = Corners::<2>::from_fn(|_| centre);
    let err = Cpdi2.evaluate(&grid, &centre, &collapsed, &mut stencil);
    assert!(
        matches!(err, Err(BasisError::DegenerateDomain { determinant, .. }) if determinant == 0.0)
    );

    // A NaN corner is named.
    let nan = good.map(|x| {
        if x.x > 2.0 && x.y > 2.0 {
            Vector2::new(f64::NAN, x.y)
        } else {
            *x
        }
    });
    let err = Cpdi2.evaluate(&grid, &centre, &nan, &mut stencil);
    assert!(
        matches!(err, Err(BasisError::NonFiniteCorner { corner: 3, .. })),
        "{err:?}"
    );

    // A corner outside the grid is named, and the stencil is left empty
    // even though earlier corners were inside.
    Cpdi2
        .evaluate(&grid, &centre, &good, &mut stencil)
        .expect("valid");
    assert!(!stencil.is_empty());
    let outside = good.map(|x| {
        if x.x > 2.0 && x.y > 2.0 {
            x + Vector2::new(5.0, 0.0)
        } else {
            *x
        }
    });
    let err = Cpdi2.evaluate(&grid, &centre, &outside, &mut stencil);
    assert!(
        matches!(&err, Err(BasisError::CornerOutsideGrid { corner: 3, point })
            if (point[0] - 7.2).abs() < 1e-12 && (point[1] - 2.3).abs() < 1e-12),
        "{err:?}"
    );
    assert!(stencil.is_empty());
}

#[test]
fn large_domains_merge_corner_contributions() {
    // A domain spanning 3 x 3 cells: each corner contributes its own cell's
    // 4 nodes, 16 distinct nodes in all, each listed once.
    let grid = RegularGrid::new(Vector2::zeros(), Vector2::new(1.0, 1.0), [6, 6]).expect("grid");
    let centre = Vector2::new(3.0, 3.0);
    let corners = Corners::rectangle(&centre, &Vector2::new(1.4, 1.3));
    let mut stencil = Stencil::for_basis::<Cpdi2>();
    Cpdi2
        .evaluate(&grid, &centre, &corners, &mut stencil)
        .expect("valid");
    assert_eq!(stencil.len(), 16);
    assert_eq!(<Cpdi2 as BasisFunction<2>>::MAX_NODES, 16);
    // A shared node: corners 0 and 1 are in different cells along x but a
    // small domain around a node shares that node among all four corners.
    let small = Corners::rectangle(&centre, &Vector2::new(0.2, 0.2));
    Cpdi2
        .evaluate(&grid, &centre, &small, &mut stencil)
        .expect("valid");
    assert_eq!(stencil.len(), 9);
    let node = grid.node_id([3, 3]).expect("node");
    let i = stencil.position(node).expect("centre node present");
    // Each corner sees N_v = 0.8 * 0.8 at the centre node, weights 1/4.
    assert!((stencil.values[i] - 0.64).abs() <= 1e-14);
    let sum: f64 = stencil.values.iter().sum();
    assert!((sum - 1.0).abs() <= 1e-14);
    // By symmetry the centre node's gradient vanishes.
    assert!(stencil.gradients[i].norm() <= 1e-14);
}
