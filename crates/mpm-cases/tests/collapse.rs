//! Elasto-plastic collapse (Coombs 2020 §7.5) against Table 6.
#![allow(clippy::unwrap_used)]

use mpm_cases::cases::Solve;
use mpm_cases::cases::collapse::{CollapseCase, CollapseParams};
use mpm_cases::run::RunControl;
use mpm_cases::variant::Variant;

/// Table 6, h = 1.0 m: (points per cell per direction, horizontal extent,
/// maximum height), standard MPM.
const TABLE_6_H1: [(usize, f64, f64); 3] =
    [(3, 13.662, 6.245), (6, 13.735, 6.277), (9, 13.750, 6.289)];

#[test]
fn standard_mpm_collapse_reproduces_table_6_within_one_percent() {
    for (ppc, extent, height) in TABLE_6_H1 {
        let p = CollapseParams {
            points_per_cell: ppc,
            ..CollapseParams::default()
        };
        let r = CollapseCase::run(
            &p,
            &Variant::default(),
            &RunControl::default(),
            |_, _, _| Ok(()),
        )
        .unwrap();
        let (e_ext, e_h) = (
            (r.horizontal_extent - extent) / extent,
            (r.max_height - height) / height,
        );
        println!(
            "{ppc}x{ppc}: extent {:.4} (paper {extent}, {:+.3} %), height {:.4} (paper {height}, {:+.3} %), {} iterations, {:.2} s",
            r.horizontal_extent,
            100.0 * e_ext,
            r.max_height,
            100.0 * e_h,
            r.output.summary.iterations,
            r.output.wall_time_s
        );
        assert!(
            e_ext.abs() <= 0.01,
            "extent {} vs {extent}",
            r.horizontal_extent
        );
        assert!(e_h.abs() <= 0.01, "height {} vs {height}", r.max_height);
        assert_eq!(r.output.reports.len(), 40);
        // Quadratic convergence in the asymptotic regime: in every step the
        // last pair of normalised residuals with r_k < 1e-2 and r_k+1 above
        // the round-off floor (1e-12) satisfies r_k+1 <= 100 r_k². (Earlier
        // pairs may be pre-asymptotic while points change between elastic
        // and plastic.) A tangent that is not consistent converges
        // linearly, r_k+1 ≈ c r_k with c ~ 0.1–0.5, which violates this.
        for report in &r.output.reports {
            let res = &report.residuals;
            assert!(res[res.len() - 1] <= 1e-9);
            if let Some(w) = res.windows(2).rfind(|w| w[0] < 1e-2 && w[1] > 1e-12) {
                assert!(w[1] <= 100.0 * w[0] * w[0], "{res:?}");
            }
        }
    }
}
