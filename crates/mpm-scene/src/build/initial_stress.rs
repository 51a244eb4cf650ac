//! A body's `initial_stress`: the elastic left Cauchy–Green tensor each of
//! its points starts from, so that the law returns the given stress at
//! $F = 1$.
//!
//! At $F = 1$ the Kirchhoff stress is the Cauchy stress, and the laws'
//! elasticity is linear between Hencky strain and Kirchhoff stress: the
//! elastic strain of a principal stress $\sigma$ is $\varepsilon_a =
//! ((1+\nu)\sigma_a - \nu\sum_b\sigma_b)/E$ and $b^e = \exp 2\varepsilon$
//! (diagonal: the geostatic and isotropic states are principal in the
//! coordinate axes). The state must lie inside the material's yield
//! surface (a law such as Cam-Clay has no stress-free state, and a
//! geostatic state beyond yield is not an equilibrium the solver can start
//! from): the return map of the elastic strain must be elastic at every
//! point, or the key is refused with the first point that yields.

use mpm_constitutive::{LogStrainLaw, SymSpectral};
use nalgebra::{Matrix3, SVector, Vector3};

use super::BuiltMaterial;
use super::bodies::BuiltBodies;
use crate::SceneError;
use crate::format::{BodySpec, InitialStressSpec};
use crate::material::SceneLaw;
use crate::source::SceneSource;

/// The principal stresses of `spec` at `x` (compression negative).
fn stress_at<const D: usize>(spec: &InitialStressSpec, x: &SVector<f64, D>) -> Vector3<f64> {
    match *spec {
        InitialStressSpec::Geostatic {
            surface,
            unit_weight,
            k0,
        } => {
            let vertical = -unit_weight * (surface - x[D - 1]).max(0.0);
            let mut s = Vector3::from_element(k0 * vertical);
            s[D - 1] = vertical;
            s
        }
        InitialStressSpec::Isotropic { pressure } => Vector3::from_element(-pressure),
    }
}

/// Checks the numbers of `spec` at its key.
fn check_spec(
    spec: &toml::Spanned<InitialStressSpec>,
    src: &SceneSource,
) -> Result<(), SceneError> {
    let bad = |m: &str| Err(src.at(spec, format!("initial_stress: {m}")));
    match *spec.get_ref() {
        InitialStressSpec::Geostatic {
            surface,
            unit_weight,
            k0,
        } => {
            if !surface.is_finite() {
                return bad("`surface` must be finite (m)");
            }
            if !(unit_weight.is_finite() && unit_weight >= 0.0) {
                return bad("`unit_weight` must be >= 0 (N/m³)");
            }
            if !(k0.is_finite() && k0 > 0.0) {
                return bad("`k0` must be > 0");
            }
        }
        InitialStressSpec::Isotropic { pressure } => {
            if !pressure.is_finite() {
                return bad("`pressure` must be finite (Pa)");
            }
        }
    }
    Ok(())
}

/// $b^e$ of every point (empty when no body has an initial stress).
///
/// # Errors
/// [`SceneError::Scene`] at a body's `initial_stress` with a number out of
/// range or a state beyond its material's yield surface.
pub(super) fn initial_be<const D: usize>(
    specs: &[BodySpec],
    bodies: &BuiltBodies<D>,
    materials: &[BuiltMaterial],
    src: &SceneSource,
) -> Result<Vec<Matrix3<f64>>, SceneError> {
    if specs.iter().all(|b| b.initial_stress.is_none()) {
        return Ok(Vec::new());
    }
    let mut be = vec![Matrix3::identity(); bodies.len()];
    for (spec, body) in specs.iter().zip(&bodies.bodies) {
        let Some(stress) = &spec.initial_stress else {
            continue;
        };
        check_spec(stress, src)?;
        let material = &materials[body.material];
        let law = SceneLaw::new(material.model, &material.params)
            .map_err(|e| src.at(stress, format!("initial_stress: {e}")))?;
        let (e, nu) = (
            material.params.youngs_modulus,
            material.params.poisson_ratio,
        );
        for p in body.points.clone() {
            let x = &bodies.points.position[p];
            let sigma = stress_at(stress.get_ref(), x);
            let strain = sigma.map(|s| ((1.0 + nu) * s - nu * sigma.sum()) / e);
            let trial = SymSpectral {
                values: strain,
                vectors: Matrix3::identity(),
            };
            if law.return_map(&trial, &law.initial_history()).yielded {
                return Err(src.at(
                    stress,
                    format!(
                        "initial_stress of body `{}` lies beyond the yield surface of material `{}` at point {p} ({:?}), stresses {:?} Pa",
                        body.name,
                        material.name,
                        x.as_slice(),
                        sigma.as_slice()
                    ),
                ));
            }
            be[p] = Matrix3::from_diagonal(&strain.map(|s| (2.0 * s).exp()));
        }
    }
    Ok(be)
}
