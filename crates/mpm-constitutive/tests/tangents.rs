//! Finite-difference verification of every tangent of the crate
//! (Coombs 2020, Appendix A), over random deformation gradients with
//! rotations up to 180°, principal stretches 0.2–5, repeated and nearly
//! repeated eigenvalues, ν up to 0.4999, elastic and yielding states,
//! perfect and hardening plasticity.
#![allow(clippy::unwrap_used)]

use mpm_constitutive::tensor::Tensor4;
use mpm_constitutive::verification::{
    SpatialErrors, TOLERANCE, check_algorithmic_tangent, check_previously_converged, check_spatial,
    hencky_strain, jacobian, plastic_scale, relative_error, sym_unit,
};
use mpm_constitutive::{
    ConsistentTangent, HenckyElastic, LogStrainLaw, MaterialState, PreviouslyConvergedTangent,
    SymSpectral, VonMises, VonMisesHistory, update,
};
use mpm_constitutive_proptest::strategies::{
    config, converged_state, deformation_gradient, poisson_ratio, rotation,
};
use nalgebra::Matrix3;
use proptest::prelude::*;

/// Required agreement of analytic and finite-difference tangents.
const TOL: f64 = 1e-6;
/// Finite-difference step relative to the smallest principal stretch (or
/// eigenvalue) of the argument; see
/// `mpm_constitutive::verification::central_difference`.
const STEP: f64 = 1e-4;

/// The exported defaults that `law_tangent_properties!` uses are the ones
/// of these tests.
#[test]
fn exported_tolerance_and_step_are_the_tests_own() {
    assert_eq!(TOLERANCE, TOL);
    assert_eq!(mpm_constitutive::verification::STEP, STEP);
    assert_eq!(mpm_constitutive_proptest::strategies::CASES, 256);
}

/// A von Mises model whose yield stress is a random fraction of the trial
/// deviatoric stress, so that both elastic and yielding steps are drawn.
fn von_mises_for(
    e: f64,
    nu: f64,
    fraction: f64,
    hardening_ratio: f64,
    delta_f: &Matrix3<f64>,
    be_n: &Matrix3<f64>,
    alpha_n: f64,
) -> VonMises {
    let elastic = HenckyElastic::new(e, nu).unwrap();
    let trial = update(
        &elastic,
        delta_f,
        &Matrix3::identity(),
        &MaterialState {
            be: *be_n,
            history: (),
        },
    )
    .unwrap();
    let s = trial.tau - trial.tau.trace() / 3.0 * Matrix3::identity();
    let mu = elastic.elasticity().mu;
    let h = hardening_ratio * 2.0 * mu;
    let rho_y = (fraction * s.norm() - h * alpha_n).max(1e-3 * mu);
    VonMises::new(e, nu, rho_y, h).unwrap()
}

// The macro a downstream law uses, instantiated for the crate's two laws:
// the yield stress E/2 gives elastic and yielding steps over the drawn
// stretches 0.2–5.
mpm_constitutive_proptest::law_tangent_properties!(hencky_macro, HenckyElastic::new);
mpm_constitutive_proptest::law_tangent_properties!(
    neo_hookean_macro,
    mpm_constitutive::NeoHookean::new
);
mpm_constitutive_proptest::law_tangent_properties!(von_mises_macro, |e, nu| {
    VonMises::new(e, nu, 0.5 * e, 0.1 * e)
});

