//! Moving-mesh Dirichlet boundary conditions (Beuth 2012, as used by Wang
//! et al. 2021 §2.2 and §5): the background mesh moves so that its boundary
//! follows the imposed displacement, so that a displacement condition can
//! be applied on mesh nodes that stay on the body's boundary.
//!
//! A [`MeshMotion`] gives the position of every mesh node as a function of
//! the load factor, $\mathbf x_v(\lambda) = \Phi(v, \mathbf X_v, \lambda)$
//! with $\mathbf X_v$ the node's initial position, so that the mesh of any
//! load factor is known without history (a resumed run restores it from the
//! load factor alone). [`MovingMesh`] wraps the other conditions: at the
//! start of every step it moves the mesh to the step's initial load factor,
//! and it prescribes, on the driven nodes and components, the increment
//! $\Phi(v, \mathbf X_v, \lambda_1) - \Phi(v, \mathbf X_v, \lambda_0)$, so
//! that the material boundary and the mesh boundary move together.

use nalgebra::{SMatrix, SVector};

use crate::boundary::{Constraints, StepView};
use crate::error::MeshMotionError;
use crate::mesh::MovableMesh;

/// Node positions as a function of the load factor.
pub trait MeshMotion<const D: usize>: Send + Sync {
    /// Position at load factor `lambda` of node `node` whose initial
    /// position is `x0`.
    fn position(&self, node: usize, x0: &SVector<f64, D>, lambda: f64) -> SVector<f64, D>;
}

/// Uniform stretch along one axis: the coordinate $x_a$ measured from
/// `origin` scales with the length $L(\lambda) = L_0 + \lambda\,\Delta L$,
/// $x_a(\lambda) = o + (X_a - o)\,L(\lambda)/L_0$; the other coordinates do
/// not move (Wang 2021 §5.3: "simply stretched the mesh along the y-axis").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stretch {
    /// The stretched axis.
    pub axis: usize,
    /// Coordinate of the fixed plane.
    pub origin: f64,
    /// Initial length $L_0$ (from the fixed plane to the driven face).
    pub length: f64,
    /// Extension $\Delta L$ at load factor 1.
    pub extension: f64,
}

impl<const D: usize> MeshMotion<D> for Stretch {
    fn position(&self, _node: usize, x0: &SVector<f64, D>, lambda: f64) -> SVector<f64, D> {
        let mut x = *x0;
        if self.axis < D {
            let ratio = (self.length + lambda * self.extension) / self.length;
            x[self.axis] = self.origin + (x0[self.axis] - self.origin) * ratio;
        }
        x
    }
}

/// Rigid rotation about a centre (2D) or an axis through a centre (3D) by
/// the angle $\lambda\,\Theta$ (Wang 2021 §5.5: "rotate the whole mesh with
/// the vane"). With $\mathbf K$ the generator ($\mathbf K\mathbf v = \hat{\mathbf n}\times\mathbf v$
/// in 3D, a quarter turn in 2D), $\mathbf R(\varphi) = \mathbf I +
/// \sin\varphi\,\mathbf K + (1-\cos\varphi)\,\mathbf K^2$ (Rodrigues; in 2D
/// $\mathbf K^2 = -\mathbf I$ and this is the plane rotation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotation<const D: usize> {
    /// Centre of rotation (a point on the axis in 3D).
    pub centre: SVector<f64, D>,
    /// The generator $\mathbf K$.
    generator: SMatrix<f64, D, D>,
    /// Total angle $\Theta$ at load factor 1 (radians).
    pub angle: f64,
}

impl Rotation<2> {
    /// Counter-clockwise rotation about `centre`.
    pub fn planar(centre: SVector<f64, 2>, angle: f64) -> Self {
        Self {
            centre,
            generator: SMatrix::<f64, 2, 2>::new(0.0, -1.0, 1.0, 0.0),
            angle,
        }
    }
}

impl Rotation<3> {
    /// Right-handed rotation about the axis through `centre` along `axis`
    /// (normalised here); `None` for a zero or non-finite axis.
    pub fn about_axis(centre: SVector<f64, 3>, axis: SVector<f64, 3>, angle: f64) -> Option<Self> {
        let n = axis.try_normalize(1e-300)?;
        Some(Self {
            centre,
            generator: n.cross_matrix(),
            angle,
        })
    }
}

