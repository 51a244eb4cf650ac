//! What the scene path's run-time choices cost: one Newton iteration's
//! assembly (ΔF, the constitutive update with tangents, the internal
//! force and the stiffness: `ImplicitSolver::assemble_at`) on the same
//! points and increment, timed two ways side by side:
//!
//! - **typed**: every component a type, as a downstream crate composes
//!   it with `ImplicitBuilder` (the law `HenckyElastic` or `VonMises`, no
//!   locking treatment `NoLocking`, the GIMP rule `StretchU`);
//! - **scene**: the solver the scene runner compiles, with the cold axes
//!   chosen at run time (the laws as `SceneLaws`, a `MaterialSet` of the
//!   registered-law enum with each point tagged; the locking treatment as
//!   `Option<FBar>` set to `None`; the GIMP rule as `AnyGimpRule`).
//!
//! Cases: 2D and 3D, standard MPM and GIMP, Hencky and von Mises (yield
//! stress low enough that the base yields), on 1 and 2 threads. The set-up
//! checks that both paths give the same normalised residual bit for bit,
//! so the time difference is the dispatch's alone.
//!
//! Run: `cargo bench -p mpm-cases --bench dispatch`; numbers are recorded
//! in `docs/src/benchmarks/dispatch.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group};
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

#[path = "dispatch_block/mod.rs"]
mod block;
use block::{grid_of, increment, points, problem};

/// Times both paths on `problem`: the typed law `law`, the typed updater
/// `typed` and the scene's `any` updater.
#[allow(clippy::too_many_arguments)]
fn compare<const D: usize, B, L, U, V>(
    c: &mut Criterion,
    name: &str,
    p: &Problem<D>,
    basis: B,
    law: L,
    typed: U,
    any: V,
) where
    B: InitialDomain<D, Mesh = RegularGrid<D>> + Clone,
    B::Domain: mpm_solver::Flat,
    L: LogStrainLaw + Clone,
    U: DomainUpdater<D, B::Domain>,
    V: DomainUpdater<D, B::Domain>,
{
    let grid = grid_of(p);
    let laws: SceneLaws = scene_laws(&[(p.materials[0].model, p.materials[0].params)]).unwrap();
    let scene_points = points::<D, B, _>(p, |_| Tagged::new(0, laws.laws()[0].initial_history()));
    let typed_points = points::<D, B, L::History>(p, |_| Default::default());
    let mut scene_solver: ImplicitSolver<
        D,
        Parts<B, PreviouslyConverged, SceneLaws, Option<FBar>, V, _>,
    > = ImplicitSolver::new(
        basis.clone(),
        grid.clone(),
        laws,
        None,
        any,
        p.constraints.clone(),
        p.newton,
    );
    let mut typed_solver: ImplicitSolver<D, Parts<B, PreviouslyConverged, L, NoLocking, U, _>> =
        ImplicitSolver::new(
            basis,
            grid.clone(),
            law,
            NoLocking,
            typed,
            p.constraints.clone(),
            p.newton,
        );
    let n = scene_solver.prepare_step(&scene_points, 0.0, 1.0).unwrap();
    assert_eq!(
        typed_solver.prepare_step(&typed_points, 0.0, 1.0).unwrap(),
        n
    );
    let du = increment(n, grid.spacing()[0]);
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let (rs, rt) = pool.install(|| {
            (
                scene_solver.assemble_at(&scene_points, &du).unwrap(),
                typed_solver.assemble_at(&typed_points, &du).unwrap(),
            )
        });
        assert_eq!(rs.to_bits(), rt.to_bits(), "{name}: {rs} against {rt}");
        let mut group = c.benchmark_group(format!("dispatch/{name}/{threads}t"));
        group
            .sample_size(20)
            .warm_up_time(Duration::from_secs(1))
            .measurement_time(Duration::from_secs(4));
        let points_label = p.position.len();
        group.bench_function(BenchmarkId::new("typed", points_label), |b| {
            b.iter(|| {
                pool.install(|| black_box(typed_solver.assemble_at(&typed_points, &du).unwrap()))
            })
        });
        group.bench_function(BenchmarkId::new("scene", points_label), |b| {
            b.iter(|| {
                pool.install(|| black_box(scene_solver.assemble_at(&scene_points, &du).unwrap()))
            })
        });
        group.finish();
    }
}

fn laws() -> (HenckyElastic, VonMises) {
    (
        HenckyElastic::new(1e6, 0.3).unwrap(),
        VonMises::new(1e6, 0.3, 4e3, 1e4).unwrap(),
    )
}

fn in_dimension<const D: usize>(c: &mut Criterion) {
    let (hencky, von_mises) = laws();
    let d = D;
    let p = problem::<D>("linear", "hencky");
    compare(
        c,
        &format!("{d}d_linear_hencky"),
        &p,
        LinearMpm,
        hencky,
        NoUpdate,
        NoUpdate,
    );
    let p = problem::<D>("linear", "von_mises");
    compare(
        c,
        &format!("{d}d_linear_von_mises"),
        &p,
        LinearMpm,
        von_mises,
        NoUpdate,
        NoUpdate,
    );
    let stretch = AnyGimpRule::new(GimpRule::Stretch);
    let p = problem::<D>("gimp", "hencky");
    compare(
        c,
        &format!("{d}d_gimp_hencky"),
        &p,
        Gimp,
        hencky,
        StretchU,
        stretch,
    );
    let p = problem::<D>("gimp", "von_mises");
    compare(
        c,
        &format!("{d}d_gimp_von_mises"),
        &p,
        Gimp,
        von_mises,
        StretchU,
        stretch,
    );
}

