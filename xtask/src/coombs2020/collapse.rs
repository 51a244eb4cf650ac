//! §7.5, the elasto-plastic collapse: final extent and height for standard
//! MPM (Table 6) and for GIMP with each domain-update rule and CPDI2
//! (Table 7), and the Newton residuals of the GIMP collapse (Table 8).

use std::fmt::Write as _;

use anyhow::Result;
use mpm_cases::cases::Solve;
use mpm_cases::cases::collapse::{CollapseCase, CollapseParams};
use mpm_cases::run::RunControl;
use mpm_cases::variant::{BasisKind, DomainUpdateKind, Variant};

use super::paper::{Collapse, TABLE_6, TABLE_8, table7};
use super::variants::{GIMP_RULES, cpdi2, domain_volume, gimp, gimp_domain_volume, label, linear};
use super::{RunStats, compare_residuals};
use crate::markdown::{Table, rel_diff};

/// One collapse analysis.
#[derive(Debug, Clone)]
pub struct Measured {
    /// Material points per cell per direction.
    pub points_per_cell: usize,
    /// Material points.
    pub points: usize,
    /// Right edge of the body (m), at the domains' edges.
    pub extent: f64,
    /// Top of the body (m), at the domains' edges.
    pub height: f64,
    /// Newton work, time and residuals.
    pub stats: RunStats,
    /// Largest rotation of the polar decomposition F = RU over the points
    /// at the end (degrees).
    pub max_rotation_deg: f64,
    /// Smallest |F_xx| or |F_yy| over the points at the end.
    pub min_diag_f: f64,
}

/// A measurement, or why the analysis failed.
pub type Outcome = Result<Measured, String>;

/// Runs the collapse with `variant`, `ppc`² points per cell and cell size `h`.
pub fn measure(variant: &Variant, ppc: usize, h: f64) -> Outcome {
    let p = CollapseParams {
        h,
        points_per_cell: ppc,
        ..CollapseParams::default()
    };
    let r = CollapseCase::run(&p, variant, &RunControl::default(), |_, _, _| Ok(()))
        .map_err(|e| e.to_string())?;
    let (mut max_rotation_deg, mut min_diag_f) = (0.0f64, f64::INFINITY);
    for f in &r.output.last.f {
        // Row-major 3×3: the in-plane block is f[0], f[1], f[3], f[4].
        let angle = (f[3] - f[1]).atan2(f[0] + f[4]).to_degrees().abs();
        max_rotation_deg = max_rotation_deg.max(angle);
        min_diag_f = min_diag_f.min(f[0].abs()).min(f[4].abs());
    }
    let m = Measured {
        points_per_cell: ppc,
        points: r.material_points,
        extent: r.horizontal_extent,
        height: r.max_height,
        stats: RunStats::of(&r.output),
        max_rotation_deg,
        min_diag_f,
    };
    println!(
        "collapse {:>44} {ppc}x{ppc} h = {h}: extent {:.4} height {:.4}, {} iterations, {:.2} s",
        label(variant),
        m.extent,
        m.height,
        m.stats.iterations,
        m.stats.time_s
    );
    Ok(m)
}

/// The collapse analyses of Tables 6 and 7.
#[derive(Debug, Clone)]
pub struct Study {
    /// Standard MPM: the paper's (h, extent, height) and ours, per
    /// points-per-cell count.
    pub table6: Vec<(Collapse, Outcome)>,
    /// GIMP with every rule integrating with the domain volume (the
    /// paper's convention), CPDI2, and GIMP with every rule integrating
    /// with det F V0; h = 1 m, 6² points per cell.
    pub table7: Vec<(Variant, Outcome)>,
}

/// Cell sizes of Table 6 run by default; `full` adds h = 0.25 m.
pub fn study(full: bool) -> Study {
    let mut table6 = Vec::new();
    for (ppc, row) in TABLE_6 {
        for paper in row {
            if paper.0 < 0.5 && !full {
                continue;
            }
            table6.push((paper, measure(&linear(), ppc, paper.0)));
        }
    }
    let mut variants: Vec<Variant> = GIMP_RULES.map(gimp_domain_volume).to_vec();
    variants.push(cpdi2());
    variants.extend(GIMP_RULES.map(gimp));
    let table7 = variants
        .into_iter()
        .map(|v| {
            let o = measure(&v, 6, 1.0);
            (v, o)
        })
        .collect();
    Study { table6, table7 }
}

