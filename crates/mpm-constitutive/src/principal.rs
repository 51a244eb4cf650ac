//! Tools for laws whose return map works on sorted principal values (the
//! soil models): the sort and its inverse, principal elasticity, and the
//! algorithmic tangent of any isotropic principal return as a tensor.
//!
//! An isotropic return map gives principal stresses $\tau_a(\varepsilon_1,
//! \varepsilon_2, \varepsilon_3)$ coaxial with the trial strain. Its
//! tangent is (de Souza Neto, Perić & Owen 2008, Appendix A, A.46)
//! $$ D^{alg} = \sum_{a,b} \frac{\partial\tau_a}{\partial\varepsilon_b}\,
//!   \mathbf P_a\otimes\mathbf P_b + \sum_{a\ne b}\theta_{ab}\,
//!   \mathbf S_{ab}\otimes\mathbf S_{ab},\qquad
//!   \theta_{ab} = \frac{\tau_a - \tau_b}{\varepsilon_a - \varepsilon_b}, $$
//! with $\mathbf P_a = \mathbf n_a\otimes\mathbf n_a$ and $\mathbf S_{ab}$ as
//! in [`crate::spectral`]. When two trial strains coincide the divided
//! difference has the limit $\theta_{ab} = \tfrac12(d_{aa} + d_{bb} -
//! d_{ab} - d_{ba})$ with $d = \partial\tau/\partial\varepsilon$. To see
//! it, write $\varepsilon_a = x + \delta$ and $\varepsilon_b = x - \delta$:
//! isotropy gives $\tau_b(x+\delta, x-\delta) = \tau_a(x-\delta,
//! x+\delta)$, so $\tau_a - \tau_b = 2\delta(d_{aa} - d_{ab}) +
//! O(\delta^2)$, here symmetrised over $a, b$. Below [`REPEATED`]
//! (relative to the strain's scale) the limit is used: the quotient there
//! loses all digits to cancellation.

use nalgebra::{Matrix3, Vector3};

use crate::spectral::SymSpectral;
use crate::tensor::Tensor4;

/// Which part of a multi-surface yield function a return ended on, kept
/// in the history so that a check by finite differences compares states
/// of one regime ([`crate::LogStrainLaw::regime`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum Regime {
    /// No plastic flow.
    #[default]
    Elastic = 0,
    /// One smooth surface: the Mohr–Coulomb main plane, the Drucker–Prager
    /// cone.
    Plane = 1,
    /// The triaxial-compression edge $\tau_1 = \tau_2$ (Mohr–Coulomb).
    CompressionEdge = 2,
    /// The triaxial-extension edge $\tau_2 = \tau_3$ (Mohr–Coulomb).
    ExtensionEdge = 3,
    /// The apex: an isotropic stress.
    Apex = 4,
    /// The tension cut-off of Mohr–Coulomb alone: the largest principal
    /// stress at the tensile strength, $\tau_1 = \sigma_t$ (Rankine).
    Tension = 5,
    /// Mohr–Coulomb's main plane and the tension cut-off: $\tau_1 =
    /// \sigma_t$ with $\tau_3$ on the main plane.
    TensionPlane = 6,
    /// The edge of two tension planes: $\tau_1 = \tau_2 = \sigma_t$.
    TensionEdge = 7,
    /// Mohr–Coulomb's triaxial-extension edge on the tension cut-off:
    /// $\tau_1 = \sigma_t$, $\tau_2 = \tau_3$ on the main plane.
    TensionExtensionEdge = 8,
    /// Mohr–Coulomb's triaxial-compression edge on the tension edge:
    /// $\tau_1 = \tau_2 = \sigma_t$, $\tau_3$ on the main plane.
    TensionCompressionEdge = 9,
    /// The apex of the tension cut-off: the isotropic stress $\sigma_t
    /// \mathbf 1$.
    TensionApex = 10,
}

impl Regime {
    /// The regime of a stored code (0 for an unknown one).
    pub fn from_code(code: u8) -> Self {
        match code {
            1 => Self::Plane,
            2 => Self::CompressionEdge,
            3 => Self::ExtensionEdge,
            4 => Self::Apex,
            5 => Self::Tension,
            6 => Self::TensionPlane,
            7 => Self::TensionEdge,
            8 => Self::TensionExtensionEdge,
            9 => Self::TensionCompressionEdge,
            10 => Self::TensionApex,
            _ => Self::Elastic,
        }
    }
}

/// Trial strains closer than this (relative to $\max(1,
/// |\varepsilon|_\infty)$) count as repeated for the divided difference.
///
/// Why 1e-6: the rounding of $\tau_a - \tau_b$ is amplified by the
/// return's own conditioning (a Mohr–Coulomb edge at ν = 0.4999), so the
/// quotient at $\varepsilon_a - \varepsilon_b = 1.9\times10^{-9}$ missed
/// the finite differences by 7.2e-6 (the property test of 3000 random
/// deformation gradients; it was 1e-9 then). Mohr–Coulomb's returns are
/// affine in the trial strain within a regime and make $\tau_a = \tau_b$
/// on an edge, so the limit is exact for them at any distance; for the
/// cone of Drucker–Prager and Cam-Clay's ellipse it is off by
/// $O(\varepsilon_a - \varepsilon_b)$, at most about 1e-6 relative here.
/// With 1e-6 three runs of 3000 cases of every law's property tests pass.
pub const REPEATED: f64 = 1e-6;

