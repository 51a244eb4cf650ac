//! Assembly cost per material point per Newton iteration: material update
//! (ΔF, stress), internal force, consistent tangents and stiffness, for
//! standard MPM in 2D and 3D, previously converged against updated
//! Lagrangian, the 3D target of 1e5 points, and the domain-based bases
//! (GIMP, CPDI2) against standard MPM in 2D on the same points.
//!
//! Run: `cargo bench -p mpm-solver --bench assembly`; numbers are
//! recorded in `docs/src/benchmarks/solver.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use mpm_basis::{BasisFunction, Cpdi2, Gimp, LinearMpm};
use mpm_constitutive::HenckyElastic;
use mpm_mesh::RegularGrid;
use mpm_solver::{
    ConvectedCorners, DomainUpdater, Formulation, ImplicitSolver, MaterialPoints, NewtonOptions,
    NoLocking, NoUpdate, NodalConstraints, Parts, PreviouslyConverged, UpdatedLagrangian,
};
use nalgebra::SVector;

type Solver<const D: usize, B, F, U> =
    ImplicitSolver<D, Parts<B, F, HenckyElastic, NoLocking, U, NodalConstraints<D>>>;

/// A solver with a prepared step, its points and a free-dof increment.
type Prepared<const D: usize, B, F, U> = (
    Solver<D, B, F, U>,
    MaterialPoints<D, (), <B as BasisFunction<D>>::Domain>,
    Vec<f64>,
);

/// The bases of the benchmark: those on regular grids.
trait BenchBasis<const D: usize>: BasisFunction<D, Mesh = RegularGrid<D>> {}

impl<const D: usize, B: BasisFunction<D, Mesh = RegularGrid<D>>> BenchBasis<D> for B {}

/// A box of `cells` cells per axis filled with 2^D points per cell, base
/// fixed, gravity; the step is prepared and one increment applied. The
/// grid has `pad` empty cells around the box, and the points are shifted by
/// `shift` cells along every axis.
fn setup<const D: usize, B, F, U>(
    basis: B,
    updater: U,
    cells: [usize; D],
    pad: usize,
    shift: f64,
) -> Prepared<D, B, F, U>
where
    B: BenchBasis<D>,
    F: Formulation,
    U: DomainUpdater<D, B::Domain>,
{
    let h = 1.0;
    let offset = pad as f64 * h;
    let grid = RegularGrid::new(
        SVector::<f64, D>::from_element(-offset),
        SVector::<f64, D>::from_element(h),
        cells.map(|c| c + 2 * pad),
    )
    .unwrap();
    let total: usize = cells.iter().map(|c| 2 * c).product();
    let pos: Vec<SVector<f64, D>> = (0..total)
        .map(|flat| {
            let mut rest = flat;
            SVector::<f64, D>::from_fn(|i, _| {
                let n1 = 2 * cells[i];
                let k = rest % n1;
                rest /= n1;
                (k as f64 + 0.5) * h / 2.0 + shift * h
            })
        })
        .collect();
    let half = SVector::<f64, D>::from_element(h / 4.0);
    let domains = pos.iter().map(|x| B::initial_domain(x, &half)).collect();
    let mut points =
        MaterialPoints::new(pos, vec![(h / 2.0).powi(D as i32); total], 1000.0, domains).unwrap();
    let mut g = SVector::<f64, D>::zeros();
    g[D - 1] = -10.0;
    points.set_gravity(g);
    let mut constraints = NodalConstraints::<D>::new(grid.node_count());
    let base: Vec<usize> = (0..grid.node_count())
        .filter(|&n| grid.node_position(n).unwrap()[D - 1] <= 0.0)
        .collect();
    for i in 0..D {
        constraints.fix(base.iter().copied(), i);
    }
    let law = HenckyElastic::new(1e6, 0.3).unwrap();
    let mut solver: Solver<D, B, F, U> = ImplicitSolver::new(
        basis,
        grid,
        law,
        NoLocking,
        updater,
        constraints,
        NewtonOptions::default(),
    );
    let n = solver.prepare_step(&points, 0.0, 1.0).unwrap();
    let du: Vec<f64> = (0..n).map(|k| 1e-3 * ((k * 31 + 7) as f64).sin()).collect();
    (solver, points, du)
}

