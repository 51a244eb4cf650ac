//! Reference problems of the explicit solver with closed-form or published
//! answers, shared by the tests (`tests/explicit.rs`) and the report
//! (`cargo xtask reproduce mpoint`): the axially vibrating bar (free–free
//! and with a fixed end), the settled nearly incompressible block, Sulsky's
//! colliding disks and the dynamic collapse. Each returns its measure;
//! every set-up error or solver failure is returned, never a panic.

use mpm_basis::{BasisFunction, QuadraticBSpline};
use mpm_constitutive::{IncrementalLaw, NeoHookean, Spectral, VonMises};
use mpm_mesh::RegularGrid;
use nalgebra::{Vector2, Vector3};

use super::{
    DilatationTreatment, ExplicitOptions, ExplicitPoints, ExplicitSolver, Flip, FlipPic, PointsFor,
    Taylor, TimeStep, Transfer, VelocityFixities,
};
use crate::domain::{DomainUpdater, NoUpdate};
use crate::error::SolverError;
use crate::locking::NoLocking;

/// `per`×`per` points per cell filling the box [lo, hi] on a grid of
/// spacing `h`.
pub fn block(
    lo: Vector2<f64>,
    hi: Vector2<f64>,
    h: f64,
    per: usize,
) -> (Vec<Vector2<f64>>, Vec<f64>) {
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

/// $\sum_p (u_p - a\sin\beta X_p)^2$: the squared error of the axial
/// displacements of `points` (started at `x0`) against the first mode of
/// the bar at an instant where its amplitude is `a`.
pub fn mode_squared_error<S, T, Dom>(
    points: &ExplicitPoints<2, S, T, Dom>,
    x0: &[Vector2<f64>],
    a: f64,
    beta: f64,
) -> f64 {
    points
        .position
        .iter()
        .zip(x0)
        .map(|(x, x0)| (x.x - x0.x - a * (beta * x0.x).sin()).powi(2))
        .sum()
}

/// The result of [`vibrating_bar`].
#[derive(Debug, Clone, PartialEq)]
pub struct Bar {
    /// The RMS displacement error relative to the amplitude.
    pub error: f64,
    /// (time, total energy) at every sample.
    pub energy: Vec<(f64, f64)>,
}

/// The axially vibrating bar: E = 100, ρ = 1, ν = 0, length L = 25 fixed at
/// x = 0 and free at x = L, started in its first mode with velocity
/// amplitude v₀. Modelled without a fixity as the symmetric half of a
/// free–free bar of length 2L (the mid-section of the first mode of a
/// free–free bar does not move): u = (v₀/ω) sin(ωt) sin(βx), β = π/(2L),
/// ω = β√(E/ρ). Lateral velocities fixed (1D). Returns the error of the
/// point displacements (RMS over points and over the `samples` instants,
/// relative to the amplitude; 8 instants per period over `periods`
/// periods) and the energies' history; `cells` cells over 2L, CFL factor
/// `cfl`.
///
/// # Errors
/// Set-up and solver errors.
pub fn vibrating_bar<B, T>(
    basis: B,
    transfer: T,
    cells: usize,
    cfl: f64,
    periods: f64,
    v0: f64,
) -> Result<Bar, SolverError>
where
    B: BasisFunction<2, Domain = (), Mesh = RegularGrid<2>>,
    T: Transfer<2>,
{
    vibrating_bar_with(basis, NoUpdate, transfer, cells, cfl, periods, v0)
}

/// [`vibrating_bar`] with a basis that may have domains (GIMP: each
/// point's initial half-lengths are half its spacing, h/4) and the domain
/// update `rule`.
///
/// # Errors
/// Set-up and solver errors.
pub fn vibrating_bar_with<B, R, T>(
    basis: B,
    rule: R,
    transfer: T,
    cells: usize,
    cfl: f64,
    periods: f64,
    v0: f64,
) -> Result<Bar, SolverError>
where
    B: BasisFunction<2, Mesh = RegularGrid<2>>,
    R: DomainUpdater<2, B::Domain>,
    T: Transfer<2>,
{
    let (l, e, rho): (f64, f64, f64) = (25.0, 100.0, 1.0);
    let h = 2.0 * l / cells as f64;
    let pad = B::PADDING as f64 + 1.0;
    let grid = RegularGrid::new(
        Vector2::new(-l - pad * h, -pad * h),
        Vector2::new(h, h),
        [cells + 2 * (pad as usize), 1 + 2 * (pad as usize)],
    )?;
    let (x0, vol) = block(Vector2::new(-l, 0.0), Vector2::new(l, h), h, 2);
    let beta = std::f64::consts::PI / (2.0 * l);
    let omega = beta * (e / rho).sqrt();
    let domains = x0
        .iter()
        .map(|x| B::initial_domain(x, &Vector2::new(h / 4.0, h / 4.0)))
        .collect();
    let points: PointsFor<2, NeoHookean, T> = ExplicitPoints::new(x0.clone(), vol, rho)?;
    let mut points = points.with_domains(domains)?;
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
        NeoHookean::new(e, 0.0)?,
        transfer,
        NoLocking,
        fixed,
        options,
    )?
    .with_domain_update(rule);
    let period = 2.0 * std::f64::consts::PI / omega;
    let amplitude = v0 / omega;
    let (mut sum, mut count) = (0.0, 0usize);
    let mut energy = Vec::new();
    let samples = (periods * 8.0).round() as usize;
    for s in 1..=samples {
        let t_end = s as f64 * period * periods / samples as f64;
        solver.run_until(&mut points, t_end, |_, _, _| Ok(()))?;
        let t = solver.time();
        sum += mode_squared_error(&points, &x0, amplitude * (omega * t).sin(), beta);
        count += points.len();
        let en = solver.energies(&points)?;
        energy.push((t, en.total()));
    }
    Ok(Bar {
        error: (sum / count as f64).sqrt() / amplitude,
        energy,
    })
}

