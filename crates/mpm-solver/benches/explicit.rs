//! Explicit solver throughput.
//!
//! - `explicit_cube`: the elastic-cube drop of issue 15
//!   (`mpm_solver::explicit::verification::elastic_cube`) on 32³, 64³ (and
//!   with `MPM_BENCH_LARGE=1`, 128³) cells, on 1 and 2 threads.
//! - `explicit_basis`: one step of a 2D elastic block (64 × 64 cells of
//!   0.25 m, a 12 m block of 2² points per cell, Neo-Hookean, FLIP, one
//!   thread, every timed step from the same initial state) with each
//!   basis the explicit solver takes: standard MPM, the quadratic B-spline,
//!   the boundary-modified spline, GIMP without a domain update, with
//!   eq. 34 and with the corner midpoint rule of eq. 37 (the cost of the
//!   domain, of its update and of reading the grid at its corners), and
//!   CPDI2 with its convected corners.
//!
//! Criterion reports time per step; particle-steps per second = points /
//! time (printed as throughput).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use mpm_basis::{BasisFunction, BoundaryBSpline, Cpdi2, Gimp, LinearMpm, QuadraticBSpline};
use mpm_constitutive::NeoHookean;
use mpm_mesh::RegularGrid;
use mpm_solver::explicit::verification::{block, elastic_cube};
use mpm_solver::explicit::{PointsFor, VelocityFixities};
use mpm_solver::{
    ConvectedCorners, CornerMidpoint, DomainUpdater, ExplicitOptions, ExplicitPoints,
    ExplicitSolver, Flip, NoLocking, NoUpdate, StretchU, TimeStep,
};
use nalgebra::Vector2;

fn cube(c: &mut Criterion) {
    let mut sizes = vec![32, 64];
    if std::env::var("MPM_BENCH_LARGE").is_ok_and(|v| v == "1") {
        sizes.push(128);
    }
    let mut group = c.benchmark_group("explicit_cube");
    group.sample_size(10);
    for n in sizes {
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let (mut solver, mut points) = elastic_cube(n).expect("cube");
            group.throughput(Throughput::Elements(points.len() as u64));
            group.bench_function(BenchmarkId::new(format!("{threads}_threads"), n), |b| {
                b.iter(|| pool.install(|| solver.step(&mut points, f64::INFINITY).expect("step")));
            });
        }
    }
    group.finish();
}

/// Times one step of the 2D block with `basis` and `rule` on one thread.
fn block_step<B, R>(
    c: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    basis: B,
    rule: R,
) where
    B: BasisFunction<2, Mesh = RegularGrid<2>>,
    R: DomainUpdater<2, B::Domain>,
{
    let h = 0.25;
    let pad = B::PADDING.max(1);
    let grid = RegularGrid::new(
        Vector2::from_element(-(pad as f64) * h),
        Vector2::new(h, h),
        [64 + 2 * pad, 64 + 2 * pad],
    )
    .expect("grid");
    let (x0, vol) = block(Vector2::new(2.0, 2.0), Vector2::new(14.0, 14.0), h, 2);
    let domains = x0
        .iter()
        .map(|x| B::initial_domain(x, &Vector2::new(h / 4.0, h / 4.0)))
        .collect();
    let points: PointsFor<2, NeoHookean, Flip> =
        ExplicitPoints::new(x0, vol, 1000.0).expect("points");
    let mut points = points.with_domains(domains).expect("domains");
    // A slow shear and stretch without net momentum: the block rings in
    // place however many steps criterion takes.
    points.set_velocity(|x| Vector2::new(0.01 * (x.y - 8.0), 0.005 * (x.y - 8.0)));
    let options = ExplicitOptions {
        time_step: TimeStep::Cfl { factor: 0.3 },
        ..Default::default()
    };
    let mut solver = ExplicitSolver::new(
        basis,
        grid,
        NeoHookean::new(1e6, 0.3).expect("law"),
        Flip,
        NoLocking,
        VelocityFixities::new(),
        options,
    )
    .expect("solver")
    .with_domain_update(rule);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    c.throughput(Throughput::Elements(points.len() as u64));
    // Every timed step starts from the same state (a copy made outside the
    // timing): standard MPM's free corners would invert after some
    // thousand steps (the small-mass instability), and the timing should
    // not depend on how many steps criterion takes.
    c.bench_function(name, |b| {
        b.iter_batched_ref(
            || points.clone(),
            |p| pool.install(|| solver.step(p, f64::INFINITY).expect("step")),
            criterion::BatchSize::LargeInput,
        );
    });
}

fn bases(c: &mut Criterion) {
    let mut group = c.benchmark_group("explicit_basis");
    group.sample_size(20);
    block_step(&mut group, "linear", LinearMpm, NoUpdate);
    block_step(&mut group, "bspline2", QuadraticBSpline, NoUpdate);
    block_step(&mut group, "bspline2_boundary", BoundaryBSpline, NoUpdate);
    block_step(&mut group, "gimp_none", Gimp, NoUpdate);
    block_step(&mut group, "gimp_stretch", Gimp, StretchU);
    block_step(&mut group, "gimp_corner_midpoint", Gimp, CornerMidpoint);
    block_step(&mut group, "cpdi2", Cpdi2, ConvectedCorners);
    group.finish();
}

criterion_group!(benches, cube, bases);
criterion_main!(benches);
