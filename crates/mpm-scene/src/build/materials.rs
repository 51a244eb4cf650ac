//! The `[[material]]` tables: each law built from its parameters and
//! checked at its key, with the scene's rule that materials share a model.

use std::collections::BTreeMap;

use super::{BuiltMaterial, unique_names};
use crate::SceneError;
use crate::format::MaterialSpec;
use crate::material::{MaterialModel, MaterialParams, SceneLaw};
use crate::source::SceneSource;

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
        let mut params = MaterialParams {
            youngs_modulus: spec.youngs_modulus,
            poisson_ratio: spec.poisson_ratio,
            yield_stress: spec.yield_stress,
            hardening: spec.hardening,
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
        {
            return Err(src.at(
                &spec.name,
                format!(
                    "material `{}` is {} but `{}` is {}: the materials of one scene share one model (hencky mixes with von_mises)",
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
