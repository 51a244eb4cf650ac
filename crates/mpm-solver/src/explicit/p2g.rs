//! Stage 1, point to grid: lumped mass (eqs. 22, 28), momentum with the
//! optional Taylor term (eq. 29), internal and external forces (eqs. 20–21).

use std::ops::Range;

use mpm_basis::{BasisFunction, Stencil};
use nalgebra::{Matrix3, SVector};

pub use super::grid::{GridBuffer, NodeSums};
use super::transfer::Transfer;
use crate::error::{BasisFailure, PointFailure};

/// What the scatter reads from the points.
#[derive(Debug, Clone, Copy)]
pub struct PointsView<'a, const D: usize, T, Dom = ()> {
    /// Positions $x^n_p$.
    pub position: &'a [SVector<f64, D>],
    /// Velocities $v^n_p$.
    pub velocity: &'a [SVector<f64, D>],
    /// Masses.
    pub mass: &'a [f64],
    /// Initial volumes.
    pub volume0: &'a [f64],
    /// Kirchhoff stresses.
    pub tau: &'a [Matrix3<f64>],
    /// Transfer states.
    pub transfer: &'a [T],
    /// The basis's domains.
    pub domain: &'a [Dom],
}

/// The failure of the basis at `x`.
fn basis_failure<const D: usize>(x: &SVector<f64, D>, source: BasisFailure) -> PointFailure {
    PointFailure::Basis {
        position: x.iter().copied().collect(),
        source,
    }
}

/// Streams the supporting nodes of the point at `x` with its basis domain
/// `domain` into `visit` ([`BasisFunction::for_each_node`]), checking that
/// every node id lies below `node_count`.
///
/// # Errors
/// The basis cannot be evaluated at `x`, or it returned a node outside the
/// mesh (a bug of the basis; nothing past that node is visited).
#[inline(always)]
pub fn visit_nodes<const D: usize, B: BasisFunction<D>>(
    basis: &B,
    mesh: &B::Mesh,
    x: &SVector<f64, D>,
    domain: &B::Domain,
    node_count: usize,
    stencil: &mut Stencil<D>,
    mut visit: impl FnMut(usize, f64, &SVector<f64, D>),
) -> Result<(), PointFailure> {
    let fail = |source| basis_failure(x, source);
    let mut outside = None;
    basis
        .for_each_node(mesh, x, domain, stencil, |i, w, g| {
            if i < node_count {
                if outside.is_none() {
                    visit(i, w, g);
                }
            } else {
                outside = Some(i);
            }
        })
        .map_err(|e| fail(BasisFailure::Basis(e)))?;
    match outside {
        None => Ok(()),
        Some(_) => Err(fail(BasisFailure::Stencil {
            nodes: B::MAX_NODES + 1,
            max: B::MAX_NODES,
        })),
    }
}

/// Scatters the points `range` into `buffer`: for every node $i$ of a
/// point's stencil, $m_i \mathrel{+}= w_{ip}m_p$,
/// $p_i \mathrel{+}= w_{ip}m_p\,(v_p + \nabla v_p(x_i - x_p))$ (the bracket
/// from [`Transfer::nodal_velocity`]) and
/// $f_i \mathrel{+}= w_{ip}m_p b - V^0_p\tau_p\nabla w_{ip}$ (eqs. 20–21
/// with $V_p\sigma_p = V^0_p\tau_p$). `node_position` is read only by
/// transfers with a Taylor term.
///
/// # Errors
/// The first point whose basis cannot be evaluated, with its index.
#[allow(clippy::too_many_arguments)]
pub fn scatter<const D: usize, B, T>(
    basis: &B,
    mesh: &B::Mesh,
    points: &PointsView<'_, D, T::PointState, B::Domain>,
    node_position: &[SVector<f64, D>],
    gravity: &SVector<f64, D>,
    range: Range<usize>,
    buffer: &mut GridBuffer<D>,
    stencil: &mut Stencil<D>,
) -> Result<(), (usize, PointFailure)>
where
    B: BasisFunction<D>,
    T: Transfer<D>,
{
    let node_count = buffer.len();
    let (mut lo, mut hi) = (buffer.lo, buffer.hi);
    let nodes = &mut buffer.nodes;
    for p in range {
        let x = &points.position[p];
        let m = points.mass[p];
        let v = &points.velocity[p];
        let state = &points.transfer[p];
        let stress = points.tau[p].fixed_view::<D, D>(0, 0) * points.volume0[p];
        let body = gravity * m;
        let domain = &points.domain[p];
        if let Some(factors) = basis.tensor_factors(mesh, x, domain) {
            let affine = T::affine(state);
            if !T::TAYLOR || affine.is_some() {
                let t = factors.map_err(|e| (p, basis_failure(x, BasisFailure::Basis(e))))?;
                let last = t.last_id();
                if last >= node_count {
                    return Err((
                        p,
                        basis_failure(
                            x,
                            BasisFailure::Stencil {
                                nodes: B::MAX_NODES + 1,
                                max: B::MAX_NODES,
                            },
                        ),
                    ));
                }
                super::tensor::scatter_point(&t, m, v, affine.as_ref(), &stress, &body, nodes);
                lo = lo.min(t.first_id);
                hi = hi.max(last + 1);
                continue;
            }
        }
        visit_nodes(basis, mesh, x, domain, node_count, stencil, |i, w, g| {
            let carried = if T::TAYLOR {
                T::nodal_velocity(v, state, &(node_position[i] - x))
            } else {
                *v
            };
            nodes[i].add_point((w, g), m, &carried, &body, &stress);
            lo = lo.min(i);
            hi = hi.max(i + 1);
        })
        .map_err(|e| (p, e))?;
    }
    buffer.lo = lo;
    buffer.hi = hi;
    Ok(())
}

/// Adds applied point forces $w_{ip}f^{app}_p$ (eq. 21) to `buffer`.
///
/// # Errors
/// As [`scatter`].
pub fn scatter_point_forces<const D: usize, B: BasisFunction<D>>(
    basis: &B,
    mesh: &B::Mesh,
    position: &[SVector<f64, D>],
    domain: &[B::Domain],
    forces: &[(usize, SVector<f64, D>)],
    buffer: &mut GridBuffer<D>,
    stencil: &mut Stencil<D>,
) -> Result<(), (usize, PointFailure)> {
    let node_count = buffer.len();
    for (p, f) in forces {
        let (lo, hi) = (&mut buffer.lo, &mut buffer.hi);
        let nodes = &mut buffer.nodes;
        visit_nodes(
            basis,
            mesh,
            &position[*p],
            &domain[*p],
            node_count,
            stencil,
            |i, w, _| {
                nodes[i].force += f * w;
                *lo = (*lo).min(i);
                *hi = (*hi).max(i + 1);
            },
        )
        .map_err(|e| (*p, e))?;
    }
    Ok(())
}