proptest! {
    #![proptest_config(config())]

    #[test]
    fn hencky_previously_converged_tangent_matches_finite_differences(
        delta_f in deformation_gradient(0.2, 5.0),
        f_n in deformation_gradient(0.8, 1.25),
        e in 1e3f64..1e7,
        nu in poisson_ratio(),
    ) {
        let law = HenckyElastic::new(e, nu).unwrap();
        let state = MaterialState { be: f_n * f_n.transpose(), history: () };
        let err = check_previously_converged(&law, &delta_f, &f_n, &state, STEP).unwrap().unwrap();
        prop_assert!(err <= TOL, "relative error {err:e}");
    }

    #[test]
    fn von_mises_previously_converged_tangent_matches_finite_differences(
        delta_f in deformation_gradient(0.2, 5.0),
        (f_n, be_n) in converged_state(),
        nu in poisson_ratio(),
        fraction in 0.05f64..2.0,
        hardening_ratio in prop_oneof![Just(0.0), 0.0f64..1.0],
        alpha_n in prop_oneof![Just(0.0), 0.0f64..0.2],
    ) {
        let law = von_mises_for(1e4, nu, fraction, hardening_ratio, &delta_f, &be_n, alpha_n);
        let state = MaterialState { be: be_n, history: VonMisesHistory { alpha: alpha_n } };
        let err = check_previously_converged(&law, &delta_f, &f_n, &state, STEP).unwrap();
        prop_assume!(err.is_some(), "stencil crosses the yield surface");
        let err = err.unwrap();
        prop_assert!(err <= TOL, "relative error {err:e}");
    }

    #[test]
    fn hencky_spatial_tangent_matches_finite_differences(
        delta_f in deformation_gradient(0.2, 5.0),
        f_n in deformation_gradient(0.8, 1.25),
        nu in poisson_ratio(),
    ) {
        let law = HenckyElastic::new(2e5, nu).unwrap();
        let state = MaterialState { be: f_n * f_n.transpose(), history: () };
        let SpatialErrors { push_forward: push, cauchy_derivative: literal } =
            check_spatial(&law, &delta_f, &f_n, &state, STEP).unwrap().unwrap();
        prop_assert!(push <= TOL, "push-forward relative error {push:e}");
        prop_assert!(literal <= TOL, "(dσ/dF)F relative error {literal:e}");
    }

    #[test]
    fn von_mises_spatial_tangent_matches_finite_differences(
        delta_f in deformation_gradient(0.2, 5.0),
        (f_n, be_n) in converged_state(),
        nu in poisson_ratio(),
        fraction in 0.05f64..2.0,
        hardening_ratio in prop_oneof![Just(0.0), 0.0f64..1.0],
    ) {
        let law = von_mises_for(1e4, nu, fraction, hardening_ratio, &delta_f, &be_n, 0.0);
        let state = MaterialState { be: be_n, history: VonMisesHistory::default() };
        let errs = check_spatial(&law, &delta_f, &f_n, &state, STEP).unwrap();
        prop_assume!(errs.is_some(), "stencil crosses the yield surface");
        let SpatialErrors { push_forward: push, cauchy_derivative: literal } = errs.unwrap();
        prop_assert!(push <= TOL, "push-forward relative error {push:e}");
        prop_assert!(literal <= TOL, "(dσ/dF)F relative error {literal:e}");
    }

    #[test]
    fn algorithmic_tangent_matches_finite_differences(
        strain_f in deformation_gradient(0.2, 5.0),
        nu in poisson_ratio(),
        fraction in 0.05f64..2.0,
        hardening_ratio in prop_oneof![Just(0.0), 0.0f64..1.0],
    ) {
        // ε^tr = ½ ln(F Fᵀ): a random symmetric strain with the same
        // eigenvalue structure as the kinematics produce.
        let eps = hencky_strain(&strain_f).unwrap();
        let elastic = HenckyElastic::new(1e4, nu).unwrap();
        let (tau_e, _) = elastic.kirchhoff_stress(&eps, &()).unwrap();
        let s_norm = (tau_e - tau_e.trace() / 3.0 * Matrix3::identity()).norm();
        let mu = elastic.elasticity().mu;
        let law = VonMises::new(1e4, nu, (fraction * s_norm).max(1e-3 * mu), hardening_ratio * 2.0 * mu).unwrap();
        let history = VonMisesHistory::default();
        let trial = SymSpectral::new(&eps).unwrap();
        let state = law.return_map(&trial, &history);
        let h = STEP * plastic_scale(&trial.values, state.yielded);
        let err = check_algorithmic_tangent(&law, &eps, &history, STEP).unwrap();
        prop_assume!(err.is_some(), "stencil crosses the yield surface");
        let err = err.unwrap();
        prop_assert!(err <= TOL, "D_alg relative error {err:e} (yielded: {})", state.yielded);
        // Hencky: D^e exactly.
        let d_e = elastic.algorithmic_tangent(&trial, &(), &elastic.return_map(&trial, &()));
        let fd_e = jacobian(|de| Some(elastic.kirchhoff(&(eps + de))), sym_unit, h).unwrap();
        prop_assert!(relative_error(&d_e, &fd_e) <= TOL);
    }

    #[test]
    fn dlog_matches_finite_differences(f in deformation_gradient(0.2, 5.0)) {
        let b = f * f.transpose();
        let s = SymSpectral::new(&b).unwrap();
        let l = s.dlog().unwrap();
        let h = STEP * s.min_value();
        let fd = jacobian(|db| SymSpectral::new(&(b + db)).unwrap().log().ok(), sym_unit, h).unwrap();
        let err = relative_error(&l, &fd);
        prop_assert!(err <= TOL, "L relative error {err:e}");
    }

    #[test]
    fn cauchy_stress_is_objective(
        delta_f in deformation_gradient(0.2, 5.0),
        (f_n, be_n) in converged_state(),
        q in rotation(),
        nu in poisson_ratio(),
        fraction in 0.05f64..2.0,
    ) {
        let law = von_mises_for(1e4, nu, fraction, 0.1, &delta_f, &be_n, 0.0);
        let state = MaterialState { be: be_n, history: VonMisesHistory::default() };
        let r = update(&law, &delta_f, &f_n, &state).unwrap();
        let rq = update(&law, &(q * delta_f), &f_n, &state).unwrap();
        let expected = q * r.sigma * q.transpose();
        let err = (rq.sigma - expected).norm() / r.sigma.norm().max(1e-12 * law.yield_stress());
        prop_assert!(err <= 1e-10, "objectivity error {err:e}");
        prop_assert_eq!(r.yielded(), rq.yielded());
        // The previously converged tangent obeys Ã(QΔF) = Q·Ã(ΔF) on the first index.
        let a = PreviouslyConvergedTangent::tangent(&law, &r).unwrap();
        let aq = PreviouslyConvergedTangent::tangent(&law, &rq).unwrap();
        let qa = rotate_first_and_third(&a, &q);
        prop_assert!(relative_error(&aq, &qa) <= 1e-9);
    }
}

