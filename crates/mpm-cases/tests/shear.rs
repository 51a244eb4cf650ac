//! Simple shear (Coombs 2020 §7.2): homogeneous, so every point must match
//! the single-point reference to 1e-6.
#![allow(clippy::unwrap_used)]

use mpm_cases::cases::Solve;
use mpm_cases::cases::shear::{ShearCase, ShearParams, SinglePoint, elastic_closed_form};
use mpm_cases::run::RunControl;
use mpm_cases::variant::{BasisKind, DomainUpdateKind, FormulationKind, Variant};
use mpm_constitutive::HenckyElastic;

#[test]
fn elastic_reference_is_the_closed_form() {
    let p = ShearParams::default();
    let law = HenckyElastic::new(p.youngs_modulus, p.poisson_ratio).unwrap();
    let mu = law.elasticity().mu;
    let mut point = SinglePoint::new(law);
    for k in 0..p.load_steps {
        let sigma = point.shear(p.shear / p.load_steps as f64).unwrap();
        let gamma = p.shear * (k + 1) as f64 / p.load_steps as f64;
        let exact = elastic_closed_form(mu, gamma);
        assert!((sigma - exact).norm() <= 1e-12 * exact.norm(), "step {k}");
    }
}

/// Standard MPM and quadratic B-splines, both formulations, elastic and
/// perfectly plastic: every point within 1e-6 of the single-point
/// reference at every step. (GIMP is left out until its domain updates
/// arrive: with fixed domains the fringe nodes of the sheared body carry
/// almost no stiffness and a converged step can fling them away.)
#[test]
fn simple_shear_is_homogeneous_and_matches_the_reference() {
    for yield_stress in [None, Some(5e3)] {
        for (basis, domain_update) in [
            (BasisKind::Linear, DomainUpdateKind::None),
            (BasisKind::BSpline2, DomainUpdateKind::None),
        ] {
            for formulation in [FormulationKind::Pc, FormulationKind::Ul] {
                let p = ShearParams {
                    yield_stress,
                    ..ShearParams::default()
                };
                let v = Variant {
                    basis,
                    formulation,
                    domain_update,
                    ..Variant::default()
                };
                let r = ShearCase::run(&p, &v, &RunControl::default(), |_, _, _| Ok(())).unwrap();
                println!(
                    "{basis} {formulation} yield {yield_stress:?}: max relative stress error {:.2e}, {} iterations",
                    r.error, r.output.summary.iterations
                );
                assert!(r.error <= 1e-6, "{basis} {formulation}: {:e}", r.error);
                assert!(r.output.reports.len() >= 30);
            }
        }
    }
}