/// A nearly incompressible block settling under gravity on a frictionless
/// base with free sides (plane strain): σ_yy = −ρg(H − y), σ_xx = 0,
/// σ_zz = νσ_yy, so the mean stress is p = (1 + ν)ρg(H − y)/3. PIC damps
/// the motion out; the pressure error (RMS over the points of the
/// deviation of −tr σ/3 from p, relative to ρgH) is measured with and
/// without the cell-averaged dilatation.
pub fn settled_block_pressure_error<K: DilatationTreatment>(
    locking: K,
    nu: f64,
) -> Result<f64, SolverError> {
    let (h, cells, rho, g, e) = (1.0 / 8.0, 16, 1000.0, 10.0, 1e7);
    let grid = RegularGrid::new(
        Vector2::new(-h, -h),
        Vector2::new(h, h),
        [cells + 2, cells + 2],
    )?;
    let (x0, vol) = block(Vector2::new(0.5, 0.0), Vector2::new(1.5, 1.0), h, 2);
    let mut points: PointsFor<2, NeoHookean, FlipPic> = ExplicitPoints::new(x0, vol, rho)?;
    let mut fixed = VelocityFixities::new();
    let nodes = cells + 3;
    fixed.fix(0..2 * nodes, 1); // the base row and the padding row below
    let options = ExplicitOptions {
        time_step: TimeStep::Cfl { factor: 0.5 },
        gravity: Vector2::new(0.0, -g),
    };
    let mut solver = ExplicitSolver::new(
        QuadraticBSpline,
        grid,
        NeoHookean::new(e, nu)?,
        FlipPic { alpha: 0.0 },
        locking,
        fixed,
        options,
    )?;
    solver.run_until(&mut points, 0.3, |_, _, _| Ok(()))?;
    let mut sum = 0.0;
    for p in 0..points.len() {
        let s = points.cauchy(p);
        let mean = -s.trace() / 3.0;
        let exact = (1.0 + nu) * rho * g * (1.0 - points.position[p].y) / 3.0;
        sum += (mean - exact).powi(2);
    }
    Ok((sum / points.len() as f64).sqrt() / (rho * g))
}

