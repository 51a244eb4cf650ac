//! The `[[boundary]]` conditions and the mesh motion: per mesh dof, the
//! displacement prescribed where its curve is 1 (fixed, roller,
//! displacement and gradient conditions), the conditions on sets that
//! follow a body, the explicit solver's prescribed velocities, and
//! `[mesh.motion]`. Later conditions replace earlier ones on shared dofs.

use nalgebra::{SMatrix, SVector};

use super::curves::CurveTable;
use super::mesh::BuiltMesh;
use super::motion::motion_of;
use super::node_sets::NodeSets;
use super::{Following, SceneConstraints, axes_of, face_name};
use crate::SceneError;
use crate::format::{Axes, BoundaryKind, BoundarySpec, Scene};
use crate::source::SceneSource;
use toml::Spanned;

/// The Dirichlet conditions of a scene.
pub(super) struct Conditions<const D: usize> {
    /// What the implicit solver prescribes.
    pub(super) constraints: SceneConstraints<D>,
    /// Per mesh dof `D * node + i`, the velocity an explicit run holds it
    /// at (0 for the held nodes of fixed, roller and zero-displacement
    /// conditions).
    pub(super) velocity_dofs: Vec<Option<f64>>,
}

/// The conditions of `scene` (its boundaries, then its mesh motion) on
/// `mesh`, with the node sets `sets` and the curves `curves`; `explicit`:
/// the scene runs the explicit solver.
///
/// # Errors
/// [`SceneError::Scene`] at the condition's key that is wrong or does not
/// apply to its kind, set or solver.
pub(super) fn conditions<const D: usize>(
    scene: &Scene,
    mesh: &BuiltMesh<D>,
    sets: &NodeSets,
    curves: &CurveTable,
    explicit: bool,
    src: &SceneSource,
) -> Result<Conditions<D>, SceneError> {
    let node_count = mesh.mesh.node_count();
    let mut held = Held {
        dofs: vec![None; node_count * D],
        velocity_dofs: vec![None; node_count * D],
        following: Vec::new(),
        initial_nodes: (0..node_count)
            .map(|v| mesh.mesh.node_position(v))
            .collect(),
        sets,
        curves,
        explicit,
        src,
    };
    for spec in &scene.boundaries {
        held.boundary(spec)?;
    }
    let motion = match &scene.mesh.motion {
        Some(spec) => Some(motion_of(
            spec,
            &sets.sets,
            &held.initial_nodes,
            mesh.origin,
            mesh.upper,
            src,
        )?),
        None => None,
    };
    Ok(Conditions {
        constraints: SceneConstraints {
            dofs: held.dofs,
            curves: curves.curves.clone(),
            following: held.following,
            motion,
        },
        velocity_dofs: held.velocity_dofs,
    })
}

/// The conditions while the boundaries are read, in file order.
struct Held<'a, const D: usize> {
    /// Per mesh dof: `(displacement, curve index)`.
    dofs: Vec<Option<(f64, u16)>>,
    /// Per mesh dof: the explicit solver's velocity.
    velocity_dofs: Vec<Option<f64>>,
    /// Conditions on sets that follow a body.
    following: Vec<Following<D>>,
    /// Initial node positions.
    initial_nodes: Vec<SVector<f64, D>>,
    sets: &'a NodeSets,
    curves: &'a CurveTable,
    explicit: bool,
    src: &'a SceneSource,
}