/// The paper's Table 7 entry for a variant, if it has one.
fn table7_reference(v: &Variant) -> Option<(f64, f64)> {
    match (v.basis, v.domain_update) {
        (BasisKind::Cpdi2, _) => Some(table7::CPDI2),
        (BasisKind::Gimp, DomainUpdateKind::DetF) => Some(table7::EQ32),
        (BasisKind::Gimp, DomainUpdateKind::DiagF) => Some(table7::EQ33),
        (BasisKind::Gimp, DomainUpdateKind::Stretch) => Some(table7::EQ34),
        (BasisKind::Gimp, DomainUpdateKind::CornerMidpoint | DomainUpdateKind::Midpoint) => {
            Some(table7::EQ37)
        }
        (
            BasisKind::Gimp,
            DomainUpdateKind::VolumeCorrectedDiagF
            | DomainUpdateKind::IncrementalVolumeCorrectedDiagF,
        ) => Some(table7::EQ38_39),
        _ => None,
    }
}

fn failed(e: &str) -> Vec<String> {
    vec![format!("failed: {e}")]
}

/// §3 of the report: Tables 6 and 7.
pub fn tables_section(study: &Study, full: bool) -> Result<String> {
    let mut md = String::new();
    writeln!(
        md,
        "## 3. Collapse: extent and height (Tables 6, 7)\n\n\
         Plane-strain collapse of a 16 m × 8 m block (half modelled), E = 1 MPa, ν = 0.3, \
         von Mises with ρ_y = 20 kPa, body force 10 kN/m³ over 40 load steps (§7.5). The \
         extent and height are measured where the paper measures them, at the edge of the \
         body: for GIMP and CPDI2 the edges of the points' domains, for standard MPM \
         x_p + l⁰_p (l⁰_p the initial half-spacing of the points).\n"
    )?;
    writeln!(md, "### Table 6: standard MPM\n")?;
    let mut t = Table::new([
        "points per cell",
        "h (m)",
        "points",
        "extent, paper (m)",
        "extent, ours (m)",
        "difference",
        "height, paper (m)",
        "height, ours (m)",
        "difference",
        "iterations",
        "time (s)",
    ]);
    let mut worst: f64 = 0.0;
    for ((h, extent, height), o) in &study.table6 {
        let row = match o {
            Ok(m) => {
                worst = worst
                    .max(((m.extent - extent) / extent).abs())
                    .max(((m.height - height) / height).abs());
                vec![
                    format!("{0}×{0}", m.points_per_cell),
                    format!("{h}"),
                    m.points.to_string(),
                    format!("{extent:.3}"),
                    format!("{:.3}", m.extent),
                    rel_diff(m.extent, *extent),
                    format!("{height:.3}"),
                    format!("{:.3}", m.height),
                    rel_diff(m.height, *height),
                    m.stats.iterations_note(),
                    format!("{:.2}", m.stats.time_s),
                ]
            }
            Err(e) => failed(e),
        };
        t.row(row);
    }
    md.push_str(&t.render());
    if !full {
        writeln!(
            md,
            "h = 0.25 m (up to 82 944 points) runs with `--full` only.\n"
        )?;
    }
    writeln!(
        md,
        "**Reading.** Every entry is within {:.2} % of the paper's. The paper's remark that the \
         grid spacing dominates (6² and 9² points per cell differ little at fine h) holds here \
         too.\n",
        100.0 * worst
    )?;

    writeln!(
        md,
        "### Table 7: GIMP domain-update rules and CPDI2 (h = 1 m, 6² points per cell)\n\n\
         Each GIMP rule is run twice: with the points integrating with their domain's volume \
         V_p = ∏2l_p (rows marked \"V = ∏2l\", `gimp_volume = domain`: the paper's \
         convention, as these results show) and with V_p = det F V⁰_p (our default, \
         `gimp_volume = det_f`). The two agree for the rules that keep ∏l_p = det F ∏l⁰_p \
         (eqs. 32, 37, 38, 39) and differ for the others. The paper's values are repeated \
         on both rows.\n"
    )?;
    let mut t = Table::new([
        "variant",
        "extent, paper (m)",
        "extent, ours (m)",
        "difference",
        "height, paper (m)",
        "height, ours (m)",
        "difference",
        "largest rotation",
        "smallest |F_ii|",
        "iterations",
        "time (s)",
    ]);
    for (v, o) in &study.table7 {
        let row = match o {
            Ok(m) => {
                let (pe, ph) = match table7_reference(v) {
                    Some((e, h)) => (
                        (format!("{e:.3}"), rel_diff(m.extent, e)),
                        (format!("{h:.3}"), rel_diff(m.height, h)),
                    ),
                    None => (("–".into(), "–".into()), ("–".into(), "–".into())),
                };
                vec![
                    label(v),
                    pe.0,
                    format!("{:.3}", m.extent),
                    pe.1,
                    ph.0,
                    format!("{:.3}", m.height),
                    ph.1,
                    format!("{:.0}°", m.max_rotation_deg),
                    format!("{:.2}", m.min_diag_f),
                    m.stats.iterations_note(),
                    format!("{:.2}", m.stats.time_s),
                ]
            }
            Err(e) => failed(e),
        };
        t.row(row);
    }
    md.push_str(&t.render());
    md.push_str(&table7_commentary(study));
    Ok(md)
}

