//! Explicit scenes (`[solver] kind = "explicit"`): the vibrating bar, the
//! colliding disks, the falling cube and the sliding block of `scenes/`
//! against what they must do, and the `mpm` program's explicit outputs,
//! thread counts and resumption.
#![allow(clippy::unwrap_used)]

use super::common;

use common::mpm;

use std::path::{Path, PathBuf};

use mpm_cases::run::{RunControl, Snapshot};
use mpm_cases::scene::{self, ExplicitEvent, ExplicitOutput, Problem};
use mpm_solver::explicit::Energies;

const BAR: &str = include_str!("../../../scenes/explicit_bar.toml");
const DISKS: &str = include_str!("../../../scenes/explicit_disks.toml");
const CUBE: &str = include_str!("../../../scenes/explicit_cube.toml");
const SLIDING_BLOCK: &str = include_str!("../../../scenes/sliding_block.toml");
const ROLLING: &str = include_str!("../../../scenes/rolling_cylinder.toml");
const COLUMN: &str = include_str!("../../../scenes/explicit_absorbing_column.toml");
const SLIDING_CONTACT: &str = include_str!("../../../scenes/sliding_block_contact.toml");
const DISKS_CONTACT: &str = include_str!("../../../scenes/explicit_disks_contact.toml");

/// One output of a run.
struct Frame {
    time: f64,
    energies: Energies,
    snapshot: Snapshot,
}

/// Parses, builds and runs an explicit scene, keeping every output.
fn run<const D: usize>(text: &str, overrides: &[&str]) -> (Problem<D>, Vec<Frame>, ExplicitOutput)
where
    Problem<D>: scene::RunExplicit<D>,
{
    let set: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let (scene, src) = scene::parse(text, "scene.toml", &set).unwrap();
    let problem = Problem::<D>::build(&scene, &src, scene.solver.padding()).unwrap();
    let mut frames = Vec::new();
    let out = scene::run_explicit(&problem, &RunControl::default(), |event| {
        if let ExplicitEvent::Output(f) = event {
            assert_eq!(f.index, frames.len());
            frames.push(Frame {
                time: f.time,
                energies: f.energies,
                snapshot: f.snapshot.clone(),
            });
        }
        Ok(())
    })
    .unwrap();
    (problem, frames, out)
}

/// The mass-weighted mean velocity of `points` in a snapshot.
fn mean_velocity<const D: usize>(
    problem: &Problem<D>,
    snap: &Snapshot,
    points: impl Iterator<Item = usize>,
) -> [f64; 3] {
    let (mut m, mut mv) = (0.0, [0.0; 3]);
    for p in points {
        m += problem.mass[p];
        for (sum, v) in mv.iter_mut().zip(snap.velocity[p]) {
            *sum += problem.mass[p] * v;
        }
    }
    mv.map(|x| x / m)
}

/// The bar fixed at x = 0 and set moving at v0 = 0.1: its free end's
/// velocity is a square wave of amplitude v0 and period 4L/c = 10
/// (+v0 until L/c = 2.5, −v0 until 7.5, +v0 until 12.5, ...), its
/// displacement a triangle wave of amplitude v0 L/c = 0.25, and its energy
/// is conserved but for FLIP's small loss.
///
/// Measured (100 × 2 cells of 0.25, 800 points, Δt = 0.005, 6000 steps):
/// the total energy falls 1.2 % by t = 2.5 — the impact of the bar on its
/// held end nodes at t = 0 — and 2.3 % by t = 30 (three periods); the
/// points within 0.5 m of the tip move +0.245 m at t = 2.5 and −0.237 m at
/// t = 17.5 (the square wave disperses).
#[test]
fn the_bar_rings_as_a_square_wave_and_keeps_its_energy() {
    let (problem, frames, out) = run::<2>(BAR, &[]);
    assert_eq!(frames.len(), 61);
    assert_eq!(out.outputs, 61);
    assert!((out.time - 30.0).abs() < 1e-9, "{}", out.time);
    assert_eq!(out.steps, 6000);
    let v0 = 0.1;
    let tip: Vec<usize> = (0..problem.len())
        .filter(|&p| problem.position[p][0] > 24.5)
        .collect();
    assert!(!tip.is_empty());
    // Mid-way through each half period the tip moves at ±v0.
    for (k, frame) in frames.iter().enumerate().step_by(10).skip(1) {
        let expected = if (k / 10) % 2 == 1 { -v0 } else { v0 };
        let v = mean_velocity(&problem, &frame.snapshot, tip.iter().copied())[0];
        assert!(
            (v - expected).abs() < 0.15 * v0,
            "t = {}: tip velocity {v}, expected {expected}",
            frame.time
        );
    }
    // At the quarter periods the tip is at ±v0 L/c.
    for (k, frame) in frames.iter().enumerate().skip(5).step_by(10) {
        let expected = if (k / 10) % 2 == 0 { 0.25 } else { -0.25 };
        let u = tip
            .iter()
            .map(|&p| frame.snapshot.displacement[p][0])
            .sum::<f64>()
            / tip.len() as f64;
        assert!(
            (u - expected).abs() < 0.1 * 0.25,
            "t = {}: tip displacement {u}, expected {expected}",
            frame.time
        );
    }
    // Energy: kinetic at the half periods, strain at the quarter periods,
    // their total conserved to a few per cent.
    let e0 = frames[0].energies.total();
    assert_eq!(e0, out.initial.total());
    for f in &frames {
        let e = f.energies;
        assert_eq!(e.gravitational, 0.0);
        assert_eq!(e.external_work, 0.0);
        assert!(
            (e.total() - e0).abs() < 0.03 * e0,
            "t = {}: total {} against {e0}",
            f.time,
            e.total()
        );
    }
    assert!(frames[5].energies.strain > 0.95 * frames[5].energies.total());
    assert!(frames[10].energies.kinetic > 0.95 * frames[10].energies.total());
    assert!(
        out.energy_drift < 0.0 && out.energy_drift > -0.03,
        "{}",
        out.energy_drift
    );
    // After the impact FLIP loses well under one per cent per period.
    let after_impact = frames[5].energies.total();
    let last = frames[60].energies.total();
    assert!(
        (after_impact - last) / e0 < 0.015 && last <= after_impact,
        "{after_impact} -> {last}"
    );
}

/// Sulsky et al. 1995's disks meet near t = 1.6 and rebound: the first
/// disk's x velocity changes sign, and the second's mirrors it.
///
/// Measured (40 × 40 cells, 1624 points, 422 steps of CFL 0.4): the total
/// energy falls 6.0 % in the collision (2.6 % on 80 × 80 cells); with the
/// cell-averaged dilatation 7.7 %, with Taylor-FLIP 4.6 %.
#[test]
fn the_disks_collide_and_rebound() {
    for (label, text, bound) in [
        ("flip", DISKS.to_owned(), 0.07),
        (
            "cell_averaged",
            DISKS.replacen("cfl = 0.4", "cfl = 0.4\nlocking = \"cell_averaged\"", 1),
            0.09,
        ),
        (
            "tflip",
            DISKS.replacen(
                "transfer = \"blend\"\nalpha = 1.0",
                "transfer = \"tflip\"",
                1,
            ),
            0.06,
        ),
    ] {
        assert!(label == "flip" || text != DISKS, "{label}");
        let (problem, frames, out) = run::<2>(&text, &[]);
        assert!((out.time - 3.0).abs() < 1e-12, "{label}");
        let [a, b] = [&problem.bodies[0], &problem.bodies[1]];
        assert_eq!(a.points.len(), b.points.len());
        let va = |f: &Frame| mean_velocity(&problem, &f.snapshot, a.points.clone());
        let vb = |f: &Frame| mean_velocity(&problem, &f.snapshot, b.points.clone());
        let first = &frames[0];
        assert!((va(first)[0] - 0.1).abs() < 1e-12);
        assert!((vb(first)[0] + 0.1).abs() < 1e-12);
        let last = frames.last().unwrap();
        let (end_a, end_b) = (va(last), vb(last));
        assert!(
            end_a[0] < -0.05 && end_a[1] < -0.05,
            "{label}: disk a ends at {end_a:?}"
        );
        assert!(
            end_b[0] > 0.05 && end_b[1] > 0.05,
            "{label}: disk b ends at {end_b:?}"
        );
        // Momentum is conserved: the disks' velocities mirror each other.
        assert!((end_a[0] + end_b[0]).abs() < 1e-9, "{end_a:?} {end_b:?}");
        // They move apart again: no point of a within a cell of b.
        let gap = a
            .points
            .clone()
            .flat_map(|p| b.points.clone().map(move |q| (p, q)))
            .map(|(p, q)| {
                let (x, y) = (last.snapshot.position[p], last.snapshot.position[q]);
                ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2)).sqrt()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(gap > 0.025, "{label}: gap {gap}");
        // Before they meet nothing changes; then energy is lost, not made.
        let (e0, e20) = (frames[0].energies.total(), frames[20].energies.total());
        assert!((e20 - e0).abs() < 1e-12 * e0, "{label}: {e0} -> {e20}");
        assert!(
            out.energy_drift < 0.0 && out.energy_drift > -bound,
            "{label}: drift {}",
            out.energy_drift
        );
    }
}

