//! Reproduction of Coombs et al. (2020) §7 with GIMP and CPDI2: Fig. 7
//! (column convergence per domain-update rule), Table 7 (collapse extent
//! and height per rule), Table 8 (Newton residuals of the GIMP collapse)
//! and the cantilever of §7.3 with GIMP (eq. 37) and CPDI2 against the
//! elastica. Reference values are the paper's, quoted where they are used.
//! `cargo run --release -p xtask -- reproduce coombs2020` writes the same
//! studies as tables and plots into `docs/src/reproduction/`.
#![allow(clippy::unwrap_used)]

use mpm_cases::cases::Solve;
use mpm_cases::cases::cantilever::{self, CantileverParams, elastica_tip};
use mpm_cases::cases::collapse::{self, CollapseParams};
use mpm_cases::cases::column::{self, ColumnParams};
use mpm_cases::run::RunControl;
use mpm_cases::variant::{BasisKind, DomainUpdateKind, FormulationKind, GimpVolumeKind, Variant};

fn variant(basis: BasisKind, domain_update: DomainUpdateKind) -> Variant {
    Variant {
        basis,
        domain_update,
        ..Variant::default()
    }
}

fn gimp(rule: DomainUpdateKind) -> Variant {
    variant(BasisKind::Gimp, rule)
}

/// GIMP with rule `rule` whose points integrate with their domain's
/// volume, the convention of the paper's GIMP results.
fn gimp_domain_volume(rule: DomainUpdateKind) -> Variant {
    Variant {
        gimp_volume: GimpVolumeKind::Domain,
        ..gimp(rule)
    }
}

fn cpdi2() -> Variant {
    variant(BasisKind::Cpdi2, DomainUpdateKind::Cpdi2)
}

/// Column error (eq. 42) with 2×2 points per cell for h = 50/2^k.
fn column_errors(v: &Variant, ks: std::ops::RangeInclusive<i32>) -> Vec<f64> {
    ks.map(|k| {
        let p = ColumnParams {
            h: 50.0 / 2f64.powi(k),
            ..ColumnParams::default()
        };
        column::ColumnCase::run(&p, v, &RunControl::default(), |_, _, _| Ok(()))
            .unwrap()
            .error
    })
    .collect()
}

/// Fig. 7: "When the domains are not updated or when the domains are updated
/// according to the determinant of the deformation gradient (32), the
/// method fails to converge beyond the third and sixth analyses,
/// respectively. However, when the domains are updated according to (33),
/// (34) or (37) the method continues to converge with background grid
/// refinement at the same rate as the CPDI2 method." The paper's range is
/// k = 2..7; k = 8, 9 are added so that the stall is unmistakable.
#[test]
fn fig7_domain_rules_that_track_the_compaction_keep_converging() {
    use DomainUpdateKind as R;
    let converging = [
        gimp(R::DiagF),
        gimp(R::Stretch),
        gimp(R::CornerMidpoint),
        gimp(R::Midpoint),
        gimp(R::VolumeCorrectedDiagF),
        gimp(R::IncrementalVolumeCorrectedDiagF),
        cpdi2(),
    ];
    let stalling = [gimp(R::None), gimp(R::DetF)];
    let mut best_fine = f64::INFINITY;
    for v in &converging {
        let e = column_errors(v, 2..=9);
        println!("{:>36}: {}", v.domain_update.name(), fmt(&e));
        // Monotone, and still an order of magnitude down from k = 7 to 9
        // (measured: 0.10 for every rule).
        assert!(e.windows(2).all(|w| w[1] < w[0]), "{e:?}");
        assert!(e[7] <= 0.15 * e[5], "{e:?}");
        best_fine = best_fine.min(e[7]);
    }
    for v in &stalling {
        let e = column_errors(v, 2..=9);
        println!("{:>36}: {}", v.domain_update.name(), fmt(&e));
        // Flat or rising from k = 7 to 9 (measured: 1.10 without update,
        // 0.90 with det F) and an order of magnitude above the tracking
        // rules at k = 9. Measured onset: both stall from k = 7 (the
        // paper: no update from k = 4).
        assert!(e[7] >= 0.8 * e[5], "{e:?}");
        assert!(e[7] >= 10.0 * best_fine, "{e:?}");
    }
}

