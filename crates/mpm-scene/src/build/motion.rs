//! The `[mesh.motion]` table: a stretch, rotation or translation of the
//! mesh with the load factor, the nodes of a set driven with it; the keys
//! of the other kinds refused where they are.

use std::collections::BTreeMap;

use mpm_solver::{MeshMotion, MovingMesh, Rotation, Stretch, Translation};
use nalgebra::SVector;
use toml::Spanned;

use super::{AXES, Free, lookup_ref};
use crate::SceneError;
use crate::format::{MotionKind, MotionSpec};
use crate::region::point;
use crate::source::SceneSource;

/// The mesh motions a scene can give (`[mesh.motion] kind`): one type, so
/// that the solvers are compiled once whatever the motion (it is evaluated
/// once per node and step).
#[derive(Debug, Clone, PartialEq)]
pub enum SceneMotion<const D: usize> {
    /// `stretch`.
    Stretch(Stretch),
    /// `rotation`.
    Rotation(Rotation<D>),
    /// `translation`.
    Translation(Translation<D>),
}

impl<const D: usize> MeshMotion<D> for SceneMotion<D> {
    #[inline]
    fn position(&self, node: usize, x0: &SVector<f64, D>, lambda: f64) -> SVector<f64, D> {
        match self {
            SceneMotion::Stretch(m) => MeshMotion::<D>::position(m, node, x0, lambda),
            SceneMotion::Rotation(m) => m.position(node, x0, lambda),
            SceneMotion::Translation(m) => m.position(node, x0, lambda),
        }
    }
}

/// A motion and the components of the driven nodes it prescribes unless
/// `components` says otherwise.
type MotionAndComponents<const D: usize> = (SceneMotion<D>, [bool; D]);

/// The mesh motion of `[mesh.motion]`: `sets` are the scene's node sets,
/// `initial` the nodes' initial positions and `lower`, `upper` the box's
/// corners (a stretch's default origin and length).
///
/// # Errors
/// [`SceneError::Scene`] at the key that is missing (at `kind`), wrong or
/// does not apply to the motion's kind.
pub(super) fn motion_of<const D: usize>(
    spec: &MotionSpec,
    sets: &BTreeMap<String, Vec<usize>>,
    initial: &[SVector<f64, D>],
    lower: SVector<f64, D>,
    upper: SVector<f64, D>,
    src: &SceneSource,
) -> Result<MovingMesh<D, Free, SceneMotion<D>>, SceneError> {
    let axis =
        match &spec.axis {
            Some(a) => Some(axis_of::<D>(a.get_ref()).ok_or_else(|| {
                src.at(a, format!("`axis` must be one of {}", AXES[..D].join(", ")))
            })?),
            None => None,
        };
    if !matches!(spec.kind.get_ref(), MotionKind::Translation) {
        refuse(
            spec,
            spec.displacement.is_some(),
            "displacement",
            "stretch or rotation",
            src,
        )?;
        refuse(
            spec,
            spec.carried.is_some(),
            "carried",
            "stretch or rotation",
            src,
        )?;
        refuse(
            spec,
            spec.fixed.is_some(),
            "fixed",
            "stretch or rotation",
            src,
        )?;
    }
    let (motion, default_components) = match spec.kind.get_ref() {
        MotionKind::Translation => translation(spec, sets, initial, src)?,
        MotionKind::Stretch => stretch(spec, axis, lower, upper, src)?,
        MotionKind::Rotation => rotation(spec, axis, src)?,
    };
    let driven = lookup_ref(sets, &spec.driven, "node set", src)?;
    let components = match &spec.components {
        None => default_components,
        Some(list) => {
            let mut components = [false; D];
            for name in list.get_ref() {
                let Some(i) = axis_of::<D>(name) else {
                    return Err(src.at(
                        list,
                        format!("`components` must name axes among {}", AXES[..D].join(", ")),
                    ));
                };
                components[i] = true;
            }
            components
        }
    };
    Ok(MovingMesh::new(
        Free,
        motion,
        initial.to_vec(),
        driven,
        components,
    ))
}

/// The index of the axis `name` among the scene's `D`.
fn axis_of<const D: usize>(name: &str) -> Option<usize> {
    AXES.iter().take(D).position(|a| *a == name)
}

/// Refuses the key `key` (if `present`) of another kind of motion than
/// `kind`, at the motion's `kind`.
fn refuse(
    spec: &MotionSpec,
    present: bool,
    key: &str,
    kind: &str,
    src: &SceneSource,
) -> Result<(), SceneError> {
    if present {
        Err(src.at(
            &spec.kind,
            format!("`{key}` does not apply to a {kind} motion"),
        ))
    } else {
        Ok(())
    }
}

