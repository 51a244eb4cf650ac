//! A body's `initial_stress`: the elastic left Cauchy–Green tensor and
//! the history each of its points starts from, so that the law returns
//! the given stress at $F = 1$.
//!
//! At $F = 1$ the Kirchhoff stress is the Cauchy stress. The linear laws'
//! elastic strain of a principal stress $\sigma$ is $\varepsilon_a =
//! ((1+\nu)\sigma_a - \nu\sum_b\sigma_b)/E$; Cam-Clay's is its own
//! inverse ($\varepsilon_v = -\hat\kappa\ln(p/p_r)$, $\operatorname{dev}
//! \varepsilon = \operatorname{dev}\sigma/2G$), and its history the
//! yield locus through the stress times the material's
//! `overconsolidation_ratio` (Cam-Clay has no stress-free state: its
//! bodies must have an `initial_stress`). $b^e = \exp 2\varepsilon$
//! (diagonal: the geostatic and isotropic states are principal in the
//! coordinate axes). The state must lie inside the material's yield
//! surface or on it (a geostatic state beyond yield is not an equilibrium
//! the solver can start from): the return map of the elastic strain must
//! leave the stress where it is at every point, or the key is refused
//! with the first point that yields.

use mpm_constitutive::{LogStrainLaw, SymSpectral};
use nalgebra::{Matrix3, SVector, Vector3};

use super::BuiltMaterial;
use super::bodies::BuiltBodies;
use crate::SceneError;
use crate::format::{BodySpec, InitialStressSpec};
use crate::material::SceneLaw;
use crate::material::{MaterialModel, MaterialParams, SceneHistory};
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

/// The elastic strain (principal, in the coordinate axes) and the
/// history a point of `law` starts from under the principal stress
/// `sigma`: the inverse of the linear elasticity and the law's default
/// history; for Cam-Clay its own inverse and the yield locus through the
/// stress scaled by the over-consolidation ratio.
fn initial_state(
    law: &SceneLaw,
    params: &MaterialParams,
    sigma: &Vector3<f64>,
) -> Result<(Vector3<f64>, SceneHistory), String> {
    if let SceneLaw::ModifiedCamClay(m) = law {
        let ocr = params.cam_clay.map_or(1.0, |c| c.overconsolidation_ratio);
        let strain = m.elastic_strain_of(sigma).map_err(|e| e.to_string())?;
        let history = m.history_for(sigma, ocr).map_err(|e| e.to_string())?;
        return Ok((strain, SceneHistory::ModifiedCamClay(history)));
    }
    let (e, nu) = (params.youngs_modulus, params.poisson_ratio);
    let strain = sigma.map(|s| ((1.0 + nu) * s - nu * sigma.sum()) / e);
    Ok((strain, law.initial_history()))
}

/// Whether the return map of the elastic strain `strain` from `history`
/// leaves the stress `sigma` where it is (to 1e-9 of its size): the state
/// lies inside the yield surface or on it (a normally consolidated
/// Cam-Clay starts on it).
fn admissible(
    law: &SceneLaw,
    strain: &Vector3<f64>,
    history: &SceneHistory,
    sigma: &Vector3<f64>,
) -> bool {
    let trial = SymSpectral {
        values: *strain,
        vectors: Matrix3::identity(),
    };
    let state = law.return_map(&trial, history);
    !state.yielded || (state.tau - sigma).amax() <= 1e-9 * sigma.amax()
}

/// $b^e$ and the history of every point (both empty when no body has an
/// initial stress).
///
/// # Errors
/// [`SceneError::Scene`] at a body's `initial_stress` with a number out of
/// range or a state beyond its material's yield surface, or a stress the
/// law cannot start from (Cam-Clay: no pressure); at a body of a law
/// without a stress-free state (Cam-Clay) that has no `initial_stress`.
pub(super) fn initial_state_of_points<const D: usize>(
    specs: &[BodySpec],
    bodies: &BuiltBodies<D>,
    materials: &[BuiltMaterial],
    src: &SceneSource,
) -> Result<(Vec<Matrix3<f64>>, Vec<SceneHistory>), SceneError> {
    for (spec, body) in specs.iter().zip(&bodies.bodies) {
        let material = &materials[body.material];
        if spec.initial_stress.is_none() && material.model == MaterialModel::ModifiedCamClay {
            return Err(src.at(
                &spec.name,
                format!(
                    "body `{}` of modified_cam_clay material `{}` needs initial_stress: Cam-Clay has no stress-free state",
                    body.name, material.name
                ),
            ));
        }
    }
    if specs.iter().all(|b| b.initial_stress.is_none()) {
        return Ok((Vec::new(), Vec::new()));
    }
    let mut be = vec![Matrix3::identity(); bodies.len()];
    let mut histories = vec![SceneHistory::default(); bodies.len()];
    for (spec, body) in specs.iter().zip(&bodies.bodies) {
        let material = &materials[body.material];
        let law = SceneLaw::new(material.model, &material.params)
            .map_err(|e| src.at(&spec.name, format!("body `{}`: {e}", body.name)))?;
        let Some(stress) = &spec.initial_stress else {
            for p in body.points.clone() {
                histories[p] = law.initial_history();
            }
            continue;
        };
        check_spec(stress, src)?;
        for p in body.points.clone() {
            let x = &bodies.points.position[p];
            let sigma = stress_at(stress.get_ref(), x);
            let place = || {
                format!(
                    "body `{}` at point {p} ({:?}), stresses {:?} Pa",
                    body.name,
                    x.as_slice(),
                    sigma.as_slice()
                )
            };
            let (strain, history) = initial_state(&law, &material.params, &sigma)
                .map_err(|e| src.at(stress, format!("initial_stress of {}: {e}", place())))?;
            if !admissible(&law, &strain, &history, &sigma) {
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
            histories[p] = history;
        }
    }
    Ok((be, histories))
}