/// Sulsky, Chen & Schreyer (1995) §5: two elastic disks in a unit square,
/// radius 0.2, centres (0.2, 0.2) and (0.8, 0.8), velocities ±(0.1, 0.1),
/// E = 1000, ν = 0.3, ρ = 1000, plane strain. Returns (time, kinetic,
/// strain, total) samples and the first disk's centroid velocity at the
/// end.
pub fn colliding_disks<T: Transfer<2>>(
    transfer: T,
    cells: usize,
    end: f64,
) -> Result<(Vec<[f64; 4]>, Vector2<f64>), SolverError> {
    let h = 1.0 / cells as f64;
    let grid = RegularGrid::new(
        Vector2::new(-h, -h),
        Vector2::new(h, h),
        [cells + 2, cells + 2],
    )?;
    let (all, vol) = block(Vector2::zeros(), Vector2::new(1.0, 1.0), h, 2);
    let centres = [Vector2::new(0.2, 0.2), Vector2::new(0.8, 0.8)];
    let keep: Vec<usize> = (0..all.len())
        .filter(|&p| centres.iter().any(|c| (all[p] - c).norm() < 0.2))
        .collect();
    let x: Vec<_> = keep.iter().map(|&p| all[p]).collect();
    let v: Vec<_> = keep.iter().map(|&p| vol[p]).collect();
    let first: Vec<bool> = x.iter().map(|p| (p - centres[0]).norm() < 0.2).collect();
    let mut points: PointsFor<2, NeoHookean, T> = ExplicitPoints::new(x, v, 1000.0)?;
    for (p, vel) in points.velocity.iter_mut().enumerate() {
        *vel = if first[p] {
            Vector2::new(0.1, 0.1)
        } else {
            Vector2::new(-0.1, -0.1)
        };
    }
    let options = ExplicitOptions {
        time_step: TimeStep::Cfl { factor: 0.5 },
        ..Default::default()
    };
    let mut solver = ExplicitSolver::new(
        QuadraticBSpline,
        grid,
        NeoHookean::new(1000.0, 0.3)?,
        transfer,
        NoLocking,
        VelocityFixities::new(),
        options,
    )?;
    let mut history = Vec::new();
    let samples = 40;
    for s in 0..=samples {
        solver.run_until(&mut points, end * s as f64 / samples as f64, |_, _, _| {
            Ok(())
        })?;
        let e = solver.energies(&points)?;
        history.push([solver.time(), e.kinetic, e.strain, e.total()]);
    }
    let (mut momentum, mut mass) = (Vector2::zeros(), 0.0);
    for p in (0..points.len()).filter(|&p| first[p]) {
        momentum += points.velocity[p] * points.mass[p];
        mass += points.mass[p];
    }
    Ok((history, momentum / mass))
}

/// The collapse of Coombs et al. 2020 §7.5 with inertia: the half block
/// 8 m × 8 m, rollers on the base and the symmetry edge, E = 1 MPa,
/// ν = 0.3, von Mises ρ_y = 20 kPa, ρ = 1000 kg/m³ under g = 10 m/s² (the
/// paper's 10 kN/m³), released at once. Returns the extent max(x_p + l⁰)
/// and height max(y_p + l⁰) at `end`, and the kinetic energy then.
pub fn dynamic_collapse<B>(
    basis: B,
    h: f64,
    alpha: f64,
    end: f64,
) -> Result<(f64, f64, f64), SolverError>
where
    B: BasisFunction<2, Domain = (), Mesh = RegularGrid<2>>,
{
    dynamic_collapse_with(basis, NoUpdate, h, alpha, end)
}

