//! Material point domains given by their corners (the CPDI2 domain).

use mpm_mesh::BoundingBox;
use nalgebra::{SMatrix, SVector};

use crate::{BasisError, Cpdi2};

/// Storage for the corners of a domain: $2^D \le 8$ for $D \le 3$.
pub const MAX_CORNERS: usize = 8;

/// The $2^D$ corners $\mathbf x_c$ of a quadrilateral (2D) or hexahedral
/// (3D) material point domain, the multilinear image of the reference cube
/// $[-1,1]^D$:
/// $\mathbf x(\boldsymbol\xi) = \sum_c \hat M_c(\boldsymbol\xi)\,\mathbf x_c$,
/// $\hat M_c(\boldsymbol\xi) = \prod_i \tfrac12(1 + s_{c,i}\xi_i)$.
///
/// Corner order is lexicographic with axis 0 fastest, like the grid: bit
/// $i$ of the corner number $c$ is set when the corner sits at
/// $\xi_i = +1$ ($s_{c,i} = +1$). In 2D the order is therefore
/// (−,−), (+,−), (−,+), (+,+) — not the counter-clockwise order of AMPLE.
///
/// `D` must be 1, 2 or 3 (checked at compile time).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corners<const D: usize> {
    points: [SVector<f64, D>; MAX_CORNERS],
}

impl<const D: usize> Corners<D> {
    /// Number of corners, $2^D$.
    pub const COUNT: usize = {
        assert!(
            D >= 1 && D <= 3,
            "CPDI2 domains are defined for D = 1, 2, 3"
        );
        1 << D
    };

    /// Corners from a function of the corner number.
    pub fn from_fn(mut corner: impl FnMut(usize) -> SVector<f64, D>) -> Self {
        let mut points = [SVector::zeros(); MAX_CORNERS];
        for (c, p) in points.iter_mut().enumerate().take(Self::COUNT) {
            *p = corner(c);
        }
        Self { points }
    }

    /// Corners from a slice in the lexicographic order described above.
    ///
    /// # Errors
    /// [`BasisError::WrongCornerCount`] unless the slice has $2^D$ points.
    pub fn from_slice(points: &[SVector<f64, D>]) -> Result<Self, BasisError> {
        if points.len() != Self::COUNT {
            return Err(BasisError::WrongCornerCount {
                dimension: D,
                expected: Self::COUNT,
                found: points.len(),
            });
        }
        Ok(Self::from_fn(|c| points[c]))
    }

    /// The axis-aligned box `center ± half_lengths` (an undeformed GIMP-like
    /// domain).
    pub fn rectangle(center: &SVector<f64, D>, half_lengths: &SVector<f64, D>) -> Self {
        Self::from_fn(|c| center + Self::reference(c).component_mul(half_lengths))
    }

    /// The parallelogram / parallelepiped $\mathbf x_c = \mathbf x_0 +
    /// \mathbf A\,\mathbf s_c$ (an affinely deformed box).
    pub fn affine(center: &SVector<f64, D>, a: &SMatrix<f64, D, D>) -> Self {
        Self::from_fn(|c| center + a * Self::reference(c))
    }

    /// Reference coordinates $\mathbf s_c \in \{-1, 1\}^D$ of corner `c`.
    pub fn reference(c: usize) -> SVector<f64, D> {
        SVector::from_fn(|i, _| if c >> i & 1 == 1 { 1.0 } else { -1.0 })
    }

    /// The corners as a slice of length $2^D$.
    pub fn as_slice(&self) -> &[SVector<f64, D>] {
        &self.points[..Self::COUNT]
    }

    /// Apply `f` to every corner (e.g. a domain update
    /// $\mathbf x_c \mapsto \mathbf x_c + \Delta\mathbf u(\mathbf x_c)$).
    pub fn map(&self, mut f: impl FnMut(&SVector<f64, D>) -> SVector<f64, D>) -> Self {
        Self::from_fn(|c| f(&self.points[c]))
    }

    /// The domain translated by `by`.
    pub fn translated(&self, by: &SVector<f64, D>) -> Self {
        self.map(|x| x + by)
    }

    /// The bounding box of the corners, which contains the whole domain
    /// (a multilinear map stays in the convex hull of its corners).
    pub fn bounding_box(&self) -> BoundingBox<D> {
        let mut b = BoundingBox {
            lower: self.points[0],
            upper: self.points[0],
        };
        for p in self.as_slice() {
            b.lower = b.lower.inf(p);
            b.upper = b.upper.sup(p);
        }
        b
    }

