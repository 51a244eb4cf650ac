//! Solver stages as free functions over the step system and plain slices,
//! so that every solver — the implicit Newton–Raphson solver now, an
//! explicit one later — composes the same pieces with its own state. The
//! modules are named after the boxes of the algorithm (rapier/sparkl
//! style):
//!
//! | module | stage | equations (Coombs et al. 2020) |
//! |---|---|---|
//! | [`system`] | active nodes, dofs, adjacency, sparsity pattern | §6.3 |
//! | [`basis`] | basis values and gradients at the points | eqs. 8, 21 |
//! | [`gather`] | point-to-grid: mass, external and internal force, stiffness | eqs. 4, 6, 21, 23–29 |
//! | [`update`] | grid-to-point: ΔF, positions, volumes, domains | eqs. 7, 22, 31, 35 |
//! | [`ghost`] | ghost penalty on the faces of cut cells | Coombs 2023 (not in the three references) |
//! | [`patch`] | patch averages of a locking treatment, their coupling | Wang et al. 2021 eqs. 9–12 |
//! | [`convergence`] | out-of-balance force, reactions, the Newton test | eq. 40 |
//!
//! Every sum runs in an order fixed by point and node numbering, so
//! results do not depend on the number of threads.

pub mod basis;
pub mod convergence;
pub mod gather;
pub mod ghost;
pub mod patch;
pub mod system;
pub mod update;

pub use convergence::{NewtonMonitor, Verdict};
pub use system::{NONE, StepSystem};
