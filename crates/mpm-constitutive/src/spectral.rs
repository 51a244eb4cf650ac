//! Spectral decomposition of symmetric 3×3 tensors, isotropic tensor
//! functions (log, exp) and their derivatives.
//!
//! The derivative of an isotropic tensor function
//! $f(\mathbf{b}) = \sum_a f(\lambda_a)\, \mathbf{n}_a \otimes \mathbf{n}_a$
//! follows the Daleckii–Krein form (the special case of Miehe's general
//! formula cited under Coombs et al. 2020, eq. A.2):
//! $$
//! \frac{\partial f(\mathbf b)}{\partial \mathbf b}
//!   = \sum_{a,b} \theta_{ab}\; \mathbf{S}_{ab} \otimes \mathbf{S}_{ab},
//! \qquad \mathbf{S}_{ab} = \tfrac12(\mathbf n_a \otimes \mathbf n_b + \mathbf n_b \otimes \mathbf n_a),
//! $$
//! with $\theta_{aa} = f'(\lambda_a)$ and the divided difference
//! $\theta_{ab} = (f(\lambda_a) - f(\lambda_b))/(\lambda_a - \lambda_b)$ for
//! $a \ne b$. For $f = \ln$ the divided difference is evaluated as
//! $\operatorname{ln\_1p}(d/\lambda_b)/d$ with $d = \lambda_a - \lambda_b$,
//! which is exact to rounding for every $d$ including $d \to 0$, where it
//! tends to $f'(\lambda_b) = 1/\lambda_b$. Equal and nearly equal
//! eigenvalues therefore need no special branch, and the result does not
//! depend on which orthonormal basis the eigen-solver picks inside a
//! repeated eigenspace. The tensor is stored with both minor symmetries, so
//! it is the derivative with respect to symmetric perturbations (the only
//! ones $\mathbf b$ can take).

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use crate::error::{ConstitutiveError, Result};
use crate::tensor::{Tensor4, Vector9, to_vec9};

/// Iteration cap for the symmetric eigen-solver (it converges in a handful
/// of sweeps for 3×3 input; the cap only turns a pathological input into an
/// error rather than a hang).
const EIGEN_MAX_ITERATIONS: usize = 200;

/// Eigenvalues and orthonormal eigenvectors of a symmetric 3×3 tensor:
/// $\mathbf A = \sum_a \lambda_a \mathbf n_a \otimes \mathbf n_a$.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SymSpectral {
    /// Eigenvalues $\lambda_a$ (unordered).
    pub values: Vector3<f64>,
    /// Eigenvectors $\mathbf n_a$ as the columns.
    pub vectors: Matrix3<f64>,
}

impl SymSpectral {
    /// Decomposes the symmetric part of `a`. Fails on non-finite entries or
    /// if the eigen-solver does not converge.
    pub fn new(a: &Matrix3<f64>) -> Result<Self> {
        if let Some(&value) = a.iter().find(|v| !v.is_finite()) {
            return Err(ConstitutiveError::NonFinite {
                which: "symmetric tensor",
                value,
            });
        }
        let sym = 0.5 * (a + a.transpose());
        if sym[(0, 2)] == 0.0 && sym[(1, 2)] == 0.0 {
            return Ok(Self::plane(&sym));
        }
        Self::iterative(&sym)
    }

    /// nalgebra's Householder + implicit QR solver. A closed-form solver
    /// (Cardano roots, a cross-product eigenvector, the exact 2×2 problem
    /// for the other pair) was twice as fast and matched this one to
    /// rounding on 2000 test tensors, but made the F-patch footing of
    /// Wang 2021 §5.1 (ν = 0.48) stall above its rounding floor and cut 7
    /// steps where this solver cuts none; it is not used until that is
    /// understood (`docs/src/benchmarks/solver.md`).
    fn iterative(sym: &Matrix3<f64>) -> Result<Self> {
        let eig = SymmetricEigen::try_new(*sym, f64::EPSILON, EIGEN_MAX_ITERATIONS)
            .ok_or(ConstitutiveError::EigenDecomposition)?;
        Ok(Self {
            values: eig.eigenvalues,
            vectors: eig.eigenvectors,
        })
    }