/// A granular column collapse (issue 43, "Explicit";
/// `scenes/granular_collapse.toml`): cohesionless Mohr–Coulomb sand
/// spreads to a run-out ΔL/L0 within 15 % of Lube et al. 2005's
/// two-dimensional columns — 1.2a below a ≈ 1.8, 1.9a^(2/3) above ≈ 2.8 —
/// at a = 0.5 (the scene) and at a = 2 (L0 = 0.5 m, H = 1 m: between the
/// two, so within 15 % of both), and its total energy never increases
/// from one output to the next (the law dissipates, the explicit step adds
/// nothing). The front is the rightmost point plus half the points'
/// spacing. Measured: 0.581 (1.2a = 0.600) and 2.61 (2.40 and 3.02).
#[test]
fn a_granular_column_runs_out_as_lube_measured() {
    let text = std::fs::read_to_string(scene_path("granular_collapse.toml")).unwrap();
    let tall = text
        .replace("size = [3.0, 0.75]", "size = [3.0, 1.25]")
        .replace("cells = [96, 24]", "cells = [96, 40]")
        .replace("upper = [1.0, 0.5]", "upper = [0.5, 1.0]");
    for (scene, l0, a, references) in [
        (text.as_str(), 1.0, 0.5, vec![1.2 * 0.5]),
        (
            tall.as_str(),
            0.5,
            2.0,
            vec![1.2 * 2.0, 1.9 * 2f64.powf(2.0 / 3.0)],
        ),
    ] {
        let (_, frames, out) = run::<2>(scene, &[]);
        assert!((out.time - 1.5).abs() < 1e-12);
        let last = frames.last().unwrap();
        let spacing = 1.0 / 64.0;
        let front = last
            .snapshot
            .position
            .iter()
            .map(|x| x[0])
            .fold(f64::MIN, f64::max)
            + spacing / 2.0;
        let runout = (front - l0) / l0;
        println!("granular collapse a = {a}: ΔL/L0 = {runout:.3} against {references:?}");
        for r in references {
            assert!(
                (runout - r).abs() <= 0.15 * r,
                "a = {a}: ΔL/L0 = {runout} against {r}"
            );
        }
        for w in frames.windows(2) {
            let (e0, e1) = (w[0].energies.total(), w[1].energies.total());
            assert!(
                e1 <= e0 + 1e-12 * e0.abs(),
                "a = {a}, t = {}: {e0} -> {e1}",
                w[1].time
            );
        }
        // At a = 2 one cell's width of points stays stacked against the
        // slip wall (32 points at x ≈ 0.02 m up to 0.63 m, the deposit
        // beside it 0.51 m): left out of the slope, and open.
        let from = if a > 1.0 { 1.0 / 32.0 } else { 0.0 };
        let steepest = steepest_surface(&last.snapshot.position, from);
        println!("granular collapse a = {a}: steepest surface {steepest:.1}°");
        assert!(steepest <= 30.0 + 1.5, "a = {a}: surface at {steepest}°");
    }
}

/// The steepest slope (degrees) of the free surface of points at
/// `position` right of `from`: the highest point of each column of cells
/// (1/32 m), a least-squares line over every 5 neighbouring columns. One
/// column alone is no measure: the points' lattice layers the surface by
/// up to one point spacing (1/64 m), 27° over one cell on a level
/// surface; over four cells that is 7°.
fn steepest_surface(position: &[[f64; 3]], from: f64) -> f64 {
    let h = 1.0 / 32.0;
    let mut top = std::collections::BTreeMap::new();
    for x in position.iter().filter(|x| x[0] >= from) {
        let column = (x[0] / h).floor() as i64;
        let y = top.entry(column).or_insert(f64::MIN);
        *y = x[1].max(*y);
    }
    let profile: Vec<(f64, f64)> = top
        .iter()
        .map(|(&k, &y)| ((k as f64 + 0.5) * h, y))
        .collect();
    profile
        .windows(5)
        .map(|w| {
            let n = w.len() as f64;
            let (mx, my) = (
                w.iter().map(|p| p.0).sum::<f64>() / n,
                w.iter().map(|p| p.1).sum::<f64>() / n,
            );
            let sxy: f64 = w.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
            let sxx: f64 = w.iter().map(|p| (p.0 - mx).powi(2)).sum();
            (sxy / sxx).abs().atan().to_degrees()
        })
        .fold(0.0, f64::max)
}

/// The cube falls freely — its energy constant to rounding, its centroid
/// at z0 − g t²/2 — until its points near the floor's nodes, then lands,
/// stops short of the floor (the held nodes reach 1.5 cells up through
/// the B-splines) and bounces.
///
/// Measured: the lowest point comes down to 0.042 m at t = 0.25 s; at
/// t = 0.3 s the cube rises at 1.7 m/s, having landed at 2.16 m/s.
#[test]
fn the_cube_falls_freely_then_bounces_on_the_floor() {
    let (problem, frames, out) = run::<3>(CUBE, &["solver.end_time=0.3"]);
    assert!((out.time - 0.3).abs() < 1e-12);
    assert_eq!(problem.len(), 4096);
    let mass: f64 = problem.mass.iter().sum();
    let centroid = |s: &Snapshot| {
        (0..problem.len())
            .map(|p| problem.mass[p] * s.position[p][2])
            .sum::<f64>()
            / mass
    };
    let e0 = frames[0].energies.total();
    let z0 = centroid(&frames[0].snapshot);
    assert!((z0 - 0.5).abs() < 1e-12);
    let mut free = 0;
    for f in frames.iter().filter(|f| f.time <= 0.2 + 1e-12) {
        let t = f.time;
        assert!(
            (f.energies.total() - e0).abs() < 1e-12 * e0,
            "t = {t}: {} against {e0}",
            f.energies.total()
        );
        let z = centroid(&f.snapshot);
        assert!(
            (z - (z0 - 0.5 * 9.81 * t * t)).abs() < 1e-9,
            "t = {t}: centroid {z}"
        );
        free += 1;
    }
    assert!(free > 10);
    let lowest = frames
        .iter()
        .flat_map(|f| f.snapshot.position.iter().map(|x| x[2]))
        .fold(f64::INFINITY, f64::min);
    assert!(lowest > 0.0 && lowest < 0.06, "lowest point {lowest}");
    let rising = mean_velocity(&problem, &frames.last().unwrap().snapshot, 0..problem.len());
    assert!(rising[2] > 1.0, "{rising:?}");
    assert!(out.energy_drift < 0.0);
}

/// The sliding block of issue 44 (`scenes/sliding_block.toml`): a block
/// on a 30° incline — the grid's floor, a friction wall, with gravity
/// turned by 30° — moves at g (sin θ − μ cos θ) t, at every output, within
/// the 1 % of the issue: 0.4905 m/s at t = 0.1 s with μ = 0 and 0.40554
/// m/s with μ = 0.1; the friction work is μ g cos θ M s with the sliding
/// distance s = ½ g (sin θ − μ cos θ) t² (1 %); with μ = 0.6 > tan θ and
/// its weight brought on over 0.05 s (the scene's curve `settle`) the
/// block stays put, |v| < 1e-6 m/s at t = 0.1 s. In every run kinetic +
/// strain + friction and wall work balance the work of gravity within 1 %
/// (the issue's energy bound).
///
/// Measured (800 points, about 4650 steps each, 2.5 s for the three runs
/// in release on 2 cores): 0.4905000 and 0.4055429 m/s (relative errors
/// 6e-15 and 9e-8), stuck below 5e-8 m/s; energy residuals −1.1e-5,
/// +1.5e-5 and −3.5e-3 of the work (with the stick's tangential loss in
/// `wall_work`; −2.2e-5, +5.4e-6 and −3.6e-3 before).
#[test]
fn a_block_slides_down_a_friction_incline_as_coulomb_says_and_sticks_beyond_tan_theta() {
    let (g, theta) = (9.81, 30f64.to_radians());
    for (mu, sets) in [
        (0.0, vec!["boundary.0.friction=0.0"]),
        (0.1, vec![]),
        (
            0.6,
            vec!["boundary.0.friction=0.6", "load.0.curve=\"settle\""],
        ),
    ] {
        let (problem, frames, out) = run::<2>(SLIDING_BLOCK, &sets);
        assert!((out.time - 0.1).abs() < 1e-12);
        assert_eq!(frames.len(), 11);
        let mass: f64 = problem.mass.iter().sum();
        let a = g * (theta.sin() - mu * theta.cos());
        let last = frames.last().unwrap();
        let v = mean_velocity(&problem, &last.snapshot, 0..problem.len());
        let (first, end) = (frames[0].energies, last.energies);
        let work = end.external_work + first.gravitational - end.gravitational;
        let residual = (end.total() - first.total()) / work;
        println!(
            "sliding block, μ = {mu}: v(0.1 s) = ({:.7}, {:.1e}) m/s against {:.7}, friction work {:.6} J/m, energy residual {residual:+.1e} of the work {work:.4e} J/m",
            v[0],
            v[1],
            a.max(0.0) * 0.1,
            end.friction_work
        );
        assert!(residual.abs() < 0.01, "μ = {mu}: {first:?} -> {end:?}");
        if a < 0.0 {
            let speed = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!(speed < 1e-6, "μ = {mu}: the block moves at {v:?}");
            continue;
        }
        for f in &frames[1..] {
            let v = mean_velocity(&problem, &f.snapshot, 0..problem.len());
            let exact = a * f.time;
            assert!(
                (v[0] - exact).abs() < 0.01 * exact && v[1].abs() < 0.01 * exact,
                "μ = {mu}, t = {}: {v:?} against {exact}",
                f.time
            );
        }
        let sliding = 0.5 * a * 0.1 * 0.1;
        let friction = mu * g * theta.cos() * mass * sliding;
        assert!(
            (end.friction_work - friction).abs() <= 0.01 * friction,
            "μ = {mu}: friction work {} against {friction}",
            end.friction_work
        );
    }
}

