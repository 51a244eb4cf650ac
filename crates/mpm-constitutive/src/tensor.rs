//! Second- and fourth-order tensors in 3D and the one index convention used
//! everywhere in the framework.
//!
//! # Index convention
//!
//! A second-order tensor $A_{ij}$ is stored as the nine-component vector
//! $\{A\}_{I}$ with $I = 3i + j$ (row-major: $A_{11}, A_{12}, A_{13},
//! A_{21}, \dots, A_{33}$; indices are zero-based in code). A fourth-order
//! tensor $\mathbb{C}_{ijkl}$ is the $9\times 9$ matrix
//! $[\mathbb{C}]_{IJ}$ with $I = 3i + j$, $J = 3k + l$, so that the double
//! contraction $(\mathbb{C} : G)_{ij} = \mathbb{C}_{ijkl} G_{kl}$ is the
//! matrix–vector product $[\mathbb{C}]\{G\}$ and
//! $(\mathbb{A}\mathbb{B})_{ijkl} = \mathbb{A}_{ijmn}\mathbb{B}_{mnkl}$ is
//! the matrix product. Full (non-Voigt) storage is used because the
//! tangents of finite-strain MPM lack minor symmetries.
//!
//! For a $D$-dimensional problem ($D = 2$: plane strain) the solver reads
//! the components with $i, j, k, l < D$; see [`restrict`].

use nalgebra::{Matrix3, SMatrix, SVector};

/// A fourth-order tensor in the $9\times 9$ storage of the module docs.
pub type Tensor4 = SMatrix<f64, 9, 9>;
/// A second-order tensor as a nine-component vector.
pub type Vector9 = SVector<f64, 9>;

/// Position of component $(i, j)$ in the nine-component storage.
#[inline(always)]
pub const fn idx(i: usize, j: usize) -> usize {
    3 * i + j
}

/// Kronecker delta.
#[inline(always)]
pub fn delta(i: usize, j: usize) -> f64 {
    if i == j { 1.0 } else { 0.0 }
}

/// $\{A\}$: the nine-component row-major vector of a 3×3 tensor.
#[inline]
pub fn to_vec9(a: &Matrix3<f64>) -> Vector9 {
    Vector9::from_fn(|r, _| a[(r / 3, r % 3)])
}

/// Inverse of [`to_vec9`].
#[inline]
pub fn from_vec9(v: &Vector9) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| v[idx(i, j)])
}

/// Dyadic product $(A \otimes B)_{ijkl} = A_{ij} B_{kl}$.
#[inline]
pub fn dyad(a: &Matrix3<f64>, b: &Matrix3<f64>) -> Tensor4 {
    to_vec9(a) * to_vec9(b).transpose()
}

/// Double contraction $(\mathbb{C} : G)_{ij} = \mathbb{C}_{ijkl} G_{kl}$.
#[inline]
pub fn contract(c: &Tensor4, g: &Matrix3<f64>) -> Matrix3<f64> {
    from_vec9(&(c * to_vec9(g)))
}

/// $C L$ for an $L$ with both minor symmetries ($L_{mnpq} = L_{nmpq} =
/// L_{mnqp}$, as $\partial\ln b/\partial b$ of eq. A.2): the sum over
/// $(m, n)$ runs over the six symmetric pairs and the six distinct columns
/// are computed once, 324 multiply-adds against the 729 of a general
/// product.
pub fn mul_minor_symmetric(c: &Tensor4, l: &Tensor4) -> Tensor4 {
    const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];
    // C with its (m, n) and (n, m) columns summed, per symmetric pair.
    let mut cs = [[0.0f64; 9]; 6];
    for (a, &(m, n)) in PAIRS.iter().enumerate() {
        for (row, x) in cs[a].iter_mut().enumerate() {
            *x = if m == n {
                c[(row, idx(m, m))]
            } else {
                c[(row, idx(m, n))] + c[(row, idx(n, m))]
            };
        }
    }
    let mut out = Tensor4::zeros();
    for &(k, l2) in &PAIRS {
        let col = idx(k, l2);
        for row in 0..9 {
            let mut acc = 0.0;
            for (a, &(m, n)) in PAIRS.iter().enumerate() {
                acc += cs[a][row] * l[(idx(m, n), col)];
            }
            out[(row, col)] = acc;
        }
        if k != l2 {
            let src = out.column(col).into_owned();
            out.set_column(idx(l2, k), &src);
        }
    }
    out
}

/// $M B$ for the kinematic tensor $B_{pqkl} = \delta_{pk}x_{ql} +
/// \delta_{qk}x_{pl}$ — the form of both $B$ (eq. A.2, $x = b$) and
/// $\tilde B$ (eq. A.5, $x = \Delta F b^e_n$):
/// $(MB)_{r,kl} = \sum_q M_{r,kq}x_{ql} + \sum_p M_{r,pk}x_{pl}$,
/// 486 multiply-adds against the 729 of a product with $B$ stored dense.
pub fn mul_b_form(m: &Tensor4, x: &Matrix3<f64>) -> Tensor4 {
    let mut out = Tensor4::zeros();
    for k in 0..3 {
        for l in 0..3 {
            let col = idx(k, l);
            for row in 0..9 {
                let mut acc = 0.0;
                for q in 0..3 {
                    acc += m[(row, idx(k, q))] * x[(q, l)] + m[(row, idx(q, k))] * x[(q, l)];
                }
                out[(row, col)] = acc;
            }
        }
    }
    out
}

/// The symmetric fourth-order identity
/// $\mathbb{I}^s_{ijkl} = \tfrac12(\delta_{ik}\delta_{jl} + \delta_{il}\delta_{jk})$.
pub fn sym_identity() -> Tensor4 {
    Tensor4::from_fn(|r, c| {
        let (i, j, k, l) = (r / 3, r % 3, c / 3, c % 3);
        0.5 * (delta(i, k) * delta(j, l) + delta(i, l) * delta(j, k))
    })
}