    /// Closed-form decomposition of a tensor whose third row and column are
    /// $(0, 0, a_{33})$ — every plane-strain tensor: the in-plane block
    /// $[[a, b], [b, c]]$ has eigenvalues $m \pm r$, $m = (a+c)/2$,
    /// $r = \sqrt{((a-c)/2)^2 + b^2}$ (the smaller one as $\det/\lambda_1$
    /// when that is more accurate) and eigenvectors at the angle
    /// $\theta = \tfrac12\operatorname{atan2}(2b, a - c)$. About four
    /// times cheaper than the iterative solver and exact to rounding.
    fn plane(sym: &Matrix3<f64>) -> Self {
        let (a, b, c) = (sym[(0, 0)], sym[(0, 1)], sym[(1, 1)]);
        let m = 0.5 * (a + c);
        let r = (0.5 * (a - c)).hypot(b);
        let (big, small) = if m >= 0.0 {
            (m + r, m - r)
        } else {
            (m - r, m + r)
        };
        let det = a * c - b * b;
        // The eigenvalue of smaller magnitude from det/big avoids the
        // cancellation in m ∓ r.
        let small = if big != 0.0 && small.abs() < 0.5 * big.abs() {
            det / big
        } else {
            small
        };
        let (l1, l2) = if m >= 0.0 { (big, small) } else { (small, big) };
        let theta = 0.5 * (2.0 * b).atan2(a - c);
        let (sn, cs) = theta.sin_cos();
        Self {
            values: Vector3::new(l1, l2, sym[(2, 2)]),
            vectors: Matrix3::new(cs, -sn, 0.0, sn, cs, 0.0, 0.0, 0.0, 1.0),
        }
    }

    /// The tensor with eigenvalues `g` and this basis: $\sum_a g_a \mathbf n_a\otimes\mathbf n_a$.
    #[inline]
    pub fn compose(&self, g: &Vector3<f64>) -> Matrix3<f64> {
        let v = &self.vectors;
        v * Matrix3::from_diagonal(g) * v.transpose()
    }

    /// The isotropic tensor function $\sum_a f(\lambda_a)\mathbf n_a\otimes\mathbf n_a$.
    #[inline]
    pub fn map(&self, f: impl Fn(f64) -> f64) -> Matrix3<f64> {
        self.compose(&self.values.map(f))
    }

    /// Eigenprojection $\mathbf n_a \otimes \mathbf n_a$ as a nine-vector.
    #[inline]
    pub fn projection(&self, a: usize) -> Vector9 {
        let n = self.vectors.column(a);
        to_vec9(&(n * n.transpose()))
    }

    /// The smallest eigenvalue.
    #[inline]
    pub fn min_value(&self) -> f64 {
        self.values.min()
    }

    /// $\ln \mathbf A$; fails unless $\mathbf A$ is positive definite.
    pub fn log(&self) -> Result<Matrix3<f64>> {
        self.require_positive()?;
        Ok(self.map(f64::ln))
    }

    /// $\exp \mathbf A$.
    pub fn exp(&self) -> Matrix3<f64> {
        self.map(f64::exp)
    }

    /// $\partial \ln(\mathbf A)/\partial \mathbf A$ in the storage of
    /// [`crate::tensor`]; the tensor $L$ of Coombs et al. 2020, eq. (A.2).
    pub fn dlog(&self) -> Result<Tensor4> {
        self.require_positive()?;
        Ok(self.derivative(|a, b| {
            let d = a - b;
            if d == 0.0 {
                1.0 / b
            } else {
                (d / b).ln_1p() / d
            }
        }))
    }

    /// The derivative of an isotropic tensor function given the divided
    /// difference `theta(λa, λb)`, which must return $f'(\lambda)$ when its
    /// arguments are equal and be symmetric in its arguments.
    ///
    /// The six rank-one terms are summed in the six-component (Voigt)
    /// storage of symmetric tensors, upper triangle only, and expanded to
    /// the $9\times9$ storage once: 126 multiply-adds against 486.
    pub fn derivative(&self, theta: impl Fn(f64, f64) -> f64) -> Tensor4 {
        // Voigt position of component (i, j) and the (i, j) of each.
        const VOIGT: [[usize; 3]; 3] = [[0, 3, 4], [3, 1, 5], [4, 5, 2]];
        const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];
        let lam = &self.values;
        let n = &self.vectors;
        let mut m = [[0.0f64; 6]; 6];
        let mut add = |w: f64, u: [f64; 6]| {
            for a in 0..6 {
                let wa = w * u[a];
                for b in a..6 {
                    m[a][b] += wa * u[b];
                }
            }
        };
        for a in 0..3 {
            add(
                theta(lam[a], lam[a]),
                PAIRS.map(|(i, j)| n[(i, a)] * n[(j, a)]),
            );
        }
        for (a, b) in [(0, 1), (0, 2), (1, 2)] {
            add(
                2.0 * theta(lam[a], lam[b]),
                PAIRS.map(|(i, j)| 0.5 * (n[(i, a)] * n[(j, b)] + n[(i, b)] * n[(j, a)])),
            );
        }
        Tensor4::from_fn(|r, c| {
            let (a, b) = (VOIGT[r / 3][r % 3], VOIGT[c / 3][c % 3]);
            if a <= b { m[a][b] } else { m[b][a] }
        })
    }

    fn require_positive(&self) -> Result<()> {
        let eigenvalue = self.min_value();
        if eigenvalue > 0.0 {
            Ok(())
        } else {
            Err(ConstitutiveError::NotPositiveDefinite { eigenvalue })
        }
    }
}

