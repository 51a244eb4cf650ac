//! Runs a built [`Problem`] with the variant and materials it names: the
//! variant and the law are dispatched to a fully monomorphised solver (a
//! scene of one material runs its law directly; several run a
//! `MaterialSet` whose history carries each point's material).

use std::sync::Arc;

use mpm_basis::LinearSimplex;
use mpm_constitutive::LogStrainLaw;
use mpm_mesh::RegularGrid;
use mpm_solver::{
    BodyForcePath, DomainUpdater, FBar, FPatch, Flat, Formulation, LockingTreatment,
    MaterialPoints, MovableMesh, NoLocking, NoUpdate, PreviouslyConverged, SolverError, StepReport,
    UpdatedLagrangian,
};
use nalgebra::SVector;

use crate::body::InitialDomain;
use crate::material::{LawVisitor, MaterialTag, dispatch_law, dispatch_law_set};
use crate::run::{
    Analysis, DomainBounds, HistoryOutput, RunControl, RunOutput, Snapshot, StepObserver,
    simulate_points,
};
use crate::variant::{FormulationKind, LockingKind, VariantVisitor, dispatch};

use super::build::{Problem, SceneMesh};

/// Runs `problem`; `observer` sees every converged step.
///
/// The solvers behind a scene (every variant × law × locking treatment)
/// are compiled once per dimension, in this crate, through
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

/// [`run`] in dimension `D`: dispatches the variant and the law.
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
    match &problem.mesh {
        SceneMesh::Grid(grid) => dispatch(
            &problem.variant,
            WithVariant {
                problem,
                mesh: grid,
                control,
                observer,
            },
        )
        .map_err(SolverError::InvalidInput)?,
        SceneMesh::Simplex(mesh) => {
            problem
                .variant
                .require_simplex("a simplex mesh", problem.patch_of_element.is_some())
                .map_err(SolverError::InvalidInput)?;
            let run = WithVariant {
                problem,
                mesh: &**mesh,
                control,
                observer,
            };
            let (pc, patches) = (
                problem.variant.formulation == FormulationKind::Pc,
                problem.patch_of_element.as_ref(),
            );
            match (problem.variant.locking, patches) {
                (LockingKind::FPatch, Some(map)) => {
                    let fpatch = FPatch::from_patch_map(map.clone());
                    if pc {
                        run.with::<LinearSimplex, PreviouslyConverged, _, _>(
                            LinearSimplex,
                            NoUpdate,
                            fpatch,
                        )
                    } else {
                        run.with::<LinearSimplex, UpdatedLagrangian, _, _>(
                            LinearSimplex,
                            NoUpdate,
                            fpatch,
                        )
                    }
                }
                _ if pc => run.with::<LinearSimplex, PreviouslyConverged, _, _>(
                    LinearSimplex,
                    NoUpdate,
                    NoLocking,
                ),
                _ => run.with::<LinearSimplex, UpdatedLagrangian, _, _>(
                    LinearSimplex,
                    NoUpdate,
                    NoLocking,
                ),
            }
        }
    }
}

struct WithVariant<'a, 'o, const D: usize, M> {
    problem: &'a Problem<D>,
    mesh: &'a M,
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
        match self.problem.variant.locking {
            // `dispatch` lets F-bar through with domain_update = none only.
            LockingKind::FBar => self.with::<B, F, NoUpdate, _>(basis, NoUpdate, FBar::default()),
            _ => self.with::<B, F, U, _>(basis, updater, NoLocking),
        }
    }
}

impl<const D: usize, M> WithVariant<'_, '_, D, M>
where
    M: MovableMesh<D> + Clone,
{
    /// Runs with basis `B` (on mesh `M`), formulation `F`, updater `U`,
    /// locking treatment `K` and the scene's materials.
    fn with<B, F, U, K>(self, basis: B, updater: U, locking: K) -> Result<RunOutput<D>, SolverError>
    where
        B: InitialDomain<D, Mesh = M, Domain: Flat + DomainBounds<D>>,
        F: Formulation,
        U: DomainUpdater<D, B::Domain>,
        K: LockingTreatment<D, M>,
    {
        let materials = &self.problem.materials;
        let model = materials[0].model;
        let with_law = WithLaw::<D, M, B, F, U, K> {
            run: self,
            basis,
            updater,
            locking,
            formulation: std::marker::PhantomData,
        };
        if materials.len() == 1 {
            dispatch_law(model, &materials[0].params, with_law)?
        } else {
            let params: Vec<_> = materials.iter().map(|m| m.params).collect();
            dispatch_law_set(model, &params, with_law)?
        }
    }
}

struct WithLaw<'a, 'o, const D: usize, M, B, F, U, K> {
    run: WithVariant<'a, 'o, D, M>,
    basis: B,
    updater: U,
    locking: K,
    formulation: std::marker::PhantomData<F>,
}

impl<const D: usize, M, B, F, U, K> LawVisitor for WithLaw<'_, '_, D, M, B, F, U, K>
where
    M: MovableMesh<D> + Clone,
    B: InitialDomain<D, Mesh = M, Domain: Flat + DomainBounds<D>>,
    F: Formulation,
    U: DomainUpdater<D, B::Domain>,
    K: LockingTreatment<D, M>,
{
    type Output = Result<RunOutput<D>, SolverError>;

    fn visit<L>(self, law: L) -> Self::Output
    where
        L: LogStrainLaw,
        L::History: HistoryOutput + Flat + MaterialTag,
    {
        let p = self.run.problem;
        let domains = p
            .position
            .iter()
            .zip(&p.half_lengths)
            .map(|(x, l)| B::initial_domain(x, l))
            .collect();
        let mut points: MaterialPoints<D, L::History, B::Domain> =
            MaterialPoints::new(p.position.clone(), p.volume.clone(), 0.0, domains)?;
        points.mass.clone_from(&p.mass);
        if p.materials.len() > 1 {
            points.history = p
                .material_of_point
                .iter()
                .map(|&m| L::History::for_material(m))
                .collect();
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
        let analysis = Analysis {
            grid: self.run.mesh.clone(),
            law,
            constraints: p.constraints.clone(),
            stepping: p.stepping,
            newton: p.newton,
        };
        simulate_points::<D, B, F, U, K, L, _>(
            points,
            analysis,
            self.basis,
            self.updater,
            self.locking,
            self.run.control,
            self.run.observer,
        )
    }
}
