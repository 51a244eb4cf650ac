//! The property bodies behind [`crate::law_tangent_properties!`]: one function per property, generic over the law, so that
//! the macro only wires strategies to them and a crate with its own
//! strategies can call them inside its own `proptest!` block.

use std::fmt::Debug;

use nalgebra::Matrix3;
use proptest::test_runner::TestCaseError;

use mpm_constitutive::verification::{
    self as checks, STEP, TOLERANCE, check_algorithmic_tangent, check_previously_converged,
    check_spatial, hencky_strain,
};
use mpm_constitutive::{LogStrainLaw, MaterialState};

/// The law built by `make` from Young's modulus `e` and Poisson's ratio
/// `nu`; a constructor error fails the test case (the drawn constants are
/// valid for any law).
pub fn law_from<L, E: Debug>(
    make: impl Fn(f64, f64) -> Result<L, E>,
    e: f64,
    nu: f64,
) -> Result<L, TestCaseError> {
    make(e, nu).map_err(|err| {
        TestCaseError::fail(format!(
            "the law constructor failed for E = {e}, ν = {nu}: {err:?}"
        ))
    })
}

/// Turns the outcome of a check into a test-case outcome: an error fails,
/// `None` (stencil across the yield surface) rejects, an error above
/// [`TOLERANCE`] fails.
fn judge(what: &str, outcome: checks::Result<Option<f64>>) -> Result<(), TestCaseError> {
    match outcome {
        Err(err) => Err(TestCaseError::fail(format!("{what}: {err}"))),
        Ok(None) => Err(TestCaseError::reject(
            "the finite-difference stencil crosses the yield surface",
        )),
        Ok(Some(err)) if err <= TOLERANCE => Ok(()),
        Ok(Some(err)) => Err(TestCaseError::fail(format!(
            "{what}: relative error {err:e} > {TOLERANCE:e}"
        ))),
    }
}

/// [`check_previously_converged`] ($\tilde A$ against
/// $\partial\tilde P/\partial\Delta F$, eqs. 18, A.3–A.6) with [`STEP`]
/// and [`TOLERANCE`], from the converged state $(F_n, b^e_n)$ and the
/// default (virgin) history.
pub fn previously_converged_property<L: LogStrainLaw>(
    law: &L,
    delta_f: &Matrix3<f64>,
    f_n: &Matrix3<f64>,
    be_n: &Matrix3<f64>,
) -> Result<(), TestCaseError> {
    let state = MaterialState {
        be: *be_n,
        history: L::History::default(),
    };
    judge(
        "Ã against ∂P̃/∂ΔF",
        check_previously_converged(law, delta_f, f_n, &state, STEP),
    )
}

/// [`check_spatial`] ($a$ against the push-forward of $\partial P/\partial
/// F$ and the Cauchy-derivative identity, eq. A.1) with [`STEP`] and
/// [`TOLERANCE`] on both errors, from $(F_n, b^e_n)$ and the default
/// history.
pub fn spatial_property<L: LogStrainLaw>(
    law: &L,
    delta_f: &Matrix3<f64>,
    f_n: &Matrix3<f64>,
    be_n: &Matrix3<f64>,
) -> Result<(), TestCaseError> {
    let state = MaterialState {
        be: *be_n,
        history: L::History::default(),
    };
    let errors = check_spatial(law, delta_f, f_n, &state, STEP);
    judge(
        "a against the push-forward of ∂P/∂F",
        errors.map(|e| e.map(|e| e.push_forward)),
    )?;
    judge(
        "(∂σ/∂F)F against a − σ_ij δ_kl + σ_il δ_jk",
        errors.map(|e| e.map(|e| e.cauchy_derivative)),
    )
}

/// [`check_algorithmic_tangent`] ($D^{alg}$ against $\partial\tau /
/// \partial\varepsilon^{e,tr}$) with [`STEP`] and [`TOLERANCE`] at the
/// trial strain $\tfrac12\ln(FF^T)$ of `strain_f` ([`hencky_strain`]) and
/// the default history.
pub fn algorithmic_tangent_property<L: LogStrainLaw>(
    law: &L,
    strain_f: &Matrix3<f64>,
) -> Result<(), TestCaseError> {
    let outcome = hencky_strain(strain_f)
        .and_then(|eps| check_algorithmic_tangent(law, &eps, &L::History::default(), STEP));
    judge("D_alg against ∂τ/∂ε", outcome)
}