/// [`dynamic_collapse`] with a basis that may have domains (GIMP: each
/// point's initial half-lengths are half its spacing, h/6) and the domain
/// update `rule`.
pub fn dynamic_collapse_with<B, R>(
    basis: B,
    rule: R,
    h: f64,
    alpha: f64,
    end: f64,
) -> Result<(f64, f64, f64), SolverError>
where
    B: BasisFunction<2, Mesh = RegularGrid<2>>,
    R: DomainUpdater<2, B::Domain>,
{
    // A padding cell below and beside the block at least: a GIMP point on
    // the base may dip below it by rounding (the held nodes stop it there).
    let padding = B::PADDING.max(1);
    let pad = padding as f64 * h;
    let nx = (24.0 / h).round() as usize + padding;
    let ny = (10.0 / h).round() as usize + padding;
    let grid = RegularGrid::new(
        Vector2::new(-pad, -pad),
        Vector2::new(h, h),
        [nx + padding, ny + padding],
    )?;
    let (x0, vol) = block(Vector2::zeros(), Vector2::new(8.0, 8.0), h, 3);
    let l0 = h / 6.0;
    let domains = x0
        .iter()
        .map(|x| B::initial_domain(x, &Vector2::new(l0, l0)))
        .collect();
    let law = Spectral::new(VonMises::new(1e6, 0.3, 20e3, 0.0)?)?;
    let points: ExplicitPoints<2, _, ()> = ExplicitPoints::new(x0, vol, 1000.0)?;
    let mut points = points.with_domains(domains)?;
    let nodes = [nx + padding + 1, ny + padding + 1];
    let mut fixed = VelocityFixities::new();
    let rows = padding + 1; // the boundary row or column and the padding beyond it
    fixed.fix(0..nodes[0] * rows, 1);
    fixed.fix(
        (0..nodes[1]).flat_map(|j| (0..rows).map(move |i| j * nodes[0] + i)),
        0,
    );
    let options = ExplicitOptions {
        time_step: TimeStep::Cfl { factor: 0.5 },
        gravity: Vector2::new(0.0, -10.0),
    };
    let mut solver = ExplicitSolver::new(
        basis,
        grid,
        law,
        FlipPic { alpha },
        NoLocking,
        fixed,
        options,
    )?
    .with_domain_update(rule);
    solver.run_until(&mut points, end, |_, _, _| Ok(()))?;
    let extent = points.position.iter().map(|x| x.x + l0).fold(0.0, f64::max);
    let height = points.position.iter().map(|x| x.y + l0).fold(0.0, f64::max);
    Ok((extent, height, solver.energies(&points)?.kinetic))
}

/// The bar of length L = 25 with its end x = 0 truly fixed (a velocity
/// fixity) and the other free: the first mode, `cells` cells over L, CFL
/// 0.02, v₀ = 1e-4, one period. The plain B-spline fixes the end node and
/// the padding node beyond it; the boundary-modified spline fixes the end
/// node, where it is interpolatory.
pub fn fixed_end_bar<B: BasisFunction<2, Domain = (), Mesh = RegularGrid<2>>>(
    basis: B,
    cells: usize,
) -> Result<f64, SolverError> {
    let (l, e, rho, v0): (f64, f64, f64, f64) = (25.0, 100.0, 1.0, 1e-4);
    let h = l / cells as f64;
    let pad = B::PADDING;
    let grid = RegularGrid::new(
        Vector2::new(-(pad as f64) * h, -(pad as f64) * h),
        Vector2::new(h, h),
        [cells + 2 + 2 * pad, 1 + 2 * pad],
    )?;
    let (x0, vol) = block(Vector2::zeros(), Vector2::new(l, h), h, 2);
    let beta = std::f64::consts::PI / (2.0 * l);
    let omega = beta * (e / rho).sqrt();
    let mut points: PointsFor<2, NeoHookean, Flip> = ExplicitPoints::new(x0.clone(), vol, rho)?;
    points.set_velocity(|x| Vector2::new(v0 * (beta * x.x).sin(), 0.0));
    let nx = cells + 3 + 2 * pad;
    let mut fixed = VelocityFixities::new();
    fixed.fix(0..grid.node_count(), 1);
    fixed.fix(
        (0..1 + 2 * pad + 1).flat_map(|j| (0..=pad).map(move |i| j * nx + i)),
        0,
    );
    let options = ExplicitOptions {
        time_step: TimeStep::Cfl { factor: 0.02 },
        ..Default::default()
    };
    let mut solver = ExplicitSolver::new(
        basis,
        grid,
        NeoHookean::new(e, 0.0)?,
        Flip,
        NoLocking,
        fixed,
        options,
    )?;
    let period = 2.0 * std::f64::consts::PI / omega;
    let amplitude = v0 / omega;
    let (mut sum, mut count) = (0.0, 0usize);
    for s in 1..=8 {
        solver.run_until(&mut points, s as f64 * period / 8.0, |_, _, _| Ok(()))?;
        let t = solver.time();
        sum += mode_squared_error(&points, &x0, amplitude * (omega * t).sin(), beta);
        count += points.len();
    }
    Ok((sum / count as f64).sqrt() / amplitude)
}

