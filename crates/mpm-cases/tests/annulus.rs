//! Elastic annulus (Coombs 2020 §7.4): the manufactured body force is
//! proven against the constitutive model by finite differences, and the
//! displacement error converges at the rate of the linear basis on
//! unstructured Gmsh meshes when enough points per element are used.
#![allow(clippy::unwrap_used)]

use std::path::PathBuf;

use mpm_cases::cases::Solve;
use mpm_cases::cases::annulus::{AnnulusCase, AnnulusParams, Torsion};
use mpm_cases::run::RunControl;
use mpm_cases::variant::{FormulationKind, Variant};
use mpm_constitutive::tensor::embed;
use mpm_constitutive::{HenckyElastic, MaterialState, update};
use nalgebra::{Matrix2, Matrix3, Vector2};

const TORSION: Torsion = Torsion {
    inner_radius: 0.75,
    outer_radius: 1.25,
    mu: 0.5,
};

#[test]
fn shear_stress_derivatives_match_finite_differences() {
    for gamma in [-1.7, -0.3, 0.0, 0.05, 0.8, 2.5] {
        let (_, (d11, d12)) = TORSION.shear_stress(gamma);
        let e = 1e-6;
        let ((p11, p12), _) = TORSION.shear_stress(gamma + e);
        let ((m11, m12), _) = TORSION.shear_stress(gamma - e);
        assert!((d11 - (p11 - m11) / (2.0 * e)).abs() < 1e-9, "{gamma}");
        assert!((d12 - (p12 - m12) / (2.0 * e)).abs() < 1e-9, "{gamma}");
    }
}

/// The Cauchy stress at the current point `x` computed by the Hencky
/// update from F of the rotation field (eq. 44), F by central differences
/// of the motion.
fn sigma_at(alpha: f64, x: &Vector2<f64>) -> Matrix3<f64> {
    let rotate = |v: &Vector2<f64>, t: f64| {
        let (s, c) = t.sin_cos();
        Vector2::new(c * v[0] - s * v[1], s * v[0] + c * v[1])
    };
    let motion = |x0: &Vector2<f64>| rotate(x0, TORSION.theta(alpha, x0.norm()).0);
    // The radius is kept: the reference point is x rotated back.
    let x0 = rotate(x, -TORSION.theta(alpha, x.norm()).0);
    let e = 1e-6;
    let mut f = Matrix2::zeros();
    for j in 0..2 {
        let mut d = Vector2::zeros();
        d[j] = e;
        let col = (motion(&(x0 + d)) - motion(&(x0 - d))) / (2.0 * e);
        f.set_column(j, &col);
    }
    let law = HenckyElastic::new(1.0, 0.0).unwrap();
    update(
        &law,
        &embed(&f),
        &Matrix3::identity(),
        &MaterialState::default(),
    )
    .unwrap()
    .sigma
}

/// b = −∇·σ in the current configuration, with σ from the constitutive
/// update: checks the closed form of the module docs (rotated shear
/// stress, polar equilibrium, its derivatives) independently.
#[test]
fn manufactured_body_force_balances_the_stress_divergence() {
    let alpha = 0.4;
    for (r, angle) in [
        (0.8, 0.3),
        (0.93, 2.0),
        (1.0, -1.1),
        (1.17, 4.0),
        (1.24, 0.0),
    ] {
        let x0 = Vector2::new(r * f64::cos(angle), r * f64::sin(angle));
        let t = TORSION.theta(alpha, r).0;
        let x = Vector2::new(r * (angle + t).cos(), r * (angle + t).sin());
        let h = 1e-4;
        let mut div = Vector2::zeros();
        for j in 0..2 {
            let mut d = Vector2::zeros();
            d[j] = h;
            let ds = (sigma_at(alpha, &(x + d)) - sigma_at(alpha, &(x - d))) / (2.0 * h);
            for i in 0..2 {
                div[i] += ds[(i, j)];
            }
        }
        let b = TORSION.body_force(alpha, &x0);
        assert!(
            (b + div).norm() <= 1e-5 * b.norm().max(1e-3),
            "r = {r}: b = {b:?}, -div sigma = {:?}",
            -div
        );
    }
}

fn mesh(i: usize) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenes/meshes/annulus_{i}.msh"))
}

fn error(i: usize, points_per_element: usize) -> (f64, f64) {
    let p = AnnulusParams {
        mesh: Some(mesh(i)),
        points_per_element,
        ..AnnulusParams::default()
    };
    let r = AnnulusCase::run(
        &p,
        &Variant::default(),
        &RunControl::default(),
        |_, _, _| Ok(()),
    )
    .unwrap();
    assert_eq!(r.output.reports.len(), 10, "no step cut");
    (r.element_size, r.error)
}

/// Fig. 19: with 4² points per element the error falls at about the rate
/// of the linear basis (least-squares slope over the paper's element sizes
/// 0.2182, 0.1091, 0.0545: measured 1.84), and on one mesh it falls as
/// points are added (one point per element "is insufficient"). At the
/// finest size (0.0273) 4² stall and 8² restore rate 1.99 (see the
/// reproduction report): the points needed grow with refinement, as for
/// the column.
#[test]
fn displacement_error_converges_at_rate_two_with_enough_points() {
    let runs: Vec<(f64, f64)> = (1..=3).map(|i| error(i, 4)).collect();
    let (xs, ys): (Vec<f64>, Vec<f64>) = runs.iter().map(|(h, e)| (h.ln(), e.ln())).unzip();
    let n = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let slope = xs
        .iter()
        .zip(&ys)
        .map(|(x, y)| (x - mx) * (y - my))
        .sum::<f64>()
        / xs.iter().map(|x| (x - mx) * (x - mx)).sum::<f64>();
    println!("4x4 points per element: {runs:?}, slope {slope:.2}");
    assert!(slope >= 1.7, "{slope}");
    let by_points: Vec<f64> = (1..=4).map(|n| error(2, n).1).collect();
    println!("mesh 0.1091, 1..4 points per direction: {by_points:?}");
    assert!(by_points[0] > 1.5 * by_points[3], "{by_points:?}");
}

#[test]
fn updated_lagrangian_equals_previously_converged_on_triangles() {
    let p = AnnulusParams {
        mesh: Some(mesh(1)),
        ..AnnulusParams::default()
    };
    let go = |formulation| {
        let v = Variant {
            formulation,
            ..Variant::default()
        };
        AnnulusCase::run(&p, &v, &RunControl::default(), |_, _, _| Ok(())).unwrap()
    };
    let (pc, ul) = (go(FormulationKind::Pc), go(FormulationKind::Ul));
    let worst = pc
        .output
        .last
        .displacement
        .iter()
        .zip(&ul.output.last.displacement)
        .map(|(a, b)| (0..2).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    assert!(worst <= 1e-8 * 0.1, "{worst:e}");
}

#[test]
fn the_simplex_cases_refuse_grid_only_variants() {
    use mpm_cases::variant::BasisKind;
    let v = Variant {
        basis: BasisKind::Gimp,
        ..Variant::default()
    };
    let e = AnnulusCase::run(
        &AnnulusParams::default(),
        &v,
        &RunControl::default(),
        |_, _, _| Ok(()),
    )
    .err()
    .unwrap();
    assert!(e.to_string().contains("standard MPM"), "{e}");
}
