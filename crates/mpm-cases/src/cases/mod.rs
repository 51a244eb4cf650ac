//! The benchmark cases, each with its reference solution, and their
//! registry.
//!
//! A case is one module here with a type implementing [`Case`] (its name,
//! its parameters — the scene-file keys, with defaults — and its scene)
//! and [`Solve`] (how it solves its built scene and what it measures of
//! the result against the reference). What every case does alike — build,
//! start a [`Session`]'s outputs, solve, write `summary.json` — is
//! [`Solve::run`] and the registry's run, once for all. Adding a case is that
//! module and one line of [`ALL`]; the `mpm` program lists and runs
//! whatever [`ALL`] holds.

use serde::Serialize;
use serde::de::DeserializeOwned;

use mpm_solver::{SolverError, StepReport};

use crate::CasesError;
use crate::output::CellMesh;
use crate::params::CaseParams;
use crate::run::{RunControl, RunOutput, Snapshot, StepObserver};
use crate::scene::build::SceneMesh;
use crate::scene::{Problem, Scene};
use crate::scene_file::parse_scene;
use crate::session::{Session, observer_error};
use crate::variant::Variant;
use crate::writer::RunWriter;

pub mod annulus;
pub mod cantilever;
pub mod collapse;
pub mod column;
#[cfg(test)]
mod scene_tests;
pub mod shear;
pub mod stretch;

/// A built-in case: what it is.
pub trait Case {
    /// The name `--case` and the scene key `case` use.
    const NAME: &'static str;
    /// One line on what it is and what it is checked against.
    const ABOUT: &'static str;
    /// Its parameters: every field a scene-file key with a default.
    type Params: Serialize + DeserializeOwned + Default + CaseParams;

    /// The case's scene with `params` and `variant` (with the variant the
    /// parameters name, what `mpm scene --case NAME` prints).
    ///
    /// # Errors
    /// Parameters that make no scene.
    fn scene(params: &Self::Params, variant: &Variant) -> Result<Scene, SolverError>;
}

/// A built-in case: how it solves its built scene and what it measures of
/// the result. [`Solve::run`] (the tests' and the reports' way in) and the
/// registry's run (the `mpm` program's, writing the outputs and
/// `summary.json` of a [`Session`]) do the rest, the same for every case.
pub trait Solve<const D: usize>: Case {
    /// The built scene, alone or with what the case reads off it once
    /// (the cantilever's loaded points).
    type Built: Built<D>;
    /// The run and what the case measured of it.
    type Result;

    /// Runs the built case with `run` and measures the result against
    /// the reference.
    ///
    /// # Errors
    /// Whatever the run returns.
    fn solve(p: &Self::Params, built: &Self::Built, run: Run<'_, D>) -> Solved<Self::Result>;

    /// The case's scene with `params` and `variant`, built (the same for
    /// every case; not meant to be overridden).
    ///
    /// # Errors
    /// As [`Case::scene`], the scene's own checks and [`Built::read`].
    fn build(params: &Self::Params, variant: &Variant) -> Solved<Self::Built> {
        Self::Built::read(build_scene(&Self::scene(params, variant)?, Self::NAME)?)
    }

    /// Runs the case with `params` and `variant`: its scene built and
    /// solved, `observer` seeing every converged step (the same for every
    /// case; not meant to be overridden).
    ///
    /// # Errors
    /// As [`Self::build`] and [`Self::solve`].
    fn run(
        params: &Self::Params,
        variant: &Variant,
        control: &RunControl,
        mut observer: impl FnMut(usize, &StepReport<D>, &Snapshot) -> Result<(), SolverError>,
    ) -> Solved<Self::Result> {
        let built = Self::build(params, variant)?;
        let observer: &mut StepObserver<'_, D> = &mut observer;
        Self::solve(params, &built, Run { control, observer })
    }

    /// What `summary.json` says of `result`.
    fn measured(result: &Self::Result) -> Measured<'_, D>;

    /// Readies the parameters for a run in `session` (e.g. a mesh path
    /// taken from the scene file's directory); by default, nothing.
    fn prepare(_p: &mut Self::Params, _session: &Session) {}

    /// Writes the case's own row of a converged step (the cantilever's
    /// `tip.csv`), before the session's outputs so that the step's
    /// checkpoint holds it; by default, none.
    ///
    /// # Errors
    /// The writer's.
    fn case_row<M: CellMesh<D>>(
        _p: &Self::Params,
        _built: &Self::Built,
        _writer: &mut RunWriter<D, M>,
        _report: &StepReport<D>,
        _snap: &Snapshot,
    ) -> Result<(), CasesError> {
        Ok(())
    }
}

/// What a case's run gives, or the solver's error.
pub type Solved<T> = Result<T, SolverError>;

/// How a case's run goes: its control, and the observer of every
/// converged step.
pub struct Run<'a, const D: usize> {
    /// Checkpoints, resume, tangent export.
    pub control: &'a RunControl,
    /// Sees every converged step.
    pub observer: &'a mut StepObserver<'a, D>,
}

impl<const D: usize> Run<'_, D> {
    /// Runs `problem` (see [`crate::scene::run`]).
    ///
    /// # Errors
    /// Whatever the run returns.
    pub fn on(self, problem: &Problem<D>) -> Solved<RunOutput<D>>
    where
        Problem<D>: crate::scene::RunScene<D>,
    {
        crate::scene::run(problem, self.control, self.observer)
    }
}

