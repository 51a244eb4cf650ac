//! The benchmark cases, each with its reference solution, and their
//! registry.
//!
//! A case is one module here with a type implementing [`Case`]: its name,
//! its parameters (the scene-file keys, with defaults) and how it runs in
//! a [`Session`] — build, solve, measure against the reference, write
//! `summary.json`. Adding a case is that module and one line of [`ALL`];
//! the `mpm` program lists and runs whatever [`ALL`] holds.

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::CasesError;
use crate::scene_file::parse_scene;
use crate::session::Session;

pub mod annulus;
pub mod cantilever;
pub mod collapse;
pub mod column;
#[cfg(test)]
mod scene_tests;
pub mod shear;
pub mod stretch;

/// A built-in case.
pub trait Case {
    /// The name `--case` and the scene key `case` use.
    const NAME: &'static str;
    /// One line on what it is and what it is checked against.
    const ABOUT: &'static str;
    /// Its parameters: every field a scene-file key with a default.
    type Params: Serialize + DeserializeOwned + Default;

    /// The case's scene with `params` and the variant they name (what
    /// `mpm scene --case NAME` prints).
    ///
    /// # Errors
    /// Parameters that make no scene.
    fn scene(params: &Self::Params) -> Result<crate::scene::Scene, mpm_solver::SolverError>;

    /// Runs the case with `params` in `session`, writing its outputs and
    /// `summary.json` (its error against the reference and its results).
    ///
    /// # Errors
    /// Invalid parameters, solver failures, output errors.
    fn run(params: Self::Params, session: &Session) -> Result<(), CasesError>;
}

/// A registered case, without its types: what the `mpm` program needs.
#[derive(Debug, Clone, Copy)]
pub struct CaseEntry {
    /// [`Case::NAME`].
    pub name: &'static str,
    /// [`Case::ABOUT`].
    pub about: &'static str,
    /// The default parameters, as TOML.
    pub defaults: fn() -> Result<String, CasesError>,
    /// Parses the scene text (`origin` names it in errors), applies the
    /// overrides and runs.
    pub run:
        fn(text: &str, origin: &str, set: &[String], session: &Session) -> Result<(), CasesError>,
    /// The case's scene with the default parameters and the overrides, as
    /// the text of a scene file.
    pub scene: fn(set: &[String]) -> Result<String, CasesError>,
}

impl CaseEntry {
    /// The entry of case `C`.
    pub const fn of<C: Case>() -> Self {
        Self {
            name: C::NAME,
            about: C::ABOUT,
            defaults: defaults::<C>,
            run: run::<C>,
            scene: scene::<C>,
        }
    }
}

fn defaults<C: Case>() -> Result<String, CasesError> {
    toml::to_string(&C::Params::default()).map_err(|source| CasesError::Toml { source })
}

fn run<C: Case>(
    text: &str,
    origin: &str,
    set: &[String],
    session: &Session,
) -> Result<(), CasesError> {
    C::run(parse_scene(text, origin, set)?, session)
}

fn scene<C: Case>(set: &[String]) -> Result<String, CasesError> {
    let params: C::Params = parse_scene("", "command line", set)?;
    toml::to_string(&C::scene(&params)?).map_err(|source| CasesError::SceneToml {
        case: C::NAME,
        source,
    })
}

/// Every built-in case, in the order `mpm list` shows them.
pub const ALL: [CaseEntry; 6] = [
    CaseEntry::of::<column::ColumnCase>(),
    CaseEntry::of::<shear::ShearCase>(),
    CaseEntry::of::<cantilever::CantileverCase>(),
    CaseEntry::of::<annulus::AnnulusCase>(),
    CaseEntry::of::<collapse::CollapseCase>(),
    CaseEntry::of::<stretch::StretchCase>(),
];

/// The registered case named `name`.
pub fn find(name: &str) -> Option<&'static CaseEntry> {
    ALL.iter().find(|c| c.name == name)
}

/// What a case measured of its run, for `summary.json`.
pub(crate) struct Measured<'a, const D: usize> {
    /// The run.
    pub output: &'a crate::run::RunOutput<D>,
    /// Number of material points.
    pub material_points: usize,
    /// The error against the reference, if the case has one.
    pub error: Option<f64>,
    /// Further results, by name.
    pub results: serde_json::Map<String, serde_json::Value>,
}

