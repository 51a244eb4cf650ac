//! Generic material point solvers.
//!
//! The plug-point traits live here (or, for the basis and the law, in the
//! lowest crate that can own them) and the solvers depend on nothing else:
//!
//! | plug point | implementations | paper |
//! |---|---|---|
//! | `mpm_basis::BasisFunction` | `LinearMpm`, `Gimp`, `Cpdi2`, `QuadraticBSpline`, `BoundaryBSpline`, `LinearSimplex` | Coombs et al. 2020 §6.1; Wang et al. 2021 §2.3; MPoint notes eqs. 24–27 |
//! | `mpm_constitutive::LogStrainLaw` | `HenckyElastic`, `VonMises`, `NeoHookean` | Coombs et al. 2020 §2 |
//! | `mpm_constitutive::IncrementalLaw` (explicit) | `NeoHookean`, `Spectral<L>` | MPoint notes eqs. 38–44 |
//! | [`explicit::Transfer`] (explicit) | [`Pic`], [`Flip`], [`FlipPic`], [`Taylor`] | MPoint notes eqs. 29, 34–36 |
//! | [`explicit::DilatationTreatment`] (explicit) | [`NoLocking`], [`CellAveraged`] | MPoint notes eqs. 47–53 |
//! | [`Formulation`] | [`UpdatedLagrangian`], [`PreviouslyConverged`] | §3, §5 |
//! | [`LockingTreatment`] | [`NoLocking`], [`FBar`], [`FPatch`] | Wang et al. 2021 §3.2; Coombs et al. 2018 |
//! | [`DomainUpdater`] (or the shorter [`DeformationRule`]) | [`NoUpdate`], [`DetF`], [`DiagF`], [`StretchU`], [`CornerMidpoint`], [`Midpoint`], [`VolumeCorrectedDiagF`], [`IncrementalVolumeCorrectedDiagF`], [`ConvectedCorners`], [`DomainVolume`]; [`AnyGimpRule`] chooses among the GIMP rules at run time | Coombs et al. 2020 §6.4 |
//! | [`Constraints`] | [`NodalConstraints`], [`MovingMesh`] | §6.2; Wang et al. 2021 §5.3 |
//! | [`LinearSolver`] | [`FaerDirect`] | eq. 26 |
//!
//! [`SolverParts`] names the components of a solver and the bounds between
//! them once; [`ImplicitSolver`] composes them into the quasi-static
//! Newton–Raphson solver of Coombs et al. 2020 §6.3, and [`LoadStepping`]
//! drives it through load steps with automatic step control;
//! [`ExplicitSolver`] is the explicit dynamic solver of the MPoint notes
//! (module [`explicit`]). The stages
//! of a step are free functions in [`stages`] (basis evaluation,
//! point-to-grid gathers, grid-to-point updates, the convergence test), so
//! other solvers reuse them. [`ImplicitBuilder`] composes a solver from
//! values and infers every type:
//!
//! ```
//! use mpm_basis::LinearMpm;
//! use mpm_constitutive::HenckyElastic;
//! use mpm_mesh::RegularGrid;
//! use mpm_solver::{
//!     ImplicitBuilder, LoadStepping, MaterialPoints, NodalConstraints, UpdatedLagrangian,
//! };
//! use nalgebra::Vector2;
//!
//! // A 1 m × 4 m column, 2×2 points per cell, under its own weight.
//! let grid = RegularGrid::new(Vector2::zeros(), Vector2::new(1.0, 1.0), [1, 4])?;
//! let mut fixed = NodalConstraints::new(grid.node_count());
//! fixed.fix(0..grid.node_count(), 0); // rollers on the sides
//! fixed.fix([0, 1], 1); // the base
//! let position: Vec<_> = (0..16)
//!     .map(|k| Vector2::new(0.25 + 0.5 * (k % 2) as f64, 0.25 + 0.5 * (k / 2) as f64))
//!     .collect();
//! let mut points: MaterialPoints<2, (), ()> =
//!     MaterialPoints::new(position, vec![0.25; 16], 80.0, vec![(); 16])?;
//! points.set_gravity(Vector2::new(0.0, -10.0));
//!
//! let mut solver = ImplicitBuilder::new(LinearMpm, grid, HenckyElastic::new(1e6, 0.0)?)
//!     .formulation(UpdatedLagrangian)
//!     .constraints(fixed)
//!     .build();
//! let mut reaction = Vector2::zeros();
//! let summary = solver.run(&mut points, &LoadStepping::uniform(5), |_, report, _| {
//!     reaction = report.reaction;
//!     Ok(())
//! })?;
//! assert_eq!(summary.steps, 5);
//! // The base carries the whole weight, ϱ g × 4 m² = 3200 N per unit depth.
//! assert!((reaction[1] - 3200.0).abs() < 1e-6 * 3200.0, "{reaction}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Everything monomorphises: a scene that needs no plasticity, locking
//! treatment, domain update or body force does not pay for them
//! (`docs/src/benchmarks/zero_cost.md` measures it against a hand-written
//! kernel).

pub mod boundary;
pub mod checkpoint;
pub mod contact;
pub mod domain;
pub mod error;
pub mod explicit;
pub mod formulation;
pub mod implicit;
pub mod linear;
pub mod locking;
pub mod mesh;
pub mod moving_mesh;
pub mod par;
pub mod parts;
pub mod points;
pub mod ranks;
pub mod stages;
pub mod stepping;

pub use boundary::{Constraints, NodalConstraints, StepView};
pub use checkpoint::Flat;
pub use contact::RigidTool;
pub use domain::{
    AnyGimpRule, ConvectedCorners, CornerMidpoint, DeformationRule, DetF, DiagF, DisplacementField,
    DomainContext, DomainError, DomainUpdater, DomainVolume, GimpContext, GimpRule,
    IncrementalVolumeCorrectedDiagF, Midpoint, NoUpdate, StretchU, VolumeCorrectedDiagF,
};
pub use error::{
    BasisFailure, LockingError, MeshMotionError, ObserverError, PointFailure, SolverError,
    StepFailure,
};
pub use explicit::{
    CellAveraged, ExplicitOptions, ExplicitPoints, ExplicitSolver, Flip, FlipPic, Pic, Taylor,
    TimeStep, Transfer, VelocityFixities,
};
pub use formulation::{Formulation, PreviouslyConverged, UpdatedLagrangian};
pub use implicit::{
    CutStep, FirstTangent, FreeStiffness, ImplicitBuilder, ImplicitSolver, NewtonOptions,
    StageTimes, StepError, StepReport,
};
pub use linear::{
    AutoLinear, DEFAULT_MAX_DIRECT_DOFS_2D, DEFAULT_MAX_DIRECT_DOFS_3D, Factorisation, FaerDirect,
    FaerIterative, IterativeOptions, LinearChoice, LinearSolveError, LinearSolver,
    MAX_FALLBACK_DOFS,
};
pub use locking::{FBar, FPatch, LockingTreatment, NoLocking, PatchAssignment, PatchInput};
pub use mesh::{MovableMesh, NodalMesh};
pub use moving_mesh::{MeshMotion, MovingMesh, Rotation, Stretch, Translation};
pub use parts::{Parts, PointsOf, SolverParts};
pub use points::{BodyForcePath, MaterialPoints};
pub use stages::ghost::GhostPenalty;
pub use stepping::{LoadStepping, MIN_LOAD_INCREMENT, RunState, RunSummary, StepContext};
