//! Ghost penalty on the faces of cut cells: the small-cut stabilisation of
//! unfitted methods (Burman 2010, *Ghost penalty*, C. R. Math. 348;
//! brought to the implicit MPM by Coombs 2023, *Ghost stabilisation of the
//! material point method for stable quasi-static and dynamic analysis of
//! large deformation problems*, IJNME 124).
//!
//! **Why.** A cell that a body barely covers (a lone point near one of its
//! edges, at the staircase boundary of a lattice of points) reaches its
//! far nodes with small weights: standard MPM's bilinear gradients there
//! are proportional to the point's distance from the near edges. Those
//! nodes then carry near-mechanisms of the stiffness (measured on Cook's
//! membrane at ν = 0.4999 on a 16-cell grid with F-bar: smallest singular
//! value 5·10⁻³ against a shear modulus of 83, its mode the right edge's
//! fringe nodes), and Newton corrections along them strain the fringe
//! points beyond any admissible increment. Holding such nodes fixed (the
//! weak-node rules of [`crate::NewtonOptions`]) removes the mode but
//! constrains the body: the same membrane's tip fell from 6.9 to 2.3 when
//! the rule held nodes up to 3 % of the largest stiffness weight.
//!
//! **What.** On every face $F$ shared by two cells that hold points, at
//! least one of them cut (its points' volume below
//! [`GhostPenalty::fill`] of its own), the step's increment pays
//!
//! $$ \tfrac12\,\gamma\,2\mu\,h_F \int_F \big[\![\partial_n \Delta\mathbf u]\!\big]^2\,\mathrm d\Gamma, $$
//!
//! where $[\![\partial_n\Delta\mathbf u]\!]$ is the jump of the normal
//! derivative of the cells' multilinear interpolant of the nodal
//! increments across $F$, $h_F$ the spacing normal to $F$, $\mu$ the
//! largest shear modulus of the two cells' points (the law's
//! `point_shear_modulus`: one value for one material, each point's own
//! under a `MaterialSet`) and $\gamma$ [`GhostPenalty::factor`]. The tangential
//! derivatives of a continuous interpolant do not jump, so this is the
//! jump of the whole gradient. It vanishes for every increment that is
//! linear in space (a patch test, [`tests`]), so it does not change the
//! solution of a problem whose exact increments are linear, and it
//! perturbs smooth increments at $O(\gamma h^2)$ relative; it ties a
//! fringe node to the nodes of the neighbouring full cell, whose stiffness
//! it borrows. It acts on each step's increment and is forgotten with the
//! grid at the end of the step, so a response that is not linear in space
//! depends on the number of steps at O(γ) (0.8 % between 1 and 3 steps on
//! a coarse Cook membrane at γ = 0.01).
//!
//! **The stiffness, exactly.** Let the face be normal to axis $a$, between
//! the lower cell $A$ and the upper cell $B$. Its nodes are three layers
//! along $a$ (A's lower face, the shared face, B's upper face) times the
//! $2^{D-1}$ corners of the face. On $F$ the derivative along $a$ of a
//! node's multilinear function is $\pm T_v/h_a$ with $T_v$ the product of
//! its 1D hat functions along the other axes; the jump $B - A$ is
//! $c_\ell\,T_v/h_a$ with $c = (1, -2, 1)$ by layer $\ell$ (a second
//! difference). With the 1D mass matrix
//! $M = \begin{pmatrix}1/3&1/6\\1/6&1/3\end{pmatrix}$ the face integral is
//! exact:
//!
//! $$ K_{vw} = \gamma\,2\mu\,\frac{c_{\ell_v}c_{\ell_w}}{h_a}\prod_{i\ne a} h_i\,M_{\beta_{v,i}\beta_{w,i}}, $$
//!
//! $\beta_{v,i}$ the corner bit of $v$ along axis $i$, acting on each
//! displacement component alike. $K$ is symmetric and positive
//! semi-definite; the residual gains $K\Delta\mathbf u$, the stiffness $K$.

use mpm_mesh::{MeshError, RegularGrid};
use nalgebra::SVector;

use crate::stages::system::{NONE, StepSystem};