impl<const D: usize> Held<'_, D> {
    /// Adds the condition `spec`.
    fn boundary(&mut self, spec: &BoundarySpec) -> Result<(), SceneError> {
        let src = self.src;
        let gradient = match &spec.gradient {
            Some(g) => Some(gradient_of::<D>(g, src)?),
            None => None,
        };
        let kind = *spec.kind.get_ref();
        if spec.velocity.is_some() && kind != BoundaryKind::Velocity {
            return Err(src.at(
                &spec.kind,
                format!(
                    "`velocity` applies to kind = velocity, not {}",
                    boundary_kind_name(kind)
                ),
            ));
        }
        if self.explicit && self.sets.following.contains_key(spec.set.get_ref()) {
            return Err(src.at(
                &spec.set,
                format!(
                    "node set `{}` follows a body; the explicit solver's conditions hold fixed sets of nodes",
                    spec.set.get_ref()
                ),
            ));
        }
        if let Some(points) = self.sets.following.get(spec.set.get_ref()) {
            let (displacement, gradient, curve) = self.following_condition(spec, gradient)?;
            self.following.push(Following {
                points: points.clone(),
                nodes: self.initial_nodes.clone(),
                active: vec![false; self.initial_nodes.len()],
                displacement,
                gradient,
                curve: curve as u16,
            });
            return Ok(());
        }
        let nodes = self.sets.set_of(&spec.set, src)?;
        match spec.kind.get_ref() {
            BoundaryKind::Fixed | BoundaryKind::Roller => self.hold(spec, nodes),
            BoundaryKind::Displacement => self.displace(spec, nodes, gradient.as_ref()),
            BoundaryKind::Velocity if self.explicit => self.velocity(spec, nodes),
            BoundaryKind::Velocity => Err(src.at(
                &spec.kind,
                "kind = velocity needs the explicit solver; the implicit solver prescribes displacements (kind = displacement)",
            )),
        }
    }

    /// The displacement, gradient and curve of a condition on a set that
    /// follows a body (every component prescribed).
    fn following_condition(
        &self,
        spec: &BoundarySpec,
        gradient: Option<SMatrix<f64, D, D>>,
    ) -> Result<(SVector<f64, D>, SMatrix<f64, D, D>, usize), SceneError> {
        let src = self.src;
        Ok(match spec.kind.get_ref() {
            BoundaryKind::Fixed => {
                if spec.displacement.is_some() || spec.gradient.is_some() || spec.curve.is_some() {
                    return Err(src.at(
                        &spec.kind,
                        "`displacement`, `gradient` and `curve` apply to kind = displacement, not fixed",
                    ));
                }
                (SVector::zeros(), SMatrix::<f64, D, D>::zeros(), 0)
            }
            BoundaryKind::Displacement => {
                let d = match &spec.displacement {
                    Some(d) => displacement_of::<D>(d, src)?,
                    None if gradient.is_some() => [None; 3],
                    None => {
                        return Err(src.at(
                            &spec.kind,
                            "kind = displacement needs `displacement = { x = …, y = … }` or `gradient`",
                        ));
                    }
                };
                if gradient.is_none() && d.iter().take(D).any(Option::is_none) {
                    return Err(src.at(
                        &spec.set,
                        "a displacement on a set that follows a body prescribes every component: give all of them, or a `gradient`",
                    ));
                }
                (
                    SVector::<f64, D>::from_fn(|i, _| d[i].unwrap_or(0.0)),
                    gradient.unwrap_or_else(SMatrix::<f64, D, D>::zeros),
                    self.curves.index(&spec.curve, src)?,
                )
            }
            BoundaryKind::Roller => {
                return Err(src.at(
                    &spec.set,
                    format!(
                        "a roller needs a grid face for its normal; `{}` follows a body",
                        spec.set.get_ref()
                    ),
                ));
            }
            BoundaryKind::Velocity => {
                return Err(src.at(
                    &spec.kind,
                    "kind = velocity needs the explicit solver; the implicit solver prescribes displacements (kind = displacement)",
                ));
            }
        })
    }

    /// Prescribes `value` on `component` of `nodes` with curve `curve`
    /// (and holds them in an explicit run: its displacements are zero).
    fn prescribe(&mut self, nodes: &[usize], component: usize, value: f64, curve: usize) {
        for &v in nodes {
            self.dofs[v * D + component] = Some((value, curve as u16));
            // Explicit runs: a held node (explicit displacements are zero).
            self.velocity_dofs[v * D + component] = Some(0.0);
        }
    }

    /// `kind = "fixed"` (every component) or `"roller"` (the normal of a
    /// face).
    fn hold(&mut self, spec: &BoundarySpec, nodes: &[usize]) -> Result<(), SceneError> {
        let src = self.src;
        let not_here = |what: &str, kind: &str| {
            src.at(
                &spec.kind,
                format!("`{what}` applies to kind = displacement, not {kind}"),
            )
        };
        let kind = if *spec.kind.get_ref() == BoundaryKind::Fixed {
            "fixed"
        } else {
            "roller"
        };
        if spec.displacement.is_some() {
            return Err(not_here("displacement", kind));
        }
        if spec.curve.is_some() {
            return Err(not_here("curve", kind));
        }
        if spec.gradient.is_some() {
            return Err(not_here("gradient", kind));
        }
        if *spec.kind.get_ref() == BoundaryKind::Fixed {
            (0..D).for_each(|i| self.prescribe(nodes, i, 0.0, 0));
        } else {
            let axis = (0..D)
                .find(|&i| [face_name(i, false), face_name(i, true)].contains(spec.set.get_ref()));
            let Some(axis) = axis else {
                return Err(src.at(
                    &spec.set,
                    format!(
                        "a roller needs a grid face for its normal ({}); `{}` is not one",
                        self.sets.faces.join(", "),
                        spec.set.get_ref()
                    ),
                ));
            };
            self.prescribe(nodes, axis, 0.0, 0);
        }
        Ok(())
    }

    /// `kind = "displacement"`: the given components, or every component
    /// `u = d + G x` with a gradient.
    fn displace(
        &mut self,
        spec: &BoundarySpec,
        nodes: &[usize],
        gradient: Option<&SMatrix<f64, D, D>>,
    ) -> Result<(), SceneError> {
        let src = self.src;
        let curve = self.curves.index(&spec.curve, src)?;
        let values = match (&spec.displacement, gradient) {
            (Some(d), _) => displacement_of::<D>(d, src)?,
            (None, Some(_)) => [None; 3],
            (None, None) => {
                return Err(src.at(
                    &spec.kind,
                    "kind = displacement needs `displacement = { x = …, y = … }` or `gradient`",
                ));
            }
        };
        if self.explicit && (gradient.is_some() || values.iter().flatten().any(|u| *u != 0.0)) {
            return Err(src.at(
                &spec.kind,
                "a non-zero displacement follows the implicit solver's load factor; the explicit solver holds nodes (fixed, roller, a zero displacement) or moves them at a constant velocity (kind = \"velocity\")",
            ));
        }
        match gradient {
            None => {
                for (i, v) in values.iter().take(D).enumerate() {
                    if let Some(v) = v {
                        self.prescribe(nodes, i, *v, curve);
                    }
                }
            }
            Some(g) => {
                // Every component: u = d + G x at the node.
                for &v in nodes {
                    let x = self.initial_nodes[v];
                    for i in 0..D {
                        let u = values[i].unwrap_or(0.0)
                            + (0..D).map(|j| g[(i, j)] * x[j]).sum::<f64>();
                        self.dofs[v * D + i] = Some((u, curve as u16));
                    }
                }
            }
        }
        Ok(())
    }

    /// `kind = "velocity"` (explicit solver): the given components move at
    /// a constant velocity.
    fn velocity(&mut self, spec: &BoundarySpec, nodes: &[usize]) -> Result<(), SceneError> {
        let src = self.src;
        for (key, present) in [
            ("displacement", spec.displacement.is_some()),
            ("gradient", spec.gradient.is_some()),
            ("curve", spec.curve.is_some()),
        ] {
            if present {
                return Err(src.at(
                    &spec.kind,
                    format!("`{key}` applies to kind = displacement, not velocity"),
                ));
            }
        }
        let Some(v) = &spec.velocity else {
            return Err(src.at(
                &spec.kind,
                "kind = velocity needs `velocity = { x = …, y = … }` (m/s)",
            ));
        };
        let values = axes_of::<D>(v, "velocity", src)?;
        for (i, value) in values.iter().take(D).enumerate() {
            if let Some(value) = value {
                for &node in nodes {
                    self.velocity_dofs[node * D + i] = Some(*value);
                }
            }
        }
        Ok(())
    }
}

