//! Quadratic B-splines with boundary-modified functions: interpolatory at
//! the grid boundary, no padding.

use mpm_mesh::RegularGrid;
use nalgebra::SVector;

use crate::quadratic_bspline::QuadraticBSpline;
use crate::tensor::AxisFactors;
use crate::{BasisError, BasisFunction, Stencil};

/// The uniform quadratic B-spline of [`QuadraticBSpline`] away from the
/// grid boundary, modified within half a cell of it so that the basis
/// needs no node outside the grid and is interpolatory at the boundary.
///
/// **Why.** The node-centred spline of a boundary node reaches half a cell
/// into the padding, and the padding node's spline half a cell into the
/// body: on $[0, \tfrac h2]$ next to a boundary node 0 the field is
/// $u(x) = u_{-1}N_{-1} + u_0N_0 + u_1N_1$ with $N_{\pm1}(0) = \tfrac18$, so
/// fixing $u_0$ (and even $u_{-1}$) leaves $u(0) = \tfrac18(u_{-1} + u_1) \ne 0$.
/// The Dirichlet condition is not imposed; the implicit column (Coombs et
/// al. 2020 §7.1) then converges at order 0.42 with the plain spline
/// against GIMP's 1.37.
///
/// **The modification** (derived here; cf. the boundary-modified splines of
/// Steffen, Kirby & Berzins 2008). On the half cell next to a boundary node
/// 0, $\xi = x/h \in [0, \tfrac12]$, the three plain functions are replaced
/// by the linear pair $\phi_0 = 1 - \xi$, $\phi_1 = \xi$. This is the only
/// choice of two functions on that interval with partition of unity and
/// linear reproduction ($\phi_0 + \phi_1 = 1$, $0\cdot\phi_0 + 1\cdot\phi_1 = \xi$),
/// and it joins the plain splines at $\xi = \tfrac12$ with $C^1$
/// continuity: $N_0(\tfrac12) = \tfrac12$, $N_0'(\tfrac12) = -1$,
/// $N_1(\tfrac12) = \tfrac12$, $N_1'(\tfrac12) = 1$, $N_2(\tfrac12) = N_2'(\tfrac12) = 0$,
/// the values and slopes of $1 - \xi$ and $\xi$ there. So the basis is
/// $C^1$ inside the grid, reproduces linear fields, is interpolatory at
/// the boundary ($\phi_0(0) = 1$, every other function 0: fixing node 0
/// fixes $u(0)$) and needs no node beyond the boundary. The same holds at
/// the upper boundary of every axis, and in 2D/3D per axis (tensor
/// product). The approximation is linear on the boundary half cells only.
///
/// Domain: `()`. Admissible points: the whole closed grid. Errors:
/// [`mpm_mesh::MeshError::PointOutsideGrid`] (in [`BasisError::Mesh`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BoundaryBSpline;

impl BoundaryBSpline {
    /// The 1D factors per axis of the point at `position`.
    #[inline(always)]
    fn axis_factors<const D: usize>(
        mesh: &RegularGrid<D>,
        position: &SVector<f64, D>,
    ) -> Result<[AxisFactors<3>; D], BasisError> {
        let location = mesh.locate(position)?;
        let cells = mesh.cells_per_axis();
        let mut axes = [AxisFactors::<3>::EMPTY; D];
        for (i, axis) in axes.iter_mut().enumerate() {
            let (k, t, h) = (location.cell[i], location.local[i], mesh.spacing()[i]);
            if k == 0 && t < 0.5 {
                axis.push(0, 1.0 - t, -1.0 / h);
                axis.push(1, t, 1.0 / h);
            } else if k + 1 == cells[i] && t > 0.5 {
                axis.push(k, 1.0 - t, -1.0 / h);
                axis.push(k + 1, t, 1.0 / h);
            } else {
                QuadraticBSpline::push_axis(axis, k, t, h, cells[i], position, i)?;
            }
        }
        Ok(axes)
    }
}

impl<const D: usize> BasisFunction<D> for BoundaryBSpline {
    type Mesh = RegularGrid<D>;
    type Domain = ();
    const MAX_NODES: usize = 3usize.pow(D as u32);
    const SUPPORT_RADIUS: f64 = 1.5;

    fn initial_domain(_: &SVector<f64, D>, _: &SVector<f64, D>) {}

    crate::tensor::tensor_basis_methods!(|mesh, position| Self::axis_factors(mesh, position));
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector1;

    fn line(n: usize) -> RegularGrid<1> {
        RegularGrid::new(Vector1::new(0.0), Vector1::new(1.0), [n]).unwrap()
    }

    fn value(g: &RegularGrid<1>, x: f64, node: usize) -> (f64, f64) {
        let mut s = Stencil::with_capacity(3);
        BoundaryBSpline
            .evaluate(g, &Vector1::new(x), &(), &mut s)
            .unwrap();
        s.position(node)
            .map_or((0.0, 0.0), |k| (s.values[k], s.gradients[k][0]))
    }

    #[test]
    fn interpolatory_at_both_boundaries() {
        let g = line(5);
        assert_eq!(value(&g, 0.0, 0), (1.0, -1.0));
        assert_eq!(value(&g, 0.0, 1).0, 0.0);
        assert_eq!(value(&g, 5.0, 5).0, 1.0);
        assert_eq!(value(&g, 5.0, 4).0, 0.0);
    }

    #[test]
    fn c1_where_the_linear_half_cell_meets_the_spline() {
        let g = line(5);
        for (x, nodes) in [(0.5, [0, 1, 2]), (4.5, [3, 4, 5])] {
            for node in nodes {
                let (a, da) = value(&g, x - 1e-9, node);
                let (b, db) = value(&g, x + 1e-9, node);
                assert!(
                    (a - b).abs() < 1e-8,
                    "value jump at {x}, node {node}: {a} vs {b}"
                );
                assert!(
                    (da - db).abs() < 1e-8,
                    "slope jump at {x}, node {node}: {da} vs {db}"
                );
            }
        }
    }

    #[test]
    fn equals_the_plain_spline_away_from_the_boundary() {
        let g = line(6);
        for x in [0.5, 0.75, 1.3, 2.9, 5.5] {
            let mut a = Stencil::with_capacity(3);
            let mut b = Stencil::with_capacity(3);
            BoundaryBSpline
                .evaluate(&g, &Vector1::new(x), &(), &mut a)
                .unwrap();
            QuadraticBSpline
                .evaluate(&g, &Vector1::new(x), &(), &mut b)
                .unwrap();
            assert_eq!(a, b, "x = {x}");
        }
    }
}
