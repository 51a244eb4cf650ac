//! The explicit solver against closed-form motions: free fall (the
//! corrected position update), the axially vibrating bar (the first mode,
//! its error and convergence), energy conservation of FLIP against the
//! dissipation of PIC, thread-count independence and the typed errors.
#![allow(clippy::unwrap_used)]

use mpm_basis::{BasisFunction, LinearMpm, QuadraticBSpline};
use mpm_constitutive::NeoHookean;
use mpm_mesh::RegularGrid;
use mpm_solver::explicit::{PointsFor, Transfer, VelocityFixities};
use mpm_solver::{
    CellAveraged, ExplicitOptions, ExplicitPoints, ExplicitSolver, Flip, FlipPic, NoLocking, Pic,
    PointFailure, SolverError, Taylor, TimeStep,
};
use nalgebra::Vector2;

/// `per`×`per` points per cell filling the box [lo, hi] on a grid of
/// spacing `h`.
fn block(lo: Vector2<f64>, hi: Vector2<f64>, h: f64, per: usize) -> (Vec<Vector2<f64>>, Vec<f64>) {
    let d = h / per as f64;
    let (nx, ny) = (
        ((hi.x - lo.x) / d).round() as usize,
        ((hi.y - lo.y) / d).round() as usize,
    );
    let mut x = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            x.push(lo + Vector2::new((i as f64 + 0.5) * d, (j as f64 + 0.5) * d));
        }
    }
    let v = vec![d * d; x.len()];
    (x, v)
}

/// A block in free flight under gravity moves as a rigid body:
/// x = x₀ + v₀t + ½gt², v = v₀ + gt, to rounding, with every transfer.
/// The notes' printed eq. (37) (+Δt² a) would be off by 1.5 g Δt t.
#[test]
fn free_fall_is_exact_with_the_corrected_position_update() {
    fn fall<T: Transfer<2>>(transfer: T) {
        let grid = RegularGrid::new(Vector2::zeros(), Vector2::new(0.25, 0.25), [16, 40]).unwrap();
        let (x0, vol) = block(Vector2::new(1.0, 8.0), Vector2::new(3.0, 9.0), 0.25, 2);
        let mut points: PointsFor<2, NeoHookean, T> =
            ExplicitPoints::new(x0.clone(), vol, 1000.0).unwrap();
        let v0 = Vector2::new(0.3, 1.0);
        points.set_velocity(|_| v0);
        let g = Vector2::new(0.0, -9.81);
        let options = ExplicitOptions {
            time_step: TimeStep::Fixed(1e-3),
            gravity: g,
        };
        let law = NeoHookean::new(1e6, 0.3).unwrap();
        let mut solver = ExplicitSolver::new(
            QuadraticBSpline,
            grid,
            law,
            transfer,
            NoLocking,
            VelocityFixities::new(),
            options,
        )
        .unwrap();
        let steps = solver
            .run_until(&mut points, 1.0, |_, _, _| Ok(()))
            .unwrap();
        assert_eq!(steps, 1000);
        let t = solver.time();
        for (p, x) in points.position.iter().enumerate() {
            let exact = x0[p] + v0 * t + g * (0.5 * t * t);
            assert!(
                (x - exact).norm() < 1e-10,
                "{transfer:?} point {p}: {x} vs {exact}"
            );
            assert!((points.velocity[p] - (v0 + g * t)).norm() < 1e-10);
            assert!(
                points.tau[p].norm() < 1e-6,
                "rigid motion must not stress: {}",
                points.tau[p]
            );
        }
    }
    fall(Flip);
    fall(Pic);
    fall(Taylor::PIC);
    fall(FlipPic { alpha: 0.95 });
}

/// The axially vibrating bar: E = 100, ρ = 1, ν = 0, length L = 25 fixed at
/// x = 0 and free at x = L, started in its first mode with velocity
/// amplitude v₀. Modelled without a fixity as the symmetric half of a
/// free–free bar of length 2L (the mid-section of the first mode of a
/// free–free bar does not move): u = (v₀/ω) sin(ωt) sin(βx), β = π/(2L),
/// ω = β√(E/ρ). Lateral velocities fixed (1D). Returns the error of the
/// point displacements (RMS over points and over the `samples` instants,
/// relative to the amplitude) and the energies' history.
struct Bar {
    error: f64,
    energy: Vec<(f64, f64)>,
}

