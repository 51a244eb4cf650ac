//! Dirichlet conditions on grid nodes (Coombs 2020 §6.2: imposed directly
//! on the background mesh as in the finite element method).

use nalgebra::SVector;

use crate::contact::RigidTool;
use crate::error::MeshMotionError;
use crate::mesh::MovableMesh;

/// Prescribed displacement increments of grid degrees of freedom.
pub trait Constraints<const D: usize>: Send + Sync {
    /// Whether [`Constraints::move_mesh`] moves the mesh (outputs then
    /// record its node positions every step).
    const MOVES_MESH: bool = false;

    /// Whether these conditions move the mesh: [`Constraints::MOVES_MESH`]
    /// unless the type decides at run time (a scene with or without a
    /// mesh motion).
    fn moves_mesh(&self) -> bool {
        Self::MOVES_MESH
    }

    /// Called at the start of every load step attempt, after the basis
    /// has been evaluated, for conditions that follow the body (e.g. every
    /// node supporting a boundary point). The default does nothing.
    fn begin_step(&mut self, _step: &StepView<'_, D>) {}

    /// The prescribed displacement increment of component `component` of
    /// mesh node `node` over the load step from load factor `lambda0` to
    /// `lambda1`, or `None` if the degree of freedom is free.
    fn prescribed(&self, node: usize, component: usize, lambda0: f64, lambda1: f64) -> Option<f64>;

    /// The rigid tools whose nodes are in frictional contact with them
    /// (implicit solver; [`crate::contact`]). The default: none.
    fn tools(&self) -> &[RigidTool<D>] {
        &[]
    }

    /// The displacement increment of tool `tool` (an index into
    /// [`Constraints::tools`]) over the load step from `lambda0` to
    /// `lambda1`. The default: at rest.
    fn tool_increment(&self, _tool: usize, _lambda0: f64, _lambda1: f64) -> SVector<f64, D> {
        SVector::zeros()
    }

    /// Brings the background mesh to its position at load factor `lambda`
    /// (called at the start of every step attempt with the step's initial
    /// load factor). Fixed meshes do nothing (the default); see
    /// [`crate::MovingMesh`].
    ///
    /// # Errors
    /// A message when the mesh cannot take that position.
    fn move_mesh<M: MovableMesh<D>>(
        &mut self,
        _mesh: &mut M,
        _lambda: f64,
    ) -> Result<(), MeshMotionError> {
        Ok(())
    }
}

/// What [`Constraints::begin_step`] may read: the material point positions
/// and the mesh nodes of every point's stencil at the start of the step.
#[derive(Debug, Clone, Copy)]
pub struct StepView<'a, const D: usize> {
    positions: &'a [SVector<f64, D>],
    nodes: &'a [u32],
    counts: &'a [u32],
    stride: usize,
}

impl<'a, const D: usize> StepView<'a, D> {
    /// A view of `positions` and the stencils stored `stride` slots per
    /// point in `nodes` (mesh node ids), `counts[p]` of them used.
    pub fn new(
        positions: &'a [SVector<f64, D>],
        nodes: &'a [u32],
        counts: &'a [u32],
        stride: usize,
    ) -> Self {
        Self {
            positions,
            nodes,
            counts,
            stride,
        }
    }

    /// Material point positions at the start of the step.
    pub fn positions(&self) -> &'a [SVector<f64, D>] {
        self.positions
    }

    /// Mesh nodes supporting point `p` (its basis stencil).
    pub fn nodes_of(&self, p: usize) -> impl Iterator<Item = usize> + 'a {
        let start = p * self.stride;
        let count = self.counts.get(p).copied().unwrap_or(0) as usize;
        self.nodes[start..start + count].iter().map(|&v| v as usize)
    }
}

/// Fixed and prescribed degrees of freedom listed per node: fixed nodes
/// (supports, rollers) have zero increments, prescribed ones move linearly
/// with the load factor, reaching their value at load factor 1.
#[derive(Debug, Clone)]
pub struct NodalConstraints<const D: usize> {
    total: Vec<Option<f64>>,
}

impl<const D: usize> NodalConstraints<D> {
    /// No constraints on a mesh of `node_count` nodes.
    pub fn new(node_count: usize) -> Self {
        Self {
            total: vec![None; node_count * D],
        }
    }

    /// Fixes component `component` of every node in `nodes` (a roller on a
    /// face fixes the normal component; a pin fixes all).
    pub fn fix(&mut self, nodes: impl IntoIterator<Item = usize>, component: usize) -> &mut Self {
        self.prescribe(nodes, component, 0.0)
    }

    /// Prescribes component `component` of every node in `nodes` to reach
    /// `displacement` at load factor 1. Out-of-range nodes are ignored.
    pub fn prescribe(
        &mut self,
        nodes: impl IntoIterator<Item = usize>,
        component: usize,
        displacement: f64,
    ) -> &mut Self {
        if component < D {
            for n in nodes {
                if let Some(slot) = self.total.get_mut(n * D + component) {
                    *slot = Some(displacement);
                }
            }
        }
        self
    }

    /// Number of constrained degrees of freedom.
    pub fn len(&self) -> usize {
        self.total.iter().filter(|v| v.is_some()).count()
    }

    /// Whether nothing is constrained.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl<const D: usize> Constraints<D> for NodalConstraints<D> {
    #[inline]
    fn prescribed(&self, node: usize, component: usize, lambda0: f64, lambda1: f64) -> Option<f64> {
        self.total
            .get(node * D + component)
            .copied()
            .flatten()
            .map(|u| u * (lambda1 - lambda0))
    }
}