/// With the paper's convention (GIMP points integrate with their domain's
/// volume) the column without domain update stalls where Fig. 7 says:
/// "fails to converge beyond the third [analysis]" (k = 4), because its
/// points keep their initial volume while the column compacts; eq. (32)
/// keeps the volume consistent and behaves as with det F V0.
#[test]
fn fig7_with_domain_volumes_no_update_stalls_after_the_third_analysis() {
    let none = column_errors(&gimp_domain_volume(DomainUpdateKind::None), 2..=9);
    println!("no update, domain volume: {}", fmt(&none));
    // Falling to k = 4, then flat within 15 % (measured 1.17e-2..1.34e-2).
    assert!(none[2] < 0.6 * none[1], "{none:?}");
    assert!(none[3..].iter().all(|e| *e >= 0.85 * none[2]), "{none:?}");
    let det_f = column_errors(&gimp_domain_volume(DomainUpdateKind::DetF), 2..=9);
    // Equal up to round-off (∏2l_i and det F V0 are computed differently).
    let det_f_v0 = column_errors(&gimp(DomainUpdateKind::DetF), 2..=9);
    for (a, b) in det_f.iter().zip(&det_f_v0) {
        assert!(
            (a - b).abs() <= 1e-9 * b,
            "eq. 32 keeps the domain volume at det F V0: {det_f:?} vs {det_f_v0:?}"
        );
    }
}