/// The ghost penalty's controls ([`crate::NewtonOptions::ghost`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GhostPenalty {
    /// $\gamma$: the penalty's modulus as a multiple of the law's $2\mu$;
    /// zero disables the penalty.
    pub factor: f64,
    /// A cell is cut when the volume of its points is below this fraction
    /// of its own volume.
    pub fill: f64,
}

impl GhostPenalty {
    /// No penalty.
    pub const OFF: Self = Self {
        factor: 0.0,
        fill: 0.5,
    };

    /// A penalty of `factor` · 2μ on the faces of cells filled below half
    /// (the setting measured on Cook's membrane,
    /// `docs/src/theory/locking.md`).
    pub const fn new(factor: f64) -> Self {
        Self { factor, fill: 0.5 }
    }

    /// Whether the penalty acts.
    pub fn is_on(&self) -> bool {
        self.factor > 0.0
    }
}

impl Default for GhostPenalty {
    fn default() -> Self {
        Self::OFF
    }
}

/// The penalised faces of a step and their stiffness, in active node
/// numbering; buffers keep their capacity between steps.
#[derive(Debug, Default)]
pub struct GhostFaces {
    /// Nodes per face: $3\cdot 2^{D-1}$.
    pub stride: usize,
    /// Active ids of each face's nodes, `stride` per face, layer-major
    /// (layer along the face normal, then the face corner).
    pub nodes: Vec<u32>,
    /// $K_{vw}$ of each face, `stride²` per face, row-major.
    pub weights: Vec<f64>,
    /// CSR over active nodes: the faces touching each node.
    pub node_ptr: Vec<usize>,
    /// See `node_ptr`.
    pub node_faces: Vec<u32>,
    /// Volume of the points per cell (scratch).
    fill: Vec<f64>,
    /// Largest modulus of the points per cell (scratch).
    cell_modulus: Vec<f64>,
    /// (lower cell id, normal axis) of each face (scratch).
    faces: Vec<(usize, usize)>,
}

impl GhostFaces {
    /// Number of penalised faces.
    pub fn len(&self) -> usize {
        self.nodes.len().checked_div(self.stride).unwrap_or(0)
    }

    /// Whether no face is penalised (the penalty is off, or no cell is
    /// cut).
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Forgets the faces (a step without the penalty).
    pub fn clear(&mut self) {
        self.nodes.clear();
        self.weights.clear();
        self.node_ptr.clear();
        self.node_faces.clear();
    }

