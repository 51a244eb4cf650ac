//! CPDI2: convected particle domain interpolation with quadrilateral (2D) /
//! hexahedral (3D) domains given by their corners.

use mpm_mesh::RegularGrid;
use nalgebra::SVector;

use crate::corners::{MAX_CORNERS, determinant_and_cofactor, reference_shape};
use crate::{BasisError, BasisFunction, Corners, Stencil};

/// Second-order convected particle domain interpolation (Sadeghirad,
/// Brannon & Guilkey 2013, IJNME 95:928–952, in the corrected form used by
/// Coombs et al. 2020 §6.1, footnote 6, and AMPLE).
///
/// # Definition
/// The domain $\Omega_p$ is the multilinear image of $[-1,1]^D$ under its
/// $2^D$ corners $\mathbf x_c$ ([`Corners`]), with corner functions
/// $M_c(\mathbf x) = \hat M_c(\boldsymbol\xi(\mathbf x))$. The grid
/// functions $N_v$ ([`crate::LinearMpm`]) are interpolated from their corner
/// values, $\tilde N_v = \sum_c M_c\,N_v(\mathbf x_c)$, and averaged over the
/// domain:
///
/// $$S_{vp} = \frac{1}{V_p}\int_{\Omega_p}\tilde N_v\,\mathrm d\Omega
///   = \sum_c w_c\,N_v(\mathbf x_c),\qquad
///   \nabla S_{vp} = \frac{1}{V_p}\int_{\Omega_p}\nabla\tilde N_v\,\mathrm d\Omega
///   = \sum_c \mathbf w^g_c\,N_v(\mathbf x_c),$$
///
/// $$w_c = \frac{1}{V_p}\int_{[-1,1]^D}\hat M_c\det\mathbf J\,\mathrm d\xi,\qquad
///   \mathbf w^g_c = \frac{1}{V_p}\int_{[-1,1]^D}\operatorname{cof}\mathbf J\,
///   \nabla_\xi\hat M_c\,\mathrm d\xi,\qquad
///   V_p = \int_{[-1,1]^D}\det\mathbf J\,\mathrm d\xi,$$
///
/// using $\nabla_x M_c = \mathbf J^{-T}\nabla_\xi\hat M_c$ and
/// $\operatorname{cof}\mathbf J = \det\mathbf J\,\mathbf J^{-T}$.
///
/// # Exact integration with $2^D$ Gauss points
/// Let $\deg_k$ be the polynomial degree in $\xi_k$ alone. Column $j$ of
/// $\mathbf J$, $\mathbf a_j = \partial\mathbf x/\partial\xi_j$, has
/// $\deg_j\mathbf a_j = 0$ and $\deg_k\mathbf a_j \le 1$ for $k\ne j$;
/// $\hat M_c$ has degree 1 in every variable and $\partial_{\xi_j}\hat M_c$
/// degree 0 in $\xi_j$, 1 in the others.
/// - 2D: $\det\mathbf J = a_{0,0}a_{1,1} - a_{1,0}a_{0,1}$ has degree
///   $\le 1$ per variable, so $\hat M_c\det\mathbf J$ has degree $\le 2$.
///   $\operatorname{cof}\mathbf J$ has columns $\mathbf a_1^\perp$ and
///   $-\mathbf a_0^\perp$ (the columns of $\mathbf J$ rotated), so
///   $\operatorname{cof}\mathbf J\,\nabla_\xi\hat M_c = \mathbf a_1^\perp
///   \partial_0\hat M_c - \mathbf a_0^\perp\partial_1\hat M_c$ with
///   $(x, y)^\perp = (y, -x)$. In the first term $\mathbf a_1$ is linear in
///   $\xi_0$ only and $\partial_0\hat M_c$ linear in $\xi_1$ only, and
///   symmetrically in the second: degree $\le 1$ per variable.
/// - 3D: $\det\mathbf J = \mathbf a_0\cdot(\mathbf a_1\times\mathbf a_2)$
///   has $\deg_k \le 2$ (the column $\mathbf a_k$ contributes 0), so
///   $\hat M_c\det\mathbf J$ has degree $\le 3$ per variable. Column $j$
///   of $\operatorname{cof}\mathbf J$ is $\mathbf a_{j+1}\times
///   \mathbf a_{j+2}$ (indices mod 3), of $\deg_j\le 2$ and $\deg_k\le 1$
///   ($k\ne j$); times $\partial_{\xi_j}\hat M_c$ ($\deg_j = 0$,
///   $\deg_k = 1$) this gives degree $\le 2$ per variable.
///
/// The tensor-product 2-point Gauss rule ($\xi = \pm 1/\sqrt3$, unit
/// weights) integrates every polynomial of degree $\le 3$ per variable
/// exactly, so $V_p$, $w_c$ and $\mathbf w^g_c$ are exact (up to rounding)
/// in 1D, 2D and 3D. The tests compare them with a 5-point Gauss rule and
/// $\mathbf w^g_c$ with the boundary integral $\frac{1}{V_p}\oint M_c\,
/// \mathbf n\,\mathrm dA$ (divergence theorem).
///
/// # Properties
/// $\sum_c w_c = 1$, $\sum_c\mathbf w^g_c = \mathbf 0$,
/// $\sum_c w_c\mathbf x_c = \bar{\mathbf x}_p$ (the centroid,
/// [`Corners::centroid`]) and $\sum_c\mathbf x_c\otimes\mathbf w^g_c =
/// \mathbf I$. Since the $N_v$ reproduce linear fields, CPDI2 gives
/// partition of unity, $\sum_v S_{vp}\mathbf x_v = \bar{\mathbf x}_p$ and
/// $\sum_v\mathbf x_v\otimes\nabla S_{vp} = \mathbf I$ whenever all corners
/// lie in the grid. Values and gradients are continuous in the corner
/// positions, so both are continuous as a domain crosses cell faces.
///
/// $\nabla S_{vp}$ is the domain average of $\nabla\tilde N_v$, not in
/// general the derivative of $S_{vp}$ under a rigid translation of the
/// domain (which is $\sum_c w_c\nabla N_v(\mathbf x_c)$). For an affine
/// domain inside one cell the two agree exactly when $N_v$ is at most
/// quadratic along every edge of the domain, where the secant equals the
/// mean of the end slopes: always in 2D (parallelograms), and in 3D for
/// parallelepipeds whose edges are parallel to coordinate planes; a fully
/// sheared parallelepiped already differs through the $xyz$ term of the
/// trilinear $N_v$ (tested).
///
/// Relation to GIMP: for an undeformed box $\mathbf x_p\pm\mathbf l_p$ the
/// CPDI2 factor per axis is the trapezoidal rule
/// $\tfrac12[\hat N(\delta-\lambda) + \hat N(\delta+\lambda)]$ of the exact
/// GIMP average, so CPDI2 equals [`crate::Gimp`] exactly when the box lies
/// in one cell and differs by up to $\lambda/2 = l_p/(2h)$ per axis (first
/// order in $l_p$) when it contains a node line; see
/// `docs/src/theory/basis.md`.
///
/// The `position` argument of [`BasisFunction::evaluate`] is not used: the
/// functions depend on the corners only.
///
/// Domain: [`Corners`]. Errors: [`BasisError::NonFiniteCorner`],
/// [`BasisError::DegenerateDomain`] if $\det\mathbf J \le 0$ at a Gauss
/// point (inverted or collapsed domain), [`BasisError::CornerOutsideGrid`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Cpdi2;

