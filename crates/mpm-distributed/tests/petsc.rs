//! PETSc as the implicit solver's linear solver on one rank
//! (`linear = { petsc = "..." }`), against the built-in direct solver on
//! committed scenes: the same Newton iterations in every step and the same
//! converged state. Runs with `--features petsc` (README, "Distributed
//! runs").
#![cfg(feature = "petsc")]
#![allow(missing_docs, clippy::unwrap_used)]

use std::path::Path;

use mpm_dispatch::run::{RunControl, RunOutput};
use mpm_scene::{self as scene, Problem};

/// The committed scene `name` with `overrides`, built.
fn problem<const D: usize>(name: &str, overrides: &[String]) -> Problem<D> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let (scene, src) = scene::parse(&text, &path.to_string_lossy(), overrides).unwrap();
    Problem::<D>::build(&scene, &src, scene.solver.padding()).unwrap()
}

/// The run control of an `mpm` built with PETSc.
fn control() -> RunControl {
    RunControl {
        external_linear: mpm_distributed::external_linear(),
        ..RunControl::default()
    }
}

fn run<const D: usize>(problem: &Problem<D>) -> RunOutput<D>
where
    Problem<D>: mpm_dispatch::implicit::RunScene<D>,
{
    mpm_dispatch::implicit::run(problem, &control(), |_, _, _| Ok(())).unwrap()
}

/// Runs scene `name` with the direct solver and with PETSc's `options`
/// (relative tolerance 1e-13, so each Krylov solve is as good as a direct
/// one well below the Newton tolerance), `overrides` on both: the same
/// Newton iterations per step, and displacements within 10 × the Newton
/// tolerance of the largest (both runs converge below that tolerance and
/// differ only by their last inexact corrections).
fn assert_petsc_matches_direct<const D: usize>(name: &str, options: &str, overrides: &[&str])
where
    Problem<D>: mpm_dispatch::implicit::RunScene<D>,
{
    let linear = format!("solver.linear={{ petsc = \"{options}\" }}");
    let with = |extra: &[&str]| -> Vec<String> {
        overrides
            .iter()
            .chain(extra)
            .map(|s| (*s).to_owned())
            .collect()
    };
    let direct_problem = problem::<D>(name, &with(&["solver.linear=direct"][..]));
    let tolerance = direct_problem.newton.tolerance;
    let direct = run(&direct_problem);
    let petsc = run(&problem::<D>(
        name,
        &with(&[linear.as_str(), "solver.linear_tolerance=1e-13"][..]),
    ));
    let iterations = |r: &RunOutput<D>| {
        r.reports
            .iter()
            .map(|s| s.residuals.len())
            .collect::<Vec<_>>()
    };
    assert_eq!(
        iterations(&petsc),
        iterations(&direct),
        "{name}, {options}: Newton iterations per step"
    );
    let largest = direct
        .last
        .displacement
        .iter()
        .flatten()
        .fold(0.0f64, |a, u| a.max(u.abs()));
    let diff = petsc
        .last
        .displacement
        .iter()
        .flatten()
        .zip(direct.last.displacement.iter().flatten())
        .fold(0.0f64, |a, (p, d)| a.max((p - d).abs()));
    assert!(largest > 0.0);
    assert!(
        diff <= 10.0 * tolerance * largest,
        "{name}, {options}: |Δu| {diff:.3e} of {largest:.3e} (Newton tolerance {tolerance:.0e})"
    );
}

/// Symmetric elasticity on tetrahedra from Gmsh, CG with GAMG given the
/// rigid-body modes.
#[test]
fn gmsh_cube_with_cg_and_gamg_matches_the_direct_solver() {
    assert_petsc_matches_direct::<3>("cube_gmsh.toml", "-ksp_type cg -pc_type gamg", &[]);
}

/// Von Mises yielding in a slope (two materials, a traction curve), GMRES
/// with ILU.
#[test]
fn plastic_slope_with_gmres_matches_the_direct_solver() {
    assert_petsc_matches_direct::<2>(
        "slope.toml",
        "-ksp_type gmres -ksp_gmres_restart 200 -pc_type ilu",
        &[],
    );
}

/// An unsymmetric tangent (F-patch on the double-notched plate, von
/// Mises), GMRES with block Jacobi: Newton keeps its iteration count.
#[test]
fn fpatch_plate_with_gmres_matches_the_direct_solver() {
    assert_petsc_matches_direct::<3>(
        "wang2021_notched_plate.toml",
        "-ksp_type gmres -ksp_gmres_restart 300 -pc_type bjacobi -sub_pc_type ilu",
        &["solver.locking=fpatch", "solver.steps=8"],
    );
}

/// A misspelt preconditioner stops the run with PETSc's message, naming
/// the type it does not know.
#[test]
fn unknown_preconditioner_stops_the_run_with_petscs_message() {
    let p = problem::<2>(
        "slope.toml",
        &["solver.linear={ petsc = \"-pc_type gammg\" }".to_owned()],
    );
    let e = mpm_dispatch::implicit::run(&p, &control(), |_, _, _| Ok(())).unwrap_err();
    assert!(e.to_string().contains("gammg"), "{e}");
}

/// A misspelt option that PETSc accepts but no object reads stops the run
/// at the first solve with the option's name, as a configuration error:
/// no load step is cut for it (a smaller increment cannot help).
#[test]
fn unused_option_stops_the_run_without_cutting_a_step() {
    let p = problem::<2>(
        "slope.toml",
        &["solver.linear={ petsc = \"-ksp_type gmres -pc_typ jacobi\" }".to_owned()],
    );
    let mut observed = 0;
    let e = mpm_dispatch::implicit::run(&p, &control(), |_, _, _| {
        observed += 1;
        Ok(())
    })
    .unwrap_err();
    // In the first step, with the first load increment (no cut).
    let first_try = match &e {
        mpm_solver::SolverError::InStep {
            step: 0,
            load_factor,
            target,
            source,
        } if *load_factor == 0.0 && *target == 0.05 => Some(source.as_ref()),
        _ => None,
    };
    assert!(
        matches!(
            first_try,
            Some(mpm_solver::SolverError::LinearConfiguration(
                mpm_solver::LinearSolveError::Configuration { .. }
            ))
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("-pc_typ"), "{e}");
    assert_eq!(observed, 0, "no step may converge before the error");
}
