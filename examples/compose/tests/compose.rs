//! The example crate's composition against the framework's own column
//! (mpm-cases), and its own plug points run through the generic solver.
#![allow(clippy::unwrap_used)]

use mpm_basis::{Gimp, LinearMpm};
use mpm_cases::cases::Solve;
use mpm_cases::cases::column::{self, ColumnParams};
use mpm_cases::run::RunControl;
use mpm_cases::variant::{BasisKind, DomainUpdateKind, FormulationKind, Variant};
use mpm_constitutive::HenckyElastic;
use mpm_example_compose::{
    ColumnSettings, FibreLength, StiffeningHencky, column_error, run_column,
};
use mpm_solver::{NoUpdate, PreviouslyConverged, StretchU, UpdatedLagrangian};

/// The paper's column: h = 50/16 m, 2×2 points per cell, 20 steps.
const SETTINGS: ColumnSettings = ColumnSettings {
    h: 50.0 / 16.0,
    points_per_cell: 2,
    load_steps: 20,
};

fn framework_error(variant: Variant) -> f64 {
    column::ColumnCase::run(
        &ColumnParams::default(),
        &variant,
        &RunControl::default(),
        |_, _, _| Ok(()),
    )
    .unwrap()
    .error
}

fn hencky() -> HenckyElastic {
    HenckyElastic::new(1e6, 0.0).unwrap()
}

fn assert_close(ours: f64, framework: f64) {
    let rel = (ours - framework).abs() / framework.abs();
    assert!(
        rel <= 1e-12,
        "ours {ours:e}, framework {framework:e}, relative {rel:e}"
    );
}

#[test]
fn composed_column_equals_the_framework_column() {
    let pc = run_column(
        LinearMpm,
        PreviouslyConverged,
        hencky(),
        NoUpdate,
        &SETTINGS,
    )
    .unwrap();
    assert_close(column_error(&pc), framework_error(Variant::default()));
    let ul = run_column(LinearMpm, UpdatedLagrangian, hencky(), NoUpdate, &SETTINGS).unwrap();
    let variant = Variant {
        formulation: FormulationKind::Ul,
        ..Variant::default()
    };
    assert_close(column_error(&ul), framework_error(variant));
    let gimp_stretch =
        run_column(Gimp, PreviouslyConverged, hencky(), StretchU, &SETTINGS).unwrap();
    let variant = Variant {
        basis: BasisKind::Gimp,
        domain_update: DomainUpdateKind::Stretch,
        ..Variant::default()
    };
    assert_close(column_error(&gimp_stretch), framework_error(variant));
}

#[test]
fn the_custom_law_runs_through_the_generic_solver() {
    // β = 0 is Hencky elasticity: the same column to round-off.
    let plain = StiffeningHencky::new(1e6, 0.0, 0.0).unwrap();
    let ours = run_column(LinearMpm, PreviouslyConverged, plain, NoUpdate, &SETTINGS).unwrap();
    assert_close(column_error(&ours), framework_error(Variant::default()));
    // Stiffening: the column is statically determinate, so the stress
    // error stays that of the discretisation, while the stiffer material
    // settles less.
    let soft = run_column(
        LinearMpm,
        PreviouslyConverged,
        hencky(),
        NoUpdate,
        &SETTINGS,
    )
    .unwrap();
    let stiff = StiffeningHencky::new(1e6, 0.0, 200.0).unwrap();
    let stiff = run_column(LinearMpm, UpdatedLagrangian, stiff, NoUpdate, &SETTINGS).unwrap();
    let (e_soft, e_stiff) = (column_error(&soft), column_error(&stiff));
    assert!(
        e_stiff <= 1.5 * e_soft,
        "error {e_stiff:e} against Hencky's {e_soft:e}"
    );
    assert!(
        stiff.top > soft.top + 1e-3,
        "top {} against Hencky's {}",
        stiff.top,
        soft.top
    );
}

#[test]
fn the_custom_domain_rule_runs_through_the_generic_solver() {
    // Uniaxial compression without rotation: the fibre length along each
    // axis is the diagonal of the right stretch tensor, so the rule
    // reproduces eq. (34).
    let ours = run_column(Gimp, PreviouslyConverged, hencky(), FibreLength, &SETTINGS).unwrap();
    let framework = run_column(Gimp, PreviouslyConverged, hencky(), StretchU, &SETTINGS).unwrap();
    let rel = (column_error(&ours) - column_error(&framework)).abs() / column_error(&framework);
    assert!(rel <= 1e-10, "relative difference {rel:e}");
    let none = run_column(Gimp, PreviouslyConverged, hencky(), NoUpdate, &SETTINGS).unwrap();
    assert_ne!(ours, none, "the rule must change the analysis");
}
