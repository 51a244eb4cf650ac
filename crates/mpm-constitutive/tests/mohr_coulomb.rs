//! Mohr–Coulomb: laboratory paths against their closed forms (issue 43,
//! "Material point, exact") and the consistent tangent of every regime
//! against finite differences.
//!
//! Paths run on fixed axes with [`PointDriver`], stresses tension-positive
//! (the closed forms are quoted compression-positive and negated). With
//! perfect plasticity the stress on a face or an edge of the pyramid is
//! exact once reached, so the failure stresses are checked to 1e-8
//! relative, the tolerance; the driver converges them to 1e-6 Pa
//! (1e-11 of the stresses).

use mpm_constitutive::point_driver::{Control, PointDriver};
use mpm_constitutive::verification::{
    STEP, TOLERANCE, check_algorithmic_tangent, check_loading_tangent, check_previously_converged,
    check_spatial,
};
use mpm_constitutive::{
    LogStrainLaw, MaterialState, MohrCoulomb, MohrCoulombHistory, Regime, SymSpectral,
};
use nalgebra::{Matrix3, Rotation3, Vector3};

const E: f64 = 1.0e7;
const NU: f64 = 0.3;
const CONFINING: f64 = -100.0e3;
/// The driver's stress tolerance (Pa).
const STRESS_TOL: f64 = 1e-6;

fn law(c: f64, phi: f64, psi: f64) -> MohrCoulomb {
    MohrCoulomb::new(E, NU, c, phi, psi, 0.0).unwrap()
}

/// A point at the isotropic stress `p` (elastic).
fn isotropic<'a>(law: &'a MohrCoulomb, p: f64) -> PointDriver<'a, MohrCoulomb> {
    let bulk = law.elasticity().bulk;
    PointDriver::new(
        law,
        Vector3::from_element(p / (3.0 * bulk)),
        MohrCoulombHistory::default(),
    )
}