impl<const D: usize> Rotation<D> {
    /// Right-handed rotation about the coordinate axis `axis` through
    /// `centre`: $K_{ik} = \varepsilon_{i\,a\,k}$ with $a$ the axis, which in
    /// 2D (`axis` = 2, the out-of-plane axis) is the counter-clockwise plane
    /// rotation. `None` unless `axis` < 3 in 3D or `axis` = 2 in 2D.
    pub fn about_coordinate_axis(centre: SVector<f64, D>, axis: usize, angle: f64) -> Option<Self> {
        let valid = match D {
            2 => axis == 2,
            3 => axis < 3,
            _ => false,
        };
        if !valid {
            return None;
        }
        let levi_civita = |i: usize, j: usize, k: usize| -> f64 {
            // (i, j, k) a permutation of (0, 1, 2): its sign; else 0.
            if i == j || j == k || i == k {
                0.0
            } else if (i + 1) % 3 == j {
                1.0
            } else {
                -1.0
            }
        };
        Some(Self {
            centre,
            generator: SMatrix::<f64, D, D>::from_fn(|i, k| levi_civita(i, axis, k)),
            angle,
        })
    }

    /// $\mathbf R(\varphi)$.
    pub fn matrix(&self, phi: f64) -> SMatrix<f64, D, D> {
        let k = &self.generator;
        SMatrix::<f64, D, D>::identity() + k * phi.sin() + k * k * (1.0 - phi.cos())
    }
}

impl<const D: usize> MeshMotion<D> for Rotation<D> {
    fn position(&self, _node: usize, x0: &SVector<f64, D>, lambda: f64) -> SVector<f64, D> {
        self.centre + self.matrix(lambda * self.angle) * (x0 - self.centre)
    }
}

/// Translation of a driven node set by $\lambda\,\mathbf d$ with the rest of
/// the mesh interpolated: node $v$ moves by $w_v\lambda\mathbf d$ with
/// $w_v = \delta^0_v/(\delta^0_v + \delta^1_v)$, where $\delta^1_v$ and
/// $\delta^0_v$ are its distances to the nearest node of the driven set
/// and of a fixed set ($w = 1$ on the driven set, 0 on the fixed set,
/// linear in between for parallel faces: the compressed mesh below a
/// footing of Wang 2021 §5.2).
#[derive(Debug, Clone, PartialEq)]
pub struct Translation<const D: usize> {
    /// Total translation $\mathbf d$ at load factor 1.
    pub displacement: SVector<f64, D>,
    weights: Vec<f64>,
}

impl<const D: usize> Translation<D> {
    /// The weights for nodes at `nodes` with the driven and fixed node
    /// sets; `None` if either set is empty, they share a node, or a node
    /// id is out of range.
    pub fn new(
        nodes: &[SVector<f64, D>],
        driven: &[usize],
        fixed: &[usize],
        displacement: SVector<f64, D>,
    ) -> Option<Self> {
        if driven.is_empty()
            || fixed.is_empty()
            || driven.iter().chain(fixed).any(|&v| v >= nodes.len())
            || driven.iter().any(|v| fixed.contains(v))
        {
            return None;
        }
        let nearest = |x: &SVector<f64, D>, set: &[usize]| {
            set.iter()
                .map(|&v| (nodes[v] - x).norm())
                .fold(f64::INFINITY, f64::min)
        };
        let weights = nodes
            .iter()
            .map(|x| {
                let (d1, d0) = (nearest(x, driven), nearest(x, fixed));
                d0 / (d0 + d1)
            })
            .collect();
        Some(Self {
            displacement,
            weights,
        })
    }

    /// The interpolation weight of every node.
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }
}

impl<const D: usize> MeshMotion<D> for Translation<D> {
    fn position(&self, node: usize, x0: &SVector<f64, D>, lambda: f64) -> SVector<f64, D> {
        x0 + self.displacement * (lambda * self.weights.get(node).copied().unwrap_or(0.0))
    }
}

/// Dirichlet conditions `C` on a mesh that moves with `motion`: the
/// `driven` nodes have their `components` prescribed to follow the mesh
/// (see the module docs); every other condition comes from `inner`.
#[derive(Debug, Clone)]
pub struct MovingMesh<const D: usize, C, M> {
    /// The other conditions (rollers, supports).
    pub inner: C,
    /// The mesh motion.
    pub motion: M,
    initial: Vec<SVector<f64, D>>,
    driven: Vec<bool>,
    components: [bool; D],
    at: Option<f64>,
}