/// The least-squares fit of $y = c_0 + c_1 t + c_2 t^2$ to `(t, y)`:
/// $(c_0, c_1, c_2)$.
fn quadratic_fit(samples: &[(f64, f64)]) -> [f64; 3] {
    let mut normal = nalgebra::Matrix3::<f64>::zeros();
    let mut rhs = nalgebra::Vector3::<f64>::zeros();
    for &(t, y) in samples {
        let row = nalgebra::Vector3::new(1.0, t, t * t);
        normal += row * row.transpose();
        rhs += row * y;
    }
    let c = normal.lu().solve(&rhs).unwrap();
    [c[0], c[1], c[2]]
}

/// The least-squares slope of `(t, y)`.
fn slope(samples: &[(f64, f64)]) -> f64 {
    let n = samples.len() as f64;
    let (t, y) = samples
        .iter()
        .fold((0.0, 0.0), |(t, y), s| (t + s.0 / n, y + s.1 / n));
    let (mut ty, mut tt) = (0.0, 0.0);
    for s in samples {
        ty += (s.0 - t) * (s.1 - y);
        tt += (s.0 - t) * (s.0 - t);
    }
    ty / tt
}

/// The centre of mass and the mean angular velocity (about the centre,
/// positive counter-clockwise) of a 2D snapshot's points:
/// $\omega = \sum m\,(\mathbf r\times\mathbf u) / \sum m\,|\mathbf r|^2$
/// with $\mathbf r$, $\mathbf u$ relative to the centre's position and
/// velocity (exact for a rigid motion).
fn centre_and_spin(problem: &Problem<2>, snap: &Snapshot) -> ([f64; 2], f64) {
    let mass: f64 = problem.mass.iter().sum();
    let (mut x, mut v) = ([0.0; 2], [0.0; 2]);
    for (p, m) in problem.mass.iter().enumerate() {
        for c in 0..2 {
            x[c] += m * snap.position[p][c] / mass;
            v[c] += m * snap.velocity[p][c] / mass;
        }
    }
    let (mut spin, mut inertia) = (0.0, 0.0);
    for (p, m) in problem.mass.iter().enumerate() {
        let r = [snap.position[p][0] - x[0], snap.position[p][1] - x[1]];
        let u = [snap.velocity[p][0] - v[0], snap.velocity[p][1] - v[1]];
        spin += m * (r[0] * u[1] - r[1] * u[0]);
        inertia += m * (r[0] * r[0] + r[1] * r[1]);
    }
    (x, spin / inertia)
}

/// The rolling cylinder of issue 44 (`scenes/rolling_cylinder.toml`): a
/// solid disk on the 30° incline of the sliding block, its floor a
/// gap-checked friction wall. With μ = 0.3 ≥ tan θ/3 it rolls without
/// slipping: its centre accelerates at g sin θ/(1 + I/(m R²)) = ⅔ g sin θ
/// = 3.270 m/s² (the issue's 3 %), its angular acceleration times R is
/// the same (rolling, ω R = v; 3 % too), and kinetic + strain + friction
/// and wall work balance the work of gravity within the issue's 1 %. With
/// μ = 0.1 < tan θ/3 it slips, at g (sin θ − μ cos θ) = 4.0554 m/s² (3 %);
/// that run takes 10 cells per radius (the slip needs no resolved
/// rotation). The accelerations are least-squares fits of the centre's
/// displacement (and of ω) over the outputs from 0.05 s: before, the disk
/// settles from gravity put on at once and tips off the flat its lattice
/// of points has at the bottom.
///
/// Measured (release): 3.2722 m/s² (+0.07 %), α R = 3.258 m/s², energy
/// residual −5.2e-3 (11304 points, 3048 steps); slipping 4.0553 m/s²
/// (−0.00 %), α R = 1.248 m/s², residual −5.9e-3; 10 s of CPU for the
/// two runs (16.6 s on 2 cores shared with other builds).
#[test]
fn a_cylinder_rolls_down_a_friction_incline_at_two_thirds_g_sin_theta_and_slips_below_tan_theta_over_three()
 {
    let (g, theta, radius) = (9.81, 30f64.to_radians(), 0.05);
    for (mu, sets) in [
        (0.3, vec![]),
        (0.1, vec!["boundary.0.friction=0.1", "mesh.cells=[60, 24]"]),
    ] {
        let (problem, frames, out) = run::<2>(ROLLING, &sets);
        assert!((out.time - 0.2).abs() < 1e-12);
        let (mut path, mut spin) = (Vec::new(), Vec::new());
        for f in frames.iter().filter(|f| f.time >= 0.05 - 1e-9) {
            let (x, omega) = centre_and_spin(&problem, &f.snapshot);
            path.push((f.time, x[0]));
            spin.push((f.time, omega));
        }
        assert_eq!(path.len(), 16);
        let a = 2.0 * quadratic_fit(&path)[2];
        let alpha_r = -slope(&spin) * radius;
        let rolls = mu >= theta.tan() / 3.0;
        let exact = if rolls {
            2.0 / 3.0 * g * theta.sin()
        } else {
            g * (theta.sin() - mu * theta.cos())
        };
        let (first, end) = (frames[0].energies, frames.last().unwrap().energies);
        let work = end.external_work + first.gravitational - end.gravitational;
        let residual = (end.total() - first.total()) / work;
        println!(
            "rolling cylinder, μ = {mu}: a = {a:.4} m/s² against {exact:.4} ({:+.2} %), α R = {alpha_r:.4} m/s², friction work {:.4e}, wall work {:.4e}, energy residual {residual:+.1e} of the work {work:.4} J/m",
            100.0 * (a / exact - 1.0),
            end.friction_work,
            end.wall_work
        );
        assert!((a - exact).abs() < 0.03 * exact, "μ = {mu}: a = {a}");
        if rolls {
            assert!((alpha_r - exact).abs() < 0.03 * exact, "α R = {alpha_r}");
        } else {
            // Slip: the contact point moves down the incline.
            assert!(alpha_r < a, "slipping: α R = {alpha_r}, a = {a}");
        }
        assert!(residual.abs() < 0.01, "μ = {mu}: {first:?} -> {end:?}");
    }
}

/// The block of issue 44 on a deformable incline with multi-field contact
/// (`scenes/sliding_block_contact.toml`): the block's mean displacement
/// along the slab is s(t) = ½ g (sin θ − μ cos θ) t² at every output
/// within the issue's 2 %, for μ = 0.2 and μ = 0; the block does not sink
/// into the slab by more than 0.1 cell (the gap between the block's
/// lowest point and the slab's highest one under it, against the initial
/// gap); the friction work is μ g cos θ M s (1 %); kinetic + strain +
/// friction and impact work balance the work of gravity within the
/// issue's 1 %.
///
/// Measured (1440 points, 10 380 steps, about 2.7 s per run in release
/// on 2 cores): s(0.1 s) = 16.0300 mm against 16.0293 (μ = 0.2, +4e-5)
/// and 24.5250 mm against 24.5250 (μ = 0).
#[test]
fn a_block_slides_on_a_deformable_incline_by_multi_field_contact() {
    let (g, theta, h) = (9.81, 30f64.to_radians(), 0.005);
    for (mu, sets) in [(0.2, vec![]), (0.0, vec!["contact.0.friction=0.0"])] {
        let (problem, frames, out) = run::<2>(SLIDING_CONTACT, &sets);
        assert!((out.time - 0.1).abs() < 1e-12);
        let [slab, block] = [&problem.bodies[0], &problem.bodies[1]];
        assert_eq!(
            (slab.name.as_str(), block.name.as_str()),
            ("incline", "block")
        );
        let mass: f64 = block.points.clone().map(|p| problem.mass[p]).sum();
        let a = g * (theta.sin() - mu * theta.cos());
        let gap = |f: &Frame| {
            let x = &f.snapshot.position;
            let lowest = block
                .points
                .clone()
                .map(|p| x[p][1])
                .fold(f64::MAX, f64::min);
            let (left, right) = block
                .points
                .clone()
                .map(|p| x[p][0])
                .fold((f64::MAX, f64::MIN), |(l, r), x| (l.min(x), r.max(x)));
            let highest = slab
                .points
                .clone()
                .filter(|&p| x[p][0] >= left - h && x[p][0] <= right + h)
                .map(|p| x[p][1])
                .fold(f64::MIN, f64::max);
            lowest - highest
        };
        let gap0 = gap(&frames[0]);
        assert!((gap0 - 0.5 * h).abs() < 1e-12, "{gap0}");
        let mut worst: f64 = 0.0;
        for f in &frames[1..] {
            let n = block.points.len() as f64;
            let s = block
                .points
                .clone()
                .map(|p| f.snapshot.displacement[p][0])
                .sum::<f64>()
                / n;
            let exact = 0.5 * a * f.time * f.time;
            assert!(
                (s - exact).abs() < 0.02 * exact,
                "μ = {mu}, t = {}: s = {s} against {exact}",
                f.time
            );
            worst = worst.max(gap0 - gap(f));
        }
        assert!(
            worst < 0.1 * h,
            "μ = {mu}: the block sinks {worst} m into the slab"
        );
        let last = frames.last().unwrap();
        let n = block.points.len() as f64;
        let s = block
            .points
            .clone()
            .map(|p| last.snapshot.displacement[p][0])
            .sum::<f64>()
            / n;
        let (first, end) = (frames[0].energies, last.energies);
        let work = end.external_work + first.gravitational - end.gravitational;
        let residual = (end.total() - first.total()) / work;
        let friction = mu * g * theta.cos() * mass * s;
        println!(
            "block on incline, μ = {mu}: s(0.1 s) = {s:.7} m against {:.7}, sinks {worst:.2e} m, friction work {:.6} J/m against {friction:.6}, impact {:.2e} J/m, energy residual {residual:+.1e} of the work {work:.4e} J/m",
            0.5 * a * 0.01,
            end.friction_work,
            end.wall_work
        );
        assert!(residual.abs() < 0.01, "μ = {mu}: {first:?} -> {end:?}");
        assert!(
            (end.friction_work - friction).abs() <= 0.01 * friction.max(1e-9 * work),
            "μ = {mu}: friction work {} against {friction}",
            end.friction_work
        );
    }
}

