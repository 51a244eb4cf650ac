//! What a scene with `[solver] kind = "explicit"` adds to its problem:
//! the CFL step's bound, the material-point fixities (`[[point_fixity]]`,
//! refused for the implicit solver), and the [`ExplicitSetup`] of the
//! run from its keys, conditions and loads.

use std::collections::BTreeMap;

use nalgebra::SVector;
use toml::Spanned;

use super::bodies::BuiltBodies;
use super::explicit_keys::ExplicitKeys;
use super::loads::ExplicitLoads;
use super::mesh::BuiltMesh;
use super::{AbsorbingFace, BuiltMaterial, ExplicitSetup, SceneMesh, axes_of};
use crate::SceneError;
use crate::format::{PointFixitySpec, Scene};
use crate::region::Region;
use crate::source::SceneSource;

/// An explicit run's checked keys, initial velocities and point
/// fixities, before its conditions and loads join them.
pub(super) struct ExplicitRun<const D: usize> {
    keys: ExplicitKeys,
    /// Initial velocity of every point (a held point's its held one).
    velocity: Vec<SVector<f64, D>>,
    /// (point, component, velocity), sorted.
    point_fixities: Vec<(usize, usize, f64)>,
}

/// The explicit run of `scene` with the keys `keys` (`None` for the
/// implicit solver, which takes no point fixity), on `mesh` with the
/// materials `materials` and the points of `bodies`.
///
/// # Errors
/// [`SceneError::Scene`] at `cfl` (or `kind`) when the CFL step would take
/// more than 1e9 steps, at a point fixity that is wrong or holds no point
/// or is given to the implicit solver.
pub(super) fn explicit_run<const D: usize>(
    keys: Option<ExplicitKeys>,
    scene: &Scene,
    mesh: &BuiltMesh<D>,
    materials: &[BuiltMaterial],
    bodies: &BuiltBodies<D>,
    src: &SceneSource,
) -> Result<Option<ExplicitRun<D>>, SceneError> {
    if let (Some(k), SceneMesh::Grid(grid)) = (&keys, &mesh.mesh) {
        cfl_bound(
            k,
            &scene.solver,
            grid.spacing().min(),
            materials,
            bodies,
            src,
        )?;
    }
    let point_fixities = point_fixities(&scene.point_fixities, keys.is_some(), bodies, src)?;
    Ok(keys.map(|keys| {
        let mut velocity = bodies.velocity.clone();
        // A held point starts at its held velocity.
        for &(p, c, v) in &point_fixities {
            velocity[p][c] = v;
        }
        ExplicitRun {
            keys,
            velocity,
            point_fixities,
        }
    }))
}

/// A CFL step is h / max(c + |v|) over the initial points (the
/// solver computes the signal speed once): the fixed `time_step`'s
/// bound of 1e9 steps, applied before running; `h`: the grid's smallest
/// spacing.
fn cfl_bound<const D: usize>(
    k: &ExplicitKeys,
    solver: &crate::format::SolverSpec,
    h: f64,
    materials: &[BuiltMaterial],
    bodies: &BuiltBodies<D>,
    src: &SceneSource,
) -> Result<(), SceneError> {
    let mpm_solver::TimeStep::Cfl { factor } = k.time_step else {
        return Ok(());
    };
    let wave = |m: &BuiltMaterial| {
        let (e, nu) = (m.params.youngs_modulus, m.params.poisson_ratio);
        (e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu)) / m.density).sqrt()
    };
    let c = materials.iter().map(wave).fold(0.0, f64::max);
    let v = bodies.velocity.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let steps = k.end_time * (c + v) / (factor * h);
    if steps.is_nan() || steps > 1e9 {
        let at = solver
            .cfl
            .as_ref()
            .map_or(solver.kind.span(), Spanned::span);
        return Err(src.error(
            Some(at),
            &format!("solver `cfl` {factor:e} would take {steps:.1e} steps of h / max(c + |v|) to reach end_time {}; more than 1e9", k.end_time),
        ));
    }
    Ok(())
}

