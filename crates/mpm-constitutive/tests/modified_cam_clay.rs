//! Modified Cam-Clay: laboratory paths against their closed forms (exact
//! at every step, whatever the step size, with the exponential hardening
//! and the backward-Euler return), the consistent tangents of every
//! regime against finite differences, refused parameters and extreme
//! inputs. Paths run with [`PointDriver`], tension positive; $p$ and $q$
//! are [`invariants`] (compression positive).

use mpm_constitutive::modified_cam_clay::invariants;
use mpm_constitutive::point_driver::{Control, PointDriver};
use mpm_constitutive::verification::{
    STEP, TOLERANCE, check_algorithmic_tangent, check_loading_tangent, check_previously_converged,
    check_spatial,
};
use mpm_constitutive::{
    CamClayRegime, LogStrainLaw, MaterialState, ModifiedCamClay, ModifiedCamClayHistory,
    SymSpectral,
};
use nalgebra::{Matrix3, Rotation3, Vector3};

const LAMBDA: f64 = 0.2;
const KAPPA: f64 = 0.05;
const M: f64 = 1.2;
const G: f64 = 1.0e6;
/// Reference pressure at zero elastic volumetric strain (Pa): not the
/// initial pressure, so the initial elastic strain is not zero.
const P_REF: f64 = 1.0e3;
const P0: f64 = 100.0e3;
/// The driver's stress tolerance (Pa).
const STRESS_TOL: f64 = 1e-6;

fn law() -> ModifiedCamClay {
    ModifiedCamClay::new(LAMBDA, KAPPA, M, G, P_REF).unwrap()
}

/// A point at the principal stress `tau` with over-consolidation ratio
/// `ocr`.
fn start(law: &ModifiedCamClay, tau: Vector3<f64>, ocr: f64) -> PointDriver<'_, ModifiedCamClay> {
    let strain = law.elastic_strain_of(&tau).unwrap();
    let history = law.history_for(&tau, ocr).unwrap();
    let point = PointDriver::new(law, strain, history);
    let err = (point.stress - tau).norm() / tau.norm();
    assert!(err < 1e-14, "initial stress off by {err:e}");
    point
}

fn isotropic(law: &ModifiedCamClay, ocr: f64) -> PointDriver<'_, ModifiedCamClay> {
    start(law, Vector3::from_element(-P0), ocr)
}

fn relative(got: f64, expected: f64) -> f64 {
    (got - expected).abs() / expected.abs()
}

fn assert_relative(got: f64, expected: f64, tol: f64, what: &str) {
    let err = relative(got, expected);
    assert!(
        err <= tol,
        "{what}: {got} against {expected} (relative {err:e})"
    );
}

/// Undrained triaxial compression (volume held: lateral strains $-\tfrac12$
/// of the axial one) by `steps` axial increments `de`; returns the largest
/// relative error of $p/p_0 = (\mathrm{OCR}\,M^2/(M^2 + \eta^2))^{(\hat
/// \lambda - \hat\kappa)/\hat\lambda}$ over the plastic steps.
fn undrained(point: &mut PointDriver<'_, ModifiedCamClay>, de: f64, steps: usize, ocr: f64) -> f64 {
    let mut worst: f64 = 0.0;
    let exponent = (LAMBDA - KAPPA) / LAMBDA;
    for _ in 0..steps {
        let lateral = Control::Strain(-0.5 * de);
        let state = point
            .step([lateral, lateral, Control::Strain(de)], STRESS_TOL)
            .unwrap();
        if state.yielded {
            let (p, q) = invariants(&point.stress);
            let eta = q / p;
            let expected = (ocr * M * M / (M * M + eta * eta)).powf(exponent);
            worst = worst.max(relative(p / P0, expected));
        }
    }
    worst
}

/// Drained triaxial compression (lateral stresses held at $-p_0$) by
/// `steps` axial increments `de`; returns the largest error of the stress
/// path $q = 3(p - p_0)$ relative to $p_0$.
fn drained(point: &mut PointDriver<'_, ModifiedCamClay>, de: f64, steps: usize) -> f64 {
    let mut worst: f64 = 0.0;
    for _ in 0..steps {
        let lateral = Control::Stress(-P0);
        point
            .step([lateral, lateral, Control::Strain(de)], STRESS_TOL)
            .unwrap();
        let (p, q) = invariants(&point.stress);
        assert!(p.is_finite() && q.is_finite());
        worst = worst.max((q - 3.0 * (p - P0)).abs() / P0);
    }
    worst
}

