//! Closed-form solutions, plastic consistency and bad-input handling.
#![allow(clippy::unwrap_used)]

use approx::assert_relative_eq;
use mpm_constitutive::tensor::embed;
use mpm_constitutive::{
    ConsistentTangent, ConstitutiveError, HenckyElastic, MaterialState, PreviouslyConvergedTangent,
    SpatialTangent, SymSpectral, VonMises, VonMisesHistory, update,
};
use mpm_constitutive_proptest::strategies::{
    config, deformation_gradient, poisson_ratio, rotation,
};
use nalgebra::{Matrix2, Matrix3, Vector3};
use proptest::prelude::*;

fn lame(e: f64, nu: f64) -> (f64, f64) {
    (
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        e / (2.0 * (1.0 + nu)),
    )
}

/// Uniaxial stretch F = diag(λ, 1, 1): ε = diag(ln λ, 0, 0), so
/// τ₁₁ = (λ_L + 2μ) ln λ, τ₂₂ = τ₃₃ = λ_L ln λ, σ = τ/λ, P̃₁₁ = τ₁₁/λ.
#[test]
fn hencky_uniaxial_stretch_matches_closed_form() {
    let (e, nu) = (1e6, 0.3);
    let law = HenckyElastic::new(e, nu).unwrap();
    let (lam, mu) = lame(e, nu);
    for stretch in [0.2, 0.7, 1.0, 1.5, 5.0] {
        let df = Matrix3::from_diagonal(&Vector3::new(stretch, 1.0, 1.0));
        let r = update(&law, &df, &Matrix3::identity(), &MaterialState::default()).unwrap();
        let ln = f64::ln(stretch);
        let expected = Matrix3::from_diagonal(&Vector3::new(
            (lam + 2.0 * mu) * ln / stretch,
            lam * ln / stretch,
            lam * ln / stretch,
        ));
        assert_relative_eq!(r.sigma, expected, epsilon = 1e-9 * e, max_relative = 1e-12);
        assert_relative_eq!(
            r.p_tilde()[(0, 0)],
            (lam + 2.0 * mu) * ln / stretch,
            epsilon = 1e-9 * e,
            max_relative = 1e-12
        );
    }
}

/// Simple shear F = [[1, γ, 0], [0, 1, 0], [0, 0, 1]] (Coombs 2020 §7.2):
/// b has eigenvalues with ln λ± = ±2 asinh(γ/2) and eigenvectors at angle
/// φ with tan 2φ = 2/γ, so with tr ε = 0 and J = 1,
/// σ₁₁ = −σ₂₂ = 2μ asinh(γ/2) γ/√(γ²+4), σ₁₂ = 2μ asinh(γ/2) 2/√(γ²+4),
/// σ₃₃ = σ₁₃ = σ₂₃ = 0.
#[test]
fn hencky_simple_shear_matches_closed_form() {
    let (e, nu) = (1e4, 0.3);
    let law = HenckyElastic::new(e, nu).unwrap();
    let (_, mu) = lame(e, nu);
    for gamma in [1e-6, 0.1, 1.0, 6.0] {
        let f2 = Matrix2::new(1.0, gamma, 0.0, 1.0);
        let r = update(
            &law,
            &embed(&f2),
            &Matrix3::identity(),
            &MaterialState::default(),
        )
        .unwrap();
        let a = (gamma / 2.0).asinh();
        let root = (gamma * gamma + 4.0).sqrt();
        let s11 = 2.0 * mu * a * gamma / root;
        let s12 = 2.0 * mu * a * 2.0 / root;
        let expected = Matrix3::new(s11, s12, 0.0, s12, -s11, 0.0, 0.0, 0.0, 0.0);
        assert_relative_eq!(
            r.sigma,
            expected,
            epsilon = 1e-12 * mu,
            max_relative = 1e-11
        );
        assert_relative_eq!(r.j, 1.0, epsilon = 1e-15);
    }
}

/// Perfectly plastic uniaxial stretch in one step: the trial deviator
/// 2μ ln λ (2, −1, −1)/3 returns radially onto ‖s‖ = ρ_y, so
/// τ₁₁ = K ln λ + ρ_y·2/√6, τ₂₂ = τ₃₃ = K ln λ − ρ_y/√6 (for λ > 1), and
/// Δγ = ‖s^tr‖/2μ − ρ_y/2μ.
#[test]
fn von_mises_uniaxial_return_matches_closed_form() {
    let (e, nu, rho_y) = (1e4, 0.3, 50.0);
    let law = VonMises::new(e, nu, rho_y, 0.0).unwrap();
    let (lam, mu) = lame(e, nu);
    let k = lam + 2.0 * mu / 3.0;
    let stretch: f64 = 1.2;
    let ln = stretch.ln();
    let df = Matrix3::from_diagonal(&Vector3::new(stretch, 1.0, 1.0));
    let r = update(&law, &df, &Matrix3::identity(), &MaterialState::default()).unwrap();
    assert!(r.yielded());
    let s6 = 6f64.sqrt();
    let expected = Matrix3::from_diagonal(&Vector3::new(
        k * ln + rho_y * 2.0 / s6,
        k * ln - rho_y / s6,
        k * ln - rho_y / s6,
    ));
    assert_relative_eq!(r.tau, expected, epsilon = 1e-10 * e, max_relative = 1e-12);
    let dgamma = 2.0 * mu * ln * (2f64 / 3.0).sqrt() / (2.0 * mu) - rho_y / (2.0 * mu);
    assert_relative_eq!(r.state.history.alpha, dgamma, max_relative = 1e-12);
}

