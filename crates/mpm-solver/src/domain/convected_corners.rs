//! CPDI2 domains convected with the grid, Coombs et al. 2020 eq. (35)
//! applied to every corner.

use mpm_basis::{Corners, MAX_CORNERS};
use nalgebra::SVector;

use super::{DisplacementField, DomainContext, DomainError, DomainUpdater};

/// CPDI2: every corner of the domain moves with the grid displacement
/// increment, $x^c_i = \tilde X^c_i + \sum_v S_{vp}(\tilde{\mathbf X}^c)
/// (\Delta u_i)_v$ (the form of Coombs et al. 2020 eq. 35), and the
/// material point's volume is the volume of the moved domain
/// ([`Corners::volume`]) rather than $\det F\,V^0_p$.
///
/// Not a column of Table 2: the corners follow any affine increment
/// exactly, so the domain is the exact image of the initial one under
/// stretch, hydrostatic compression/extension, simple shear and rotation,
/// with volume $\det F\,V^0_p$ (§6.4: the midpoint rule is "inspired by
/// CPDI2 approaches in that the individual corners of a particle's domain
/// are updated according to the nodal deformation").
///
/// # Errors
/// A [`DomainError`] when `displacement_at` fails or the moved domain is
/// not finite, inverted or degenerate (a non-positive Jacobian
/// determinant at a Gauss point of the corner map).
#[derive(Debug, Clone, Copy, Default)]
pub struct ConvectedCorners;

impl<const D: usize> DomainUpdater<D, Corners<D>> for ConvectedCorners {
    const NAME: &'static str = "cpdi2";

    fn update(
        &self,
        ctx: &DomainContext<'_, D, Corners<D>>,
        displacement_at: impl DisplacementField<D>,
    ) -> Result<Corners<D>, DomainError> {
        let mut moved = [SVector::<f64, D>::zeros(); MAX_CORNERS];
        for (m, x) in moved.iter_mut().zip(ctx.previous.as_slice()) {
            *m = x + displacement_at(x)?;
        }
        let corners = Corners::from_fn(|c| moved[c]);
        corners.volume().map_err(DomainError::Corners)?;
        Ok(corners)
    }

    /// The volume of the convected domain. A domain [`Self::update`]
    /// accepted always has one; for any other (inverted, degenerate) domain
    /// this returns `f_volume`.
    fn volume(&self, domain: &Corners<D>, f_volume: f64) -> f64 {
        domain.volume().unwrap_or(f_volume)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::checks::Fixture;
    use nalgebra::{Matrix3, Vector2, Vector3};

    #[test]
    fn the_volume_is_that_of_the_moved_corners() {
        let xp = Vector2::new(1.0, 2.0);
        let c0 = Corners::rectangle(&xp, &Vector2::new(0.3, 0.2));
        let p = Fixture::<2, _>::first_step(c0, Matrix3::identity(), xp);
        // A trapezoid: u0 = 0.5 (x0 - 1)(x1 - 1.8) widens the top edge to 0.72.
        let field = |x: &Vector2<f64>| Ok(Vector2::new(0.5 * (x[0] - 1.0) * (x[1] - 1.8), 0.0));
        let c = ConvectedCorners.update(&p.ctx(), field).expect("update");
        let top = c.as_slice()[3][0] - c.as_slice()[2][0];
        assert!((top - 0.72).abs() <= 1e-15);
        let trapezoid = 0.5 * (0.6 + 0.72) * 0.4;
        assert!((ConvectedCorners.volume(&c, 1.0) - trapezoid).abs() <= 1e-15);
    }

    #[test]
    fn an_inverted_domain_is_an_error() {
        let c0 = Corners::rectangle(&Vector3::zeros(), &Vector3::repeat(0.1));
        let p = Fixture::<3, _>::first_step(c0, Matrix3::identity(), Vector3::zeros());
        // x0 -> -x0: the corner map is a reflection.
        let e = ConvectedCorners
            .update(&p.ctx(), |x| Ok(Vector3::new(-2.0 * x[0], 0.0, 0.0)))
            .expect_err("inverted");
        assert!(e.to_string().contains("not admissible"), "{e}");
        let e = ConvectedCorners
            .update(&p.ctx(), |_| Ok(Vector3::new(f64::INFINITY, 0.0, 0.0)))
            .expect_err("not finite");
        assert!(e.to_string().contains("not admissible"), "{e}");
        assert!((ConvectedCorners.volume(&p.initial, 7.0) - 0.008).abs() <= 1e-17);
    }
}