/// Axis 2 strained by `steps` increments of `de` at the confining stress
/// on axes 0 and 1.
fn triaxial(point: &mut PointDriver<'_, MohrCoulomb>, de: f64, steps: usize) {
    for _ in 0..steps {
        let controls = [
            Control::Stress(CONFINING),
            Control::Stress(CONFINING),
            Control::Strain(de),
        ];
        point.step(controls, STRESS_TOL).unwrap();
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
fn triaxial_compression_of_a_cohesionless_soil_fails_at_three_times_the_confining_stress() {
    // σ1 = σ3 (1 + sin φ)/(1 − sin φ) = 3 σ3 at φ = 30°.
    let law = law(0.0, 30.0, 0.0);
    let mut point = isotropic(&law, CONFINING);
    triaxial(&mut point, -2e-4, 200);
    assert_eq!(point.history.regime, Regime::CompressionEdge);
    assert_relative(point.stress[2], -300.0e3, 1e-8, "axial stress");
    assert_relative(point.stress[0], CONFINING, 1e-8, "lateral stress");
}

#[test]
fn triaxial_compression_with_cohesion_adds_two_c_root_n_phi() {
    // σ1 = 3 σ3 + 2c√3 = 334.641016 kPa at c = 10 kPa.
    let law = law(10.0e3, 30.0, 0.0);
    let mut point = isotropic(&law, CONFINING);
    triaxial(&mut point, -2e-4, 200);
    assert_relative(
        point.stress[2],
        -334.641_016_151_377_5e3,
        1e-8,
        "axial stress",
    );
}

#[test]
fn triaxial_extension_fails_at_a_third_of_the_confining_stress() {
    let law = law(0.0, 30.0, 0.0);
    let mut point = isotropic(&law, CONFINING);
    triaxial(&mut point, 1e-4, 200);
    assert_eq!(point.history.regime, Regime::ExtensionEdge);
    assert_relative(point.stress[2], CONFINING / 3.0, 1e-8, "axial stress");
}

#[test]
fn plastic_dilatancy_on_the_compression_edge_is_two_sin_psi_over_one_minus_sin_psi() {
    let law = law(0.0, 30.0, 10.0);
    let mut point = isotropic(&law, CONFINING);
    triaxial(&mut point, -2e-4, 200);
    // At failure the stresses stay put: every further increment is plastic.
    let (strain0, elastic0) = (point.strain, point.elastic_strain);
    triaxial(&mut point, -2e-4, 10);
    let plastic = (point.strain - strain0) - (point.elastic_strain - elastic0);
    let ratio = plastic.sum() / -plastic[2];
    let sin_psi = 10f64.to_radians().sin();
    assert_relative(
        ratio,
        2.0 * sin_psi / (1.0 - sin_psi),
        1e-8,
        "dilatancy ratio",
    );
    assert_relative(ratio, 0.4203, 1e-4, "0.4203 at ψ = 10°");
}

#[test]
fn isotropic_tension_ends_at_the_apex_c_cot_phi() {
    let c = 10.0e3;
    let law = law(c, 30.0, 30.0);
    let mut point = isotropic(&law, 0.0);
    for _ in 0..20 {
        point.step([Control::Strain(1e-3); 3], STRESS_TOL).unwrap();
    }
    assert_eq!(point.history.regime, Regime::Apex);
    let apex = c / 30f64.to_radians().tan();
    for a in 0..3 {
        assert_relative(point.stress[a], apex, 1e-12, "apex stress");
    }
}

#[test]
fn zero_friction_is_tresca_with_finite_stresses_everywhere() {
    let c = 10.0e3;
    let law = law(c, 0.0, 0.0);
    let mut point = isotropic(&law, CONFINING);
    triaxial(&mut point, -2e-4, 100);
    assert_relative(
        point.stress[0] - point.stress[2],
        2.0 * c,
        1e-12,
        "τ1 − τ3 = 2c",
    );
    // Isotropic tension and compression never yield a pressure-independent
    // law, and large distortions return to a finite state.
    for eps in [
        Vector3::from_element(5.0),
        Vector3::from_element(-5.0),
        Vector3::new(2.0, -1.0, 0.3),
        Vector3::new(1.0, 1.0, -3.0),
    ] {
        let trial = SymSpectral {
            values: eps,
            vectors: Matrix3::identity(),
        };
        let s = law.return_map(&trial, &MohrCoulombHistory::default());
        assert!(s.tau.iter().all(|t| t.is_finite()), "{eps:?}: {:?}", s.tau);
        let spread = s.tau.max() - s.tau.min();
        assert!(
            spread <= 2.0 * c * (1.0 + 1e-12),
            "{eps:?}: spread {spread}"
        );
    }
}

/// A rotated strain of the given principal values, so the tangent is
/// checked off the axes.
fn rotated(values: [f64; 3]) -> Matrix3<f64> {
    let r = Rotation3::from_euler_angles(0.7, -1.1, 2.3);
    r * Matrix3::from_diagonal(&Vector3::from(values)) * r.transpose()
}

/// Trial strains of each regime for the laws of [`laws_to_check`] (φ =
/// 30°, c = 10 kPa), given by their elastic trial stresses (kPa),
/// including repeated principal values on the edges and the apex.
fn regime_cases() -> Vec<(Regime, [f64; 3])> {
    let strain = |t: [f64; 3]| {
        let tr: f64 = t.iter().sum();
        t.map(|s| ((1.0 + NU) * s - NU * tr) * 1e3 / E)
    };
    vec![
        (Regime::Elastic, strain([-100.0, -120.0, -150.0])),
        (Regime::Plane, strain([-50.0, -120.0, -400.0])),
        (Regime::CompressionEdge, strain([-100.0, -101.0, -500.0])),
        (Regime::CompressionEdge, strain([-100.0, -100.0, -500.0])),
        (Regime::ExtensionEdge, strain([0.0, -300.0, -301.0])),
        (Regime::ExtensionEdge, strain([0.0, -300.0, -300.0])),
        (Regime::Apex, strain([60.0, 50.0, 40.0])),
        (Regime::Apex, strain([50.0, 50.0, 50.0])),
    ]
}

fn laws_to_check() -> Vec<(&'static str, MohrCoulomb)> {
    vec![
        (
            "associated, hardening",
            MohrCoulomb::new(E, NU, 10e3, 30.0, 30.0, 0.05 * E).unwrap(),
        ),
        (
            "non-associated, hardening",
            MohrCoulomb::new(E, NU, 10e3, 30.0, 10.0, 0.05 * E).unwrap(),
        ),
        (
            "ψ = 0, hardening",
            MohrCoulomb::new(E, NU, 10e3, 30.0, 0.0, 0.05 * E).unwrap(),
        ),
    ]
}

#[test]
fn the_algorithmic_tangent_matches_finite_differences_in_every_regime() {
    for (name, law) in laws_to_check() {
        for (regime, values) in regime_cases() {
            let eps = rotated(values);
            let trial = SymSpectral::new(&eps).unwrap();
            let state = law.return_map(&trial, &MohrCoulombHistory::default());
            assert_eq!(state.history.regime, regime, "{name}: {values:?}");
            let err = check_algorithmic_tangent(&law, &eps, &MohrCoulombHistory::default(), STEP)
                .unwrap()
                .unwrap_or_else(|| panic!("{name} {regime:?}: the stencil changed regime"));
            assert!(
                err <= TOLERANCE,
                "{name} {regime:?} {values:?}: error {err:e}"
            );
        }
    }
}

#[test]
fn both_formulations_tangents_match_finite_differences_in_every_regime() {
    // ΔF = exp(ε) R with the trial strain of each regime: b^e_n = 1.
    for (name, law) in laws_to_check() {
        for (regime, values) in regime_cases() {
            let r = Rotation3::from_euler_angles(-0.3, 0.4, 1.2).into_inner();
            let v = rotated(values);
            let delta_f = SymSpectral::new(&v).unwrap().exp() * r;
            let f_n = Rotation3::from_euler_angles(0.2, 0.1, -0.5).into_inner()
                * Matrix3::from_diagonal(&Vector3::new(1.05, 0.97, 1.0));
            let state = MaterialState {
                be: Matrix3::identity(),
                history: MohrCoulombHistory::default(),
            };
            let pc = check_previously_converged(&law, &delta_f, &f_n, &state, STEP)
                .unwrap()
                .unwrap_or_else(|| panic!("{name} {regime:?}: the stencil changed regime"));
            assert!(
                pc <= TOLERANCE,
                "{name} {regime:?}: previously converged error {pc:e}"
            );
            let ul = check_spatial(&law, &delta_f, &f_n, &state, STEP)
                .unwrap()
                .unwrap_or_else(|| panic!("{name} {regime:?}: the stencil changed regime"));
            assert!(
                ul.max() <= TOLERANCE,
                "{name} {regime:?}: spatial errors {ul:?}"
            );
        }
    }
}

#[test]
fn the_tangent_is_major_symmetric_exactly_when_the_flow_is_associated() {
    for (name, law) in laws_to_check() {
        for (regime, values) in regime_cases() {
            if regime == Regime::Elastic {
                continue;
            }
            let trial = SymSpectral::new(&rotated(values)).unwrap();
            let h = MohrCoulombHistory::default();
            let state = law.return_map(&trial, &h);
            let d = law.algorithmic_tangent(&trial, &h, &state);
            let asym = (d - d.transpose()).norm() / d.norm();
            if law.symmetric_tangent() {
                assert!(asym < 1e-12, "{name} {regime:?}: asymmetry {asym:e}");
            } else if regime != Regime::Apex {
                assert!(asym > 1e-3, "{name} {regime:?}: asymmetry {asym:e}");
            }
        }
    }
}

// Random deformation gradients with large rotations and repeated
// stretches (the exported property tests): a friction angle with
// non-associated flow, and φ = 0 (Tresca), both hardening. The cohesions
// put the drawn stretches (0.2–5) in every regime.
mpm_constitutive_proptest::law_tangent_properties!(mohr_coulomb_macro, |e, nu| {
    MohrCoulomb::new(e, nu, 0.05 * e, 30.0, 10.0, 0.1 * e)
});
mpm_constitutive_proptest::law_tangent_properties!(tresca_macro, |e, nu| {
    MohrCoulomb::new(e, nu, 0.2 * e, 0.0, 0.0, 0.1 * e)
});

/// A load step starts from a converged plastic state, which the return
/// map reads as elastic (on the surface to rounding): the loading tangent
/// there is the one-sided derivative for continued loading in every
/// regime. Checked along the increment that led there, to 1e-6.
#[test]
fn the_loading_tangent_on_the_surface_continues_each_regime() {
    let law = MohrCoulomb::new(E, NU, 10e3, 30.0, 10.0, 0.05 * E).unwrap();
    for (regime, values) in regime_cases()
        .into_iter()
        .filter(|(r, _)| *r != Regime::Elastic)
    {
        let err =
            check_loading_tangent(&law, &rotated(values), &MohrCoulombHistory::default(), 1e-7)
                .unwrap()
                .unwrap_or_else(|| panic!("{regime:?}: not a plastic step re-read as elastic"));
        assert!(err < 1e-6, "{regime:?}: loading tangent error {err:e}");
    }
}

/// Strength reduction by F (Griffiths & Lane 1999): c/F and tan φ/F, the
/// dilation angle capped at the reduced friction angle. The reduced law
/// fails in triaxial compression at σ3 N + 2c_f √N with N = (1 + sin
/// φ_f)/(1 − sin φ_f), to 1e-8; a factor that is not positive and finite
/// is refused.
#[test]
fn a_reduced_law_fails_with_the_reduced_strength() {
    let (c, phi, factor) = (10.0e3, 30.0f64, 1.5);
    let law = MohrCoulomb::new(E, NU, c, phi, phi, 0.0)
        .unwrap()
        .reduced(factor)
        .unwrap();
    let phi_f = (phi.to_radians().tan() / factor).atan();
    let n = (1.0 + phi_f.sin()) / (1.0 - phi_f.sin());
    let expected = CONFINING * n - 2.0 * (c / factor) * n.sqrt();
    let mut point = isotropic(&law, CONFINING);
    triaxial(&mut point, -2e-4, 200);
    assert_relative(point.stress[2], expected, 1e-8, "reduced axial stress");
    // ψ = φ before: associated after, at the reduced angle.
    assert!(law.symmetric_tangent());
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(
            MohrCoulomb::new(E, NU, c, phi, 0.0, 0.0)
                .unwrap()
                .reduced(bad)
                .is_err(),
            "{bad}"
        );
    }
}
