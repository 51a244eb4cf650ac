//! Drucker–Prager: each matching against the Mohr–Coulomb value on the
//! path it matches (issue 43, to 1e-8 relative in Kirchhoff stress), and
//! the consistent tangent of the cone and the apex against finite
//! differences. Paths run with [`PointDriver`], tension positive.

use mpm_constitutive::point_driver::{Control, PointDriver};
use mpm_constitutive::verification::{
    STEP, TOLERANCE, check_algorithmic_tangent, check_loading_tangent, check_previously_converged,
    check_spatial,
};
use mpm_constitutive::{
    DruckerPrager, DruckerPragerHistory, LogStrainLaw, Matching, MaterialState, Regime, SymSpectral,
};
use nalgebra::{Matrix3, Rotation3, Vector3};

const E: f64 = 1.0e7;
const NU: f64 = 0.3;
const CONFINING: f64 = -100.0e3;
const STRESS_TOL: f64 = 1e-6;

fn law(c: f64, phi: f64, psi: f64, matching: Matching) -> DruckerPrager {
    DruckerPrager::new(E, NU, (c, phi, psi), 0.0, matching).unwrap()
}

fn isotropic(law: &DruckerPrager, p: f64) -> PointDriver<'_, DruckerPrager> {
    let bulk = law.elasticity().bulk;
    PointDriver::new(
        law,
        Vector3::from_element(p / (3.0 * bulk)),
        DruckerPragerHistory::default(),
    )
}

/// Axis 2 strained by `steps` increments of `de`; axis 0 at the confining
/// stress, axis 1 too (`plane = false`) or held at zero strain rate
/// (plane strain).
fn drive(point: &mut PointDriver<'_, DruckerPrager>, de: f64, steps: usize, plane: bool) {
    let side = if plane {
        Control::Strain(0.0)
    } else {
        Control::Stress(CONFINING)
    };
    for _ in 0..steps {
        point
            .step(
                [Control::Stress(CONFINING), side, Control::Strain(de)],
                STRESS_TOL,
            )
            .unwrap();
    }
}

fn assert_relative(got: f64, expected: f64, tol: f64, what: &str) {
    let err = (got - expected).abs() / expected.abs();
    assert!(
        err <= tol,
        "{what}: {got} against {expected} (relative {err:e})"
    );
}

#[test]
fn the_outer_cone_fails_in_triaxial_compression_where_mohr_coulomb_does() {
    for (c, expected) in [(0.0, -300.0e3), (10.0e3, -334.641_016_151_377_5e3)] {
        let law = law(c, 30.0, 0.0, Matching::Outer);
        let mut point = isotropic(&law, CONFINING);
        drive(&mut point, -2e-4, 200, false);
        assert_eq!(point.history.regime, Regime::Plane);
        assert_relative(point.stress[2], expected, 1e-8, "axial stress");
    }
}

#[test]
fn the_inner_cone_fails_in_triaxial_extension_where_mohr_coulomb_does() {
    let law = law(0.0, 30.0, 0.0, Matching::Inner);
    let mut point = isotropic(&law, CONFINING);
    drive(&mut point, 1e-4, 200, false);
    assert_relative(point.stress[2], CONFINING / 3.0, 1e-8, "axial stress");
}

#[test]
fn the_plane_strain_cone_gives_mohr_coulombs_plane_strain_limit_with_associated_flow() {
    // Mohr–Coulomb's plane-strain limit: σ1 = 3σ3 at φ = 30° (cohesionless)
    // whatever the out-of-plane stress. The cone reaches it as the
    // out-of-plane plastic strain rate dies out (0.6 of axial strain).
    for (c, expected) in [(0.0, -300.0e3), (10.0e3, -334.641_016_151_377_5e3)] {
        let law = law(c, 30.0, 30.0, Matching::PlaneStrain);
        let mut point = isotropic(&law, CONFINING);
        drive(&mut point, -1e-3, 600, true);
        assert_relative(point.stress[2], expected, 1e-8, "in-plane major stress");
    }
}

