//! Point location in tetrahedral meshes: walking (Wang et al. 2021
//! Algorithm 1) against brute force on the paper's problem size (§5.7: a
//! cube of edge 2 with 31,328 tetrahedra and one material point per
//! element), and the walking cost per point for 10^3 to 10^6 elements.
//!
//! Points: the centroid of an element moved by 0.3 element sizes in a
//! pseudo-random direction (clamped to the box), located from that element
//! as hint, as at the start of a load step.
//!
//! Run: `cargo bench -p mpm-mesh --bench locate`. The numbers are recorded
//! in `docs/src/benchmarks/mesh.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use mpm_mesh::{BoxMesh, SimplexMesh, SplitMix64};
use nalgebra::Vector3;

/// Box edge of the paper's efficiency example.
const EDGE: f64 = 2.0;
/// Displacement of a point from its element's centroid, in element sizes.
const DISPLACEMENT: f64 = 0.3;
/// Points per iteration of the brute-force benchmark (each costs about
/// half the elements).
const BRUTE_POINTS: usize = 64;
/// Points per iteration of the scaling benchmark.
const SCALING_POINTS: usize = 8192;

/// The cube [0, 2]^3 with `cells` cells per axis, six tetrahedra per cell.
fn cube(cells: [usize; 3]) -> SimplexMesh<3> {
    BoxMesh::new(Vector3::zeros(), Vector3::repeat(EDGE), cells)
        .simplex_mesh()
        .unwrap()
}

/// One point per listed element: its centroid moved by `DISPLACEMENT`
/// element sizes (cube root of six volumes) in a random direction, with
/// the element as hint.
fn displaced_points(
    mesh: &SimplexMesh<3>,
    elements: &[usize],
    seed: u64,
) -> (Vec<Vector3<f64>>, Vec<usize>) {
    let mut random = SplitMix64(seed);
    let points = elements
        .iter()
        .map(|&e| {
            let centroid = mesh
                .element_nodes(e)
                .iter()
                .fold(Vector3::zeros(), |c, &n| c + mesh.nodes()[n])
                / 4.0;
            let size = (6.0 * mesh.volumes()[e]).cbrt();
            let direction = loop {
                let d = Vector3::from_fn(|_, _| random.symmetric());
                let n = d.norm();
                if n > 1e-3 && n <= 1.0 {
                    break d / n;
                }
            };
            (centroid + direction * (DISPLACEMENT * size)).map(|c| c.clamp(0.0, EDGE))
        })
        .collect();
    (points, elements.to_vec())
}

fn paper_size(c: &mut Criterion) {
    // 17 x 17 x 18 cells x 6 = 31,212 tetrahedra (the paper: 31,328).
    let mesh = cube([17, 17, 18]);
    let all: Vec<usize> = (0..mesh.element_count()).collect();
    let (points, hints) = displaced_points(&mesh, &all, 1);
    let mut group = c.benchmark_group(format!("locate_{}_tets", mesh.element_count()));
    group.throughput(Throughput::Elements(points.len() as u64));
    group.bench_function("walk_all_points", |b| {
        b.iter(|| {
            let mut checksum = 0;
            for (x, &hint) in points.iter().zip(&hints) {
                checksum += mesh.locate(black_box(x), Some(hint)).unwrap().element;
            }
            black_box(checksum)
        })
    });
    group.bench_function("buckets_all_points", |b| {
        b.iter(|| {
            let mut checksum = 0;
            for x in &points {
                checksum += mesh.locate(black_box(x), None).unwrap().element;
            }
            black_box(checksum)
        })
    });
    let stride = points.len() / BRUTE_POINTS;
    let sample: Vec<Vector3<f64>> = points
        .iter()
        .step_by(stride)
        .take(BRUTE_POINTS)
        .copied()
        .collect();
    group.throughput(Throughput::Elements(sample.len() as u64));
    group.sample_size(10);
    group.bench_function("brute_force_sample", |b| {
        b.iter(|| {
            let mut checksum = 0;
            for x in &sample {
                checksum += mesh.locate_brute_force(black_box(x)).unwrap().element;
            }
            black_box(checksum)
        })
    });
    group.finish();
}

fn scaling(c: &mut Criterion) {
    let mut group = c.benchmark_group("walk_per_point");
    group.throughput(Throughput::Elements(SCALING_POINTS as u64));
    for n in [6, 12, 26, 55] {
        let mesh = cube([n; 3]);
        let mut random = SplitMix64(n as u64);
        let mut elements: Vec<usize> = (0..SCALING_POINTS)
            .map(|_| (random.next_unit() * mesh.element_count() as f64) as usize)
            .collect();
        elements.sort_unstable();
        let (points, hints) = displaced_points(&mesh, &elements, 2);
        group.bench_with_input(
            BenchmarkId::from_parameter(mesh.element_count()),
            &mesh,
            |b, mesh| {
                b.iter(|| {
                    let mut checksum = 0;
                    for (x, &hint) in points.iter().zip(&hints) {
                        checksum += mesh.locate(black_box(x), Some(hint)).unwrap().element;
                    }
                    black_box(checksum)
                })
            },
        );
    }
    group.finish();
}

criterion_group!(benches, paper_size, scaling);
criterion_main!(benches);