/// Whether a Table 7 analysis is within 0.1 % of the paper.
struct Verdict {
    label: String,
    /// Integrates with the domain volume (GIMP) or is CPDI2.
    paper_convention: bool,
    extent: bool,
    height: bool,
}

fn table7_commentary(study: &Study) -> String {
    let get = |rule: DomainUpdateKind, dv: bool| {
        study
            .table7
            .iter()
            .find(|(v, _)| {
                v.basis == BasisKind::Gimp && v.domain_update == rule && domain_volume(v) == dv
            })
            .and_then(|(_, o)| o.as_ref().ok())
    };
    let (Some(eq33), Some(eq34), Some(eq37), Some(eq38), Some(eq37_dv), Some(eq38_dv)) = (
        get(DomainUpdateKind::DiagF, false),
        get(DomainUpdateKind::Stretch, false),
        get(DomainUpdateKind::CornerMidpoint, false),
        get(DomainUpdateKind::VolumeCorrectedDiagF, false),
        get(DomainUpdateKind::CornerMidpoint, true),
        get(DomainUpdateKind::VolumeCorrectedDiagF, true),
    ) else {
        return "Some analyses failed; see the table.\n\n".into();
    };
    let pct = |a: f64, b: f64| 100.0 * ((a - b) / b).abs();
    let vs38 = |m: &Measured| pct(m.extent, eq38.extent).max(pct(m.height, eq38.height));
    let verdicts: Vec<Verdict> = study
        .table7
        .iter()
        .filter_map(|(v, o)| {
            let m = o.as_ref().ok()?;
            let (e, h) = table7_reference(v)?;
            let close = |ours: f64, paper: f64| ((ours - paper) / paper).abs() <= 1e-3;
            Some(Verdict {
                label: label(v),
                paper_convention: domain_volume(v) || v.basis == BasisKind::Cpdi2,
                extent: close(m.extent, e),
                height: close(m.height, h),
            })
        })
        .collect();
    let list = |f: &dyn Fn(&Verdict) -> bool| {
        let names: Vec<&str> = verdicts
            .iter()
            .filter(|x| f(x))
            .map(|x| x.label.as_str())
            .collect();
        if names.is_empty() {
            "none".to_owned()
        } else {
            names.join("; ")
        }
    };
    let paper_eq37_height = table7::EQ37.1;
    format!(
        "**Reading.** *With the paper's convention* (V = ∏2l), within 0.1 % of the paper in \
         extent and height: {}. Extent only: {}. Neither: {}. The one entry not reproduced \
         is the height for eq. 37: {:.3} m against the paper's {paper_eq37_height} m \
         ({:.1} % lower), while its extent matches; our eq. 37 height equals eq. 38's \
         ({:.3} m) within {:.2} %. Eqs. 37, 38 and 39 all scale the domain so that \
         ∏l_p = det F ∏l⁰_p, so they integrate the same volumes and differ only in the \
         domains' aspect ratios; in the paper, too, their extents agree to all five printed \
         digits (13.769 m) while the heights differ by 2.2 %. We tried eq. 37 without its \
         volume correction, with the corners convected by the GIMP weights instead of the \
         grid's shape functions, with the corners carried from step to step instead of \
         rebuilt from the rectangle, with the extents of the corners instead of the \
         mid-points, and as the direct mid-point variant (Fig. 5b): none gives \
         the paper's height. The paper's text says eqs. 38/39 give \"similar extent and \
         maximum height values as the (34) and (37) domain updating methods\", consistent \
         with our result, and its Table 8, computed with eq. 37 on this problem, points the \
         same way: measured as the paper's code measures it, the out-of-balance force at \
         iteration 0 of steps 10, 20, 30 and 40 — which depends on the positions, domains \
         and stresses of every point at the end of the previous step — agrees with the \
         paper's within {:.2} % (§4), so the two eq. 37 analyses pass through the same \
         states to about four digits up to step 39. We therefore suspect the printed height, \
         but cannot prove it and leave it as an open discrepancy rather than tune for it.\n\n\
         *With det F V0* (our default, volume-consistent for every rule), within 0.1 % of the \
         paper: {}. Here eqs. 33 and 34 give the collapse of the volume-corrected rules, \
         differing from eq. 38 by at most {:.2} % and {:.2} % (eq. 37: {:.2} %): the paper's \
         softer eq. 33 (14.415 m / 5.546 m) and stiffer eq. 34 (13.425 m / 6.441 m) come from \
         the volumes their domains integrate — eq. 33 shrinks the domains of rotating points \
         (footnote d; here the largest rotation is {:.0}° and the smallest |F_ii| {:.2}), \
         eq. 34 grows those of shearing points (footnote c) — not from the shape of the \
         domains. The test `table7_collapse_extent_and_height_per_domain_rule` \
         (crates/mpm-cases/tests/coombs2020.rs) pins both conventions.\n\n",
        list(&|x| x.paper_convention && x.extent && x.height),
        list(&|x| x.paper_convention && x.extent && !x.height),
        list(&|x| x.paper_convention && !x.extent && !x.height),
        eq37_dv.height,
        pct(eq37_dv.height, paper_eq37_height),
        eq38_dv.height,
        pct(eq37_dv.height, eq38_dv.height),
        100.0 * compare_residuals(&TABLE_8, &eq37_dv.stats).initial_worst,
        list(&|x| !x.paper_convention && x.extent && x.height),
        vs38(eq33),
        vs38(eq34),
        vs38(eq37),
        eq33.max_rotation_deg,
        eq33.min_diag_f,
    )
}