/// `kind = "translation"`: the carried set (the driven one by default)
/// moves by `displacement`, the `fixed` set stays.
fn translation<const D: usize>(
    spec: &MotionSpec,
    sets: &BTreeMap<String, Vec<usize>>,
    initial: &[SVector<f64, D>],
    src: &SceneSource,
) -> Result<MotionAndComponents<D>, SceneError> {
    for (present, key) in [
        (spec.axis.is_some(), "axis"),
        (spec.extension.is_some(), "extension"),
        (spec.length.is_some(), "length"),
        (spec.origin.is_some(), "origin"),
        (spec.centre.is_some(), "centre"),
        (spec.angle.is_some(), "angle"),
    ] {
        refuse(spec, present, key, "translation", src)?;
    }
    let Some(d) = &spec.displacement else {
        return Err(src.at(
            &spec.kind,
            "a translation needs `displacement` (m, one number per axis, at load factor 1)",
        ));
    };
    let displacement = point::<D>(d, "translation `displacement`", src)?;
    if !displacement.iter().all(|v| v.is_finite()) {
        return Err(src.at(d, "translation `displacement` must be finite"));
    }
    let Some(fixed_name) = &spec.fixed else {
        return Err(src.at(
            &spec.kind,
            "a translation needs `fixed`: the node set that stays (the mesh between it and the carried set is compressed or stretched)",
        ));
    };
    let carried_name = spec.carried.as_ref().unwrap_or(&spec.driven);
    let named = |name: &Spanned<String>| lookup_ref(sets, name, "node set", src);
    let (carried, fixed) = (named(carried_name)?, named(fixed_name)?);
    let translation =
        Translation::new(initial, carried, fixed, displacement).ok_or_else(|| {
            src.at(
                fixed_name,
                format!(
                    "a translation needs non-empty carried (`{}`, {} nodes) and fixed (`{}`, {} nodes) sets with no node in both",
                    carried_name.get_ref(),
                    carried.len(),
                    fixed_name.get_ref(),
                    fixed.len()
                ),
            )
        })?;
    Ok((SceneMotion::Translation(translation), [true; D]))
}

/// `kind = "stretch"`: the mesh along `axis` from `origin` (the box's
/// lower corner by default) over `length` (to the upper corner) stretched
/// by `extension`.
fn stretch<const D: usize>(
    spec: &MotionSpec,
    axis: Option<usize>,
    lower: SVector<f64, D>,
    upper: SVector<f64, D>,
    src: &SceneSource,
) -> Result<MotionAndComponents<D>, SceneError> {
    refuse(spec, spec.centre.is_some(), "centre", "stretch", src)?;
    refuse(spec, spec.angle.is_some(), "angle", "stretch", src)?;
    let Some(axis) = axis else {
        return Err(src.at(&spec.kind, "a stretch needs `axis`"));
    };
    let Some(extension_at) = &spec.extension else {
        return Err(src.at(&spec.kind, "a stretch needs `extension` (m)"));
    };
    let extension = *extension_at.get_ref();
    let origin = spec.origin.unwrap_or(lower[axis]);
    let length = match &spec.length {
        Some(l) => *l.get_ref(),
        None => upper[axis] - origin,
    };
    if !(length > 0.0 && length.is_finite() && origin.is_finite()) {
        let at = spec.length.as_ref().map_or(spec.kind.span(), Spanned::span);
        return Err(src.error(
            Some(at),
            &format!("a stretch needs a finite positive length from `origin`, got {length}"),
        ));
    }
    if !extension.is_finite() || length + extension <= 0.0 {
        return Err(src.at(
            extension_at,
            format!("`extension` {extension} must be finite and leave a positive length"),
        ));
    }
    let mut components = [false; D];
    components[axis] = true;
    Ok((
        SceneMotion::Stretch(Stretch {
            axis,
            origin,
            length,
            extension,
        }),
        components,
    ))
}

/// `kind = "rotation"`: the mesh turned by `angle` about `centre` (the
/// out-of-plane axis in 2D, `axis` in 3D).
fn rotation<const D: usize>(
    spec: &MotionSpec,
    axis: Option<usize>,
    src: &SceneSource,
) -> Result<MotionAndComponents<D>, SceneError> {
    refuse(spec, spec.extension.is_some(), "extension", "rotation", src)?;
    refuse(spec, spec.length.is_some(), "length", "rotation", src)?;
    refuse(spec, spec.origin.is_some(), "origin", "rotation", src)?;
    if D == 3 && axis.is_none() {
        return Err(src.at(&spec.kind, "a rotation in 3D needs `axis` (x, y or z)"));
    }
    if let (2, Some(a)) = (D, &spec.axis) {
        return Err(src.at(
            a,
            "a rotation in 2D is about the out-of-plane axis: leave out `axis`",
        ));
    }
    let centre = match &spec.centre {
        None => SVector::<f64, D>::zeros(),
        Some(c) => point::<D>(c, "rotation `centre`", src)?,
    };
    let Some(angle) = &spec.angle else {
        return Err(src.at(
            &spec.kind,
            "a rotation needs `angle` (radians at load factor 1)",
        ));
    };
    if !angle.get_ref().is_finite() {
        return Err(src.at(angle, "`angle` must be finite"));
    }
    let rotation = Rotation::about_coordinate_axis(centre, axis.unwrap_or(2), *angle.get_ref())
        .ok_or_else(|| src.at(&spec.kind, "a rotation needs 2 or 3 dimensions"))?;
    Ok((SceneMotion::Rotation(rotation), [true; D]))
}
