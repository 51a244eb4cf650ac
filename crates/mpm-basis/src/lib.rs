//! Basis functions for the material point method.
//!
//! The plug-point trait [`BasisFunction<D>`](BasisFunction) writes, for one
//! material point, the supporting node ids, the values $S_{vp}$ and the
//! gradients $\partial S_{vp}/\partial\tilde X$ into a caller-owned
//! [`Stencil`], so that nothing allocates per material point. The mesh and
//! the per-point domain are associated types. Implementations, one file
//! each, on [`mpm_mesh::RegularGrid<D>`] (the last on
//! [`mpm_mesh::SimplexMesh<D>`]) with one code path for 2D and 3D
//! (`const D: usize`):
//!
//! | type | domain | nodes (2D / 3D) | source |
//! |---|---|---|---|
//! | [`LinearMpm`] | `()` | 4 / 8 | Sulsky et al. 1994; Coombs et al. 2020 §6.1 |
//! | [`Gimp`] | half-lengths `SVector<f64, D>` | 9 / 27 | Bardenhagen & Kober 2004; Charlton et al. 2017 |
//! | [`Cpdi2`] | [`Corners<D>`] | ≤ 16 / ≤ 64 | Sadeghirad et al. 2013 (corrected, Coombs et al. 2020 fn. 6) |
//! | [`QuadraticBSpline`] | `()` | 9 / 27 | Steffen et al. 2008; MPoint notes eqs. 24–27 |
//! | [`LinearSimplex`] | `()` | 3 / 4 | Wang et al. 2021 §2.3, eqs. 13–15 (on [`mpm_mesh::SimplexMesh`]) |
//!
//! Tensor-product bases are assembled from 1D factors by one loop over the
//! axes. Every failure is a [`BasisError`] naming the point; a node beyond
//! the grid never appears in a stencil.
//!
//! ```
//! use mpm_basis::{BasisFunction, Gimp};
//! use mpm_mesh::RegularGrid;
//! use nalgebra::Vector2;
//! let grid = RegularGrid::new(Vector2::zeros(), Vector2::new(1.0, 1.0), [4, 4])?;
//! let mut stencil = BasisFunction::<2>::new_stencil(&Gimp);
//! Gimp.evaluate(&grid, &Vector2::new(1.9, 2.2), &Vector2::new(0.25, 0.25), &mut stencil)?;
//! let sum: f64 = stencil.values.iter().sum();
//! assert!((sum - 1.0).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![cfg_attr(test, allow(clippy::unwrap_used))]

mod basis;
mod boundary_bspline;
mod corners;
mod cpdi2;
mod error;
mod gimp;
mod linear_mpm;
mod linear_simplex;
mod quadratic_bspline;
mod stencil;
mod tensor;

pub use basis::BasisFunction;
pub use boundary_bspline::BoundaryBSpline;
pub use corners::{Corners, MAX_CORNERS, reference_shape};
pub use cpdi2::{Cpdi2, DomainIntegrals};
pub use error::BasisError;
pub use gimp::Gimp;
pub use linear_mpm::LinearMpm;
pub use linear_simplex::LinearSimplex;
pub use quadratic_bspline::QuadraticBSpline;
pub use stencil::Stencil;
pub use tensor::TensorFactors;