/// The colliding disks with multi-field contact
/// (`scenes/explicit_disks_contact.toml`): they rebound (each disk's
/// velocity reversed, mirrored by the other's: momentum is conserved) and
/// come apart — the gap between their closest points, smallest at the
/// impact, has grown by more than a cell at t = 3 (with one field the
/// points of the two disks near the impact move together: they stick).
/// The energy drift of both runs is printed (measured: −10.6 % with
/// contact, impact losses booked, against −6.0 % with one field: the
/// contact's normal correction makes each contact node's impact
/// inelastic, docs/src/theory/contact.md).
#[test]
fn colliding_disks_with_contact_rebound_and_come_apart() {
    let h = 0.025;
    let (problem, frames, out) = run::<2>(DISKS_CONTACT, &[]);
    let [a, b] = [&problem.bodies[0], &problem.bodies[1]];
    let gap = |f: &Frame| {
        let x = &f.snapshot.position;
        let mut d2 = f64::MAX;
        for p in a.points.clone() {
            for q in b.points.clone() {
                let (dx, dy) = (x[p][0] - x[q][0], x[p][1] - x[q][1]);
                d2 = d2.min(dx * dx + dy * dy);
            }
        }
        d2.sqrt()
    };
    let gaps: Vec<f64> = frames.iter().map(gap).collect();
    let (closest, smallest) =
        gaps.iter().enumerate().fold(
            (0, f64::MAX),
            |(k, g), (j, &x)| if x < g { (j, x) } else { (k, g) },
        );
    let last = frames.last().unwrap();
    let va = mean_velocity(&problem, &last.snapshot, a.points.clone());
    let vb = mean_velocity(&problem, &last.snapshot, b.points.clone());
    let (_, _, single) = run::<2>(DISKS, &[]);
    println!(
        "disks with contact: closest {smallest:.4} m at t = {}, {:.4} m at t = 3; velocities {va:?} {vb:?}; energy drift {:+.3e} (one field {:+.3e})",
        frames[closest].time,
        gaps.last().unwrap(),
        out.energy_drift,
        single.energy_drift
    );
    assert!(closest > 0 && closest + 1 < frames.len(), "{gaps:?}");
    assert!(*gaps.last().unwrap() > smallest + h, "{gaps:?}");
    assert!(va[0] < -0.05 && va[1] < -0.05, "{va:?}");
    assert!(vb[0] > 0.05 && vb[1] > 0.05, "{vb:?}");
    assert!((va[0] + vb[0]).abs() < 1e-9 && (va[1] + vb[1]).abs() < 1e-9);
}

fn scene_path(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(file)
}

/// The rows of a CSV file as numbers, after checking its header.
fn csv_rows(path: &Path, header: &str) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(header), "{}", path.display());
    lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect()
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// `mpm run` of the bar on one and on two threads: the same energies to
/// rounding (the points are split into one range per thread, so sums are
/// taken in another order), and every explicit output.
#[test]
fn one_and_two_threads_give_the_same_energies() {
    let header = "time,kinetic,strain,gravitational,external_work,friction_work,wall_work,absorbed_work,spring_energy,total";
    let mut runs = Vec::new();
    for threads in ["1", "2"] {
        let dir = common::fresh_dir(&format!("explicit-threads-{threads}"));
        let (ok, out, err) = mpm(&[
            "run",
            scene_path("explicit_bar.toml").to_str().unwrap(),
            "--threads",
            threads,
            "--set",
            "solver.output_interval=2.5",
            "--out",
            dir.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        assert!(
            out.contains("scene [explicit bspline2 flip none]: 800 points, 6000 time steps"),
            "{out}"
        );
        let rows = csv_rows(&dir.join("energy.csv"), header);
        assert_eq!(rows.len(), 13);
        assert_eq!(rows[0][0], 0.0);
        assert!((rows[12][0] - 30.0).abs() < 1e-9);
        for row in &rows {
            assert_eq!(
                (row[5], row[6], row[7], row[8]),
                (0.0, 0.0, 0.0, 0.0),
                "no wall"
            );
            let total = row[1] + row[2] + row[3] + row[5] + row[6] + row[7] + row[8] - row[4];
            assert!((row[9] - total).abs() < 1e-15, "{row:?}");
        }
        let probe = csv_rows(&dir.join("probe_tip.csv"), "time,ux,uy");
        assert_eq!(probe.len(), 13);
        assert!((probe[1][1] - 0.245).abs() < 0.01, "{:?}", probe[1]);
        for file in [
            "points.pvd",
            "grid.pvd",
            "points_0000.vtu",
            "points_0012.vtu",
            "grid_0012.vtu",
            "checkpoint.mpm",
        ] {
            assert!(dir.join(file).exists(), "{file}");
        }
        assert!(!dir.join("steps.csv").exists());
        let vtu = std::fs::read_to_string(dir.join("points_0012.vtu")).unwrap();
        assert!(vtu.contains("Name=\"velocity\""));
        let s = summary(&dir);
        assert_eq!(s["solver"], "explicit");
        assert_eq!(s["transfer"], "flip");
        assert_eq!(s["time_steps"], 6000);
        assert_eq!(s["outputs"], 13);
        assert_eq!(s["material_points"], 800);
        assert!((s["end_time"].as_f64().unwrap() - 30.0).abs() < 1e-9);
        assert!(s["wall_time_s"].as_f64().unwrap() > 0.0);
        let drift = s["energy_drift"].as_f64().unwrap();
        assert!(drift < 0.0 && drift > -0.03, "{drift}");
        assert_eq!(s["final_energies"]["total"].as_f64().unwrap(), rows[12][9]);
        runs.push(rows);
    }
    for (a, b) in runs[0].iter().zip(&runs[1]) {
        let scale = a[9].abs();
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-9 * scale, "{a:?} against {b:?}");
        }
    }
}

/// An explicit run split with `--stop-after` (outputs) and `--resume`
/// writes exactly the files of the uninterrupted run.
#[test]
fn an_explicit_run_resumes_bit_for_bit() {
    resumes_bit_for_bit("explicit", &[]);
}

/// The same with GIMP, whose half-lengths (updated by eq. 34 after every
/// step) the checkpoint keeps, and the VTU files write as each point's
/// domain box.
#[test]
fn an_explicit_gimp_run_resumes_bit_for_bit() {
    let dir = resumes_bit_for_bit(
        "explicit-gimp",
        &[
            "--set",
            "solver.basis=gimp",
            "--set",
            "solver.domain_update=stretch",
        ],
    );
    let vtu = std::fs::read_to_string(dir.join("points_0012.vtu")).unwrap();
    assert!(vtu.contains("Name=\"domain_lower\"") && vtu.contains("Name=\"domain_upper\""));
}

/// The same with CPDI2, whose convected corners the checkpoint keeps.
#[test]
fn an_explicit_cpdi2_run_resumes_bit_for_bit() {
    let dir = resumes_bit_for_bit("explicit-cpdi2", &["--set", "solver.basis=cpdi2"]);
    let vtu = std::fs::read_to_string(dir.join("points_0012.vtu")).unwrap();
    assert!(vtu.contains("Name=\"domain_lower\"") && vtu.contains("Name=\"domain_upper\""));
}

/// Runs the disks whole and split in three; returns the whole run's
/// directory.
fn resumes_bit_for_bit(tag: &str, sets: &[&str]) -> PathBuf {
    resumes_bit_for_bit_in("explicit_disks.toml", tag, sets)
}

/// The disks with multi-field contact resume bit for bit: each point's
/// velocity field is rebuilt from its body when the checkpoint is read
/// (the checkpoint holds no field), and the fields' grids are rebuilt
/// every step.
#[test]
fn an_explicit_run_with_contact_resumes_bit_for_bit() {
    resumes_bit_for_bit_in("explicit_disks_contact.toml", "explicit-contact", &[]);
}

/// Runs the scene `file` (the disks, or a variant with their output
/// times) whole and split in three; returns the whole run's directory.
fn resumes_bit_for_bit_in(file: &str, tag: &str, sets: &[&str]) -> PathBuf {
    let scene = scene_path(file);
    let run = |dir: &Path, extra: &[&str]| {
        let mut args = vec![
            "run",
            scene.to_str().unwrap(),
            "--set",
            "solver.output_interval=0.25",
            "--out",
            dir.to_str().unwrap(),
        ];
        args.extend(sets);
        args.extend(extra);
        mpm(&args)
    };
    let whole = common::fresh_dir(&format!("{tag}-whole"));
    let split = common::fresh_dir(&format!("{tag}-split"));
    let (ok, _, err) = run(&whole, &[]);
    assert!(ok, "{err}");
    let (ok, out, err) = run(&split, &["--stop-after", "5"]);
    assert!(ok, "{err}");
    assert!(out.contains("stopped after output 5 at t = 1.2"), "{out}");
    assert!(!split.join("summary.json").exists());
    let (ok, out, err) = run(&split, &["--resume", "--stop-after", "4"]);
    assert!(ok && out.contains("stopped after output 9"), "{out}{err}");
    let (ok, _, err) = run(&split, &["--resume"]);
    assert!(ok, "{err}");
    let files = common::run_outputs;
    let (a, b) = (files(&whole), files(&split));
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    assert!(a.contains_key("final.png") && a.contains_key("energy.csv"));
    for (name, bytes) in &a {
        assert!(*bytes == b[name], "{name} differs after resuming");
    }
    let timeless = |dir: &Path| {
        let mut s = summary(dir);
        let o = s.as_object_mut().unwrap();
        o.remove("wall_time_s");
        o.remove("stage_times_s");
        s
    };
    assert_eq!(timeless(&whole), timeless(&split));
    whole
}

