//! One path of the `dispatch` benchmark alone, for instruction counts:
//! the benchmark binary run with `--count` sets up the block under
//! gravity, then runs `ImplicitSolver::assemble_at` `N` times on the typed
//! or the scene solver, so that a profiler sees one path and nothing of
//! criterion. (A mode of the benchmark, not an example: `cargo test`
//! builds every example, and this one cost 35 s of the test build.)
//!
//! ```text
//! cargo bench -p mpm-cases --bench dispatch --no-run   # prints the binary
//! for n in 0 20; do RAYON_NUM_THREADS=1 valgrind --tool=callgrind \
//!     --callgrind-out-file=cg.$n target/release/deps/dispatch-HASH \
//!     --count 2 gimp hencky scene $n; done
//! callgrind_annotate --inclusive=yes cg.20 | head -40
//! ```
//!
//! Arguments: dimension (`2`, `3`), basis (`linear`, `gimp`), model
//! (`hencky`, `von_mises`), path (`typed`, `scene`), repetitions (default
//! 20). Instructions per assembly are the difference of the totals of 20
//! and 0 repetitions over 20 (the assemblies run on rayon's worker
//! thread, so `--toggle-collect` on the calling thread misses them).
//! Prints the last normalised residual (the same bits on both paths).
//! With 2 points per cell the GIMP domains of this block sit where GIMP
//! and linear weights coincide, so the GIMP and linear rows assemble the
//! same stencil and count the same.

use std::hint::black_box;

use mpm_basis::{Gimp, LinearMpm};
use mpm_cases::body::InitialDomain;
use mpm_cases::material::{SceneLaws, scene_laws};
use mpm_cases::scene::Problem;
use mpm_constitutive::{HenckyElastic, LogStrainLaw, Tagged, VonMises};
use mpm_mesh::RegularGrid;
use mpm_solver::{
    AnyGimpRule, DomainUpdater, FBar, GimpRule, ImplicitSolver, NoLocking, NoUpdate, Parts,
    PreviouslyConverged, StretchU,
};

use super::{grid_of, increment, points, problem};

/// Sets up one path and runs `reps` assemblies; returns the last residual.
#[allow(clippy::too_many_arguments)]
fn run<const D: usize, B, L, U, V>(
    p: &Problem<D>,
    basis: B,
    law: L,
    typed: U,
    any: V,
    scene_path: bool,
    reps: usize,
) -> f64
where
    B: InitialDomain<D, Mesh = RegularGrid<D>> + Clone,
    B::Domain: mpm_solver::Flat,
    L: LogStrainLaw + Clone,
    U: DomainUpdater<D, B::Domain>,
    V: DomainUpdater<D, B::Domain>,
{
    let grid = grid_of(p);
    let h = grid.spacing()[0];
    let mut r = 0.0;
    if scene_path {
        let laws: SceneLaws = scene_laws(&[(p.materials[0].model, p.materials[0].params)]).unwrap();
        let pts = points::<D, B, _>(p, |_| Tagged::new(0, laws.laws()[0].initial_history()));
        let mut solver: ImplicitSolver<
            D,
            Parts<B, PreviouslyConverged, SceneLaws, Option<FBar>, V, _>,
        > = ImplicitSolver::new(
            basis,
            grid.clone(),
            laws,
            None,
            any,
            p.constraints.clone(),
            p.newton,
        );
        let du = increment(solver.prepare_step(&pts, 0.0, 1.0).unwrap(), h);
        for _ in 0..reps {
            r = black_box(solver.assemble_at(&pts, &du).unwrap());
        }
    } else {
        let pts = points::<D, B, L::History>(p, |_| Default::default());
        let mut solver: ImplicitSolver<D, Parts<B, PreviouslyConverged, L, NoLocking, U, _>> =
            ImplicitSolver::new(
                basis,
                grid.clone(),
                law,
                NoLocking,
                typed,
                p.constraints.clone(),
                p.newton,
            );
        let du = increment(solver.prepare_step(&pts, 0.0, 1.0).unwrap(), h);
        for _ in 0..reps {
            r = black_box(solver.assemble_at(&pts, &du).unwrap());
        }
    }
    r
}

fn in_dimension<const D: usize>(basis: &str, model: &str, scene_path: bool, reps: usize) -> f64 {
    let p = problem::<D>(basis, model);
    let hencky = HenckyElastic::new(1e6, 0.3).unwrap();
    let von_mises = VonMises::new(1e6, 0.3, 4e3, 1e4).unwrap();
    let stretch = AnyGimpRule::new(GimpRule::Stretch);
    match (basis, model) {
        ("linear", "hencky") => run(&p, LinearMpm, hencky, NoUpdate, NoUpdate, scene_path, reps),
        ("linear", "von_mises") => run(
            &p, LinearMpm, von_mises, NoUpdate, NoUpdate, scene_path, reps,
        ),
        ("gimp", "hencky") => run(&p, Gimp, hencky, StretchU, stretch, scene_path, reps),
        ("gimp", "von_mises") => run(&p, Gimp, von_mises, StretchU, stretch, scene_path, reps),
        _ => panic!("basis linear|gimp, model hencky|von_mises"),
    }
}

/// Runs the path `args` names (module docs) and prints its residual.
pub fn main(args: &[String]) {
    let arg = |k: usize, default: &str| args.get(k).cloned().unwrap_or_else(|| default.into());
    let (dim, basis, model, path) = (
        arg(0, "2"),
        arg(1, "gimp"),
        arg(2, "hencky"),
        arg(3, "scene"),
    );
    let reps: usize = arg(4, "20").parse().unwrap();
    let scene_path = match path.as_str() {
        "scene" => true,
        "typed" => false,
        _ => panic!("path typed|scene"),
    };
    let r = match dim.as_str() {
        "2" => in_dimension::<2>(&basis, &model, scene_path, reps),
        "3" => in_dimension::<3>(&basis, &model, scene_path, reps),
        _ => panic!("dimension 2|3"),
    };
    println!(
        "{dim}d {basis} {model} {path}: residual {r:e} ({:#x})",
        r.to_bits()
    );
}