fn dispatch(c: &mut Criterion) {
    in_dimension::<2>(c);
    in_dimension::<3>(c);
}

/// One solver of `where_it_goes` on the problem's points.
fn timed<const D: usize, L, K>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    label: &str,
    p: &Problem<D>,
    law: L,
    locking: K,
    history: impl Fn(&L) -> L::History,
    reference: Option<f64>,
) -> f64
where
    L: LogStrainLaw,
    K: mpm_solver::LockingTreatment<D, RegularGrid<D>>,
{
    let grid = grid_of(p);
    let h = history(&law);
    let points = points::<D, LinearMpm, _>(p, |_| h);
    let mut solver: ImplicitSolver<D, Parts<LinearMpm, PreviouslyConverged, L, K, NoUpdate, _>> =
        ImplicitSolver::new(
            LinearMpm,
            grid.clone(),
            law,
            locking,
            NoUpdate,
            p.constraints.clone(),
            p.newton,
        );
    let n = solver.prepare_step(&points, 0.0, 1.0).unwrap();
    let du = increment(n, grid.spacing()[0]);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let r = pool.install(|| solver.assemble_at(&points, &du).unwrap());
    if let Some(want) = reference {
        assert_eq!(r.to_bits(), want.to_bits(), "{label}");
    }
    group.bench_function(label, |b| {
        b.iter(|| pool.install(|| black_box(solver.assemble_at(&points, &du).unwrap())))
    });
    r
}

/// Where the scene path's cost goes, 2D standard MPM with Hencky on one
/// thread: each run-time choice added alone to the typed solver.
fn where_it_goes(c: &mut Criterion) {
    use mpm_cases::material::SceneLaw;
    use mpm_constitutive::MaterialSet;
    let p = problem::<2>("linear", "hencky");
    let hencky = HenckyElastic::new(1e6, 0.3).unwrap();
    let scene_law = SceneLaw::Hencky(hencky);
    let mut group = c.benchmark_group("where_it_goes/2d_linear_hencky/1t");
    group
        .sample_size(30)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5));
    let r = timed(&mut group, "typed", &p, hencky, NoLocking, |_| (), None);
    let fbar: Option<FBar> = None;
    timed(&mut group, "option_fbar", &p, hencky, fbar, |_| (), Some(r));
    let set = MaterialSet::new(vec![hencky]).unwrap();
    timed(
        &mut group,
        "material_set",
        &p,
        set,
        NoLocking,
        |_| Tagged::new(0, ()),
        Some(r),
    );
    timed(
        &mut group,
        "scene_law",
        &p,
        scene_law.clone(),
        NoLocking,
        |l| l.initial_history(),
        Some(r),
    );
    let laws = MaterialSet::new(vec![scene_law]).unwrap();
    timed(
        &mut group,
        "scene",
        &p,
        laws,
        fbar,
        |l| Tagged::new(0, l.laws()[0].initial_history()),
        Some(r),
    );
    group.finish();
}

/// One explicit step of the elastic-cube drop (3D, quadratic B-splines,
/// Taylor-PIC, Neo-Hookean; `mpm_solver::explicit::verification`), typed
/// (`NeoHookean`) against the scene's run-time laws (`ExplicitLaws`: the
/// closed-form Neo-Hookean behind the enum, each point tagged), on 1 and
/// 2 threads. The set-up checks that ten steps give the same positions
/// and stresses bit for bit.
fn explicit_cube(c: &mut Criterion) {
    use mpm_cases::material::{MaterialModel, MaterialParams};
    use mpm_cases::scene::explicit_law::{ExplicitLaw, ExplicitLaws};
    use mpm_constitutive::MaterialSet;
    use mpm_solver::explicit::verification::{elastic_cube, elastic_cube_with};
    let params = MaterialParams::elastic(1e6, 0.3);
    let n = 32;
    let law = ExplicitLaw::new(MaterialModel::NeoHookean, &params).unwrap();
    let laws: ExplicitLaws = MaterialSet::new(vec![law]).unwrap();
    let (mut typed, mut typed_points) = elastic_cube(n).unwrap();
    let (mut scene, mut scene_points) = elastic_cube_with(n, laws).unwrap();
    for _ in 0..10 {
        typed.step(&mut typed_points, f64::INFINITY).unwrap();
        scene.step(&mut scene_points, f64::INFINITY).unwrap();
    }
    assert_eq!(typed_points.position, scene_points.position);
    assert_eq!(typed_points.tau, scene_points.tau);
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut group = c.benchmark_group(format!("dispatch/explicit_cube_{n}/{threads}t"));
        group
            .sample_size(20)
            .warm_up_time(Duration::from_secs(1))
            .measurement_time(Duration::from_secs(5));
        let points = typed_points.len();
        group.bench_function(BenchmarkId::new("typed", points), |b| {
            b.iter(|| {
                pool.install(|| black_box(typed.step(&mut typed_points, f64::INFINITY).unwrap()))
            })
        });
        group.bench_function(BenchmarkId::new("scene", points), |b| {
            b.iter(|| {
                pool.install(|| black_box(scene.step(&mut scene_points, f64::INFINITY).unwrap()))
            })
        });
        group.finish();
    }
}

criterion_group!(benches, dispatch, where_it_goes, explicit_cube);

/// Criterion's main, or with `--count` one path for a profiler
/// ([`block::count`]).
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--count") {
        block::count::main(&args[1..]);
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
