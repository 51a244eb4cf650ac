//! Shared strategies and finite-difference helpers for the property tests.
#![allow(dead_code, clippy::unwrap_used)]

use mpm_constitutive::tensor::{Tensor4, idx};
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use proptest::prelude::*;

/// 256 cases per property; failures are persisted beside the test sources
/// (`tests/proptest-regressions/`) and committed.
pub fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 256,
        failure_persistence: Some(Box::new(
            proptest::test_runner::FileFailurePersistence::WithSource("proptest-regressions"),
        )),
        ..ProptestConfig::default()
    }
}

/// Fourth-order central difference
/// f'(x) ≈ [-f(x+2h) + 8 f(x+h) - 8 f(x-h) + f(x-2h)] / (12 h):
/// truncation O(h⁴), so a step of ~1e-4 relative to the smallest principal
/// stretch keeps both truncation (~1e-13) and round-off (~1e-12/h) far
/// below the 1e-6 tolerance of the tests.
pub fn central_difference<F>(f: F, h: f64) -> Option<Matrix3<f64>>
where
    F: Fn(f64) -> Option<Matrix3<f64>>,
{
    let p2 = f(2.0 * h)?;
    let p1 = f(h)?;
    let m1 = f(-h)?;
    let m2 = f(-2.0 * h)?;
    Some((-p2 + 8.0 * p1 - 8.0 * m1 + m2) / (12.0 * h))
}

/// The 9×9 Jacobian whose column `3k + l` is the directional derivative of
/// `f` along the perturbation `direction(k, l)`.
pub fn jacobian<F, D>(f: F, direction: D, h: f64) -> Option<Tensor4>
where
    F: Fn(&Matrix3<f64>) -> Option<Matrix3<f64>>,
    D: Fn(usize, usize) -> Matrix3<f64>,
{
    let mut out = Tensor4::zeros();
    for k in 0..3 {
        for l in 0..3 {
            let dir = direction(k, l);
            let col = central_difference(|t| f(&(t * dir)), h)?;
            for i in 0..3 {
                for j in 0..3 {
                    out[(idx(i, j), idx(k, l))] = col[(i, j)];
                }
            }
        }
    }
    Some(out)
}

/// Unit tensor E_kl.
pub fn unit(k: usize, l: usize) -> Matrix3<f64> {
    let mut e = Matrix3::zeros();
    e[(k, l)] = 1.0;
    e
}

/// Symmetric unit direction (E_kl + E_lk)/2.
pub fn sym_unit(k: usize, l: usize) -> Matrix3<f64> {
    0.5 * (unit(k, l) + unit(l, k))
}

/// Relative Frobenius error ‖a − b‖/‖b‖.
pub fn rel(a: &Tensor4, b: &Tensor4) -> f64 {
    (a - b).norm() / b.norm()
}

/// A rotation about a random axis by an angle in [0, π] (rotations up to 180°).
pub fn rotation() -> impl Strategy<Value = Matrix3<f64>> {
    (
        prop::array::uniform3(-1.0f64..1.0),
        0.0f64..=std::f64::consts::PI,
    )
        .prop_filter_map("axis too short", |(a, angle)| {
            let axis = Vector3::from(a);
            (axis.norm() > 1e-3)
                .then(|| Rotation3::from_axis_angle(&Unit::new_normalize(axis), angle).into_inner())
        })
}

/// Principal stretches in [lo, hi] (log-uniform), with distinct, exactly
/// repeated, nearly repeated (relative gap 1e-14..1e-6) or all-equal values.
pub fn stretches(lo: f64, hi: f64) -> impl Strategy<Value = Vector3<f64>> {
    let (a, b) = (lo.ln(), hi.ln());
    (prop::array::uniform3(a..=b), 0usize..4, -14.0f64..-6.0).prop_map(move |(l, kind, gap_exp)| {
        let mut s = Vector3::from(l.map(f64::exp));
        match kind {
            1 => s[1] = s[0],
            2 => s[1] = s[0] * (1.0 + 10f64.powf(gap_exp)),
            3 => {
                s[1] = s[0];
                s[2] = s[0];
            }
            _ => {}
        }
        s
    })
}

/// A deformation gradient R₁ diag(λ) R₂ with the given stretch range.
pub fn deformation_gradient(lo: f64, hi: f64) -> impl Strategy<Value = Matrix3<f64>> {
    (rotation(), stretches(lo, hi), rotation())
        .prop_map(|(r1, s, r2)| r1 * Matrix3::from_diagonal(&s) * r2)
}

/// Smallest singular value, used to scale finite-difference steps.
pub fn min_singular_value(f: &Matrix3<f64>) -> f64 {
    f.singular_values().min()
}

/// Poisson's ratio in [0, 0.4999], with the nearly incompressible limit
/// drawn explicitly.
pub fn poisson_ratio() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.4999), Just(0.0), 0.0f64..0.4999]
}
