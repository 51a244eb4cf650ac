//! The crate's error type.

use thiserror::Error;

/// Everything that can go wrong in a constitutive update.
///
/// Every variant names the offending value so that a caller (the solver)
/// can attach the material point or load step and report it.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum ConstitutiveError {
    /// A deformation gradient (or its increment) with a non-positive
    /// determinant: the motion inverts or annihilates the material.
    #[error("det({which}) = {det:e} <= 0: the deformation inverts the material")]
    NonPositiveJacobian {
        /// Which tensor, e.g. `"ΔF"` or `"F_n"`.
        which: &'static str,
        /// Its determinant.
        det: f64,
    },
    /// An input tensor or scalar holds NaN or infinity.
    #[error("{which} has a non-finite entry ({value})")]
    NonFinite {
        /// Which input.
        which: &'static str,
        /// The first non-finite value found.
        value: f64,
    },
    /// The previously converged elastic left Cauchy–Green tensor is not
    /// symmetric positive definite.
    #[error("the elastic left Cauchy–Green tensor b_e has eigenvalue {eigenvalue:e} <= 0")]
    NotPositiveDefinite {
        /// The smallest eigenvalue found.
        eigenvalue: f64,
    },
    /// The symmetric eigen-solver did not converge.
    #[error("symmetric eigen-decomposition did not converge")]
    EigenDecomposition,
    /// Young's modulus must be positive and finite.
    #[error("Young's modulus E = {value} must be positive and finite")]
    InvalidYoungsModulus {
        /// The value given.
        value: f64,
    },
    /// Poisson's ratio must lie in the open interval (-1, 0.5).
    #[error("Poisson's ratio ν = {value} must lie in (-1, 0.5)")]
    InvalidPoissonRatio {
        /// The value given.
        value: f64,
    },
    /// The yield stress must be positive and finite.
    #[error("yield stress ρ_y = {value} must be positive and finite")]
    InvalidYieldStress {
        /// The value given.
        value: f64,
    },
    /// The hardening modulus must be non-negative and finite (softening is
    /// not supported: it makes the local problem ill-posed).
    #[error("hardening modulus H = {value} must be non-negative and finite")]
    InvalidHardening {
        /// The value given.
        value: f64,
    },
    /// A law's parameter outside its range.
    #[error("{name} = {value} must be {range}")]
    InvalidParameter {
        /// The parameter, e.g. `"friction angle"`.
        name: &'static str,
        /// The value given.
        value: f64,
        /// Its range, in words.
        range: &'static str,
    },
    /// A [`crate::MaterialSet`] needs at least one law and at most
    /// `u32::MAX` of them.
    #[error("a material set holds {count} laws; it needs 1 to 2^32 - 1")]
    MaterialSetSize {
        /// The number of laws given.
        count: usize,
    },
    /// An explicit solver needs the law's elastic wave speed (MPoint notes
    /// eq. 46) and the law does not define isotropic elastic constants.
    #[error("the law defines no elastic constants; give its P-wave modulus K + 4G/3 explicitly")]
    NoElasticConstants,
    /// The P-wave modulus must be positive and finite.
    #[error("P-wave modulus {value} must be positive and finite")]
    InvalidWaveModulus {
        /// The value given.
        value: f64,
    },
    /// An energy balance asked for the stored energy of a law that does
    /// not define it.
    #[error("the law does not define a stored energy")]
    NoStoredEnergy,
}

/// Shorthand for results of this crate.
pub type Result<T> = std::result::Result<T, ConstitutiveError>;