/// Volume and corner weights of a CPDI2 domain, from
/// [`Cpdi2::domain_integrals`]; only the first $2^D$ weights are used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DomainIntegrals<const D: usize> {
    /// Domain volume (area in 2D) $V_p$.
    pub volume: f64,
    /// Value weights $w_c = \frac{1}{V_p}\int_{\Omega_p} M_c\,\mathrm d\Omega$.
    pub value_weights: [f64; MAX_CORNERS],
    /// Gradient weights $\mathbf w^g_c = \frac{1}{V_p}\int_{\Omega_p}
    /// \nabla M_c\,\mathrm d\Omega$.
    pub gradient_weights: [SVector<f64, D>; MAX_CORNERS],
}

impl Cpdi2 {
    /// $V_p$, $w_c$ and $\mathbf w^g_c$ of a domain, integrated exactly with
    /// the $2^D$-point Gauss rule (see the type documentation for the
    /// proof).
    ///
    /// # Errors
    /// [`BasisError::NonFiniteCorner`] for a corner with a NaN or infinite
    /// coordinate and [`BasisError::DegenerateDomain`] if
    /// $\det\mathbf J \le 0$ at a Gauss point.
    pub fn domain_integrals<const D: usize>(
        corners: &Corners<D>,
    ) -> Result<DomainIntegrals<D>, BasisError> {
        let n = Corners::<D>::COUNT;
        let points = corners.as_slice();
        if let Some(c) = points.iter().position(|p| p.iter().any(|x| !x.is_finite())) {
            return Err(BasisError::NonFiniteCorner {
                corner: c,
                point: points[c].iter().copied().collect(),
            });
        }
        let degenerate = |gauss_point: usize, determinant: f64| BasisError::DegenerateDomain {
            corners: points.iter().map(|p| p.iter().copied().collect()).collect(),
            gauss_point,
            determinant,
        };
        let g = 1.0 / 3f64.sqrt();
        let mut volume = 0.0;
        let mut value_weights = [0.0; MAX_CORNERS];
        let mut gradient_weights = [SVector::<f64, D>::zeros(); MAX_CORNERS];
        for q in 0..n {
            let xi = Corners::<D>::reference(q) * g;
            let (det, cofactor) = determinant_and_cofactor(&corners.jacobian_at(&xi));
            if det.is_nan() || det <= 0.0 {
                return Err(degenerate(q, det));
            }
            volume += det;
            for c in 0..n {
                let (m, grad_xi) = reference_shape(c, &xi);
                value_weights[c] += m * det;
                gradient_weights[c] += cofactor * grad_xi;
            }
        }
        for c in 0..n {
            value_weights[c] /= volume;
            gradient_weights[c] /= volume;
        }
        Ok(DomainIntegrals {
            volume,
            value_weights,
            gradient_weights,
        })
    }
}

