//! The `[[boundary]]` conditions and the mesh motion: per mesh dof, the
//! displacement prescribed where its curve is 1 (fixed, roller,
//! displacement and gradient conditions), the conditions on sets that
//! follow a body, the explicit solver's prescribed velocities and friction
//! walls, and `[mesh.motion]` (absorbing boundaries: `absorbing.rs`).
//! Later conditions replace earlier ones on shared dofs.

use std::collections::BTreeMap;

use nalgebra::{SMatrix, SVector};

use super::curves::CurveTable;
use super::mesh::BuiltMesh;
use super::motion::motion_of;
use super::node_sets::NodeSets;
use super::{Following, SceneConstraints, axes_of, face_name};
use crate::SceneError;
use crate::format::{Axes, BoundaryKind, BoundarySpec, Scene};
use crate::source::SceneSource;
use mpm_solver::RigidTool;
use toml::Spanned;

/// The Dirichlet conditions of a scene.
pub(super) struct Conditions<const D: usize> {
    /// What the implicit solver prescribes.
    pub(super) constraints: SceneConstraints<D>,
    /// Per mesh dof `D * node + i`, the velocity an explicit run holds it
    /// at (0 for the held nodes of fixed, roller and zero-displacement
    /// conditions).
    pub(super) velocity_dofs: Vec<Option<f64>>,
    /// The explicit solver's friction walls: (node, axis, upper face, μ,
    /// gap check), sorted by node and face.
    pub(super) walls: Vec<(usize, usize, bool, f64, bool)>,
}

/// A rigid tool of `kind = "contact"`, its motion where its curve is 1
/// and the curve.
type SceneTool<const D: usize> = (RigidTool<D>, SVector<f64, D>, u16);

/// Refuses `gap_check = true` with a basis that keeps the points
/// `basis.padding()` cells inside the grid (the quadratic B-splines
/// without boundary modification): a body's face then never comes within
/// the check's tolerance of the wall, and the wall would let it through.
///
/// # Errors
/// [`SceneError::Scene`] at the `gap_check` key.
pub(super) fn refuse_unreachable_gap_checks(
    scene: &Scene,
    basis: crate::variant::BasisKind,
    src: &SceneSource,
) -> Result<(), SceneError> {
    if basis.padding() == 0 {
        return Ok(());
    }
    match (scene.boundaries.iter())
        .filter_map(|b| b.gap_check.as_ref())
        .find(|g| *g.get_ref())
    {
        Some(g) => Err(src.at(
            g,
            format!(
                "`gap_check = true` needs a basis whose points reach the grid's faces: basis = {} keeps them {} cell(s) inside, so a body never touches the wall and would pass it; use bspline2_boundary, linear or gimp",
                basis.name(),
                basis.padding()
            ),
        )),
        None => Ok(()),
    }
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
        walls: BTreeMap::new(),
        tools: Vec::new(),
        grid: matches!(mesh.mesh, super::SceneMesh::Grid(_)),
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
            tool_motion: held.tools.iter().map(|t| (t.1, t.2)).collect(),
            tools: held.tools.into_iter().map(|t| t.0).collect(),
        },
        velocity_dofs: held.velocity_dofs,
        walls: (held.walls.into_iter())
            .map(|((node, axis, upper), (mu, gap))| (node, axis, upper, mu, gap))
            .collect(),
    })
}