/// What the program refuses for an explicit scene, and a valid scene of
/// the malformed-scene table run explicitly.
#[test]
fn explicit_runs_refuse_what_they_cannot_do() {
    let dir = common::fresh_dir("explicit-refusals");
    let disks = scene_path("explicit_disks.toml");
    let (ok, _, err) = mpm(&[
        "run",
        disks.to_str().unwrap(),
        "--export-tangent",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("--export-tangent writes the implicit solver's stiffness"),
        "{err}"
    );
    let (ok, _, err) = mpm(&[
        "run",
        disks.to_str().unwrap(),
        "--threads",
        "0",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("--threads"), "{err}");
    // A domain rule that does not fit the basis is located at its override.
    let (ok, _, err) = mpm(&[
        "run",
        disks.to_str().unwrap(),
        "--set",
        "solver.basis=cpdi2",
        "--set",
        "solver.domain_update=stretch",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains(
            "override `solver.domain_update=stretch`: basis = cpdi2 convects its corners"
        ),
        "{err}"
    );

    // The implicit runner refuses an explicit problem and back.
    let (scene, src) = scene::parse(DISKS, "d.toml", &[]).unwrap();
    let problem = Problem::<2>::build(&scene, &src, scene.solver.padding()).unwrap();
    let e = scene::run(&problem, &RunControl::default(), |_, _, _| Ok(())).unwrap_err();
    assert!(e.to_string().contains("run_explicit"), "{e}");
    let (scene, src) = scene::parse(
        include_str!("../../../scenes/two_layer_column.toml"),
        "c.toml",
        &[],
    )
    .unwrap();
    let problem = Problem::<2>::build(&scene, &src, scene.solver.padding()).unwrap();
    assert!(problem.explicit.is_none());
    let e = scene::run_explicit(&problem, &RunControl::default(), |_| Ok(())).unwrap_err();
    assert!(e.to_string().contains("implicit"), "{e}");
}

/// Point loads and tractions are constant forces whose work the energy
/// balance books; a `velocity` condition drives its nodes.
#[test]
fn point_loads_do_work_and_velocity_conditions_drive_nodes() {
    let text = r#"
[mesh]
origin = [0.0, 0.0]
size = [4.0, 1.0]
cells = [32, 8]

[[material]]
name = "m"
model = "hencky"
youngs_modulus = 1e4
poisson_ratio = 0.3
density = 100.0

[[body]]
name = "b"
material = "m"
region = { box = { lower = [1.0, 0.0], upper = [3.0, 1.0] } }

[[load]]
kind = "point"
force = [5.0, 0.0]
region = { box = { lower = [2.5, 0.0], upper = [3.0, 1.0] } }

[[load]]
kind = "traction"
body = "b"
side = "x_min"
traction = [-5.0, 0.0]

[solver]
kind = "explicit"
basis = "linear"
end_time = 0.5
"#;
    let (problem, frames, out) = run::<2>(text, &[]);
    let setup = problem.explicit.as_ref().unwrap();
    let total: f64 = setup.point_forces.iter().map(|(_, f)| f[0]).sum();
    assert!((total - 0.0).abs() < 1e-12, "{total}");
    // The forces stretch the block: work done, and the balance holds to
    // the discretisation's error (the work is integrated with the points'
    // velocities, the forces act through the grid): measured 4.1, 1.5 and
    // 0.8 % of the largest kinetic + strain energy on 16 × 4, 32 × 8 and
    // 64 × 16 cells, the same for Δt five times smaller.
    let last = frames.last().unwrap().energies;
    assert!(last.external_work > 0.0 && last.strain > 0.0);
    assert!(out.energy_drift.abs() < 0.02, "{}", out.energy_drift);
    // Nodes across the block's right end held at 0.1 m/s pull it along.
    let pulled = text.replacen(
        "[solver]",
        "[[node_set]]\nname = \"right\"\nregion = { box = { lower = [2.75, -1.0], upper = [3.25, 2.0] } }\n\n[[boundary]]\nset = \"right\"\nkind = \"velocity\"\nvelocity = { x = 0.1 }\n\n[solver]",
        1,
    );
    let (problem, frames, _) = run::<2>(&pulled, &[]);
    let right: Vec<usize> = (0..problem.len())
        .filter(|&p| problem.position[p][0] > 2.9)
        .collect();
    let v = mean_velocity(
        &problem,
        &frames.last().unwrap().snapshot,
        right.into_iter(),
    );
    assert!((v[0] - 0.1).abs() < 0.02, "{v:?}");
}

/// Two materials that differ in stiffness run as a set: the disks of
/// `explicit_disks.toml` with the second one 100 times stiffer (its wave
/// speed 10 times the first's) collide, the step follows the stiff disk's
/// wave speed, the energy is kept until they touch and only lost after,
/// and a run stopped and resumed (each point's material tag in the
/// checkpoint) writes the same files as the whole run.
#[test]
fn a_soft_and_a_stiff_disk_run_as_a_material_set_and_resume() {
    let base = std::fs::read_to_string(scene_path("explicit_disks.toml")).unwrap();
    let stiff = base.replacen(
        "[[material]]",
        "[[material]]\nname = \"stiff\"\nmodel = \"neo_hookean\"\nyoungs_modulus = 1.0e5\npoisson_ratio = 0.3\ndensity = 1000.0\n\n[[material]]",
        1,
    );
    let at = stiff.rfind("material = \"elastic\"").unwrap();
    let mut text = stiff.clone();
    text.replace_range(
        at..at + "material = \"elastic\"".len(),
        "material = \"stiff\"",
    );
    let dir = common::fresh_dir("explicit-set");
    let file = dir.join("two_materials.toml");
    std::fs::write(&file, &text).unwrap();
    let run = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "run",
            file.to_str().unwrap(),
            "--set",
            "solver.output_interval=0.5",
            "--set",
            "output.png=false",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        mpm(&args)
    };
    let (whole, split) = (dir.join("whole"), dir.join("split"));
    let (ok, _, err) = run(&whole, &[]);
    assert!(ok, "{err}");
    let (ok, out, err) = run(&split, &["--stop-after", "2"]);
    assert!(ok && out.contains("stopped after output 2"), "{out}{err}");
    let (ok, _, err) = run(&split, &["--resume"]);
    assert!(ok, "{err}");
    let (a, b) = (common::run_outputs(&whole), common::run_outputs(&split));
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (name, bytes) in &a {
        assert!(*bytes == b[name], "{name} differs after resuming");
    }
    let set = summary(&whole);
    let steps = |s: &serde_json::Value| s["time_steps"].as_f64().unwrap();
    // Before the disks touch (t ≤ 1) the energy is kept to rounding; the
    // grid's contact is sticky, and holding a disk 100 times stiffer the
    // soft one rings and loses more in it than two equal disks (−18 %
    // measured at t = 3, −6 % for one material at any stiffness), but
    // energy is only lost, never gained.
    let csv = std::fs::read_to_string(whole.join("energy.csv")).unwrap();
    let totals: Vec<(f64, f64)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (v[0], v[9])
        })
        .collect();
    let initial = totals[0].1;
    for &(t, total) in &totals {
        if t <= 1.0 {
            assert!(
                (total / initial - 1.0).abs() < 1e-12,
                "t = {t}: {total} vs {initial}"
            );
        }
        assert!(
            total.is_finite() && total <= initial * (1.0 + 1e-12),
            "t = {t}: {total}"
        );
    }
    let drift = set["energy_drift"].as_f64().unwrap();
    assert!(drift < 0.0 && drift > -0.25, "energy drift {drift}");
    // One material: the step is (c_stiff + |v|) / (c + |v|) times longer,
    // c = √(M/ϱ) with M = E(1 − ν)/((1 + ν)(1 − 2ν)), |v| = 0.1√2.
    let one = dir.join("one");
    let (ok, _, err) = mpm(&[
        "run",
        scene_path("explicit_disks.toml").to_str().unwrap(),
        "--set",
        "solver.output_interval=0.5",
        "--set",
        "output.png=false",
        "--out",
        one.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let ratio = steps(&set) / steps(&summary(&one));
    let c = |e: f64| (e * 0.7 / (1.3 * 0.4) / 1000.0).sqrt();
    let v = 0.1 * 2f64.sqrt();
    let expected = (c(1e5) + v) / (c(1e3) + v);
    assert!(
        (ratio / expected - 1.0).abs() < 0.05,
        "steps {ratio} times the one material's, expected {expected}"
    );
}

/// Runs an explicit scene, keeping the last snapshot and every step's
/// (start time, increment).
fn run_with_steps(text: &str) -> (Problem<2>, Snapshot, Vec<(f64, f64)>, ExplicitOutput) {
    let (scene, src) = scene::parse(text, "scene.toml", &[]).unwrap();
    let problem = Problem::<2>::build(&scene, &src, scene.solver.padding()).unwrap();
    let mut steps = Vec::new();
    let out = scene::run_explicit(&problem, &RunControl::default(), |event| {
        if let ExplicitEvent::Step(info) = event {
            steps.push((info.time - info.dt, info.dt));
        }
        Ok(())
    })
    .unwrap();
    (problem, out.last.clone(), steps, out)
}

/// The total momentum of the points of a snapshot.
fn momentum(problem: &Problem<2>, snap: &Snapshot) -> [f64; 2] {
    let mut p = [0.0; 2];
    for (k, v) in snap.velocity.iter().enumerate() {
        p[0] += problem.mass[k] * v[0];
        p[1] += problem.mass[k] * v[1];
    }
    p
}

/// Loads with a `curve` follow it over the simulated time (s). A free
/// block's momentum changes only by the applied forces, so it must equal
/// the sum over the steps of force × curve(step start) × Δt (eq. 32 is
/// forward Euler in the force) to rounding: for a point load ramped from
/// zero at t = 0.1 s to its full value at 0.3 s, and for gravity ramped
/// the same way (a force m_p g c(t) on every point, its work booked as
/// external work). Nothing moves while the curves are zero, a curve that
/// holds 1 gives the constant load bit for bit, and the energy balance
/// (external work against kinetic + strain energy) holds as for constant
/// loads.
#[test]
fn load_curves_scale_explicit_loads_over_time() {
    let base = r#"
[mesh]
origin = [0.0, 0.0]
size = [4.0, 2.0]
cells = [32, 16]

[[material]]
name = "m"
model = "neo_hookean"
youngs_modulus = 1e4
poisson_ratio = 0.3
density = 100.0

[[body]]
name = "b"
material = "m"
region = { box = { lower = [1.0, 0.5], upper = [3.0, 1.5] } }

[[curve]]
name = "ramp"
points = [[0.1, 0.0], [0.3, 1.0]]

[[curve]]
name = "one"
points = [[0.0, 1.0]]

[[load]]
kind = "point"
force = [5.0, 0.0]
region = { box = { lower = [2.5, 0.0], upper = [3.0, 2.0] } }
curve = "ramp"

[[load]]
kind = "gravity"
acceleration = [0.0, -0.5]
curve = "ramp"

[solver]
kind = "explicit"
basis = "bspline2"
transfer = "flip"
end_time = 0.5
output_interval = 0.05
"#;
    let (problem, last, steps, out) = run_with_steps(base);
    let setup = problem.explicit.as_ref().unwrap();
    assert_eq!(
        setup.gravity.norm(),
        0.0,
        "a curved gravity is a point force"
    );
    assert!(setup.point_forces.is_empty());
    assert_eq!(setup.timed_forces.len(), 2);
    let mass: f64 = problem.mass.iter().sum();
    let ramp = |t: f64| ((t - 0.1) / 0.2).clamp(0.0, 1.0);
    let (mut impulse_x, mut impulse_y) = (0.0, 0.0);
    for &(t, dt) in &steps {
        impulse_x += 5.0 * ramp(t) * dt;
        impulse_y += -0.5 * mass * ramp(t) * dt;
    }
    // Against the continuous ramp: (0.5 - 0.2) s at full load.
    assert!((impulse_x - 5.0 * 0.3).abs() < 0.02 * 1.5, "{impulse_x}");
    let p = momentum(&problem, &last);
    assert!(
        (p[0] - impulse_x).abs() < 1e-11 * impulse_x.abs(),
        "{p:?} against {impulse_x}"
    );
    assert!(
        (p[1] - impulse_y).abs() < 1e-11 * impulse_y.abs(),
        "{p:?} against {impulse_y}"
    );
    assert!(
        out.last_energies.external_work > 0.0 && out.energy_drift.abs() < 0.02,
        "{:?}, drift {}",
        out.last_energies,
        out.energy_drift
    );
    assert_eq!(out.last_energies.gravitational, 0.0);
    // Nothing moves before t = 0.1 s.
    let (scene, src) = scene::parse(base, "scene.toml", &["solver.end_time=0.1".into()]).unwrap();
    let early = Problem::<2>::build(&scene, &src, scene.solver.padding()).unwrap();
    let out = scene::run_explicit(&early, &RunControl::default(), |_| Ok(())).unwrap();
    assert!(out.last.velocity.iter().all(|v| *v == [0.0; 3]));
    assert!(out.last.displacement.iter().all(|u| *u == [0.0; 3]));
    // A curve that holds 1 is the constant load (the gravity then a
    // field, so only the point load).
    let point_only = |curve: &str| {
        base.replacen(
            "[[load]]\nkind = \"gravity\"\nacceleration = [0.0, -0.5]\ncurve = \"ramp\"\n",
            "",
            1,
        )
        .replacen("curve = \"ramp\"\n", curve, 1)
    };
    let (_, constant, _, _) = run_with_steps(&point_only(""));
    let (_, one, _, _) = run_with_steps(&point_only("curve = \"one\"\n"));
    assert_eq!(constant.position, one.position);
    assert_eq!(constant.velocity, one.velocity);
    assert_eq!(constant.sigma, one.sigma);
}

/// Material-point fixities (`[[point_fixity]]`): the bar of
/// `explicit_bar.toml` held by its first column of points (at x = h/4)
/// instead of its end nodes. The held points keep x and their x velocity
/// exactly (they start at it); the rest of the bar rings as with the
/// nodal support. Measured: at a quarter period the tip has moved 0.244 m
/// (the nodal run: 0.245; v0 L/c = 0.25 m), and at the half period the
/// momentum has turned from +m v0 to −0.968 m v0.
#[test]
fn point_fixities_hold_a_bar_by_its_points() {
    let held = BAR.replacen(
        "[[boundary]]\nset = \"x_min\"\nkind = \"fixed\"\n",
        "[[point_fixity]]\nregion = { box = { lower = [-1.0, -1.0], upper = [0.125, 1.0] } }\nvelocity = { x = 0.0 }\n",
        1,
    );
    assert_ne!(held, BAR);
    let (problem, frames, out) = run::<2>(&held, &["solver.end_time=5.0"]);
    let fixities = &problem.explicit.as_ref().unwrap().point_fixities;
    assert_eq!(fixities.len(), 4, "{fixities:?}"); // 2 cells × 2 points high
    assert!(
        fixities
            .iter()
            .all(|&(p, c, v)| c == 0 && v == 0.0 && problem.position[p][0] < 0.125)
    );
    for f in &frames {
        for &(p, _, _) in fixities {
            assert_eq!(f.snapshot.displacement[p][0], 0.0, "t = {}", f.time);
            assert_eq!(f.snapshot.velocity[p][0], 0.0, "t = {}", f.time);
        }
    }
    let tip: Vec<usize> = (0..problem.len())
        .filter(|&p| problem.position[p][0] > 24.5)
        .collect();
    let (_, nodal, _) = run::<2>(BAR, &["solver.end_time=5.0"]);
    let tip_u = |frames: &[Frame]| {
        let f = &frames[5];
        assert!((f.time - 2.5).abs() < 1e-9);
        tip.iter()
            .map(|&p| f.snapshot.displacement[p][0])
            .sum::<f64>()
            / tip.len() as f64
    };
    let (u_points, u_nodes) = (tip_u(&frames), tip_u(&nodal));
    eprintln!("tip at t = 2.5: held points {u_points}, held nodes {u_nodes}");
    assert!((u_points - 0.25).abs() < 0.1 * 0.25, "{u_points}");
    assert!(
        (u_points - u_nodes).abs() < 0.03 * 0.25,
        "{u_points} against {u_nodes}"
    );
    // The supports take the bar's momentum: at the half period it has
    // turned from +m v0 to about −m v0 (the square wave's dispersion).
    let mass: f64 = problem.mass.iter().sum();
    let p = momentum(&problem, &frames[10].snapshot);
    eprintln!("momentum at t = 5: {} of m v0", p[0] / (mass * 0.1));
    assert!((p[0] / (mass * 0.1) + 1.0).abs() < 0.15, "{p:?}");
    assert!(out.energy_drift.abs() < 0.05, "{}", out.energy_drift);
}

/// The error building a 2D scene `text` (file `s.toml`) gives, empty if
/// it builds.
fn build(text: &str) -> String {
    let (scene, src) = match scene::parse(text, "s.toml", &[]) {
        Ok(s) => s,
        Err(e) => return e.to_string(),
    };
    match Problem::<2>::build(&scene, &src, scene.solver.padding()) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    }
}

/// What `[[point_fixity]]` and the explicit curves refuse, located.
#[test]
fn point_fixities_and_curves_refuse_bad_input() {
    let fixity = |region: &str, velocity: &str| {
        BAR.replacen(
            "[solver]",
            &format!("[[point_fixity]]\nregion = {region}\nvelocity = {velocity}\n\n[solver]"),
            1,
        )
    };
    let inside = "{ box = { lower = [-1.0, -1.0], upper = [0.125, 1.0] } }";
    assert_eq!(build(&fixity(inside, "{ x = 0.0 }")), "");
    let e = build(&fixity(
        "{ box = { lower = [30.0, 0.0], upper = [31.0, 1.0] } }",
        "{ x = 0.0 }",
    ));
    assert!(
        e.contains("holds no material point") && e.contains("s.toml:"),
        "{e}"
    );
    let e = build(&fixity(inside, "{ z = 0.0 }"));
    assert!(e.contains("a 2D scene has no z component"), "{e}");
    let e = build(&fixity(inside, "{ x = nan }"));
    assert!(e.contains("not finite"), "{e}");
    let e = build(&fixity(inside, "{ x = 0.0 }").replacen(
        "[[point_fixity]]",
        "[[point_fixity]]\nbody = \"rod\"",
        1,
    ));
    assert!(e.contains("rod"), "{e}");
    // The implicit solver holds nodes.
    let implicit = include_str!("../../../scenes/two_layer_column.toml").replacen(
        "[solver]",
        &format!("[[point_fixity]]\nregion = {inside}\nvelocity = {{ x = 0.0 }}\n\n[solver]"),
        1,
    );
    let e = build(&implicit);
    assert!(
        e.contains("material-point fixities are a condition of the explicit solver"),
        "{e}"
    );
    // Curves: finite rows (a scene file cannot hold a NaN; a scene built
    // in code can).
    let curve = BAR.replacen(
        "[solver]",
        "[[curve]]\nname = \"c\"\npoints = [[0.0, 0.0], [1.0, 1.0]]\n\n[solver]",
        1,
    );
    let (mut scene, src) = scene::parse(&curve, "s.toml", &[]).unwrap();
    scene.curves[0].points = toml::Spanned::new(0..0, vec![[0.0, 0.0], [f64::NAN, 1.0]]);
    let e = Problem::<2>::build(&scene, &src, scene.solver.padding())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("curve `c`: row 2") && e.contains("must be finite"),
        "{e}"
    );
    // A gravity field without a curve acts on every body.
    let field = BAR.replacen(
        "[solver]",
        "[[load]]\nkind = \"gravity\"\nacceleration = [0.0, -1.0]\nbody = \"bar\"\n\n[solver]",
        1,
    );
    let e = build(&field);
    assert!(
        e.contains("give a `curve` to load one body's points"),
        "{e}"
    );
    assert_eq!(
        build(
            &field
                .replacen("body = \"bar\"", "body = \"bar\"\ncurve = \"c\"", 1)
                .replacen(
                    "[[load]]",
                    "[[curve]]\nname = \"c\"\npoints = [[0.0, 1.0]]\n\n[[load]]",
                    1
                )
        ),
        ""
    );
}

