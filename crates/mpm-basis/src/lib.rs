//! Basis functions for the material point method.
//!
//! This crate will hold the `BasisFunction<const D: usize>` trait and its
//! implementations, one file each: standard MPM (linear shape functions on
//! quadrilaterals/hexahedra and on triangles/tetrahedra), uniform GIMP,
//! CPDI2 and uniform quadratic B-splines (Coombs et al. 2020 §6.1; MPoint
//! theory notes eqs. 24–27). Implementations write node ids, values and
//! gradients into caller-owned buffers so that nothing allocates per
//! material point.
