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
        match Self::closed_form(&sym) {
            Some(s) => Ok(s),
            None => Self::iterative(&sym),
        }
    }

    /// Closed-form decomposition of a general symmetric tensor, backward
    /// stable: every eigenvalue is accurate to a few ε‖A‖ and the
    /// eigenvectors are orthonormal to rounding, for repeated and nearly
    /// repeated eigenvalues too.
    ///
    /// With $\mathbf A = m\mathbf 1 + s\mathbf C$ ($m = \operatorname{tr}\mathbf A/3$,
    /// $s$ the largest entry of the deviator, so $|C_{ij}| \le 1$), the
    /// eigenvalues of $\mathbf C$ are $2\sqrt p\cos(\varphi + 2\pi k/3)$ with
    /// $p = \|\mathbf C\|^2/6$, $\cos 3\varphi = r = \det\mathbf C/(2p^{3/2})$.
    /// Only the **isolated** root is taken from this formula: the largest
    /// when $r \ge 0$, the smallest when $r < 0$. Its distance from the other
    /// two is at least $\sqrt{3p}$ and its derivative with respect to $r$ is
    /// bounded, whereas the two roots of a nearly repeated pair lose half
    /// the digits there ($\partial\varphi/\partial r \sim (1-r^2)^{-1/2}$):
    /// a closed form that takes all three roots from the cubic puts an
    /// error of order $\sqrt\varepsilon\,\|\mathbf C\|$ into such a pair.
    /// Its eigenvector is the largest cross
    /// product of two rows of $\mathbf C - \mu_1\mathbf 1$ (rank two). The
    /// other pair is the exact $2\times2$ problem of $\mathbf C$ projected on
    /// an orthonormal basis of the complement, diagonalised by one Jacobi
    /// rotation, so its eigenvalues are accurate however close they are;
    /// the isolated eigenvalue is re-read as the Rayleigh quotient.
    ///
    /// `None` for a deviator so small that the scaling could underflow;
    /// the iterative solver takes those.
    fn closed_form(sym: &Matrix3<f64>) -> Option<Self> {
        let m = (sym[(0, 0)] + sym[(1, 1)] + sym[(2, 2)]) / 3.0;
        let mut dev = *sym;
        for i in 0..3 {
            dev[(i, i)] -= m;
        }
        let scale = dev.amax();
        if scale == 0.0 {
            return Some(Self {
                values: Vector3::repeat(m),
                vectors: Matrix3::identity(),
            });
        }
        if scale < 1e-250 || !scale.is_finite() {
            return None;
        }
        let c = dev / scale;
        let (c00, c11, c22) = (c[(0, 0)], c[(1, 1)], c[(2, 2)]);
        let (c01, c02, c12) = (c[(0, 1)], c[(0, 2)], c[(1, 2)]);
        let p =
            (c00 * c00 + c11 * c11 + c22 * c22) / 6.0 + (c01 * c01 + c02 * c02 + c12 * c12) / 3.0;
        let det = c00 * (c11 * c22 - c12 * c12) - c01 * (c01 * c22 - c12 * c02)
            + c02 * (c01 * c12 - c11 * c02);
        let sp = p.sqrt();
        let r = (0.5 * det / (p * sp)).clamp(-1.0, 1.0);
        let phi = r.acos() / 3.0;
        let mu1 = if r >= 0.0 {
            2.0 * sp * phi.cos()
        } else {
            2.0 * sp * (phi + 2.0 * std::f64::consts::FRAC_PI_3).cos()
        };
        // Eigenvector of the isolated root: the largest cross product of
        // two rows of C − μ₁1.
        let rows = [
            Vector3::new(c00 - mu1, c01, c02),
            Vector3::new(c01, c11 - mu1, c12),
            Vector3::new(c02, c12, c22 - mu1),
        ];
        let mut n1 = rows[0].cross(&rows[1]);
        let mut best = n1.norm_squared();
        for (a, b) in [(0, 2), (1, 2)] {
            let x = rows[a].cross(&rows[b]);
            let nx = x.norm_squared();
            if nx > best {
                (n1, best) = (x, nx);
            }
        }
        if !(best > 0.0 && best.is_finite()) {
            return None;
        }
        n1 /= best.sqrt();
        // An orthonormal basis (u, v) of the complement of n1.
        let k = n1.iamin();
        let mut axis = Vector3::zeros();
        axis[k] = 1.0;
        let u = n1.cross(&axis).normalize();
        let v = n1.cross(&u);
        let (cu, cv) = (c * u, c * v);
        let (a, b, d) = (u.dot(&cu), u.dot(&cv), v.dot(&cv));
        // One Jacobi rotation diagonalises [[a, b], [b, d]] exactly.
        let (cs, sn, t) = if b == 0.0 {
            (1.0, 0.0, 0.0)
        } else {
            let tau = (d - a) / (2.0 * b);
            let t = tau.signum() / (tau.abs() + tau.hypot(1.0));
            let cs = 1.0 / t.hypot(1.0);
            (cs, t * cs, t)
        };
        let e2 = cs * u - sn * v;
        let e3 = sn * u + cs * v;
        let l1 = n1.dot(&(c * n1));
        Some(Self {
            values: Vector3::new(
                m + scale * l1,
                m + scale * (a - t * b),
                m + scale * (d + t * b),
            ),
            vectors: Matrix3::from_columns(&[n1, e2, e3]),
        })
    }

    /// nalgebra's Householder + implicit QR solver, for the deviators too
    /// small to scale in [`Self::closed_form`].
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

    /// Eigenvalues (ascending) of `a` from nalgebra's QR solver.
    fn reference_values(a: &Matrix3<f64>) -> Vec<f64> {
        let mut v: Vec<f64> = SymmetricEigen::new(*a)
            .eigenvalues
            .iter()
            .copied()
            .collect();
        v.sort_by(f64::total_cmp);
        v
    }

    #[test]
    fn closed_form_is_backward_stable_on_clustered_graded_and_scaled_spectra() {
        // Deterministic pseudo-random rotations and spectra: nearly
        // repeated pairs and triples (gaps 1 … 1e-15 relative), graded
        // spectra, nearly isotropic tensors I + δ, scaled by 1e±90.
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut worst = [0.0f64; 4];
        let mut closed = 0;
        for k in 0..6000 {
            let angles = [0.0; 3].map(|_| (2.0 * uniform() - 1.0) * std::f64::consts::PI);
            let q = Rotation3::from_euler_angles(angles[0], angles[1], angles[2]).into_inner();
            let base = 0.1 + 3.0 * uniform();
            let gap = 10f64.powi(-((k % 16) as i32));
            let values = match k % 5 {
                0 => [base, base * (1.0 + gap), base * (1.0 + 0.7 * uniform())],
                1 => [base, base * (1.0 + gap), base * (1.0 - gap * uniform())],
                2 => [base * 1e-3, base, base * 1e3],
                3 => [
                    1.0 + gap * uniform(),
                    1.0 - gap * uniform(),
                    1.0 + gap * uniform(),
                ],
                _ => [base, 2.0 * base * uniform(), -base * uniform()],
            };
            let scale = [1.0, 1e90, 1e-90][k % 3];
            let a = q * Matrix3::from_diagonal(&Vector3::from(values)) * q.transpose() * scale;
            let a = 0.5 * (a + a.transpose());
            if a[(0, 2)] == 0.0 && a[(1, 2)] == 0.0 {
                continue;
            }
            let Some(s) = SymSpectral::closed_form(&a) else {
                continue;
            };
            closed += 1;
            let norm = a.norm();
            let v = s.vectors;
            worst[0] = worst[0].max((v.transpose() * v - Matrix3::identity()).norm());
            worst[1] = worst[1].max((s.compose(&s.values) - a).norm() / norm);
            for i in 0..3 {
                let n = v.column(i);
                worst[2] = worst[2].max((a * n - s.values[i] * n).norm() / norm);
            }
            let mut ours: Vec<f64> = s.values.iter().copied().collect();
            ours.sort_by(f64::total_cmp);
            for (x, y) in ours.iter().zip(reference_values(&a)) {
                worst[3] = worst[3].max((x - y).abs() / norm);
            }
        }
        assert!(closed > 5900, "{closed}");
        // Orthonormality, reconstruction, eigen-residual and agreement of
        // the eigenvalues with nalgebra's (whose own error adds), all at a
        // few ε (ε = 2.2e-16).
        assert!(worst[0] < 2e-15, "orthonormality {:e}", worst[0]);
        assert!(worst[1] < 2e-15, "reconstruction {:e}", worst[1]);
        assert!(worst[2] < 2e-15, "eigen-residual {:e}", worst[2]);
        assert!(
            worst[3] < 4e-15,
            "eigenvalues against nalgebra {:e}",
            worst[3]
        );
    }

    #[test]
    fn closed_form_keeps_a_nearly_repeated_pair_apart() {
        // The roots of the cubic alone would give this pair with an error
        // of about sqrt(ε)·‖C‖ ≈ 1e-8·‖C‖; the 2×2 problem gives its gap
        // to rounding.
        let base = [1.0, 1.0 + 1e-10, 1.3];
        let a = rotated(base);
        let s = SymSpectral::closed_form(&a).expect("scales");
        let mut v: Vec<f64> = s.values.iter().copied().collect();
        v.sort_by(f64::total_cmp);
        assert!(((v[1] - v[0]) - 1e-10).abs() < 1e-15, "{:e}", v[1] - v[0]);
        assert!((v[2] - 1.3).abs() < 1e-15);
        // Isotropic and scalar inputs: exact.
        let s = SymSpectral::closed_form(&(2.5 * Matrix3::identity())).expect("scales");
        assert_eq!(s.values, Vector3::repeat(2.5));
        assert_eq!(s.vectors, Matrix3::identity());
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
