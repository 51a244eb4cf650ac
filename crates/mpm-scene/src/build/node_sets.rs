//! The node sets a scene's conditions and outputs name: the faces of the
//! box, a simplex mesh's physical groups, the `[[node_set]]` regions, and
//! the sets that follow a body (its boundary points, `around`).

use std::collections::BTreeMap;

use nalgebra::SVector;
use toml::Spanned;

use super::bodies::BuiltBodies;
use super::mesh::BuiltMesh;
use super::{SceneMesh, face_name, lookup, lookup_ref};
use crate::SceneError;
use crate::format::NodeSetSpec;
use crate::region::Region;
use crate::source::SceneSource;

/// The node sets of a scene.
pub(super) struct NodeSets {
    /// Mesh nodes by set name: the faces, the mesh's groups (unless a
    /// face has their name) and the `[[node_set]]` regions.
    pub(super) sets: BTreeMap<String, Vec<usize>>,
    /// Sets that follow a body: their boundary points, by set name.
    pub(super) following: BTreeMap<String, Vec<usize>>,
    /// The faces' names (`x_min`, `x_max`, …), sorted.
    pub(super) faces: Vec<String>,
}

impl NodeSets {
    /// The nodes of the set `name`, which must not follow a body.
    ///
    /// # Errors
    /// [`SceneError::Scene`] at `name` when no set has it or its set
    /// follows a body.
    pub(super) fn set_of<'s>(
        &'s self,
        name: &Spanned<String>,
        src: &SceneSource,
    ) -> Result<&'s Vec<usize>, SceneError> {
        if self.following.contains_key(name.get_ref()) {
            return Err(src.at(
                name,
                format!(
                    "node set `{}` follows a body (its nodes change every step); use it for a fixed or displacement boundary",
                    name.get_ref()
                ),
            ));
        }
        lookup_ref(&self.sets, name, "node set", src)
    }
}

/// The node sets of `mesh`: its faces, then the mesh's groups, then
/// `specs` in file order (a region, or `around` a body of `bodies`).
///
/// # Errors
/// [`SceneError::Scene`] at a set defined twice, empty, or with neither
/// or both of `region` and `around`.
pub(super) fn node_sets<const D: usize>(
    specs: &[NodeSetSpec],
    mesh: &BuiltMesh<D>,
    bodies: &BuiltBodies<D>,
    src: &SceneSource,
) -> Result<NodeSets, SceneError> {
    let mut sets = faces(mesh);
    let faces: Vec<String> = sets.keys().cloned().collect();
    if let SceneMesh::Simplex(sm) = &mesh.mesh {
        // The mesh's physical groups, unless a face has their name.
        for (name, nodes) in sm.node_sets().iter() {
            sets.entry(name.to_owned())
                .or_insert_with(|| nodes.to_vec());
        }
    }
    // Sets that follow a body: its boundary points.
    let mut following_sets: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for spec in specs {
        if sets.contains_key(spec.name.get_ref())
            || following_sets.contains_key(spec.name.get_ref())
        {
            return Err(src.at(
                &spec.name,
                format!(
                    "node set `{}` is already defined (a grid face or an earlier set)",
                    spec.name.get_ref()
                ),
            ));
        }
        let region_spec = match (&spec.region, &spec.around) {
            (Some(r), None) => r,
            (None, Some(body_name)) => {
                let boundary = boundary_points(body_name, bodies, src)?;
                following_sets.insert(spec.name.get_ref().clone(), boundary);
                continue;
            }
            _ => {
                return Err(src.at(
                    &spec.name,
                    format!(
                        "node set `{}` needs one of `region` or `around`",
                        spec.name.get_ref()
                    ),
                ));
            }
        };
        let region = Region::<D>::new(region_spec, src)?;
        let nodes: Vec<usize> = (0..mesh.mesh.node_count())
            .filter(|&v| region.contains(&mesh.mesh.node_position(v)))
            .collect();
        if nodes.is_empty() {
            return Err(src.at(
                &spec.name,
                format!("node set `{}` holds no grid node", spec.name.get_ref()),
            ));
        }
        sets.insert(spec.name.get_ref().clone(), nodes);
    }
    Ok(NodeSets {
        sets,
        following: following_sets,
        faces,
    })
}

/// The nodes on each face of the box, by face name.
fn faces<const D: usize>(mesh: &BuiltMesh<D>) -> BTreeMap<String, Vec<usize>> {
    let (origin, upper, tol) = (mesh.origin, mesh.upper, mesh.tol());
    let mut sets = BTreeMap::new();
    for axis in 0..D {
        for upper_face in [false, true] {
            let bound = if upper_face {
                upper[axis]
            } else {
                origin[axis]
            };
            let nodes = (0..mesh.mesh.node_count())
                .filter(|&v| {
                    let x = mesh.mesh.node_position(v)[axis];
                    if upper_face {
                        x >= bound - tol
                    } else {
                        x <= bound + tol
                    }
                })
                .collect();
            sets.insert(face_name(axis, upper_face), nodes);
        }
    }
    sets
}

/// The boundary points of the body `body_name` (a region on a grid): those
/// with a lattice neighbour outside the region.
fn boundary_points<const D: usize>(
    body_name: &Spanned<String>,
    bodies: &BuiltBodies<D>,
    src: &SceneSource,
) -> Result<Vec<usize>, SceneError> {
    let k = lookup(&bodies.names, body_name, "body", src)?;
    let body = &bodies.bodies[k];
    let (Some(region), false) = (&bodies.regions[k], body.step.is_empty()) else {
        return Err(src.at(
            body_name,
            "`around` needs a body given by a region on a grid (its boundary points are those with a lattice neighbour outside the region)",
        ));
    };
    Ok(body
        .points
        .clone()
        .filter(|&p| {
            let x = bodies.points.position[p];
            (0..D).any(|i| {
                let mut e = SVector::<f64, D>::zeros();
                e[i] = body.step[i];
                !region.contains(&(x + e)) || !region.contains(&(x - e))
            })
        })
        .collect())
}
