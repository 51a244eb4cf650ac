//! Procedural meshes: structured simplex meshes of a box (optionally
//! graded), their quadratic versions (patch parents), and a staggered,
//! optionally jittered triangle mesh of an annulus.

use std::f64::consts::TAU;

use nalgebra::{SVector, Vector2};

use crate::simplex::signed_volume;
use crate::{MeshError, NamedSets, QuadraticMesh, SimplexMesh, SplitMix64};

/// How the cells of a [`BoxMesh`] are split into simplices.
///
/// Every cell is split into the $D!$ simplices of the Kuhn (Freudenthal)
/// triangulation, one per permutation $\pi$ of the axes: the path
/// $\mathbf v_0 = \mathbf 0$, $\mathbf v_{k+1} = \mathbf v_k + \mathbf
/// e_{\pi(k)}$ through the unit cell (2 triangles in 2D, 6 tetrahedra in
/// 3D around the main diagonal). The split of every face is the Kuhn split
/// of the face, so the mesh is conforming.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum DiagonalPattern {
    /// The same split in every cell: all diagonals parallel.
    #[default]
    Uniform,
    /// The split mirrored along axis $a$ in cells with an odd index along
    /// $a$: in 2D the "union jack" pattern. Mirrored neighbours split their
    /// shared face identically, so the mesh stays conforming.
    Alternating,
}

/// A structured simplex mesh of the box $[\mathbf l, \mathbf u]$ with
/// `cells[a]` cells along axis $a$, each split by `pattern`, cell sizes
/// growing by the factor `grading[a]` from one cell to the next along axis
/// $a$ (1 for uniform cells).
///
/// Nodes are numbered lexicographically with axis 0 fastest, like
/// [`crate::RegularGrid`]. Node sets `"x0"`, `"x1"`, `"y0"`, `"y1"` (and
/// `"z0"`, `"z1"` in 3D) hold the nodes on the lower and upper face of
/// every axis.
///
/// ```
/// use mpm_mesh::{BoxMesh, DiagonalPattern};
/// use nalgebra::Vector3;
/// let mesh = BoxMesh::new(Vector3::zeros(), Vector3::new(1.0, 1.0, 2.0), [2, 2, 4])
///     .with_pattern(DiagonalPattern::Alternating)
///     .simplex_mesh()?;
/// assert_eq!(mesh.element_count(), 6 * 16);
/// assert!((mesh.total_volume() - 2.0).abs() < 1e-12);
/// assert_eq!(mesh.node_sets().get("z1").map(<[usize]>::len), Some(9));
/// # Ok::<(), mpm_mesh::MeshError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxMesh<const D: usize> {
    /// Lower corner $\mathbf l$.
    pub lower: SVector<f64, D>,
    /// Upper corner $\mathbf u$.
    pub upper: SVector<f64, D>,
    /// Cells per axis.
    pub cells: [usize; D],
    /// How every cell is split.
    pub pattern: DiagonalPattern,
    /// Ratio of successive cell sizes per axis (positive; 1 is uniform).
    pub grading: [f64; D],
}

impl<const D: usize> BoxMesh<D> {
    /// Uniform cells, [`DiagonalPattern::Uniform`].
    pub fn new(lower: SVector<f64, D>, upper: SVector<f64, D>, cells: [usize; D]) -> Self {
        Self {
            lower,
            upper,
            cells,
            pattern: DiagonalPattern::Uniform,
            grading: [1.0; D],
        }
    }

    /// The same box split by `pattern`.
    pub fn with_pattern(mut self, pattern: DiagonalPattern) -> Self {
        self.pattern = pattern;
        self
    }

    /// The same box with cell-size ratios `grading`.
    pub fn with_grading(mut self, grading: [f64; D]) -> Self {
        self.grading = grading;
        self
    }

    /// Node coordinates along `axis`: $l + L\,(r^k - 1)/(r^n - 1)$ for
    /// ratio $r \ne 1$, equal steps for $r = 1$; the last is exactly $u$.
    fn axis_coordinates(&self, axis: usize) -> Vec<f64> {
        let (l, u, n, r) = (
            self.lower[axis],
            self.upper[axis],
            self.cells[axis],
            self.grading[axis],
        );
        (0..=n)
            .map(|k| {
                let t = if k == n {
                    1.0
                } else if r == 1.0 {
                    k as f64 / n as f64
                } else {
                    (r.powi(k as i32) - 1.0) / (r.powi(n as i32) - 1.0)
                };
                if k == n { u } else { l + (u - l) * t }
            })
            .collect()
    }