/// Normally consolidated isotropic compression from $p_0$ to $4p_0$ under
/// stress control: $p_c = p$ after every step, the elastic part of
/// $\varepsilon_v$ is $-\hat\kappa\ln(p/p_0)$ and the plastic part
/// $-(\hat\lambda - \hat\kappa)\ln(p/p_0)$, so the total is
/// $-\hat\lambda\ln(p/p_0)$, $-\hat\lambda\ln 4 = -0.27726$ at the end.
#[test]
fn isotropic_compression_follows_the_normal_compression_line() {
    let law = law();
    let mut point = isotropic(&law, 1.0);
    let steps = 30;
    let mut worst: f64 = 0.0;
    for k in 1..=steps {
        let target = -P0 * (1.0 + 3.0 * k as f64 / steps as f64);
        let state = point
            .step([Control::Stress(target); 3], STRESS_TOL)
            .unwrap();
        assert!(state.yielded, "step {k} elastic");
        let (p, _) = invariants(&point.stress);
        // ε_v = -λ̂ ln(p/p0) along the NCL, and p_c = p (isotropic).
        worst = worst.max(relative(point.strain.sum(), -LAMBDA * (p / P0).ln()));
        worst = worst.max(relative(point.history.preconsolidation, p));
    }
    assert!(worst <= 1e-10, "NCL error {worst:e}");
    assert_relative(
        point.strain.sum(),
        -LAMBDA * 4f64.ln(),
        1e-10,
        "ε_v at 4 p0",
    );
    assert_relative(
        -LAMBDA * 4f64.ln(),
        -0.277_258_872_223_978_1,
        1e-15,
        "λ̂ ln 4",
    );
}

/// Undrained: $\varepsilon^p_v = -\Delta\varepsilon^e_v$, so $p_c/p_{c0} =
/// (p/p_0)^{-\hat\kappa/(\hat\lambda - \hat\kappa)}$; on the surface
/// $p_c = p(1 + \eta^2/M^2)$, whence $p/p_0 = (M^2/(M^2 +
/// \eta^2))^{(\hat\lambda-\hat\kappa)/\hat\lambda}$ (exponent 0.75) at
/// every plastic step, and $p_{cs} = p_0 2^{-0.75}$ at $\eta = M$.
#[test]
fn undrained_compression_of_a_normally_consolidated_soil_is_exact_and_ends_at_critical_state() {
    let law = law();
    let mut point = isotropic(&law, 1.0);
    let worst = undrained(&mut point, -1e-3, 1000, 1.0);
    let (p, q) = invariants(&point.stress);
    assert!(worst <= 1e-10, "path error {worst:e}");
    assert_relative(q / p, M, 1e-6, "η at critical state");
    assert_relative(p / P0, 0.5f64.powf(0.75), 1e-6, "p_cs/p0 = (1/2)^0.75");
}

/// Drained (lateral stresses $-p_0$): $q = 3(p - p_0)$, ending where it
/// meets $q = Mp$, $p_{cs} = 3p_0/(3 - M)$. The approach is exponential in
/// the axial strain (a decade per 0.5), hence the long path.
#[test]
fn drained_compression_of_a_normally_consolidated_soil_follows_q_3p_to_critical_state() {
    let law = law();
    let mut point = isotropic(&law, 1.0);
    let worst = drained(&mut point, -5e-3, 700);
    let (p, q) = invariants(&point.stress);
    assert!(worst <= 1e-10, "path error {worst:e}");
    assert_relative(p, 3.0 * P0 / (3.0 - M), 1e-6, "p at critical state");
    assert_relative(q, M * p, 1e-6, "q = M p");
}