/// Embeds a $D \times D$ tensor ($D \le 3$) into 3D, filling the missing
/// diagonal entries with one: for $D = 2$ this is the plane-strain
/// kinematics $F_{33} = 1$, $F_{i3} = F_{3i} = 0$.
#[inline]
pub fn embed<const D: usize>(a: &SMatrix<f64, D, D>) -> Matrix3<f64> {
    const { assert!(D >= 1 && D <= 3, "embed needs 1 <= D <= 3") };
    Matrix3::from_fn(|i, j| {
        if i < D && j < D {
            a[(i, j)]
        } else {
            delta(i, j)
        }
    })
}

/// The in-plane block of a 3D tensor (inverse of [`embed`] on the block).
#[inline]
pub fn project<const D: usize>(a: &Matrix3<f64>) -> SMatrix<f64, D, D> {
    const { assert!(D >= 1 && D <= 3, "project needs 1 <= D <= 3") };
    SMatrix::<f64, D, D>::from_fn(|i, j| a[(i, j)])
}

/// The $D^2 \times D^2$ block of a fourth-order tensor with all four
/// indices below $D$, in the same row-major convention ($I = D i + j$).
/// `D2` must equal `D * D` (checked at compile time).
#[inline]
pub fn restrict<const D: usize, const D2: usize>(c: &Tensor4) -> SMatrix<f64, D2, D2> {
    const { assert!(D2 == D * D && D <= 3, "restrict needs D2 == D * D") };
    SMatrix::<f64, D2, D2>::from_fn(|r, s| {
        let (i, j, k, l) = (r / D, r % D, s / D, s % D);
        c[(idx(i, j), idx(k, l))]
    })
}

/// Frobenius-norm relative difference $\|A - B\| / \max(\|B\|, \text{floor})$.
pub fn relative_difference<const R: usize, const C: usize>(
    a: &SMatrix<f64, R, C>,
    b: &SMatrix<f64, R, C>,
    floor: f64,
) -> f64 {
    (a - b).norm() / b.norm().max(floor)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vec9_round_trip_and_contraction_match_index_notation() {
        let a = Matrix3::from_fn(|i, j| (1 + 3 * i + j) as f64);
        let g = Matrix3::from_fn(|i, j| ((i + 2) * (j + 5)) as f64 / 7.0);
        assert_eq!(from_vec9(&to_vec9(&a)), a);
        assert_eq!(to_vec9(&a)[idx(1, 2)], a[(1, 2)]);
        let c = Tensor4::from_fn(|r, s| (r * 9 + s) as f64 / 13.0);
        let by_matrix = contract(&c, &g);
        for i in 0..3 {
            for j in 0..3 {
                let mut sum = 0.0;
                for k in 0..3 {
                    for l in 0..3 {
                        sum += c[(idx(i, j), idx(k, l))] * g[(k, l)];
                    }
                }
                assert!((by_matrix[(i, j)] - sum).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn symmetric_identity_maps_to_symmetric_part() {
        let g = Matrix3::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0);
        let s = contract(&sym_identity(), &g);
        assert!((s - 0.5 * (g + g.transpose())).norm() < 1e-14);
    }

    #[test]
    fn plane_strain_embedding_and_restriction() {
        let f2 = nalgebra::Matrix2::new(1.1, 0.2, -0.3, 0.9);
        let f3 = embed(&f2);
        assert_eq!(f3[(2, 2)], 1.0);
        assert_eq!(f3[(0, 2)], 0.0);
        assert_eq!(project::<2>(&f3), f2);
        let c = Tensor4::from_fn(|r, s| (r * 9 + s) as f64);
        let c2 = restrict::<2, 4>(&c);
        assert_eq!(c2[(1, 3)], c[(idx(0, 1), idx(1, 1))]);
        assert_eq!(c2[(2, 1)], c[(idx(1, 0), idx(0, 1))]);
        let c3 = restrict::<3, 9>(&c);
        assert_eq!(c3, c);
    }

    /// The structured products equal the dense ones: $L$ with both minor
    /// symmetries (symmetrised from arbitrary entries) and $B$ stored
    /// densely from its definition.
    #[test]
    fn structured_products_match_dense_products() {
        let c = Tensor4::from_fn(|r, s| ((r * 7 + s * 3) % 11) as f64 / 3.0 - 1.5);
        let raw = Tensor4::from_fn(|r, s| ((r * 5 + s * 13) % 17) as f64 / 5.0 - 1.0);
        let l = Tensor4::from_fn(|r, s| {
            let (i, j, k, m) = (r / 3, r % 3, s / 3, s % 3);
            0.25 * (raw[(idx(i, j), idx(k, m))]
                + raw[(idx(j, i), idx(k, m))]
                + raw[(idx(i, j), idx(m, k))]
                + raw[(idx(j, i), idx(m, k))])
        });
        let dense = c * l;
        assert!((mul_minor_symmetric(&c, &l) - dense).norm() <= 1e-14 * dense.norm());
        let x = Matrix3::new(1.3, -0.2, 0.4, 0.7, 0.9, -1.1, 0.05, 0.3, 2.0);
        let b = Tensor4::from_fn(|r, s| {
            let (p, q, k, m) = (r / 3, r % 3, s / 3, s % 3);
            delta(p, k) * x[(q, m)] + delta(q, k) * x[(p, m)]
        });
        let dense = c * b;
        assert!((mul_b_form(&c, &x) - dense).norm() <= 1e-14 * dense.norm());
    }
}