#[test]
fn plane_strain_tangents_have_no_out_of_plane_coupling_in_first_index_pairs() {
    // For F with F₃₃ = 1 and no out-of-plane shear, the in-plane stress
    // does not depend on F₁₃, F₃₁, F₂₃, F₃₂ at first order (symmetry z → −z).
    let law = HenckyElastic::new(1e6, 0.3).unwrap();
    let df = embed(&Matrix2::new(1.2, 0.3, -0.1, 0.9));
    let r = update(&law, &df, &Matrix3::identity(), &MaterialState::default()).unwrap();
    for a in [
        PreviouslyConvergedTangent::tangent(&law, &r).unwrap(),
        SpatialTangent::tangent(&law, &r).unwrap(),
    ] {
        for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            for (k, l) in [(0, 2), (2, 0), (1, 2), (2, 1)] {
                assert!(a[(3 * i + j, 3 * k + l)].abs() <= 1e-9 * a.norm());
            }
        }
    }
}

proptest! {
    #![proptest_config(config())]

    /// After a plastic return the state lies on the yield surface:
    /// f = 2μ‖dev ε^e‖ − ρ_y(α) ≤ 1e-10 ρ_y, evaluated from the returned
    /// elastic strain (hardening moves the surface with α). The Kirchhoff
    /// stress itself, τ = K tr(ε^e) 1 + s, cannot carry its deviator to
    /// better than ε_mach‖τ‖ in absolute terms — for ν → 0.5 and a large
    /// volume change that rounding exceeds 1e-10 ρ_y by orders of
    /// magnitude — so f(τ) is checked against 1e-10 ρ_y plus that floor.
    #[test]
    fn plastic_return_lands_on_the_yield_surface(
        delta_f in deformation_gradient(0.2, 5.0),
        f_n in deformation_gradient(0.8, 1.25),
        rho_y in 1.0f64..200.0,
        h in prop_oneof![Just(0.0), 0.0f64..1e4],
        nu in poisson_ratio(),
    ) {
        let law = VonMises::new(1e4, nu, rho_y, h).unwrap();
        let state = MaterialState { be: f_n * f_n.transpose(), history: VonMisesHistory { alpha: 0.01 } };
        let r = update(&law, &delta_f, &f_n, &state).unwrap();
        let eps = r.law_state.elastic_strain;
        let dev_norm = eps.map(|e| e - eps.sum() / 3.0).norm();
        let f = 2.0 * law.elasticity().mu * dev_norm - law.current_yield_stress(&r.state.history);
        let rounding = 8.0 * f64::EPSILON * r.tau.norm();
        let f_principal = law.yield_function_principal(&r.law_state.tau, &r.state.history);
        let f_tensor = law.yield_function(&r.tau, &r.state.history);
        if r.yielded() {
            prop_assert!(f.abs() <= 1e-10 * rho_y, "f = {f:e}");
            prop_assert!(f_principal.abs() <= 1e-10 * rho_y + rounding, "f(τ_a) = {f_principal:e}");
            prop_assert!(f_tensor.abs() <= 1e-10 * rho_y + rounding, "f(τ) = {f_tensor:e}");
            prop_assert!(r.state.history.alpha > state.history.alpha);
        } else {
            prop_assert!(f <= 1e-12 * rho_y);
            prop_assert!(f_tensor <= 1e-12 * rho_y + rounding);
            prop_assert_eq!(r.state.history, state.history);
        }
    }

    /// ΔF = cQ on an isotropic b_eⁿ keeps the stress hydrostatic: no
    /// yielding however small the yield stress.
    #[test]
    fn hydrostatic_states_never_yield(
        c in 0.2f64..5.0,
        q in rotation(),
        a in 0.5f64..2.0,
        rho_y in 1e-6f64..1.0,
        nu in poisson_ratio(),
    ) {
        let law = VonMises::new(1e4, nu, rho_y, 0.0).unwrap();
        let state = MaterialState { be: a * Matrix3::identity(), history: VonMisesHistory::default() };
        let r = update(&law, &(c * q), &Matrix3::identity(), &state).unwrap();
        prop_assert!(!r.yielded());
        let s = r.tau - r.tau.trace() / 3.0 * Matrix3::identity();
        prop_assert!(s.norm() <= 1e-9 * r.tau.norm().max(1.0));
    }

    /// From a plastic state, a step that shrinks the deviator along the
    /// flow direction, ΔF = exp(−c N) with 2μc = u ρ_y, 0 < u < 2, is
    /// elastic: no flow, unchanged history, stress from the elastic law.
    #[test]
    fn elastic_unloading_from_a_plastic_state_is_elastic(
        delta_f in deformation_gradient(0.3, 3.0),
        q in rotation(),
        u in 0.05f64..1.95,
        nu in poisson_ratio(),
        h in prop_oneof![Just(0.0), 0.0f64..1e3],
    ) {
        let law = VonMises::new(1e4, nu, 5.0, h).unwrap();
        let mu = law.elasticity().mu;
        // Load plastically (rotate so the flow direction is arbitrary).
        let loaded = update(&law, &(q * delta_f), &Matrix3::identity(), &MaterialState::default()).unwrap();
        prop_assume!(loaded.yielded());
        let s = loaded.tau - loaded.tau.trace() / 3.0 * Matrix3::identity();
        let n = s / s.norm();
        let c = u * law.current_yield_stress(&loaded.state.history) / (2.0 * mu);
        let unload = SymSpectral::new(&(-c * n)).unwrap().exp();
        let r = update(&law, &unload, &loaded.f, &loaded.state).unwrap();
        prop_assert!(!r.yielded());
        prop_assert_eq!(r.state.history, loaded.state.history);
        let expected_norm = (1.0 - u).abs() * law.current_yield_stress(&loaded.state.history);
        let s2 = r.tau - r.tau.trace() / 3.0 * Matrix3::identity();
        // The deviator is taken from τ, whose volumetric part is of order
        // K ln J: for ν = 0.4999 (K ≈ 1.7e7 here) and stretches to 3 its
        // rounding, a few ε‖τ‖ after two updates, exceeds 1e-8 ρ_y. The
        // same floor as the yield-surface test above (8 ε‖τ‖); CI drew
        // ν = 0.4999, u = 1.87 with an error of 3.7 ε‖τ‖ (committed in
        // behaviour.proptest-regressions).
        let rounding = 8.0 * f64::EPSILON * r.tau.norm();
        prop_assert!((s2.norm() - expected_norm).abs() <= 1e-8 * law.yield_stress() + rounding);
    }

    /// Arbitrary (also inverted or singular) increments give either a typed
    /// error or finite stresses and tangents: never NaN, never a panic.
    #[test]
    fn any_input_gives_an_error_or_finite_output(
        entries in prop::array::uniform9(-5.0f64..5.0),
        rho_y in 0.1f64..100.0,
    ) {
        let df = Matrix3::from_row_slice(&entries);
        let law = VonMises::new(1e4, 0.3, rho_y, 0.0).unwrap();
        match update(&law, &df, &Matrix3::identity(), &MaterialState::default()) {
            Err(ConstitutiveError::NonPositiveJacobian { det, .. }) => prop_assert!(det <= 0.0),
            Err(other) => prop_assert!(false, "unexpected error {other}"),
            Ok(r) => {
                prop_assert!(df.determinant() > 0.0);
                prop_assert!(r.sigma.iter().chain(r.p_tilde().iter()).all(|v| v.is_finite()));
                let a = PreviouslyConvergedTangent::tangent(&law, &r).unwrap();
                let s = SpatialTangent::tangent(&law, &r).unwrap();
                prop_assert!(a.iter().chain(s.iter()).all(|v| v.is_finite()));
            }
        }
    }
}

