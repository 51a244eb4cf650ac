//! Scenes as data: the TOML format of a whole problem — mesh, materials,
//! bodies, node sets, boundary conditions, loads with load curves, solver
//! and outputs — its validation, and the build of the [`Problem`] it
//! describes.
//!
//! [`format`] is what the file deserialises into (unknown keys refused);
//! [`source`] parses it with its `--set` overrides and keeps every key's
//! place in the file; [`build`] checks it across sections and builds the
//! grid, points, conditions and loads, every error naming its place in the
//! file or the override it comes from; [`typed`] writes a scene in Rust
//! instead (the built-in cases), which builds the same way. The names a scene chooses by —
//! the variant ([`variant`]) and the registered laws ([`material`]) — live
//! here too; running a problem is the `mpm-dispatch` crate's concern. The
//! key-by-key reference is the guide page `docs/src/guide/scenes.md`.

pub mod body;
pub mod build;
mod error;
pub mod format;
pub mod manufactured;
pub mod material;
pub mod region;
pub use variant::rules;
pub mod source;
pub mod typed;
pub mod variant;

pub use build::{
    ContactSetup, ExplicitSetup, Problem, ReactionOutput, SceneConstraints, SceneMotion,
    TimedForces,
};
pub use error::SceneError;
pub use format::Scene;

use source::{SceneSource, parse_scene_located};

/// Parses scene `text` (named `origin` in errors) with `--set` overrides.
///
/// # Errors
/// As [`crate::source::parse_scene`].
pub fn parse(
    text: &str,
    origin: &str,
    overrides: &[String],
) -> Result<(Scene, SceneSource), SceneError> {
    parse_scene_located(text, origin, overrides)
}

/// The dimension of a scene: the length of its grid (or simplex box)
/// origin, or the
/// `dimension` of its Gmsh mesh, if 2 or 3.
///
/// # Errors
/// [`SceneError::Scene`] at the origin or dimension otherwise,
/// [`SceneError::SceneUnlocated`] when the mesh gives neither.
pub fn dimension(scene: &Scene, source: &SceneSource) -> Result<usize, SceneError> {
    let m = &scene.mesh;
    let (d, at) = match (m.kind, &m.origin, &m.dimension) {
        (format::MeshKind::Annulus, _, _) => return Ok(2),
        (format::MeshKind::Grid | format::MeshKind::Simplex, Some(origin), _) => {
            (origin.get_ref().len(), origin.span())
        }
        (format::MeshKind::Gmsh, _, Some(d)) => (*d.get_ref(), d.span()),
        (format::MeshKind::Grid | format::MeshKind::Simplex, None, _) => {
            return Err(source.error(
                None,
                "[mesh]: a grid or simplex box needs `origin`, `size` and `cells` or `spacing`",
            ));
        }
        (format::MeshKind::Gmsh, _, None) => {
            return Err(source.error(None, "[mesh]: a Gmsh mesh needs `file` and `dimension`"));
        }
    };
    match d {
        2 | 3 => Ok(d),
        _ => Err(source.error(
            Some(at),
            &format!("the mesh has dimension {d}; scenes are 2D or 3D"),
        )),
    }
}