#[test]
fn each_matching_has_its_own_cone() {
    // At φ = 30°: outer η = 6 sin φ/(√3 (3 − sin φ)) = 0.69282, inner
    // 0.49487, plane strain 3 tan φ/√(9 + 12 tan² φ) = √(3/13) = 0.48038
    // (de Souza Neto
    // et al. 2008, §8.3).
    let eta = |m| law(1.0, 30.0, 30.0, m).coefficients().0;
    assert_relative(
        eta(Matching::Outer),
        2.0 * 3f64.sqrt() / 5.0,
        1e-14,
        "outer",
    );
    assert_relative(
        eta(Matching::Inner),
        6.0 * 0.5 / (3f64.sqrt() * 3.5),
        1e-14,
        "inner",
    );
    assert_relative(
        eta(Matching::PlaneStrain),
        (3.0f64 / 13.0).sqrt(),
        1e-14,
        "plane strain",
    );
}

#[test]
fn isotropic_tension_ends_at_the_apex() {
    let c = 10.0e3;
    let law = law(c, 30.0, 10.0, Matching::Outer);
    let (eta, xi, _) = law.coefficients();
    let mut point = isotropic(&law, 0.0);
    for _ in 0..20 {
        point.step([Control::Strain(1e-3); 3], STRESS_TOL).unwrap();
    }
    assert_eq!(point.history.regime, Regime::Apex);
    // ξ c/η = c cot φ for every matching.
    assert_relative(point.stress[0], xi * c / eta, 1e-12, "apex");
    assert_relative(
        point.stress[0],
        c / 30f64.to_radians().tan(),
        1e-12,
        "c cot φ",
    );
}

fn rotated(values: [f64; 3]) -> Matrix3<f64> {
    let r = Rotation3::from_euler_angles(0.7, -1.1, 2.3);
    r * Matrix3::from_diagonal(&Vector3::from(values)) * r.transpose()
}

/// Trial strains of each regime (φ = 30°, c = 10 kPa) from their elastic
/// trial stresses (kPa), with repeated principal values.
fn regime_cases() -> Vec<(Regime, [f64; 3])> {
    let strain = |t: [f64; 3]| {
        let tr: f64 = t.iter().sum();
        t.map(|s| ((1.0 + NU) * s - NU * tr) * 1e3 / E)
    };
    vec![
        (Regime::Elastic, strain([-100.0, -120.0, -150.0])),
        (Regime::Plane, strain([-50.0, -120.0, -400.0])),
        (Regime::Plane, strain([-100.0, -100.0, -500.0])),
        (Regime::Plane, strain([0.0, -300.0, -300.0])),
        (Regime::Apex, strain([60.0, 50.0, 40.0])),
        (Regime::Apex, strain([50.0, 50.0, 50.0])),
    ]
}

fn laws_to_check() -> Vec<(&'static str, DruckerPrager)> {
    let make = |psi, m| DruckerPrager::new(E, NU, (10e3, 30.0, psi), 0.05 * E, m).unwrap();
    vec![
        ("outer, associated", make(30.0, Matching::Outer)),
        ("inner, ψ = 10°", make(10.0, Matching::Inner)),
        ("plane strain, ψ = 0", make(0.0, Matching::PlaneStrain)),
    ]
}