/// (Q·Ã)_ijkl = Q_ia Ã_ajbl Q_kb: P̃(QΔF) = Q P̃(ΔF), and a perturbation
/// dΔF of QΔF is Q (QᵀdΔF).
fn rotate_first_and_third(a: &Tensor4, q: &Matrix3<f64>) -> Tensor4 {
    use mpm_constitutive::tensor::idx;
    Tensor4::from_fn(|r, c| {
        let (i, j, k, l) = (r / 3, r % 3, c / 3, c % 3);
        let mut v = 0.0;
        for p in 0..3 {
            for m in 0..3 {
                v += q[(i, p)] * a[(idx(p, j), idx(m, l))] * q[(k, m)];
            }
        }
        v
    })
}

// A material set answers with the law of the point's tag (the default
// history: material 0), so its tangents pass the same checks.
mpm_constitutive_proptest::law_tangent_properties!(material_set_macro, |e, nu| {
    mpm_constitutive::MaterialSet::new(vec![
        mpm_constitutive::VonMises::new(e, nu, 1e-3 * e, 0.1 * e)?,
        mpm_constitutive::VonMises::new(10.0 * e, nu, e, 0.0)?,
    ])
});

proptest! {
    #![proptest_config(config())]

    /// A load step starts at ΔF = 1, where a point that yielded in the last
    /// step is read again on the yield surface: the return map has a kink
    /// there and takes the state as elastic. The loading tangent
    /// (`LogStrainLaw::loading_tangent`, the first solve of a
    /// displacement-driven step) must be the one-sided derivative for
    /// plastic loading: Ã : δ equals the derivative of P̃(1 + tδ) for
    /// t → 0⁺ along any δ that loads, N : δ > 0. The derivative is the
    /// forward difference extrapolated twice (Richardson, error O(t³)),
    /// t = 1e-4 against elastic strains near ρ_y/2μ ≈ 0.065: measured
    /// errors up to 1.9e-9 over 3000 cases. The algorithmic tangent (the
    /// elastic branch) misses by 2μ·2μ/(2μ+H) (N : δ) N; the test asserts
    /// that this miss exceeds ten times the tolerance, so the check
    /// discriminates on every case (smallest miss over 3000 cases: 4.3e-5).
    #[test]
    fn the_loading_tangent_on_the_yield_surface_is_the_one_sided_derivative(
        delta_f in deformation_gradient(0.5, 2.0),
        q in rotation(),
        g in proptest::array::uniform9(-1.0f64..1.0),
        nu in poisson_ratio(),
        hardening_ratio in prop_oneof![Just(0.0), 0.0f64..1.0],
    ) {
        let elastic = HenckyElastic::new(1e4, nu).unwrap();
        let mu = elastic.elasticity().mu;
        let law = VonMises::new(1e4, nu, 500.0, hardening_ratio * 2.0 * mu).unwrap();
        let one = Matrix3::identity();
        let loaded = update(&law, &(q * delta_f), &one, &MaterialState::default()).unwrap();
        prop_assume!(loaded.yielded());
        let start = update(&law, &one, &loaded.f, &loaded.state).unwrap();
        prop_assert!(!start.yielded(), "the converged state read again must not flow");
        let a = PreviouslyConvergedTangent::loading_tangent(&law, &start).unwrap();
        let elastic_branch = PreviouslyConvergedTangent::tangent(&law, &start).unwrap();

        let s = start.tau - start.tau.trace() / 3.0 * one;
        let n = s / s.norm();
        let mut delta = 0.5 * Matrix3::from_iterator(g);
        let load = n.dot(&delta);
        if load < 0.5 {
            delta += (0.5 - load) * n;
        }
        let p = |t: f64| {
            let r = update(&law, &(one + t * delta), &loaded.f, &loaded.state).unwrap();
            assert!(r.yielded(), "δ loads plastically for t > 0");
            (r.p_tilde() - start.p_tilde()) / t
        };
        let t = 1e-4;
        let (d1, d2, d4) = (p(t), p(t / 2.0), p(t / 4.0));
        let derivative = (8.0 * d4 - 6.0 * d2 + d1) / 3.0;
        let tangent = mpm_constitutive::tensor::contract(&a, &delta);
        let err = (tangent - derivative).norm() / derivative.norm();
        prop_assert!(err <= TOL, "relative error {err:e}");
        // The algorithmic tangent is the elastic branch there.
        let elastic = mpm_constitutive::tensor::contract(&elastic_branch, &delta);
        let miss = (elastic - derivative).norm() / derivative.norm();
        prop_assert!(miss > 10.0 * TOL, "the elastic branch misses by only {miss:e}");
    }
}
