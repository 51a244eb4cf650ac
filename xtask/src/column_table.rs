//! `column-table`: error and solver time of the column (Coombs 2020 §7.1)
//! for h = 50/2^k, k = 2..7, 2×2 points per cell, standard MPM and GIMP
//! (stretch update, eq. 34), fastest of at least [`REPEATS`] runs; writes
//! `docs/src/benchmarks/column.md`. The full comparison of every variant
//! is part of `reproduce coombs2020`.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Result, anyhow};
use mpm_cases::variant::DomainUpdateKind;

use crate::coombs2020::column::{Measured, REPEATS, cell_size, measure};
use crate::coombs2020::variants::{gimp, linear};
use crate::markdown::{millis, sci};
use crate::write_file;

/// Measures the table and writes it under `docs`.
pub fn run(docs: &Path) -> Result<()> {
    let start = std::time::Instant::now();
    let mut md = String::new();
    writeln!(md, "# Column: error against run time\n")?;
    writeln!(
        md,
        "Compaction under self weight (Coombs et al. 2020 §7.1): error of eq. (42) and solver wall time\n\
         (fastest of at least {REPEATS} runs, file output excluded) for h = 50/2^k, 2×2 points per cell, 20 load steps,\n\
         tolerance 1e-9, previously converged formulation. Regenerate with\n\
         `cargo run --release -p xtask -- column-table` (on {} (UTC), {}; it took {}). Every GIMP domain\n\
         update, CPDI2 and the quadratic B-spline are compared in\n\
         [the Coombs et al. (2020) reproduction](../reproduction/coombs2020.md).\n",
        crate::machine::today(),
        crate::machine::description(),
        crate::machine::TOOK,
    )?;
    writeln!(
        md,
        "| k | h (m) | points | standard MPM error | time (ms) | iterations | GIMP (eq. 34) error | time (ms) | iterations |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|---|---|---|")?;
    for k in 2..=7 {
        let run = |v| measure(&v, k).map_err(|e| anyhow!("column, k = {k}: {e}"));
        let (a, b): (Measured, Measured) = (run(linear())?, run(gimp(DomainUpdateKind::Stretch))?);
        let row = format!(
            "| {k} | {} | {} | {} | {} | {} | {} | {} | {} |",
            cell_size(k),
            a.points,
            sci(a.error),
            millis(a.time_s),
            a.iterations,
            sci(b.error),
            millis(b.time_s),
            b.iterations
        );
        println!("{row}");
        writeln!(md, "{row}")?;
    }
    let path = docs.join("benchmarks/column.md");
    write_file(&path, crate::machine::stamp_duration(md, start))?;
    println!("wrote {}", path.display());
    Ok(())
}
