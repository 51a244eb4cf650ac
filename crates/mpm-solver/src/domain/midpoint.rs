//! The midpoint rule with volume correction, Coombs et al. 2020
//! eqs. (35)–(37) and Fig. 5, in its two variants: mid-points from the
//! moved corners ([`CornerMidpoint`]) or moved directly ([`Midpoint`]).

use mpm_basis::{Corners, MAX_CORNERS};
use nalgebra::SVector;

use super::{DisplacementField, DomainError, DomainUpdater, GimpContext, checks};

/// The midpoint rule with the mid-points taken from the moved corners
/// (Coombs et al. 2020 Fig. 5a, eqs. 35–37).
///
/// 1. The $2^D$ corners $\tilde{\mathbf X}^c = \tilde{\mathbf x}_p \pm
///    \mathbf l^{pn}$ of the domain at the start of the step move with the
///    grid displacement increment (eq. 35):
///    $x^c_i = \tilde X^c_i + \sum_v S_{vp}(\tilde{\mathbf X}^c)(\Delta u_i)_v$.
/// 2. The mid-points of the $2D$ faces (edges in 2D, face centres in 3D)
///    are the averages of the moved corners of each face: $2^{D-1}$ corners
///    each. This is the 3D generalisation chosen here; in 2D it is Fig. 5(a).
/// 3. Eq. (36) over **all** $2D$ mid-points $\mathbf x^m$:
///    $l^{pm}_i = \tfrac12\left(\max_m x^m_i - \min_m x^m_i\right)$.
/// 4. The volume correction of eq. (37):
///    $l^p_i = l^{pm}_i\left(\det F\prod_{j=1}^{n_D} l^{p0}_j\big/
///    \prod_{j=1}^{n_D} l^{pm}_j\right)^{1/n_D}$, so that the domain volume
///    is $\det F\,V^0_p$.
///
/// **Why all mid-points in eq. (36).** Taking for $l^{pm}_i$ only the two
/// mid-points of the faces normal to $\mathbf e_i$ would collapse the
/// domain under a rotation by 90° within a step: those two mid-points
/// $\tilde{\mathbf x}_p \pm l^{pn}_i\mathbf e_i$ move to
/// $\mathbf x_p \pm l^{pn}_i\mathbf e_j$, which share their $i$-coordinate,
/// so $l^{pm}_i = 0$ and eq. (37) divides by zero. Over all mid-points the
/// pair normal to $\mathbf e_j$ supplies the extent: the lengths swap,
/// $l^p_i = l^{pn}_j$, as the rotated domain does. Under a rotation by
/// $\theta$ of a domain square in the rotation plane every in-plane
/// $l^{pm}$ is $l^{pn}\max(|\cos\theta|, |\sin\theta|)$, which eq. (37)
/// restores in 2D.
///
/// Table 2 (column "(37)"): suitable for simple stretch, hydrostatic
/// compression/extension, simple shear and pure rotation; so it is in 2D.
/// In 3D the uniform correction of eq. (37) spreads the in-plane shrinkage
/// $m = \max(|\cos\Delta\theta|, |\sin\Delta\theta|)$ of a rotation step
/// $\Delta\theta$ about a coordinate axis over all $n_D = 3$ axes: per step
/// the in-plane lengths scale by $m^{1-2/n_D} = m^{1/3}$ and the length
/// along the rotation axis by $m^{-2/n_D} = m^{-2/3}$. The volume stays
/// exact but the shape drifts with the number of steps (measured in
/// `tests/domain_table2.rs`; see the theory chapter on domain updating).
///
/// # Errors
/// A [`DomainError`] for a non-finite $F$, $\det F \le 0$, initial
/// half-lengths that are not all positive, previous half-lengths that are
/// negative or not finite, a non-finite or failed `displacement_at`, or
/// moved mid-points without extent along an axis.
#[derive(Debug, Clone, Copy, Default)]
pub struct CornerMidpoint;

/// The midpoint rule with the mid-points moved directly (Coombs et al.
/// 2020 Fig. 5b, eqs. 36–37): the $2D$ face mid-points
/// $\tilde{\mathbf x}_p \pm l^{pn}_i\mathbf e_i$ of the domain at the start
/// of the step move with the grid displacement increment (the eq. 35 form),
/// then eqs. (36) and (37) as in [`CornerMidpoint`], whose documentation
/// explains the choice of all mid-points and the Table 2 verdict (the
/// same). Under an affine displacement increment both variants coincide;
/// under the grid's piecewise multilinear field they differ when a face
/// spans several cells.
///
/// # Errors
/// As [`CornerMidpoint`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Midpoint;

impl<const D: usize> DomainUpdater<D, SVector<f64, D>> for CornerMidpoint {
    const NAME: &'static str = "corner_midpoint";