/// The solver of the cube scene.
pub type CubeSolver = CubeSolverWith<NeoHookean>;
/// The solver of [`elastic_cube_with`], with law `L`.
pub type CubeSolverWith<L> = ExplicitSolver<3, QuadraticBSpline, L, Taylor, NoLocking>;
/// Its points.
pub type CubePoints = PointsFor<3, NeoHookean, Taylor>;

/// The elastic-cube drop of issue 15 on a grid of `n`³ cells (`n` ≥ 8):
/// a Neo-Hookean cube (E = 1e6, ν = 0.3, ρ = 1000) of side 0.4 in a unit
/// box, 2³ points per cell, quadratic B-splines, Taylor-PIC, slip walls
/// three cells thick, Δt = 0.3 h/c fixed, gravity, f64 — the throughput
/// benchmark of `benches/explicit.rs` and `cargo xtask reproduce mpoint`.
///
/// # Errors
/// `n` < 8; set-up errors.
pub fn elastic_cube(n: usize) -> Result<(CubeSolver, CubePoints), SolverError> {
    elastic_cube_with(n, NeoHookean::new(1e6, 0.3)?)
}

/// [`elastic_cube`] with the law `law` (its wave speed sets the time
/// step): a downstream crate's law, or the same Neo-Hookean behind a
/// run-time choice, on the same cube.
///
/// # Errors
/// As [`elastic_cube`].
pub fn elastic_cube_with<L: IncrementalLaw>(
    n: usize,
    law: L,
) -> Result<(CubeSolverWith<L>, PointsFor<3, L, Taylor>), SolverError> {
    if n < 8 {
        return Err(SolverError::InvalidInput(format!(
            "the cube needs at least 8 cells per axis, not {n}"
        )));
    }
    let h = 1.0 / n as f64;
    let grid = RegularGrid::new(Vector3::zeros(), Vector3::from_element(h), [n; 3])?;
    let per_side = (0.8 * n as f64).round() as usize;
    let d = h / 2.0;
    let lo = 0.5 - 0.5 * per_side as f64 * d;
    let mut x = Vec::with_capacity(per_side.pow(3));
    for k in 0..per_side {
        for j in 0..per_side {
            for i in 0..per_side {
                x.push(Vector3::new(
                    lo + (i as f64 + 0.5) * d,
                    lo + (j as f64 + 0.5) * d,
                    lo + (k as f64 + 0.5) * d,
                ));
            }
        }
    }
    let volume = vec![d * d * d; x.len()];
    let points: PointsFor<3, L, Taylor> = ExplicitPoints::new(x, volume, 1000.0)?;
    let c = (law.p_wave_modulus() / 1000.0).sqrt();
    let mut walls = VelocityFixities::new();
    let nodes = n + 1;
    for axis in 0..3 {
        let near = |i: usize| i < 3 || i > n - 3;
        let ids = (0..nodes.pow(3)).filter(|id| {
            let index = [id % nodes, id / nodes % nodes, id / (nodes * nodes)];
            near(index[axis])
        });
        walls.fix(ids, axis);
    }
    let options = ExplicitOptions {
        time_step: TimeStep::Fixed(0.3 * h / c),
        gravity: Vector3::new(0.0, 0.0, -9.81),
    };
    let solver = ExplicitSolver::new(
        QuadraticBSpline,
        grid,
        law,
        Taylor::PIC,
        NoLocking,
        walls,
        options,
    )?;
    Ok((solver, points))
}
