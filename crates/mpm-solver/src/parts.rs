//! The components a solver is composed of, named once.
//!
//! A solver is generic over six plug points — basis, formulation,
//! constitutive law, locking treatment, domain updater and Dirichlet
//! conditions — and the bounds that make them fit together (the updater
//! must update the basis's kind of domain, the mesh must be movable) are
//! stated here, in the one `where` clause of the crate, instead of on every
//! `impl` block and every generic function. Generic code names one
//! parameter `P: SolverParts<D>` and reads the components as associated
//! types (`P::Basis`, `P::Law`, …); [`Parts`] is the ordinary
//! implementation, so a concrete solver's type is
//! `ImplicitSolver<D, Parts<B, F, L, K, U, C>>` — which the builder
//! ([`crate::ImplicitSolver::builder`]) infers, so users do not spell it.

use std::fmt::Debug;
use std::marker::PhantomData;

use mpm_basis::BasisFunction;
use mpm_constitutive::LogStrainLaw;

use crate::boundary::Constraints;
use crate::domain::DomainUpdater;
use crate::formulation::Formulation;
use crate::locking::LockingTreatment;
use crate::mesh::MovableMesh;
use crate::points::MaterialPoints;

/// The components of a solver and the bounds between them (module docs).
pub trait SolverParts<const D: usize> {
    /// Basis functions (mpm-basis).
    type Basis: BasisFunction<D, Mesh = Self::Mesh, Domain = Self::Domain>;
    /// The basis's background mesh.
    type Mesh: MovableMesh<D>;
    /// The basis's material point domain (`()` for standard MPM).
    type Domain: Copy + Send + Sync + Debug;
    /// Statement of equilibrium.
    type Formulation: Formulation;
    /// Constitutive law.
    type Law: LogStrainLaw<History = Self::History>;
    /// The law's internal variables (`()` for elasticity).
    type History: Copy + Default + Debug + PartialEq + Send + Sync + 'static;
    /// Locking treatment.
    type Locking: LockingTreatment<D, Self::Mesh>;
    /// Domain update rule.
    type Updater: DomainUpdater<D, Self::Domain>;
    /// Dirichlet conditions (and the mesh motion).
    type Constraints: Constraints<D>;
}

/// The plain composition of six components as [`SolverParts`]: a type-level
/// tuple, never constructed.
pub struct Parts<B, F, L, K, U, C>(PhantomData<(B, F, L, K, U, C)>);

impl<const D: usize, B, F, L, K, U, C> SolverParts<D> for Parts<B, F, L, K, U, C>
where
    B: BasisFunction<D>,
    B::Mesh: MovableMesh<D>,
    F: Formulation,
    L: LogStrainLaw,
    K: LockingTreatment<D, B::Mesh>,
    U: DomainUpdater<D, B::Domain>,
    C: Constraints<D>,
{
    type Basis = B;
    type Mesh = B::Mesh;
    type Domain = B::Domain;
    type Formulation = F;
    type Law = L;
    type History = L::History;
    type Locking = K;
    type Updater = U;
    type Constraints = C;
}

/// The material points a solver with components `P` works on.
pub type PointsOf<const D: usize, P> =
    MaterialPoints<D, <P as SolverParts<D>>::History, <P as SolverParts<D>>::Domain>;
