//! Developer tasks, run as `cargo xtask <task>` (build in release for
//! meaningful timings: `cargo xtask` runs the release profile only if asked,
//! so use `cargo run --release -p xtask -- <task>`).
//!
//! - `column-table`: error and solver time of the column (Coombs 2020 §7.1)
//!   for h = 50/2^k, k = 2..7, 2×2 points per cell, standard MPM and GIMP
//!   (stretch update, eq. 34), best of three runs; writes
//!   `docs/src/benchmarks/column.md`.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Result, bail};
use mpm_cases::cases::column::{ColumnParams, run};
use mpm_cases::run::RunControl;
use mpm_cases::variant::{BasisKind, DomainUpdateKind};

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    match args.next().as_deref() {
        None | Some("help") | Some("--help") | Some("-h") => {
            println!(
                "usage: cargo run --release -p xtask -- <task>\n\ntasks:\n  column-table  error and run time of the column case, written to docs/src/benchmarks/column.md"
            );
            Ok(())
        }
        Some("column-table") => column_table(),
        Some(other) => bail!("unknown task `{other}` (run `cargo xtask help`)"),
    }
}

fn column_table() -> Result<()> {
    let mut md = String::new();
    writeln!(md, "# Column: error against run time\n")?;
    writeln!(
        md,
        "Compaction under self weight (Coombs et al. 2020 §7.1): error of eq. (42) and solver wall time\n\
         (best of three, file output excluded) for h = 50/2^k, 2×2 points per cell, 20 load steps,\n\
         tolerance 1e-9, previously converged formulation. Regenerate with\n\
         `cargo run --release -p xtask -- column-table` (2-core machine).\n"
    )?;
    writeln!(
        md,
        "| k | h (m) | points | standard MPM error | time (ms) | iterations | GIMP (eq. 34) error | time (ms) | iterations |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|---|---|---|")?;
    for k in 2..=7 {
        let h = 50.0 / 2f64.powi(k);
        let mut row = format!("| {k} | {h} |");
        for (i, (basis, update)) in [
            (BasisKind::Linear, DomainUpdateKind::None),
            (BasisKind::Gimp, DomainUpdateKind::Stretch),
        ]
        .into_iter()
        .enumerate()
        {
            let p = ColumnParams {
                h,
                basis,
                domain_update: update,
                ..ColumnParams::default()
            };
            let mut best = f64::INFINITY;
            let mut last = None;
            for _ in 0..3 {
                let r = run(&p, &p.variant(), &RunControl::default(), |_, _, _| Ok(()))?;
                best = best.min(r.output.wall_time_s);
                last = Some(r);
            }
            let Some(r) = last else { bail!("no run") };
            if i == 0 {
                write!(row, " {} |", r.material_points)?;
            }
            write!(
                row,
                " {:.3e} | {:.1} | {} |",
                r.error,
                1e3 * best,
                r.output.summary.iterations
            )?;
        }
        println!("{row}");
        writeln!(md, "{row}")?;
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/src/benchmarks/column.md");
    std::fs::write(&path, md)?;
    println!("wrote {}", path.display());
    Ok(())
}