    /// The point $\mathbf x(\boldsymbol\xi)$ of the domain.
    pub fn point_at(&self, xi: &SVector<f64, D>) -> SVector<f64, D> {
        (0..Self::COUNT).fold(SVector::zeros(), |x, c| {
            x + self.points[c] * reference_shape(c, xi).0
        })
    }

    /// The Jacobian $\mathbf J = \partial\mathbf x/\partial\boldsymbol\xi =
    /// \sum_c \mathbf x_c \otimes \nabla_\xi\hat M_c$ at $\boldsymbol\xi$.
    ///
    /// Computed as $\sum_c (\mathbf x_c - \mathbf x_0)\otimes\nabla_\xi
    /// \hat M_c$ (equal, since $\sum_c\nabla_\xi\hat M_c = \mathbf 0$): the
    /// differences of nearby corners are exact, so a small domain far from
    /// the origin keeps full relative accuracy.
    pub fn jacobian_at(&self, xi: &SVector<f64, D>) -> SMatrix<f64, D, D> {
        let x0 = self.points[0];
        (1..Self::COUNT).fold(SMatrix::zeros(), |j, c| {
            j + (self.points[c] - x0) * reference_shape(c, xi).1.transpose()
        })
    }

    /// The domain volume $V_p = \int_{[-1,1]^D}\det\mathbf J\,\mathrm d\xi$,
    /// integrated exactly (see [`Cpdi2::domain_integrals`]).
    ///
    /// # Errors
    /// As [`Cpdi2::domain_integrals`].
    pub fn volume(&self) -> Result<f64, BasisError> {
        Ok(Cpdi2::domain_integrals(self)?.volume)
    }

    /// The centroid $\frac{1}{V_p}\int_{\Omega_p}\mathbf x\,\mathrm d\Omega =
    /// \sum_c w_c\mathbf x_c$, which CPDI2 reproduces.
    ///
    /// # Errors
    /// As [`Cpdi2::domain_integrals`].
    pub fn centroid(&self) -> Result<SVector<f64, D>, BasisError> {
        let w = Cpdi2::domain_integrals(self)?;
        Ok((0..Self::COUNT).fold(SVector::zeros(), |x, c| {
            x + self.points[c] * w.value_weights[c]
        }))
    }
}

/// The reference corner function $\hat M_c(\boldsymbol\xi) = \prod_i
/// \tfrac12(1 + s_{c,i}\xi_i)$ and its gradient
/// $\partial_{\xi_j}\hat M_c = \tfrac12 s_{c,j}\prod_{i\ne j}\tfrac12(1 + s_{c,i}\xi_i)$.
pub fn reference_shape<const D: usize>(c: usize, xi: &SVector<f64, D>) -> (f64, SVector<f64, D>) {
    let sign = |i: usize| if c >> i & 1 == 1 { 1.0 } else { -1.0 };
    let factor = |i: usize| 0.5 * (1.0 + sign(i) * xi[i]);
    let value = (0..D).map(factor).product();
    let gradient = SVector::from_fn(|j, _| {
        (0..D).fold(1.0, |g, i| {
            g * if i == j { 0.5 * sign(i) } else { factor(i) }
        })
    });
    (value, gradient)
}

