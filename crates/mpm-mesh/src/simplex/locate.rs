//! Point location in a simplex mesh: the walk of Wang et al. (2021) §4.2,
//! Algorithm 1, with a bucket-grid fallback, and a brute-force reference.
//!
//! **Walking rule.** Starting from the hint (the point's previous parent
//! element), compute the local coordinates $\boldsymbol\xi$ of eq. (13) and
//! the barycentric coordinates $\lambda_1 = 1 - \sum_i\xi_i$,
//! $\lambda_{k+1} = \xi_k$ of eq. (15). If all are $\ge -\varepsilon$
//! ([`BARYCENTRIC_TOLERANCE`]) the point is inside (case IV of the paper).
//! Otherwise the most negative $\lambda_k$ names the face (opposite local
//! node $k$) whose plane separates the point from the element (cases
//! I–III), and the walk steps to the neighbour across it.
//!
//! **Fallback.** The walk gives up when it reaches a boundary face (the
//! point may lie beyond a concave part of the boundary, or outside the
//! mesh), steps straight back to the element it came from (rounding), or
//! exceeds a step budget (a cycle, possible on non-Delaunay meshes); it
//! then asks the bucket grid for the candidates at the point and tests them
//! in ascending element order. A point in no element is
//! [`MeshError::PointOutsideMesh`].
//!
//! **Tie rule.** A point on a face, edge or vertex shared by several
//! elements is inside each of them within the tolerance. The walk returns
//! the first such element it meets (deterministic for a given hint); the
//! fallback and [`SimplexMesh::locate_brute_force`] return the one with the
//! lowest id. The linear interpolation of nodal values is continuous, so it
//! is the same (to rounding) whichever element is returned.

use nalgebra::SVector;

use super::{NO_NEIGHBOUR, SimplexMesh};
use crate::MeshError;

/// Tolerance $\varepsilon$ on the barycentric coordinates: a point is inside
/// an element when all its barycentric coordinates are $\ge -\varepsilon$.
/// Barycentric coordinates are dimensionless, so this is a distance of
/// $\varepsilon$ times the element's height, far above the rounding of
/// eq. (13) for points exactly on faces, edges and vertices.
pub const BARYCENTRIC_TOLERANCE: f64 = 1e-12;

/// The element containing a point and the point's local coordinates in it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Location<const D: usize> {
    /// The element id.
    pub element: usize,
    /// Local coordinates $\boldsymbol\xi$ of eq. (13).
    pub local: SVector<f64, D>,
}

impl<const D: usize> Location<D> {
    /// Barycentric coordinate (shape function value, eq. 15) of local node
    /// `vertex`: $1 - \sum_i\xi_i$ for node 0, $\xi_{k-1}$ for node $k$.
    ///
    /// # Panics
    /// If `vertex > D`.
    pub fn barycentric(&self, vertex: usize) -> f64 {
        if vertex == 0 {
            1.0 - self.local.sum()
        } else {
            self.local[vertex - 1]
        }
    }

    /// The smallest barycentric coordinate: $\ge -\varepsilon$ for a point
    /// inside the element.
    pub fn min_barycentric(&self) -> f64 {
        most_negative(&self.local).1
    }
}

/// How a walk ([`SimplexMesh::walk`]) ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Walk<const D: usize> {
    /// The element containing the point, reached after `steps` steps
    /// across faces.
    Found {
        /// The element and the point's local coordinates in it.
        location: Location<D>,
        /// Faces crossed.
        steps: usize,
    },
    /// The point lies beyond boundary face `face` of `element`: outside the
    /// mesh, or beyond a concave part of its boundary.
    Boundary {
        /// The last element visited.
        element: usize,
        /// Its boundary face separating it from the point.
        face: usize,
    },
    /// The walk exceeded its step budget or was sent straight back to the
    /// element it came from: a cycle (possible on non-Delaunay meshes) or
    /// rounding on a face.
    Stalled {
        /// The last element visited.
        element: usize,
    },
}