/// Over-consolidated (OCR 4 and 10, dry side): the undrained closed form
/// with $p_{c0} = \mathrm{OCR}\,p_0$, $p/p_0 = (\mathrm{OCR}\,M^2/(M^2 +
/// \eta^2))^{0.75}$; drained, a peak and softening ($p_c$ falls) to the
/// same critical state as the normally consolidated soil.
#[test]
fn overconsolidated_soils_soften_on_the_dry_side_to_critical_state() {
    for ocr in [4.0, 10.0] {
        let law = law();
        let mut point = isotropic(&law, ocr);
        let worst = undrained(&mut point, -1e-3, 1000, ocr);
        let (p, q) = invariants(&point.stress);
        assert!(worst <= 1e-10, "OCR {ocr}: path error {worst:e}");
        assert_relative(q / p, M, 1e-6, "undrained η at critical state");
        // p_cs = p0 (OCR/2)^((λ̂−κ̂)/λ̂): with η = M in the closed form.
        assert_relative(p / P0, (ocr / 2.0).powf(0.75), 1e-6, "undrained p_cs");

        let mut point = isotropic(&law, ocr);
        let worst = drained(&mut point, -5e-3, 700);
        let (p, q) = invariants(&point.stress);
        assert!(worst <= 1e-10, "OCR {ocr}: path error {worst:e}");
        // Softened: p_c fell from OCR p0 to 2 p_cs.
        assert_relative(
            point.history.preconsolidation,
            2.0 * p,
            1e-6,
            "p_c = 2 p_cs",
        );
        assert!(point.history.preconsolidation < ocr * P0);
        assert_relative(p, 3.0 * P0 / (3.0 - M), 1e-6, "drained p_cs");
        assert_relative(q, M * p, 1e-6, "drained q = M p");
    }
}

fn rotated(values: Vector3<f64>) -> Matrix3<f64> {
    let r = Rotation3::from_euler_angles(0.7, -1.1, 2.3);
    r * Matrix3::from_diagonal(&values) * r.transpose()
}

/// A regime case: the law, the elastic trial stress (kPa) whose elastic
/// strain is the trial strain, the preconsolidation pressure (kPa) and the
/// regime the return ends in.
struct Case {
    name: &'static str,
    law: ModifiedCamClay,
    trial_stress: [f64; 3],
    preconsolidation: f64,
    regime: CamClayRegime,
}

impl Case {
    fn history(&self) -> ModifiedCamClayHistory {
        ModifiedCamClayHistory::new(self.preconsolidation * 1e3)
    }

    /// The trial strain, rotated off the axes.
    fn strain(&self) -> Matrix3<f64> {
        let tau = Vector3::from(self.trial_stress) * 1e3;
        rotated(self.law.elastic_strain_of(&tau).unwrap())
    }
}

/// p_min of the law with a floor (Pa).
const FLOOR: f64 = 50e3;

fn regime_cases() -> Vec<Case> {
    use CamClayRegime::{Elastic, Floor, Hardening};
    let plain = law();
    let floored = law().with_minimum_pressure(FLOOR).unwrap();
    let case = |name, law, trial_stress, preconsolidation, regime| Case {
        name,
        law,
        trial_stress,
        preconsolidation,
        regime,
    };
    vec![
        case("elastic", plain, [-80.0, -90.0, -100.0], 200.0, Elastic),
        case("wet", plain, [-120.0, -150.0, -250.0], 150.0, Hardening),
        case(
            "wet, two equal",
            plain,
            [-150.0, -150.0, -300.0],
            150.0,
            Hardening,
        ),
        case("wet, isotropic", plain, [-200.0; 3], 150.0, Hardening),
        case("dry", plain, [0.0, -20.0, -250.0], 300.0, Hardening),
        case(
            "dry, two equal",
            plain,
            [-30.0, -30.0, -250.0],
            300.0,
            Hardening,
        ),
        case(
            "elastic, floor",
            floored,
            [-20.0, -25.0, -30.0],
            50.0,
            Elastic,
        ),
        case(
            "dry above the floor",
            floored,
            [-5.0, -10.0, -60.0],
            60.0,
            Hardening,
        ),
        case(
            "dry, just above the floor",
            floored,
            [10.0, 0.0, -40.0],
            52.0,
            Hardening,
        ),
        case(
            "dry onto the floor",
            floored,
            [15.0, 5.0, -60.0],
            52.0,
            Floor,
        ),
        case(
            "dry onto the floor, two equal",
            floored,
            [10.0, 10.0, -50.0],
            52.0,
            Floor,
        ),
        case("dry at the floor", floored, [0.0, -5.0, -40.0], 50.0, Floor),
        case(
            "wet from the floor",
            floored,
            [-60.0, -60.0, -100.0],
            50.0,
            Hardening,
        ),
    ]
}