/// GIMP from a scene (`basis = "gimp"`, `domain_update = "stretch"`): the
/// bar of `explicit_bar.toml` rings as with the B-spline, and its points'
/// half-lengths follow eq. 34 (l = U_ii l⁰) in the outputs. Measured: the
/// tip at a quarter period 0.245 m with GIMP as with the B-spline
/// (v0 L/c = 0.25 m). The rules that convect corners and mid-points run
/// from a scene too; see [`convected_domains_run_from_a_scene`].
#[test]
fn gimp_runs_from_a_scene_with_its_domains_updated() {
    let sets = [
        "solver.end_time=2.5",
        "solver.basis=gimp",
        "solver.domain_update=stretch",
    ];
    let (problem, frames, out) = run::<2>(BAR, &sets);
    let tip: Vec<usize> = (0..problem.len())
        .filter(|&p| problem.position[p][0] > 24.5)
        .collect();
    let last = &frames.last().unwrap().snapshot;
    let u = tip.iter().map(|&p| last.displacement[p][0]).sum::<f64>() / tip.len() as f64;
    eprintln!("GIMP bar: tip at t = 2.5 {u}, drift {}", out.energy_drift);
    assert!((u - 0.25).abs() < 0.1 * 0.25, "{u}");
    assert_eq!(last.domain_bounds.len(), problem.len());
    // The bar is in uniaxial strain: l_x = F_xx l0_x, l_y = l0_y.
    let mut worst: f64 = 0.0;
    for p in 0..problem.len() {
        let (lo, hi) = last.domain_bounds[p];
        let l0 = problem.half_lengths[p];
        let fxx = last.f[p][0];
        worst = worst.max(((hi[0] - lo[0]) / 2.0 - fxx * l0[0]).abs() / l0[0]);
        worst = worst.max(((hi[1] - lo[1]) / 2.0 - l0[1]).abs() / l0[1]);
    }
    assert!(worst < 1e-12, "{worst}");
}

