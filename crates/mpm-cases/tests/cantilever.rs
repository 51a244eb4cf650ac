//! Elastic cantilever (Coombs 2020 §7.3): quadratic Newton convergence and
//! agreement of the two formulations.
#![allow(clippy::unwrap_used)]

use mpm_basis::LinearMpm;
use mpm_cases::cases::Solve;
use mpm_cases::cases::cantilever::{CantileverCase, CantileverParams};
use mpm_cases::run::RunControl;
use mpm_cases::variant::{FormulationKind, Variant};
use mpm_constitutive::HenckyElastic;
use mpm_solver::{
    ImplicitSolver, MaterialPoints, NewtonOptions, NoLocking, NoUpdate, Parts, PreviouslyConverged,
    UpdatedLagrangian,
};
use nalgebra::SVector;

#[test]
fn cantilever_converges_quadratically_and_ul_equals_pc() {
    let p = CantileverParams::default();
    let control = RunControl::default();
    let pc = CantileverCase::run(&p, &Variant::default(), &control, |_, _, _| Ok(())).unwrap();
    let ul = CantileverCase::run(
        &p,
        &Variant {
            formulation: FormulationKind::Ul,
            ..Variant::default()
        },
        &control,
        |_, _, _| Ok(()),
    )
    .unwrap();
    assert_eq!(pc.output.reports.len(), 50, "no step was cut");
    let (_, ux, uy) = *pc.tip.last().unwrap();
    println!(
        "tip at full load: u/l0 = {:.4}, v/l0 = {:.4}; {} iterations, {:.3} s",
        ux / p.length,
        uy / p.length,
        pc.output.summary.iterations,
        pc.output.wall_time_s
    );
    for k in [9, 19, 39, 48, 49] {
        println!("step {}: {:?}", k + 1, pc.output.reports[k].residuals);
    }
    // Large deflection: the tip moves down by most of the length and back.
    assert!(uy / p.length < -0.5 && ux / p.length < -0.1);
    // Quadratic convergence. For the last pair of each step,
    // ratio = log(r_k+1)/log(r_k), which tends to 2 as r_k → 0 (its constant
    // C of r_k+1 = C r_k² fades like log C/log r_k). Measured over the 50
    // steps its median must be >= 1.8 and no step may take more than 6
    // iterations (Table 3: 3 to 4). Steps that end at the round-off floor
    // (about 1e-14 here) lower the ratio; hence the median. The assembled
    // stiffness is proven consistent exactly (against finite differences of
    // the assembled residual) by mpm-solver/tests/stiffness.rs.
    let mut ratios: Vec<f64> = pc
        .output
        .reports
        .iter()
        .filter_map(|report| {
            let r = &report.residuals;
            assert!(report.iterations() <= 6, "{r:?}");
            r.windows(2)
                .last()
                .filter(|w| w[0] < 1.0 && w[1] > 0.0)
                .map(|w| w[1].ln() / w[0].ln())
        })
        .collect();
    ratios.sort_by(f64::total_cmp);
    let median = ratios[ratios.len() / 2];
    println!(
        "log(r_k+1)/log(r_k) of the last pair: median {median:.2}, min {:.2}, max {:.2}",
        ratios[0],
        ratios[ratios.len() - 1]
    );
    assert!(median >= 1.8, "{ratios:?}");
    // UL and PC solve the same equations (Coombs 2020 §5): the tip
    // histories agree to 1e-8 relative at every step.
    let mut worst = 0.0f64;
    for (a, b) in pc.tip.iter().zip(&ul.tip) {
        let diff =
            ((a.1 - b.1).powi(2) + (a.2 - b.2).powi(2)).sqrt() / (a.1 * a.1 + a.2 * a.2).sqrt();
        worst = worst.max(diff);
    }
    println!("UL vs PC: largest relative tip difference {worst:.2e}");
    assert_eq!(pc.tip.len(), ul.tip.len());
    assert!(worst <= 1e-8, "{worst:e}");
}

