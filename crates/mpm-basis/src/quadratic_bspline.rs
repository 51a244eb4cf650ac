//! Uniform quadratic B-splines centred at the grid nodes.

use mpm_mesh::RegularGrid;
use nalgebra::SVector;

use crate::tensor::AxisFactors;
use crate::{BasisError, BasisFunction, Stencil};

/// Uniform quadratic B-spline basis (Steffen et al. 2008; MPoint theory
/// notes eqs. 24–27), one spline centred at every grid node:
///
/// $$N(r) = \begin{cases} \tfrac34 - r^2 & |r| < \tfrac12\\
/// \tfrac12\left(\tfrac32 - |r|\right)^2 & \tfrac12 \le |r| < \tfrac32\\
/// 0 & \tfrac32 \le |r|\end{cases}\qquad\text{(24)}$$
///
/// $$N'(r) = \begin{cases} -2r & |r| < \tfrac12\\
/// \left(|r| - \tfrac32\right)\operatorname{sign} r & \tfrac12 \le |r| < \tfrac32\\
/// 0 & \tfrac32 \le |r|\end{cases}\qquad\text{(25)}$$
///
/// with $r_i = (x_{p,i} - X_{v,i})/h_i$, $S_{vp} = \prod_i N(r_i)$ (26) and
/// $\partial_j S_{vp} = \frac{1}{h_j}N'(r_j)\prod_{i\ne j}N(r_i)$ (27). The
/// support is $\pm 1.5h$: three nodes per axis, $3^D$ in all. $N$ is $C^1$,
/// so values and gradients are continuous everywhere.
///
/// Boundary treatment (a decision of this crate): no boundary-modified
/// splines. Every spline of the stencil must be a full interior spline, so
/// a point must lie at least half a cell inside the grid along every axis,
/// i.e. in $[o_i + h_i/2,\ o_i + (n_i - \tfrac12)h_i]$. Build the grid with
/// one padding cell around the region the material can reach. A point
/// closer to the boundary gets [`BasisError::StencilOutsideGrid`]; a node
/// beyond the grid never appears. Inside that region partition of unity and
/// linear reproduction hold exactly.
///
/// Domain: `()`. Errors: [`BasisError::StencilOutsideGrid`] as above,
/// [`mpm_mesh::MeshError::PointOutsideGrid`] (in [`BasisError::Mesh`]) for
/// a point outside the grid.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct QuadraticBSpline;

impl QuadraticBSpline {
    /// The 1D spline and its derivative, $(N(r), N'(r))$, eqs. (24)–(25),
    /// for the normalised distance $r = (x_p - X_v)/h$.
    pub fn shape_1d(r: f64) -> (f64, f64) {
        let a = r.abs();
        if a < 0.5 {
            (0.75 - r * r, -2.0 * r)
        } else if a < 1.5 {
            let b = 1.5 - a;
            (0.5 * b * b, -b * r.signum())
        } else {
            (0.0, 0.0)
        }
    }
}

impl<const D: usize> BasisFunction<D> for QuadraticBSpline {
    type Mesh = RegularGrid<D>;
    type Domain = ();
    const MAX_NODES: usize = 3usize.pow(D as u32);
    const PADDING: usize = 1;
    const SUPPORT_RADIUS: f64 = 1.5;

    fn initial_domain(_: &SVector<f64, D>, _: &SVector<f64, D>) {}

    crate::tensor::tensor_basis_methods!(|mesh, position| Self::axis_factors(mesh, position));
}

impl QuadraticBSpline {
    /// The three 1D factors per axis of the point at `position`.
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
            Self::push_axis(axis, k, t, h, cells[i], position, i)?;
        }
        Ok(axes)
    }

    /// Pushes the factors along axis `i` of a point in cell `k` at local
    /// coordinate `t` (cell size `h`, `cells` cells on the axis).
    ///
    /// # Errors
    /// [`BasisError::StencilOutsideGrid`] when a node of the stencil lies
    /// beyond the grid.
    #[inline(always)]
    pub(crate) fn push_axis<const D: usize>(
        axis: &mut AxisFactors<3>,
        k: usize,
        t: f64,
        h: f64,
        cells: usize,
        position: &SVector<f64, D>,
        i: usize,
    ) -> Result<(), BasisError> {
        // Nodes k-1..=k+1 when t < 1/2, k..=k+2 otherwise; node j sits at
        // r = t + k - j. With fx = r of the first node, in [0.5, 1.5), the
        // three factors of eqs. (24)-(25) need no branch (the quadratic
        // pieces at r = fx, fx - 1, fx - 2). A node at exactly |r| = 3/2
        // has a zero factor and zero slope and is skipped, so the
        // admissible region is closed.
        let (first, fx) = if t < 0.5 {
            (k.wrapping_sub(1), t + 1.0)
        } else {
            (k, t)
        };
        let (a, b, c) = (1.5 - fx, fx - 1.0, fx - 0.5);
        let values = [0.5 * a * a, 0.75 - b * b, 0.5 * c * c];
        let slopes = [-a, -2.0 * b, c];
        for (offset, (n, dn)) in values.into_iter().zip(slopes).enumerate() {
            if n == 0.0 && dn == 0.0 {
                continue;
            }
            let node = first.wrapping_add(offset);
            if node > cells {
                return Err(BasisError::StencilOutsideGrid {
                    point: position.iter().copied().collect(),
                    axis: i,
                });
            }
            axis.push(node, n, dn / h);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_1d_matches_eqs_24_25() {
        let cases = [
            (0.0, 0.75, 0.0),
            (0.25, 0.6875, -0.5),
            (-0.25, 0.6875, 0.5),
            (0.5, 0.5, -1.0),
            (-0.5, 0.5, 1.0),
            (1.0, 0.125, -0.5),
            (-1.0, 0.125, 0.5),
            (1.25, 0.03125, -0.25),
            (1.5, 0.0, 0.0),
            (-2.0, 0.0, 0.0),
        ];
        for (r, n, dn) in cases {
            assert_eq!(QuadraticBSpline::shape_1d(r), (n, dn), "r = {r}");
        }
    }

    #[test]
    fn shape_1d_is_c1_at_the_breakpoints() {
        for b in [-1.5, -0.5, 0.5, 1.5] {
            let eps = 1e-9;
            let (n0, d0) = QuadraticBSpline::shape_1d(b - eps);
            let (n1, d1) = QuadraticBSpline::shape_1d(b + eps);
            assert!((n0 - n1).abs() <= 4.0 * eps, "value jump at {b}");
            assert!((d0 - d1).abs() <= 8.0 * eps, "slope jump at {b}");
        }
    }
}