/// $\Delta F = \exp(\varepsilon)R$ with $b^e_n = \mathbf 1$: the trial
/// strain of the case, rotated; and a stretched, rotated $F_n$.
fn kinematics(eps: &Matrix3<f64>) -> (Matrix3<f64>, Matrix3<f64>) {
    let delta_f = SymSpectral::new(eps).unwrap().exp()
        * Rotation3::from_euler_angles(-0.3, 0.4, 1.2).into_inner();
    let f_n = Rotation3::from_euler_angles(0.2, 0.1, -0.5).into_inner()
        * Matrix3::from_diagonal(&Vector3::new(1.05, 0.97, 1.0));
    (delta_f, f_n)
}

#[test]
fn the_tangents_match_finite_differences_in_every_regime() {
    for c in regime_cases() {
        let (eps, h) = (c.strain(), c.history());
        let state = c.law.return_map(&SymSpectral::new(&eps).unwrap(), &h);
        assert_eq!(state.history.regime, c.regime, "{}", c.name);
        let alg = check_algorithmic_tangent(&c.law, &eps, &h, STEP)
            .unwrap()
            .unwrap_or_else(|| panic!("{}: the stencil changed regime", c.name));
        let (delta_f, f_n) = kinematics(&eps);
        let point = MaterialState {
            be: Matrix3::identity(),
            history: h,
        };
        let pc = check_previously_converged(&c.law, &delta_f, &f_n, &point, STEP)
            .unwrap()
            .unwrap_or_else(|| panic!("{}: the stencil changed regime", c.name));
        let ul = check_spatial(&c.law, &delta_f, &f_n, &point, STEP)
            .unwrap()
            .unwrap_or_else(|| panic!("{}: the stencil changed regime", c.name))
            .max();
        for (what, e) in [("D_alg", alg), ("Ã", pc), ("a", ul)] {
            assert!(e <= TOLERANCE, "{} {what}: error {e:e}", c.name);
        }
    }
}

/// The loading tangent at a converged plastic state (re-read as elastic)
/// is the one-sided derivative for continued loading, on both sides and
/// at the floor. The one-sided difference has a truncation error of
/// $O(h/\hat\kappa)$, hence the small step.
#[test]
fn the_loading_tangent_on_the_surface_continues_each_regime() {
    for c in regime_cases()
        .into_iter()
        .filter(|c| c.regime != CamClayRegime::Elastic)
    {
        let err = check_loading_tangent(&c.law, &c.strain(), &c.history(), 1e-9)
            .unwrap()
            .unwrap_or_else(|| panic!("{}: not a plastic step re-read as elastic", c.name));
        assert!(err < 1e-6, "{}: loading tangent error {err:e}", c.name);
    }
}

/// Associated flow and hyperelasticity make $D^{alg}$ major-symmetric when
/// elastic, at the floor (perfect plasticity) and on the surface
/// ($\Delta\gamma = 0$, the loading tangent), but not in a hardening step
/// (module docs): the law says so.
#[test]
fn the_tangent_is_major_symmetric_except_in_a_hardening_step() {
    let asymmetry = |d: &mpm_constitutive::Tensor4| (d - d.transpose()).norm() / d.norm();
    for c in regime_cases() {
        let (trial, h) = (SymSpectral::new(&c.strain()).unwrap(), c.history());
        let state = c.law.return_map(&trial, &h);
        let asym = asymmetry(&c.law.algorithmic_tangent(&trial, &h, &state));
        let isotropic = c.trial_stress.iter().all(|&t| t == c.trial_stress[0]);
        if c.regime == CamClayRegime::Hardening && !isotropic {
            assert!(asym > 1e-3, "{}: asymmetry {asym:e}", c.name);
        } else {
            assert!(asym < 1e-12, "{}: asymmetry {asym:e}", c.name);
        }
        let on = SymSpectral::new(&trial.compose(&state.elastic_strain)).unwrap();
        let again = c.law.return_map(&on, &state.history);
        assert!(!again.yielded, "{}", c.name);
        let loading = c.law.loading_tangent(&on, &state.history, &again);
        let asym = asymmetry(&loading);
        assert!(asym < 1e-12, "{}: loading asymmetry {asym:e}", c.name);
    }
    assert!(!law().symmetric_tangent());
}