    fn validate(&self) -> Result<(), MeshError> {
        crate::simplex::check_dimension(D)?;
        for axis in 0..D {
            let (lower, upper) = (self.lower[axis], self.upper[axis]);
            if !(lower.is_finite() && upper.is_finite() && lower < upper) {
                return Err(MeshError::InvalidBounds { axis, lower, upper });
            }
            if self.cells[axis] == 0 {
                return Err(MeshError::NoCells { axis });
            }
            let r = self.grading[axis];
            if !(r.is_finite() && r > 0.0) {
                return Err(MeshError::InvalidGeneratorParameter {
                    parameter: "grading",
                    value: r,
                    requirement: "a cell-size ratio must be positive and finite",
                });
            }
        }
        Ok(())
    }

    /// The linear simplex mesh ($D!$ simplices per cell).
    ///
    /// # Errors
    /// [`MeshError::UnsupportedDimension`], [`MeshError::InvalidBounds`],
    /// [`MeshError::NoCells`], [`MeshError::InvalidGeneratorParameter`] for
    /// a bad grading, and the errors of [`SimplexMesh::new`] (for example
    /// [`MeshError::TooManyElements`]).
    pub fn simplex_mesh(&self) -> Result<SimplexMesh<D>, MeshError> {
        self.validate()?;
        let coordinates: Vec<Vec<f64>> = (0..D).map(|a| self.axis_coordinates(a)).collect();
        let nodes_per_axis: [usize; D] = std::array::from_fn(|a| self.cells[a] + 1);
        let node_id = |index: &[usize; D]| {
            (0..D)
                .rev()
                .fold(0, |id, a| id * nodes_per_axis[a] + index[a])
        };
        let node_count: usize = nodes_per_axis.iter().product();
        let nodes: Vec<SVector<f64, D>> = (0..node_count)
            .map(|id| {
                let index = unflatten(id, &nodes_per_axis);
                SVector::from_fn(|a, _| coordinates[a][index[a]])
            })
            .collect();
        let permutations = permutations(D);
        let cell_count: usize = self.cells.iter().product();
        let mut connectivity = Vec::with_capacity(cell_count * permutations.len() * (D + 1));
        for cell in 0..cell_count {
            let c = unflatten(cell, &self.cells);
            let mirror: [bool; D] = std::array::from_fn(|a| {
                self.pattern == DiagonalPattern::Alternating && c[a] % 2 == 1
            });
            let corner = |bits: usize| {
                let index: [usize; D] =
                    std::array::from_fn(|a| c[a] + usize::from((bits >> a & 1 == 1) != mirror[a]));
                node_id(&index)
            };
            for permutation in &permutations {
                let mut bits = 0;
                connectivity.push(corner(bits));
                for &axis in permutation {
                    bits |= 1 << axis;
                    connectivity.push(corner(bits));
                }
            }
        }
        orient_positive::<D>(&nodes, &mut connectivity)?;
        let mut mesh = SimplexMesh::new(nodes, connectivity)?;
        let mut node_sets = NamedSets::default();
        for (axis, name) in AXIS_NAMES.iter().enumerate().take(D) {
            for (side, at) in [(0, 0), (1, self.cells[axis])] {
                let ids = (0..node_count)
                    .filter(|&id| unflatten(id, &nodes_per_axis)[axis] == at)
                    .collect();
                node_sets.insert_trusted(format!("{name}{side}"), ids);
            }
        }
        mesh.sets_mut().replace(node_sets, NamedSets::default());
        Ok(mesh)
    }

    /// The quadratic mesh (six-node triangles, ten-node tetrahedra) of
    /// [`BoxMesh::simplex_mesh`], see [`QuadraticMesh::from_linear`]: the
    /// patch parents of the F-patch method.
    ///
    /// # Errors
    /// As [`BoxMesh::simplex_mesh`].
    pub fn quadratic_mesh(&self) -> Result<QuadraticMesh<D>, MeshError> {
        Ok(QuadraticMesh::from_linear(&self.simplex_mesh()?))
    }
}

const AXIS_NAMES: [&str; 3] = ["x", "y", "z"];

/// Multi-index of the lexicographic id `id` (axis 0 fastest).
fn unflatten<const D: usize>(mut id: usize, counts: &[usize; D]) -> [usize; D] {
    std::array::from_fn(|a| {
        let i = id % counts[a];
        id /= counts[a];
        i
    })
}