/// The material-point fixities of `specs` (`explicit`: the scene runs the
/// explicit solver, the only one that takes them), sorted by point and
/// component.
fn point_fixities<const D: usize>(
    specs: &[PointFixitySpec],
    explicit: bool,
    bodies: &BuiltBodies<D>,
    src: &SceneSource,
) -> Result<Vec<(usize, usize, f64)>, SceneError> {
    let mut point_fixities: Vec<(usize, usize, f64)> = Vec::new();
    for spec in specs {
        if !explicit {
            return Err(src.at(
                &spec.velocity,
                "material-point fixities are a condition of the explicit solver ([solver] kind = \"explicit\"); the implicit solver holds nodes ([[boundary]])",
            ));
        }
        let values = axes_of::<D>(&spec.velocity, "velocity", src)?;
        let range = bodies.points_of(&spec.body, src)?;
        let region = Region::<D>::new(&spec.region, src)?;
        let held = bodies.points_in(range, &region);
        if held.is_empty() {
            return Err(src.at(
                &spec.velocity,
                "the point fixity's region holds no material point",
            ));
        }
        for p in held {
            for (c, v) in values.iter().take(D).enumerate() {
                if let Some(v) = v {
                    point_fixities.push((p, c, *v));
                }
            }
        }
    }
    // Sorted by point and component, a later fixity of the same
    // component replacing an earlier one: the rule of the solver's
    // nodal fixities, whose list serves points as well.
    let mut sorted = mpm_solver::VelocityFixities::new();
    for &(p, c, v) in &point_fixities {
        sorted.prescribe([p], c, v);
    }
    sorted.finish();
    Ok(sorted.entries().to_vec())
}

impl<const D: usize> ExplicitRun<D> {
    /// The run's setup with the nodal velocities `velocity_dofs` (per mesh
    /// dof), the friction walls `walls` ((node, axis, upper face, μ, gap check)), the
    /// loads `loads`, the absorbing faces `absorbing` and the contact
    /// between bodies `contact`.
    pub(super) fn setup(
        self,
        velocity_dofs: &[Option<f64>],
        walls: &[(usize, usize, bool, f64, bool)],
        loads: ExplicitLoads<D>,
        absorbing: &[AbsorbingFace],
        contact: Option<super::ContactSetup>,
    ) -> ExplicitSetup<D> {
        let k = self.keys;
        // One call per component and value (each call sorts the list).
        let mut groups: BTreeMap<(usize, u64), Vec<usize>> = BTreeMap::new();
        for (dof, v) in velocity_dofs.iter().enumerate() {
            if let Some(v) = v {
                groups
                    .entry((dof % D, v.to_bits()))
                    .or_default()
                    .push(dof / D);
            }
        }
        let mut fixities = mpm_solver::VelocityFixities::new();
        for ((component, bits), nodes) in groups {
            fixities.prescribe(nodes, component, f64::from_bits(bits));
        }
        for &(node, axis, upper, mu, gap) in walls {
            if gap {
                fixities.friction_gap_checked([node], axis, upper, mu);
            } else {
                fixities.friction([node], axis, upper, mu);
            }
        }
        for face in absorbing {
            let nodes = face.nodes.iter().copied();
            fixities.absorbing_with_springs(
                nodes,
                face.axis,
                (face.rho_cp, face.rho_cs),
                face.springs,
            );
        }
        ExplicitSetup {
            end_time: k.end_time,
            output_interval: k.output_interval,
            time_step: k.time_step,
            transfer: k.transfer,
            alpha: k.alpha,
            locking: k.locking,
            gravity: loads.gravity,
            fixities,
            velocity: self.velocity,
            point_forces: loads.forces,
            timed_forces: loads.timed,
            point_fixities: self.point_fixities,
            rebalance_every: k.rebalance_every,
            rebalance_threshold: k.rebalance_threshold,
            contact,
        }
    }
}
