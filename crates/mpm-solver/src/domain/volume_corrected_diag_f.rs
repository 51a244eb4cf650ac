//! The volume-corrected diagonal rule, Coombs et al. 2020 eq. (38).

use nalgebra::{Matrix3, SVector};

use super::{DeformationRule, DomainError, GimpContext, checks};

/// GIMP half-lengths scaled by the diagonal of $F$ and corrected to the
/// volume change (Coombs et al. 2020 eq. 38, no sum on $i$):
///
/// $$l^p_i = l^{p0}_i\,|F_{ii}|\left(\frac{\det F}{\prod_{j=1}^{n_D}
/// |F_{jj}|}\right)^{1/n_D},$$
///
/// so that $\prod_i l^p_i = \det F\prod_i l^{p0}_i$ always. Magnitudes
/// $|F_{ii}|$ as in [`super::DiagF`] (a rotation beyond 90° makes $F_{ii}$
/// negative; with the signed values the bracket can be negative and its
/// root undefined). Under pure rotation by $\theta \ne 90°$ about a
/// coordinate axis the in-plane diagonal is $|\cos\theta|$ and the lengths
/// are $l^{p0}_i|\cos\theta|^{1-2/n_D}$ in the rotation plane and
/// $l^{p0}_i|\cos\theta|^{-2/n_D}$ along the axis: $l^{p0}$ in 2D, but in 3D
/// the uniform correction turns the in-plane shrinkage into growth along
/// the axis (the volume stays exact).
///
/// Not in Table 2; the paper's text: "there is still an issue with this
/// approach when components of $F_{ii}$ are equal to zero, such as the case
/// of 90° rotation". Such a diagonal is an error here. A diagonal that is
/// zero only up to rounding (90° reached in steps) would give an arbitrary
/// aspect ratio, since $F_{ii}$ is known to an absolute accuracy of about
/// $\varepsilon\lVert F\rVert$ and $l^p_i$ then has a relative error of
/// about $\varepsilon\lVert F\rVert/|F_{ii}|$. So a diagonal with
/// $|F_{ii}| \le \sqrt\varepsilon\,\lVert F\rVert_F$ counts as zero (below
/// it fewer than half the digits of $l^p_i$ would be meaningful); see
/// [`VolumeCorrectedDiagF::MIN_RELATIVE_DIAGONAL`]. The incremental form (39) is
/// [`super::IncrementalVolumeCorrectedDiagF`].
///
/// # Errors
/// A [`DomainError`] for a non-finite $F$, $\det F \le 0$, a zero diagonal
/// component as above, or initial half-lengths that are negative or not
/// finite.
#[derive(Debug, Clone, Copy, Default)]
pub struct VolumeCorrectedDiagF;

impl VolumeCorrectedDiagF {
    /// A diagonal component $|F_{ii}| \le$ `MIN_RELATIVE_DIAGONAL`
    /// $\cdot\lVert F\rVert_F$ counts as zero in eqs. (38)/(39):
    /// $\sqrt\varepsilon \approx 1.5\times10^{-8}$ (see the type
    /// documentation).
    pub const MIN_RELATIVE_DIAGONAL: f64 = 1.490_116_119_384_765_6e-8;
}

impl<const D: usize> DeformationRule<D> for VolumeCorrectedDiagF {
    const NAME: &'static str = "volume_corrected_diag_f";

    fn half_lengths(&self, ctx: &GimpContext<'_, D>) -> Result<SVector<f64, D>, DomainError> {
        checks::half_lengths(ctx.initial, "initial")?;
        volume_corrected_diagonal(ctx.initial, ctx.f, "F")
    }
}