/// $\ln\mathbf A$ of a symmetric positive definite tensor.
pub fn sym_log(a: &Matrix3<f64>) -> Result<Matrix3<f64>> {
    SymSpectral::new(a)?.log()
}

/// $\exp\mathbf A$ of a symmetric tensor.
pub fn sym_exp(a: &Matrix3<f64>) -> Result<Matrix3<f64>> {
    Ok(SymSpectral::new(a)?.exp())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    fn rotated(values: [f64; 3]) -> Matrix3<f64> {
        let r = Rotation3::from_euler_angles(0.3, -1.1, 2.5).into_inner();
        r * Matrix3::from_diagonal(&Vector3::from(values)) * r.transpose()
    }

    #[test]
    fn decomposition_is_exact_for_repeated_and_nearly_repeated_eigenvalues() {
        for values in [
            [2.0, 2.0, 2.0],
            [2.0, 2.0, 3.0],
            [1.0, 1.0 + 1e-13, 4.0],
            [0.04, 0.04 * (1.0 + 1e-9), 25.0],
            [1e-3, 1.0, 1e3],
        ] {
            let a = rotated(values);
            let s = SymSpectral::new(&a).expect("decomposes");
            let v = s.vectors;
            assert!((v.transpose() * v - Matrix3::identity()).norm() < 1e-14);
            assert!((s.compose(&s.values) - a).norm() <= 1e-14 * a.norm());
        }
    }

    #[test]
    fn plane_closed_form_matches_the_iterative_solver() {
        for k in 0..500 {
            let t = k as f64;
            let (a, c) = (1.0 + 0.9 * (0.37 * t).sin(), 1.0 + 0.8 * (0.11 * t).cos());
            let b = 0.5 * (0.23 * t).sin() * if k % 7 == 0 { 1e-9 } else { 1.0 };
            let m = Matrix3::new(a, b, 0.0, b, c, 0.0, 0.0, 0.0, 0.3 + 0.001 * t);
            let s = SymSpectral::new(&m).expect("decomposes");
            let v = s.vectors;
            assert!((v.transpose() * v - Matrix3::identity()).norm() < 1e-15);
            assert!((s.compose(&s.values) - m).norm() <= 4e-16 * m.norm(), "{k}");
            let mut reference: Vec<f64> =
                SymmetricEigen::new(m).eigenvalues.iter().copied().collect();
            let mut ours: Vec<f64> = s.values.iter().copied().collect();
            reference.sort_by(f64::total_cmp);
            ours.sort_by(f64::total_cmp);
            for (x, y) in ours.iter().zip(&reference) {
                assert!((x - y).abs() <= 1e-15 * m.norm());
            }
        }
        // Nearly singular in-plane block: the small eigenvalue keeps its
        // relative accuracy.
        let e = (1.0 + 1e-12) - 1.0; // the perturbation as stored
        let m = Matrix3::new(1.0, 1.0, 0.0, 1.0, 1.0 + e, 0.0, 0.0, 0.0, 1.0);
        let s = SymSpectral::new(&m).expect("decomposes");
        let small = s.values.iter().copied().fold(f64::INFINITY, f64::min);
        assert!((small - e / (2.0 + e)).abs() <= 1e-12 * e, "{small:e}");
    }

    #[test]
    fn log_and_exp_are_inverse() {
        let a = rotated([0.2, 0.2 * (1.0 + 1e-11), 5.0]);
        let l = sym_log(&a).expect("spd");
        let back = sym_exp(&l).expect("finite");
        assert!((back - a).norm() < 1e-13 * a.norm());
        assert!((sym_log(&Matrix3::identity()).expect("spd")).norm() == 0.0);
    }

    #[test]
    fn log_of_non_positive_or_non_finite_tensor_is_an_error() {
        let a = rotated([1.0, -0.5, 2.0]);
        assert!(matches!(
            sym_log(&a),
            Err(ConstitutiveError::NotPositiveDefinite { .. })
        ));
        let mut b = Matrix3::identity();
        b[(0, 1)] = f64::NAN;
        assert!(matches!(
            SymSpectral::new(&b),
            Err(ConstitutiveError::NonFinite { .. })
        ));
    }

    #[test]
    fn dlog_of_identity_is_symmetric_identity() {
        let l = SymSpectral::new(&Matrix3::identity())
            .and_then(|s| s.dlog())
            .expect("spd");
        assert!((l - crate::tensor::sym_identity()).norm() < 1e-15);
    }
}