/// The part of [`Case::run`] every case shares: start the session's
/// outputs on `mesh`, `run` with its control and observer, and finish with
/// the summary of what `measure` reads off the result.
///
/// # Errors
/// The session's, the run's and the outputs' errors.
pub(crate) fn run_in_session<const D: usize, M, P, R>(
    case: &str,
    p: &P,
    variant: crate::variant::Variant,
    session: &Session,
    mesh: M,
    run: impl FnOnce(
        &crate::run::RunControl,
        &mut crate::session::Observer<D, M>,
    ) -> Result<R, mpm_solver::SolverError>,
    measure: impl FnOnce(&R) -> Measured<'_, D>,
) -> Result<(), CasesError>
where
    M: crate::output::CellMesh<D>,
    P: Serialize,
{
    let (mut observer, control) = session.start(p, mesh)?;
    let result = run(&control, &mut observer)?;
    let m = measure(&result);
    let summary = crate::session::summary(
        case,
        variant,
        m.material_points,
        m.output,
        m.error,
        m.results,
        p,
    );
    observer.finish(summary)
}

/// The regular grid of a case's problem, or `what` (e.g. "the column runs
/// on a grid") when the scene built another mesh.
pub(crate) fn grid_of<const D: usize>(
    problem: &crate::scene::Problem<D>,
    what: &str,
) -> Result<mpm_mesh::RegularGrid<D>, mpm_solver::SolverError> {
    match &problem.mesh {
        crate::scene::build::SceneMesh::Grid(grid) => Ok(grid.clone()),
        crate::scene::build::SceneMesh::Simplex(_) => {
            Err(mpm_solver::SolverError::InvalidInput(what.into()))
        }
    }
}

/// The simplex mesh of a case's problem, or `what` when the scene built a
/// grid.
pub(crate) fn simplices_of<const D: usize>(
    problem: &crate::scene::Problem<D>,
    what: &str,
) -> Result<mpm_mesh::SimplexMesh<D>, mpm_solver::SolverError> {
    match &problem.mesh {
        crate::scene::build::SceneMesh::Simplex(mesh) => Ok((**mesh).clone()),
        crate::scene::build::SceneMesh::Grid(_) => {
            Err(mpm_solver::SolverError::InvalidInput(what.into()))
        }
    }
}

/// The number of cells of size `h` along `length` (`what`, e.g. "the
/// column height"), which `h` must divide.
///
/// # Errors
/// [`mpm_solver::SolverError::InvalidInput`] when it does not (to 1e-9
/// relative), or gives no cell.
pub(crate) fn cells_along(
    h: f64,
    length: f64,
    what: &str,
) -> Result<usize, mpm_solver::SolverError> {
    let n = (length / h).round();
    if n.is_nan() || n < 1.0 || (n * h - length).abs() > 1e-9 * length {
        return Err(mpm_solver::SolverError::InvalidInput(format!(
            "h = {h} must divide {what} {length}"
        )));
    }
    Ok(n as usize)
}

/// The scene of one body of `material`, named as the material, filling
/// the box from the origin to `upper` with `points_per_cell` per axis on
/// the grid `mesh` (the column's and the collapse's).
pub(crate) fn one_block(
    mesh: crate::scene::format::MeshSpec,
    material: crate::scene::format::MaterialSpec,
    upper: [f64; 2],
    points_per_cell: usize,
) -> crate::scene::Scene {
    let name = material.name.get_ref().clone();
    let body =
        crate::scene::format::BodySpec::block(&name, &name, [0.0, 0.0], upper, points_per_cell);
    crate::scene::Scene::new(mesh, vec![material], vec![body])
}

/// Builds a case's typed `scene` (named `case` in errors): a case's
/// parameters that make no valid scene are refused with the scene's
/// message, which names the case's scene (it has no file, so no line and
/// column: [`mpm_scene::source::SceneSource::typed`]).
pub(crate) fn build_scene<const D: usize>(
    scene: &crate::scene::Scene,
    case: &str,
    padding: usize,
) -> Result<crate::scene::Problem<D>, mpm_solver::SolverError> {
    let source = mpm_scene::source::SceneSource::typed(&format!("the {case} case's scene"));
    crate::scene::Problem::<D>::build_in(scene, &source, padding, std::path::Path::new(""))
        .map_err(|e| mpm_solver::SolverError::InvalidInput(format!("case {case}: {e}")))
}
