//! Sum-factorised point-to-grid and grid-to-point kernels for
//! tensor-product bases ([`mpm_basis::BasisFunction::tensor_factors`]).
//!
//! With weights $w = w^{(0)}_a\,o$ and gradients
//! $\nabla w = (s^{(0)}_a\,o,\ w^{(0)}_a\,\partial_1 o,\ \dots)$, where the
//! "outer" product $o = \prod_{k\ge1} w^{(k)}$ runs over the other axes and
//! $\partial_k o = s^{(k)}\prod_{j\ge1, j\ne k} w^{(j)}$, every nodal
//! contribution of a point is a combination of two vectors per outer node
//! combination, so the work per node is a few multiply-adds instead of the
//! full products (3 + 3 per node against 9 + 9 for the Taylor term and the
//! internal force):
//!
//! - momentum, eq. (29): $m w (v + \nabla v\,(x_i - x_p)) = w_a P + (w_a\,\Delta x_a) Q$
//!   with $P = m\,o\,(v + \sum_{k\ge1}\nabla v_{:,k}\Delta x_k)$, $Q = m\,o\,\nabla v_{:,0}$;
//! - force, eqs. (20)–(21): $w\,m b - V^0\tau\nabla w = w_a F - s_a G$ with
//!   $F = o\,m b - \sum_{k\ge1} V^0\tau_{:,k}\,\partial_k o$, $G = V^0\tau_{:,0}\,o$;
//! - grid to point: per outer combination the sums over the first axis
//!   $A = \sum_a w_a\tilde v$, $A^n = \sum_a w_a v^n$, $B = \sum_a s_a\tilde v$,
//!   then $\bar{\tilde v} \mathrel{+}= o A$, $\bar v \mathrel{+}= o A^n$,
//!   $\nabla v_{:,0} \mathrel{+}= o B$, $\nabla v_{:,k} \mathrel{+}= \partial_k o\,A$.
//!
//! The results equal the node-by-node stages to rounding (test
//! `tensor_kernels_match_the_node_by_node_path`).

use mpm_basis::TensorFactors;
use nalgebra::{SMatrix, SVector};

use super::grid::{Gathered, GridState, NodeSums};

/// One combination of the non-first axes: the id of its first node along
/// axis 0, the outer weight $o$, the outer partials $\partial_k o$ (entry 0
/// unused) and the offsets $\Delta x_k$ of its nodes (entry 0 unused).
struct Outer<const D: usize> {
    row: usize,
    weight: f64,
    partial: [f64; D],
    offset: [f64; D],
}

/// Calls `f` for every combination of the axes 1..D.
// The loops index the per-axis arrays (values, slopes, counters) by axis.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn for_each_outer<const D: usize>(t: &TensorFactors<D>, mut f: impl FnMut(&Outer<D>)) {
    let mut counter = [0usize; D];
    loop {
        let mut o = Outer {
            row: t.first_id,
            weight: 1.0,
            partial: [0.0; D],
            offset: [0.0; D],
        };
        for k in 1..D {
            let c = counter[k];
            o.row += c * t.strides[k];
            o.weight *= t.value[k][c];
            o.offset[k] = t.first_offset[k] + c as f64 * t.spacing[k];
            let mut p = t.slope[k][c];
            for j in 1..D {
                if j != k {
                    p *= t.value[j][counter[j]];
                }
            }
            o.partial[k] = p;
        }
        f(&o);
        let mut axis = 1;
        loop {
            if axis >= D {
                return;
            }
            counter[axis] += 1;
            if counter[axis] < t.len[axis] {
                break;
            }
            counter[axis] = 0;
            axis += 1;
        }
    }
}

/// Point to grid for one point: adds $w m$, $w m (v + \nabla v\,\Delta x)$
/// (the Taylor term when `grad_v` is given) and $w m b - V^0\tau\nabla w$
/// to `nodes`. `stress` is $V^0\tau$ (D×D), `body` is $m b$.
#[inline(always)]
pub fn scatter_point<const D: usize>(
    t: &TensorFactors<D>,
    mass: f64,
    v: &SVector<f64, D>,
    grad_v: Option<&SMatrix<f64, D, D>>,
    stress: &SMatrix<f64, D, D>,
    body: &SVector<f64, D>,
    nodes: &mut [NodeSums<D>],
) {
    let n0 = t.len[0];
    let (w0, s0) = (&t.value[0], &t.slope[0]);
    let mut wdx = [0.0; 3];
    for a in 0..n0 {
        wdx[a] = w0[a] * (t.first_offset[0] + a as f64 * t.spacing[0]);
    }
    let stress0 = stress.column(0).into_owned();
    let c0 = grad_v.map(|g| g.column(0).into_owned() * mass);
    for_each_outer(t, |o| {
        let mut p = *v;
        if let Some(g) = grad_v {
            for k in 1..D {
                p += g.column(k) * o.offset[k];
            }
        }
        let p = p * (mass * o.weight);
        let q = c0.map(|c| c * o.weight);
        let mut f = body * o.weight;
        for k in 1..D {
            f -= stress.column(k) * o.partial[k];
        }
        let g = stress0 * o.weight;
        let m = mass * o.weight;
        let row = &mut nodes[o.row..o.row + n0];
        for (a, node) in row.iter_mut().enumerate() {
            node.mass += w0[a] * m;
            node.momentum += p * w0[a];
            if let Some(q) = &q {
                node.momentum += q * wdx[a];
            }
            node.force += f * w0[a] - g * s0[a];
        }
    });
}

/// Grid to point for one point: the interpolated new and old velocities
/// and the velocity gradient (eq. 38).
#[inline(always)]
pub fn gather_point<const D: usize>(t: &TensorFactors<D>, grid: &GridState<D>) -> Gathered<D> {
    let n0 = t.len[0];
    let (w0, s0) = (&t.value[0], &t.slope[0]);
    let mut g = Gathered::default();
    for_each_outer(t, |o| {
        let (mut a_new, mut a_old, mut b) = (
            SVector::<f64, D>::zeros(),
            SVector::<f64, D>::zeros(),
            SVector::<f64, D>::zeros(),
        );
        for (a, node) in grid.velocity[o.row..o.row + n0].iter().enumerate() {
            a_new += node.new * w0[a];
            a_old += node.old * w0[a];
            b += node.new * s0[a];
        }
        g.new_velocity += a_new * o.weight;
        g.old_velocity += a_old * o.weight;
        let mut column = g.grad.column_mut(0);
        column += b * o.weight;
        for k in 1..D {
            let mut column = g.grad.column_mut(k);
            column += a_new * o.partial[k];
        }
    });
    g
}