/// $l_i\,|G_{ii}|\,(\det G/\prod_j|G_{jj}|)^{1/D}$ for $G$ = `g` (named
/// `name` in errors): eq. (38) with $(l, G) = (l^{p0}, F)$ and eq. (39)
/// with $(l^{pn}, \Delta F)$.
pub(super) fn volume_corrected_diagonal<const D: usize>(
    l: &SVector<f64, D>,
    g: &Matrix3<f64>,
    name: &'static str,
) -> Result<SVector<f64, D>, DomainError> {
    let j = checks::jacobian(g, name)?;
    let floor = VolumeCorrectedDiagF::MIN_RELATIVE_DIAGONAL * g.norm();
    let mut product = 1.0;
    for i in 0..D {
        let gii = g[(i, i)].abs();
        if gii <= floor {
            return Err(DomainError::Inadmissible {
                rule: "volume_corrected_diag_f",
                reason: format!(
                    "the diagonal component {name}[({i}, {i})] = {:e} is zero (|{name}_ii| <= \
                 sqrt(eps)*|{name}| = {floor:e}), as under a rotation by 90°: the \
                 volume-corrected diagonal rule divides by the product of the diagonal; \
                 rotate in smaller steps (eq. 39) or use the midpoint rule (eq. 37)",
                    g[(i, i)]
                ),
            });
        }
        product *= gii;
    }
    let scale = checks::dimension_root::<D>(j / product);
    Ok(SVector::from_fn(|i, _| l[i] * g[(i, i)].abs() * scale))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::checks::Fixture;
    #[allow(unused_imports)]
    use crate::domain::{DomainContext, DomainUpdater};
    use nalgebra::{Rotation3, Vector2, Vector3};

    #[test]
    fn the_threshold_is_the_square_root_of_epsilon() {
        assert_eq!(
            VolumeCorrectedDiagF::MIN_RELATIVE_DIAGONAL,
            f64::EPSILON.sqrt()
        );
    }

    #[test]
    fn keeps_the_volume_and_under_rotation_the_documented_lengths() {
        // 2D: a rotation beyond 90° (F_ii < 0) leaves the lengths at l0.
        let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), 2.5).into_inner();
        let l0 = Vector2::new(0.1, 0.2);
        let p = Fixture::<2, _>::first_step(l0, rot, Vector2::zeros());
        assert!(rot[(0, 0)] < 0.0 && rot[(1, 1)] < 0.0);
        let l = VolumeCorrectedDiagF
            .update(&p.ctx(), |_| Ok(Vector2::zeros()))
            .expect("update");
        assert!((l - l0).norm() <= 1e-15);
        // 3D, rotation about x: in-plane |cos θ|^(1/3), axial |cos θ|^(-2/3).
        let l0 = Vector3::new(0.1, 0.2, 0.3);
        let rot = Rotation3::from_axis_angle(&Vector3::x_axis(), 2.5).into_inner();
        let p = Fixture::<3, _>::first_step(l0, rot, Vector3::zeros());
        let l = VolumeCorrectedDiagF
            .update(&p.ctx(), |_| Ok(Vector3::zeros()))
            .expect("update");
        let c = 2.5f64.cos().abs();
        let expected = Vector3::new(0.1 * c.powf(-2.0 / 3.0), 0.2 * c.cbrt(), 0.3 * c.cbrt());
        assert!((l - expected).norm() <= 1e-15, "{l} {expected}");
        let f = rot * Matrix3::from_diagonal(&Vector3::new(1.0, 1.3, 0.6));
        let p = Fixture::<3, _>::first_step(l0, f, Vector3::zeros());
        let l = VolumeCorrectedDiagF
            .update(&p.ctx(), |_| Ok(Vector3::zeros()))
            .expect("update");
        let volume_ratio = l.product() / l0.product();
        assert!((volume_ratio - f.determinant()).abs() <= 1e-14);
    }

    #[test]
    fn a_zero_diagonal_is_an_error() {
        let quarter = Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        let p = Fixture::<2, _>::first_step(Vector2::new(0.2, 0.2), quarter, Vector2::zeros());
        let e = VolumeCorrectedDiagF
            .update(&p.ctx(), |_| Ok(Vector2::zeros()))
            .expect_err("F_00 = 0");
        assert!(
            e.to_string().contains("F[(0, 0)]") && e.to_string().contains("zero"),
            "{e}"
        );
        // Zero up to rounding (90° as three steps of 30°) is zero as well.
        let step = Rotation3::from_axis_angle(&Vector3::z_axis(), 30f64.to_radians()).into_inner();
        let p = Fixture::<2, _>::first_step(
            Vector2::new(0.2, 0.2),
            step * step * step,
            Vector2::zeros(),
        );
        assert!(p.f[(0, 0)] != 0.0 && p.f[(0, 0)].abs() < 1e-15);
        assert!(
            VolumeCorrectedDiagF
                .update(&p.ctx(), |_| Ok(Vector2::zeros()))
                .is_err()
        );
    }

    #[test]
    fn a_non_positive_jacobian_is_an_error() {
        let f = Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0));
        let p = Fixture::<2, _>::first_step(Vector2::new(0.2, 0.2), f, Vector2::zeros());
        let e = VolumeCorrectedDiagF
            .update(&p.ctx(), |_| Ok(Vector2::zeros()))
            .expect_err("det < 0");
        assert!(e.to_string().contains("det F"), "{e}");
    }
}