/// The permutation sorting principal values in descending order:
/// `values[order[0]] >= values[order[1]] >= values[order[2]]`.
#[inline]
pub fn descending(values: &Vector3<f64>) -> [usize; 3] {
    let mut order = [0, 1, 2];
    order.sort_by(|&a, &b| values[b].total_cmp(&values[a]));
    order
}

/// `sorted` (in the order of `order`) put back in the original order.
#[inline]
pub fn unsort(sorted: &Vector3<f64>, order: [usize; 3]) -> Vector3<f64> {
    let mut out = Vector3::zeros();
    for (k, &a) in order.iter().enumerate() {
        out[a] = sorted[k];
    }
    out
}

/// `values` in the order of `order`.
#[inline]
pub fn sort(values: &Vector3<f64>, order: [usize; 3]) -> Vector3<f64> {
    Vector3::new(values[order[0]], values[order[1]], values[order[2]])
}

/// A matrix over sorted principal values (`d[(k, l)]` for the `k`-th and
/// `l`-th largest) put back in the original order.
#[inline]
pub fn unsort_matrix(sorted: &Matrix3<f64>, order: [usize; 3]) -> Matrix3<f64> {
    let mut out = Matrix3::zeros();
    for (k, &a) in order.iter().enumerate() {
        for (l, &b) in order.iter().enumerate() {
            out[(a, b)] = sorted[(k, l)];
        }
    }
    out
}

/// The principal elasticity $\partial\tau_a/\partial\varepsilon_b =
/// \lambda + 2\mu\delta_{ab}$ (Hencky strain, Kirchhoff stress).
#[inline]
pub fn elastic_matrix(lambda: f64, mu: f64) -> Matrix3<f64> {
    Matrix3::from_element(lambda) + Matrix3::from_diagonal_element(2.0 * mu)
}

/// $D^{alg}$ as a tensor (module docs) from the trial strain `trial`, the
/// returned principal stresses `tau` (in `trial`'s order) and their
/// derivatives `d[(a, b)]` $= \partial\tau_a/\partial\varepsilon_b$.
pub fn tangent(trial: &SymSpectral, tau: &Vector3<f64>, d: &Matrix3<f64>) -> Tensor4 {
    let eps = &trial.values;
    let scale = eps.amax().max(1.0);
    let theta = |a: usize, b: usize| {
        let de = eps[a] - eps[b];
        if de.abs() <= REPEATED * scale {
            0.5 * (d[(a, a)] - d[(a, b)] + d[(b, b)] - d[(b, a)])
        } else {
            (tau[a] - tau[b]) / de
        }
    };
    let mut out = Tensor4::zeros();
    let p: [_; 3] = std::array::from_fn(|a| trial.projection(a));
    for a in 0..3 {
        for b in 0..3 {
            out += d[(a, b)] * p[a] * p[b].transpose();
        }
    }
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let s = spin(trial, a, b);
        out += 2.0 * theta(a, b) * s * s.transpose();
    }
    out
}

/// $\mathbf S_{ab} = \tfrac12(\mathbf n_a\otimes\mathbf n_b + \mathbf n_b
/// \otimes\mathbf n_a)$ as a nine-vector.
fn spin(trial: &SymSpectral, a: usize, b: usize) -> crate::tensor::Vector9 {
    let (na, nb) = (trial.vectors.column(a), trial.vectors.column(b));
    let m = 0.5 * (na * nb.transpose() + nb * na.transpose());
    crate::tensor::to_vec9(&m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::IsotropicElasticity;

    #[test]
    fn the_elastic_principal_tangent_is_the_elastic_stiffness() {
        let el = IsotropicElasticity::new(1e6, 0.3).expect("valid constants");
        let eps = Matrix3::new(0.01, 0.002, 0.0, 0.002, -0.004, 0.001, 0.0, 0.001, 0.003);
        for e in [eps, Matrix3::from_diagonal_element(0.01)] {
            let trial = SymSpectral::new(&e).expect("decomposes");
            let tau = el.principal_stress(&trial.values);
            let d = tangent(&trial, &tau, &elastic_matrix(el.lambda, el.mu));
            let err = (d - el.stiffness()).norm() / el.stiffness().norm();
            assert!(err < 1e-14, "{err:e}");
        }
    }

    #[test]
    fn sorting_round_trips() {
        let v = Vector3::new(-1.0, 3.0, 2.0);
        let order = descending(&v);
        assert_eq!(order, [1, 2, 0]);
        assert_eq!(unsort(&sort(&v, order), order), v);
    }
}
