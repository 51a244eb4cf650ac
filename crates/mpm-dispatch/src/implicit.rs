//! Runs a built [`Problem`] with the variant and materials it names.
//!
//! What runs per point and per node is compiled for each dimension, basis
//! and formulation; everything else is a value chosen here at run time:
//! the materials (one [`SceneLaws`], the law chosen per point), the GIMP
//! domain rule and volume convention (`mpm_solver::AnyGimpRule`) and the
//! locking treatment (`Option<FBar>`, `Option<FPatch>`, chosen per stage).

use std::sync::Arc;

use mpm_basis::LinearSimplex;
use mpm_constitutive::Tagged;
use mpm_mesh::RegularGrid;
use mpm_solver::{
    BodyForcePath, DomainUpdater, FBar, FPatch, Flat, Formulation, LockingTreatment,
    MaterialPoints, MovableMesh, NoUpdate, PreviouslyConverged, SolverError, StepReport,
    UpdatedLagrangian,
};
use nalgebra::SVector;

use crate::run::{
    Analysis, DomainBounds, RunControl, RunOutput, Snapshot, StepObserver, simulate_points,
};
use mpm_scene::body::InitialDomain;
use mpm_scene::material::{SceneHistory, SceneLaws, scene_laws};
use mpm_scene::variant::{FormulationKind, LockingKind, VariantVisitor, dispatch};

use mpm_scene::build::{Problem, SceneMesh};

/// Runs `problem`; `observer` sees every converged step.
///
/// The solvers behind a scene (one per basis and formulation) are
/// compiled once per dimension, in this crate, through
/// [`RunScene`]: a caller's closure reaches them as a
/// [`StepObserver`] trait object, so neither this crate's cases nor a
/// downstream binary compiles the matrix again.
///
/// # Errors
/// [`SolverError::InvalidInput`] for a variant that does not exist (e.g.
/// a domain update with a basis without domains), and whatever the run
/// returns.
pub fn run<const D: usize, O>(
    problem: &Problem<D>,
    control: &RunControl,
    mut observer: O,
) -> Result<RunOutput<D>, SolverError>
where
    Problem<D>: RunScene<D>,
    O: FnMut(usize, &StepReport<D>, &Snapshot) -> Result<(), SolverError>,
{
    problem.run_scene(control, &mut observer)
}

/// A scene problem that runs: implemented for two and three dimensions,
/// each implementation the one place where that dimension's solvers are
/// monomorphised.
pub trait RunScene<const D: usize> {
    /// Runs the problem; `observer` sees every converged step.
    ///
    /// # Errors
    /// As [`run`].
    fn run_scene(
        &self,
        control: &RunControl,
        observer: &mut StepObserver<'_, D>,
    ) -> Result<RunOutput<D>, SolverError>;
}

/// The two dimensions' implementations, each compiled once, here.
macro_rules! run_scene_in {
    ($($d:literal),*) => {$(
        impl RunScene<$d> for Problem<$d> {
            #[inline(never)]
            fn run_scene(
                &self,
                control: &RunControl,
                observer: &mut StepObserver<'_, $d>,
            ) -> Result<RunOutput<$d>, SolverError> {
                run_in(self, control, observer)
            }
        }
    )*};
}

run_scene_in!(2, 3);

/// [`run`] in dimension `D`: the scene's laws, then its variant.
fn run_in<const D: usize>(
    problem: &Problem<D>,
    control: &RunControl,
    observer: &mut StepObserver<'_, D>,
) -> Result<RunOutput<D>, SolverError> {
    if problem.explicit.is_some() {
        return Err(SolverError::InvalidInput(
            "the scene's solver is explicit: run it with scene::run_explicit".into(),
        ));
    }
    let materials: Vec<_> = (problem.materials.iter())
        .map(|m| (m.model, m.params))
        .collect();
    let laws = scene_laws(&materials)?;
    match &problem.mesh {
        SceneMesh::Grid(grid) => dispatch(
            &problem.variant,
            WithVariant {
                problem,
                mesh: grid,
                laws,
                control,
                observer,
            },
        )
        .map_err(SolverError::InvalidInput)?,
        SceneMesh::Simplex(mesh) => {
            let patches = problem.patch_of_element.as_ref();
            problem
                .variant
                .require_simplex("a simplex mesh", patches.is_some())
                .map_err(SolverError::InvalidInput)?;
            let run = WithVariant {
                problem,
                mesh: &**mesh,
                laws,
                control,
                observer,
            };
            // `require_simplex` lets F-patch through with patches only.
            let locking = patches
                .filter(|_| problem.variant.locking == LockingKind::FPatch)
                .map(|map| FPatch::from_patch_map(map.clone()));
            match problem.variant.formulation {
                FormulationKind::Pc => run.with::<LinearSimplex, PreviouslyConverged, _, _>(
                    LinearSimplex,
                    NoUpdate,
                    locking,
                ),
                FormulationKind::Ul => run.with::<LinearSimplex, UpdatedLagrangian, _, _>(
                    LinearSimplex,
                    NoUpdate,
                    locking,
                ),
            }
        }
    }
}