/// All permutations of `0..n` in lexicographic order (the $n!$ Kuhn
/// simplices of a cube, one per permutation of the axes).
pub fn permutations(n: usize) -> Vec<Vec<usize>> {
    if n == 0 {
        return vec![Vec::new()];
    }
    let mut all = Vec::new();
    for first in 0..n {
        for rest in permutations(n - 1) {
            let mut p = vec![first];
            p.extend(rest.into_iter().map(|k| if k >= first { k + 1 } else { k }));
            all.push(p);
        }
    }
    all
}

/// Swap local nodes 1 and 2 of every negatively oriented element.
fn orient_positive<const D: usize>(
    nodes: &[SVector<f64, D>],
    connectivity: &mut [usize],
) -> Result<(), MeshError> {
    for (element, vertices) in connectivity.chunks_exact_mut(D + 1).enumerate() {
        if signed_volume(nodes, element, vertices)? < 0.0 {
            vertices.swap(1, 2);
        }
    }
    Ok(())
}

/// A triangle mesh of the annulus $R_i \le r \le R_o$ (the elastic annulus
/// case uses $R_i = 0.75$, $R_o = 1.25$): `radial + 1` rings of
/// `circumferential` nodes, ring $i$ at radius $R_i + i\,(R_o - R_i)/n_r$
/// and rotated by half an angular step from ring $i-1$, so that each band
/// between rings holds $2 n_\theta$ nearly equilateral triangles; optionally
/// the interior rings' nodes are jittered.
///
/// Nodes are numbered ring by ring from the inside, counter-clockwise from
/// angle 0. Node sets `"inner"` and `"outer"` hold the two boundary rings.
/// The mesh covers the region between two regular $n_\theta$-gons, of area
/// $\tfrac{n_\theta}{2}\sin(2\pi/n_\theta)\,(R_o^2 - R_i^2)$ whatever the
/// jitter.
///
/// ```
/// use mpm_mesh::AnnulusMesh;
/// let mesh = AnnulusMesh::new(0.75, 1.25, 4, 48).simplex_mesh()?;
/// assert_eq!(mesh.element_count(), 2 * 4 * 48);
/// assert_eq!(mesh.node_sets().get("outer").map(<[usize]>::len), Some(48));
/// # Ok::<(), mpm_mesh::MeshError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnnulusMesh {
    /// Inner radius $R_i > 0$.
    pub inner_radius: f64,
    /// Outer radius $R_o > R_i$.
    pub outer_radius: f64,
    /// Element layers across the thickness, $n_r \ge 1$.
    pub radial: usize,
    /// Nodes per ring, $n_\theta \ge 3$.
    pub circumferential: usize,
    /// Jitter of interior nodes, as a fraction in $[0, 0.2]$ of the radial
    /// step (radially) and of the angular step (circumferentially).
    pub jitter: f64,
    /// Seed of the jitter's pseudo-random sequence.
    pub seed: u64,
}

impl AnnulusMesh {
    /// Largest admissible [`AnnulusMesh::jitter`].
    pub const MAX_JITTER: f64 = 0.2;

    /// An annulus without jitter.
    pub fn new(
        inner_radius: f64,
        outer_radius: f64,
        radial: usize,
        circumferential: usize,
    ) -> Self {
        Self {
            inner_radius,
            outer_radius,
            radial,
            circumferential,
            jitter: 0.0,
            seed: 0,
        }
    }

    /// The same annulus with interior nodes jittered by `fraction` (see
    /// [`AnnulusMesh::jitter`]) from the pseudo-random sequence `seed`.
    pub fn with_jitter(mut self, fraction: f64, seed: u64) -> Self {
        self.jitter = fraction;
        self.seed = seed;
        self
    }

    fn validate(&self) -> Result<(), MeshError> {
        let invalid = |parameter, value, requirement| {
            Err(MeshError::InvalidGeneratorParameter {
                parameter,
                value,
                requirement,
            })
        };
        let (ri, ro) = (self.inner_radius, self.outer_radius);
        if !(ri.is_finite() && ri > 0.0) {
            return invalid("inner_radius", ri, "must be positive and finite");
        }
        if !(ro.is_finite() && ro > ri) {
            return invalid(
                "outer_radius",
                ro,
                "must be finite and above the inner radius",
            );
        }
        if self.radial == 0 {
            return invalid("radial", 0.0, "at least one element layer");
        }
        if self.circumferential < 3 {
            return invalid(
                "circumferential",
                self.circumferential as f64,
                "at least three nodes per ring",
            );
        }
        // The chord between two nodes of ring i + 1 must pass outside the
        // node of ring i between them, r_{i+1} cos(pi / n) > r_i, tightest
        // for the outermost band.
        let dr = (ro - ri) / self.radial as f64;
        let half_step = std::f64::consts::PI / self.circumferential as f64;
        if ro * half_step.cos() <= ro - dr {
            return invalid(
                "circumferential",
                self.circumferential as f64,
                "too few nodes per ring for the radial step: the triangles would fold",
            );
        }
        if !(0.0..=Self::MAX_JITTER).contains(&self.jitter) {
            return invalid("jitter", self.jitter, "must lie in [0, 0.2]");
        }
        Ok(())
    }

