//! Property tests for constitutive laws, so that a downstream
//! `LogStrainLaw` is verified by the same finite-difference properties as
//! the laws of `mpm-constitutive` (as fenris exports its element property
//! tests).
//!
//! - [`strategies`]: the random inputs (large rotations, stretches with
//!   repeated and nearly repeated eigenvalues, deformation gradients built
//!   from them, Poisson ratios up to the nearly incompressible limit,
//!   converged states);
//! - [`previously_converged_property`], [`spatial_property`],
//!   [`algorithmic_tangent_property`]: one property per tangent over
//!   `mpm_constitutive::verification`'s checks;
//! - [`law_tangent_properties!`]: the three as `proptest` tests for any
//!   law constructor `|e, nu| -> Result<L, _>`.
//!
//! Use it as a dev-dependency.

mod properties;
pub mod strategies;

pub use properties::{
    algorithmic_tangent_property, law_from, previously_converged_property, spatial_property,
};
/// The `proptest` crate, re-exported so that [`law_tangent_properties!`]
/// expands in a crate that does not depend on it directly.
pub use proptest;
