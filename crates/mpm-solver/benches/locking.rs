//! What the locking treatments cost per Newton iteration on the same mesh
//! and points: the assembly (material update, internal force, tangents,
//! stiffness) with F-patch against standard MPM on split tetrahedra (Wang
//! et al. 2021 measured 2.05), F-bar against none on a hexahedral grid,
//! and assembly plus the sparse LU solve, whose difference is the
//! factorisation and solve on the wider pattern. The stiffness sizes are
//! printed.
//!
//! Run: `cargo bench -p mpm-solver --bench locking`; numbers are recorded
//! in `docs/src/benchmarks/locking.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use mpm_basis::{LinearMpm, LinearSimplex};
use mpm_constitutive::HenckyElastic;
use mpm_mesh::{BoxMesh, PatchMesh, RegularGrid, SimplexMesh};
use mpm_solver::{
    FBar, FPatch, ImplicitSolver, LockingTreatment, MaterialPoints, NewtonOptions, NoLocking,
    NoUpdate, NodalConstraints, NodalMesh, Parts, PreviouslyConverged,
};
use nalgebra::SVector;

type Points = MaterialPoints<3, (), ()>;

/// Base fixed, the rest free.
fn base_fixed<M: NodalMesh<3>>(mesh: &M, z: impl Fn(usize) -> f64) -> NodalConstraints<3> {
    let mut c = NodalConstraints::<3>::new(mesh.node_count());
    for n in 0..mesh.node_count() {
        if z(n) <= 1e-12 {
            c.fix([n], 0).fix([n], 1).fix([n], 2);
        }
    }
    c
}

fn gravity(points: &mut Points) {
    points.set_gravity(SVector::<f64, 3>::new(0.0, 0.0, -10.0));
}

fn law() -> HenckyElastic {
    HenckyElastic::new(1e6, 0.3).unwrap()
}

/// Split tet10 parents on `m`³ cubes, four points per child.
fn tets(m: usize) -> (PatchMesh<3>, Points) {
    let parents = BoxMesh::new(
        SVector::<f64, 3>::zeros(),
        SVector::<f64, 3>::from_element(1.0),
        [m; 3],
    )
    .quadratic_mesh()
    .unwrap();
    let patches = PatchMesh::from_parents(&parents).unwrap();
    let mesh = patches.mesh();
    let (a, b) = (0.585_410_196_624_968_5, 0.138_196_601_125_010_5);
    let (mut position, mut volume) = (Vec::new(), Vec::new());
    for e in 0..mesh.element_count() {
        let nodes = mesh.element_nodes(e);
        for k in 0..4 {
            position.push((0..4).fold(SVector::<f64, 3>::zeros(), |acc, v| {
                acc + mesh.nodes()[nodes[v]] * if v == k { a } else { b }
            }));
            volume.push(mesh.volumes()[e] / 4.0);
        }
    }
    let n = position.len();
    let mut points = MaterialPoints::new(position, volume, 1000.0, vec![(); n]).unwrap();
    gravity(&mut points);
    (patches, points)
}

/// Benchmarks one prepared solver: assembly, and assembly plus solve.
fn bench_solver<P: mpm_solver::SolverParts<3, History = (), Domain = ()>>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    mut s: ImplicitSolver<3, P>,
    points: &Points,
) {
    let n = s.prepare_step(points, 0.0, 1.0).unwrap();
    let du: Vec<f64> = (0..n).map(|k| 1e-4 * ((k * 31 + 7) as f64).sin()).collect();
    s.assemble_at(points, &du).unwrap();
    let nnz = s.free_stiffness().unwrap().row_idx.len();
    eprintln!(
        "{name}: {} points, {n} free dofs, {nnz} stiffness entries",
        points.len()
    );
    group.bench_function(format!("{name}_assembly"), |b| {
        b.iter(|| black_box(s.assemble_at(points, &du).unwrap()))
    });
    group.bench_function(format!("{name}_assembly_and_solve"), |b| {
        b.iter(|| {
            s.assemble_at(points, &du).unwrap();
            s.solve().unwrap();
        })
    });
}

fn simplex_solver<K: LockingTreatment<3, SimplexMesh<3>>>(
    mesh: &SimplexMesh<3>,
    locking: K,
) -> ImplicitSolver<
    3,
    Parts<LinearSimplex, PreviouslyConverged, HenckyElastic, K, NoUpdate, NodalConstraints<3>>,
> {
    let c = base_fixed(mesh, |n| mesh.nodes()[n][2]);
    ImplicitSolver::new(
        LinearSimplex,
        mesh.clone(),
        law(),
        locking,
        NoUpdate,
        c,
        NewtonOptions::default(),
    )
}

fn fpatch(c: &mut Criterion) {
    let mut group = c.benchmark_group("locking_tets");
    group.sample_size(10);
    // 8³ parents: 4096 parents, 32 768 children, 131 072 points.
    let (patches, points) = tets(8);
    group.throughput(Throughput::Elements(points.len() as u64));
    let mesh = patches.mesh();
    bench_solver(&mut group, "none", simplex_solver(mesh, NoLocking), &points);
    bench_solver(
        &mut group,
        "fpatch",
        simplex_solver(mesh, FPatch::new(&patches)),
        &points,
    );
    group.finish();
}

/// A hexahedral-grid solver with treatment `K`.
type GridSolver<K> = ImplicitSolver<
    3,
    Parts<LinearMpm, PreviouslyConverged, HenckyElastic, K, NoUpdate, NodalConstraints<3>>,
>;

fn grid_solver<K: LockingTreatment<3, RegularGrid<3>>>(
    cells: usize,
    locking: K,
) -> (GridSolver<K>, Points) {
    let grid = RegularGrid::new(
        SVector::<f64, 3>::zeros(),
        SVector::<f64, 3>::from_element(1.0),
        [cells; 3],
    )
    .unwrap();
    let per = 2 * cells;
    let position: Vec<SVector<f64, 3>> = (0..per.pow(3))
        .map(|flat| {
            SVector::<f64, 3>::new(
                (flat % per) as f64 + 0.5,
                (flat / per % per) as f64 + 0.5,
                (flat / per / per) as f64 + 0.5,
            ) / 2.0
        })
        .collect();
    let n = position.len();
    let mut points = MaterialPoints::new(position, vec![0.125; n], 1000.0, vec![(); n]).unwrap();
    gravity(&mut points);
    let c = base_fixed(&grid, |n| grid.node_position(n).unwrap()[2]);
    (
        ImplicitSolver::new(
            LinearMpm,
            grid,
            law(),
            locking,
            NoUpdate,
            c,
            NewtonOptions::default(),
        ),
        points,
    )
}

fn fbar(c: &mut Criterion) {
    let mut group = c.benchmark_group("locking_hex");
    group.sample_size(10);
    let cells = 16;
    group.throughput(Throughput::Elements((2 * cells as u64).pow(3)));
    let (s, points) = grid_solver(cells, NoLocking);
    bench_solver(&mut group, "none", s, &points);
    let (s, points) = grid_solver(cells, FBar::default());
    bench_solver(&mut group, "fbar", s, &points);
    group.finish();
}

criterion_group!(benches, fpatch, fbar);
criterion_main!(benches);
