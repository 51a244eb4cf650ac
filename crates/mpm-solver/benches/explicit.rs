//! Explicit solver throughput on the elastic-cube drop of issue 15
//! (`mpm_solver::explicit::verification::elastic_cube`) on 32³, 64³ (and with
//! `MPM_BENCH_LARGE=1`, 128³) cells, on 1 and 2 threads. Criterion reports
//! time per step; particle-steps per second = points / time (printed).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

use mpm_solver::explicit::verification::elastic_cube;

fn bench(c: &mut Criterion) {
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

criterion_group!(benches, bench);
criterion_main!(benches);