/// The local node with the smallest barycentric coordinate (the lowest on
/// ties) and that coordinate.
fn most_negative<const D: usize>(local: &SVector<f64, D>) -> (usize, f64) {
    let mut best = (0, 1.0 - local.sum());
    for k in 0..D {
        if local[k] < best.1 {
            best = (k + 1, local[k]);
        }
    }
    best
}

impl<const D: usize> SimplexMesh<D> {
    /// The element containing `x` and the local coordinates of `x` in it,
    /// found by walking from `hint` (Algorithm 1; see the module
    /// documentation for the rule, the fallback and the tie rule). With no
    /// hint the bucket grid is queried directly.
    ///
    /// # Errors
    /// [`MeshError::ElementIdOutOfRange`] for a hint that is not an
    /// element; [`MeshError::PointOutsideMesh`] naming `x` when no element
    /// contains it (or it is not finite).
    pub fn locate(
        &self,
        x: &SVector<f64, D>,
        hint: Option<usize>,
    ) -> Result<Location<D>, MeshError> {
        match hint {
            Some(start) => match self.walk(x, start)? {
                Walk::Found { location, .. } => Ok(location),
                Walk::Boundary { .. } | Walk::Stalled { .. } => self.locate_in_buckets(x),
            },
            None if x.iter().all(|c| c.is_finite()) => self.locate_in_buckets(x),
            None => Err(outside(x)),
        }
    }

    /// The walk of Algorithm 1 alone, from element `start`, without the
    /// fallback: [`SimplexMesh::locate`] is this followed by the bucket
    /// grid unless the walk found the element.
    ///
    /// # Errors
    /// [`MeshError::ElementIdOutOfRange`] for a `start` that is not an
    /// element and [`MeshError::PointOutsideMesh`] for a non-finite `x`.
    pub fn walk(&self, x: &SVector<f64, D>, start: usize) -> Result<Walk<D>, MeshError> {
        if x.iter().any(|c| !c.is_finite()) {
            return Err(outside(x));
        }
        if start >= self.element_count() {
            return Err(MeshError::ElementIdOutOfRange {
                id: start,
                count: self.element_count(),
            });
        }
        let mut current = start;
        let mut previous = NO_NEIGHBOUR;
        for steps in 0..self.step_budget {
            let local = self.local_coordinates(current, x);
            let (face, lambda) = most_negative(&local);
            if lambda >= -BARYCENTRIC_TOLERANCE {
                let location = Location {
                    element: current,
                    local,
                };
                return Ok(Walk::Found { location, steps });
            }
            let next = self.neighbours[current * (D + 1) + face];
            if next == NO_NEIGHBOUR {
                return Ok(Walk::Boundary {
                    element: current,
                    face,
                });
            }
            if next == previous {
                break;
            }
            previous = current;
            current = next;
        }
        Ok(Walk::Stalled { element: current })
    }

    /// The element with the lowest id containing `x` (within the
    /// tolerance), testing every element: the reference for tests and
    /// benchmarks, $O(n)$ per point.
    ///
    /// # Errors
    /// [`MeshError::PointOutsideMesh`] naming `x`.
    pub fn locate_brute_force(&self, x: &SVector<f64, D>) -> Result<Location<D>, MeshError> {
        (0..self.element_count())
            .find_map(|element| self.inside(element, x))
            .ok_or_else(|| outside(x))
    }

    fn locate_in_buckets(&self, x: &SVector<f64, D>) -> Result<Location<D>, MeshError> {
        self.buckets
            .candidates(x)
            .iter()
            .find_map(|&element| self.inside(element as usize, x))
            .ok_or_else(|| outside(x))
    }

    fn inside(&self, element: usize, x: &SVector<f64, D>) -> Option<Location<D>> {
        let local = self.local_coordinates(element, x);
        (most_negative(&local).1 >= -BARYCENTRIC_TOLERANCE).then_some(Location { element, local })
    }
}

fn outside<const D: usize>(x: &SVector<f64, D>) -> MeshError {
    MeshError::PointOutsideMesh {
        point: x.iter().copied().collect(),
    }
}
