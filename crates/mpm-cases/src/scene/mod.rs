//! Scenes as data: a whole problem — mesh, materials, bodies, node sets,
//! boundary conditions, loads with load curves, solver and outputs — in
//! one TOML file, run without writing Rust.
//!
//! [`format`] is what the file deserialises into (unknown keys refused);
//! [`build`] checks it across sections and builds the grid, points,
//! conditions and loads, every error naming its place in the file or the
//! `--set` override it comes from; [`run`] runs the result with the
//! variant and materials it names. The key-by-key reference is the guide
//! page `docs/src/guide/scenes.md`.
//!
//! ```
//! use mpm_cases::scene::{self, Problem};
//! use mpm_cases::run::RunControl;
//!
//! let text = r#"
//! [mesh]
//! origin = [0.0, 0.0]
//! size = [1.0, 10.0]
//! cells = [1, 4]
//!
//! [[material]]
//! name = "soil"
//! model = "hencky"
//! youngs_modulus = 1e6
//! poisson_ratio = 0.0
//! density = 80.0
//!
//! [[body]]
//! name = "column"
//! material = "soil"
//! region = { box = { lower = [0.0, 0.0], upper = [1.0, 10.0] } }
//!
//! [[boundary]]
//! set = "y_min"
//! kind = "fixed"
//!
//! [[boundary]]
//! set = "x_min"
//! kind = "roller"
//!
//! [[boundary]]
//! set = "x_max"
//! kind = "roller"
//!
//! [[load]]
//! kind = "gravity"
//! acceleration = [0.0, -10.0]
//! "#;
//! let (scene, source) = scene::parse(text, "column.toml", &[])?;
//! let problem = Problem::<2>::build(&scene, &source, scene.solver.padding())?;
//! let out = scene::run(&problem, &RunControl::default(), |_, _, _| Ok(()))?;
//! // The base carries the weight: 80 kg/m³ × 10 m/s² × 10 m².
//! let reaction = out.reports.last().unwrap().reaction;
//! assert!((reaction[1] - 8000.0).abs() < 1e-6 * 8000.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod build;
pub mod explicit;
pub mod explicit_law;
pub mod format;
pub mod png;
mod program;
pub mod region;
mod runner;

pub use build::{
    ExplicitSetup, Problem, ReactionOutput, SceneConstraints, SceneMotion, TimedForces,
};
pub use explicit::{
    ExplicitEvent, ExplicitFrame, ExplicitObserver, ExplicitOutput, RunExplicit, run_explicit,
};
pub use format::Scene;
pub use program::run_file;
pub use runner::{RunScene, run};

use crate::CasesError;
use crate::scene_file::{SceneSource, parse_scene_located};

/// Parses scene `text` (named `origin` in errors) with `--set` overrides.
///
/// # Errors
/// As [`crate::scene_file::parse_scene`].
pub fn parse(
    text: &str,
    origin: &str,
    overrides: &[String],
) -> Result<(Scene, SceneSource), CasesError> {
    parse_scene_located(text, origin, overrides)
}

/// The dimension of a scene: the length of its grid (or simplex box)
/// origin, or the
/// `dimension` of its Gmsh mesh, if 2 or 3.
///
/// # Errors
/// [`CasesError::Scene`] at the origin or dimension otherwise,
/// [`CasesError::SceneUnlocated`] when the mesh gives neither.
pub fn dimension(scene: &Scene, source: &SceneSource) -> Result<usize, CasesError> {
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