    fn update(
        &self,
        ctx: &GimpContext<'_, D>,
        displacement_at: impl DisplacementField<D>,
    ) -> Result<SVector<f64, D>, DomainError> {
        midpoint_lengths(ctx, displacement_at, Source::Corners)
    }
}

impl<const D: usize> DomainUpdater<D, SVector<f64, D>> for Midpoint {
    const NAME: &'static str = "midpoint";

    fn update(
        &self,
        ctx: &GimpContext<'_, D>,
        displacement_at: impl DisplacementField<D>,
    ) -> Result<SVector<f64, D>, DomainError> {
        midpoint_lengths(ctx, displacement_at, Source::Direct)
    }
}

/// Where the moved mid-points come from (Fig. 5).
#[derive(Debug, Clone, Copy)]
enum Source {
    /// Averages of the moved corners of each face (Fig. 5a).
    Corners,
    /// The face mid-points moved directly (Fig. 5b).
    Direct,
}

/// Eqs. (36)–(37) with the mid-points from `source`.
fn midpoint_lengths<const D: usize>(
    ctx: &GimpContext<'_, D>,
    displacement_at: impl DisplacementField<D>,
    source: Source,
) -> Result<SVector<f64, D>, DomainError> {
    checks::half_lengths(ctx.initial, "initial")?;
    checks::half_lengths(ctx.previous, "previous")?;
    let j = checks::jacobian(ctx.f, "F")?;
    let volume0: f64 = ctx.initial.product();
    if volume0 <= 0.0 {
        return Err(DomainError::Inadmissible {
            rule: "midpoint",
            reason: format!(
                "eq. 37 needs an initial domain of positive volume, not the half-lengths {:?}",
                ctx.initial.as_slice()
            ),
        });
    }
    let (centre, l) = (ctx.position_previous, ctx.previous);
    let moved = |x: SVector<f64, D>| -> Result<SVector<f64, D>, DomainError> {
        let u = displacement_at(&x)?;
        if u.iter().any(|v| !v.is_finite()) {
            return Err(DomainError::NonFiniteDisplacement {
                value: u.as_slice().to_vec(),
                at: x.as_slice().to_vec(),
            });
        }
        Ok(x + u)
    };
    let mut lower = SVector::<f64, D>::repeat(f64::INFINITY);
    let mut upper = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
    let mut include = |m: &SVector<f64, D>| {
        lower = lower.inf(m);
        upper = upper.sup(m);
    };
    match source {
        Source::Direct => {
            for i in 0..D {
                for side in [-1.0, 1.0] {
                    let mut x = *centre;
                    x[i] += side * l[i];
                    include(&moved(x)?);
                }
            }
        }
        Source::Corners => {
            let n = Corners::<D>::COUNT;
            let mut corners = [SVector::<f64, D>::zeros(); MAX_CORNERS];
            for (c, corner) in corners.iter_mut().enumerate().take(n) {
                *corner = moved(centre + Corners::<D>::reference(c).component_mul(l))?;
            }
            let per_face = (n / 2) as f64;
            for i in 0..D {
                for bit in [0, 1] {
                    let sum = (0..n)
                        .filter(|c| c >> i & 1 == bit)
                        .fold(SVector::<f64, D>::zeros(), |s, c| s + corners[c]);
                    include(&(sum / per_face));
                }
            }
        }
    }
    let lm = (upper - lower) * 0.5;
    if let Some(i) = lm.iter().position(|x| x.is_nan() || *x <= 0.0) {
        return Err(DomainError::Inadmissible {
            rule: "midpoint",
            reason: format!(
                "the moved mid-points have no extent along axis {i} (eq. 36 gives {:?}): the \
                 domain collapsed",
                lm.as_slice()
            ),
        });
    }
    let scale = checks::dimension_root::<D>(j * volume0 / lm.product());
    Ok(lm * scale)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::checks::Fixture;
    use nalgebra::{Matrix3, Vector2, Vector3};

    /// Eqs. (36)–(37) from a list of moved mid-points, $\det F = 1$.
    fn lengths_from<const D: usize>(
        midpoints: &[SVector<f64, D>],
        l0: &SVector<f64, D>,
    ) -> SVector<f64, D> {
        let lm = SVector::<f64, D>::from_fn(|i, _| {
            let hi = midpoints
                .iter()
                .map(|x| x[i])
                .fold(f64::NEG_INFINITY, f64::max);
            let lo = midpoints.iter().map(|x| x[i]).fold(f64::INFINITY, f64::min);
            0.5 * (hi - lo)
        });
        lm * (l0.product() / lm.product()).powf(1.0 / D as f64)
    }

    /// A non-affine field, $u_0 = x_0x_1^2$, $u_1 = 0.05\,x_0^2$,
    /// $u_2 = 0.3\,x_0x_1$ (3D).
    fn field<const D: usize>(x: &SVector<f64, D>) -> Result<SVector<f64, D>, DomainError> {
        Ok(SVector::from_fn(|i, _| match i {
            0 => x[0] * x[1] * x[1],
            1 => 0.05 * x[0] * x[0],
            _ => 0.3 * x[0] * x[1],
        }))
    }

    /// The moved mid-points of both variants, written out face by face:
    /// (corner averages, moved directly).
    fn midpoints<const D: usize>(
        xp: &SVector<f64, D>,
        l: &SVector<f64, D>,
    ) -> (Vec<SVector<f64, D>>, Vec<SVector<f64, D>>) {
        let moved = |signs: &[f64]| {
            let x = xp + SVector::<f64, D>::from_fn(|i, _| signs[i] * l[i]);
            x + field(&x).expect("field")
        };
        let (mut averaged, mut direct) = (Vec::new(), Vec::new());
        for axis in 0..D {
            for side in [-1.0, 1.0] {
                let mut centre = [0.0; 3];
                centre[axis] = side;
                direct.push(moved(&centre));
                // The 2^(D-1) corners of the face: the other axes' signs.
                let others: Vec<usize> = (0..D).filter(|&k| k != axis).collect();
                let mut sum = SVector::<f64, D>::zeros();
                let count = 1 << others.len();
                for pattern in 0..count {
                    let mut corner = [0.0; 3];
                    corner[axis] = side;
                    for (bit, &k) in others.iter().enumerate() {
                        corner[k] = if pattern >> bit & 1 == 1 { 1.0 } else { -1.0 };
                    }
                    sum += moved(&corner);
                }
                averaged.push(sum / count as f64);
            }
        }
        (averaged, direct)
    }

    fn variants_follow_fig_5<const D: usize>(xp: SVector<f64, D>, l: SVector<f64, D>) {
        let p = Fixture::<D, _>::first_step(l, Matrix3::identity(), xp);
        let (averaged, direct) = midpoints(&xp, &l);
        let a = CornerMidpoint.update(&p.ctx(), field).expect("corners");
        let b = Midpoint.update(&p.ctx(), field).expect("direct");
        assert!((a - lengths_from(&averaged, &l)).norm() <= 1e-14, "{a}");
        assert!((b - lengths_from(&direct, &l)).norm() <= 1e-14, "{b}");
        assert!((a - b).norm() > 1e-3, "the variants coincide: {a} {b}");
    }

    #[test]
    fn the_variants_differ_under_a_non_affine_field_as_fig_5_draws() {
        variants_follow_fig_5(Vector2::new(1.0, 2.0), Vector2::new(0.3, 0.2));
        variants_follow_fig_5(Vector3::new(1.0, 2.0, 0.5), Vector3::new(0.3, 0.2, 0.25));
    }

    #[test]
    fn errors_instead_of_nan() {
        let l = Vector2::new(0.2, 0.1);
        let f = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0));
        let p = Fixture::<2, _>::first_step(l, f, Vector2::zeros());
        let e = CornerMidpoint
            .update(&p.ctx(), |x| Ok(p.affine_displacement(x)))
            .expect_err("det < 0");
        assert!(e.to_string().contains("det F"), "{e}");
        let p = Fixture::<2, _>::first_step(l, Matrix3::identity(), Vector2::zeros());
        let e = Midpoint
            .update(&p.ctx(), |_| Ok(Vector2::new(f64::NAN, 0.0)))
            .expect_err("NaN displacement");
        assert!(e.to_string().contains("not finite"), "{e}");
        // Every mid-point moved onto one line x1 = 0: no extent along axis 1.
        let e = CornerMidpoint
            .update(&p.ctx(), |x| Ok(Vector2::new(0.0, -x[1])))
            .expect_err("collapsed");
        assert!(e.to_string().contains("axis 1"), "{e}");
        let flat = Fixture::<2, _>::first_step(
            Vector2::new(0.2, 0.0),
            Matrix3::identity(),
            Vector2::zeros(),
        );
        let e = Midpoint
            .update(&flat.ctx(), |_| Ok(Vector2::zeros()))
            .expect_err("zero initial volume");
        assert!(e.to_string().contains("positive volume"), "{e}");
        let outside = DomainError::InactiveNode {
            node: 0,
            at: vec![],
        };
        let failing = |_: &Vector2<f64>| Err(outside.clone());
        let e = Midpoint.update(&p.ctx(), failing).expect_err("propagated");
        assert_eq!(e, outside);
    }
}
