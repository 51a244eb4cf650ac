//! The incremental (explicit-solver) stress updates: the closed-form
//! Neo-Hookean update against the spectral driver, objectivity and the
//! absence of rate-form drift, the stored energy as the potential of the
//! stress, the wave modulus with the corrected bulk modulus, a set of
//! materials answering as each of its laws.
#![allow(clippy::unwrap_used)]

use mpm_constitutive::{
    ConstitutiveError, HenckyElastic, IncrementalLaw, MaterialSet, MaterialState, NeoHookean,
    Spectral, Tagged, VonMises,
};
use mpm_constitutive_proptest::strategies::{config, deformation_gradient, rotation};
use nalgebra::Matrix3;
use proptest::prelude::*;

fn rel(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    (a - b).norm() / b.norm().max(1e-300)
}

proptest! {
    #![proptest_config(config())]

    /// Two random increments (stretches 0.2–5, any rotation, repeated
    /// eigenvalues among the draws): the closed form and the spectral
    /// driver give the same stress, state and energy.
    #[test]
    fn closed_form_neo_hookean_equals_the_spectral_driver(
        f1 in deformation_gradient(0.2, 5.0),
        f2 in deformation_gradient(0.5, 2.0),
        nu in 0.0f64..0.49,
    ) {
        let law = NeoHookean::new(1e6, nu).unwrap();
        let spectral = Spectral::new(law).unwrap();
        let (mut a, mut b) = (MaterialState::<()>::default(), MaterialState::<()>::default());
        for df in [f1, f2] {
            let ta = law.update(&df, &mut a).unwrap();
            let tb = spectral.update(&df, &mut b).unwrap();
            prop_assert!(rel(&ta, &tb) < 1e-9, "{ta} vs {tb}");
            prop_assert!(rel(&a.be, &b.be) < 1e-10);
        }
        let (ea, eb) = (law.stored_energy(&a).unwrap(), spectral.stored_energy(&b).unwrap());
        prop_assert!((ea - eb).abs() <= 1e-9 * ea.abs().max(1.0) * 1e6, "{ea} vs {eb}");
    }

    /// A rigid rotation increment rotates the stress and leaves the energy.
    #[test]
    fn rotation_increments_are_objective(f in deformation_gradient(0.5, 2.0), r in rotation()) {
        let law = NeoHookean::new(1e6, 0.3).unwrap();
        let hencky = Spectral::new(HenckyElastic::new(1e6, 0.3).unwrap()).unwrap();
        let mut s = MaterialState::<()>::default();
        let tau = law.update(&f, &mut s).unwrap();
        let e0 = law.stored_energy(&s).unwrap();
        let rotated = law.update(&r, &mut s).unwrap();
        prop_assert!(rel(&rotated, &(r * tau * r.transpose())) < 1e-10);
        prop_assert!((law.stored_energy(&s).unwrap() - e0).abs() <= 1e-10 * e0.abs().max(1.0));
        let mut h = MaterialState::<()>::default();
        let tau = hencky.update(&f, &mut h).unwrap();
        let rotated = hencky.update(&r, &mut h).unwrap();
        prop_assert!(rel(&rotated, &(r * tau * r.transpose())) < 1e-9);
    }
}

