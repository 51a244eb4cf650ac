//! The `modified_cam_clay` keys of a `[[material]]`: given for that model
//! and only for it, each finite and in its range, every error at its key.

use toml::Spanned;

use crate::SceneError;
use crate::format::MaterialSpec;
use crate::material::{CamClayParams, MaterialModel};
use crate::source::SceneSource;

/// A key's value: `None` when absent; refused when out of `range`
/// (`ok` decides, `range` says it in the message).
fn checked(
    spec: &MaterialSpec,
    (key, value): (&str, Option<&Spanned<f64>>),
    ok: impl Fn(f64) -> bool,
    range: &str,
    src: &SceneSource,
) -> Result<Option<f64>, SceneError> {
    match value {
        None => Ok(None),
        Some(v) if v.get_ref().is_finite() && ok(*v.get_ref()) => Ok(Some(*v.get_ref())),
        Some(v) => Err(src.at(
            v,
            format!(
                "material `{}`: {key} must be {range}, got {}",
                spec.name.get_ref(),
                v.get_ref()
            ),
        )),
    }
}

/// The keys of `spec` in file order, with their values.
fn keys(spec: &MaterialSpec) -> [(&'static str, Option<&Spanned<f64>>); 7] {
    [
        ("compression_index", spec.compression_index.as_ref()),
        ("swelling_index", spec.swelling_index.as_ref()),
        ("critical_state_slope", spec.critical_state_slope.as_ref()),
        ("shear_modulus", spec.shear_modulus.as_ref()),
        ("reference_pressure", spec.reference_pressure.as_ref()),
        ("minimum_pressure", spec.minimum_pressure.as_ref()),
        (
            "overconsolidation_ratio",
            spec.overconsolidation_ratio.as_ref(),
        ),
    ]
}

/// Cam-Clay's constants of `spec` (`None` for another model).
///
/// # Errors
/// [`SceneError::Scene`] at a key of another model, at the material for a
/// missing key, at a key out of range.
pub(super) fn params(
    spec: &MaterialSpec,
    src: &SceneSource,
) -> Result<Option<CamClayParams>, SceneError> {
    let name = spec.name.get_ref();
    let keys = keys(spec);
    if spec.model != MaterialModel::ModifiedCamClay {
        return match keys.iter().find_map(|(k, v)| v.map(|v| (k, v))) {
            Some((key, v)) => Err(src.at(
                v,
                format!("material `{name}`: {key} applies to model = modified_cam_clay"),
            )),
            None => Ok(None),
        };
    }
    let need = |v: Option<f64>, key: &str| {
        v.ok_or_else(|| {
            src.at(
                &spec.name,
                format!("material `{name}` (modified_cam_clay) needs {key}"),
            )
        })
    };
    let positive = |x: f64| x > 0.0;
    let kappa = checked(spec, keys[1], positive, "> 0", src)?;
    let kappa = need(kappa, "swelling_index")?;
    let lambda = checked(spec, keys[0], |x| x > kappa, "> swelling_index", src)?;
    Ok(Some(CamClayParams {
        compression_index: need(lambda, "compression_index")?,
        swelling_index: kappa,
        critical_state_slope: need(checked(spec, keys[2], positive, "> 0", src)?, keys[2].0)?,
        shear_modulus: need(checked(spec, keys[3], positive, "> 0 Pa", src)?, keys[3].0)?,
        reference_pressure: need(checked(spec, keys[4], positive, "> 0 Pa", src)?, keys[4].0)?,
        minimum_pressure: checked(spec, keys[5], |x| x >= 0.0, ">= 0 Pa", src)?.unwrap_or(0.0),
        overconsolidation_ratio: checked(spec, keys[6], |x| x >= 1.0, ">= 1", src)?.unwrap_or(1.0),
    }))
}