impl<const D: usize> BasisFunction<D> for Cpdi2 {
    type Mesh = RegularGrid<D>;
    type Domain = Corners<D>;
    /// Each corner touches the $2^D$ nodes of its cell: at most $4^D$
    /// distinct nodes.
    const MAX_NODES: usize = 1 << (2 * D);
    const SUPPORT_RADIUS: f64 = 1.5;

    /// The rectangle of half-lengths `half_lengths` around the point.
    fn initial_domain(position: &SVector<f64, D>, half_lengths: &SVector<f64, D>) -> Corners<D> {
        Corners::rectangle(position, half_lengths)
    }

    fn evaluate(
        &self,
        mesh: &RegularGrid<D>,
        _position: &SVector<f64, D>,
        corners: &Corners<D>,
        out: &mut Stencil<D>,
    ) -> Result<(), BasisError> {
        out.clear();
        let weights = Self::domain_integrals(corners)?;
        let n = Corners::<D>::COUNT;
        // Locate every corner before writing anything, so that an error
        // leaves `out` empty.
        let mut locations = [None; MAX_CORNERS];
        for (c, x) in corners.as_slice().iter().enumerate() {
            let location = mesh.locate(x).map_err(|_| BasisError::CornerOutsideGrid {
                corner: c,
                point: x.iter().copied().collect(),
            })?;
            locations[c] = Some(location);
        }
        // Merging the corners' contributions: when all corner cells lie in
        // a window of at most WINDOW nodes per axis (domains spanning up to
        // two cells), a node's stencil slot is found by a table lookup on
        // its index relative to the window; larger domains fall back to a
        // linear search of the stencil.
        const WINDOW: usize = 4;
        let mut lowest = [usize::MAX; D];
        let mut highest = [0usize; D];
        for location in locations.iter().take(n).flatten() {
            for i in 0..D {
                lowest[i] = lowest[i].min(location.cell[i]);
                highest[i] = highest[i].max(location.cell[i]);
            }
        }
        let windowed = (0..D).all(|i| highest[i] - lowest[i] + 2 <= WINDOW);
        let mut slots = [usize::MAX; WINDOW * WINDOW * WINDOW];
        for (c, location) in locations.iter().take(n).enumerate() {
            let Some(location) = location else { continue };
            let (w, wg) = (weights.value_weights[c], weights.gradient_weights[c]);
            // N_v at the corner: the multilinear functions of its cell.
            for b in 0..1usize << D {
                let mut index = location.cell;
                let mut value = 1.0;
                for (i, entry) in index.iter_mut().enumerate() {
                    let t = location.local[i];
                    if b >> i & 1 == 1 {
                        *entry += 1;
                        value *= t;
                    } else {
                        value *= 1.0 - t;
                    }
                }
                if value == 0.0 {
                    continue;
                }
                let node = match mesh.node_id(index) {
                    Ok(node) => node,
                    Err(e) => {
                        out.clear();
                        return Err(e.into());
                    }
                };
                if windowed {
                    let key = (0..D)
                        .rev()
                        .fold(0, |k, i| k * WINDOW + index[i] - lowest[i]);
                    match slots[key] {
                        usize::MAX => {
                            slots[key] = out.len();
                            out.push(node, w * value, wg * value);
                        }
                        slot => {
                            out.values[slot] += w * value;
                            out.gradients[slot] += wg * value;
                        }
                    }
                } else {
                    out.accumulate(node, w * value, wg * value);
                }
            }
        }
        Ok(())
    }
}