/// Many small increments around a closed loop (stretch, shear, rotate,
/// then undo each in reverse): the stress returns to zero to rounding. A
/// rate-form update (MPoint eqs. 42–44 with a Jaumann or no rate) drifts.
#[test]
fn closed_loops_return_to_zero_stress() {
    let n = 2000;
    let step = |k: usize| -> Matrix3<f64> {
        let t = 1.0 / n as f64;
        match k {
            0 => Matrix3::new(1.0 + 0.8 * t, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
            1 => Matrix3::new(1.0, 0.7 * t, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
            _ => {
                let a = std::f64::consts::PI * t;
                Matrix3::new(a.cos(), -a.sin(), 0.0, a.sin(), a.cos(), 0.0, 0.0, 0.0, 1.0)
            }
        }
    };
    let hencky = Spectral::new(HenckyElastic::new(1e6, 0.3).unwrap()).unwrap();
    let neo = NeoHookean::new(1e6, 0.3).unwrap();
    let mut h = MaterialState::<()>::default();
    let mut s = MaterialState::<()>::default();
    let mut peak: f64 = 0.0;
    for k in [0, 1, 2] {
        for _ in 0..n {
            let d = step(k);
            hencky.update(&d, &mut h).unwrap();
            peak = peak.max(neo.update(&d, &mut s).unwrap().norm());
        }
    }
    for k in [2, 1, 0] {
        for _ in 0..n {
            let d = step(k).try_inverse().unwrap();
            hencky.update(&d, &mut h).unwrap();
            neo.update(&d, &mut s).unwrap();
        }
    }
    let last_h = hencky.update(&Matrix3::identity(), &mut h).unwrap();
    let last_s = neo.update(&Matrix3::identity(), &mut s).unwrap();
    assert!(
        peak > 1e5,
        "the loop must load the material: peak |τ| = {peak}"
    );
    assert!(
        last_h.norm() < 1e-6 * peak,
        "Hencky residual stress {last_h}"
    );
    assert!(
        last_s.norm() < 1e-6 * peak,
        "Neo-Hookean residual stress {last_s}"
    );
}

/// The stored energy is the potential of the stress: for a small
/// increment with symmetric velocity gradient d, Δψ = τ : d Δt to second
/// order (τ per unit reference volume, i.e. Kirchhoff).
#[test]
fn stored_energy_rate_is_the_stress_power() {
    fn check<L: IncrementalLaw>(name: &str, law: &L) {
        let d = Matrix3::new(0.3, 0.1, -0.2, 0.1, -0.5, 0.05, -0.2, 0.05, 0.25);
        let mut s = L::State::default();
        law.update(
            &Matrix3::new(1.2, 0.3, 0.0, -0.1, 0.9, 0.1, 0.0, 0.2, 1.05),
            &mut s,
        )
        .unwrap();
        let mut errors = Vec::new();
        for dt in [1e-3, 5e-4] {
            let mut a = s;
            let tau0 = law.update(&Matrix3::identity(), &mut a).unwrap();
            let e0 = law.stored_energy(&a).unwrap();
            // ΔF = exp(d Δt) to second order.
            let df = Matrix3::identity() + d * dt + d * d * (0.5 * dt * dt);
            let tau1 = law.update(&df, &mut a).unwrap();
            let e1 = law.stored_energy(&a).unwrap();
            let power = 0.5 * (tau0 + tau1).dot(&d) * dt;
            errors.push(((e1 - e0) - power).abs() / power.abs());
        }
        // The trapezoidal power is exact to O(Δt²) relative: a quarter on halving.
        assert!(errors[0] < 1e-5, "{name}: {errors:?}");
        assert!(
            errors[1] < 0.3 * errors[0],
            "{name}: not second order: {errors:?}"
        );
    }
    check("neo-hookean", &NeoHookean::new(1e6, 0.3).unwrap());
    check(
        "hencky",
        &Spectral::new(HenckyElastic::new(1e6, 0.3).unwrap()).unwrap(),
    );
    check(
        "neo-hookean (spectral)",
        &Spectral::new(NeoHookean::new(1e6, 0.3).unwrap()).unwrap(),
    );
}

#[test]
fn inverting_increments_are_refused_and_leave_the_state() {
    let law = NeoHookean::new(1e6, 0.3).unwrap();
    let mut s = MaterialState::<()>::default();
    law.update(&Matrix3::from_diagonal_element(1.1), &mut s)
        .unwrap();
    let before = s;
    let flip = Matrix3::new(-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    let err = law.update(&flip, &mut s).unwrap_err();
    assert!(
        matches!(err, ConstitutiveError::NonPositiveJacobian { .. }),
        "{err}"
    );
    assert_eq!(s, before);
    let spectral = Spectral::new(law).unwrap();
    assert!(spectral.update(&flip, &mut s).is_err());
    assert_eq!(s, before);
    let nan = Matrix3::from_element(f64::NAN);
    assert!(matches!(
        law.update(&nan, &mut s),
        Err(ConstitutiveError::NonFinite { .. })
    ));
}

/// Eq. 46 with K = E/(3(1−2ν)): K + 4G/3 = E(1−ν)/((1+ν)(1−2ν)). The
/// notes' K = E/(3(1+ν)) would give, at ν = 0.3, a modulus 43 % too low,
/// a wave speed 24 % too low and a CFL step 32 % too long — the misprint
/// this test pins.
#[test]
fn wave_modulus_uses_the_correct_bulk_modulus() {
    let (e, nu) = (1e6, 0.3);
    let exact = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let neo = NeoHookean::new(e, nu).unwrap();
    assert!((neo.p_wave_modulus() - exact).abs() < 1e-9 * exact);
    let vm = Spectral::new(VonMises::new(e, nu, 1e3, 0.0).unwrap()).unwrap();
    assert!((vm.p_wave_modulus() - exact).abs() < 1e-9 * exact);
    let misprint = e / (3.0 * (1.0 + nu)) + 4.0 / 3.0 * e / (2.0 * (1.0 + nu));
    assert!(misprint < 0.6 * exact, "{misprint} vs {exact}");
    assert!(matches!(
        Spectral::with_p_wave_modulus(neo, -1.0),
        Err(ConstitutiveError::InvalidWaveModulus { .. })
    ));
}

/// A set of materials updates, stores energy and reports the wave modulus
/// of each point's own material, bit for bit as that law alone; the set's
/// modulus is the largest.
#[test]
fn a_material_set_answers_as_each_points_law() {
    let laws = vec![
        NeoHookean::new(1e5, 0.3).unwrap(),
        NeoHookean::new(1e11, 0.2).unwrap(),
        NeoHookean::new(3e7, 0.45).unwrap(),
    ];
    let set = MaterialSet::new(laws.clone()).unwrap();
    let df = Matrix3::new(1.02, 0.01, 0.0, -0.005, 0.97, 0.003, 0.0, 0.002, 1.01);
    for (k, law) in laws.iter().enumerate() {
        let mut alone = MaterialState::<()>::default();
        let mut tagged = Tagged::new(k as u32, MaterialState::<()>::default());
        for _ in 0..3 {
            let want = law.update(&df, &mut alone).unwrap();
            let got = set.update(&df, &mut tagged).unwrap();
            assert_eq!(got, want, "material {k}");
        }
        assert_eq!(tagged.material, k as u32);
        assert_eq!(tagged.inner, alone);
        assert_eq!(
            set.stored_energy(&tagged).unwrap(),
            law.stored_energy(&alone).unwrap()
        );
        assert_eq!(set.point_p_wave_modulus(&tagged), law.p_wave_modulus());
        // A law of one material reports its own modulus for every point.
        assert_eq!(law.point_p_wave_modulus(&alone), law.p_wave_modulus());
    }
    assert_eq!(set.p_wave_modulus(), laws[1].p_wave_modulus());
    // An inverting increment is refused and leaves the tagged state.
    let mut tagged = Tagged::new(2, MaterialState::<()>::default());
    let before = tagged;
    let flip = Matrix3::from_diagonal(&nalgebra::Vector3::new(-1.0, 1.0, 1.0));
    assert!(set.update(&flip, &mut tagged).is_err());
    assert_eq!(tagged, before);
}

/// Cam-Clay's stiffness grows with the pressure, so the explicit step
/// takes each point's wave speed at its own state (issue 43): the P-wave
/// modulus of a point is p/κ̂ + 4G/3 at its elastic volumetric strain (to
/// rounding), not the modulus given for the law, and a material set
/// answers with each point's own.
#[test]
fn cam_clay_points_have_the_wave_modulus_of_their_pressure() {
    use mpm_constitutive::{ModifiedCamClay, ModifiedCamClayHistory};
    let (kappa, g) = (0.05, 5.0e6);
    let clay = ModifiedCamClay::new(0.2, kappa, 1.2, g, 1.0e5).unwrap();
    let law = Spectral::with_p_wave_modulus(clay, clay.p_wave_modulus_at(1.0e5).unwrap()).unwrap();
    let set = MaterialSet::new(vec![law, law]).unwrap();
    let mut moduli = Vec::new();
    for p in [2.0e4, 1.0e5, 8.0e5] {
        let tau = nalgebra::Vector3::new(-p - 1.0e4, -p + 5.0e3, -p + 5.0e3);
        let eps = clay.elastic_strain_of(&tau).unwrap();
        let state = MaterialState {
            be: Matrix3::from_diagonal(&eps.map(|e| (2.0 * e).exp())),
            history: ModifiedCamClayHistory::new(2.0 * p),
        };
        let expected = p / kappa + 4.0 / 3.0 * g;
        let got = law.point_p_wave_modulus(&state);
        assert!(
            (got - expected).abs() <= 1e-12 * expected,
            "p = {p}: {got} against {expected}"
        );
        assert_eq!(set.point_p_wave_modulus(&Tagged::new(1, state)), got);
        moduli.push(got);
    }
    assert!(moduli[0] < law.p_wave_modulus() && law.p_wave_modulus() < moduli[2]);
}