fn vibrating_bar<B, T>(basis: B, transfer: T, cells: usize, cfl: f64, periods: f64, v0: f64) -> Bar
where
    B: BasisFunction<2, Domain = (), Mesh = RegularGrid<2>>,
    T: Transfer<2>,
{
    let (l, e, rho): (f64, f64, f64) = (25.0, 100.0, 1.0);
    let h = 2.0 * l / cells as f64;
    let pad = B::PADDING as f64 + 1.0;
    let grid = RegularGrid::new(
        Vector2::new(-l - pad * h, -pad * h),
        Vector2::new(h, h),
        [cells + 2 * (pad as usize), 1 + 2 * (pad as usize)],
    )
    .unwrap();
    let (x0, vol) = block(Vector2::new(-l, 0.0), Vector2::new(l, h), h, 2);
    let beta = std::f64::consts::PI / (2.0 * l);
    let omega = beta * (e / rho).sqrt();
    let mut points: PointsFor<2, NeoHookean, T> =
        ExplicitPoints::new(x0.clone(), vol, rho).unwrap();
    points.set_velocity(|x| Vector2::new(v0 * (beta * x.x).sin(), 0.0));
    let mut fixed = VelocityFixities::new();
    fixed.fix(0..grid.node_count(), 1);
    let options = ExplicitOptions {
        time_step: TimeStep::Cfl { factor: cfl },
        ..Default::default()
    };
    let mut solver = ExplicitSolver::new(
        basis,
        grid,
        NeoHookean::new(e, 0.0).unwrap(),
        transfer,
        NoLocking,
        fixed,
        options,
    )
    .unwrap();
    let period = 2.0 * std::f64::consts::PI / omega;
    let amplitude = v0 / omega;
    let (mut sum, mut count) = (0.0, 0usize);
    let mut energy = Vec::new();
    let samples = (periods * 8.0).round() as usize;
    for s in 1..=samples {
        let t_end = s as f64 * period * periods / samples as f64;
        solver
            .run_until(&mut points, t_end, |_, _, _| Ok(()))
            .unwrap();
        let t = solver.time();
        for (p, x) in points.position.iter().enumerate() {
            let u = x.x - x0[p].x;
            let exact = amplitude * (omega * t).sin() * (beta * x0[p].x).sin();
            sum += (u - exact).powi(2);
            count += 1;
        }
        let en = solver.energies(&points).unwrap();
        energy.push((t, en.total()));
    }
    Bar {
        error: (sum / count as f64).sqrt() / amplitude,
        energy,
    }
}

/// Convergence in h at a small CFL factor (0.02, so that the time error,
/// first order, stays below the spatial one) and in Δt at h = L/40.
/// Measured over 10 → 80 cells: linear MPM 3.0e-2 → 6.7e-4 (rates 1.92,
/// 1.85, 1.70), B-spline 5.5e-2 → 1.06e-3 (1.94, 1.92, 1.84); in Δt at 80
/// cells, CFL 0.4 → 0.1: 7.2e-3 → 2.2e-3 (rates 0.90, 0.80, the spatial
/// error entering): the time error is first order (the velocity update of
/// eq. 32 is forward Euler in the stress of the step's start).
#[test]
fn vibrating_bar_converges_in_h_and_dt() {
    for (name, bspline) in [("linear", false), ("bspline", true)] {
        let mut errors = Vec::new();
        for cells in [10, 20, 40, 80] {
            let bar = if bspline {
                vibrating_bar(QuadraticBSpline, Flip, cells, 0.02, 1.0, 1e-4)
            } else {
                vibrating_bar(LinearMpm, Flip, cells, 0.02, 1.0, 1e-4)
            };
            errors.push(bar.error);
        }
        let rates: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        eprintln!("{name}: errors {errors:?} rates {rates:?}");
        assert!(errors[3] < 2e-3, "{name}: {errors:?}");
        assert!(rates.iter().all(|r| *r > 1.6), "{name}: rates {rates:?}");
    }
    let mut errors = Vec::new();
    for cfl in [0.4, 0.2, 0.1] {
        errors.push(vibrating_bar(QuadraticBSpline, Flip, 80, cfl, 1.0, 1e-4).error);
    }
    let rates: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    eprintln!("dt: errors {errors:?} rates {rates:?}");
    assert!(
        rates.iter().all(|r| *r > 0.7 && *r < 1.3),
        "time rates {rates:?}"
    );
}

/// Ten periods of the bar at v₀ = 0.1 (1 % strain), CFL 0.2, 40 cells.
/// Measured total-energy ratios after 10 periods: FLIP 0.987, Taylor-PIC
/// 0.984, blend α = 0.99 0.928, PIC 0.002.
#[test]
fn flip_conserves_energy_and_pic_dissipates() {
    let ratio = |bar: &Bar| bar.energy.last().unwrap().1 / bar.energy[0].1;
    let flip = ratio(&vibrating_bar(QuadraticBSpline, Flip, 40, 0.2, 10.0, 0.1));
    let tpic = ratio(&vibrating_bar(
        QuadraticBSpline,
        Taylor::PIC,
        40,
        0.2,
        10.0,
        0.1,
    ));
    let blend = ratio(&vibrating_bar(
        QuadraticBSpline,
        FlipPic { alpha: 0.99 },
        40,
        0.2,
        10.0,
        0.1,
    ));
    let pic = ratio(&vibrating_bar(QuadraticBSpline, Pic, 40, 0.2, 10.0, 0.1));
    eprintln!(
        "energy after 10 periods / after 1/8: FLIP {flip}, TPIC {tpic}, blend {blend}, PIC {pic}"
    );
    assert!((0.98..1.0).contains(&flip), "FLIP {flip}");
    assert!((0.97..1.0).contains(&tpic), "TPIC {tpic}");
    assert!(pic < 0.01, "PIC {pic}");
    assert!(pic < blend && blend < flip, "blend {blend}");
    // Halving Δt halves FLIP's loss: the dissipation is the time
    // integration's, not a drift.
    let half = ratio(&vibrating_bar(QuadraticBSpline, Flip, 40, 0.1, 10.0, 0.1));
    let r = (1.0 - flip) / (1.0 - half);
    assert!((1.6..2.4).contains(&r), "loss ratio {r}");
}