/// §4, first part: Table 8 from the eq. 37 analysis of Table 7.
pub fn table8_section(study: &Study) -> Result<String> {
    let mut md = String::new();
    writeln!(
        md,
        "### Table 8: GIMP collapse (eq. 37, h = 1 m, 6² points per cell)\n\n\
         Normalised out-of-balance force of eq. (40) per Newton iteration, load steps 10, 20, \
         30 and 40 (from the eq. 37 analysis of Table 7).\n"
    )?;
    let run = study.table7.iter().find(|(v, _)| {
        v.basis == BasisKind::Gimp
            && v.domain_update == DomainUpdateKind::CornerMidpoint
            && !domain_volume(v)
    });
    let Some((_, Ok(m))) = run else {
        writeln!(md, "The eq. 37 analysis failed; no residuals.\n")?;
        return Ok(md);
    };
    let c = compare_residuals(&TABLE_8, &m.stats);
    md.push_str(&c.table.render());
    writeln!(
        md,
        "**Reading.** Iteration 0: the paper prints the out-of-balance force of the \
         unchanged previous state under the new load, ‖f_ext − f_int‖ / ‖f_ext‖ over every \
         dof with the reactions not yet known (so that f_int at the supports, which carries \
         the previous reactions, counts as out of balance); this is the first residual the \
         authors' AMPLE code prints. Measured the same way (first row, \
         `StepReport::initial_unbalance`) ours is {} against the paper's {}: equal within \
         {:.2} %, so the collapse states at steps 9, 19, 29 and 39 agree with the paper's to \
         about four digits. Our convergence measure, eq. (40) over the free dofs with the \
         reactions included, starts from {} (row 0). From iteration 1 on both sequences fall \
         the same way and end in quadratic convergence: {} iterations here against the \
         paper's {} (steps 10, 20, 30, 40); the values differ because the paper's later \
         iterations keep a reaction estimate from the linear solves in numerator and \
         denominator.\n",
        c.ours_initial,
        c.paper_first,
        100.0 * c.initial_worst,
        c.ours_first,
        c.ours_iterations,
        c.paper_iterations,
    )?;
    Ok(md)
}
