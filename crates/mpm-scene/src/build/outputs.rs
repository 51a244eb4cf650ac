//! The `[output]` keys: how often, which reactions and probes (names
//! safe as file names), which point fields; each value checked at its key.

use nalgebra::SVector;
use toml::Spanned;

use super::{Check, ReactionOutput, unique_names};
use crate::SceneError;
use crate::format::{Field, OutputSpec, SolverSpec};
use crate::region::point;
use crate::source::SceneSource;

/// The outputs' step interval, reactions, probes and fields.
type Outputs<const D: usize> = (
    usize,
    Vec<ReactionOutput<D>>,
    Vec<(String, usize)>,
    Vec<Field>,
);

/// Finds a node set by name (or says why the name cannot be used).
type SetOf<'s> = dyn Fn(&Spanned<String>) -> Result<&'s Vec<usize>, SceneError> + 's;

/// The outputs of `o`; `explicit`: the scene runs the explicit solver;
/// `set_of` finds a node set by name, `nearest` the point nearest a
/// position.
///
/// # Errors
/// [`SceneError::Scene`] at the key whose value is wrong or does not apply.
pub(super) fn outputs<'s, const D: usize>(
    o: &OutputSpec,
    explicit: bool,
    src: &SceneSource,
    set_of: &SetOf<'s>,
    nearest: &dyn Fn(&SVector<f64, D>) -> usize,
) -> Result<Outputs<D>, SceneError> {
    let check = Check { src };
    let every = check.at_least(&o.every, 1, "output `every`")?;
    if explicit {
        if SolverSpec::given(&o.every) {
            return Err(src.at(
                &o.every,
                "output `every` counts the implicit solver's load steps; an explicit run writes every [solver] `output_interval` of simulated time",
            ));
        }
        if let Some(r) = o.reactions.first() {
            return Err(src.at(
                &r.name,
                "reaction outputs are the implicit solver's nodal reactions; the explicit solver does not compute them",
            ));
        }
    }
    let safe = |name: &Spanned<String>| -> Result<String, SceneError> {
        let v = name.get_ref();
        // 200 bytes leave room for the suffixes within the 255 of a
        // file name on common file systems.
        if v.is_empty()
            || v.len() > 200
            || !v
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        {
            return Err(src.at(
                name,
                "an output name must be 1 to 200 letters, digits, `_` or `-` (it names a file)",
            ));
        }
        Ok(v.clone())
    };
    unique_names(o.reactions.iter().map(|r| &r.name), "reaction output", src)?;
    unique_names(o.probes.iter().map(|r| &r.name), "probe output", src)?;
    let reactions = o
        .reactions
        .iter()
        .map(|r| {
            Ok(ReactionOutput {
                name: safe(&r.name)?,
                nodes: set_of(&r.set)?.clone(),
                about: match &r.about {
                    Some(a) => Some(point::<D>(a, "reaction `about`", src)?),
                    None => None,
                },
            })
        })
        .collect::<Result<Vec<_>, SceneError>>()?;
    let probes = o
        .probes
        .iter()
        .map(|p| {
            Ok((
                safe(&p.name)?,
                nearest(&point::<D>(&p.at, "probe `at`", src)?),
            ))
        })
        .collect::<Result<Vec<_>, SceneError>>()?;
    if o.png && D != 2 {
        return Err(src.error(None, "output `png` draws 2D scenes only"));
    }
    let fields = o.fields.clone().unwrap_or_else(|| Field::ALL.to_vec());
    Ok((every, reactions, probes, fields))
}