    /// Finds the penalised faces of the step on `grid` from the points at
    /// the start of the step and computes their stiffness; `modulus(p)` is
    /// $\gamma\,2\mu_p$ at point `p`, and a face takes the largest of its two
    /// cells' points (one value for a law of one material; with several,
    /// a soft body's faces are not penalised at a stiff body's modulus).
    /// Faces with a node outside the active set (possible with bases whose
    /// stencils are not the cell's nodes) are left out.
    ///
    /// # Errors
    /// A [`MeshError`] for a point outside the grid.
    pub fn build<const D: usize>(
        &mut self,
        grid: &RegularGrid<D>,
        position: &[SVector<f64, D>],
        volume: &[f64],
        sys: &StepSystem<D>,
        modulus: &dyn Fn(usize) -> f64,
        fill: f64,
    ) -> Result<(), MeshError> {
        self.clear();
        let half = 1usize << (D - 1);
        self.stride = 3 * half;
        self.fill.clear();
        self.fill.resize(grid.cell_count(), 0.0);
        self.cell_modulus.clear();
        self.cell_modulus.resize(grid.cell_count(), 0.0);
        for (p, (x, &v)) in position.iter().zip(volume).enumerate() {
            let cell = grid.cell_id(grid.cell_containing(x)?)?;
            self.fill[cell] += v;
            self.cell_modulus[cell] = self.cell_modulus[cell].max(modulus(p));
        }
        let h = grid.spacing();
        let cell_volume: f64 = h.iter().product();
        let cells = grid.cells_per_axis();
        self.faces.clear();
        for (id, &f) in self.fill.iter().enumerate() {
            if f <= 0.0 || f >= fill * cell_volume {
                continue;
            }
            let index = grid.cell_index(id)?;
            for a in 0..D {
                for up in [false, true] {
                    let mut other = index;
                    match up {
                        true if index[a] + 1 < cells[a] => other[a] += 1,
                        false if index[a] > 0 => other[a] -= 1,
                        _ => continue,
                    }
                    let other_id = grid.cell_id(other)?;
                    if self.fill[other_id] > 0.0 {
                        self.faces.push((id.min(other_id), a));
                    }
                }
            }
        }
        self.faces.sort_unstable();
        self.faces.dedup();
        // The 1D mass matrix of the hat functions on [0, 1].
        let mass = |p: usize, q: usize| if p == q { 1.0 / 3.0 } else { 1.0 / 6.0 };
        let layer_factor = [1.0, -2.0, 1.0];
        let m = self.stride;
        let mut local = vec![0u32; m];
        let mut corners = vec![[0usize; D]; m];
        let faces = std::mem::take(&mut self.faces);
        'faces: for &(lower, a) in &faces {
            let base = grid.cell_index(lower)?;
            let mut upper = base;
            upper[a] += 1;
            let face_modulus =
                self.cell_modulus[lower].max(self.cell_modulus[grid.cell_id(upper)?]);
            for (slot, corner) in corners.iter_mut().enumerate() {
                // Slot = layer · 2^(D−1) + face corner; the corner's bits
                // run over the axes other than `a`.
                let (layer, bits) = (slot / half, slot % half);
                let mut index = base;
                let mut bit = 0;
                for (i, entry) in index.iter_mut().enumerate() {
                    if i == a {
                        *entry += layer;
                        corner[i] = layer;
                    } else {
                        let b = (bits >> bit) & 1;
                        *entry += b;
                        corner[i] = b;
                        bit += 1;
                    }
                }
                let active = sys.active_of_mesh[grid.node_id(index)?];
                if active == NONE {
                    continue 'faces;
                }
                local[slot] = active;
            }
            self.nodes.extend_from_slice(&local);
            for (cv, bv) in corners.iter().enumerate().map(|(s, c)| (s / half, c)) {
                for (cw, bw) in corners.iter().enumerate().map(|(s, c)| (s / half, c)) {
                    let tangential: f64 = (0..D)
                        .filter(|&i| i != a)
                        .map(|i| h[i] * mass(bv[i], bw[i]))
                        .product();
                    self.weights.push(
                        face_modulus * layer_factor[cv] * layer_factor[cw] / h[a] * tangential,
                    );
                }
            }
        }
        self.faces = faces;
        // Faces per node.
        let n = sys.n_active();
        self.node_ptr.resize(n + 1, 0);
        for &v in &self.nodes {
            self.node_ptr[v as usize + 1] += 1;
        }
        for v in 0..n {
            self.node_ptr[v + 1] += self.node_ptr[v];
        }
        self.node_faces.resize(self.node_ptr[n], 0);
        let mut next = self.node_ptr[..n].to_vec();
        for (k, face) in self.nodes.chunks_exact(m).enumerate() {
            for &v in face {
                self.node_faces[next[v as usize]] = k as u32;
                next[v as usize] += 1;
            }
        }
        Ok(())
    }

    /// Pushes the nodes that share a penalised face with active node `w`
    /// (for [`StepSystem::extend_neighbours`]).
    pub fn partners(&self, w: usize, push: &mut dyn FnMut(u32)) {
        if self.node_ptr.len() <= w + 1 {
            return;
        }
        let m = self.stride;
        for &k in &self.node_faces[self.node_ptr[w]..self.node_ptr[w + 1]] {
            for &v in &self.nodes[k as usize * m..(k as usize + 1) * m] {
                push(v);
            }
        }
    }

    /// Each face's active nodes and its `stride²` stiffness weights.
    fn face_blocks(&self) -> impl Iterator<Item = (&[u32], &[f64])> {
        let m = self.stride;
        self.nodes
            .chunks_exact(m)
            .zip(self.weights.chunks_exact(m * m))
    }

    /// Adds the penalty's force $K\Delta\mathbf u$ to `force` (both per
    /// active dof, `D · v + i`).
    pub fn add_force<const D: usize>(&self, du: &[f64], force: &mut [f64]) {
        let m = self.stride;
        for (nodes, k) in self.face_blocks() {
            for (a, &v) in nodes.iter().enumerate() {
                for (b, &w) in nodes.iter().enumerate() {
                    let kab = k[a * m + b];
                    for i in 0..D {
                        force[D * v as usize + i] += kab * du[D * w as usize + i];
                    }
                }
            }
        }
    }

    /// Adds the penalty's stiffness to the CSC `values` of `sys` (whose
    /// neighbour lists hold the face partners, [`Self::partners`]).
    pub fn add_stiffness<const D: usize>(&self, sys: &StepSystem<D>, values: &mut [f64]) {
        let m = self.stride;
        for (nodes, k) in self.face_blocks() {
            for (b, &w) in nodes.iter().enumerate() {
                let w = w as usize;
                let nbs = &sys.nb[sys.nb_ptr[w]..sys.nb_ptr[w + 1]];
                let map = &sys.block_map[sys.nb_ptr[w] * D * D..];
                let block = &mut values[sys.block_ptr[w]..sys.block_ptr[w + 1]];
                for (a, &v) in nodes.iter().enumerate() {
                    let Ok(pos) = nbs.binary_search(&v) else {
                        continue;
                    };
                    for i in 0..D {
                        let offset = map[(pos * D + i) * D + i];
                        if offset != NONE {
                            block[offset as usize] += k[a * m + b];
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{SMatrix, Vector2, Vector3};

    /// A step system whose active nodes are all nodes of `grid` (active id
    /// = mesh id), enough for [`GhostFaces::build`].
    fn all_active<const D: usize>(grid: &RegularGrid<D>) -> StepSystem<D> {
        StepSystem {
            active_of_mesh: (0..grid.node_count() as u32).collect(),
            active: (0..grid.node_count()).collect(),
            ..StepSystem::default()
        }
    }

    /// The penalty's force on the nodal field `u(x)` of `grid`.
    fn force_of<const D: usize>(
        grid: &RegularGrid<D>,
        faces: &GhostFaces,
        u: impl Fn(&SVector<f64, D>) -> SVector<f64, D>,
    ) -> Vec<f64> {
        let mut du = vec![0.0; D * grid.node_count()];
        for v in 0..grid.node_count() {
            let x = grid.node_position(v).unwrap_or_else(|_| SVector::zeros());
            du[D * v..D * v + D].copy_from_slice(u(&x).as_slice());
        }
        let mut f = vec![0.0; du.len()];
        faces.add_force::<D>(&du, &mut f);
        f
    }

    /// Points on a lattice of `per`^D per cell filling the part of the
    /// grid where `inside` holds, so that the cells it cuts are partly
    /// filled.
    fn lattice<const D: usize>(
        grid: &RegularGrid<D>,
        per: usize,
        inside: impl Fn(&SVector<f64, D>) -> bool,
    ) -> (Vec<SVector<f64, D>>, Vec<f64>) {
        let (o, h) = (grid.origin(), grid.spacing());
        let counts = grid.cells_per_axis().map(|c| c * per);
        let total: usize = counts.iter().product();
        let v: f64 = h.iter().map(|h| h / per as f64).product();
        let mut out = (Vec::new(), Vec::new());
        for k in 0..total {
            let mut rest = k;
            let x = SVector::<f64, D>::from_fn(|i, _| {
                let j = rest % counts[i];
                rest /= counts[i];
                o[i] + (j as f64 + 0.5) * h[i] / per as f64
            });
            if inside(&x) {
                out.0.push(x);
                out.1.push(v);
            }
        }
        out
    }

    fn faces_of<const D: usize>(
        grid: &RegularGrid<D>,
        inside: impl Fn(&SVector<f64, D>) -> bool,
    ) -> GhostFaces {
        let (x, v) = lattice(grid, 2, inside);
        let sys = all_active(grid);
        let mut faces = GhostFaces::default();
        faces
            .build(grid, &x, &v, &sys, &|_| 3.0, 0.9)
            .unwrap_or_else(|e| panic!("{e}"));
        faces
    }

    /// Each face takes the larger modulus of its two cells' points: two
    /// materials side by side (moduli 1 and 5 split at x = 1.75, inside a
    /// column of cells) give faces of 1 in the soft part, 5 in the stiff
    /// part and 5 on the faces between them.
    #[test]
    fn a_face_takes_the_larger_modulus_of_its_cells() {
        let grid = RegularGrid::new(Vector2::zeros(), Vector2::new(0.5, 0.5), [7, 5])
            .unwrap_or_else(|e| panic!("{e}"));
        let (x, v) = lattice(&grid, 2, |x| (x - Vector2::new(1.7, 1.2)).norm() < 1.3);
        let sys = all_active(&grid);
        let soft = |p: usize| if x[p][0] < 1.75 { 1.0 } else { 5.0 };
        let mut unit = GhostFaces::default();
        unit.build(&grid, &x, &v, &sys, &|_| 1.0, 0.9)
            .unwrap_or_else(|e| panic!("{e}"));
        let mut mixed = GhostFaces::default();
        mixed
            .build(&grid, &x, &v, &sys, &soft, 0.9)
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(unit.nodes, mixed.nodes);
        let mut cell_max = vec![0.0f64; grid.cell_count()];
        for (p, y) in x.iter().enumerate() {
            let c = grid
                .cell_id(grid.cell_containing(y).unwrap_or_else(|e| panic!("{e}")))
                .unwrap_or_else(|e| panic!("{e}"));
            cell_max[c] = cell_max[c].max(soft(p));
        }
        let m2 = unit.stride * unit.stride;
        let mut seen = [false; 2];
        for (k, &(lower, a)) in mixed.faces.iter().enumerate() {
            let mut upper = grid.cell_index(lower).unwrap_or_else(|e| panic!("{e}"));
            upper[a] += 1;
            let upper = grid.cell_id(upper).unwrap_or_else(|e| panic!("{e}"));
            let want = cell_max[lower].max(cell_max[upper]);
            seen[usize::from(want > 1.0)] = true;
            for (w, u) in mixed.weights[k * m2..(k + 1) * m2]
                .iter()
                .zip(&unit.weights[k * m2..(k + 1) * m2])
            {
                assert!((w - want * u).abs() <= 1e-12 * u.abs(), "face {k}: {w} {u}");
            }
        }
        assert_eq!(seen, [true, true], "faces of both moduli");
    }

    /// The penalty vanishes for every linear increment (patch test, to
    /// rounding), in 2D and 3D on non-square cells, and not for a
    /// quadratic one.
    #[test]
    fn the_penalty_vanishes_for_linear_increments_only() {
        let grid = RegularGrid::new(Vector2::new(-1.0, 0.5), Vector2::new(0.7, 1.3), [8, 6])
            .unwrap_or_else(|e| panic!("{e}"));
        // A disc: its staircase cuts cells on every side.
        let faces = faces_of(&grid, |x| (x - Vector2::new(1.8, 4.4)).norm() < 2.6);
        assert!(faces.len() > 10, "{} faces", faces.len());
        let a = SMatrix::<f64, 2, 2>::new(0.3, -1.1, 0.7, 0.2);
        let b = Vector2::new(0.4, -0.9);
        let linear = force_of(&grid, &faces, |x| a * x + b);
        let quadratic = force_of(&grid, &faces, |x| Vector2::new(x[0] * x[1], x[1] * x[1]));
        let norm = |f: &[f64]| f.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!(norm(&linear) < 1e-13, "linear: {:e}", norm(&linear));
        assert!(norm(&quadratic) > 1e-2, "quadratic: {:e}", norm(&quadratic));

        let grid3 = RegularGrid::new(Vector3::zeros(), Vector3::new(0.5, 0.8, 0.6), [5, 4, 4])
            .unwrap_or_else(|e| panic!("{e}"));
        let faces3 = faces_of(&grid3, |x| x[0] + 0.7 * x[1] + 0.4 * x[2] < 2.1);
        assert!(faces3.len() > 10, "{} faces", faces3.len());
        let a3 = SMatrix::<f64, 3, 3>::new(0.3, -1.1, 0.7, 0.2, 0.5, -0.4, 1.2, 0.1, -0.6);
        let linear3 = force_of(&grid3, &faces3, |x| a3 * x + Vector3::new(1.0, 2.0, 3.0));
        let quadratic3 = force_of(&grid3, &faces3, |x| {
            Vector3::new(x[0] * x[2], x[1] * x[1], x[0])
        });
        assert!(norm(&linear3) < 1e-13, "linear 3D: {:e}", norm(&linear3));
        assert!(
            norm(&quadratic3) > 1e-2,
            "quadratic 3D: {:e}",
            norm(&quadratic3)
        );
    }

    /// The face stiffness is symmetric and positive semi-definite, and its
    /// energy for an increment equals the face integral of the squared
    /// gradient jump, computed independently by Gauss quadrature of the
    /// multilinear functions of the two cells.
    #[test]
    fn the_face_stiffness_is_the_integral_of_the_squared_jump() {
        let grid = RegularGrid::new(Vector3::zeros(), Vector3::new(0.5, 0.8, 0.6), [3, 3, 3])
            .unwrap_or_else(|e| panic!("{e}"));
        // One cell filled, its neighbours a quarter: every face of the
        // corner cell's neighbours is cut.
        let faces = faces_of(&grid, |x| x[0] < 0.75 && x[1] < 1.2 && x[2] < 0.9);
        assert!(!faces.is_empty());
        let m = faces.stride;
        let u = |x: &Vector3<f64>| {
            Vector3::new(
                (3.0 * x[0]).sin() * x[1],
                x[2] * x[2] - x[0],
                (x[1] * x[0]).cos(),
            )
        };
        let h = grid.spacing();
        for (k, (nodes, w)) in faces
            .nodes
            .chunks_exact(m)
            .zip(faces.weights.chunks_exact(m * m))
            .enumerate()
        {
            for a in 0..m {
                for b in 0..m {
                    assert_eq!(w[a * m + b], w[b * m + a], "face {k}");
                }
            }
            // Energy from the stiffness.
            let value = |v: u32| {
                u(&grid
                    .node_position(v as usize)
                    .unwrap_or_else(|_| Vector3::zeros()))
            };
            let energy: f64 = (0..m)
                .flat_map(|a| (0..m).map(move |b| (a, b)))
                .map(|(a, b)| w[a * m + b] * value(nodes[a]).dot(&value(nodes[b])))
                .sum();
            assert!(energy >= 0.0);
            // The same by quadrature: the face's normal axis is where the
            // first and last layers differ.
            let x0 = grid
                .node_position(nodes[0] as usize)
                .unwrap_or_else(|_| Vector3::zeros());
            let x2 = grid
                .node_position(nodes[m - 1] as usize)
                .unwrap_or_else(|_| Vector3::zeros());
            let axis = (0..3).find(|&i| x2[i] - x0[i] > 1.5 * h[i]).unwrap_or(0);
            let mid = x0[axis] + h[axis];
            let gauss = [0.5 - 0.5 / 3f64.sqrt(), 0.5 + 0.5 / 3f64.sqrt()];
            let others: Vec<usize> = (0..3).filter(|&i| i != axis).collect();
            let mut quad = 0.0;
            for &s in &gauss {
                for &t in &gauss {
                    let mut x = x0;
                    x[axis] = mid;
                    x[others[0]] = x0[others[0]] + s * h[others[0]];
                    x[others[1]] = x0[others[1]] + t * h[others[1]];
                    // The normal derivative of the multilinear interpolant
                    // in the lower and the upper cell by central
                    // differences of each cell's own interpolant.
                    let interp = |lower: f64, y: &Vector3<f64>| -> Vector3<f64> {
                        let mut acc = Vector3::zeros();
                        for corner in 0..8 {
                            let mut node = Vector3::zeros();
                            let mut weight = 1.0;
                            for i in 0..3 {
                                let origin = if i == axis { lower } else { x0[i] };
                                let bit = ((corner >> i) & 1) as f64;
                                node[i] = origin + bit * h[i];
                                let t = (y[i] - origin) / h[i];
                                weight *= if bit > 0.5 { t } else { 1.0 - t };
                            }
                            acc += weight * u(&node);
                        }
                        acc
                    };
                    let e = 1e-6 * h[axis];
                    let (mut lo, mut hi) = (x, x);
                    lo[axis] -= e;
                    hi[axis] += e;
                    let below = (interp(x0[axis], &x) - interp(x0[axis], &lo)) / e;
                    let above = (interp(mid, &hi) - interp(mid, &x)) / e;
                    let area = h[others[0]] * h[others[1]] / 4.0;
                    quad += area * (above - below).norm_squared();
                }
            }
            let expected = 3.0 * h[axis] * quad;
            assert!(
                (energy - expected).abs() <= 1e-6 * expected.max(1e-12),
                "face {k}: {energy} against {expected}"
            );
        }
    }
}