/// Ten times larger steps leave the undrained path exact (the closed form
/// holds at every converged state, whatever the step) and end at the
/// same critical state.
#[test]
fn ten_times_larger_steps_keep_the_undrained_path_exact() {
    let law = law();
    let mut point = isotropic(&law, 1.0);
    let worst = undrained(&mut point, -1e-2, 100, 1.0);
    let (p, q) = invariants(&point.stress);
    assert!(worst <= 1e-10, "path error {worst:e}");
    assert_relative(q / p, M, 1e-6, "η at critical state");
}

#[test]
fn bad_parameters_are_refused() {
    let bad = [
        (0.05, 0.05, M, G, P_REF),
        (0.04, 0.05, M, G, P_REF),
        (LAMBDA, 0.0, M, G, P_REF),
        (LAMBDA, -0.05, M, G, P_REF),
        (f64::NAN, KAPPA, M, G, P_REF),
        (f64::INFINITY, KAPPA, M, G, P_REF),
        (LAMBDA, KAPPA, 0.0, G, P_REF),
        (LAMBDA, KAPPA, -1.0, G, P_REF),
        (LAMBDA, KAPPA, M, 0.0, P_REF),
        (LAMBDA, KAPPA, M, G, 0.0),
        (LAMBDA, KAPPA, M, G, f64::NAN),
    ];
    for (lambda, kappa, m, g, p_r) in bad {
        let err = ModifiedCamClay::new(lambda, kappa, m, g, p_r);
        assert!(
            matches!(
                err,
                Err(mpm_constitutive::ConstitutiveError::InvalidParameter { .. })
            ),
            "({lambda}, {kappa}, {m}, {g}, {p_r}): {err:?}"
        );
    }
    for p_min in [-1.0, f64::NAN, f64::INFINITY] {
        assert!(law().with_minimum_pressure(p_min).is_err(), "{p_min}");
    }
    assert!(law().with_minimum_pressure(0.0).is_ok());
    // No tension: an initial stress needs a positive mean pressure.
    let law = law();
    for tau in [Vector3::zeros(), Vector3::new(10.0, -5.0, -5.0)] {
        assert!(law.elastic_strain_of(&tau).is_err(), "{tau:?}");
        assert!(law.history_for(&tau, 1.0).is_err(), "{tau:?}");
    }
    let tau = Vector3::from_element(-P0);
    for ocr in [0.5, f64::NAN, f64::INFINITY] {
        assert!(law.history_for(&tau, ocr).is_err(), "OCR {ocr}");
    }
    assert!(law.p_wave_modulus_at(0.0).is_err());
}

/// The initial state of a point: its elastic strain gives its stress, and
/// its history puts it on the yield surface for OCR = 1 and inside it,
/// on the ellipse scaled by the OCR, otherwise.
#[test]
fn the_initial_state_lies_on_the_scaled_yield_surface() {
    let law = law().with_minimum_pressure(1e3).unwrap();
    let tau = Vector3::new(-60e3, -60e3, -150e3);
    let (p, q) = invariants(&tau);
    let strain = law.elastic_strain_of(&tau).unwrap();
    let trial = SymSpectral {
        values: strain,
        vectors: Matrix3::identity(),
    };
    for ocr in [1.0, 4.0] {
        let h = law.history_for(&tau, ocr).unwrap();
        assert_relative(
            h.preconsolidation,
            ocr * (p + q * q / (M * M * p)),
            1e-15,
            "p_c",
        );
        let state = law.return_map(&trial, &h);
        assert!(!state.yielded, "OCR {ocr}");
        assert!((state.tau - tau).norm() <= 1e-14 * tau.norm(), "OCR {ocr}");
        let f = law.yield_function(&tau, &h) / (p * p);
        if ocr == 1.0 {
            assert!(f.abs() < 1e-14, "f = {f:e}");
        } else {
            assert!(f < -1.0, "f = {f:e}");
        }
    }
    // A small stress's ellipse is floored at p_min.
    let small = Vector3::from_element(-100.0);
    assert_eq!(law.history_for(&small, 1.0).unwrap().preconsolidation, 1e3);
}

