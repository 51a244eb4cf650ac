//! The plug-point trait for basis functions.

use std::fmt::Debug;

use nalgebra::SVector;

use crate::{BasisError, Stencil};

/// A material point basis: for one material point, the supporting nodes
/// $v$, the values $S_{vp}$ and the gradients
/// $\partial S_{vp}/\partial\tilde X$ with respect to the background mesh
/// coordinates (Coombs et al. 2020, eqs. 2 and 19).
///
/// Implementations write into a [`Stencil`] the caller owns (fenris
/// "populate" style), so the solver's loops over material points allocate
/// nothing. The mesh and the per-point domain are associated types: the
/// four bases of this crate live on [`mpm_mesh::RegularGrid`]; a linear
/// basis on simplex meshes will use its own mesh type.
pub trait BasisFunction<const D: usize>: Send + Sync {
    /// Background mesh the basis lives on.
    type Mesh: Sync;
    /// Per-point domain: `()` for standard MPM and B-splines, the
    /// half-lengths for GIMP, the corners for CPDI2.
    type Domain: Copy + Send + Sync + Debug;
    /// Largest number of supporting nodes of one point.
    const MAX_NODES: usize;
    /// Cells of padding the basis needs between a body and a grid boundary
    /// (the B-spline stencil must stay inside the grid).
    const PADDING: usize = 0;
    /// Half-width of a point's support in cells, per axis (an upper bound
    /// for domain-based bases with domains of at most half a cell).
    const SUPPORT_RADIUS: f64 = 1.0;

    /// The undeformed domain of a point at `position` that represents the
    /// box of half-lengths `half_lengths` around it (`()` for bases without
    /// a domain).
    fn initial_domain(position: &SVector<f64, D>, half_lengths: &SVector<f64, D>) -> Self::Domain;

    /// Clear `out` and write the node ids, values and gradients of the point
    /// at `position` with domain `domain`.
    ///
    /// # Errors
    /// A [`BasisError`] naming the point when it (or its domain or
    /// stencil) cannot be evaluated on `mesh`; `out` is then left empty.
    fn evaluate(
        &self,
        mesh: &Self::Mesh,
        position: &SVector<f64, D>,
        domain: &Self::Domain,
        out: &mut Stencil<D>,
    ) -> Result<(), BasisError>;

    /// Like [`evaluate`](Self::evaluate), with a per-point cell hint: a basis on an unstructured mesh starts its point location (walking, Wang et al. 2021 Algorithm 1) at `*hint` and writes the cell it found there; bases on regular grids ignore it. `usize::MAX` means "no hint".
    ///
    /// # Errors
    /// As [`evaluate`](Self::evaluate).
    fn evaluate_hinted(
        &self,
        mesh: &Self::Mesh,
        position: &SVector<f64, D>,
        domain: &Self::Domain,
        hint: &mut usize,
        out: &mut Stencil<D>,
    ) -> Result<(), BasisError> {
        let _ = hint;
        self.evaluate(mesh, position, domain, out)
    }

    /// Calls `visit(node, value, gradient)` for every supporting node of
    /// the point at `position`, as [`evaluate`](Self::evaluate) would list
    /// them. The default evaluates into `scratch` and walks it; bases with
    /// a cheaper direct form (the tensor-product bases of this crate)
    /// override it and leave `scratch` untouched, so a solver that only
    /// streams over the nodes (the explicit point-to-grid and grid-to-point
    /// stages) never stores a stencil.
    ///
    /// # Errors
    /// As [`evaluate`](Self::evaluate); nothing is visited then.
    #[inline]
    fn for_each_node(
        &self,
        mesh: &Self::Mesh,
        position: &SVector<f64, D>,
        domain: &Self::Domain,
        scratch: &mut Stencil<D>,
        mut visit: impl FnMut(usize, f64, &SVector<f64, D>),
    ) -> Result<(), BasisError> {
        self.evaluate(mesh, position, domain, scratch)?;
        for ((&node, &value), gradient) in scratch
            .nodes
            .iter()
            .zip(&scratch.values)
            .zip(&scratch.gradients)
        {
            visit(node, value, gradient);
        }
        Ok(())
    }

    /// For a tensor-product basis on a regular grid: the per-axis factors
    /// of the point at `position`, whose products are exactly the stencil
    /// [`evaluate`](Self::evaluate) lists (up to nodes whose product is
    /// zero in value and gradient). `None` (the default) when the basis
    /// has no such structure; a solver then uses
    /// [`for_each_node`](Self::for_each_node).
    ///
    /// # Errors
    /// As [`evaluate`](Self::evaluate), inside the `Some`.
    #[inline]
    fn tensor_factors(
        &self,
        mesh: &Self::Mesh,
        position: &SVector<f64, D>,
        domain: &Self::Domain,
    ) -> Option<Result<crate::TensorFactors<D>, BasisError>> {
        let _ = (mesh, position, domain);
        None
    }

    /// An empty stencil with room for [`BasisFunction::MAX_NODES`] nodes.
    fn new_stencil(&self) -> Stencil<D> {
        Stencil::with_capacity(Self::MAX_NODES)
    }
}