/// $\det\mathbf J$ and $\operatorname{cof}\mathbf J = \det\mathbf J\,
/// \mathbf J^{-T}$ for $D \le 3$, as polynomials in the entries (no
/// division, so also defined for singular $\mathbf J$). With $\mathbf a_k$
/// the columns of $\mathbf J$: in 2D the columns of the cofactor are
/// $(a_{1,1}, -a_{1,0})$ and $(-a_{0,1}, a_{0,0})$; in 3D column $k$ is
/// $\mathbf a_{k+1}\times\mathbf a_{k+2}$ (indices mod 3) and
/// $\det\mathbf J = \mathbf a_0\cdot(\mathbf a_1\times\mathbf a_2)$.
pub(crate) fn determinant_and_cofactor<const D: usize>(
    j: &SMatrix<f64, D, D>,
) -> (f64, SMatrix<f64, D, D>) {
    let mut cof = SMatrix::<f64, D, D>::zeros();
    let det = match D {
        1 => {
            cof[(0, 0)] = 1.0;
            j[(0, 0)]
        }
        2 => {
            cof[(0, 0)] = j[(1, 1)];
            cof[(1, 0)] = -j[(0, 1)];
            cof[(0, 1)] = -j[(1, 0)];
            cof[(1, 1)] = j[(0, 0)];
            j[(0, 0)] * j[(1, 1)] - j[(0, 1)] * j[(1, 0)]
        }
        _ => {
            for k in 0..3 {
                let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
                for i in 0..3 {
                    let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
                    cof[(i, k)] = j[(i1, k1)] * j[(i2, k2)] - j[(i2, k1)] * j[(i1, k2)];
                }
            }
            (0..3).map(|i| j[(i, 0)] * cof[(i, 0)]).sum()
        }
    };
    (det, cof)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

    #[test]
    fn cofactor_is_det_times_inverse_transpose() {
        let j2 = Matrix2::new(1.3, -0.4, 0.25, 0.9);
        let (d2, c2) = determinant_and_cofactor(&j2);
        assert!((d2 - j2.determinant()).abs() <= 1e-15);
        let expected2 = j2.try_inverse().expect("regular").transpose() * j2.determinant();
        assert!((c2 - expected2).norm() <= 1e-15);
        let j3 = Matrix3::new(1.1, 0.2, -0.3, 0.05, 0.8, 0.4, -0.2, 0.1, 1.7);
        let (d3, c3) = determinant_and_cofactor(&j3);
        assert!((d3 - j3.determinant()).abs() <= 1e-14);
        let expected3 = j3.try_inverse().expect("regular").transpose() * j3.determinant();
        assert!((c3 - expected3).norm() <= 1e-14);
    }

    #[test]
    fn corner_order_is_lexicographic_axis_zero_fastest() {
        let c = Corners::<3>::rectangle(&Vector3::new(1.0, 2.0, 3.0), &Vector3::new(0.1, 0.2, 0.3));
        assert_eq!(c.as_slice().len(), 8);
        assert_eq!(c.as_slice()[0], Vector3::new(0.9, 1.8, 2.7));
        assert_eq!(c.as_slice()[1], Vector3::new(1.1, 1.8, 2.7));
        assert_eq!(c.as_slice()[2], Vector3::new(0.9, 2.2, 2.7));
        assert_eq!(c.as_slice()[4], Vector3::new(0.9, 1.8, 3.3));
        assert_eq!(c.as_slice()[7], Vector3::new(1.1, 2.2, 3.3));
    }

    #[test]
    fn from_slice_checks_the_count() {
        let p = [Vector2::new(0.0, 0.0); 3];
        assert_eq!(
            Corners::<2>::from_slice(&p),
            Err(BasisError::WrongCornerCount {
                dimension: 2,
                expected: 4,
                found: 3
            })
        );
        let p = [
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            Vector2::new(0.0, 1.0),
            Vector2::new(1.0, 1.0),
        ];
        let c = Corners::<2>::from_slice(&p).expect("four corners");
        assert_eq!(c.as_slice(), &p);
    }

    #[test]
    fn map_and_point_at_reproduce_the_corners() {
        let a = Matrix2::new(0.3, 0.1, -0.05, 0.2);
        let c = Corners::<2>::affine(&Vector2::new(1.0, -1.0), &a);
        for k in 0..4 {
            let x = c.point_at(&Corners::<2>::reference(k));
            assert!((x - c.as_slice()[k]).norm() <= 1e-15);
        }
        let centre = c.point_at(&Vector2::zeros());
        assert!((centre - Vector2::new(1.0, -1.0)).norm() <= 1e-15);
        let moved = c.translated(&Vector2::new(0.5, 0.25));
        assert!((moved.as_slice()[3] - c.as_slice()[3] - Vector2::new(0.5, 0.25)).norm() <= 1e-15);
        // An affine domain has the constant Jacobian A.
        assert!((c.jacobian_at(&Vector2::new(0.3, -0.7)) - a).norm() <= 1e-15);
    }

    #[test]
    fn reference_shape_partition_and_gradient() {
        let xi = Vector3::new(0.2, -0.6, 0.9);
        let mut sum = 0.0;
        let mut grad_sum = Vector3::zeros();
        for c in 0..8 {
            let (m, g) = reference_shape(c, &xi);
            sum += m;
            grad_sum += g;
            // Central differences are exact for the multilinear M_c.
            for k in 0..3 {
                let mut e = Vector3::zeros();
                e[k] = 1e-3;
                let fd = (reference_shape(c, &(xi + e)).0 - reference_shape(c, &(xi - e)).0) / 2e-3;
                assert!((fd - g[k]).abs() <= 1e-12);
            }
        }
        assert!((sum - 1.0).abs() <= 1e-15);
        assert!(grad_sum.norm() <= 1e-15);
    }
}
