//! `report [--quick]` (issue 16): every case with an analytic or published
//! reference, every variant that applies to it, its error and wall time
//! over a refinement series — a log–log plot of error against time per
//! case, the fastest run reaching each accuracy level, the observed
//! convergence orders — written to `docs/src/reproduction/report.md` with
//! its PNGs `docs/src/reproduction/img/report-<case>.png`.
//!
//! The cases are built in [`implicit`] (column, shear, annulus, stretch),
//! [`locking`] (Cook's membrane, Prandtl footing) and [`explicit`]
//! (vibrating bar, colliding disks) as lists of variants with a run
//! each; [`study`] measures them, [`analysis`] reads orders and the
//! cheapest runs, [`page`] writes the page.

mod analysis;
mod explicit;
mod implicit;
mod locking;
mod page;
mod study;

use std::path::Path;
use std::time::Instant;

use anyhow::Result;

use crate::{machine, write_file};
use study::{CaseResult, CaseSpec};

/// How much the report measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// The two coarsest levels and the few variants that exercise every
    /// case: about a minute in release; the unit test runs it.
    Quick,
    /// Every variant that applies over the whole series of each case.
    Full,
}

/// The cases, in the page's order.
fn cases(mode: Mode) -> Vec<CaseSpec> {
    vec![
        implicit::column(mode),
        implicit::shear(mode),
        implicit::annulus(mode),
        implicit::stretch(mode),
        locking::cook(mode),
        locking::footing(mode),
        explicit::bar(mode),
        explicit::disks(mode),
    ]
}

/// Measures every case of `mode`.
pub fn measure(mode: Mode) -> Vec<CaseResult> {
    cases(mode).into_iter().map(CaseSpec::measure).collect()
}

/// Measures the report and writes it under `docs`.
pub fn run(docs: &Path, mode: Mode) -> Result<()> {
    let load_at_start = machine::load_average();
    let started = Instant::now();
    let results = measure(mode);
    let run = page::Run {
        mode,
        total_s: started.elapsed().as_secs_f64(),
        load_at_start,
    };
    let dir = docs.join("reproduction");
    let md = page::render(&results, &run, &dir.join("img"))?;
    let path = dir.join("report.md");
    write_file(&path, md)?;
    println!(
        "wrote {} in {:.0} s of measuring",
        path.display(),
        run.total_s
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::study::Outcome;
    use super::*;

    /// The quick report has every case, finite positive errors, a
    /// successful variant per case and a converging column; its page and
    /// plots are written to a temporary folder.
    #[test]
    fn quick_report_has_every_case() {
        let results = measure(Mode::Quick);
        let slugs: Vec<&str> = results.iter().map(|c| c.slug).collect();
        for expected in [
            "column", "shear", "annulus", "stretch", "cook", "footing", "bar", "disks",
        ] {
            assert!(slugs.contains(&expected), "{expected} missing: {slugs:?}");
        }
        for case in &results {
            let mut succeeded = 0;
            for v in &case.variants {
                for (level, o) in case.levels.iter().zip(&v.outcomes) {
                    if let Outcome::Measured(m) = o {
                        assert!(
                            m.error.is_finite() && m.error > 0.0,
                            "{} {} {}: error {}",
                            case.slug,
                            v.label,
                            level.label,
                            m.error
                        );
                        assert!(m.seconds > 0.0 && m.seconds.is_finite());
                    }
                }
                if v.outcomes.iter().all(|o| o.measured().is_some()) {
                    succeeded += 1;
                }
            }
            assert!(succeeded > 0, "no variant of {} succeeded", case.slug);
            assert!(
                !analysis::accuracy_levels(case).is_empty(),
                "{} has no accuracy level",
                case.slug
            );
        }
        let column = results
            .iter()
            .find(|c| c.slug == "column")
            .expect("the column");
        let gimp = column
            .variants
            .iter()
            .find(|v| v.label.starts_with("GIMP, eq. 34"))
            .expect("the quick column runs GIMP with eq. 34");
        let order = analysis::fitted_order(gimp, &column.levels).expect("two levels");
        assert!(order > 0.5, "GIMP's column order {order}");

        let dir = std::env::temp_dir().join(format!("xtask-report-{}", std::process::id()));
        let run = page::Run {
            mode: Mode::Quick,
            total_s: 1.0,
            load_at_start: None,
        };
        let md = page::render(&results, &run, &dir).expect("the page renders");
        for case in &results {
            assert!(md.contains(&format!("## {}", case.title)));
            assert!(dir.join(format!("report-{}.png", case.slug)).is_file());
        }
        std::fs::remove_dir_all(&dir).expect("removing the temporary folder");
    }
}