/// The components of a `displacement` table, checked against the
/// dimension (at least one given).
fn displacement_of<const D: usize>(
    d: &Spanned<Axes>,
    src: &SceneSource,
) -> Result<[Option<f64>; 3], SceneError> {
    axes_of::<D>(d, "displacement", src)
}

/// The name of a boundary kind in scene files.
fn boundary_kind_name(kind: BoundaryKind) -> &'static str {
    match kind {
        BoundaryKind::Fixed => "fixed",
        BoundaryKind::Roller => "roller",
        BoundaryKind::Displacement => "displacement",
        BoundaryKind::Velocity => "velocity",
    }
}

/// A `gradient`: `D` rows of `D` finite numbers.
fn gradient_of<const D: usize>(
    g: &Spanned<Vec<Vec<f64>>>,
    src: &SceneSource,
) -> Result<SMatrix<f64, D, D>, SceneError> {
    let rows = g.get_ref();
    if rows.len() != D || rows.iter().any(|r| r.len() != D) {
        return Err(src.at(
            g,
            format!("`gradient` must be {D} rows of {D} numbers in a {D}D scene"),
        ));
    }
    if rows.iter().flatten().any(|v| !v.is_finite()) {
        return Err(src.at(g, "`gradient` must be finite"));
    }
    Ok(SMatrix::<f64, D, D>::from_fn(|i, j| rows[i][j]))
}
