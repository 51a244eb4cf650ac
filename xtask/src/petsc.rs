//! `linear-petsc [--full]`: the full vane of Wang et al. (2021) §5.6 with
//! F-patch (an unsymmetric stiffness of 139,425 free dofs at the paper's
//! scale), its linear solves by our ILU(0)-preconditioned BiCGSTAB and by
//! PETSc's Krylov methods with algebraic multigrid (GAMG given the
//! rigid-body modes, hypre's BoomerAMG) and block Jacobi, one after the
//! other in one process: the solve time per Newton iteration, the Krylov
//! iterations per solve, the Newton iterations (which must not change),
//! the wall time, the peak memory and the torque. Written to
//! `docs/src/benchmarks/petsc.md`. Needs xtask built with PETSc:
//! `cargo run --release -p xtask --features petsc -- linear-petsc`.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use anyhow::{Result, bail};

use crate::machine;
use crate::markdown::Table;
use crate::scene_run::Run;
use crate::vane;

/// The solvers compared: a label and the `solver.linear` override.
const SOLVERS: [(&str, &str); 5] = [
    ("ours: ILU(0) + BiCGSTAB (faer)", "\"iterative\""),
    (
        "PETSc: BiCGSTAB + GAMG (interpolation reused in a step)",
        "{ petsc = \"-ksp_type bcgs -pc_type gamg -pc_gamg_reuse_interpolation true\" }",
    ),
    (
        "PETSc: BiCGSTAB + GAMG (unsmoothed aggregation, preconditioner kept through a step)",
        "{ petsc = \"-ksp_type bcgs -pc_type gamg -pc_gamg_agg_nsmooths 0 -ksp_reuse_preconditioner true\" }",
    ),
    (
        "PETSc: GMRES(100) + hypre BoomerAMG (3D settings)",
        "{ petsc = \"-ksp_type gmres -ksp_gmres_restart 100 -pc_type hypre \
         -pc_hypre_type boomeramg -pc_hypre_boomeramg_strong_threshold 0.7 \
         -pc_hypre_boomeramg_coarsen_type HMIS -pc_hypre_boomeramg_interp_type ext+i \
         -pc_hypre_boomeramg_P_max 4 -pc_hypre_boomeramg_agg_nl 1\" }",
    ),
    (
        "PETSc: BiCGSTAB + block Jacobi ILU(0)",
        "{ petsc = \"-ksp_type bcgs -pc_type bjacobi -sub_pc_type ilu\" }",
    ),
];

/// Runs the comparison and writes the page.
pub fn linear_petsc(full: bool, root: &Path) -> Result<()> {
    if mpm_cases::distributed::external_linear().is_none() {
        bail!(
            "xtask was built without PETSc: cargo run --release -p xtask --features petsc -- linear-petsc"
        );
    }
    let start = Instant::now();
    let mesh = if full {
        "meshes/vane_full.msh"
    } else {
        "meshes/vane_full_quick.msh"
    };
    let mut runs = Vec::new();
    for (label, linear) in SOLVERS {
        let extra = [
            format!("solver.linear={linear}"),
            "solver.linear_tolerance=1e-12".to_owned(),
        ];
        runs.push(vane::full_with(mesh, true, &extra, label)?);
    }
    let mut md = String::new();
    writeln!(
        md,
        "# PETSc's linear solvers on the full vane\n\n\
         `cargo run --release -p xtask --features petsc -- linear-petsc{}` \
         ({}; {}). The scene `scenes/wang2021_vane_full.toml` with F-patch \
         (`--set solver.locking=fpatch`), {}: {} material points, {} free dofs, 10 steps of \
         4·10⁻⁵ rad, 2 rayon threads for the material-point loops, each linear solve to a \
         relative residual of 10⁻¹² (`linear_tolerance`; PETSc's `-ksp_rtol`, measured in \
         PETSc's default norm of each method: the preconditioned residual for GMRES, the \
         unpreconditioned one for BiCGSTAB). One PETSc rank: these runs measure the \
         preconditioners, not parallelism. GAMG is given the free dofs' six rigid-body \
         modes as its near-null space.\n",
        if full { " --full" } else { "" },
        machine::today(),
        machine::description(),
        if full {
            "at the paper's scale (352,968 tetrahedra)"
        } else {
            "on the quick mesh `vane_full_quick.msh` (21,584 tetrahedra; `--full` runs the paper's scale)"
        },
        runs.first().map_or(0, |r| r.material_points),
        runs.first().map_or(0, |r| r.free_dofs),
    )?;
    md.push_str(&table(&runs).render());
    md.push_str(&reading(&runs));
    let page = machine::stamp_duration(md, start);
    let out = root.join("docs/src/benchmarks/petsc.md");
    std::fs::write(&out, page)?;
    println!("wrote {}", out.display());
    Ok(())
}

/// One row per solver.
fn table(runs: &[Run]) -> Table {
    let mut t = Table::new([
        "linear solver",
        "steps (cut)",
        "Newton iterations",
        "Krylov iterations per solve",
        "solve s per Newton iteration",
        "rest s per Newton iteration",
        "wall time (s)",
        "peak MB",
        "torque at 0.4 mrad (N m)",
    ]);
    for r in runs {
        let solves: usize = r.steps.iter().map(|s| s.0).sum::<usize>().max(1);
        let krylov: usize = r.steps.iter().map(|s| s.2).sum();
        let per = |x: f64| format!("{:.3}", x / solves as f64);
        t.row(vec![
            r.label.clone(),
            r.steps_cell(),
            r.iterations_cell(),
            format!("{:.0}", krylov as f64 / solves as f64),
            per(r.times.solve),
            per(r.times.total() - r.times.solve),
            format!("{:.1}", r.seconds),
            r.peak_cell(),
            format!("{:.3}", r.end()),
        ]);
    }
    t
}

/// The solve-time ratios against ours, and what agrees.
fn reading(runs: &[Run]) -> String {
    let Some(ours) = runs.first() else {
        return String::new();
    };
    let per_iteration =
        |r: &Run| r.times.solve / r.steps.iter().map(|s| s.0).sum::<usize>().max(1) as f64;
    let mut md = String::from("\n**Reading.** Solve time per Newton iteration against ours: ");
    let ratios: Vec<String> = runs[1..]
        .iter()
        .map(|r| format!("{} {:.2}×", r.label, per_iteration(ours) / per_iteration(r)))
        .collect();
    md.push_str(&ratios.join("; "));
    let same = runs[1..]
        .iter()
        .all(|r| r.iterations == ours.iterations && r.failure.is_none());
    let _ = writeln!(
        md,
        " (above 1: faster than ours). The Newton iterations are {} and the torques agree to \
         {:.1e} relative.\n",
        if same {
            "the same in every run"
        } else {
            "not the same in every run (see the table)"
        },
        runs[1..]
            .iter()
            .map(|r| ((r.end() - ours.end()) / ours.end()).abs())
            .fold(0.0, f64::max)
    );
    md
}
