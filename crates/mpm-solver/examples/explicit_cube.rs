//! Times the explicit elastic-cube drop of `benches/explicit.rs` outside
//! criterion: `cargo run --release -p mpm-solver --example explicit_cube --
//! <cells> <threads> <steps>` prints the particle-steps per second of every
//! step and their median.

use std::time::Instant;

use mpm_solver::explicit::verification::elastic_cube;

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("integer arguments: cells threads steps"))
        .collect();
    let (n, threads, steps) = (
        args.first().copied().unwrap_or(64),
        args.get(1).copied().unwrap_or(1),
        args.get(2).copied().unwrap_or(20),
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    let (mut solver, mut points) = elastic_cube(n).expect("cube");
    let mut rates = Vec::new();
    pool.install(|| {
        for _ in 0..steps {
            let t = Instant::now();
            solver.step(&mut points, f64::INFINITY).expect("step");
            rates.push(points.len() as f64 / t.elapsed().as_secs_f64());
        }
    });
    let t = solver.stage_times();
    let total = t.p2g + t.grid + t.g2p;
    println!(
        "stages: p2g {:.1} %, grid {:.1} %, g2p {:.1} % of {:.3} s",
        100.0 * t.p2g / total,
        100.0 * t.grid / total,
        100.0 * t.g2p / total,
        total
    );
    let mut sorted = rates.clone();
    sorted.sort_by(f64::total_cmp);
    println!(
        "{n}^3 cells, {} points, {threads} threads: median {:.3} M particle-steps/s (min {:.3}, max {:.3})",
        points.len(),
        sorted[sorted.len() / 2] / 1e6,
        sorted[0] / 1e6,
        sorted[sorted.len() - 1] / 1e6
    );
}
