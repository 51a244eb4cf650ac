//! The `LockingTreatment` plug point: which material points share a
//! volumetric deformation.
//!
//! Standard MPM gives every point its own $\Delta F_p$ (Coombs et al. 2020
//! eq. 7). The treatments here replace its volumetric part with an average
//! over a *patch* of points (Wang et al. 2021 eq. 9):
//!
//! $$\Delta\bar F_p = \Big(\frac{\Delta\bar J_P}{\det\Delta F_p}\Big)^{1/n_D}\Delta F_p,
//! \qquad \Delta\bar J_P = \frac{\sum_{q\in P} w_q\det\Delta F_q}{\sum_{q\in P} w_q},$$
//!
//! with the in-plane block scaled in plane strain ($\Delta\bar F_{33} = 1$).
//! A treatment only says, at the start of every load step, which patch each
//! point belongs to and with which weight $w_q$ it enters the average
//! ([`LockingTreatment::assign`]); the kinematics, the consistent
//! linearisation and the wider sparsity pattern are common to all of them
//! and live in [`crate::stages::patch`] (derivation:
//! `docs/src/theory/locking.md`). So a new treatment (a cell-averaged
//! dilatation for the explicit solver, patches of another shape) is a new
//! `assign`, and the solver assembles it without a special case.
//!
//! | treatment | mesh | patch | weight $w_q$ |
//! |---|---|---|---|
//! | [`NoLocking`] | any | — | — |
//! | [`FBar`] | regular grid | a block of `cells_per_patch`$^D$ cells (Coombs et al. 2018) | $V^n_q$ |
//! | [`FPatch`] | linear simplices split from tri6/tet10 parents | the parent (Wang et al. 2021 §4.1) | $V_e/n_e$ |
//!
//! For F-patch the weight $V_e/n_e$ — the volume of the point's element
//! shared among the $n_e$ points in it — makes the average the paper's
//! $v_{patch}/\tilde V_{patch}$ over the patch's *active* elements (Fig.
//! 3B): on linear simplices $\Delta F$ is constant in an element.

use std::sync::Arc;

use mpm_mesh::{PatchMesh, RegularGrid, SimplexMesh};
use nalgebra::SVector;

use crate::error::LockingError;

/// The patch of every point and its averaging weight, written by
/// [`LockingTreatment::assign`] (buffers keep their capacity).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PatchAssignment {
    /// Patch id of every point (any numbering; the solver compacts it).
    pub patch: Vec<u32>,
    /// Weight of every point in its patch's average (positive).
    pub weight: Vec<f64>,
}

/// What a treatment sees at the start of a load step.
#[derive(Debug, Clone, Copy)]
pub struct PatchInput<'a, const D: usize> {
    /// Point positions at the start of the step.
    pub position: &'a [SVector<f64, D>],
    /// Per point, the cell the basis located it in (unstructured meshes;
    /// `usize::MAX` on regular grids).
    pub cells: &'a [usize],
    /// Converged point volumes $V^n_p$.
    pub volume: &'a [f64],
}

/// Which points share a volumetric deformation (module docs), on
/// background meshes of type `M`.
pub trait LockingTreatment<const D: usize, M>: Send + Sync {
    /// Name used in outputs (`none`, `fbar`, `fpatch`).
    const NAME: &'static str;
    /// Whether points of this type may be coupled through patches: the
    /// value of [`Self::couples_points`] for every value of a typed
    /// treatment (an upper bound for one chosen at run time).
    const COUPLES_POINTS: bool;

    /// Whether this treatment couples points through patches. When false
    /// the solver never calls [`Self::assign`] and runs standard MPM's
    /// kernels. A typed treatment answers its constant (the branch folds
    /// away); a treatment chosen at run time (`Option<K>`) answers per
    /// value, once per stage.
    #[inline(always)]
    fn couples_points(&self) -> bool {
        Self::COUPLES_POINTS
    }

    /// Writes the patch and weight of every point at the start of a load
    /// step into `out` (resized to the number of points).
    ///
    /// # Errors
    /// A [`LockingError`] naming a point that cannot be placed in a patch.
    fn assign(
        &mut self,
        mesh: &M,
        input: PatchInput<'_, D>,
        out: &mut PatchAssignment,
    ) -> Result<(), LockingError>;
}

/// No treatment: standard MPM, each point uses its own $\Delta F$.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoLocking;

impl<const D: usize, M> LockingTreatment<D, M> for NoLocking {
    const NAME: &'static str = "none";
    const COUPLES_POINTS: bool = false;

    fn assign(
        &mut self,
        _mesh: &M,
        _input: PatchInput<'_, D>,
        out: &mut PatchAssignment,
    ) -> Result<(), LockingError> {
        out.patch.clear();
        out.weight.clear();
        Ok(())
    }
}

