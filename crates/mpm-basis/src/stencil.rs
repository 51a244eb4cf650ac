//! The caller-owned output buffer of a basis evaluation.

use nalgebra::SVector;

use crate::BasisFunction;

/// Supporting nodes of one material point with the basis values $S_{vp}$ and
/// gradients $\partial S_{vp}/\partial \tilde X$ (with respect to the mesh
/// coordinates), as three parallel arrays.
///
/// The caller creates one stencil per thread with room for
/// [`BasisFunction::MAX_NODES`] entries ([`Stencil::for_basis`]) and reuses
/// it for every point: [`BasisFunction::evaluate`] clears it and pushes at
/// most `MAX_NODES` entries, so nothing allocates per material point.
///
/// Invariants kept by every implementation in this crate: the three arrays
/// have the same length, each node id appears at most once, and entries
/// whose value and gradient are both zero are omitted.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stencil<const D: usize> {
    /// Node ids.
    pub nodes: Vec<usize>,
    /// Basis values $S_{vp}$, one per node.
    pub values: Vec<f64>,
    /// Basis gradients $\partial S_{vp}/\partial \tilde X$, one per node.
    pub gradients: Vec<SVector<f64, D>>,
}

impl<const D: usize> Stencil<D> {
    /// An empty stencil with room for `capacity` nodes.
    pub fn with_capacity(capacity: usize) -> Self {
        Self {
            nodes: Vec::with_capacity(capacity),
            values: Vec::with_capacity(capacity),
            gradients: Vec::with_capacity(capacity),
        }
    }

    /// An empty stencil with room for the largest stencil of basis `B`.
    pub fn for_basis<B: BasisFunction<D>>() -> Self {
        Self::with_capacity(B::MAX_NODES)
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the stencil has no nodes.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Remove all entries, keeping the capacity.
    #[inline]
    pub fn clear(&mut self) {
        self.nodes.clear();
        self.values.clear();
        self.gradients.clear();
    }

    /// Append an entry (the caller keeps node ids unique).
    #[inline]
    pub fn push(&mut self, node: usize, value: f64, gradient: SVector<f64, D>) {
        self.nodes.push(node);
        self.values.push(value);
        self.gradients.push(gradient);
    }

    /// Add `value` and `gradient` to the entry of `node`, appending it if
    /// absent (a linear search: stencils are small).
    pub fn accumulate(&mut self, node: usize, value: f64, gradient: SVector<f64, D>) {
        match self.position(node) {
            Some(i) => {
                self.values[i] += value;
                self.gradients[i] += gradient;
            }
            None => self.push(node, value, gradient),
        }
    }

    /// Index of `node` in the stencil, if present.
    pub fn position(&self, node: usize) -> Option<usize> {
        self.nodes.iter().position(|&n| n == node)
    }

    /// Iterate over `(node, value, gradient)`.
    pub fn iter(&self) -> impl Iterator<Item = (usize, f64, &SVector<f64, D>)> {
        self.nodes
            .iter()
            .zip(&self.values)
            .zip(&self.gradients)
            .map(|((&n, &v), g)| (n, v, g))
    }
}
