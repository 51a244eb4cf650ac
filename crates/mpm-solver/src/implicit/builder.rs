//! Composing an [`ImplicitSolver`] from values, with every type inferred.

use crate::boundary::NodalConstraints;
use crate::domain::NoUpdate;
use crate::formulation::PreviouslyConverged;
use crate::implicit::{ImplicitSolver, NewtonOptions};
use crate::linear::{FaerDirect, LinearSolver};
use crate::locking::NoLocking;
use crate::mesh::NodalMesh;
use crate::parts::{Parts, SolverParts};

/// A builder for [`ImplicitSolver`]: start from a basis, a mesh and a law;
/// every other component has a default (previously converged formulation,
/// no locking treatment, no domain update, no Dirichlet condition, default
/// Newton options, the faer direct solver) and is replaced by value.
/// [`ImplicitBuilder::build`] checks that the components fit.
///
/// ```
/// use mpm_basis::LinearMpm;
/// use mpm_constitutive::HenckyElastic;
/// use mpm_mesh::RegularGrid;
/// use mpm_solver::{ImplicitBuilder, NodalConstraints, UpdatedLagrangian};
/// use nalgebra::Vector2;
///
/// let grid = RegularGrid::new(Vector2::zeros(), Vector2::new(1.0, 1.0), [2, 2])?;
/// let mut fixed = NodalConstraints::new(grid.node_count());
/// fixed.fix(0..3, 1);
/// let solver = ImplicitBuilder::new(LinearMpm, grid, HenckyElastic::new(1e6, 0.3)?)
///     .formulation(UpdatedLagrangian)
///     .constraints(fixed)
///     .build();
/// assert_eq!(solver.options.max_iterations, 30);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct ImplicitBuilder<const D: usize, B, M, F, L, K, U, C> {
    basis: B,
    mesh: M,
    formulation: F,
    law: L,
    locking: K,
    updater: U,
    constraints: C,
    options: NewtonOptions,
    linear: Option<Box<dyn LinearSolver>>,
}

impl<const D: usize, B, M: NodalMesh<D>, L>
    ImplicitBuilder<D, B, M, PreviouslyConverged, L, NoLocking, NoUpdate, NodalConstraints<D>>
{
    /// Starts from basis, mesh and law, with the defaults of the type docs.
    pub fn new(basis: B, mesh: M, law: L) -> Self {
        let constraints = NodalConstraints::new(mesh.node_count());
        Self {
            basis,
            mesh,
            formulation: PreviouslyConverged,
            law,
            locking: NoLocking,
            updater: NoUpdate,
            constraints,
            options: NewtonOptions::default(),
            linear: None,
        }
    }
}

impl<const D: usize, B, M, F, L, K, U, C> ImplicitBuilder<D, B, M, F, L, K, U, C> {
    /// The statement of equilibrium ([`crate::UpdatedLagrangian`],
    /// [`crate::PreviouslyConverged`]).
    pub fn formulation<F2>(self, formulation: F2) -> ImplicitBuilder<D, B, M, F2, L, K, U, C> {
        ImplicitBuilder {
            formulation,
            basis: self.basis,
            mesh: self.mesh,
            law: self.law,
            locking: self.locking,
            updater: self.updater,
            constraints: self.constraints,
            options: self.options,
            linear: self.linear,
        }
    }

    /// The locking treatment.
    pub fn locking<K2>(self, locking: K2) -> ImplicitBuilder<D, B, M, F, L, K2, U, C> {
        ImplicitBuilder {
            locking,
            basis: self.basis,
            mesh: self.mesh,
            formulation: self.formulation,
            law: self.law,
            updater: self.updater,
            constraints: self.constraints,
            options: self.options,
            linear: self.linear,
        }
    }

    /// The domain update rule (GIMP, CPDI2).
    pub fn domain_update<U2>(self, updater: U2) -> ImplicitBuilder<D, B, M, F, L, K, U2, C> {
        ImplicitBuilder {
            updater,
            basis: self.basis,
            mesh: self.mesh,
            formulation: self.formulation,
            law: self.law,
            locking: self.locking,
            constraints: self.constraints,
            options: self.options,
            linear: self.linear,
        }
    }

    /// The Dirichlet conditions (and mesh motion).
    pub fn constraints<C2>(self, constraints: C2) -> ImplicitBuilder<D, B, M, F, L, K, U, C2> {
        ImplicitBuilder {
            constraints,
            basis: self.basis,
            mesh: self.mesh,
            formulation: self.formulation,
            law: self.law,
            locking: self.locking,
            updater: self.updater,
            options: self.options,
            linear: self.linear,
        }
    }

    /// Newton controls.
    pub fn options(mut self, options: NewtonOptions) -> Self {
        self.options = options;
        self
    }

    /// The linear solver (default: [`FaerDirect`], sequential).
    pub fn linear_solver(mut self, linear: impl LinearSolver + 'static) -> Self {
        self.linear = Some(Box::new(linear));
        self
    }

    /// The solver. The bound says that the components fit together (the
    /// conditions of [`SolverParts`]); the compiler names the one that
    /// does not.
    pub fn build(self) -> ImplicitSolver<D, Parts<B, F, L, K, U, C>>
    where
        Parts<B, F, L, K, U, C>: SolverParts<
                D,
                Basis = B,
                Mesh = M,
                Formulation = F,
                Law = L,
                Locking = K,
                Updater = U,
                Constraints = C,
            >,
    {
        let mut solver = ImplicitSolver::new(
            self.basis,
            self.mesh,
            self.law,
            self.locking,
            self.updater,
            self.constraints,
            self.options,
        );
        solver.formulation = self.formulation;
        solver.set_linear_solver(
            self.linear
                .unwrap_or_else(|| Box::new(FaerDirect::default())),
        );
        solver
    }
}