impl<const D: usize, C, M: MeshMotion<D>> MovingMesh<D, C, M> {
    /// Conditions on the mesh whose initial node positions are `initial`;
    /// nodes in `driven` follow the motion in the components marked in
    /// `components`.
    pub fn new(
        inner: C,
        motion: M,
        initial: Vec<SVector<f64, D>>,
        driven: &[usize],
        components: [bool; D],
    ) -> Self {
        let mut flags = vec![false; initial.len()];
        for &v in driven {
            if let Some(f) = flags.get_mut(v) {
                *f = true;
            }
        }
        Self {
            inner,
            motion,
            initial,
            driven: flags,
            components,
            at: None,
        }
    }

    /// Node positions at load factor `lambda`.
    pub fn positions(&self, lambda: f64) -> Vec<SVector<f64, D>> {
        self.initial
            .iter()
            .enumerate()
            .map(|(v, x0)| self.motion.position(v, x0, lambda))
            .collect()
    }
}

impl<const D: usize, C: Constraints<D>, M: MeshMotion<D>> Constraints<D> for MovingMesh<D, C, M> {
    const MOVES_MESH: bool = true;

    fn begin_step(&mut self, step: &StepView<'_, D>) {
        self.inner.begin_step(step);
    }

    fn prescribed(&self, node: usize, component: usize, lambda0: f64, lambda1: f64) -> Option<f64> {
        if self.driven.get(node).copied().unwrap_or(false) && self.components[component] {
            let x0 = &self.initial[node];
            let (a, b) = (
                self.motion.position(node, x0, lambda0),
                self.motion.position(node, x0, lambda1),
            );
            return Some(b[component] - a[component]);
        }
        self.inner.prescribed(node, component, lambda0, lambda1)
    }

    fn tools(&self) -> &[crate::contact::RigidTool<D>] {
        self.inner.tools()
    }

    fn tool_increment(&self, tool: usize, lambda0: f64, lambda1: f64) -> SVector<f64, D> {
        self.inner.tool_increment(tool, lambda0, lambda1)
    }

