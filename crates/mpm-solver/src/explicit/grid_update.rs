//! Stage 2, the grid update: nodal velocity (eq. 30), acceleration (eq.
//! 31), updated velocity (eq. 32) and the velocity fixities.

use rayon::prelude::*;

use super::fixities::VelocityFixities;
use super::grid::{GridBuffer, NodeSums};
pub use super::grid::{GridState, NodeVelocity};

/// Nodes per parallel task of the grid update.
const NODES_PER_TASK: usize = 4096;

/// Sums the threads' `buffers` into `grid` and updates the velocities
/// (eqs. 30–32); nodes without mass get zero velocity. Then the fixities:
/// $\tilde v^{n+1}_i$ is set to the prescribed value, which recomputes the
/// acceleration as the notes require (a fixity on a node without mass has
/// no effect: no point reads it).
pub fn update<const D: usize>(
    buffers: &[GridBuffer<D>],
    grid: &mut GridState<D>,
    dt: f64,
    fixities: &VelocityFixities,
) {
    let lo = buffers.iter().map(|b| b.lo).min().unwrap_or(usize::MAX);
    let hi = buffers.iter().map(|b| b.hi).max().unwrap_or(0);
    if lo >= hi {
        grid.lo = 0;
        grid.hi = 0;
        return;
    }
    grid.lo = lo;
    grid.hi = hi;
    let (mass, velocity) = (&mut grid.mass[lo..hi], &mut grid.velocity[lo..hi]);
    (
        mass.par_chunks_mut(NODES_PER_TASK),
        velocity.par_chunks_mut(NODES_PER_TASK),
    )
        .into_par_iter()
        .enumerate()
        .for_each(|(task, (mass, velocity))| {
            let start = lo + task * NODES_PER_TASK;
            for (k, (m_out, v_out)) in mass.iter_mut().zip(velocity.iter_mut()).enumerate() {
                let i = start + k;
                let mut sum = NodeSums::<D>::ZERO;
                for b in buffers {
                    if i >= b.lo && i < b.hi {
                        let n = &b.nodes[i];
                        sum.mass += n.mass;
                        sum.momentum += n.momentum;
                        sum.force += n.force;
                    }
                }
                *m_out = sum.mass;
                *v_out = if sum.mass > 0.0 {
                    let v = sum.momentum / sum.mass;
                    NodeVelocity {
                        old: v,
                        new: v + sum.force * (dt / sum.mass),
                    }
                } else {
                    NodeVelocity::default()
                };
            }
        });
    for &(node, component, value) in fixities.entries() {
        if node >= lo && node < hi && grid.mass[node] > 0.0 {
            grid.velocity[node].new[component] = value;
        }
    }
}

/// Material-point fixities on the grid: the updated grid velocities are
/// corrected so that each held point's interpolated velocity component
/// $\sum_i w_{ip}\tilde v_{i,c}$ equals its prescribed value, with the
/// smallest change of kinetic energy (lumped mass):
/// $\tilde v_{i,c} \mathrel{+}= \lambda_p w_{ip}/m_i$,
/// $\lambda_p = (v^{fix}_p - \sum_i w_{ip}\tilde v_{i,c}) / \sum_i w_{ip}^2/m_i$
/// — a Lagrange multiplier per held point, $\lambda_p/\Delta t$ its
/// reaction force — by Gauss–Seidel sweeps over the held points (which
/// couple where they share nodes) until every constraint holds to 1e-12 of
/// the velocity scale or 100 sweeps. Nodes with a nodal fixity on the
/// component do not move. `pairs[ends[k-1]..ends[k]]` (from 0 for the
/// first) are held point k's (node, weight) pairs.
///
/// Returns the largest remaining violation.
pub fn hold_points<const D: usize>(
    grid: &mut GridState<D>,
    held: &[(usize, usize, f64)],
    pairs: &[(usize, f64)],
    ends: &[usize],
    fixities: &VelocityFixities,
) -> f64 {
    let scale = velocity_scale(grid, held);
    hold_points_to(grid, held, (pairs, ends), fixities, scale)
}

/// The velocity scale of [`hold_points`]' tolerance: the largest held
/// value or updated grid velocity component.
pub fn velocity_scale<const D: usize>(grid: &GridState<D>, held: &[(usize, usize, f64)]) -> f64 {
    held.iter()
        .map(|h| h.2.abs())
        .fold(0.0, f64::max)
        .max(
            grid.velocity[grid.lo..grid.hi]
                .iter()
                .map(|v| v.new.amax())
                .fold(0.0, f64::max),
        )
        .max(f64::MIN_POSITIVE)
}

/// [`hold_points`] to the tolerance 1e-12 × `scale`.
pub fn hold_points_to<const D: usize>(
    grid: &mut GridState<D>,
    held: &[(usize, usize, f64)],
    (pairs, ends): (&[(usize, f64)], &[usize]),
    fixities: &VelocityFixities,
    scale: f64,
) -> f64 {
    let stencils = ends.iter().scan(0, |start, &end| {
        let s = &pairs[*start..end];
        *start = end;
        Some(s)
    });
    let fixed = |node: usize, c: usize| {
        fixities
            .entries()
            .binary_search_by(|&(n, k, _)| (n, k).cmp(&(node, c)))
            .is_ok()
    };
    let mut worst = 0.0;
    for _ in 0..100 {
        worst = 0.0f64;
        for (&(_, c, target), stencil) in held.iter().zip(stencils.clone()) {
            let (mut value, mut denominator) = (0.0, 0.0);
            for &(i, w) in stencil {
                value += w * grid.velocity[i].new[c];
                if grid.mass[i] > 0.0 && !fixed(i, c) {
                    denominator += w * w / grid.mass[i];
                }
            }
            let violation = target - value;
            worst = worst.max(violation.abs());
            if denominator > 0.0 {
                let lambda = violation / denominator;
                for &(i, w) in stencil {
                    if grid.mass[i] > 0.0 && !fixed(i, c) {
                        grid.velocity[i].new[c] += lambda * w / grid.mass[i];
                    }
                }
            }
        }
        if worst <= 1e-12 * scale {
            break;
        }
    }
    worst
}