/// 1 and 2 threads give the same motion (the per-thread grid buffers only
/// change the order of the sums).
#[test]
fn thread_count_changes_only_rounding() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let grid =
                RegularGrid::new(Vector2::zeros(), Vector2::new(0.1, 0.1), [20, 20]).unwrap();
            let (x0, vol) = block(Vector2::new(0.5, 0.5), Vector2::new(1.5, 1.2), 0.1, 3);
            let mut points: PointsFor<2, NeoHookean, Taylor> =
                ExplicitPoints::new(x0, vol, 1000.0).unwrap();
            points.set_velocity(|x| Vector2::new(-(x.y - 0.85), x.x - 1.0) * 0.5);
            let mut fixed = VelocityFixities::new();
            fixed.fix(0..21, 1);
            let options = ExplicitOptions {
                gravity: Vector2::new(0.0, -9.81),
                ..Default::default()
            };
            let mut solver = ExplicitSolver::new(
                QuadraticBSpline,
                grid,
                NeoHookean::new(1e5, 0.3).unwrap(),
                Taylor::FLIP,
                CellAveraged,
                fixed,
                options,
            )
            .unwrap();
            solver
                .run_until(&mut points, 0.1, |_, _, _| Ok(()))
                .unwrap();
            points
        })
    };
    let (a, b) = (run(1), run(2));
    let scale = a.position.iter().map(|x| x.norm()).fold(0.0, f64::max);
    for p in 0..a.len() {
        assert!((a.position[p] - b.position[p]).norm() < 1e-12 * scale);
        assert!((a.tau[p] - b.tau[p]).norm() <= 1e-8 * a.tau[p].norm().max(1.0));
    }
}

/// A point thrown out of the grid stops the run with the point, the step
/// and the position; an inverting motion names det F.
#[test]
fn leaving_the_grid_is_a_typed_error() {
    let grid = RegularGrid::new(Vector2::zeros(), Vector2::new(0.5, 0.5), [6, 6]).unwrap();
    let (x0, vol) = block(Vector2::new(1.0, 1.0), Vector2::new(2.0, 2.0), 0.5, 2);
    let mut points: PointsFor<2, NeoHookean, Flip> = ExplicitPoints::new(x0, vol, 1.0).unwrap();
    points.set_velocity(|_| Vector2::new(10.0, 0.0));
    let mut solver = ExplicitSolver::new(
        QuadraticBSpline,
        grid,
        NeoHookean::new(1.0, 0.3).unwrap(),
        Flip,
        NoLocking,
        VelocityFixities::new(),
        ExplicitOptions::default(),
    )
    .unwrap();
    let err = solver
        .run_until(&mut points, 10.0, |_, _, _| Ok(()))
        .unwrap_err();
    match &err {
        SolverError::ExplicitPoint {
            step,
            point,
            reason: PointFailure::Basis { position, .. },
            ..
        } => {
            assert!(*step > 1 && *point < 16, "{err}");
            assert!(position[0] > 2.5, "{err}");
        }
        other => panic!("unexpected {other}"),
    }
    let text = err.to_string();
    assert!(
        text.contains("material point") && text.contains("explicit step"),
        "{text}"
    );
}

/// Bad set-up is refused before the first step.
#[test]
fn invalid_options_are_refused() {
    let grid = || RegularGrid::new(Vector2::zeros(), Vector2::new(0.5, 0.5), [6, 6]).unwrap();
    let law = NeoHookean::new(1.0, 0.3).unwrap();
    let mut fixed = VelocityFixities::new();
    fixed.fix([1000], 0);
    let bad_node = ExplicitSolver::new(
        QuadraticBSpline,
        grid(),
        law,
        Flip,
        NoLocking,
        fixed,
        ExplicitOptions::default(),
    );
    assert!(matches!(bad_node, Err(SolverError::InvalidInput(_))));
    for time_step in [
        TimeStep::Cfl { factor: 1.5 },
        TimeStep::Cfl { factor: 0.0 },
        TimeStep::Fixed(-1.0),
        TimeStep::Fixed(f64::NAN),
    ] {
        let options = ExplicitOptions {
            time_step,
            ..Default::default()
        };
        let r = ExplicitSolver::new(
            QuadraticBSpline,
            grid(),
            law,
            Flip,
            NoLocking,
            VelocityFixities::new(),
            options,
        );
        assert!(
            matches!(r, Err(SolverError::InvalidInput(_))),
            "{time_step:?}"
        );
    }
    let r = ExplicitSolver::new(
        QuadraticBSpline,
        grid(),
        law,
        FlipPic { alpha: 1.5 },
        NoLocking,
        VelocityFixities::new(),
        ExplicitOptions::default(),
    );
    assert!(matches!(r, Err(SolverError::InvalidInput(_))));
}
