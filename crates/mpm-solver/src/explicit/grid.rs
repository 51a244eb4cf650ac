//! The grid state shared by the stages of an explicit step: the nodal sums
//! that point-to-grid accumulates ([`NodeSums`], [`GridBuffer`]), the
//! nodal velocities of the grid update ([`GridState`]) and the fields
//! grid-to-point interpolates ([`Gathered`]). The stage files and the
//! Taylor terms (`tensor`) read them from here, so no stage depends on
//! another for its types.

use nalgebra::{SMatrix, SVector};

/// The sums of one node, stored together so that a point's update of a
/// node touches one cache line rather than three.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeSums<const D: usize> {
    /// $m_i$ (eq. 28).
    pub mass: f64,
    /// $p_i = m_i v_i$ (eq. 29).
    pub momentum: SVector<f64, D>,
    /// $f^{ext}_i + f^{int}_i$ (eqs. 20–21).
    pub force: SVector<f64, D>,
}

impl<const D: usize> NodeSums<D> {
    /// Adds one point's share at a node of weight `w` and gradient `g`
    /// (eqs. 20–22, 28–29): mass $w m_p$, momentum $w m_p$ times the
    /// velocity the point carries to the node, force $w\,m_p\mathbf g -
    /// V^0_p\tau_p\nabla w$ (`body` $= m_p\mathbf g$, `stress` $=
    /// V^0_p\tau_p$).
    #[inline(always)]
    pub fn add_point(
        &mut self,
        (w, g): (f64, &SVector<f64, D>),
        mass: f64,
        carried: &SVector<f64, D>,
        body: &SVector<f64, D>,
        stress: &SMatrix<f64, D, D>,
    ) {
        let wm = w * mass;
        self.mass += wm;
        self.momentum += carried * wm;
        self.force += body * w - stress * g;
    }

    /// Nothing.
    pub const ZERO: Self = Self {
        mass: 0.0,
        momentum: SVector::from_array_storage(nalgebra::ArrayStorage([[0.0; D]; 1])),
        force: SVector::from_array_storage(nalgebra::ArrayStorage([[0.0; D]; 1])),
    };
}

/// Nodal sums of one thread's points. The array spans the whole mesh; only
/// `lo..hi`, the nodes touched since the last [`GridBuffer::clear`], can be
/// non-zero, so a thread whose points are spatially coherent clears and
/// reduces little more than its share of the grid.
#[derive(Debug, Clone)]
pub struct GridBuffer<const D: usize> {
    /// The sums per node.
    pub nodes: Vec<NodeSums<D>>,
    /// First touched node.
    pub lo: usize,
    /// One past the last touched node.
    pub hi: usize,
}

impl<const D: usize> GridBuffer<D> {
    /// Zeroed sums for `nodes` nodes.
    pub fn new(nodes: usize) -> Self {
        Self {
            nodes: vec![NodeSums::ZERO; nodes],
            lo: usize::MAX,
            hi: 0,
        }
    }

    /// Zeroes the touched range.
    pub fn clear(&mut self) {
        if self.lo < self.hi {
            self.nodes[self.lo..self.hi].fill(NodeSums::ZERO);
        }
        self.lo = usize::MAX;
        self.hi = 0;
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the buffer has no nodes.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }
}

/// The velocities of one node, stored together (one cache line per node
/// read by the grid-to-point stage).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeVelocity<const D: usize> {
    /// $v^n_i$.
    pub old: SVector<f64, D>,
    /// $\tilde v^{n+1}_i$.
    pub new: SVector<f64, D>,
}

impl<const D: usize> Default for NodeVelocity<D> {
    fn default() -> Self {
        Self {
            old: SVector::zeros(),
            new: SVector::zeros(),
        }
    }
}

/// The grid velocities of a step: $v^n_i = p_i/m_i$ (eq. 30) and
/// $\tilde v^{n+1}_i = v^n_i + \Delta t\,(f^{ext}_i + f^{int}_i)/m_i$ (eqs.
/// 31–32). Entries outside `lo..hi` are stale and never read.
#[derive(Debug, Clone, Default)]
pub struct GridState<const D: usize> {
    /// Lumped mass $m_i$.
    pub mass: Vec<f64>,
    /// The velocities.
    pub velocity: Vec<NodeVelocity<D>>,
    /// First node with mass.
    pub lo: usize,
    /// One past the last node with mass.
    pub hi: usize,
}

impl<const D: usize> GridState<D> {
    /// A grid of `nodes` nodes.
    pub fn new(nodes: usize) -> Self {
        Self {
            mass: vec![0.0; nodes],
            velocity: vec![NodeVelocity::default(); nodes],
            lo: 0,
            hi: 0,
        }
    }

    /// The nodal acceleration $a_i = (\tilde v^{n+1}_i - v^n_i)/\Delta t$,
    /// which after the fixities is the recomputed one of the notes.
    pub fn acceleration(&self, node: usize, dt: f64) -> SVector<f64, D> {
        (self.velocity[node].new - self.velocity[node].old) / dt
    }
}

/// The grid fields interpolated at a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gathered<const D: usize> {
    /// $\sum_i w_{ip}\tilde v^{n+1}_i$.
    pub new_velocity: SVector<f64, D>,
    /// $\sum_i w_{ip}v^n_i$.
    pub old_velocity: SVector<f64, D>,
    /// $\nabla v_p = \sum_i \tilde v^{n+1}_i\otimes\nabla w_{ip}$ (eq. 38).
    pub grad: SMatrix<f64, D, D>,
}

/// Adds the contribution of node `i` with weight `w` and weight gradient
/// `dw` to the interpolated fields.
#[inline(always)]
pub fn gather_node<const D: usize>(
    g: &mut Gathered<D>,
    grid: &GridState<D>,
    i: usize,
    w: f64,
    dw: &SVector<f64, D>,
) {
    let node = &grid.velocity[i];
    g.new_velocity += node.new * w;
    g.old_velocity += node.old * w;
    g.grad += node.new * dw.transpose();
}

impl<const D: usize> Default for Gathered<D> {
    fn default() -> Self {
        Self {
            new_velocity: SVector::zeros(),
            old_velocity: SVector::zeros(),
            grad: SMatrix::zeros(),
        }
    }
}
