//! Manufactured solutions: fields with a closed form and the body force
//! that holds them in equilibrium, shared by the cases that check against
//! them and the scene builder that applies their forces (`[[load]] kind =
//! "manufactured"`).
//!
//! [`Torsion`]: the rotation field of Coombs et al. 2020 §7.4, eq. (44), in
//! the annulus $R_i \le R \le R_o$ (derivation of the body force:
//! [`crate::cases::annulus`]).

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

/// The rotation field of eq. (44) and its manufactured body force.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Torsion {
    /// Inner radius $R_i$.
    pub inner_radius: f64,
    /// Outer radius $R_o$.
    pub outer_radius: f64,
    /// Shear modulus $\mu$.
    pub mu: f64,
}

impl Torsion {
    /// $(\theta, \theta', \theta'')$ at radius `r` for amplitude `alpha`.
    pub fn theta(&self, alpha: f64, r: f64) -> (f64, f64, f64) {
        let (a, b) = (self.inner_radius, self.outer_radius);
        let c = 16.0 * alpha / (a - b).powi(4);
        let (p, q) = (r - a, r - b);
        (
            c * p * p * q * q,
            c * 2.0 * p * q * (p + q),
            c * 2.0 * (q * q + 4.0 * p * q + p * p),
        )
    }

    /// The exact displacement of the point initially at `x0`.
    pub fn displacement(&self, alpha: f64, x0: &Vector2<f64>) -> Vector2<f64> {
        let r = x0.norm();
        let (t, _, _) = self.theta(alpha, r);
        let (s, c) = t.sin_cos();
        Vector2::new(c * x0[0] - s * x0[1], s * x0[0] + c * x0[1]) - x0
    }

    /// The simple-shear stresses $(s_{11}, s_{12})$ and their derivatives
    /// with respect to $\gamma$.
    pub fn shear_stress(&self, gamma: f64) -> ((f64, f64), (f64, f64)) {
        let a = (gamma / 2.0).asinh();
        let q = gamma * gamma + 4.0;
        let root = q.sqrt();
        let m = 2.0 * self.mu;
        (
            (m * a * gamma / root, m * 2.0 * a / root),
            (
                m * (gamma / q + 4.0 * a / (q * root)),
                m * (2.0 / q - 2.0 * gamma * a / (q * root)),
            ),
        )
    }

    /// The body force per unit volume, in Cartesian components, that holds
    /// the point initially at `x0` in equilibrium at amplitude `alpha`.
    pub fn body_force(&self, alpha: f64, x0: &Vector2<f64>) -> Vector2<f64> {
        let r = x0.norm();
        let (t, dt, ddt) = self.theta(alpha, r);
        let gamma = r * dt;
        let dgamma = dt + r * ddt;
        let ((s11, s12), (ds11, ds12)) = self.shear_stress(gamma);
        let b_r = ds11 * dgamma + 2.0 * s11 / r;
        let b_phi = -ds12 * dgamma - 2.0 * s12 / r;
        let phi = x0[1].atan2(x0[0]) + t;
        let (s, c) = phi.sin_cos();
        Vector2::new(c * b_r - s * b_phi, s * b_r + c * b_phi)
    }
}