/// The conditions while the boundaries are read, in file order.
struct Held<'a, const D: usize> {
    /// Per mesh dof: `(displacement, curve index)`.
    dofs: Vec<Option<(f64, u16)>>,
    /// Per mesh dof: the explicit solver's velocity.
    velocity_dofs: Vec<Option<f64>>,
    /// Friction walls by (node, axis, upper face): μ and the gap check.
    walls: BTreeMap<(usize, usize, bool), (f64, bool)>,
    /// The rigid tools of `kind = "contact"`.
    tools: Vec<SceneTool<D>>,
    /// The mesh is a regular grid (a tool's penalty needs its cell size).
    grid: bool,
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
        for (key, present, owner) in [
            ("velocity", spec.velocity.is_some(), BoundaryKind::Velocity),
            ("material", spec.material.is_some(), BoundaryKind::Absorbing),
            ("spring", spec.spring.is_some(), BoundaryKind::Absorbing),
            (
                "gap_check",
                spec.gap_check.is_some(),
                BoundaryKind::Friction,
            ),
            ("normal", spec.normal.is_some(), BoundaryKind::Contact),
            ("rough", spec.rough.is_some(), BoundaryKind::Contact),
            (
                "normal_stiffness",
                spec.normal_stiffness.is_some(),
                BoundaryKind::Contact,
            ),
            (
                "tangential_stiffness",
                spec.tangential_stiffness.is_some(),
                BoundaryKind::Contact,
            ),
        ] {
            if present && kind != owner {
                return Err(src.at(
                    &spec.kind,
                    format!(
                        "`{key}` applies to kind = {}, not {}",
                        boundary_kind_name(owner),
                        boundary_kind_name(kind)
                    ),
                ));
            }
        }
        if let Some(mu) = spec
            .friction
            .as_ref()
            .filter(|_| kind != BoundaryKind::Friction && kind != BoundaryKind::Contact)
        {
            return Err(src.at(
                mu,
                format!(
                    "`friction` applies to kind = friction or contact, not {}",
                    boundary_kind_name(kind)
                ),
            ));
        }
        if kind == BoundaryKind::Friction && !self.explicit {
            return Err(src.at(
                &spec.kind,
                "kind = friction needs the explicit solver; the implicit solver's frictional wall is kind = contact (a rigid tool)",
            ));
        }
        if kind == BoundaryKind::Contact && self.explicit {
            return Err(src.at(
                &spec.kind,
                "kind = contact (a rigid tool) needs the implicit solver; the explicit solver's frictional wall is kind = friction",
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
            BoundaryKind::Friction => self.friction(spec, nodes),
            BoundaryKind::Contact => self.contact(spec, nodes),
            // Its dashpots are built by `absorbing.rs`; it holds nothing.
            BoundaryKind::Absorbing => Ok(()),
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
            BoundaryKind::Roller | BoundaryKind::Friction | BoundaryKind::Contact => {
                return Err(src.at(
                    &spec.set,
                    format!(
                        "{} needs a grid face for its normal; `{}` follows a body",
                        wall_name(*spec.kind.get_ref()),
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
            BoundaryKind::Absorbing => {
                return Err(src.at(
                    &spec.kind,
                    "kind = absorbing needs the explicit solver ([solver] kind = \"explicit\"); the implicit solver is static",
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
        refuse_displacement_keys(spec, self.src)?;
        if *spec.kind.get_ref() == BoundaryKind::Fixed {
            (0..D).for_each(|i| self.prescribe(nodes, i, 0.0, 0));
        } else {
            let (axis, _) = self.face_of(spec)?;
            self.prescribe(nodes, axis, 0.0, 0);
        }
        Ok(())
    }

    /// The axis and side (upper) of the grid face `spec.set`, which a
    /// roller or friction wall needs for its normal.
    fn face_of(&self, spec: &BoundarySpec) -> Result<(usize, bool), SceneError> {
        let set = spec.set.get_ref();
        let face = (0..D)
            .flat_map(|i| [(i, false), (i, true)])
            .find(|&(i, upper)| face_name(i, upper) == *set);
        face.ok_or_else(|| {
            self.src.at(
                &spec.set,
                format!(
                    "{} needs a grid face for its normal ({}); `{set}` is not one",
                    wall_name(*spec.kind.get_ref()),
                    self.sets.faces.join(", "),
                ),
            )
        })
    }

    /// `kind = "friction"` (explicit solver): the face's nodes become nodes
    /// of a friction wall with coefficient `friction`; the wall replaces an
    /// earlier hold of their normal component (a later one replaces the
    /// wall: the solver holds a node whose normal is held).
    fn friction(&mut self, spec: &BoundarySpec, nodes: &[usize]) -> Result<(), SceneError> {
        let src = self.src;
        refuse_displacement_keys(spec, self.src)?;
        let Some(mu) = &spec.friction else {
            return Err(src.at(
                &spec.kind,
                "kind = friction needs `friction = μ`, the Coulomb coefficient (≥ 0; 0 is a slip wall that lets go)",
            ));
        };
        let value = *mu.get_ref();
        if !(value.is_finite() && value >= 0.0) {
            return Err(src.at(
                mu,
                format!("`friction` is a Coulomb coefficient: finite and ≥ 0, got {value}"),
            ));
        }
        let (axis, upper) = self.face_of(spec)?;
        let gap = spec.gap_check.as_ref().is_some_and(|g| *g.get_ref());
        for &v in nodes {
            self.walls.insert((v, axis, upper), (value, gap));
            self.dofs[v * D + axis] = None;
            self.velocity_dofs[v * D + axis] = None;
        }
        Ok(())
    }

    /// `kind = "contact"`: a rigid tool on the set's nodes, its normal
    /// (the face's inward one by default), friction, penalties and motion
    /// (`displacement` along `curve`, at rest without).
    fn contact(&mut self, spec: &BoundarySpec, nodes: &[usize]) -> Result<(), SceneError> {
        let src = self.src;
        if let Some(g) = &spec.gradient {
            return Err(src.at(
                g,
                "`gradient` applies to kind = displacement, not contact (a rigid tool moves by `displacement`)",
            ));
        }
        if !self.grid {
            return Err(src.at(
                &spec.kind,
                "kind = contact needs a regular grid (its penalties scale with the cell size); this mesh is not one",
            ));
        }
        let normal = match &spec.normal {
            Some(n) => {
                let a = axes_of::<D>(n, "normal", src)?;
                let v = SVector::<f64, D>::from_fn(|i, _| a[i].unwrap_or(0.0));
                // Scaled by its largest component first: no overflow or
                // underflow of the norm for extreme components.
                let largest = v.amax();
                if largest == 0.0 {
                    return Err(src.at(n, "`normal` must not be zero"));
                }
                let v = v / largest;
                v / v.norm()
            }
            None => {
                let set = spec.set.get_ref();
                let face = (0..D)
                    .flat_map(|i| [(i, false), (i, true)])
                    .find(|&(i, upper)| face_name(i, upper) == *set);
                let Some((axis, upper)) = face else {
                    return Err(src.at(
                        &spec.set,
                        format!(
                            "a rigid tool on `{set}` needs `normal = {{ x = …, y = … }}`, its face's normal pointing into the body (a grid face gives its own: {})",
                            self.sets.faces.join(", ")
                        ),
                    ));
                };
                let mut v = SVector::<f64, D>::zeros();
                v[axis] = if upper { -1.0 } else { 1.0 };
                v
            }
        };
        let friction = match (&spec.friction, &spec.rough) {
            (Some(mu), Some(r)) if *r.get_ref() => {
                return Err(src.at(
                    mu,
                    "give `friction = μ` or `rough = true`, not both (rough is pure stick)",
                ));
            }
            (Some(mu), _) => {
                let value = *mu.get_ref();
                if !(value.is_finite() && value >= 0.0) {
                    return Err(src.at(
                        mu,
                        format!("`friction` is a Coulomb coefficient: finite and ≥ 0, got {value}"),
                    ));
                }
                value
            }
            (None, Some(r)) if *r.get_ref() => f64::INFINITY,
            _ => 0.0,
        };
        let stiffness = |k: &Option<Spanned<f64>>, key: &str| -> Result<Option<f64>, SceneError> {
            match k {
                Some(k) if !(k.get_ref().is_finite() && *k.get_ref() > 0.0) => Err(src.at(
                    k,
                    format!(
                        "`{key}` is a penalty per unit area (Pa/m): finite and > 0, got {}",
                        k.get_ref()
                    ),
                )),
                Some(k) => Ok(Some(*k.get_ref())),
                None => Ok(None),
            }
        };
        let motion = match &spec.displacement {
            Some(d) => {
                let a = displacement_of::<D>(d, src)?;
                SVector::<f64, D>::from_fn(|i, _| a[i].unwrap_or(0.0))
            }
            None => SVector::zeros(),
        };
        let curve = self.curves.index(&spec.curve, src)?;
        let mut nodes = nodes.to_vec();
        nodes.sort_unstable();
        nodes.dedup();
        let tool = RigidTool {
            name: spec.set.get_ref().clone(),
            nodes,
            normal,
            friction,
            normal_stiffness: stiffness(&spec.normal_stiffness, "normal_stiffness")?,
            tangential_stiffness: stiffness(&spec.tangential_stiffness, "tangential_stiffness")?,
        };
        self.tools.push((tool, motion, curve as u16));
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
        refuse_displacement_keys(spec, src)?;
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

/// Refuses the keys of `kind = "displacement"` (`displacement`,
/// `gradient`, `curve`) on a condition of another kind.
///
/// # Errors
/// [`SceneError::Scene`] at `kind`, naming the first key given.
pub(super) fn refuse_displacement_keys(
    spec: &BoundarySpec,
    src: &SceneSource,
) -> Result<(), SceneError> {
    for (key, present) in [
        ("displacement", spec.displacement.is_some()),
        ("gradient", spec.gradient.is_some()),
        ("curve", spec.curve.is_some()),
    ] {
        if present {
            return Err(src.at(
                &spec.kind,
                format!(
                    "`{key}` applies to kind = displacement, not {}",
                    boundary_kind_name(*spec.kind.get_ref())
                ),
            ));
        }
    }
    Ok(())
}

/// The name of a boundary kind in scene files.
fn boundary_kind_name(kind: BoundaryKind) -> &'static str {
    match kind {
        BoundaryKind::Fixed => "fixed",
        BoundaryKind::Roller => "roller",
        BoundaryKind::Displacement => "displacement",
        BoundaryKind::Velocity => "velocity",
        BoundaryKind::Friction => "friction",
        BoundaryKind::Absorbing => "absorbing",
        BoundaryKind::Contact => "contact",
    }
}

/// What a condition on a face is called in messages: "a roller", "a
/// friction wall".
fn wall_name(kind: BoundaryKind) -> &'static str {
    match kind {
        BoundaryKind::Friction => "a friction wall",
        BoundaryKind::Contact => "a rigid tool",
        _ => "a roller",
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

#[cfg(test)]
mod tests {
    use crate::Problem;

    /// A block on the floor of a 2 x 2 grid, explicit, with `boundaries`.
    fn build(boundaries: &str) -> Problem<2> {
        let text = format!(
            r#"[mesh]
origin = [0.0, 0.0]
size = [1.0, 1.0]
cells = [2, 2]

[[material]]
name = "m"
model = "neo_hookean"
youngs_modulus = 1.0e6
poisson_ratio = 0.3
density = 1.0

[[body]]
name = "b"
material = "m"
region = {{ box = {{ lower = [0.0, 0.0], upper = [1.0, 0.5] }} }}

{boundaries}
[solver]
kind = "explicit"
basis = "bspline2_boundary"
end_time = 0.1
"#
        );
        let (scene, src) = crate::parse(&text, "s.toml", &[]).expect("the scene parses");
        Problem::<2>::build(&scene, &src, scene.solver.padding()).expect("the scene builds")
    }

    /// A wall's (node, axis, upper, μ).
    type Wall = (usize, usize, bool, f64);

    /// The walls the solver keeps, and the held (node, component)s.
    fn conditions(boundaries: &str) -> (Vec<Wall>, Vec<(usize, usize)>) {
        let problem = build(boundaries);
        let mut fixities = problem.explicit.expect("an explicit scene").fixities;
        fixities.finish();
        (
            (fixities.walls().iter())
                .map(|w| (w.node, w.axis, w.upper, w.mu))
                .collect(),
            fixities.entries().iter().map(|&(n, c, _)| (n, c)).collect(),
        )
    }

    /// In file order, a friction wall replaces a roller on the same face
    /// and a roller (or any hold of the normal) a friction wall; a later
    /// wall on a face replaces the earlier; the x_max face's walls push
    /// along +x.
    #[test]
    fn friction_walls_and_holds_replace_each_other_in_file_order() {
        let roller = "[[boundary]]\nset = \"y_min\"\nkind = \"roller\"\n";
        let wall = |face: &str, mu: f64| {
            format!("[[boundary]]\nset = \"{face}\"\nkind = \"friction\"\nfriction = {mu:?}\n")
        };
        let floor: Vec<_> = (0..3).map(|i| (i, 1, false, 0.3)).collect();
        let (walls, held) = conditions(&format!("{roller}{}", wall("y_min", 0.3)));
        assert_eq!((walls, held), (floor.clone(), vec![]));
        let (walls, held) = conditions(&format!("{}{roller}", wall("y_min", 0.3)));
        assert_eq!(walls, vec![]);
        assert_eq!(held, (0..3).map(|i| (i, 1)).collect::<Vec<_>>());
        let (walls, _) = conditions(&format!("{}{}", wall("y_min", 0.1), wall("y_min", 0.3)));
        assert_eq!(walls, floor);
        let (walls, _) = conditions(&wall("x_max", 0.0));
        assert_eq!(
            walls,
            vec![(2, 0, true, 0.0), (5, 0, true, 0.0), (8, 0, true, 0.0)]
        );
    }

    /// `gap_check = true` makes the face's walls gap-checked; without it
    /// they act wherever a node has mass.
    #[test]
    fn gap_check_marks_the_walls_of_its_face() {
        for (key, expected) in [
            ("", false),
            ("gap_check = true\n", true),
            ("gap_check = false\n", false),
        ] {
            let text = format!(
                "[[boundary]]\nset = \"y_min\"\nkind = \"friction\"\nfriction = 0.3\n{key}"
            );
            let mut fixities = build(&text).explicit.expect("an explicit scene").fixities;
            fixities.finish();
            assert_eq!(fixities.walls().len(), 3);
            assert!(
                fixities.walls().iter().all(|w| w.gap_check == expected),
                "{key}"
            );
        }
    }

    /// The quadratic B-splines without boundary modification keep the
    /// points a cell inside the grid: a gap-checked wall is refused with
    /// them, at its key (a block at 40 m/s went through such a wall in the
    /// stability matrix before this refusal).
    #[test]
    fn a_gap_check_the_points_cannot_reach_is_refused() {
        let wall = "[[boundary]]\nset = \"y_min\"\nkind = \"friction\"\nfriction = 0.3\ngap_check = true\n";
        let text = format!(
            "[mesh]\norigin = [0.0, 0.0]\nsize = [2.0, 2.0]\ncells = [4, 4]\n\n\
             [[material]]\nname = \"m\"\nmodel = \"neo_hookean\"\nyoungs_modulus = 1.0e6\npoisson_ratio = 0.3\ndensity = 1.0\n\n\
             [[body]]\nname = \"b\"\nmaterial = \"m\"\nregion = {{ box = {{ lower = [0.5, 0.5], upper = [1.5, 1.0] }} }}\n\n\
             {wall}\n[solver]\nkind = \"explicit\"\nbasis = \"bspline2\"\nend_time = 0.1\n"
        );
        let (scene, src) = crate::parse(&text, "s.toml", &[]).expect("the scene parses");
        let Err(err) = Problem::<2>::build(&scene, &src, scene.solver.padding()) else {
            panic!("a gap check with bspline2 built");
        };
        let err = err.to_string();
        assert!(
            err.starts_with("s.toml:22:13: `gap_check = true` needs a basis whose points reach the grid's faces: basis = bspline2"),
            "{err}"
        );
    }
}