    fn move_mesh<Mesh: MovableMesh<D>>(
        &mut self,
        mesh: &mut Mesh,
        lambda: f64,
    ) -> Result<(), MeshMotionError> {
        if self.at == Some(lambda) {
            return Ok(());
        }
        if self.initial.len() != mesh.node_count() {
            return Err(MeshMotionError::NodeCount {
                got: self.initial.len(),
                expected: mesh.node_count(),
            });
        }
        mesh.move_nodes(self.positions(lambda))?;
        self.at = Some(lambda);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::NodalConstraints;
    use mpm_mesh::{BoxMesh, RegularGrid};
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn coordinate_axis_rotations_match_the_explicit_constructors() {
        let c2 = Vector2::new(0.3, -0.2);
        let r2 = Rotation::<2>::about_coordinate_axis(c2, 2, 0.7).expect("z in 2D");
        assert_eq!(r2, Rotation::planar(c2, 0.7));
        let c3 = Vector3::new(0.1, 0.2, 0.3);
        for axis in 0..3 {
            let r = Rotation::<3>::about_coordinate_axis(c3, axis, -0.4).expect("axis < 3");
            let expected = Rotation::about_axis(
                c3,
                Vector3::from_fn(|i, _| f64::from(u8::from(i == axis))),
                -0.4,
            )
            .expect("a unit axis");
            assert!((r.matrix(0.9) - expected.matrix(0.9)).norm() < 1e-15);
            // Right-handed: a quarter turn about z takes x to y.
        }
        let z = Rotation::<3>::about_coordinate_axis(Vector3::zeros(), 2, 1.0).expect("z");
        let y = z.matrix(std::f64::consts::FRAC_PI_2) * Vector3::x();
        assert!((y - Vector3::y()).norm() < 1e-15);
        assert!(Rotation::<2>::about_coordinate_axis(c2, 0, 1.0).is_none());
        assert!(Rotation::<3>::about_coordinate_axis(c3, 3, 1.0).is_none());
    }

    #[test]
    fn motions_are_functions_of_the_load_factor() {
        let s = Stretch {
            axis: 1,
            origin: 0.0,
            length: 2.0,
            extension: 6.8,
        };
        let x = MeshMotion::<3>::position(&s, 0, &Vector3::new(0.5, 2.0, 1.0), 0.5);
        assert_eq!(x, Vector3::new(0.5, 5.4, 1.0));
        let r =
            Rotation::about_axis(Vector3::zeros(), Vector3::new(0.0, 0.0, 2.0), 1.0).expect("axis");
        let y = r.position(0, &Vector3::new(1.0, 0.0, 3.0), std::f64::consts::FRAC_PI_2);
        assert!((y - Vector3::new(0.0, 1.0, 3.0)).norm() < 1e-15);
        assert!((r.matrix(0.7).determinant() - 1.0).abs() < 1e-15);
        let p = Rotation::planar(Vector2::new(1.0, 1.0), std::f64::consts::PI);
        assert!(
            (p.position(0, &Vector2::new(2.0, 1.0), 1.0) - Vector2::new(0.0, 1.0)).norm() < 1e-15
        );
        assert!(Rotation::about_axis(Vector3::zeros(), Vector3::zeros(), 1.0).is_none());
    }

    #[test]
    fn translation_weights_are_linear_between_parallel_faces() {
        let mesh = BoxMesh::new(Vector2::zeros(), Vector2::new(1.0, 2.0), [2, 8])
            .simplex_mesh()
            .expect("mesh");
        let nodes = mesh.nodes();
        let set = |y: f64| -> Vec<usize> {
            (0..nodes.len())
                .filter(|&v| (nodes[v][1] - y).abs() < 1e-12)
                .collect()
        };
        let t =
            Translation::new(nodes, &set(2.0), &set(0.0), Vector2::new(0.0, -0.5)).expect("sets");
        for (x, w) in nodes.iter().zip(t.weights()) {
            assert!((w - x[1] / 2.0).abs() < 1e-14, "{x:?}: {w}");
        }
        assert!(Translation::new(nodes, &set(2.0), &set(2.0), Vector2::zeros()).is_none());
        assert!(Translation::new(nodes, &[], &set(0.0), Vector2::zeros()).is_none());
    }

    #[test]
    fn moving_mesh_prescribes_the_mesh_increment_on_driven_components_only() {
        let mut mesh = BoxMesh::new(Vector3::zeros(), Vector3::new(2.0, 2.0, 2.0), [2, 2, 2])
            .simplex_mesh()
            .expect("mesh");
        let top: Vec<usize> = (0..mesh.node_count())
            .filter(|&v| mesh.nodes()[v][1] > 2.0 - 1e-12)
            .collect();
        let mut rollers = NodalConstraints::<3>::new(mesh.node_count());
        rollers.fix(0..mesh.node_count(), 0);
        let stretch = Stretch {
            axis: 1,
            origin: 0.0,
            length: 2.0,
            extension: 2.0,
        };
        let mut c = MovingMesh::new(
            rollers,
            stretch,
            mesh.nodes().to_vec(),
            &top,
            [false, true, false],
        );
        let v = top[0];
        let dy = c.prescribed(v, 1, 0.2, 0.6).expect("driven");
        assert!((dy - 0.8).abs() < 1e-15, "{dy}");
        assert_eq!(c.prescribed(v, 0, 0.2, 0.6), Some(0.0)); // the roller
        assert_eq!(c.prescribed(v, 2, 0.2, 0.6), None);
        c.move_mesh(&mut mesh, 0.5).expect("move");
        assert!((mesh.total_volume() - 12.0).abs() < 1e-12);
        c.move_mesh(&mut mesh, 0.0).expect("back");
        assert!((mesh.total_volume() - 8.0).abs() < 1e-12);
    }

    #[test]
    fn a_regular_grid_moves_only_along_its_axes() {
        let mut grid =
            RegularGrid::new(Vector2::zeros(), Vector2::new(0.5, 0.25), [4, 8]).expect("grid");
        let nodes: Vec<_> = (0..grid.node_count())
            .map(|v| MovableMesh::node_position(&grid, v))
            .collect();
        let stretched: Vec<_> = nodes
            .iter()
            .map(|x| Vector2::new(x[0] + 1.0, 3.0 * x[1]))
            .collect();
        MovableMesh::move_nodes(&mut grid, stretched).expect("stretch");
        assert_eq!(grid.spacing(), &Vector2::new(0.5, 0.75));
        assert_eq!(grid.origin(), &Vector2::new(1.0, 0.0));
        let r = Rotation::planar(Vector2::zeros(), 0.1);
        let rotated: Vec<_> = nodes
            .iter()
            .enumerate()
            .map(|(v, x)| r.position(v, x, 1.0))
            .collect();
        let before = grid.clone();
        assert!(MovableMesh::move_nodes(&mut grid, rotated).is_err());
        assert_eq!(grid, before);
    }
}