/// A treatment chosen at run time: `None` is standard MPM
/// ([`NoLocking`]), `Some(k)` is `k`. The scene runner compiles one
/// solver for both instead of one per treatment; the choice is a branch
/// per stage, never per point and node. [`LockingTreatment::NAME`] is
/// `K`'s.
impl<const D: usize, M, K: LockingTreatment<D, M>> LockingTreatment<D, M> for Option<K> {
    const NAME: &'static str = K::NAME;
    const COUPLES_POINTS: bool = K::COUPLES_POINTS;

    #[inline(always)]
    fn couples_points(&self) -> bool {
        self.as_ref().is_some_and(K::couples_points)
    }

    fn assign(
        &mut self,
        mesh: &M,
        input: PatchInput<'_, D>,
        out: &mut PatchAssignment,
    ) -> Result<(), LockingError> {
        match self {
            Some(k) => k.assign(mesh, input, out),
            None => NoLocking.assign(mesh, input, out),
        }
    }
}

/// F-bar on a regular grid: the points of a block of
/// `cells_per_patch`$^D$ cells share the volume-weighted average of their
/// $\det\Delta F$ (the regular-grid analogue of Wang et al. 2021 eq. 9;
/// Coombs, Charlton, Cortis & Augarde 2018, CMAME 333). A point belongs to
/// the cell containing it; the weights are the converged volumes, so the
/// patch's volume after the step is exactly the sum of its points' own
/// deformed volumes. Works with every regular-grid basis: with linear MPM
/// the points of a cell share their stencil, so single-cell patches add
/// no entry to the stiffness; GIMP, CPDI2 and B-spline stencils reach
/// beyond the cell and the pattern grows to the union of the patch's
/// stencils.
#[derive(Debug, Clone, Copy)]
pub struct FBar {
    /// Cells per patch along each axis (1: one cell).
    pub cells_per_patch: usize,
}

impl Default for FBar {
    fn default() -> Self {
        Self { cells_per_patch: 1 }
    }
}

impl<const D: usize> LockingTreatment<D, RegularGrid<D>> for FBar {
    const NAME: &'static str = "fbar";
    const COUPLES_POINTS: bool = true;

    fn assign(
        &mut self,
        grid: &RegularGrid<D>,
        input: PatchInput<'_, D>,
        out: &mut PatchAssignment,
    ) -> Result<(), LockingError> {
        let n = self.cells_per_patch.max(1);
        let cells = grid.cells_per_axis();
        out.patch.clear();
        out.weight.clear();
        for (p, x) in input.position.iter().enumerate() {
            let cell = grid
                .cell_containing(x)
                .map_err(|_| LockingError::OutsideMesh {
                    point: p,
                    position: x.iter().copied().collect(),
                })?;
            let mut id = 0usize;
            for i in (0..D).rev() {
                id = id * cells[i].div_ceil(n) + cell[i] / n;
            }
            out.patch.push(id as u32);
            out.weight.push(input.volume[p]);
        }
        Ok(())
    }
}

/// F-patch on a linear simplex mesh made of the children of six-node
/// triangles or ten-node tetrahedra (Wang et al. 2021 §3.2, §4.1): the
/// points of the active children of one parent share the parent's
/// volumetric deformation (eq. 9). Build it from the [`PatchMesh`] whose
/// [`PatchMesh::mesh`] is the solver's mesh.
#[derive(Debug, Clone)]
pub struct FPatch {
    patch_of_element: Arc<[usize]>,
    points_in: Vec<u32>,
}

impl FPatch {
    /// The treatment for the children mesh of `patches`.
    pub fn new<const D: usize>(patches: &PatchMesh<D>) -> Self {
        Self::from_patch_map(patches.patch_of_element().to_vec())
    }

    /// The treatment with the patch of every element given directly.
    pub fn from_patch_map(patch_of_element: Vec<usize>) -> Self {
        Self {
            patch_of_element: patch_of_element.into(),
            points_in: Vec::new(),
        }
    }
}

impl<const D: usize> LockingTreatment<D, SimplexMesh<D>> for FPatch {
    const NAME: &'static str = "fpatch";
    const COUPLES_POINTS: bool = true;

    fn assign(
        &mut self,
        mesh: &SimplexMesh<D>,
        input: PatchInput<'_, D>,
        out: &mut PatchAssignment,
    ) -> Result<(), LockingError> {
        let elements = mesh.element_count();
        if self.patch_of_element.len() != elements {
            return Err(LockingError::PatchMap {
                entries: self.patch_of_element.len(),
                elements,
            });
        }
        self.points_in.clear();
        self.points_in.resize(elements, 0);
        let element =
            |p: usize| {
                input.cells.get(p).copied().filter(|&e| e < elements).ok_or(
                    LockingError::OutsideMesh {
                        point: p,
                        position: input.position[p].iter().copied().collect(),
                    },
                )
            };
        for p in 0..input.position.len() {
            self.points_in[element(p)?] += 1;
        }
        out.patch.clear();
        out.weight.clear();
        let volumes = mesh.volumes();
        for p in 0..input.position.len() {
            let e = element(p)?;
            out.patch.push(self.patch_of_element[e] as u32);
            out.weight.push(volumes[e] / f64::from(self.points_in[e]));
        }
        Ok(())
    }
}
