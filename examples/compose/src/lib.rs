//! A downstream crate, as a user of the framework would write one: it
//! depends only on the public APIs of `mpm-basis`, `mpm-constitutive`,
//! `mpm-mesh` and `mpm-solver`, and
//!
//! - composes an implicit solver for the self-weight column of Coombs et
//!   al. 2020 §7.1 from parts ([`column`], under 100 lines);
//! - implements two plug points outside the framework: a constitutive law,
//!   [`StiffeningHencky`] (Hencky elasticity whose shear modulus grows with
//!   the deviatoric strain), and a GIMP domain rule, [`FibreLength`]
//!   (half-lengths follow the stretch of the material fibres along the
//!   axes);
//! - verifies its law with the finite-difference checks that
//!   `mpm-constitutive` exports (`tests/law.rs`).

pub mod column;
pub mod domain;
pub mod law;

pub use column::{ColumnSettings, ColumnState, column_error, run_column};
pub use domain::FibreLength;
pub use law::StiffeningHencky;
