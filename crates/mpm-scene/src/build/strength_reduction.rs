//! `[strength_reduction]`: the trial factors, the bracket width and the
//! failure criterion, checked at their keys; and the problem of one trial
//! (its materials' strength divided by the factor).

use toml::Spanned;

use super::Problem;
use crate::SceneError;
use crate::format::{FailureCriterion, Scene, StrengthReductionSpec};
use crate::source::SceneSource;

/// When a trial has failed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Failure {
    /// A load step did not converge after cutting to the minimum increment.
    Convergence,
    /// That, or the displacement magnitude of probe `probe` (an index into
    /// [`Problem::probes`]) beyond `limit` (m) at the end of the trial.
    Displacement {
        /// The probe watched.
        probe: usize,
        /// The limit (m).
        limit: f64,
    },
}

/// A checked `[strength_reduction]` table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrengthReduction {
    /// The first factor tried (> 0).
    pub lower: f64,
    /// The second factor tried (> `lower`).
    pub upper: f64,
    /// The bisection stops at a bracket this narrow (> 0).
    pub tolerance: f64,
    /// When a trial has failed.
    pub failure: Failure,
    /// The most trials run.
    pub max_trials: usize,
}

/// A number of the table, checked to be finite and positive.
fn positive(
    v: &Option<Spanned<f64>>,
    default: f64,
    key: &str,
    src: &SceneSource,
) -> Result<f64, SceneError> {
    match v {
        None => Ok(default),
        Some(s) if s.get_ref().is_finite() && *s.get_ref() > 0.0 => Ok(*s.get_ref()),
        Some(s) => Err(src.at(
            s,
            format!(
                "strength_reduction: `{key}` must be finite and > 0, got {}",
                s.get_ref()
            ),
        )),
    }
}

/// The checked table of `scene` (`None` without one); `probes` are the
/// scene's `[[output.probe]]` names, in order.
///
/// # Errors
/// [`SceneError::Scene`] at a key out of range, a displacement criterion
/// without its probe or limit, or the table in an explicit scene.
pub(super) fn strength_reduction(
    scene: &Scene,
    probes: &[(String, usize)],
    explicit: bool,
    src: &SceneSource,
) -> Result<Option<StrengthReduction>, SceneError> {
    let Some(table) = &scene.strength_reduction else {
        return Ok(None);
    };
    if explicit {
        return Err(src.at(
            table,
            "strength_reduction runs the implicit solver (quasi-static trials); remove it or `kind = \"explicit\"`",
        ));
    }
    if let Some(m) = scene
        .materials
        .iter()
        .find(|m| m.model == crate::material::MaterialModel::ModifiedCamClay)
    {
        return Err(src.at(
            &m.name,
            format!(
                "strength_reduction divides c, tan φ and the yield stress; material `{}` is modified_cam_clay, whose strength it does not reduce",
                m.name.get_ref()
            ),
        ));
    }
    let t: &StrengthReductionSpec = table.get_ref();
    let lower = positive(&t.lower, 1.0, "lower", src)?;
    let upper = positive(&t.upper, 2.0 * lower, "upper", src)?;
    if let Some(u) = &t.upper
        && upper <= lower
    {
        return Err(src.at(
            u,
            format!("strength_reduction: `upper` ({upper}) must exceed `lower` ({lower})"),
        ));
    }
    let tolerance = positive(&t.tolerance, 0.01, "tolerance", src)?;
    let max_trials = match &t.max_trials {
        None => 30,
        Some(n) if (2..=1000).contains(n.get_ref()) => *n.get_ref(),
        Some(n) => {
            return Err(src.at(n, "strength_reduction: `max_trials` must be in 2..=1000"));
        }
    };
    let failure = failure(t, table, probes, src)?;
    Ok(Some(StrengthReduction {
        lower,
        upper,
        tolerance,
        failure,
        max_trials,
    }))
}

/// The failure criterion of `t` with its probe and limit.
fn failure(
    t: &StrengthReductionSpec,
    table: &Spanned<StrengthReductionSpec>,
    probes: &[(String, usize)],
    src: &SceneSource,
) -> Result<Failure, SceneError> {
    let criterion = t
        .criterion
        .as_ref()
        .map_or(FailureCriterion::Convergence, |c| *c.get_ref());
    if criterion == FailureCriterion::Convergence {
        for (key, given) in [
            ("probe", t.probe.as_ref().map(Spanned::span)),
            (
                "displacement_limit",
                t.displacement_limit.as_ref().map(Spanned::span),
            ),
        ] {
            if let Some(span) = given {
                return Err(src.error(
                    Some(span),
                    &format!(
                        "strength_reduction: `{key}` belongs to `criterion = \"displacement\"`"
                    ),
                ));
            }
        }
        return Ok(Failure::Convergence);
    }
    let Some(name) = &t.probe else {
        return Err(src.at(
            table,
            "strength_reduction: `criterion = \"displacement\"` needs `probe` (an [[output.probe]] name)",
        ));
    };
    let Some(probe) = probes.iter().position(|(n, _)| n == name.get_ref()) else {
        return Err(src.at(
            name,
            format!(
                "strength_reduction: no [[output.probe]] is named `{}`",
                name.get_ref()
            ),
        ));
    };
    if t.displacement_limit.is_none() {
        return Err(src.at(
            table,
            "strength_reduction: `criterion = \"displacement\"` needs `displacement_limit` (m)",
        ));
    }
    let limit = positive(&t.displacement_limit, 0.0, "displacement_limit", src)?;
    Ok(Failure::Displacement { probe, limit })
}

impl<const D: usize> Problem<D> {
    /// The problem of a strength-reduction trial: every material's
    /// strength divided by `factor`
    /// ([`crate::material::MaterialParams::reduced`]).
    pub fn with_reduced_strength(&self, factor: f64) -> Self {
        let mut trial = self.clone();
        for m in &mut trial.materials {
            m.params = m.params.reduced(factor);
        }
        trial
    }
}
