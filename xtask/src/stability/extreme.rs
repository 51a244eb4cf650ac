//! Principal stretches 0.05 and 20: in the constitutive driver (the
//! stress finite, both consistent tangents against finite differences)
//! and in a one-cell case stretched or compressed by a moving mesh in
//! uniaxial strain, where the stress has the closed form
//! $\sigma_{yy} = (\lambda_L + 2\mu)\ln\lambda/\lambda$ (Hencky, $J =
//! \lambda$).

use std::time::Instant;

use mpm_constitutive::verification::{STEP, TOLERANCE, check_previously_converged, check_spatial};
use mpm_constitutive::{HenckyElastic, LogStrainLaw, MaterialState, NeoHookean, VonMises, update};
use nalgebra::{Matrix3, Rotation3, Vector3};

use super::{Expect, Mode, Outcome, Row, guarded};

const YOUNG: f64 = 1e6;
const NU: f64 = 0.3;

/// The steps of the finite-difference checks: the default
/// [`STEP`] and two larger ones. At stretch ratios of 400 the default
/// step ($10^{-4}\sigma_{min}/\|F\|$ for the spatial tangent) is so small
/// that round-off dominates (the error grows as 1/step: 1.4e-5 at 1e-4,
/// 1.5e-6 at 1e-3, 2e-7 at 1e-2 for Hencky at stretches 20, 0.05, 1), so
/// the best of the three is the tangent's error.
const STEPS: [f64; 3] = [STEP, 1e-3, 1e-2];

/// The stress, the best finite-difference errors of both tangents over
/// [`STEPS`], and the errors at the default step, of `law` at `f` from
/// the virgin state.
fn driver<L: LogStrainLaw>(law: &L, f: &Matrix3<f64>) -> Result<[f64; 5], String>
where
    L::History: Default,
{
    let state = MaterialState::<L::History>::default();
    let id = Matrix3::identity();
    let r = update(law, f, &id, &state).map_err(|e| e.to_string())?;
    let (mut pc, mut ul) = ([f64::INFINITY; 3], [f64::INFINITY; 3]);
    for (i, step) in STEPS.into_iter().enumerate() {
        pc[i] = check_previously_converged(law, f, &id, &state, step)
            .map_err(|e| e.to_string())?
            .unwrap_or(f64::INFINITY);
        ul[i] = check_spatial(law, f, &id, &state, step)
            .map_err(|e| e.to_string())?
            .map_or(f64::INFINITY, |e| e.max());
    }
    let best = |e: [f64; 3]| e.into_iter().fold(f64::INFINITY, f64::min);
    Ok([r.sigma.norm(), best(pc), best(ul), pc[0], ul[0]])
}

fn driver_rows(rows: &mut Vec<Row>) {
    let turn = Rotation3::from_axis_angle(&Vector3::x_axis(), 0.7)
        * Rotation3::from_axis_angle(&Vector3::z_axis(), 2.1);
    let stretches: [(&str, [f64; 3]); 4] = [
        ("uniaxial 0.05", [0.05, 1.0, 1.0]),
        ("uniaxial 20", [20.0, 1.0, 1.0]),
        ("20, 0.05, 1", [20.0, 0.05, 1.0]),
        ("0.05, 0.05, 0.05", [0.05, 0.05, 0.05]),
    ];
    let hencky = HenckyElastic::new(YOUNG, NU);
    let von_mises = VonMises::new(YOUNG, NU, 1e4, 1e3);
    let neo = NeoHookean::new(YOUNG, NU);
    for (name, s) in stretches {
        let f = turn.matrix() * Matrix3::from_diagonal(&Vector3::from(s));
        type Check = Box<dyn Fn() -> Result<[f64; 5], String>>;
        let laws: [(&str, Check); 3] = [
            ("Hencky", {
                let l = hencky;
                Box::new(move || driver(l.as_ref().map_err(|e| e.to_string())?, &f))
            }),
            ("von Mises", {
                let l = von_mises;
                Box::new(move || driver(l.as_ref().map_err(|e| e.to_string())?, &f))
            }),
            ("Neo-Hookean", {
                let l = neo;
                Box::new(move || driver(l.as_ref().map_err(|e| e.to_string())?, &f))
            }),
        ];
        for (law, check) in laws {
            let mut row = Row::new(
                "extreme",
                format!("driver, stretches {name}, rotated"),
                law,
                Expect::Converge,
            );
            let started = Instant::now();
            let (outcome, r) = Outcome::of(guarded(check), |_| 0);
            row.outcome = outcome;
            row.seconds = started.elapsed().as_secs_f64();
            if let Some([sigma, pc, ul, pc0, ul0]) = r {
                row.work = "1 update, 3 × 2 × 9 perturbations".into();
                row.error = Some(pc.max(ul));
                row.measured = format!(
                    "|σ|/E {:.2e}; tangent FD error PC {pc:.1e}, UL {ul:.1e} (at the default step {pc0:.1e}, {ul0:.1e})",
                    sigma / YOUNG
                );
                row.value("sigma", sigma);
                if pc.max(ul) > TOLERANCE {
                    row.outcome = Outcome::Error {
                        error: "tangent".into(),
                        message: format!(
                            "consistent tangent differs from the finite difference by {:.1e} > {TOLERANCE:e}",
                            pc.max(ul)
                        ),
                    };
                }
            }
            rows.push(row);
        }
    }
}

