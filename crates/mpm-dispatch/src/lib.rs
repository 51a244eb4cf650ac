//! The one place a scene meets the solvers: a [`Problem`](mpm_scene::Problem)
//! built from a scene file runs here with the variant and materials it
//! names, through solvers compiled once per dimension.
//!
//! [`run`](mod@run) composes one implicit run from typed parts (what the
//! cases and the typed studies share: the run control, the snapshot, the
//! checkpoint); [`implicit`] and [`explicit`] decide the scene's run-time
//! choices and call the monomorphised solvers ([`mpm_scene::variant`]'s
//! `dispatch` turns the basis and formulation names into types). Editing a
//! case, an output writer or the `mpm` program does not recompile this
//! crate. Its errors are the solver's ([`mpm_solver::SolverError`]): a run
//! fails only where the solver does.

pub mod explicit;
pub mod explicit_law;
mod explicit_ranks;
pub mod implicit;
pub mod linear;
pub mod on_ranks;
pub mod run;

pub use explicit::{
    ExplicitEvent, ExplicitFrame, ExplicitObserver, ExplicitOutput, RunExplicit, run_explicit,
};
pub use implicit::{RunScene, run};
