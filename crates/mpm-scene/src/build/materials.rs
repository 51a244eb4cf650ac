//! The `[[material]]` tables: each law built from its parameters and
//! checked at its key, with the scene's rule that materials share a model.

use std::collections::BTreeMap;

use super::{BuiltMaterial, unique_names};
use crate::SceneError;
use crate::format::MaterialSpec;
use crate::material::{CamClayParams, MaterialModel, MaterialParams, SceneLaw};
use crate::source::SceneSource;
use toml::Spanned;

/// The materials' names (for the bodies' lookups) and the built
/// materials, in file order; `explicit`: the scene runs the explicit
/// solver (which needs a positive density).
///
/// # Errors
/// [`SceneError::Scene`] at the material whose key is wrong.
pub(super) fn materials(
    specs: &[MaterialSpec],
    explicit: bool,
    src: &SceneSource,
) -> Result<(BTreeMap<String, usize>, Vec<BuiltMaterial>), SceneError> {
    let material_names = unique_names(specs.iter().map(|m| &m.name), "material", src)?;
    if specs.is_empty() {
        return Err(src.error(None, "a scene needs at least one [[material]]"));
    }
    let plastic = specs.iter().any(|m| m.model == MaterialModel::VonMises);
    let mut materials: Vec<BuiltMaterial> = Vec::new();
    for spec in specs {
        let density = *spec.density.get_ref();
        if density < 0.0 {
            return Err(src.at(&spec.density, "density must be non-negative"));
        }
        if explicit && density <= 0.0 {
            return Err(src.at(
                &spec.density,
                "the explicit solver needs a positive density (the points' masses set the wave speed and the time step)",
            ));
        }
        check_soil_keys(spec, src)?;
        let cam_clay = super::cam_clay::params(spec, src)?;
        let (youngs_modulus, poisson_ratio) = elastic_constants(spec, cam_clay.as_ref(), src)?;
        let mut params = MaterialParams {
            youngs_modulus,
            poisson_ratio,
            yield_stress: spec.yield_stress,
            hardening: spec.hardening,
            cohesion: spec.cohesion.as_ref().map(|v| *v.get_ref()),
            friction_angle: spec.friction_angle.as_ref().map(|v| *v.get_ref()),
            dilation_angle: spec.dilation_angle.as_ref().map_or(0.0, |v| *v.get_ref()),
            matching: spec.matching.as_ref().map(|v| *v.get_ref()),
            tension_cutoff: spec.tension_cutoff.as_ref().map(|v| *v.get_ref()),
            cam_clay,
        };
        if spec.model != MaterialModel::VonMises && spec.yield_stress.is_some() {
            return Err(src.at(
                &spec.name,
                format!(
                    "material `{}`: yield_stress applies to model = von_mises",
                    spec.name.get_ref()
                ),
            ));
        }
        SceneLaw::new(spec.model, &params).map_err(|e| {
            src.at(
                &spec.name,
                format!("material `{}`: {e}", spec.name.get_ref()),
            )
        })?;
        let model = if plastic && spec.model == MaterialModel::Hencky {
            params.yield_stress = Some(f64::MAX);
            params.hardening = 0.0;
            MaterialModel::VonMises
        } else {
            spec.model
        };
        // The materials of a scene share one model: Hencky joins von
        // Mises as a von Mises law that never yields, other mixtures are
        // refused. (The run-time law, `SceneLaws`, could hold any mix; the
        // rule keeps the results of existing scenes until a scene may
        // name laws per material.)
        if let Some(first) = materials.first()
            && first.model != model
            && !mixes_with_soil(first.model, model)
        {
            return Err(src.at(
                &spec.name,
                format!(
                    "material `{}` is {} but `{}` is {}: the materials of one scene share one model (hencky mixes with von_mises; mohr_coulomb, drucker_prager and modified_cam_clay with each other and with hencky and neo_hookean)",
                    spec.name.get_ref(),
                    spec.model,
                    first.name,
                    first.model
                ),
            ));
        }
        materials.push(BuiltMaterial {
            name: spec.name.get_ref().clone(),
            model,
            params,
            density,
        });
    }
    Ok((material_names, materials))
}