#[test]
fn inverted_or_non_finite_kinematics_are_typed_errors() {
    let law = HenckyElastic::new(1e6, 0.3).unwrap();
    let id = Matrix3::identity();
    let fresh = MaterialState::default();
    let reflect = Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0));
    let err = update(&law, &reflect, &id, &fresh).unwrap_err();
    assert_eq!(
        err,
        ConstitutiveError::NonPositiveJacobian {
            which: "ΔF",
            det: -1.0
        }
    );
    assert!(err.to_string().contains("-1e0"), "{err}");
    let singular = Matrix3::from_diagonal(&Vector3::new(0.0, 1.0, 1.0));
    assert!(matches!(
        update(&law, &singular, &id, &fresh),
        Err(ConstitutiveError::NonPositiveJacobian { det, .. }) if det == 0.0
    ));
    assert!(matches!(
        update(&law, &id, &reflect, &fresh),
        Err(ConstitutiveError::NonPositiveJacobian { which: "F_n", .. })
    ));
    let mut nan = id;
    nan[(1, 2)] = f64::NAN;
    assert!(matches!(
        update(&law, &nan, &id, &fresh),
        Err(ConstitutiveError::NonFinite { which: "ΔF", .. })
    ));
    let mut inf = id;
    inf[(0, 0)] = f64::INFINITY;
    assert!(matches!(
        update(&law, &id, &inf, &fresh),
        Err(ConstitutiveError::NonFinite { which: "F_n", .. })
    ));
    let bad_be = MaterialState {
        be: nan,
        history: (),
    };
    assert!(matches!(
        update(&law, &id, &id, &bad_be),
        Err(ConstitutiveError::NonFinite { which: "b_e^n", .. })
    ));
    let indefinite = MaterialState {
        be: reflect,
        history: (),
    };
    assert!(matches!(
        update(&law, &id, &id, &indefinite),
        Err(ConstitutiveError::NotPositiveDefinite { eigenvalue }) if eigenvalue == -1.0
    ));
}