/// A built case: its scene's problem, alone or with what the case reads
/// off it once.
pub trait Built<const D: usize>: Sized {
    /// Reads what the case needs off its built `problem`.
    ///
    /// # Errors
    /// A problem the case cannot run.
    fn read(problem: Problem<D>) -> Result<Self, SolverError>;

    /// The scene's problem.
    fn problem(&self) -> &Problem<D>;
}

impl<const D: usize> Built<D> for Problem<D> {
    fn read(problem: Problem<D>) -> Result<Self, SolverError> {
        Ok(problem)
    }

    fn problem(&self) -> &Problem<D> {
        self
    }
}

/// What a case measured of its run, for `summary.json`.
#[derive(Debug)]
pub struct Measured<'a, const D: usize> {
    /// The run.
    pub output: &'a RunOutput<D>,
    /// Number of material points.
    pub material_points: usize,
    /// The error against the reference, if the case has one.
    pub error: Option<f64>,
    /// Further results, by name.
    pub results: serde_json::Map<String, serde_json::Value>,
}

impl<'a, const D: usize> Measured<'a, D> {
    /// The run `output` of `material_points` points with `error`, and no
    /// further results.
    pub fn new(output: &'a RunOutput<D>, material_points: usize, error: Option<f64>) -> Self {
        Self {
            output,
            material_points,
            error,
            results: serde_json::Map::new(),
        }
    }

    /// With the further results `results`, by name.
    #[must_use]
    pub fn with<const N: usize>(mut self, results: [(&str, serde_json::Value); N]) -> Self {
        self.results
            .extend(results.map(|(name, value)| (name.to_owned(), value)));
        self
    }
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
    /// The entry of case `C`, which runs in `D` dimensions.
    pub const fn of<C: Solve<D>, const D: usize>() -> Self {
        Self {
            name: C::NAME,
            about: C::ABOUT,
            defaults: defaults::<C>,
            run: run_entry::<C, D>,
            scene: scene::<C>,
        }
    }
}

fn defaults<C: Case>() -> Result<String, CasesError> {
    toml::to_string(&C::Params::default()).map_err(|source| CasesError::Toml { source })
}

fn scene<C: Case>(set: &[String]) -> Result<String, CasesError> {
    let params: C::Params = parse_scene("", "command line", set)?;
    toml::to_string(&C::scene(&params, &params.variant())?).map_err(|source| {
        CasesError::SceneToml {
            case: C::NAME,
            source,
        }
    })
}

/// Every built-in case, in the order `mpm list` shows them.
pub const ALL: [CaseEntry; 6] = [
    CaseEntry::of::<column::ColumnCase, 2>(),
    CaseEntry::of::<shear::ShearCase, 2>(),
    CaseEntry::of::<cantilever::CantileverCase, 2>(),
    CaseEntry::of::<annulus::AnnulusCase, 2>(),
    CaseEntry::of::<collapse::CollapseCase, 2>(),
    CaseEntry::of::<stretch::StretchCase, 3>(),
];

/// The registered case named `name`.
pub fn find(name: &str) -> Option<&'static CaseEntry> {
    ALL.iter().find(|c| c.name == name)
}

/// Runs case `C` in `session` with the parameters of the scene text
/// (`origin` names it in errors) and the overrides `set`: the case's own
/// preparation, its scene built with the variant the parameters name, the
/// session's outputs started on the scene's mesh.
fn run_entry<C: Solve<D>, const D: usize>(
    text: &str,
    origin: &str,
    set: &[String],
    session: &Session,
) -> Result<(), CasesError> {
    let mut p: C::Params = parse_scene(text, origin, set)?;
    C::prepare(&mut p, session);
    let built = C::build(&p, &p.variant())?;
    match &built.problem().mesh {
        SceneMesh::Grid(grid) => {
            let grid = grid.clone();
            run_on::<C, D, _>(&p, &built, session, grid)
        }
        SceneMesh::Simplex(mesh) => {
            let mesh = (**mesh).clone();
            run_on::<C, D, _>(&p, &built, session, mesh)
        }
    }
}

/// Solves the built case `C` in `session`, its outputs written on `mesh`
/// (the case's own row of a step first), and ends with the summary of
/// what the case measured.
fn run_on<C: Solve<D>, const D: usize, M: CellMesh<D>>(
    p: &C::Params,
    built: &C::Built,
    session: &Session,
    mesh: M,
) -> Result<(), CasesError> {
    let (mut obs, control) = session.start(p, mesh)?;
    let observer: &mut StepObserver<'_, D> = &mut |s, rep, snap| {
        C::case_row(p, built, &mut obs.writer, rep, snap).map_err(observer_error)?;
        obs.step(s, rep, snap)
    };
    let result = C::solve(
        p,
        built,
        Run {
            control: &control,
            observer,
        },
    )?;
    let m = C::measured(&result);
    let summary = crate::session::summary(
        C::NAME,
        p.variant(),
        m.material_points,
        m.output,
        m.error,
        m.results,
        p,
    );
    obs.finish(summary)
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

/// Builds a case's typed `scene` (named `case` in errors), with the
/// padding its solver's basis needs: a case's parameters that make no
/// valid scene are refused with the scene's message, which names the
/// case's scene (it has no file, so no line and column:
/// [`mpm_scene::source::SceneSource::typed`]).
fn build_scene<const D: usize>(scene: &Scene, case: &str) -> Result<Problem<D>, SolverError> {
    let source = mpm_scene::source::SceneSource::typed(&format!("the {case} case's scene"));
    Problem::<D>::build_in(scene, &source, 0, std::path::Path::new(""))
        .map_err(|e| SolverError::InvalidInput(format!("case {case}: {e}")))
}