    /// The triangle mesh.
    ///
    /// # Errors
    /// [`MeshError::InvalidGeneratorParameter`] naming a bad parameter
    /// (including too few nodes per ring, $R_o\cos(\pi/n_\theta) \le R_o -
    /// \Delta r$, where the outermost triangles would fold), and the errors of
    /// [`SimplexMesh::new`], for example [`MeshError::InvertedElement`] when
    /// the jitter folds a coarse mesh.
    pub fn simplex_mesh(&self) -> Result<SimplexMesh<2>, MeshError> {
        self.validate()?;
        let (n_r, n_t) = (self.radial, self.circumferential);
        let dr = (self.outer_radius - self.inner_radius) / n_r as f64;
        let dt = TAU / n_t as f64;
        let id = |ring: usize, j: usize| ring * n_t + j % n_t;
        let position = |ring: usize, j: usize, shift: (f64, f64)| {
            let r = self.inner_radius + (ring as f64 + shift.0) * dr;
            let t = (j as f64 + 0.5 * ring as f64 + shift.1) * dt;
            Vector2::new(r * t.cos(), r * t.sin())
        };
        let mut nodes: Vec<Vector2<f64>> = (0..=n_r)
            .flat_map(|ring| (0..n_t).map(move |j| (ring, j)))
            .map(|(ring, j)| position(ring, j, (0.0, 0.0)))
            .collect();
        let mut connectivity = Vec::with_capacity(6 * n_r * n_t);
        for ring in 0..n_r {
            for j in 0..n_t {
                // Node j of the outer ring lies between nodes j and j + 1
                // of the inner ring; both triangles counter-clockwise.
                let (a, b, c, d) = (
                    id(ring, j),
                    id(ring, j + 1),
                    id(ring + 1, j),
                    id(ring + 1, j + 1),
                );
                connectivity.extend_from_slice(&[a, c, b, c, d, b]);
            }
        }
        if self.jitter > 0.0 {
            let mut random = SplitMix64(self.seed);
            for ring in 1..n_r {
                for j in 0..n_t {
                    let shift = (
                        self.jitter * random.symmetric(),
                        self.jitter * random.symmetric(),
                    );
                    nodes[id(ring, j)] = position(ring, j, shift);
                }
            }
        }
        let mut mesh = SimplexMesh::new(nodes, connectivity)?;
        let mut node_sets = NamedSets::default();
        node_sets.insert_trusted("inner", (0..n_t).collect());
        node_sets.insert_trusted("outer", (n_r * n_t..(n_r + 1) * n_t).collect());
        mesh.sets_mut().replace(node_sets, NamedSets::default());
        Ok(mesh)
    }

    /// The six-node triangle mesh of [`AnnulusMesh::simplex_mesh`] (straight
    /// edges), see [`QuadraticMesh::from_linear`].
    ///
    /// # Errors
    /// As [`AnnulusMesh::simplex_mesh`].
    pub fn quadratic_mesh(&self) -> Result<QuadraticMesh<2>, MeshError> {
        Ok(QuadraticMesh::from_linear(&self.simplex_mesh()?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permutations_are_all_distinct() {
        assert_eq!(permutations(2), vec![vec![0, 1], vec![1, 0]]);
        let p = permutations(3);
        assert_eq!(p.len(), 6);
        assert_eq!(p[0], vec![0, 1, 2]);
        assert_eq!(p[5], vec![2, 1, 0]);
    }

    #[test]
    fn graded_axis_grows_by_the_ratio() {
        let spec = BoxMesh::new(Vector2::new(0.0, 1.0), Vector2::new(7.0, 2.0), [3, 2])
            .with_grading([2.0, 1.0]);
        let x = spec.axis_coordinates(0);
        assert_eq!(x, vec![0.0, 1.0, 3.0, 7.0]);
        assert_eq!(spec.axis_coordinates(1), vec![1.0, 1.5, 2.0]);
    }
}
