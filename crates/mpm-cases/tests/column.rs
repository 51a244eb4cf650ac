//! Compaction under self weight (Coombs 2020 §7.1, eqs. 41–42).
#![allow(clippy::unwrap_used)]

use mpm_cases::cases::Solve;
use mpm_cases::cases::column::{ColumnCase, ColumnParams};
use mpm_cases::run::RunControl;
use mpm_cases::variant::{BasisKind, DomainUpdateKind, FormulationKind};

fn params(
    k: i32,
    basis: BasisKind,
    formulation: FormulationKind,
    domain_update: DomainUpdateKind,
) -> ColumnParams {
    ColumnParams {
        h: 50.0 / 2f64.powi(k),
        basis,
        formulation,
        domain_update,
        ..ColumnParams::default()
    }
}

/// UL and PC give the same stresses and positions (relative difference
/// <= 1e-8) for every basis.
#[test]
fn updated_lagrangian_equals_previously_converged() {
    for (basis, update) in [
        (BasisKind::Linear, DomainUpdateKind::None),
        (BasisKind::Gimp, DomainUpdateKind::Stretch),
        (BasisKind::BSpline2, DomainUpdateKind::None),
    ] {
        let pc_p = params(4, basis, FormulationKind::Pc, update);
        let ul_p = params(4, basis, FormulationKind::Ul, update);
        let pc = ColumnCase::run(&pc_p, &pc_p.variant(), &RunControl::default(), |_, _, _| {
            Ok(())
        })
        .unwrap();
        let ul = ColumnCase::run(&ul_p, &ul_p.variant(), &RunControl::default(), |_, _, _| {
            Ok(())
        })
        .unwrap();
        let smax = pc
            .output
            .last
            .sigma
            .iter()
            .map(|s| s[4].abs())
            .fold(0.0, f64::max);
        let ds = pc
            .output
            .last
            .sigma
            .iter()
            .zip(&ul.output.last.sigma)
            .map(|(a, b)| (a[4] - b[4]).abs())
            .fold(0.0, f64::max);
        let dx = pc
            .output
            .last
            .position
            .iter()
            .zip(&ul.output.last.position)
            .map(|(a, b)| (a[1] - b[1]).abs())
            .fold(0.0, f64::max);
        println!(
            "{basis}: UL-PC stress {:.1e} relative, position {:.1e} m; error {:.3e} vs {:.3e}",
            ds / smax,
            dx,
            pc.error,
            ul.error
        );
        assert!(ds <= 1e-8 * smax && dx <= 1e-8 * 50.0);
        assert!((pc.error - ul.error).abs() <= 1e-8 * pc.error);
    }
}

/// GIMP with the stretch update (eq. 34) converges with refinement, as
/// in Fig. 7; standard MPM with 2x2 points stagnates (Fig. 6: too few
/// points for the finer grids). Every step converges quadratically to 1e-9.
#[test]
fn gimp_converges_with_grid_refinement_and_standard_mpm_stagnates() {
    let mut previous = f64::INFINITY;
    for k in 2..=6 {
        let p = params(
            k,
            BasisKind::Gimp,
            FormulationKind::Pc,
            DomainUpdateKind::Stretch,
        );
        let r =
            ColumnCase::run(&p, &p.variant(), &RunControl::default(), |_, _, _| Ok(())).unwrap();
        println!(
            "gimp k={k}: error {:.4e}, {} iterations",
            r.error, r.output.summary.iterations
        );
        assert!(
            r.error < previous,
            "error must decrease: {} then {}",
            previous,
            r.error
        );
        previous = r.error;
        for report in &r.output.reports {
            assert!(report.iterations() <= 4, "{:?}", report.residuals);
        }
    }
    assert!(previous < 1e-3);
    let coarse = params(
        3,
        BasisKind::Linear,
        FormulationKind::Pc,
        DomainUpdateKind::None,
    );
    let fine = params(
        6,
        BasisKind::Linear,
        FormulationKind::Pc,
        DomainUpdateKind::None,
    );
    let (c, f) = (
        ColumnCase::run(
            &coarse,
            &coarse.variant(),
            &RunControl::default(),
            |_, _, _| Ok(()),
        )
        .unwrap()
        .error,
        ColumnCase::run(&fine, &fine.variant(), &RunControl::default(), |_, _, _| {
            Ok(())
        })
        .unwrap()
        .error,
    );
    println!("standard MPM 2x2: k=3 {c:.3e}, k=6 {f:.3e}");
    assert!(f > 0.5 * c, "standard MPM with 2x2 points should stagnate");
}

#[test]
fn bad_grid_size_is_a_clear_error() {
    let p = ColumnParams {
        h: 3.0,
        ..ColumnParams::default()
    };
    let err =
        ColumnCase::run(&p, &p.variant(), &RunControl::default(), |_, _, _| Ok(())).unwrap_err();
    assert!(
        err.to_string().contains("must divide the column height"),
        "{err}"
    );
    let p = ColumnParams {
        basis: BasisKind::Linear,
        domain_update: DomainUpdateKind::Stretch,
        ..ColumnParams::default()
    };
    let err =
        ColumnCase::run(&p, &p.variant(), &RunControl::default(), |_, _, _| Ok(())).unwrap_err();
    assert!(err.to_string().contains("needs basis = gimp"), "{err}");
}

/// The column's scene with `locking = "fbar"` (cell patches): it runs
/// through the scene dispatch and UL and PC agree. In this
/// one-dimensional compaction the linear basis gives every point of a
/// cell the same ΔF, so the cell average is each point's own and F-bar
/// must reproduce standard MPM (to rounding).
#[test]
fn the_column_scene_runs_with_fbar() {
    use mpm_cases::variant::{LockingKind, Variant};
    let mut errors = Vec::new();
    let mut last = Vec::new();
    for (formulation, locking) in [
        (FormulationKind::Pc, LockingKind::None),
        (FormulationKind::Pc, LockingKind::FBar),
        (FormulationKind::Ul, LockingKind::FBar),
    ] {
        let p = params(3, BasisKind::Linear, formulation, DomainUpdateKind::None);
        let v = Variant {
            locking,
            ..p.variant()
        };
        let r = ColumnCase::run(&p, &v, &RunControl::default(), |_, _, _| Ok(())).unwrap();
        println!("{formulation} {locking}: error {:.4e}", r.error);
        errors.push(r.error);
        last.push(r.output.last.position.clone());
    }
    let dx = last[1]
        .iter()
        .zip(&last[2])
        .map(|(a, b)| (a[1] - b[1]).abs())
        .fold(0.0, f64::max);
    assert!(dx <= 1e-8 * 50.0, "{dx:e}");
    assert!(
        (errors[1] - errors[0]).abs() <= 1e-9 * errors[0],
        "{errors:?}"
    );
}