/// With 2×2 points per cell the Newton paths of UL and PC part in step 6
/// (an iterate's stiffness has an eigenvalue of ~1e-15 of the largest: a
/// cell holding one point with two nodes no other point supports), and the
/// converged states then differ by the tolerance times that conditioning.
/// The formulations still define the same discrete equations: at every
/// step, the increment PC converged to satisfies UL's equilibrium (eq. 40)
/// to the same residual, from the same start.
#[test]
fn the_pc_solution_satisfies_ul_equilibrium_at_every_step() {
    let p = CantileverParams {
        points_per_cell: 2,
        ..CantileverParams::default()
    };
    // The case's own scene: its grid, points, conditions and loaded points.
    let (built, loaded) = CantileverCase::build(&p, &p.variant()).unwrap();
    let mpm_cases::scene::build::SceneMesh::Grid(grid) = built.mesh.clone() else {
        panic!("the cantilever runs on a grid")
    };
    let constraints = built.constraints.clone();
    let law = HenckyElastic::new(p.youngs_modulus, p.poisson_ratio).unwrap();
    let mut points: MaterialPoints<2, (), ()> = MaterialPoints::new(
        built.position.clone(),
        built.volume.clone(),
        0.0,
        vec![(); built.len()],
    )
    .unwrap();
    let force = SVector::<f64, 2>::new(0.0, -p.load / 2.0);
    points.point_force = vec![(loaded[0], force), (loaded[1], force)];
    let options = NewtonOptions::default();
    let mut pc: ImplicitSolver<
        2,
        Parts<LinearMpm, PreviouslyConverged, _, NoLocking, NoUpdate, _>,
    > = ImplicitSolver::new(
        LinearMpm,
        grid.clone(),
        law,
        NoLocking,
        NoUpdate,
        constraints.clone(),
        options,
    );
    let mut ul: ImplicitSolver<2, Parts<LinearMpm, UpdatedLagrangian, _, NoLocking, NoUpdate, _>> =
        ImplicitSolver::new(
            LinearMpm,
            grid,
            law,
            NoLocking,
            NoUpdate,
            constraints,
            options,
        );
    let mut worst = 0.0f64;
    for step in 0..p.load_steps {
        let (l0, l1) = (
            step as f64 / p.load_steps as f64,
            (step + 1) as f64 / p.load_steps as f64,
        );
        let start = points.clone();
        pc.solve_load_step(&mut points, l0, l1).unwrap();
        let du = pc.free_increment();
        assert_eq!(ul.prepare_step(&start, l0, l1).unwrap(), du.len());
        ul.free_residual(&start, &du).unwrap();
        // Eq. (40) at the converged state, in both formulations (the
        // solver accepts a step against the largest force of the step,
        // hence the factor 2).
        let (r_pc, r_ul) = (pc.normalised_residual(), ul.normalised_residual());
        assert!(
            r_ul <= 2.0 * options.tolerance,
            "step {step}: UL residual {r_ul:e}"
        );
        worst = worst.max((r_ul - r_pc).abs());
    }
    println!("largest |r_UL - r_PC| at PC's solutions: {worst:.2e}");
    assert!(worst <= 1e-12, "{worst:e}");
}

/// The elastica reproduces Euler–Bernoulli theory for small loads (tip
/// deflection α/3, axial shortening α²/15 from inextensibility) and keeps
/// the tip on the arc of the beam's length.
#[test]
fn the_elastica_reference_has_the_small_load_limits() {
    use mpm_cases::cases::cantilever::elastica_tip;
    let alpha = 1e-3;
    let (u, v) = elastica_tip(alpha);
    assert!((v + alpha / 3.0).abs() < 1e-6 * alpha, "{v}");
    assert!(
        (u + alpha * alpha / 15.0).abs() < 1e-3 * alpha * alpha,
        "{u}"
    );
    // Bisshopp & Drucker (1945), also Gere & Timoshenko: at PL²/EI = 1 the
    // tip deflects by 0.30172 l0 and moves in by 0.05643 l0.
    let (u, v) = elastica_tip(1.0);
    assert!(
        (v + 0.30172).abs() < 1e-5 && (u + 0.05643).abs() < 1e-5,
        "{u} {v}"
    );
    let mut previous = 0.0;
    for alpha in [0.5, 2.0, 5.0, 10.0, 20.0] {
        let (u, v) = elastica_tip(alpha);
        // The tip lies inside the circle of radius l0 about the root and
        // deflects monotonically with the load.
        assert!((1.0 + u).hypot(v) < 1.0 && v < previous, "{alpha}: {u} {v}");
        previous = v;
    }
}