/// The one-cell case: a unit cell in uniaxial strain, its top face driven
/// by a stretching mesh to `stretch`.
fn one_cell(rows: &mut Vec<Row>, mode: Mode) {
    let steps = if mode == Mode::Quick { 10 } else { 40 };
    let (lame, mu) = (
        YOUNG * NU / ((1.0 + NU) * (1.0 - 2.0 * NU)),
        YOUNG / (2.0 * (1.0 + NU)),
    );
    for stretch in [0.05_f64, 20.0] {
        for (basis, form) in [("linear", "ul"), ("linear", "pc"), ("gimp", "pc")] {
            // GIMP's domains must follow the stretching cells.
            let update = if basis == "gimp" { "stretch" } else { "none" };
            let mut row = Row::new(
                "extreme",
                format!("one cell in uniaxial strain to λ = {stretch}, {steps} steps"),
                format!("{basis}, {form}, domain {update}"),
                Expect::Converge,
            );
            let text = format!(
                "[mesh]\norigin = [0.0, 0.0]\nsize = [1.0, 1.0]\ncells = [1, 1]\n\n\
                 [mesh.motion]\nkind = \"stretch\"\naxis = \"y\"\nextension = {ext:?}\ndriven = \"y_max\"\n\n\
                 [[material]]\nname = \"m\"\nmodel = \"hencky\"\nyoungs_modulus = {YOUNG:?}\npoisson_ratio = {NU:?}\ndensity = 1.0\n\n\
                 [[body]]\nname = \"b\"\nmaterial = \"m\"\nregion = {{ box = {{ lower = [0.0, 0.0], upper = [1.0, 1.0] }} }}\npoints_per_cell = 2\n\n\
                 [[boundary]]\nset = \"y_min\"\nkind = \"roller\"\n\n\
                 [[boundary]]\nset = \"x_min\"\nkind = \"roller\"\n\n\
                 [[boundary]]\nset = \"x_max\"\nkind = \"roller\"\n\n\
                 [solver]\nbasis = \"{basis}\"\ndomain_update = \"{update}\"\nformulation = \"{form}\"\nsteps = {steps}\n",
                ext = stretch - 1.0
            );
            if let Some(out) = super::run_problem::<2>(&text, &mut row) {
                let exact = (lame + 2.0 * mu) * stretch.ln() / stretch;
                let worst = out
                    .last
                    .sigma
                    .iter()
                    .map(|s| (s[4] - exact).abs() / exact.abs())
                    .fold(0.0, f64::max);
                let syy = out.last.sigma.first().map_or(f64::NAN, |s| s[4]);
                row.error = Some(worst);
                row.measured = format!("σ_yy {syy:.4e} Pa (closed form {exact:.4e})");
                row.value("sigma_yy", syy);
            }
            rows.push(row);
        }
    }
}

pub fn rows(mode: Mode) -> Vec<Row> {
    let mut rows = Vec::new();
    driver_rows(&mut rows);
    one_cell(&mut rows, mode);
    rows
}
