//! Proptest strategies for the property tests of constitutive laws
//! : large rotations, stretches with repeated and nearly
//! repeated eigenvalues, deformation gradients built from them, Poisson
//! ratios up to the nearly incompressible limit, and converged states.

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use proptest::prelude::*;
use proptest::test_runner::FileFailurePersistence;

/// Cases per property of the crate's tests and of
/// [`crate::law_tangent_properties!`].
pub const CASES: u32 = 256;

/// The configuration of the property tests: [`CASES`] cases, failures
/// persisted beside the test source that runs them (`tests/foo.rs` →
/// `tests/foo.proptest-regressions`), to be committed.
pub fn config() -> ProptestConfig {
    ProptestConfig {
        cases: CASES,
        failure_persistence: Some(Box::new(FileFailurePersistence::WithSource(
            "proptest-regressions",
        ))),
        ..ProptestConfig::default()
    }
}

/// A rotation about a random axis by an angle in $[0, \pi]$ (rotations up
/// to 180°).
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

/// Principal stretches in $[lo, hi]$ (log-uniform), with distinct, exactly
/// repeated, nearly repeated (relative gap $10^{-14}$–$10^{-6}$) or
/// all-equal values, in equal proportions.
///
/// # Panics
/// Unless $0 < lo \le hi < \infty$ (as proptest's own ranges do, when the
/// strategy is built).
pub fn stretches(lo: f64, hi: f64) -> impl Strategy<Value = Vector3<f64>> {
    assert!(
        lo > 0.0 && lo <= hi && hi.is_finite(),
        "stretch range [{lo}, {hi}] must satisfy 0 < lo <= hi < inf"
    );
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

/// A deformation gradient $R_1\,\operatorname{diag}(\lambda)\,R_2$ with
/// [`rotation`]s $R_1, R_2$ and [`stretches`] $\lambda$ in $[lo, hi]$.
///
/// # Panics
/// As [`stretches`].
pub fn deformation_gradient(lo: f64, hi: f64) -> impl Strategy<Value = Matrix3<f64>> {
    (rotation(), stretches(lo, hi), rotation())
        .prop_map(|(r1, s, r2)| r1 * Matrix3::from_diagonal(&s) * r2)
}

/// Poisson's ratio in $[0, 0.4999]$, with $0$ and the nearly incompressible
/// limit $0.4999$ drawn explicitly.
pub fn poisson_ratio() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.4999), Just(0.0), 0.0f64..0.4999]
}

/// A random converged state $(F_n, b^e_n)$: $F_n$ with moderate stretches
/// (0.8–1.25) and a $b^e_n = F^e_n F^{eT}_n$ drawn independently, so that
/// it differs from $F_nF_n^T$ as after earlier plastic flow.
pub fn converged_state() -> impl Strategy<Value = (Matrix3<f64>, Matrix3<f64>)> {
    (
        deformation_gradient(0.8, 1.25),
        deformation_gradient(0.8, 1.25),
    )
        .prop_map(|(f_n, fe_n)| (f_n, fe_n * fe_n.transpose()))
}
