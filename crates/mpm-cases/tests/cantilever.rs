//! Elastic cantilever (Coombs 2020 §7.3): quadratic Newton convergence and
//! agreement of the two formulations.
#![allow(clippy::unwrap_used)]

use mpm_cases::cases::cantilever::{CantileverParams, run};
use mpm_cases::run::RunControl;
use mpm_cases::variant::{FormulationKind, Variant};

#[test]
fn cantilever_converges_quadratically_and_ul_equals_pc() {
    let p = CantileverParams::default();
    let pc = run(
        &p,
        &Variant::default(),
        &RunControl::default(),
        |_, _, _| Ok(()),
    )
    .unwrap();
    let ul = run(
        &p,
        &Variant {
            formulation: FormulationKind::Ul,
            ..Variant::default()
        },
        &RunControl::default(),
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
    // steps its median must be >= 1.8 and no step may take more than 8
    // iterations. A few steps end at the round-off floor (1e-14 to 4e-11 in
    // this problem), where the ratio drops; hence the median. The assembled
    // stiffness is proven consistent exactly (against finite differences of
    // the assembled residual) by mpm-solver/tests/stiffness.rs.
    let mut ratios: Vec<f64> = pc
        .output
        .reports
        .iter()
        .filter_map(|report| {
            let r = &report.residuals;
            assert!(report.iterations() <= 8, "{r:?}");
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
    // UL and PC solve the same equations: identical to 1e-15 over the
    // first five steps. In step 6 the stiffness at one iterate is indefinite
    // and nearly singular (Cholesky fails in both runs, LU takes over); the
    // Newton correction along the near-null direction then depends on the
    // last bits, the two runs take different paths to the same tolerance,
    // and the converged states differ by ~tolerance × condition number.
    // Measured: tip difference ~1e-7 relative at full load.
    let (a, b) = (pc.tip.last().unwrap(), ul.tip.last().unwrap());
    let tip_diff =
        ((a.1 - b.1).powi(2) + (a.2 - b.2).powi(2)).sqrt() / (a.1 * a.1 + a.2 * a.2).sqrt();
    for k in 0..5 {
        let (x, y) = (pc.tip[k], ul.tip[k]);
        assert!(
            (x.2 - y.2).abs() <= 1e-12 * x.2.abs(),
            "step {k}: {x:?} vs {y:?}"
        );
    }
    println!("UL vs PC: relative tip difference {tip_diff:.2e}");
    assert!(tip_diff <= 1e-5);
}