/// Young's modulus and Poisson's ratio: given for every model but
/// `modified_cam_clay`, whose elasticity is its shear modulus and its
/// pressure-dependent bulk modulus; for it, the pair with its shear
/// modulus and its bulk modulus at the reference pressure, p_r/κ̂ (what a
/// stiffness-scaled stabilisation reads).
fn elastic_constants(
    spec: &MaterialSpec,
    cam_clay: Option<&CamClayParams>,
    src: &SceneSource,
) -> Result<(f64, f64), SceneError> {
    let name = spec.name.get_ref();
    let keys = [
        ("youngs_modulus", spec.youngs_modulus.as_ref()),
        ("poisson_ratio", spec.poisson_ratio.as_ref()),
    ];
    if let Some(c) = cam_clay {
        if let Some((key, Some(v))) = keys.iter().find(|(_, v)| v.is_some()) {
            return Err(src.at(
                v,
                format!("material `{name}`: {key} does not apply to model = modified_cam_clay (its elasticity is shear_modulus and the bulk modulus p/κ̂)"),
            ));
        }
        let (k, g) = (c.reference_pressure / c.swelling_index, c.shear_modulus);
        return Ok((
            9.0 * k * g / (3.0 * k + g),
            (3.0 * k - 2.0 * g) / (2.0 * (3.0 * k + g)),
        ));
    }
    let mut values = [0.0; 2];
    for (value, (key, given)) in values.iter_mut().zip(keys) {
        *value = *given
            .ok_or_else(|| {
                src.at(
                    &spec.name,
                    format!("material `{name}` ({}) needs {key}", spec.model),
                )
            })?
            .get_ref();
    }
    Ok((values[0], values[1]))
}

/// The soil laws' keys: present where the model needs them, absent
/// elsewhere, and in range, each error at its key.
fn check_soil_keys(spec: &MaterialSpec, src: &SceneSource) -> Result<(), SceneError> {
    let model = spec.model;
    let soil = matches!(
        model,
        MaterialModel::MohrCoulomb | MaterialModel::DruckerPrager
    );
    let name = spec.name.get_ref();
    let keys: [(&str, Option<&Spanned<f64>>); 3] = [
        ("cohesion", spec.cohesion.as_ref()),
        ("friction_angle", spec.friction_angle.as_ref()),
        ("dilation_angle", spec.dilation_angle.as_ref()),
    ];
    for (key, value) in keys {
        match value {
            Some(v) if !soil => {
                return Err(src.at(
                    v,
                    format!(
                        "material `{name}`: {key} applies to model = mohr_coulomb or drucker_prager"
                    ),
                ));
            }
            None if soil && key != "dilation_angle" => {
                return Err(src.at(
                    &spec.name,
                    format!("material `{name}` ({model}) needs {key}"),
                ));
            }
            _ => {}
        }
    }
    if let Some(t) = &spec.tension_cutoff
        && model != MaterialModel::MohrCoulomb
    {
        return Err(src.at(
            t,
            format!("material `{name}`: tension_cutoff applies to model = mohr_coulomb"),
        ));
    }
    if let Some(m) = &spec.matching
        && model != MaterialModel::DruckerPrager
    {
        return Err(src.at(
            m,
            format!("material `{name}`: matching applies to model = drucker_prager"),
        ));
    }
    if model == MaterialModel::DruckerPrager && spec.matching.is_none() {
        return Err(src.at(
            &spec.name,
            format!("material `{name}` (drucker_prager) needs matching = \"outer\", \"inner\" or \"plane_strain\""),
        ));
    }
    check_ranges(spec, src)
}

/// c ≥ 0 (Pa), φ in [0, 90), ψ in [0, φ] (degrees), c > 0 when φ = 0.
fn check_ranges(spec: &MaterialSpec, src: &SceneSource) -> Result<(), SceneError> {
    let name = spec.name.get_ref();
    let phi = spec.friction_angle.as_ref().map(|v| *v.get_ref());
    if let Some(c) = &spec.cohesion
        && (*c.get_ref() < 0.0 || (*c.get_ref() == 0.0 && phi == Some(0.0)))
    {
        return Err(src.at(
            c,
            format!("material `{name}`: cohesion must be >= 0 Pa, and > 0 when friction_angle = 0 (no strength otherwise)"),
        ));
    }
    if let Some(f) = &spec.friction_angle
        && !(0.0..90.0).contains(f.get_ref())
    {
        return Err(src.at(
            f,
            format!("material `{name}`: friction_angle must lie in [0, 90) degrees"),
        ));
    }
    if let Some(d) = &spec.dilation_angle
        && !(*d.get_ref() >= 0.0 && *d.get_ref() <= phi.unwrap_or(0.0))
    {
        return Err(src.at(
            d,
            format!("material `{name}`: dilation_angle must lie in [0, friction_angle] degrees"),
        ));
    }
    Ok(())
}

/// Whether two models may share a scene as a soil law beside another soil
/// law or an elastic one (a footing on soil): the run-time law set holds
/// both, each point with its own.
fn mixes_with_soil(a: MaterialModel, b: MaterialModel) -> bool {
    use MaterialModel::{DruckerPrager, Hencky, ModifiedCamClay, MohrCoulomb, NeoHookean};
    let soil = |m| matches!(m, MohrCoulomb | DruckerPrager | ModifiedCamClay);
    let elastic = |m| matches!(m, Hencky | NeoHookean);
    (soil(a) && (soil(b) || elastic(b))) || (soil(b) && elastic(a))
}