struct WithVariant<'a, 'o, const D: usize, M> {
    problem: &'a Problem<D>,
    mesh: &'a M,
    laws: SceneLaws,
    control: &'a RunControl,
    observer: &'a mut StepObserver<'o, D>,
}

impl<const D: usize> VariantVisitor<D> for WithVariant<'_, '_, D, RegularGrid<D>> {
    type Output = Result<RunOutput<D>, SolverError>;

    fn visit<B, F, U>(self, basis: B, updater: U) -> Self::Output
    where
        B: InitialDomain<D, Mesh = RegularGrid<D>, Domain: Flat + DomainBounds<D>>,
        F: Formulation,
        U: DomainUpdater<D, B::Domain>,
    {
        // `dispatch` lets F-bar through with domain_update = none only;
        // the updater still carries the GIMP volume convention.
        let locking = (self.problem.variant.locking == LockingKind::FBar).then(FBar::default);
        self.with::<B, F, U, _>(basis, updater, locking)
    }
}

impl<const D: usize, M> WithVariant<'_, '_, D, M>
where
    M: MovableMesh<D> + Clone,
{
    /// Runs with basis `B` (on mesh `M`), formulation `F`, updater `U`,
    /// locking treatment `K` and the scene's laws.
    fn with<B, F, U, K>(self, basis: B, updater: U, locking: K) -> Result<RunOutput<D>, SolverError>
    where
        B: InitialDomain<D, Mesh = M, Domain: Flat + DomainBounds<D>>,
        F: Formulation,
        U: DomainUpdater<D, B::Domain>,
        K: LockingTreatment<D, M>,
    {
        let points = initial_points::<D, B>(self.problem, &self.laws)?;
        let p = self.problem;
        let analysis = Analysis {
            grid: self.mesh.clone(),
            law: self.laws,
            constraints: p.constraints.clone(),
            stepping: p.stepping,
            newton: p.newton,
            petsc: p.petsc.clone(),
        };
        simulate_points::<D, B, F, U, K, SceneLaws, _>(
            points,
            analysis,
            basis,
            updater,
            locking,
            self.control,
            self.observer,
        )
    }
}

/// The scene's material points for basis `B`, each point's history its
/// material's law's initial history, tagged with the material.
fn initial_points<const D: usize, B>(
    p: &Problem<D>,
    laws: &SceneLaws,
) -> Result<MaterialPoints<D, Tagged<SceneHistory>, B::Domain>, SolverError>
where
    B: InitialDomain<D>,
{
    let domains = p
        .position
        .iter()
        .zip(&p.half_lengths)
        .map(|(x, l)| B::initial_domain(x, l))
        .collect();
    let mut points = MaterialPoints::new(p.position.clone(), p.volume.clone(), 0.0, domains)?;
    points.mass.clone_from(&p.mass);
    for (k, h) in points.history.iter_mut().enumerate() {
        let m = p.material_of_point.get(k).copied().unwrap_or(0);
        let law = laws.laws().get(m as usize).ok_or_else(|| {
            SolverError::InvalidInput(format!(
                "point {k} is of material {m}, the scene has {}",
                laws.laws().len()
            ))
        })?;
        let history = p.initial_history.get(k).copied();
        *h = Tagged::new(m, history.unwrap_or_else(|| law.initial_history()));
    }
    if !p.initial_be.is_empty() {
        points.be.clone_from(&p.initial_be);
    }
    points.body_force.clone_from(&p.body_force);
    points.point_force.clone_from(&p.point_forces);
    if !p.curved.is_empty() || !p.manufactured.is_empty() {
        let curved = Arc::new(p.curved.clone());
        let manufactured = p.manufactured.clone();
        points.body_force_path = Some(BodyForcePath(Arc::new(move |point, lambda| {
            let f = curved.iter().fold(SVector::<f64, D>::zeros(), |f, c| {
                f + c.force[point] * c.curve.at(lambda)
            });
            manufactured.iter().fold(f, |f, m| f + (m.0)(point, lambda))
        })));
    }
    Ok(points)
}