/// CPDI2 (`basis = "cpdi2"`) and GIMP with the midpoint rule of eq. 37
/// (`domain_update = "corner_midpoint"` and `"midpoint"`) from a scene:
/// the bar of `explicit_bar.toml` rings as with the B-spline; in its
/// uniaxial strain the domains stretch along the bar with F_xx, to a
/// mismatch first order in Δt (the corners move with ½(vⁿ + ṽⁿ⁺¹), F with
/// ṽⁿ⁺¹), and keep their height (CPDI2 exactly: the nodes' y velocities
/// are held; eq. 37 up to its volume correction).
#[test]
fn convected_domains_run_from_a_scene() {
    for (basis, rule) in [
        ("cpdi2", "none"),
        ("gimp", "corner_midpoint"),
        ("gimp", "midpoint"),
    ] {
        let sets = [
            "solver.end_time=2.5".to_string(),
            format!("solver.basis={basis}"),
            format!("solver.domain_update={rule}"),
        ];
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        let (problem, frames, out) = run::<2>(BAR, &sets);
        let tip: Vec<usize> = (0..problem.len())
            .filter(|&p| problem.position[p][0] > 24.5)
            .collect();
        let last = &frames.last().unwrap().snapshot;
        let u = tip.iter().map(|&p| last.displacement[p][0]).sum::<f64>() / tip.len() as f64;
        let (mut along, mut across, mut stretched): (f64, f64, f64) = (0.0, 0.0, 0.0);
        for p in 0..problem.len() {
            let (lo, hi) = last.domain_bounds[p];
            let (lo0, hi0) = frames[0].snapshot.domain_bounds[p];
            let (l0x, l0y) = ((hi0[0] - lo0[0]) / 2.0, (hi0[1] - lo0[1]) / 2.0);
            let fxx = last.f[p][0];
            along = along.max(((hi[0] - lo[0]) / 2.0 - fxx * l0x).abs() / l0x);
            across = across.max(((hi[1] - lo[1]) / 2.0 - l0y).abs() / l0y);
            stretched = stretched.max((fxx - 1.0).abs());
        }
        eprintln!(
            "{basis} {rule} bar: tip at t = 2.5 {u}, drift {}; F_xx - 1 up to {stretched:.2e}; domain along the bar off F_xx l0 by {along:.2e}, across off l0 by {across:.2e}",
            out.energy_drift
        );
        assert!((u - 0.25).abs() < 0.1 * 0.25, "{basis} {rule}: {u}");
        // Measured (Δt = 0.005 s): along 1.0e-3 (CPDI2) and 5.0e-4 (eq. 37)
        // against a stretch of 1.2e-2.
        assert!(
            stretched > 1e-2 && along < 0.1 * stretched,
            "{basis} {rule}: {along} {stretched}"
        );
        if basis == "cpdi2" {
            assert!(across < 1e-12, "{across}");
        } else {
            assert!(across < 0.1 * stretched, "{basis} {rule}: {across}");
        }
    }
}

/// The absorbing column of `explicit_absorbing_column.toml` (issue 44):
/// the velocity behind the front (0.6 transit times) q/(ϱ c_p) = 0.0609
/// m/s within 3 %; the base reaction between 1.2 and 1.6 transit times,
/// from the absorbed power Σ C_n v'² = F v, q within 5 %; the velocity
/// behind where the reflection would be (1.6 transit times) the incident
/// one within 5 %, where a fixed base stops it; and kinetic + strain +
/// absorbed − external work balanced to 1 % of the external work, in
/// `energy.csv`'s terms.
#[test]
fn an_absorbing_base_takes_the_columns_wave() {
    let (rho, e, nu, q, width) = (2000.0_f64, 1e7, 0.3, 1e4, 0.1);
    let cp = (e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu)) / rho).sqrt();
    let (incident, transit) = (q / (rho * cp), 1.0 / cp);
    let mean = |problem: &Problem<2>, frame: &Frame, lo: f64, hi: f64| {
        let inside = (0..problem.len()).filter(|&p| (lo..hi).contains(&problem.position[p][1]));
        -mean_velocity(problem, &frame.snapshot, inside)[1] / incident
    };
    let at = |frames: &[Frame], t: f64| {
        let i = frames
            .iter()
            .position(|f| (f.time - t).abs() < 1e-3 * transit);
        i.unwrap_or_else(|| panic!("no output at {t}"))
    };
    let (problem, frames, _) = run::<2>(COLUMN, &[]);
    let front = mean(&problem, &frames[at(&frames, 0.6 * transit)], 0.55, 0.9);
    let last = frames.last().unwrap();
    assert!((last.time - 1.6 * transit).abs() < 1e-3 * transit);
    let behind = mean(&problem, last, 0.1, 0.5);
    let (a, b) = (&frames[at(&frames, 1.2 * transit)], last);
    let power = (b.energies.absorbed_work - a.energies.absorbed_work) / (b.time - a.time);
    let reaction = power / (incident * width) / q;
    let (start, end) = (frames[0].energies, last.energies);
    let residual = (end.total() - start.total()) / end.external_work;
    println!(
        "absorbing column scene: incident velocity {front:.4} of q/(ϱ c_p), after the reflection time {behind:.4}, base reaction {reaction:.4} q, energy residual {residual:.1e} of the work"
    );
    assert!((front - 1.0).abs() < 0.03, "{front}");
    assert!((behind - 1.0).abs() < 0.05, "{behind}");
    assert!((reaction - 1.0).abs() < 0.05, "{reaction}");
    assert!(residual.abs() < 0.01, "{start:?} -> {end:?}");
    assert!(end.absorbed_work > 0.3 * end.external_work, "{end:?}");
    let fixed = COLUMN.replacen(
        "kind = \"absorbing\"\nmaterial = \"soil\"",
        "kind = \"fixed\"",
        1,
    );
    let (problem, frames, _) = run::<2>(&fixed, &[]);
    let last = frames.last().unwrap();
    let stopped = mean(&problem, last, 0.1, 0.5);
    assert!(
        stopped.abs() < 0.05 && last.energies.absorbed_work == 0.0,
        "{stopped}"
    );
}