/// The explicit path: no constant elastic constants, so the wave modulus
/// is given at a pressure bound, $p_{max}/\hat\kappa + 4G/3$; the
/// wrapped law updates a prestressed point like the return map.
#[test]
fn an_explicit_update_takes_the_wave_modulus_at_a_pressure_bound() {
    use mpm_constitutive::{IncrementalLaw, Spectral};
    let law = law();
    assert!(law.elasticity().is_none());
    assert_eq!(
        law.point_shear_modulus(&ModifiedCamClayHistory::default()),
        Some(G)
    );
    assert!(Spectral::new(law).is_err());
    let modulus = law.p_wave_modulus_at(4.0 * P0).unwrap();
    assert_relative(modulus, 4.0 * P0 / KAPPA + 4.0 / 3.0 * G, 1e-15, "K + 4G/3");
    let explicit = Spectral::with_p_wave_modulus(law, modulus).unwrap();
    let tau0 = Vector3::from_element(-P0);
    let strain = law.elastic_strain_of(&tau0).unwrap();
    let mut state = MaterialState {
        be: Matrix3::from_diagonal(&strain.map(|e| (2.0 * e).exp())),
        history: law.history_for(&tau0, 1.0).unwrap(),
    };
    let delta_f = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 0.99));
    let tau = explicit.update(&delta_f, &mut state).unwrap();
    let mut point = PointDriver::new(&law, strain, law.history_for(&tau0, 1.0).unwrap());
    point
        .step(
            [
                Control::Strain(0.0),
                Control::Strain(0.0),
                Control::Strain(0.99f64.ln()),
            ],
            1e-6,
        )
        .unwrap();
    let expected = Matrix3::from_diagonal(&point.stress);
    assert!(
        (tau - expected).norm() <= 1e-12 * expected.norm(),
        "{tau} against {expected}"
    );
    assert!(explicit.stored_energy(&state).unwrap() > 0.0);
}

/// Extreme trials give finite stresses and tangents: a huge extension
/// (the pressure stays positive, the law has no tension), a huge
/// compression, a huge shear, an OCR of 1000, and the degenerate default
/// history ($p_c = 0$ without a floor: an empty elastic domain).
#[test]
fn extreme_inputs_give_finite_stresses() {
    let plain = law();
    let floored = law().with_minimum_pressure(FLOOR).unwrap();
    let tau0 = Vector3::from_element(-P0);
    let histories = [
        plain.history_for(&tau0, 1.0).unwrap(),
        plain.history_for(&tau0, 1000.0).unwrap(),
        ModifiedCamClayHistory::default(),
    ];
    let strains = [
        Vector3::from_element(2.0),
        Vector3::new(3.0, -1.0, 0.5),
        Vector3::from_element(-5.0),
        Vector3::new(-3.0, 1.0, 2.5),
        Vector3::new(-0.2, -0.2, 1.5),
        Vector3::new(1e-3, 0.0, -1e-3),
    ];
    for law in [plain, floored] {
        for h in &histories {
            for eps in &strains {
                let trial = SymSpectral::new(&rotated(*eps)).unwrap();
                let state = law.return_map(&trial, h);
                let d = law.algorithmic_tangent(&trial, h, &state);
                let finite = state
                    .tau
                    .iter()
                    .chain(state.elastic_strain.iter())
                    .all(|v| v.is_finite())
                    && state.history.preconsolidation.is_finite()
                    && state.history.multiplier.is_finite()
                    && d.iter().all(|v| v.is_finite());
                assert!(finite, "{eps:?} from {h:?}: {state:?}");
                // p > 0 in the law; its mean of τ to rounding (of 2G dev ε).
                let (p, _) = invariants(&state.tau);
                assert!(p >= -1e-14 * G * eps.amax(), "{eps:?}: tension {p}");
                if state.yielded && h.preconsolidation > 0.0 {
                    let f = law.yield_function(&state.tau, &state.history);
                    let pc = state.history.preconsolidation;
                    assert!(f.abs() <= 1e-10 * pc * pc, "{eps:?} from {h:?}: f = {f:e}");
                }
            }
        }
    }
}

// Random deformation gradients from the default history (p_c at the
// floor), the exported property tests. The indices keep the drawn
// stretches (0.2–5, log strains up to ±1.6 per axis) within a finite
// range of pressures; about 90 % of the drawn trials yield, a third of
// those onto the floor.
mpm_constitutive_proptest::law_tangent_properties!(cam_clay_macro, |e: f64, nu: f64| {
    ModifiedCamClay::new(1.0, 0.5, 1.2, e / (2.0 * (1.0 + nu)), 0.1 * e)
        .and_then(|law| law.with_minimum_pressure(0.05 * e))
});
