//! Generic material point solvers.
//!
//! The plug-point traits live here and the solvers depend on nothing else:
//! [`Formulation`] (updated Lagrangian / previously converged, Coombs et
//! al. 2020 §3 and §5), [`LockingTreatment`] (none now; F-bar / F-patch /
//! cell-averaged dilatation to come), [`DomainUpdater`] (the GIMP
//! domain-update rules, §6.4), [`Constraints`] (Dirichlet conditions on the
//! grid) and, from `mpm-basis`, `BasisFunction`. [`ImplicitSolver`]
//! composes them into the quasi-static Newton–Raphson solver of §6.3 and
//! [`run`] drives it through load steps with automatic step control.

pub mod boundary;
pub mod checkpoint;
pub mod domain;
pub mod error;
pub mod formulation;
pub mod implicit;
pub mod linear;
pub mod locking;
pub mod mesh;
pub mod moving_mesh;
pub mod parts;
pub mod points;
pub mod stages;
pub mod stepping;

pub use boundary::{Constraints, NodalConstraints, StepView};
pub use checkpoint::Flat;
pub use domain::{
    ConvectedCorners, CornerMidpoint, DeformationRule, DetF, DiagF, DomainContext, DomainError,
    DomainUpdater, DomainVolume, GimpContext, IncrementalVolumeCorrectedDiagF, Midpoint, NoUpdate,
    StretchU, VolumeCorrectedDiagF,
};
pub use error::{BasisFailure, MeshMotionError, ObserverError, SolverError, StepFailure};
pub use formulation::{Formulation, PreviouslyConverged, UpdatedLagrangian};
pub use implicit::{
    FreeStiffness, ImplicitBuilder, ImplicitSolver, NewtonOptions, StepError, StepReport,
};
pub use linear::{Factorisation, FaerDirect, LinearSolveError, LinearSolver};
pub use locking::{LockingTreatment, NoLocking};
pub use mesh::{MovableMesh, NodalMesh};
pub use moving_mesh::{MeshMotion, MovingMesh, Rotation, Stretch, Translation};
pub use parts::{Parts, PointsOf, SolverParts};
pub use points::{BodyForcePath, MaterialPoints};
pub use stepping::{LoadStepping, RunState, RunSummary, StepContext};
