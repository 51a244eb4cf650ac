//! `kind = "absorbing"` boundaries (explicit solver): the viscous boundary
//! of Lysmer & Kuhlemeyer (1969) on a grid face, its dashpots per unit
//! area ρ c_p (normal) and ρ c_s (tangential) from a named material.

use std::collections::BTreeMap;

use mpm_solver::explicit::absorbing::tributary_area;

use super::mesh::BuiltMesh;
use super::node_sets::NodeSets;
use super::{BuiltMaterial, SceneMesh, face_name};
use crate::SceneError;
use crate::format::{BoundaryKind, BoundarySpec, Scene, SpringSpec};
use crate::source::SceneSource;

/// One absorbing face: its nodes with their tributary areas, its normal
/// axis and the impedances of its material.
#[derive(Debug, Clone, PartialEq)]
pub struct AbsorbingFace {
    /// (node, tributary area on the face: m² in 3D, m in 2D).
    pub nodes: Vec<(usize, f64)>,
    /// The axis normal to the face.
    pub axis: usize,
    /// ρ c_p (Pa·s/m).
    pub rho_cp: f64,
    /// ρ c_s (Pa·s/m).
    pub rho_cs: f64,
    /// The spring layer's (k_n, k_t) per unit area (Pa/m; zero without
    /// `spring`).
    pub springs: (f64, f64),
}

/// The absorbing faces of `scene`'s boundaries on `mesh`, in file order
/// (`explicit`: the scene runs the explicit solver, the only one that
/// takes them).
///
/// # Errors
/// [`SceneError::Scene`] at `kind` for the implicit solver, without
/// `material`, or with a key of another kind; at `material` when no
/// material has the name or it has no Young's modulus and Poisson's ratio
/// (`modified_cam_clay`); at `set` when it is not a face of a grid; at
/// `spring` when a stiffness is negative or not finite.
pub(super) fn absorbing_faces<const D: usize>(
    scene: &Scene,
    mesh: &BuiltMesh<D>,
    sets: &NodeSets,
    material_names: &BTreeMap<String, usize>,
    materials: &[BuiltMaterial],
    explicit: bool,
    src: &SceneSource,
) -> Result<Vec<AbsorbingFace>, SceneError> {
    let specs = scene.boundaries.iter();
    specs
        .filter(|spec| *spec.kind.get_ref() == BoundaryKind::Absorbing)
        .map(|spec| {
            if !explicit {
                return Err(src.at(
                    &spec.kind,
                    "kind = absorbing needs the explicit solver ([solver] kind = \"explicit\"); the implicit solver is static",
                ));
            }
            super::conditions::refuse_displacement_keys(spec, src)?;
            let (rho_cp, rho_cs) = impedances(spec, material_names, materials, src)?;
            let springs = springs(spec, src)?;
            let SceneMesh::Grid(grid) = &mesh.mesh else {
                return Err(src.at(&spec.set, "kind = absorbing needs a face of a grid"));
            };
            let axis = (0..D)
                .find(|&i| [face_name(i, false), face_name(i, true)].contains(spec.set.get_ref()));
            let (Some(axis), Some(nodes)) = (axis, sets.sets.get(spec.set.get_ref())) else {
                return Err(src.at(
                    &spec.set,
                    format!(
                        "kind = absorbing needs a grid face for its normal ({}); `{}` is not one",
                        sets.faces.join(", "),
                        spec.set.get_ref()
                    ),
                ));
            };
            Ok(AbsorbingFace {
                nodes: (nodes.iter())
                    .map(|&n| (n, tributary_area(grid, n, axis)))
                    .collect(),
                axis,
                rho_cp,
                rho_cs,
                springs,
            })
        })
        .collect()
}

/// ρ c_p and ρ c_s of the boundary's `material`: c_p = √(M/ρ) with the
/// constrained modulus M = E(1−ν)/((1+ν)(1−2ν)), c_s = √(G/ρ).
fn impedances(
    spec: &BoundarySpec,
    material_names: &BTreeMap<String, usize>,
    materials: &[BuiltMaterial],
    src: &SceneSource,
) -> Result<(f64, f64), SceneError> {
    let Some(name) = &spec.material else {
        return Err(src.at(
            &spec.kind,
            "kind = absorbing needs `material = \"<name>\"`, the [[material]] whose density and wave speeds give the dashpots",
        ));
    };
    let index = super::lookup(material_names, name, "material", src)?;
    let m = &materials[index];
    if m.params.cam_clay.is_some() {
        return Err(src.at(
            name,
            format!(
                "material `{}` has no Young's modulus and Poisson's ratio (modified_cam_clay's elasticity follows its pressure): an absorbing boundary needs a material with constant wave speeds",
                m.name
            ),
        ));
    }
    let (e, nu, rho) = (m.params.youngs_modulus, m.params.poisson_ratio, m.density);
    let constrained = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let shear = e / (2.0 * (1.0 + nu));
    Ok(((constrained * rho).sqrt(), (shear * rho).sqrt()))
}

/// The boundary's spring layer (k_n, k_t), (0, 0) without `spring`.
fn springs(spec: &BoundarySpec, src: &SceneSource) -> Result<(f64, f64), SceneError> {
    let Some(spring) = &spec.spring else {
        return Ok((0.0, 0.0));
    };
    let SpringSpec { normal, tangential } = *spring.get_ref();
    if [normal, tangential]
        .iter()
        .all(|k| k.is_finite() && *k >= 0.0)
    {
        Ok((normal, tangential))
    } else {
        Err(src.at(
            spring,
            format!(
                "spring = {{ normal = {normal}, tangential = {tangential} }}: the stiffnesses per unit area (Pa/m) must be finite and non-negative"
            ),
        ))
    }
}