#[test]
fn invalid_material_parameters_are_typed_errors_naming_the_value() {
    for e in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let err = HenckyElastic::new(e, 0.3).unwrap_err();
        assert!(matches!(
            err,
            ConstitutiveError::InvalidYoungsModulus { .. }
        ));
        assert!(err.to_string().contains(&format!("{e}")), "{err}");
    }
    for nu in [0.5, -1.0, 0.7, -2.0, f64::NAN] {
        let err = VonMises::new(1.0, nu, 1.0, 0.0).unwrap_err();
        assert!(matches!(err, ConstitutiveError::InvalidPoissonRatio { .. }));
        assert!(err.to_string().contains(&format!("{nu}")), "{err}");
    }
    for y in [0.0, -5.0, f64::NAN] {
        let err = VonMises::new(1.0, 0.3, y, 0.0).unwrap_err();
        assert!(matches!(err, ConstitutiveError::InvalidYieldStress { .. }));
        assert!(err.to_string().contains(&format!("{y}")), "{err}");
    }
    for h in [-1.0, f64::INFINITY] {
        let err = VonMises::new(1.0, 0.3, 1.0, h).unwrap_err();
        assert!(matches!(err, ConstitutiveError::InvalidHardening { .. }));
    }
    assert!(HenckyElastic::new(1.0, 0.4999).is_ok());
    assert!(VonMises::new(1.0, -0.99, 1.0, 0.0).is_ok());
}

proptest! {
    #![proptest_config(config())]

    /// The Neo-Hookean law through the log-strain driver equals the
    /// closed form τ = μ(FFᵀ − 1) + λ ln J 1 computed from F directly, for
    /// stretches 0.2–5 with large rotations, both in one step and in two
    /// (the second from the first's converged b^e), and its principal
    /// stresses are the derivatives of its energy.
    #[test]
    fn neo_hookean_matches_its_closed_form_and_its_energy(
        f1 in deformation_gradient(0.2, 5.0),
        f2 in deformation_gradient(0.5, 2.0),
        e in 1e3f64..1e7,
        nu in poisson_ratio(),
    ) {
        let law = mpm_constitutive::NeoHookean::new(e, nu).unwrap();
        let one = update(&law, &f1, &Matrix3::identity(), &MaterialState::default()).unwrap();
        let want = law.kirchhoff_of_f(&f1);
        prop_assert!((one.tau - want).norm() <= 1e-9 * want.norm().max(e), "{} vs {}", one.tau, want);
        let two = update(&law, &f2, &one.f, &one.state).unwrap();
        let want = law.kirchhoff_of_f(&(f2 * f1));
        prop_assert!((two.tau - want).norm() <= 1e-9 * want.norm().max(e), "{} vs {}", two.tau, want);
        // τ_a = ∂ψ/∂ε_a by central differences of the energy.
        let eps = one.trial_be.values.map(|b| 0.5 * b.ln());
        let state = mpm_constitutive::LogStrainLaw::return_map(
            &law,
            &SymSpectral::new(&Matrix3::from_diagonal(&eps)).unwrap(),
            &(),
        );
        for a in 0..3 {
            let h = 1e-6;
            let (mut up, mut down) = ([eps[0], eps[1], eps[2]], [eps[0], eps[1], eps[2]]);
            up[a] += h;
            down[a] -= h;
            let derivative = (law.energy(&up) - law.energy(&down)) / (2.0 * h);
            let expected = SymSpectral::new(&Matrix3::from_diagonal(&eps)).unwrap().compose(&state.tau);
            prop_assert!(
                (derivative - expected[(a, a)]).abs() <= 1e-6 * expected.norm().max(e),
                "{a}: {derivative} vs {}",
                expected[(a, a)]
            );
        }
    }
}