/// Generates proptest `#[test]`s verifying the tangents of a
/// [`LogStrainLaw`] by finite differences (feature `proptest`).
///
/// `law_tangent_properties!(name, constructor)` expands to a module `name`
/// holding three property tests, each over [`strategies::config`]
/// ([`strategies::CASES`] = 256 cases, failures persisted beside the
/// calling test file) and with [`TOLERANCE`] $= 10^{-6}$ and [`STEP`]:
///
/// - `previously_converged_tangent_matches_finite_differences`:
///   [`previously_converged_property`] ($\tilde A$, eqs. 18, A.3–A.6);
/// - `spatial_tangent_matches_finite_differences`: [`spatial_property`]
///   ($a$, eq. A.1, and the Cauchy-derivative identity);
/// - `algorithmic_tangent_matches_finite_differences`:
///   [`algorithmic_tangent_property`] ($D^{alg}$).
///
/// The inputs: $\Delta F$ (and, for $D^{alg}$, the $F$ of the trial strain)
/// from [`strategies::deformation_gradient`]`(0.2, 5.0)`, i.e. rotations
/// up to 180° and principal stretches 0.2–5 with repeated and nearly
/// repeated values; $(F_n, b^e_n)$ from [`strategies::converged_state`] with
/// the default history; $E$ uniform in $[10^3, 10^7)$ and
/// $\nu$ from [`strategies::poisson_ratio`] (up to 0.4999). Cases whose
/// stencil crosses the yield surface are rejected.
///
/// `constructor` is any `Fn(f64, f64) -> Result<L, E>` with `E: Debug`
/// building the law under test from Young's modulus and Poisson's ratio:
/// a closure `|e, nu| ...` or a constructor path such as
/// `HenckyElastic::new`. It is expanded inside `name`, which glob-imports
/// the caller's module, so it may name whatever the caller has in scope. A
/// plastic law should choose its yield stress relative to `e` (e.g.
/// $\rho_y = E/2$) so that both elastic and yielding steps are drawn.
///
/// A downstream crate adds this crate to its dev-dependencies, needing no
/// dependency on `proptest` of its own:
/// ```toml
/// [dev-dependencies]
/// # inside this workspace; elsewhere `path = ...` or `version = ...`
/// mpm-constitutive-proptest.workspace = true
/// ```
/// and writes, in a test file such as `tests/tangents.rs`:
/// ```
/// use mpm_constitutive::{HenckyElastic, VonMises};
///
/// mpm_constitutive_proptest::law_tangent_properties!(hencky, HenckyElastic::new);
/// mpm_constitutive_proptest::law_tangent_properties!(von_mises, |e, nu| {
///     VonMises::new(e, nu, 0.5 * e, 0.1 * e)
/// });
/// # fn main() {}
/// ```
/// (A doctest is not compiled as a test harness, so here the `#[test]`
/// functions are expanded but compiled out; the crate's own
/// `tests/tangents.rs` runs the same two invocations.)
///
/// [`LogStrainLaw`]: mpm_constitutive::LogStrainLaw
/// [`strategies::config`]: crate::strategies::config
/// [`strategies::CASES`]: crate::strategies::CASES
/// [`strategies::deformation_gradient`]: crate::strategies::deformation_gradient
/// [`strategies::converged_state`]: crate::strategies::converged_state
/// [`strategies::poisson_ratio`]: crate::strategies::poisson_ratio
/// [`TOLERANCE`]: mpm_constitutive::verification::TOLERANCE
/// [`STEP`]: mpm_constitutive::verification::STEP
/// [`previously_converged_property`]: crate::previously_converged_property
/// [`spatial_property`]: crate::spatial_property
/// [`algorithmic_tangent_property`]: crate::algorithmic_tangent_property
#[macro_export]
macro_rules! law_tangent_properties {
    ($name:ident, $constructor:expr $(,)?) => {
        mod $name {
            #[allow(unused_imports)]
            use super::*;

            $crate::proptest::proptest! {
                #![proptest_config($crate::strategies::config())]

                #[test]
                fn previously_converged_tangent_matches_finite_differences(
                    delta_f in $crate::strategies::deformation_gradient(0.2, 5.0),
                    (f_n, be_n) in $crate::strategies::converged_state(),
                    e in 1e3f64..1e7,
                    nu in $crate::strategies::poisson_ratio(),
                ) {
                    let law = $crate::law_from($constructor, e, nu)?;
                    $crate::previously_converged_property(&law, &delta_f, &f_n, &be_n)?;
                }

                #[test]
                fn spatial_tangent_matches_finite_differences(
                    delta_f in $crate::strategies::deformation_gradient(0.2, 5.0),
                    (f_n, be_n) in $crate::strategies::converged_state(),
                    e in 1e3f64..1e7,
                    nu in $crate::strategies::poisson_ratio(),
                ) {
                    let law = $crate::law_from($constructor, e, nu)?;
                    $crate::spatial_property(&law, &delta_f, &f_n, &be_n)?;
                }

                #[test]
                fn algorithmic_tangent_matches_finite_differences(
                    strain_f in $crate::strategies::deformation_gradient(0.2, 5.0),
                    e in 1e3f64..1e7,
                    nu in $crate::strategies::poisson_ratio(),
                ) {
                    let law = $crate::law_from($constructor, e, nu)?;
                    $crate::algorithmic_tangent_property(&law, &strain_f)?;
                }
            }
        }
    };
}