/// What `kind = "absorbing"` refuses, located: no `material`, an unknown
/// one, one without E and ν (Cam-Clay), a set that is not a grid face,
/// the keys of other kinds, `material` or `spring` on another kind, a
/// negative or unknown spring stiffness, and the implicit solver.
#[test]
fn absorbing_boundaries_refuse_bad_input() {
    let base = "kind = \"absorbing\"\nmaterial = \"soil\"";
    let with = |replacement: &str| COLUMN.replacen(base, replacement, 1);
    assert_eq!(build(COLUMN), "");
    let springs = format!("{base}\nspring = {{ normal = 1e7, tangential = 5e6 }}");
    assert_eq!(build(&with(&springs)), "");
    let cases = [
        (
            "kind = \"absorbing\"".to_owned(),
            "s.toml:52:8: kind = absorbing needs `material = \"<name>\"`",
        ),
        (
            "kind = \"absorbing\"\nmaterial = \"rock\"".to_owned(),
            "s.toml:53:12: no material named `rock`; the scene has: soil",
        ),
        (
            format!("{base}\ncurve = \"c\""),
            "s.toml:52:8: `curve` applies to kind = displacement, not absorbing",
        ),
        (
            "kind = \"roller\"\nmaterial = \"soil\"".to_owned(),
            "s.toml:52:8: `material` applies to kind = absorbing, not roller",
        ),
        (
            "kind = \"roller\"\nspring = { normal = 1e6 }".to_owned(),
            "s.toml:52:8: `spring` applies to kind = absorbing, not roller",
        ),
        (
            format!("{base}\nspring = {{ normal = -1.0 }}"),
            "s.toml:54:10: spring = { normal = -1, tangential = 0 }: the stiffnesses per unit area (Pa/m) must be finite and non-negative",
        ),
        (
            format!("{base}\nspring = {{ normal = 1e6, along = 2.0 }}"),
            "s.toml:54:",
        ),
    ];
    for (replacement, expected) in cases {
        let e = build(&with(&replacement));
        assert!(e.starts_with(expected), "{e}\nexpected: {expected}");
    }
    let set = with(base).replacen("set = \"y_min\"", "set = \"bottom\"", 1).replacen(
        "[[boundary]]\nset = \"x_min\"",
        "[[node_set]]\nname = \"bottom\"\nregion = { box = { lower = [-1.0, -1.0], upper = [1.0, 0.001] } }\n\n[[boundary]]\nset = \"x_min\"",
        1,
    );
    let e = build(&set);
    assert!(
        e.contains("kind = absorbing needs a grid face for its normal") && e.contains("s.toml:"),
        "{e}"
    );
    let clay = with("kind = \"absorbing\"\nmaterial = \"clay\"").replacen(
        "[[body]]",
        "[[material]]\nname = \"clay\"\nmodel = \"modified_cam_clay\"\ndensity = 2000.0\ncompression_index = 0.2\nswelling_index = 0.05\ncritical_state_slope = 1.2\nshear_modulus = 5.0e6\nreference_pressure = 1.0e5\nminimum_pressure = 1.0e3\noverconsolidation_ratio = 1.0\n\n[[body]]",
        1,
    );
    let e = build(&clay);
    assert!(
        e.contains("material `clay` has no Young's modulus and Poisson's ratio")
            && e.contains("s.toml:"),
        "{e}"
    );
    let implicit = include_str!("../../../scenes/two_layer_column.toml");
    let e = build(&implicit.replacen(
        "[solver]",
        "[[boundary]]\nset = \"y_min\"\nkind = \"absorbing\"\nmaterial = \"soft\"\n\n[solver]",
        1,
    ));
    assert!(
        e.contains("kind = absorbing needs the explicit solver") && e.contains("s.toml:"),
        "{e}"
    );
}

/// The absorbing column stopped after 8 of its 16 outputs and resumed
/// writes the uninterrupted run's `energy.csv` byte for byte: the
/// checkpoint keeps the absorbed work so far and, with a spring layer
/// (`spring = { normal = 1e7, tangential = 5e6 }`), its nodes' spring
/// displacements.
#[test]
fn the_absorbing_column_resumes_with_its_absorbed_work() {
    let springs = common::fresh_dir("absorbing-springs-scene").join("springs.toml");
    std::fs::write(
        &springs,
        COLUMN.replacen(
            "material = \"soil\"\n\n[solver]",
            "material = \"soil\"\nspring = { normal = 1e7, tangential = 5e6 }\n\n[solver]",
            1,
        ),
    )
    .unwrap();
    for (scene, name, with_springs) in [
        (
            scene_path("explicit_absorbing_column.toml"),
            "absorbing",
            false,
        ),
        (springs, "absorbing-springs", true),
    ] {
        let whole = common::fresh_dir(&format!("{name}-whole"));
        let split = common::fresh_dir(&format!("{name}-split"));
        for (dir, extra) in [
            (&whole, &[][..]),
            (&split, &["--stop-after", "8"][..]),
            (&split, &["--resume"][..]),
        ] {
            let mut args = vec![
                "run",
                scene.to_str().unwrap(),
                "--out",
                dir.to_str().unwrap(),
            ];
            args.extend(extra);
            let (ok, _, err) = mpm(&args);
            assert!(ok, "{err}");
        }
        let energies = |dir: &Path| std::fs::read_to_string(dir.join("energy.csv")).unwrap();
        let (a, b) = (energies(&whole), energies(&split));
        assert_eq!(a, b);
        let last: Vec<f64> = (a.lines().last().unwrap().split(','))
            .map(|x| x.parse().unwrap())
            .collect();
        let (absorbed, spring) = (last[7], last[8]);
        assert!(absorbed > 0.0 && (spring > 0.0) == with_springs, "{a}");
        let e = &summary(&whole)["final_energies"];
        assert_eq!(e["absorbed_work"].as_f64(), Some(absorbed));
        assert_eq!(e["spring_energy"].as_f64(), Some(spring));
    }
}

/// `scenes/explicit_absorbing_gravity.toml` (issue 44): a column starting
/// from its geostatic stress under gravity on an absorbing base with the
/// spring layer k_n = M / H. The springs start unloaded, so the base (the
/// mean vertical displacement of the bottom row of points) settles onto
/// them by ϱ g H / k_n = 1.458 mm — measured 1.47 mm averaged over 5–10
/// transit times (bound 10 %) — and rings there within 0.37 mm (bound:
/// issue 44's 10⁻³ H); without springs the same column sinks: its base,
/// released from the geostatic stress ϱ g H onto matched dashpots,
/// starts at g H / (2 c_p) = 0.060 m/s (measured 0.0609 m/s over the
/// second transit, before its points sink out of the base cells), which
/// tends to g H / c_p as the unloading wave comes back from the top
/// (bound: 0.4–1.5 times g H / c_p). The energy,
/// spring energy included, balances to 1 % of the work of gravity.
#[test]
fn a_geostatic_column_rests_on_the_spring_layer_of_an_absorbing_base() {
    let text = include_str!("../../../scenes/explicit_absorbing_gravity.toml");
    let (rho, g, h, m): (f64, f64, f64, f64) = (2000.0, 9.81, 1.0, 1e7 * 0.7 / (1.3 * 0.4));
    let cp = (m / rho).sqrt();
    let base = |problem: &Problem<2>, f: &Frame| {
        let bottom: Vec<usize> = (0..problem.position.len())
            .filter(|&p| problem.position[p][1] < 0.01)
            .collect();
        -bottom
            .iter()
            .map(|&p| f.snapshot.displacement[p][1])
            .sum::<f64>()
            / bottom.len() as f64
    };
    let (problem, frames, _) = run::<2>(text, &[]);
    let settled: Vec<f64> = frames[5..].iter().map(|f| base(&problem, f)).collect();
    let mean = settled.iter().sum::<f64>() / settled.len() as f64;
    let range = settled.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
        - settled.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    let expected = rho * g * h / 1.346e7;
    let (start, end) = (frames[0].energies, frames.last().unwrap().energies);
    let residual = (end.total() - start.total()) / (start.gravitational - end.gravitational);
    let free = text.replacen(
        "spring = { normal = 1.346e7, tangential = 7.69e6 }\n",
        "",
        1,
    );
    assert_ne!(free, text);
    let (problem, frames, _) = run::<2>(&free, &["solver.end_time=0.02438"]);
    let rate = (base(&problem, &frames[2]) - base(&problem, &frames[1]))
        / (frames[2].time - frames[1].time);
    println!(
        "geostatic column on springs: base settles {mean:.4e} m over 5-10 transits (rho g H / k_n = {expected:.4e}, {:+.1e}), range {range:.2e} m, residual {residual:.1e}; without springs it sinks at {rate:.4} m/s (g H / c_p = {:.4})",
        mean / expected - 1.0,
        g * h / cp
    );
    assert!((mean / expected - 1.0).abs() < 0.1, "{settled:?}");
    assert!(range < 1e-3 * h, "{settled:?}");
    assert!(residual.abs() < 0.01 && end.spring_energy > 0.0, "{end:?}");
    assert!((0.4..1.5).contains(&(rate / (g * h / cp))), "{rate}");
}
