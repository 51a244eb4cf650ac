//! Volumetric locking treatments of the explicit solver (MPoint theory
//! notes eqs. 47–53).

use crate::locking::NoLocking;

/// How the velocity gradient a point's stress update sees is formed from
/// its own gradient. The deformation gradient, volume and density always
/// follow the unmodified gradient (the note under eq. 53); only the strain
/// increment handed to the law changes.
pub trait DilatationTreatment: Send + Sync + Copy + std::fmt::Debug {
    /// Whether the treatment averages the dilatation over cells, which
    /// needs a second pass over the points; `false` keeps the update fused.
    const AVERAGES: bool;
}

/// Each point's own gradient (no treatment).
impl DilatationTreatment for NoLocking {
    const AVERAGES: bool = false;
}

/// The cell-averaged dilatation of eqs. (47)–(53): the volume-weighted
/// average over the points of a background cell,
/// $(\nabla\cdot v)_c = \sum_p (\nabla\cdot v_p)V_p / \sum_p V_p$ (eq. 53),
/// replaces each point's dilatation,
/// $\overline{\nabla v}_p = \nabla v_p + \tfrac1d\left((\nabla\cdot v)_c - \nabla\cdot v_p\right)\mathbf 1$
/// (eq. 52), with $d$ the model dimension (2 in plane strain). The cell
/// of a point is the one containing it at the start of the step, the
/// volume its volume then.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CellAveraged;

impl DilatationTreatment for CellAveraged {
    const AVERAGES: bool = true;
}