fn bench_dim<const D: usize>(c: &mut Criterion, cells: usize) {
    let mut group = c.benchmark_group(format!("assembly_{D}d"));
    group.sample_size(10);
    let points = (2 * cells).pow(D as u32) as u64;
    group.throughput(Throughput::Elements(points));
    {
        let (mut s, p, du) =
            setup::<D, _, PreviouslyConverged, _>(LinearMpm, NoUpdate, [cells; D], 0, 0.0);
        group.bench_function(BenchmarkId::new("pc_force_and_stiffness", points), |b| {
            b.iter(|| black_box(s.assemble_at(&p, &du).unwrap()))
        });
        group.bench_function(BenchmarkId::new("pc_force_only", points), |b| {
            b.iter(|| black_box(s.free_residual(&p, &du).unwrap()))
        });
    }
    {
        let (mut s, p, du) =
            setup::<D, _, UpdatedLagrangian, _>(LinearMpm, NoUpdate, [cells; D], 0, 0.0);
        group.bench_function(BenchmarkId::new("ul_force_and_stiffness", points), |b| {
            b.iter(|| black_box(s.assemble_at(&p, &du).unwrap()))
        });
    }
    group.finish();
}

fn assembly(c: &mut Criterion) {
    bench_dim::<2>(c, 64);
    bench_dim::<3>(c, 12);
}

fn target_3d(c: &mut Criterion) {
    // 25 x 25 x 20 cells x 8 points = 100 000 points.
    let mut group = c.benchmark_group("assembly_3d_1e5");
    group.sample_size(10);
    let (mut s, p, du) =
        setup::<3, _, PreviouslyConverged, _>(LinearMpm, NoUpdate, [25, 25, 20], 0, 0.0);
    group.throughput(Throughput::Elements(p.len() as u64));
    group.bench_function("pc_force_and_stiffness", |b| {
        b.iter(|| black_box(s.assemble_at(&p, &du).unwrap()))
    });
    group.finish();
}

/// One basis in the 2D comparison: force and stiffness per Newton
/// iteration, and the basis evaluation done once per load step.
fn bench_basis<B, U>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    basis: B,
    updater: U,
    cells: usize,
) where
    B: BenchBasis<2>,
    U: DomainUpdater<2, B::Domain>,
{
    let (mut s, p, du) =
        setup::<2, B, PreviouslyConverged, U>(basis, updater, [cells; 2], 1, 0.125);
    group.bench_function(format!("{name}_force_and_stiffness"), |b| {
        b.iter(|| black_box(s.assemble_at(&p, &du).unwrap()))
    });
    group.bench_function(format!("{name}_evaluate_basis"), |b| {
        b.iter(|| s.evaluate_basis(black_box(&p)).unwrap())
    });
}

/// Standard MPM, GIMP and CPDI2 on the same 2D points (64×64 cells' worth,
/// 2×2 points per cell, undeformed domains of half a cell) and the same
/// grid (one empty cell around the body): the cost per point of the wider
/// stencils. The body is shifted by h/8 so that, as in a deformed body,
/// half of the domains straddle a grid line along each axis (aligned with
/// the cells, every GIMP and CPDI2 domain would lie in one cell and touch
/// the 2² nodes of standard MPM); GIMP and CPDI2 then touch 2² to 3² nodes
/// per point, 6.25 on average.
fn domain_bases(c: &mut Criterion) {
    let cells = 64;
    let mut group = c.benchmark_group("assembly_2d_bases");
    group.sample_size(10);
    group.throughput(Throughput::Elements((2 * cells as u64).pow(2)));
    bench_basis(&mut group, "linear", LinearMpm, NoUpdate, cells);
    bench_basis(&mut group, "gimp", Gimp, NoUpdate, cells);
    bench_basis(&mut group, "cpdi2", Cpdi2, ConvectedCorners, cells);
    group.finish();
}

criterion_group!(benches, assembly, target_3d, domain_bases);
criterion_main!(benches);
