//! Assembly cost per material point per Newton iteration: material update
//! (ΔF, stress), internal force, consistent tangents and stiffness, for
//! standard MPM in 2D and 3D, previously converged against updated
//! Lagrangian, and the 3D target of 1e5 points.
//!
//! Run: `cargo bench -p mpm-solver --bench assembly`; numbers are
//! recorded in `docs/src/benchmarks/solver.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use mpm_basis::LinearMpm;
use mpm_constitutive::HenckyElastic;
use mpm_mesh::RegularGrid;
use mpm_solver::{
    Formulation, ImplicitSolver, MaterialPoints, NewtonOptions, NoLocking, NoUpdate,
    NodalConstraints, PreviouslyConverged, UpdatedLagrangian,
};
use nalgebra::SVector;

type Solver<const D: usize, F> =
    ImplicitSolver<D, LinearMpm, F, HenckyElastic, NoLocking, NoUpdate, NodalConstraints<D>>;

/// A box of `cells` cells per axis filled with 2^D points per cell, base
/// fixed, gravity; the step is prepared and one increment applied.
fn setup<const D: usize, F: Formulation>(
    cells: [usize; D],
) -> (Solver<D, F>, MaterialPoints<D, (), ()>, Vec<f64>) {
    let h = 1.0;
    let grid = RegularGrid::new(
        SVector::<f64, D>::zeros(),
        SVector::<f64, D>::from_element(h),
        cells,
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
                (k as f64 + 0.5) * h / 2.0
            })
        })
        .collect();
    let mut points = MaterialPoints::new(
        pos,
        vec![(h / 2.0).powi(D as i32); total],
        1000.0,
        vec![(); total],
    )
    .unwrap();
    let mut g = SVector::<f64, D>::zeros();
    g[D - 1] = -10.0;
    points.set_gravity(g);
    let mut constraints = NodalConstraints::<D>::new(grid.node_count());
    let base: Vec<usize> = (0..grid.node_count())
        .filter(|&n| grid.node_position(n).unwrap()[D - 1] == 0.0)
        .collect();
    for i in 0..D {
        constraints.fix(base.iter().copied(), i);
    }
    let law = HenckyElastic::new(1e6, 0.3).unwrap();
    let mut solver: Solver<D, F> = ImplicitSolver::new(
        LinearMpm,
        grid,
        law,
        NoLocking,
        NoUpdate,
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
        let (mut s, p, du) = setup::<D, PreviouslyConverged>([cells; D]);
        group.bench_function(BenchmarkId::new("pc_force_and_stiffness", points), |b| {
            b.iter(|| black_box(s.assemble_at(&p, &du).unwrap()))
        });
        group.bench_function(BenchmarkId::new("pc_force_only", points), |b| {
            b.iter(|| black_box(s.free_residual(&p, &du).unwrap()))
        });
    }
    {
        let (mut s, p, du) = setup::<D, UpdatedLagrangian>([cells; D]);
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
    let (mut s, p, du) = setup::<3, PreviouslyConverged>([25, 25, 20]);
    group.throughput(Throughput::Elements(p.len() as u64));
    group.bench_function("pc_force_and_stiffness", |b| {
        b.iter(|| black_box(s.assemble_at(&p, &du).unwrap()))
    });
    group.finish();
}

criterion_group!(benches, assembly, target_3d);
criterion_main!(benches);
