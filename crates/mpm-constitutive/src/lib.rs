//! Finite-strain constitutive models for implicit material point methods.
//!
//! The models follow Coombs et al. (2020), *Lagrangian formulations for the
//! material point method*, CMAME 358:112622 (cited as "Coombs 2020" with
//! equation numbers): multiplicative elasto-plasticity with a linear
//! relation between elastic Hencky strains and Kirchhoff stresses (§2), the
//! stress measures of the updated Lagrangian (§3) and previously converged
//! (§5) formulations, and their consistent tangents (Appendix A).
//!
//! - [`tensor`]: the one $9\times9$ index convention for fourth-order
//!   tensors, plane-strain embedding.
//! - [`spectral`]: symmetric eigen-decomposition, $\ln$, $\exp$ and
//!   $L = \partial\ln b/\partial b$ (eq. A.2).
//! - [`kinematics`]: $b^{e,tr}$, $B$ (eq. A.2), $\tilde B$ (eq. A.5).
//! - [`law`]: the plug-point trait [`LogStrainLaw`] for small-strain
//!   algorithmic laws; [`HenckyElastic`], [`NeoHookean`] and [`VonMises`]
//!   implement it, and so do the soil laws [`MohrCoulomb`],
//!   [`DruckerPrager`] and [`ModifiedCamClay`].
//! - [`driver`]: the finite-strain update [`update`] generic over the law,
//!   and the tangents [`SpatialTangent`] ($a_{ijkl}$, eq. A.1) and
//!   [`PreviouslyConvergedTangent`] ($\tilde A_{ijkl}$, eqs. A.3–A.6).
//! - [`verification`]: finite-difference checks of those tangents for any
//!   [`LogStrainLaw`]; the crate `mpm-constitutive-proptest` holds the
//!   strategies and the `law_tangent_properties!` macro that turn them
//!   into property tests of a downstream law.
//!
//! Models always work in 3D; a plane-strain problem embeds its $2\times2$
//! deformation gradient with [`tensor::embed`] ($F_{33} = 1$) and reads its
//! tangent back with [`tensor::restrict`].
//!
//! ```
//! use mpm_constitutive::{HenckyElastic, MaterialState, PreviouslyConvergedTangent,
//!                        ConsistentTangent, update};
//! use nalgebra::Matrix3;
//! let law = HenckyElastic::new(1e6, 0.3)?;
//! let df = Matrix3::new(1.1, 0.2, 0.0, 0.0, 0.95, 0.0, 0.0, 0.0, 1.0);
//! let r = update(&law, &df, &Matrix3::identity(), &MaterialState::default())?;
//! let a_tilde = PreviouslyConvergedTangent::tangent(&law, &r)?;
//! assert!(r.sigma.iter().all(|s| s.is_finite()) && a_tilde.norm() > 0.0);
//! # Ok::<(), mpm_constitutive::ConstitutiveError>(())
//! ```

pub mod driver;
pub mod drucker_prager;
pub mod error;
pub mod hencky;
pub mod incremental;
pub mod kinematics;
pub mod law;
pub mod material_set;
pub mod modified_cam_clay;
pub mod mohr_coulomb;
pub mod neo_hookean;
pub mod point_driver;
pub mod principal;
pub mod spectral;
pub mod tensor;
pub mod verification;
pub mod von_mises;

pub use driver::{
    ConsistentTangent, MaterialState, PreviouslyConvergedTangent, Response, SpatialTangent,
    TangentParts, update,
};
pub use drucker_prager::{DruckerPrager, DruckerPragerHistory, Matching};
pub use error::{ConstitutiveError, Result};
pub use hencky::HenckyElastic;
pub use incremental::{IncrementalLaw, Spectral};
pub use law::{IsotropicElasticity, LawState, LogStrainLaw};
pub use material_set::{MaterialSet, Tagged};
pub use modified_cam_clay::{CamClayRegime, ModifiedCamClay, ModifiedCamClayHistory};
pub use mohr_coulomb::{MohrCoulomb, MohrCoulombHistory};
pub use neo_hookean::NeoHookean;
pub use principal::Regime;
pub use spectral::{SymSpectral, sym_exp, sym_log};
pub use tensor::Tensor4;
pub use von_mises::{VonMises, VonMisesHistory};
