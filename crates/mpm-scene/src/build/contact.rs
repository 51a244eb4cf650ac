//! The `[[contact]]` tables of an explicit run: multi-field contact
//! between deformable bodies (`mpm_solver::explicit::contact`). Each body
//! a table names gets a velocity field of its own and meets every other
//! field with the table's Coulomb `friction`; the bodies no table names
//! share the default field (field 0).

use super::bodies::BuiltBodies;
use super::lookup;
use crate::SceneError;
use crate::format::Scene;
use crate::source::SceneSource;

/// The contact of a run: each point's velocity field and each field's
/// friction coefficient (the default field 0 has none of its own).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactSetup {
    /// The velocity field of every point.
    pub field: Vec<u8>,
    /// μ of each field (0 for the default field: at a node the largest
    /// of the fields present applies).
    pub friction: Vec<f64>,
}

/// The most fields a run may have (a point's field is a byte).
const MAX_FIELDS: usize = 256;

/// The `[[contact]]` tables of `scene` (`None` without any), with the
/// points of `bodies`; `explicit`: the scene runs the explicit solver;
/// `absorbing`: it has absorbing boundaries.
///
/// # Errors
/// [`SceneError::Scene`] at a table of an implicit scene, a body that
/// does not exist or is named twice (in one table or two), an empty
/// list, a friction that is negative or not finite, too many bodies, and
/// at the first table of a scene with absorbing boundaries or
/// material-point fixities (not supported with contact).
pub(super) fn contact<const D: usize>(
    scene: &Scene,
    explicit: bool,
    absorbing: bool,
    bodies: &BuiltBodies<D>,
    src: &SceneSource,
) -> Result<Option<ContactSetup>, SceneError> {
    let Some(first) = scene.contacts.first() else {
        return Ok(None);
    };
    let refuse = |why: &str| Err(src.at(&first.bodies, why));
    if !explicit {
        return refuse(
            "[[contact]] is a condition of the explicit solver ([solver] kind = \"explicit\")",
        );
    }
    if absorbing {
        return refuse(
            "[[contact]] is not supported with absorbing boundaries (their spring layer holds one state per node, not per velocity field)",
        );
    }
    if !scene.point_fixities.is_empty() {
        return refuse(
            "[[contact]] is not supported with material-point fixities ([[point_fixity]])",
        );
    }
    let mut field_of_body: Vec<Option<u8>> = vec![None; bodies.bodies.len()];
    let mut friction = vec![0.0];
    for spec in &scene.contacts {
        let mu = match &spec.friction {
            Some(f) if !(f.get_ref().is_finite() && *f.get_ref() >= 0.0) => {
                return Err(src.at(
                    f,
                    format!(
                        "contact `friction` {} must be finite and non-negative",
                        f.get_ref()
                    ),
                ));
            }
            Some(f) => *f.get_ref(),
            None => 0.0,
        };
        if spec.bodies.get_ref().is_empty() {
            return Err(src.at(&spec.bodies, "contact `bodies` names no body"));
        }
        for name in spec.bodies.get_ref() {
            let b = lookup(&bodies.names, name, "body", src)?;
            if field_of_body[b].is_some() {
                return Err(src.at(
                    name,
                    format!(
                        "body `{}` is already in a contact: a body has one velocity field",
                        name.get_ref()
                    ),
                ));
            }
            let k = u8::try_from(friction.len())
                .ok()
                .filter(|_| friction.len() < MAX_FIELDS)
                .ok_or_else(|| {
                    src.at(name, format!("more than {} contact bodies", MAX_FIELDS - 1))
                })?;
            field_of_body[b] = Some(k);
            friction.push(mu);
        }
    }
    let mut field = vec![0u8; bodies.len()];
    for (body, k) in bodies.bodies.iter().zip(&field_of_body) {
        if let Some(k) = k {
            field[body.points.clone()].fill(*k);
        }
    }
    Ok(Some(ContactSetup { field, friction }))
}
