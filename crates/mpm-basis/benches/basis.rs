//! Evaluations per second of every basis in 2D and 3D: one stencil
//! (node ids, values, gradients) per material point, written into one
//! reused caller-owned buffer.
//!
//! Run: `cargo bench -p mpm-basis --bench basis`. The numbers are recorded in
//! `docs/src/benchmarks/basis.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use mpm_basis::{BasisFunction, Corners, Cpdi2, Gimp, LinearMpm, QuadraticBSpline, Stencil};
use mpm_mesh::RegularGrid;
use nalgebra::{SMatrix, SVector};

/// Material points per benchmark iteration.
const POINTS: usize = 1024;
/// Cells per axis of the benchmark grid (unit cells).
const CELLS: usize = 16;

/// Deterministic points in [2, CELLS - 2]^D (inside the B-spline admissible
/// region and far enough from the boundary for every domain below).
fn points<const D: usize>() -> Vec<SVector<f64, D>> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..POINTS)
        .map(|_| SVector::from_fn(|_, _| 2.0 + (CELLS as f64 - 4.0) * next()))
        .collect()
}

fn bench_basis<const D: usize, B>(c: &mut Criterion, name: &str, basis: &B, domains: &[B::Domain])
where
    B: BasisFunction<D, Mesh = RegularGrid<D>>,
{
    let grid = RegularGrid::<D>::new(SVector::zeros(), SVector::repeat(1.0), [CELLS; D]).unwrap();
    let xs = points::<D>();
    let mut stencil = Stencil::for_basis::<B>();
    let mut group = c.benchmark_group(format!("{name}_{D}d"));
    group.throughput(Throughput::Elements(POINTS as u64));
    group.bench_function("evaluate", |b| {
        b.iter(|| {
            let mut checksum = 0.0;
            for (x, domain) in xs.iter().zip(domains) {
                basis
                    .evaluate(&grid, black_box(x), black_box(domain), &mut stencil)
                    .unwrap();
                checksum += stencil.values[0] + stencil.gradients[0][0];
            }
            black_box(checksum)
        })
    });
    group.finish();
}

fn bench_dimension<const D: usize>(c: &mut Criterion) {
    let xs = points::<D>();
    let unit = vec![(); POINTS];
    bench_basis::<D, _>(c, "linear_mpm", &LinearMpm, &unit);
    // GIMP: two points per cell and direction, l = h/4.
    let half_lengths = vec![SVector::<f64, D>::repeat(0.25); POINTS];
    bench_basis::<D, _>(c, "gimp", &Gimp, &half_lengths);
    // CPDI2: the same domains, sheared by 10% (a deformed parallelogram /
    // parallelepiped, so the Jacobian is not diagonal).
    let a = SMatrix::<f64, D, D>::from_fn(|i, j| if i == j { 0.25 } else { 0.025 });
    let corners: Vec<Corners<D>> = xs.iter().map(|x| Corners::affine(x, &a)).collect();
    bench_basis::<D, _>(c, "cpdi2", &Cpdi2, &corners);
    bench_basis::<D, _>(c, "quadratic_bspline", &QuadraticBSpline, &unit);
}

fn basis(c: &mut Criterion) {
    bench_dimension::<2>(c);
    bench_dimension::<3>(c);
}

criterion_group!(benches, basis);
criterion_main!(benches);