fn fmt(e: &[f64]) -> String {
    e.iter()
        .map(|x| format!("{x:.3e}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Table 7: "collapse extent and height with the generalised interpolation
/// and CPDI2 methods with h = 1 m and 6² material points", measured at the
/// edges of the domains.
///
/// The paper's GIMP points integrate with their domain's volume
/// (`gimp_volume = domain`): with that convention every entry is
/// reproduced within 0.05 % except the height of eq. (37), 2.1 % below the
/// paper's 6.392 (its extent, 13.769, is reproduced; eqs. 37, 38 and 39
/// keep the domain volume equal to det F V0, so their heights coincide
/// here, as the paper's text says they should). With det F V0 instead
/// (our default), eqs. (33) and (34) give the collapse of the
/// volume-corrected rules within 0.3 %.
#[test]
fn table7_collapse_extent_and_height_per_domain_rule() {
    use DomainUpdateKind as R;
    let p = CollapseParams {
        points_per_cell: 6,
        ..CollapseParams::default()
    };
    let run = |v: &Variant| {
        let r =
            collapse::CollapseCase::run(&p, v, &RunControl::default(), |_, _, _| Ok(())).unwrap();
        assert_eq!(r.output.reports.len(), 40, "{v:?}: no step cut");
        println!(
            "{:>36} ({}): extent {:.4} height {:.4}",
            v.domain_update.name(),
            v.gimp_volume.name(),
            r.horizontal_extent,
            r.max_height
        );
        (r.horizontal_extent, r.max_height)
    };
    let within = |(x, y): (f64, f64), (px, py): (f64, f64), tol: f64| {
        assert!(
            ((x - px) / px).abs() <= tol && ((y - py) / py).abs() <= tol,
            "({x}, {y}) vs ({px}, {py})"
        );
    };
    // The paper's convention: within 1 % (measured: 0.05 % or better).
    for (rule, paper) in [
        (R::DetF, (13.645, 6.316)),
        (R::DiagF, (14.415, 5.546)),
        (R::Stretch, (13.425, 6.441)),
        (R::VolumeCorrectedDiagF, (13.769, 6.257)),
        (R::IncrementalVolumeCorrectedDiagF, (13.769, 6.257)),
    ] {
        within(run(&gimp_domain_volume(rule)), paper, 0.01);
    }
    within(run(&cpdi2()), (13.780, 6.292), 0.01);
    let eq37 = run(&gimp_domain_volume(R::CornerMidpoint));
    assert!(((eq37.0 - 13.769) / 13.769).abs() <= 0.01);
    within(eq37, (13.769, 6.257), 0.002);
    // Our default, det F V0: the volume-inconsistent rules 33 and 34 give
    // the collapse of the volume-corrected ones.
    let eq38 = run(&gimp(R::VolumeCorrectedDiagF));
    within(run(&gimp(R::DiagF)), eq38, 0.003);
    within(run(&gimp(R::Stretch)), eq38, 0.003);
}

/// Table 8: GIMP collapse (h = 1 m, 6² points) residuals of steps 10, 20,
/// 30, 40 — "once approaching the correct solution asymptotic quadratic
/// convergence is achieved" in 3, 5, 6 and 6 iterations — and its
/// iteration-0 row.
#[test]
fn table8_gimp_collapse_converges_quadratically() {
    let p = CollapseParams {
        points_per_cell: 6,
        ..CollapseParams::default()
    };
    let r = collapse::CollapseCase::run(
        &p,
        &gimp(DomainUpdateKind::CornerMidpoint),
        &RunControl::default(),
        |_, _, _| Ok(()),
    )
    .unwrap();
    let paper_iterations = [3, 5, 6, 6];
    // Iteration 0 as the paper's code measures it (all dofs, reactions not
    // yet known): 2.656e0, 2.794e0, 2.701e0, 2.410e0 in Table 8; measured
    // 2.6562, 2.7943, 2.7009, 2.4110. It depends on the whole state at the
    // end of the previous step, so this pins our collapse to the paper's.
    for (step, paper) in [9, 19, 29, 39]
        .into_iter()
        .zip([2.656, 2.794, 2.701, 2.410])
    {
        let ours = r.output.reports[step].initial_unbalance.unwrap();
        assert!(
            ((ours - paper) / paper).abs() <= 1e-3,
            "step {}: {ours}",
            step + 1
        );
    }
    for (step, paper) in [9, 19, 29, 39].into_iter().zip(paper_iterations) {
        let res = &r.output.reports[step].residuals;
        println!(
            "step {}: {} (initial unbalance {:.4e})",
            step + 1,
            fmt(res),
            r.output.reports[step].initial_unbalance.unwrap_or(f64::NAN)
        );
        assert!(*res.last().unwrap() <= 1e-9);
        assert!(res.len() - 1 <= paper + 1, "{res:?}");
        let w = res
            .windows(2)
            .rfind(|w| w[0] < 1e-2 && w[1] > 1e-12)
            .unwrap();
        assert!(w[1] <= 100.0 * w[0] * w[0], "{res:?}");
    }
}

/// Largest distance of the tip history from the elastica (α = P l0²/EI at
/// each load factor), in units of l0: (horizontal, vertical).
fn elastica_deviation(p: &CantileverParams, tip: &[(f64, f64, f64)]) -> (f64, f64) {
    let ei = p.youngs_modulus * p.depth.powi(3) / 12.0;
    tip.iter()
        .fold((0.0f64, 0.0f64), |(du, dv), &(lambda, u, v)| {
            let (ua, va) = elastica_tip(lambda * p.load * p.length.powi(2) / ei);
            (
                du.max((u / p.length - ua).abs()),
                dv.max((v / p.length - va).abs()),
            )
        })
}

/// §7.3 with GIMP (eq. 37, 6² points, Fig. 15) and CPDI2 (4² points; the
/// paper's Fig. 17 uses 3², but the load is split between the two points
/// beside the neutral axis, which needs an even count): all 50 steps
/// converge, UL = PC (to 1e-9 at a Newton tolerance of 1e-11), and the tip
/// at full load is within 0.015 l0 of the
/// elastica (α = P l0²/EI = 10). Along the path, h = 0.5 m (two cells
/// through the depth) is too stiff in early bending and the point load
/// makes it overshoot late (the paper's Fig. 16); refining to h = 0.25 m
/// brings the whole GIMP history closer to the elastica.
#[test]
fn cantilever_with_gimp_and_cpdi2_follows_the_elastica() {
    let mut coarse = 0.0;
    for (v, ppc) in [(gimp(DomainUpdateKind::CornerMidpoint), 6), (cpdi2(), 4)] {
        // UL and PC reach the same equilibrium, so they differ by what
        // the Newton tolerance leaves: measured 1.5e-8 at the default 1e-9
        // (1.0e-9 before the 2026-12-03 rounding changes of the tangent
        // products), 3.2e-10 at 1e-11. Compared at 1e-11, to 1e-9.
        let p = CantileverParams {
            points_per_cell: ppc,
            tolerance: 1e-11,
            ..CantileverParams::default()
        };
        let go = |f: FormulationKind| {
            let v = Variant {
                formulation: f,
                ..v
            };
            cantilever::CantileverCase::run(&p, &v, &RunControl::default(), |_, _, _| Ok(()))
                .unwrap()
        };
        let (pc, ul) = (go(FormulationKind::Pc), go(FormulationKind::Ul));
        assert_eq!(pc.output.reports.len(), 50, "{v:?}");
        let worst_ul = pc
            .tip
            .iter()
            .zip(&ul.tip)
            .map(|(a, b)| (a.1 - b.1).hypot(a.2 - b.2) / a.1.hypot(a.2))
            .fold(0.0, f64::max);
        let last = *pc.tip.last().unwrap();
        let (u, w) = elastica_tip(10.0);
        let end = ((last.1 / p.length - u).abs(), (last.2 / p.length - w).abs());
        let path = elastica_deviation(&p, &pc.tip);
        println!(
            "{} {ppc}x{ppc}, h = {}: tip at full load off the elastica by {end:.4?} l0, along the path by up to {path:.4?}; UL vs PC {worst_ul:.1e}",
            v.basis.name(),
            p.h
        );
        assert!(end.0 <= 0.015 && end.1 <= 0.015, "{end:?}");
        assert!(worst_ul <= 1e-9, "{worst_ul:e}");
        if v.basis == BasisKind::Gimp {
            coarse = path.0.max(path.1);
        }
    }
    let p = CantileverParams {
        h: 0.25,
        points_per_cell: 6,
        ..CantileverParams::default()
    };
    let fine = cantilever::CantileverCase::run(
        &p,
        &gimp(DomainUpdateKind::CornerMidpoint),
        &RunControl::default(),
        |_, _, _| Ok(()),
    )
    .unwrap();
    let path = elastica_deviation(&p, &fine.tip);
    println!("gimp 6x6, h = 0.25: along the path off by up to {path:.4?} (h = 0.5: {coarse:.4})");
    assert!(path.0.max(path.1) <= 0.75 * coarse, "{path:?} vs {coarse}");
}
