//! The affine map of one simplex, Wang et al. (2021) eqs. (13)–(15):
//! $\mathbf x = \mathbf T\boldsymbol\xi + \mathbf x_1$ with
//! $\mathbf T = [\mathbf x_2 - \mathbf x_1, \dots, \mathbf x_{D+1} - \mathbf x_1]$,
//! validated (finite, non-degenerate) for the mesh constructors.

use nalgebra::{SMatrix, SVector};

use crate::MeshError;

/// Relative degeneracy threshold: an element is rejected when
/// $|\det\mathbf T| \le 10^{-12}\,\ell^D$, $\ell$ its longest edge.
pub(crate) const DEGENERACY: f64 = 1e-12;

/// The map $\mathbf T$ of eq. (13) of the simplex with vertices
/// `vertices[0..=D]` (node ids into `nodes`, already range-checked).
pub(crate) fn edge_matrix<const D: usize>(
    nodes: &[SVector<f64, D>],
    vertices: &[usize],
) -> SMatrix<f64, D, D> {
    let origin = nodes[vertices[0]];
    SMatrix::from_fn(|i, j| nodes[vertices[j + 1]][i] - origin[i])
}

/// $\det\mathbf T$ and $\mathbf T^{-1}$ by Cramer's rule, the explicit
/// formula Wang et al. (2021) recommend after eq. (15), for $D$ = 2 or 3.
/// In 3D, with columns $\mathbf a_0, \mathbf a_1, \mathbf a_2$ of
/// $\mathbf T$, row $k$ of $\mathbf T^{-1}$ is $(\mathbf a_{k+1}\times
/// \mathbf a_{k+2})/\det\mathbf T$ (indices mod 3). The inverse is not
/// finite for a singular $\mathbf T$; callers check the determinant first.
pub(crate) fn determinant_and_inverse<const D: usize>(
    t: &SMatrix<f64, D, D>,
) -> (f64, SMatrix<f64, D, D>) {
    let mut adjugate = SMatrix::<f64, D, D>::zeros();
    let det = if D == 2 {
        adjugate[(0, 0)] = t[(1, 1)];
        adjugate[(0, 1)] = -t[(0, 1)];
        adjugate[(1, 0)] = -t[(1, 0)];
        adjugate[(1, 1)] = t[(0, 0)];
        t[(0, 0)] * t[(1, 1)] - t[(0, 1)] * t[(1, 0)]
    } else {
        let column = |k: usize| nalgebra::Vector3::new(t[(0, k)], t[(1, k)], t[(2, k)]);
        for k in 0..3 {
            let row = column((k + 1) % 3).cross(&column((k + 2) % 3));
            for i in 0..3 {
                adjugate[(k, i)] = row[i];
            }
        }
        (0..3).map(|i| t[(i, 0)] * adjugate[(0, i)]).sum()
    };
    (det, adjugate / det)
}

/// $D!$ for the simplex volume $\det\mathbf T / D!$.
pub(crate) fn factorial(dimension: usize) -> f64 {
    (1..=dimension).map(|k| k as f64).product()
}

/// Check the vertex ids of `element` (range, no repeats) and return its
/// signed volume, rejecting degenerate simplices.
pub(crate) fn signed_volume<const D: usize>(
    nodes: &[SVector<f64, D>],
    element: usize,
    vertices: &[usize],
) -> Result<f64, MeshError> {
    let (det, _) = determinant_and_inverse(&edge_matrix(nodes, vertices));
    let volume = det / factorial(D);
    let mut longest: f64 = 0.0;
    for a in 0..=D {
        for b in a + 1..=D {
            longest = longest.max((nodes[vertices[a]] - nodes[vertices[b]]).norm());
        }
    }
    let scale = longest.powi(D as i32) / factorial(D);
    if volume.is_nan() || volume.abs() <= DEGENERACY * scale {
        return Err(MeshError::DegenerateElement { element, volume });
    }
    Ok(volume)
}

/// Check that the node ids of an element (any number of nodes) are in range
/// and distinct.
pub(crate) fn check_element_nodes(
    element: usize,
    ids: &[usize],
    node_count: usize,
) -> Result<(), MeshError> {
    for (local, &node) in ids.iter().enumerate() {
        if node >= node_count {
            return Err(MeshError::ElementNodeOutOfRange {
                element,
                local,
                node,
                count: node_count,
            });
        }
        if ids[..local].contains(&node) {
            return Err(MeshError::RepeatedElementNode { element, node });
        }
    }
    Ok(())
}

/// Check that every node coordinate is finite.
pub(crate) fn check_nodes<const D: usize>(nodes: &[SVector<f64, D>]) -> Result<(), MeshError> {
    match nodes.iter().position(|x| x.iter().any(|c| !c.is_finite())) {
        Some(node) => Err(MeshError::NonFiniteNode {
            node,
            point: nodes[node].iter().copied().collect(),
        }),
        None => Ok(()),
    }
}

/// Reject dimensions other than 2 and 3.
pub(crate) fn check_dimension(dimension: usize) -> Result<(), MeshError> {
    if dimension == 2 || dimension == 3 {
        Ok(())
    } else {
        Err(MeshError::UnsupportedDimension { dimension })
    }
}

/// Check the connectivity length against `nodes_per_element` and return the
/// element count (at least one, at most `u32::MAX - 1`).
pub(crate) fn element_count(length: usize, nodes_per_element: usize) -> Result<usize, MeshError> {
    if !length.is_multiple_of(nodes_per_element) {
        return Err(MeshError::ConnectivityLength {
            length,
            nodes_per_element,
        });
    }
    let count = length / nodes_per_element;
    let max = u32::MAX as usize - 1;
    if count == 0 {
        Err(MeshError::NoElements)
    } else if count > max {
        Err(MeshError::TooManyElements { count, max })
    } else {
        Ok(count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix3};

    #[test]
    fn cramer_matches_lu() {
        let t2 = Matrix2::new(2.0, -0.5, 0.25, 1.5);
        let (d2, i2) = determinant_and_inverse(&t2);
        assert!((d2 - t2.determinant()).abs() < 1e-15);
        assert!((i2 * t2 - Matrix2::identity()).norm() < 1e-15);
        let t3 = Matrix3::new(1.0, 0.2, -0.3, 0.1, 2.0, 0.4, -0.2, 0.3, 0.7);
        let (d3, i3) = determinant_and_inverse(&t3);
        assert!((d3 - t3.determinant()).abs() < 1e-14);
        assert!((i3 * t3 - Matrix3::identity()).norm() < 1e-14);
    }
}
