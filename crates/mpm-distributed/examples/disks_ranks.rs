//! Times the colliding disks ([`mpm_solver::ranks::disks`]) on the MPI
//! processes it is started on, for the "N ranks against 1" page
//! (`docs/src/benchmarks/ranks.md`):
//!
//! ```sh
//! cargo build --release -p mpm-distributed --features mpi --example disks_ranks
//! RAYON_NUM_THREADS=1 mpirun -n 2 target/release/examples/disks_ranks 128 1.0
//! ```
//!
//! Arguments: cells per side (128) and end time in s (1.0). Rank 0 prints
//! one line: processes, threads per process, points, steps, the slowest
//! rank's wall time of the run (set-up included, a few per cent).

use std::time::Instant;

use mpm_distributed::mpi_ranks::Mpi;
use mpm_solver::ranks::disks::{Deal, Disks};
use mpm_solver::ranks::{Ranks, Reduce};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let cells = args.next().map_or(Ok(128), |a| a.parse())?;
    let end = args.next().map_or(Ok(1.0), |a| a.parse())?;
    let mpi = Mpi::init();
    let ranks = mpi.ranks();
    let disks = Disks {
        cells,
        speed: 0.1,
        end,
    };
    let start = Instant::now();
    let out = disks.on_ranks(Box::new(ranks), Deal::Stripes)?;
    let mut seconds = [start.elapsed().as_secs_f64()];
    let mut points = [out.points.len() as f64];
    ranks.all_reduce(&mut seconds, Reduce::Max)?;
    ranks.all_reduce(&mut points, Reduce::Sum)?;
    if ranks.rank() == 0 {
        println!(
            "processes {} threads {} points {} steps {} seconds {:.3}",
            ranks.size(),
            rayon::current_num_threads(),
            points[0],
            out.steps,
            seconds[0]
        );
    }
    Ok(())
}
