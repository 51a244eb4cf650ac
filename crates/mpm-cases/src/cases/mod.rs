//! The benchmark cases, each with its reference solution.

pub mod annulus;
pub mod cantilever;
pub mod collapse;
pub mod column;
pub mod shear;
pub mod stretch;