#[test]
fn the_tangents_match_finite_differences_on_the_cone_and_at_the_apex() {
    let history = DruckerPragerHistory::default();
    for (name, law) in laws_to_check() {
        for (regime, values) in regime_cases() {
            let eps = rotated(values);
            let state = law.return_map(&SymSpectral::new(&eps).unwrap(), &history);
            assert_eq!(state.history.regime, regime, "{name}: {values:?}");
            let err = check_algorithmic_tangent(&law, &eps, &history, STEP)
                .unwrap()
                .unwrap();
            assert!(
                err <= TOLERANCE,
                "{name} {regime:?} {values:?}: error {err:e}"
            );
            let delta_f = SymSpectral::new(&eps).unwrap().exp()
                * Rotation3::from_euler_angles(-0.3, 0.4, 1.2).into_inner();
            let f_n = Rotation3::from_euler_angles(0.2, 0.1, -0.5).into_inner()
                * Matrix3::from_diagonal(&Vector3::new(1.05, 0.97, 1.0));
            let point = MaterialState {
                be: Matrix3::identity(),
                history,
            };
            let pc = check_previously_converged(&law, &delta_f, &f_n, &point, STEP)
                .unwrap()
                .unwrap();
            assert!(
                pc <= TOLERANCE,
                "{name} {regime:?}: previously converged error {pc:e}"
            );
            let ul = check_spatial(&law, &delta_f, &f_n, &point, STEP)
                .unwrap()
                .unwrap();
            assert!(
                ul.max() <= TOLERANCE,
                "{name} {regime:?}: spatial errors {ul:?}"
            );
            let d = law.algorithmic_tangent(&SymSpectral::new(&eps).unwrap(), &history, &state);
            let asym = (d - d.transpose()).norm() / d.norm();
            if law.symmetric_tangent() || regime != Regime::Plane {
                assert!(asym < 1e-12, "{name} {regime:?}: asymmetry {asym:e}");
            } else {
                assert!(asym > 1e-3, "{name} {regime:?}: asymmetry {asym:e}");
            }
        }
    }
}

// Random deformation gradients (the exported property tests), each
// matching with non-associated flow and hardening.
mpm_constitutive_proptest::law_tangent_properties!(outer_macro, |e, nu| {
    DruckerPrager::new(e, nu, (0.05 * e, 30.0, 10.0), 0.1 * e, Matching::Outer)
});
mpm_constitutive_proptest::law_tangent_properties!(plane_strain_macro, |e, nu| {
    DruckerPrager::new(e, nu, (0.05 * e, 20.0, 0.0), 0.1 * e, Matching::PlaneStrain)
});

/// The loading tangent on the surface (cone and apex) is the one-sided
/// derivative for continued loading, as for Mohr–Coulomb.
#[test]
fn the_loading_tangent_on_the_surface_continues_the_cone_and_the_apex() {
    let law = DruckerPrager::new(E, NU, (10e3, 30.0, 10.0), 0.05 * E, Matching::Outer).unwrap();
    for (regime, values) in regime_cases()
        .into_iter()
        .filter(|(r, _)| *r != Regime::Elastic)
    {
        let err = check_loading_tangent(
            &law,
            &rotated(values),
            &DruckerPragerHistory::default(),
            1e-7,
        )
        .unwrap()
        .unwrap_or_else(|| panic!("{regime:?}: not a plastic step re-read as elastic"));
        assert!(err < 1e-6, "{regime:?}: loading tangent error {err:e}");
    }
}

/// Strength reduction keeps the matching: the outer cone reduced by F
/// fails in triaxial compression where Mohr–Coulomb with c/F and
/// atan(tan φ/F) does, to 1e-8.
#[test]
fn a_reduced_cone_fails_where_the_reduced_mohr_coulomb_does() {
    let (c, phi, factor) = (10.0e3, 30.0f64, 1.5);
    let law = DruckerPrager::new(E, NU, (c, phi, 0.0), 0.0, Matching::Outer)
        .unwrap()
        .reduced(factor)
        .unwrap();
    let phi_f = (phi.to_radians().tan() / factor).atan();
    let n = (1.0 + phi_f.sin()) / (1.0 - phi_f.sin());
    let expected = CONFINING * n - 2.0 * (c / factor) * n.sqrt();
    let mut point = isotropic(&law, CONFINING);
    drive(&mut point, -2e-4, 200, false);
    assert_relative(point.stress[2], expected, 1e-8, "reduced axial stress");
    assert_eq!(law.matching(), Matching::Outer);
    assert!(law.reduced(-1.0).is_err());
}
